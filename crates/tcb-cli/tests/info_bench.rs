//! `tcb info` and `tcb bench` as a user runs them.

mod common;

use common::{assert_success, file, stderr, stdout, tcb};

#[test]
fn info_names_tracks_grids_and_bytes() {
    let o = tcb(&["info", &file("examples/clips/bounce.json")]);
    assert_success(&o);
    let out = stdout(&o);
    assert!(
        out.contains("3 tracks, 8 channels, 10 keys, 0 to 2 s"),
        "{out}"
    );
    assert!(
        out.contains("ball.squash                      scalar      2"),
        "{out}"
    );
    // The ball turns a quarter turn and more between keys: one cubic per
    // segment would miss there, so the rotation's segments are split into
    // cubic pieces on key times of its own (a loose lane), none exact.
    assert!(
        out.contains(
            "0 shared key grid(s), 2 loose vector track(s), 1 loose rotation(s), 0 rotation segment(s) evaluated exactly"
        ),
        "{out}"
    );
    assert!(out.contains("bytes: "));
    // A BVH file, imported on the fly, with its skeleton.
    let o = tcb(&["info", &file("data/cmu-01_01.bvh"), "--rotation", "hermite"]);
    assert_success(&o);
    let out = stdout(&o);
    assert!(
        out.contains("32 tracks") && out.contains("skeleton: 38 joints"),
        "{out}"
    );
    // Capture at 120 fps: every inner key's incoming tangent is its
    // outgoing one; the first and last keys have one side only.
    assert!(
        out.contains(
            "grid 0: 2752 keys (2 with incoming tangents stored apart), 3 vector channels, 31 rotations"
        ),
        "{out}"
    );
    // Quantized: smaller, and every track states its error bound.
    let q = tcb(&[
        "info",
        &file("data/cmu-01_01.bvh"),
        "--rotation",
        "hermite",
        "--quantize",
    ]);
    assert_success(&q);
    let qout = stdout(&q);
    assert_eq!(
        qout.matches("quantization error at most").count(),
        32,
        "{qout}"
    );
    let mb = |s: &str| -> f64 {
        let line = s.lines().find(|l| l.starts_with("bytes: ")).unwrap();
        line["bytes: ".len()..]
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(mb(&qout) * 1.5 < mb(&out), "{} vs {}", mb(&qout), mb(&out));
}

#[test]
fn bench_reports_ns_per_joint_bytes_and_flags() {
    let o = tcb(&[
        "bench",
        &file("examples/clips/bounce.json"),
        "--rounds",
        "1",
        "--slice-ms",
        "1",
        "--instances",
        "3",
        "--threads",
        "2",
        "--quantize",
    ]);
    assert_success(&o);
    let out = stdout(&o);
    for want in [
        "build:",
        "RUSTFLAGS=",
        "ns per joint",
        "ns per channel",
        "bytes:",
        "on 2 thread(s)",
    ] {
        assert!(out.contains(want), "{want:?} missing from\n{out}");
    }
}

#[test]
fn bench_and_info_refuse_bad_input() {
    let bounce = file("examples/clips/bounce.json");
    for args in [
        vec!["bench", &bounce, "--fps", "0"],
        vec!["bench", &bounce, "--fps", "nan"],
        vec!["bench", &bounce, "--fps", "-1"],
        vec!["bench", &bounce, "--instances", "0"],
        vec!["bench", &bounce, "--threads", "0"],
        vec!["bench", &bounce, "--rotation", "hermite"],
        vec!["bench", "/no/such/file.json"],
        vec!["info", "/no/such/file.bvh"],
        vec!["info", &bounce, "--animation", "0"],
    ] {
        let o = tcb(&args);
        assert!(!o.status.success(), "{args:?} succeeded");
        let err = stderr(&o);
        assert!(
            err.starts_with("tcb: error: ") || err.contains("error:"),
            "{args:?}: {err}"
        );
        assert!(o.stdout.is_empty(), "{args:?} printed {}", stdout(&o));
    }
}

/// `tcb info --quantize` says which tracks it keeps in f32 (a range beyond
/// what 16 bits span within a finite error) instead of stating a bound the
/// 16-bit keys would not keep (issue 29, class 4).
#[test]
fn info_says_which_tracks_quantizing_keeps_in_f32() {
    let dir = common::scratch("info-kept-f32");
    let path = dir.join("wide-range.json");
    std::fs::write(
        &path,
        r#"{"format": "tcb-clip/1", "tracks": [
          {"name": "huge", "kind": "scalar", "times": [0, 0.25, 0.75, 1], "values": [-1.8e38, 0, 1.8e38, 1.8e38]},
          {"name": "small", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#,
    )
    .unwrap();
    let o = tcb(&["info", path.to_str().unwrap(), "--quantize"]);
    assert_success(&o);
    let out = stdout(&o);
    assert_eq!(out.matches("kept in f32").count(), 1, "{out}");
    assert_eq!(
        out.matches("quantization error at most").count(),
        1,
        "{out}"
    );
    let huge = out.find("huge").unwrap();
    assert!(
        out[huge..].find("kept in f32") < out[huge..].find("small"),
        "{out}"
    );
}
