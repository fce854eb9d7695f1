//! `tcb` never panics, whatever the file or the flags (issue 29): every
//! input of the committed fuzz corpora (`fuzz/corpus/`) is given to the
//! command under each file name a reader takes, and each file it reads is
//! put through every subcommand; then the bundled clips get edge values for
//! every numeric flag. A run either succeeds or fails with a message and
//! writes nothing; a panic, a signal or a run past its time fails the test.

mod common;

use common::{command, root, scratch};
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

/// Longest a single run may take (a debug build, beside other tests).
const LIMIT: Duration = Duration::from_secs(120);

/// Runs `tcb ARGS` in `dir` to its end, or fails after [`LIMIT`].
fn run(dir: &Path, args: &[&str]) -> Output {
    let mut child = command()
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run tcb");
    let start = Instant::now();
    // Drain both pipes on threads so that a large output cannot block the
    // child while it is waited for.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out_thread = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut out, &mut v).unwrap();
        v
    });
    let err_thread = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut err, &mut v).unwrap();
        v
    });
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > LIMIT {
            child.kill().unwrap();
            panic!("`tcb {}` ran past {LIMIT:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Output {
        status,
        stdout: out_thread.join().unwrap(),
        stderr: err_thread.join().unwrap(),
    }
}

/// What a run must do whatever it was given: end with a status (not a
/// signal, not a panic); on failure say why on stderr and leave `output`
/// (when it has one) unwritten. Returns whether it succeeded.
#[track_caller]
fn judge(dir: &Path, args: &[&str], output: Option<&str>) -> bool {
    if let Some(out) = output {
        let _ = std::fs::remove_file(dir.join(out));
    }
    let o = run(dir, args);
    let err = String::from_utf8_lossy(&o.stderr);
    let what = format!("`tcb {}` in {}", args.join(" "), dir.display());
    assert!(!err.contains("panicked"), "{what} panicked:\n{err}");
    let code = o
        .status
        .code()
        .unwrap_or_else(|| panic!("{what} ended by a signal: {:?}\n{err}", o.status));
    assert_ne!(code, 101, "{what} exited as a panic does:\n{err}");
    if !o.status.success() {
        assert!(!err.trim().is_empty(), "{what} failed without a message");
        if let Some(out) = output {
            assert!(
                !dir.join(out).exists(),
                "{what} failed ({}) but wrote {out}",
                err.trim()
            );
        }
    }
    o.status.success()
}

/// Every subcommand on `input` (a file in `dir` that `tcb info` read).
fn every_subcommand(dir: &Path, input: &str) {
    let sample = |extra: &[&str]| {
        let mut args = vec!["sample", input];
        args.extend_from_slice(extra);
        judge(dir, &args, None);
    };
    sample(&["--at", "0,-1e300,1e300,-0,5e-324,0.5"]);
    sample(&["--fps", "30", "--from", "-0.5", "--to", "1"]);
    sample(&["--inbetweens", "2", "--velocity"]);
    sample(&["--inbetweens", "1", "--scalar"]);
    judge(dir, &["info", input, "--quantize"], None);
    judge(dir, &["reduce", input, "-o", "r.json"], Some("r.json"));
    judge(dir, &["compress", input, "-o", "c.tcbc"], Some("c.tcbc"));
    judge(dir, &["export", input, "-o", "e.glb"], Some("e.glb"));
    judge(dir, &["plot", input, "-o", "p.svg"], Some("p.svg"));
    judge(
        dir,
        &["plot", input, "-o", "p.svg", "--path"],
        Some("p.svg"),
    );
    judge(
        dir,
        &["plot", input, "-o", "p.svg", "--speed"],
        Some("p.svg"),
    );
    judge(dir, &["view", input, "-o", "v.html"], Some("v.html"));
    judge(
        dir,
        &["bench", input, "--rounds", "1", "--slice-ms", "1"],
        None,
    );
}

/// The file names a corpus's inputs are given under: the reader of the
/// target's own input first, then every other reader.
fn names(target: &str) -> &'static [&'static str] {
    match target {
        "bvh" => &["in.bvh", "in.json", "in.gltf", "in.glb", "in.tcbc"],
        "gltf" => &["in.gltf", "in.glb", "in.json", "in.bvh", "in.tcbc"],
        "tcbc" => &["in.tcbc", "in.json", "in.bvh", "in.glb"],
        _ => &["in.json", "in.bvh", "in.gltf", "in.glb", "in.tcbc"],
    }
}

