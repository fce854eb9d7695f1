//! `tcb export` and glTF's f32 key times (issue 29, class 6): times glTF
//! cannot hold are refused on one line, writing nothing; keys that f32
//! times move are reported, not called exact, and `tcb import` reads the
//! export back within the error reported.

mod common;

use common::{assert_success, scratch, stderr, stdout, tcb, tcb_to};
use std::path::PathBuf;

/// This binary's scratch folder.
fn dir() -> PathBuf {
    scratch("export-times-test")
}

/// A clip file `name` of one `a.translation` track at `times`.
fn clip_at(name: &str, times: &str) -> PathBuf {
    let n = times.split(',').count();
    let values: Vec<String> = (0..n)
        .map(|k| format!("[{}, {}, 0]", k % 3, (k % 2) * 2))
        .collect();
    let path = dir().join(name);
    std::fs::write(
        &path,
        format!(
            r#"{{"format": "tcb-clip/1", "tracks": [{{"name": "a.translation", "kind": "vec3",
              "times": [{times}], "values": [{}]}}]}}"#,
            values.join(", ")
        ),
    )
    .unwrap();
    path
}

#[test]
fn times_gltf_cannot_hold_are_one_line_and_write_nothing() {
    for (name, times, why) in [
        ("beyond.json", "0, 1, 1e39", "beyond glTF's key times (f32"),
        (
            "equal.json",
            "0, 100000000, 100000001",
            "are one time in glTF's f32 key times",
        ),
    ] {
        let clip = clip_at(name, times);
        let out = dir().join(format!("{name}.glb"));
        let o = tcb_to("export", &clip, &out, &[]);
        assert!(!o.status.success(), "{name}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("tcb: error: "), "{err}");
        assert!(err.contains(why), "{err}");
        assert!(err.contains("before exporting"), "{err}");
        assert!(!out.exists(), "{name}");
    }
}

/// `tcb sample --scalar FILE --at TIMES`, as rows of numbers.
fn sample(file: &str, at: &str) -> Vec<Vec<f64>> {
    let o = tcb(&["sample", "--scalar", file, "--at", at]);
    assert_success(&o);
    stdout(&o)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn keys_moved_by_f32_times_are_reported_and_read_back_within_it() {
    let clip = clip_at(
        "million.json",
        "1e6, 1000000.1, 1000000.2, 1000000.3, 1000000.4",
    );
    let glb = dir().join("million.glb");
    let o = tcb_to("export", &clip, &glb, &[]);
    assert_success(&o);
    let err = stderr(&o);
    let wrote = err.lines().find(|l| l.contains("wrote")).expect(&err);
    assert!(wrote.contains("1 tracks, 0 exact"), "{err}");
    let reported: f64 = wrote
        .split_once("max error ")
        .and_then(|(_, rest)| rest.split_once(','))
        .map(|(e, _)| e.parse().unwrap())
        .expect(&err);
    assert!(
        err.contains("glTF's f32 key times move its keys by up to"),
        "{err}"
    );

    let back = dir().join("million-back.json");
    let o = tcb_to("import", &glb, &back, &[]);
    assert_success(&o);
    // The keys, where f32 stores them, and between.
    let at: Vec<String> = (0..=64)
        .map(|i| format!("{:?}", 1e6 + 0.4 * f64::from(i) / 64.0))
        .collect();
    let at = at.join(",");
    let (a, b) = (
        sample(clip.to_str().unwrap(), &at),
        sample(back.to_str().unwrap(), &at),
    );
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(&b) {
        for (u, v) in x.iter().zip(y).skip(1) {
            worst = worst.max((u - v).abs() / u.abs().max(1.0));
        }
    }
    assert!(worst > 1e-3, "the keys moved: {worst}");
    assert!(
        worst <= reported,
        "read back {worst} off, reported {reported}"
    );
}
