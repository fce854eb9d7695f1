//! `tcb reduce`'s output reads back bit for bit (issue 29, class 1): the
//! clip verified in memory is the clip a reader of the written file gets,
//! key times (frame times such as `348 * 0.0083333`, which a reader that is
//! not round-trip exact reads 1 ulp off), values and tangents alike.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("tcb-round-trip-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The first `frames` frames of the bundled CMU clip, as a BVH file.
fn short_cmu(frames: usize) -> PathBuf {
    let text = std::fs::read_to_string(repo("data/cmu-01_01.bvh")).unwrap();
    let (head, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<&str> = lines.take(frames).collect();
    let path = dir().join(format!("cmu-{frames}.bvh"));
    std::fs::write(
        &path,
        format!(
            "{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n",
            rows.join("\n")
        ),
    )
    .unwrap();
    path
}

/// Equal `Debug` text is equal bits: every float is printed in its
/// shortest round-trip form (`-0` and `0` differ). The first difference,
/// or `None`.
fn difference(read: &tcb_io::ClipDoc, written: &tcb_io::ClipDoc) -> Option<String> {
    let (a, b) = (format!("{read:?}"), format!("{written:?}"));
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let at = a
        .iter()
        .zip(&b)
        .position(|(x, y)| x != y)
        .or_else(|| (a.len() != b.len()).then(|| a.len().min(b.len())))?;
    let around = |s: &[char]| -> String {
        s[at.saturating_sub(80)..(at + 40).min(s.len())]
            .iter()
            .collect()
    };
    Some(format!(
        "read back:\n  ...{}...\nwritten:\n  ...{}...",
        around(&a),
        around(&b)
    ))
}

#[test]
fn a_reduced_clip_written_then_read_is_the_clip_verified() {
    let input = short_cmu(400);
    let loaded = tcb_io::load(&input).unwrap();
    let options = tcb_fit::ReduceOptions {
        // Tight: most frames stay keys, among them frame times that a
        // reader that is not round-trip exact misreads.
        tolerance: Some(0.005),
        ..Default::default()
    };
    let reduced = tcb_fit::reduce(
        tcb_fit::reduce::Input {
            doc: &loaded.doc,
            clip: &loaded.clip,
            skeleton: loaded.skeleton.as_ref(),
        },
        &options,
        &|_, _| {},
    )
    .unwrap();
    let path = dir().join("reduced.json");
    tcb_io::write_clip_doc(&reduced.doc, &path).unwrap();
    let read = tcb_io::read_clip_doc(&path).unwrap();
    if let Some(d) = difference(&read, &reduced.doc) {
        panic!("{d}");
    }

    // `tcb reduce` writes that same text.
    let out = dir().join("reduced-by-tcb.json");
    let o = Command::new(env!("CARGO_BIN_EXE_tcb"))
        .args(["reduce", input.to_str().unwrap(), "-o"])
        .arg(&out)
        .args(["--tolerance", "0.005"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read_to_string(&out).unwrap() == reduced.doc.to_json(),
        "tcb reduce wrote another clip than tcb_fit::reduce made"
    );
}