#[test]
fn every_corpus_input_under_every_reader_and_subcommand() {
    let corpora = root().join("fuzz/corpus");
    let mut targets: Vec<PathBuf> = std::fs::read_dir(&corpora)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    targets.sort();
    assert!(targets.len() >= 13, "the corpora are missing: {corpora:?}");
    let base = scratch("corpora");
    let (mut inputs, mut read) = (0, 0);
    for target in &targets {
        let name = target.file_name().unwrap().to_str().unwrap();
        let mut files: Vec<PathBuf> = std::fs::read_dir(target)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for file in files {
            let mut bytes = std::fs::read(&file).unwrap();
            // `roundtrip` reads its text after a first byte that chooses
            // between text and a structured clip.
            if name == "roundtrip" && bytes.first().is_some_and(|b| b % 2 == 0) {
                bytes.remove(0);
            }
            inputs += 1;
            // One folder per input: a glTF's buffers are looked up beside it.
            let dir = base.join(format!(
                "{name}-{}",
                file.file_name().unwrap().to_string_lossy()
            ));
            std::fs::create_dir_all(&dir).unwrap();
            for (i, as_name) in names(name).iter().enumerate() {
                std::fs::write(dir.join(as_name), &bytes).unwrap();
                let ok = judge(&dir, &["info", as_name], None);
                // Every subcommand on what a reader takes, under the
                // target's own file name.
                if ok && i == 0 {
                    read += 1;
                    every_subcommand(&dir, as_name);
                }
            }
        }
    }
    // The seeds of the readers' corpora are real clips: most of them read.
    assert!(inputs > 100 && read >= 15, "{inputs} inputs, {read} read");
    let _ = std::fs::remove_dir_all(&base);
}

/// Edge values for a numeric flag.
const EDGES: &[&str] = &[
    "0", "-0", "-1", "1e-320", "1e308", "inf", "-inf", "nan", "", "x", "1e999",
];

#[test]
fn every_numeric_flag_at_its_edges() {
    let dir = scratch("flags");
    let root = root();
    for (name, from) in [
        ("b.json", "examples/clips/bounce.json"),
        ("cmu.bvh", "fuzz/corpus/bvh/cmu-01_01-4-frames.bvh"),
    ] {
        std::fs::copy(root.join(from), dir.join(name)).unwrap();
    }
    assert!(judge(
        &dir,
        &["compress", "cmu.bvh", "-o", "cmu.tcbc"],
        Some("cmu.tcbc")
    ));
    // (the arguments before the edge value, `IN` for the input; the file
    // the run would write)
    let cases: &[(&str, Option<&str>)] = &[
        ("sample IN --at", None),
        ("sample IN --fps", None),
        ("sample IN --fps 10 --from", None),
        ("sample IN --fps 10 --to", None),
        ("sample IN --inbetweens", None),
        ("export IN -o o.glb --max-error", Some("o.glb")),
        ("reduce IN -o o.json --tolerance", Some("o.json")),
        ("reduce IN -o o.json --shell", Some("o.json")),
        (
            "reduce IN -o o.json --metric value --rotation-tolerance",
            Some("o.json"),
        ),
        ("reduce IN -o o.json --timing-ms", Some("o.json")),
        ("compress IN -o o.tcbc --tolerance", Some("o.tcbc")),
        ("compress IN -o o.tcbc --shell", Some("o.tcbc")),
        ("compress IN -o o.tcbc --seek-keys", Some("o.tcbc")),
        (
            "compress IN -o o.tcbc --metric value --rotation-tolerance",
            Some("o.tcbc"),
        ),
        ("bench IN --rounds 1 --slice-ms 1 --fps", None),
        ("bench IN --rounds 1 --slice-ms 1 --instances", None),
        ("bench IN --rounds 1 --slice-ms 1 --threads", None),
        ("bench IN --slice-ms 1 --rounds", None),
        ("bench IN --rounds 1 --slice-ms", None),
        ("plot IN -o o.svg --from", Some("o.svg")),
        ("plot IN -o o.svg --to", Some("o.svg")),
        ("plot IN -o o.svg --inbetweens", Some("o.svg")),
        ("plot IN -o o.svg --path --components", Some("o.svg")),
        ("plot IN -o o.svg --track", Some("o.svg")),
        ("view IN -o o.html --fps", Some("o.html")),
        ("view IN -o o.html --joint", Some("o.html")),
        ("info IN --animation", None),
    ];
    for input in ["b.json", "cmu.bvh", "cmu.tcbc"] {
        for (head, output) in cases {
            for edge in EDGES {
                let mut args: Vec<&str> = head
                    .split(' ')
                    .map(|a| if a == "IN" { input } else { a })
                    .collect();
                args.push(edge);
                judge(&dir, &args, *output);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
