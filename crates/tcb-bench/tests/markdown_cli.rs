//! `tcb-bench --markdown` as a user runs it, without timing anything: a
//! document with nowhere to put the tables is refused before the first
//! round, in one line, and left as it was.

use std::process::Command;

#[test]
fn a_document_without_the_markers_is_refused_before_timing() {
    let dir = std::env::temp_dir().join(format!("tcb-bench-md-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let doc = dir.join("bench.md");
    let text = "# Benchmarks\n\nhand-written, no markers\n";
    std::fs::write(&doc, text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tcb-bench"))
        .arg("--markdown")
        .arg(&doc)
        .output()
        .expect("run tcb-bench");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("no lines '<!-- tcb-bench --markdown"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    // Nothing was timed: the report's table never started.
    assert!(String::from_utf8_lossy(&o.stdout).is_empty());
    assert_eq!(std::fs::read_to_string(&doc).unwrap(), text);
    let _ = std::fs::remove_dir_all(&dir);
}
