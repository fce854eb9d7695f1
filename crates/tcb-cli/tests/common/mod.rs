//! What the `tcb` command's tests share: running the binary, reading what
//! it wrote, naming the repository's files and a scratch folder per test
//! binary.

#![allow(dead_code, reason = "each test binary uses some of these")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `tcb` binary, to set up before running (a working folder, say).
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tcb"))
}

/// `tcb ARGS...`, run to the end.
pub fn tcb(args: &[&str]) -> Output {
    command().args(args).output().expect("run tcb")
}

/// `tcb SUBCOMMAND INPUT -o OUT EXTRA...`, run to the end: the shape of
/// `import`, `export`, `reduce`, `compress`, `plot` and `view`.
pub fn tcb_to(
    subcommand: &str,
    input: impl AsRef<Path>,
    out: impl AsRef<Path>,
    extra: &[&str],
) -> Output {
    command()
        .arg(subcommand)
        .arg(input.as_ref())
        .arg("-o")
        .arg(out.as_ref())
        .args(extra)
        .output()
        .expect("run tcb")
}

/// Asserts that the run succeeded (showing what it wrote to stderr if
/// not).
#[track_caller]
pub fn assert_success(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// What the run wrote to stdout (`tcb` writes UTF-8).
pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("stdout is UTF-8")
}

/// What the run wrote to stderr (`tcb` writes UTF-8).
pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("stderr is UTF-8")
}

/// The repository's root folder.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A file of the repository (`rel` from its root), as an argument.
pub fn file(rel: &str) -> String {
    root().join(rel).to_string_lossy().into_owned()
}

/// A folder of the system's temporary folder, `tcb-NAME-PID`, created: the
/// process id keeps test binaries running at once apart.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tcb-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Asserts that what the run wrote to stderr holds `text` (showing all of
/// it if not).
#[track_caller]
pub fn stderr_has(o: &Output, text: &str) {
    let err = stderr(o);
    assert!(err.contains(text), "{err}");
}

/// The first `frames` frames of the bundled CMU clip, as a BVH file.
pub fn short_cmu(frames: usize) -> PathBuf {
    let text = std::fs::read_to_string(file("data/cmu-01_01.bvh")).unwrap();
    let (head, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<&str> = lines.take(frames).collect();
    let out = format!(
        "{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n",
        rows.join("\n")
    );
    // A file per call: tests run in parallel, and two rewriting one path
    // could hand a `tcb` child a file being truncated.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = scratch("cmu").join(format!("cmu-{frames}-{n}.bvh"));
    std::fs::write(&path, out).unwrap();
    path
}
