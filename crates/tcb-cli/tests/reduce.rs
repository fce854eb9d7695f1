//! `tcb reduce` as a user runs it (`spec/reduce.md`): the summary line, a
//! result the other commands accept, and bad input that writes nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tcb(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tcb"))
        .args(args)
        .output()
        .expect("run tcb")
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
        .to_string_lossy()
        .into_owned()
}

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("tcb-reduce-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The first `frames` frames of the bundled CMU clip, as a BVH file.
fn short_cmu(frames: usize) -> PathBuf {
    let text = std::fs::read_to_string(repo("data/cmu-01_01.bvh")).unwrap();
    let (head, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<&str> = lines.take(frames).collect();
    let out = format!(
        "{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n",
        rows.join("\n")
    );
    let path = dir().join(format!("cmu-{frames}.bvh"));
    std::fs::write(&path, out).unwrap();
    path
}

/// `reduced: tracks T, keys K0 -> K1, values V0 -> V1, bytes B0 -> B1,
/// max error e (METRIC, joint J, time t)`, its numbers.
fn summary(stdout: &str, metric: &str) -> [f64; 8] {
    let line = stdout.lines().last().unwrap();
    let rest = line.strip_prefix("reduced: tracks ").expect(line);
    let (counts, tail) = rest.split_once(", max error ").expect(line);
    let (error, place) = tail.split_once(" (").expect(line);
    assert!(place.starts_with(&format!("{metric}, joint ")), "{line}");
    assert!(place.contains(", time ") && place.ends_with(')'), "{line}");
    let mut n = Vec::new();
    for part in counts.split(", ") {
        let part = part.trim_start_matches(|c: char| c.is_alphabetic() || c == ' ');
        for x in part.split(" -> ") {
            n.push(x.parse::<f64>().expect(line));
        }
    }
    assert_eq!(n.len(), 7, "{line}");
    let mut out = [0.0; 8];
    out[..7].copy_from_slice(&n);
    out[7] = error.parse().expect(line);
    out
}

#[test]
fn reduces_a_bvh_within_the_shell_tolerance_and_the_result_plays_and_exports() {
    let input = short_cmu(240);
    let out = dir().join("short.json");
    let o = tcb(&[
        "reduce",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tolerance",
        "0.05",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8(o.stdout.clone()).unwrap();
    let [tracks, k0, k1, v0, v1, b0, b1, e] = summary(&stdout, "shell");
    assert_eq!(tracks, 32.0);
    assert_eq!(k0, 32.0 * 240.0);
    assert!(k1 < k0 && v1 < v0 && b1 < b0, "{stdout}");
    assert!(e <= 0.05, "{stdout}");
    assert!(
        stderr(&o).contains("metric shell, tolerance 5e-2"),
        "{}",
        stderr(&o)
    );
    for args in [
        vec!["sample", out.to_str().unwrap(), "--at", "0.5,1"],
        vec![
            "export",
            out.to_str().unwrap(),
            "-o",
            dir().join("short.glb").to_str().unwrap(),
        ],
    ] {
        let o = tcb(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn a_clip_without_skeleton_reduces_by_value() {
    let out = dir().join("bounce.json");
    let o = tcb(&[
        "reduce",
        &repo("examples/clips/bounce.json"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8(o.stdout.clone()).unwrap();
    let [_, _, _, v0, v1, ..] = summary(&stdout, "value");
    assert!(v1 <= v0, "{stdout}");
    assert!(
        stderr(&o).contains("metric value, tolerance 1e-4, rotation tolerance 0.01 degrees"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bad_input_is_a_clear_error_and_writes_nothing() {
    let out = dir().join("never.json");
    let empty = dir().join("empty.json");
    std::fs::write(&empty, "").unwrap();
    let empty_bvh = dir().join("empty.bvh");
    std::fs::write(&empty_bvh, "").unwrap();
    let bounce = repo("examples/clips/bounce.json");
    let bvh = repo("data/cmu-01_01.bvh");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![&bounce, "--metric", "shell"],
            "--metric shell needs a skeleton",
        ),
        (
            vec![&bvh, "--tolerance", "0"],
            "--tolerance must be a positive number, got 0",
        ),
        (
            vec![&bvh, "--tolerance", "-1"],
            "--tolerance must be a positive number, got -1",
        ),
        (
            vec![&bvh, "--tolerance", "NaN"],
            "--tolerance must be a positive number, got NaN",
        ),
        (
            vec![&bvh, "--tolerance", "inf"],
            "--tolerance must be a positive number, got inf",
        ),
        (
            vec![&bvh, "--shell", "-0.5"],
            "--shell must be a number >= 0, got -0.5",
        ),
        (
            vec![&bounce, "--rotation-tolerance", "0"],
            "--rotation-tolerance must be a positive number, got 0",
        ),
        (vec![empty.to_str().unwrap()], "empty.json"),
        (vec![empty_bvh.to_str().unwrap()], "empty.bvh"),
        (vec![&bvh, "--knots", "bone"], "unknown knot sharing 'bone'"),
    ];
    for (args, message) in cases {
        let mut all = vec!["reduce", args[0], "-o", out.to_str().unwrap()];
        all.extend(&args[1..]);
        let o = tcb(&all);
        assert!(!o.status.success(), "{all:?}");
        assert!(stderr(&o).contains(message), "{all:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{all:?}");
        assert!(!out.exists(), "{all:?} wrote {}", out.display());
    }
    let o = tcb(&[
        "reduce",
        &bounce,
        "-o",
        dir().join("x.csv").to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("the output must end in .json"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn an_imported_clip_keeps_its_skeleton_and_reduces_by_shell() {
    let bvh = short_cmu(120);
    let json = dir().join("short-import.json");
    let o = tcb(&[
        "import",
        bvh.to_str().unwrap(),
        "-o",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let from_bvh = tcb_io::load(&bvh).unwrap().skeleton.unwrap();
    let from_json = tcb_io::load(&json).unwrap().skeleton.unwrap();
    assert_eq!(from_json, from_bvh);
    assert!(from_json.joint("Head_end").is_some());
    let out = dir().join("short-import-reduced.json");
    let o = tcb(&[
        "reduce",
        json.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tolerance",
        "0.05",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8(o.stdout.clone()).unwrap();
    let [.., e] = summary(&stdout, "shell");
    assert!(e <= 0.05, "{stdout}");
    // The reduced clip carries the rig on.
    assert_eq!(tcb_io::load(&out).unwrap().skeleton.unwrap(), from_bvh);
}
