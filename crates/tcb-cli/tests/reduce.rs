//! `tcb reduce` as a user runs it (`docs/reduce.md`): the summary line, a
//! result the other commands accept, and bad input that writes nothing.

mod common;

use common::{assert_success, file, scratch, short_cmu, stderr, stderr_has, stdout, tcb, tcb_to};
use std::path::{Path, PathBuf};
use std::process::Output;

/// This binary's scratch folder.
fn dir() -> PathBuf {
    scratch("reduce-test")
}

/// `tcb reduce INPUT -o OUT [EXTRA...]`, which must succeed.
fn reduce_ok(input: &Path, out: &Path, extra: &[&str]) -> Output {
    let o = tcb_to("reduce", input, out, extra);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    o
}

/// `reduced: tracks T, keys K0 -> K1, values V0 -> V1, bytes B0 -> B1,
/// max error e (METRIC, joint J, time t)`, its numbers.
/// `tcb reduce` of the first 240 frames of the CMU clip into `name` with
/// `extra`: the output file, the run, and the summary (shell metric).
fn reduce_short(name: &str, extra: &[&str]) -> (PathBuf, Output, [f64; 8]) {
    let out = dir().join(name);
    let o = reduce_ok(&short_cmu(240), &out, extra);
    let numbers = summary(&stdout(&o), "shell");
    (out, o, numbers)
}

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
    let (out, o, [tracks, k0, k1, v0, v1, b0, b1, e]) = reduce_short(
        "short.json",
        &["--tolerance", "0.05", "--speed", "fewest-bytes"],
    );
    let stdout = stdout(&o);
    assert_eq!(tracks, 32.0);
    assert_eq!(k0, 32.0 * 240.0);
    assert!(k1 < k0 && v1 < v0 && b1 < b0, "{stdout}");
    assert!(e <= 0.05, "{stdout}");
    assert!(!stderr(&o).contains("note:"), "{}", stderr(&o));
    stderr_has(&o, "metric shell, tolerance 5e-2");
    // Issue 33: input and output timed in one run, and their estimated cost.
    stderr_has(&o, "tcb: a quick timing (300 ms, one run");
    stderr_has(&o, "ns per joint per frame");
    stderr_has(&o, "tcb: estimated runtime cost: input ");
    assert_success(&tcb(&["sample", out.to_str().unwrap(), "--at", "0.5,1"]));
    assert_success(&tcb_to("export", &out, dir().join("short.glb"), &[]));
}

/// At the default tolerance the jittery capture keeps most keys. Fitted
/// onto key times of their own, such tracks play as loose lanes, which hold
/// about twice the bytes per key of the shared grid: before `tcb reduce`
/// put those tracks back on the input's grid, this clip compiled to more
/// bytes than its input (`bytes 314901 -> 326161` for a file of
/// these 240 frames; then `314901 -> 275069`, no note printed). The fits
/// save 13% of the bytes and would cost 64% more per frame, so by default
/// (`--speed balanced`) they go back on the grid: only the 4 constant
/// rotations keep 2 keys, in the grid's free lanes, and the clip plays and
/// compiles as its input does.
#[test]
fn a_reduction_keeping_most_keys_stays_on_the_grid() {
    let (_, o, [_, k0, k1, _, _, b0, b1, _]) = reduce_short("short-default.json", &[]);
    let stdout = stdout(&o);
    assert!(k1 < k0 && b1 == b0, "{stdout}");
    assert!(!stderr(&o).contains("more bytes"), "{}", stderr(&o));
    stderr_has(&o, "output 1084 instructions per frame (1.00x)");
    stderr_has(&o, "(with --speed fewest-bytes: kept)");
    let (_, o, [.., b1, _]) = reduce_short("short-default.json", &["--speed", "fewest-bytes"]);
    assert!(b1 < b0, "{}", common::stdout(&o));
    stderr_has(&o, ": slower; ");
}

/// Where the reduction still compiles larger (at a tenth of the default
/// tolerance only a few nearly constant tracks are fitted: the grid keeps
/// its blocks of 8 and a block of loose lanes is added), `tcb reduce` says
/// so on stderr; the summary line is the contract's.
#[test]
fn a_reduction_that_compiles_larger_says_so() {
    let (_, o, [_, _, _, _, _, b0, b1, _]) = reduce_short(
        "short-tight.json",
        &[
            "--tolerance",
            "1.087e-4",
            "--timing-ms",
            "0",
            "--speed",
            "fewest-bytes",
        ],
    );
    let stdout = stdout(&o);
    assert!(b1 > b0, "{stdout}");
    assert!(!stderr(&o).contains("quick timing"), "{}", stderr(&o));
    let note = format!("compiles to more bytes than the input ({b1} against {b0})");
    stderr_has(&o, &note);
}

/// `tcb sample --at` of `clip` at `times`: one row of numbers per time.
fn sample_at(clip: &Path, times: &[f64]) -> Vec<Vec<f64>> {
    sample_with(clip, times, &[])
}

/// `tcb sample CLIP --at TIMES EXTRA...`: the rows without their time.
fn sample_with(clip: &Path, times: &[f64], extra: &[&str]) -> Vec<Vec<f64>> {
    let at: Vec<String> = times.iter().map(|t| t.to_string()).collect();
    let at = at.join(",");
    let mut args = vec!["sample", clip.to_str().unwrap(), "--at", &at];
    args.extend(extra);
    let o = tcb(&args);
    assert_success(&o);
    stdout(&o)
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(1).map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn a_clip_without_skeleton_reduces_by_value() {
    // A dense smooth clip: 241 keys at 120 fps of a scalar and a rotation.
    let n = 241;
    let times: Vec<f64> = (0..n).map(|i| i as f64 / 120.0).collect();
    let list =
        |f: &dyn Fn(f64) -> String| times.iter().map(|&t| f(t)).collect::<Vec<_>>().join(", ");
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [
          {{"name": "x", "kind": "scalar", "times": [{t}], "values": [{x}]}},
          {{"name": "r", "kind": "quat", "times": [{t}], "values": [{q}], "rotation": "hermite"}}]}}"#,
        t = list(&|t| t.to_string()),
        x = list(&|t| (3.0 * t).sin().to_string()),
        q = list(&|t| format!("[0, {}, 0, {}]", (0.4 * t).sin(), (0.4 * t).cos())),
    );
    let input = dir().join("dense-smooth.json");
    std::fs::write(&input, text).unwrap();
    let out = dir().join("dense-smooth-reduced.json");
    // Both tracks share one grid, one group of two blocks; reduced, each
    // plays as a loose lane, a block of its own: 766 instructions a frame
    // against 634 (callgrind), so with --never-slower the input comes back.
    let o = reduce_ok(&input, &out, &["--never-slower"]);
    let [_, k0, k1, v0, v1, b0, b1, _] = summary(&stdout(&o), "value");
    assert!(k1 == k0 && v1 == v0 && b1 == b0, "{}", stdout(&o));
    stderr_has(&o, "(with --speed fewest-bytes: kept)");
    // By default the fewest bytes, and the slowdown said.
    let o = reduce_ok(&input, &out, &[]);
    stderr_has(&o, ": slower; ");
    stderr_has(
        &o,
        "metric value, tolerance 1e-4, rotation tolerance 0.01 degrees",
    );
    let stdout = stdout(&o);
    let [_, k0, k1, v0, v1, ..] = summary(&stdout, "value");
    assert!(k1 < k0 / 4.0 && v1 < v0 / 4.0, "{stdout}");
    // Measured here, by sampling both files at every key time and 3
    // inbetweens, as the contract checks.
    let mut check = Vec::new();
    for w in times.windows(2) {
        check.extend((0..4).map(|j| w[0] + (w[1] - w[0]) * j as f64 / 4.0));
    }
    check.push(times[n - 1]);
    for chunk in check.chunks(200) {
        let (a, b) = (sample_at(&input, chunk), sample_at(&out, chunk));
        for (ra, rb) in a.iter().zip(&b) {
            assert!((ra[0] - rb[0]).abs() <= 1e-4, "{ra:?} {rb:?}");
            // The rotation angle between them from the chord of the unit
            // quaternions, |a - b| = 2 sin(angle / 4) (well conditioned).
            let unit = |r: &[f64]| {
                let l = r.iter().map(|x| x * x).sum::<f64>().sqrt();
                r.iter().map(|x| x / l).collect::<Vec<_>>()
            };
            let (qa, qb) = (unit(&ra[1..5]), unit(&rb[1..5]));
            let chord = qa
                .iter()
                .zip(&qb)
                .map(|(x, y)| (x - y).powi(2))
                .sum::<f64>()
                .sqrt();
            let angle = 4.0 * (chord / 2.0).asin().to_degrees();
            assert!(angle <= 0.01, "{angle}: {ra:?} {rb:?}");
        }
    }
}

#[test]
fn bad_input_is_a_clear_error_and_writes_nothing() {
    let out = dir().join("never.json");
    let empty = dir().join("empty.json");
    std::fs::write(&empty, "").unwrap();
    let empty_bvh = dir().join("empty.bvh");
    std::fs::write(&empty_bvh, "").unwrap();
    let bounce = file("examples/clips/bounce.json");
    let bvh = file("data/cmu-01_01.bvh");
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
        let o = tcb_to("reduce", args[0], &out, &args[1..]);
        assert!(!o.status.success(), "{args:?}");
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{args:?}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    let o = tcb_to("reduce", &bounce, dir().join("x.csv"), &[]);
    stderr_has(&o, "the output must end in .json");
    let o = tcb_to("reduce", &bounce, "/nonexistent-tcb-dir/x.json", &[]);
    stderr_has(&o, "/nonexistent-tcb-dir: no such directory");
    // A file where the output's folder should be.
    let o = tcb_to("reduce", &bounce, format!("{bounce}/x.json"), &[]);
    stderr_has(&o, "bounce.json: not a directory");
}

#[test]
fn an_imported_clip_keeps_its_skeleton_and_reduces_by_shell() {
    let bvh = short_cmu(120);
    let json = dir().join("short-import.json");
    let o = tcb_to("import", &bvh, &json, &[]);
    assert_success(&o);
    let from_bvh = tcb_io::load(&bvh).unwrap().skeleton.unwrap();
    let from_json = tcb_io::load(&json).unwrap().skeleton.unwrap();
    assert_eq!(from_json, from_bvh);
    assert!(from_json.joint("Head_end").is_some());
    let out = dir().join("short-import-reduced.json");
    let o = reduce_ok(&json, &out, &["--tolerance", "0.05"]);
    let stdout = stdout(&o);
    let [.., e] = summary(&stdout, "shell");
    assert!(e <= 0.05, "{stdout}");
    // The reduced clip carries the rig on.
    assert_eq!(tcb_io::load(&out).unwrap().skeleton.unwrap(), from_bvh);
}

/// docs/reduce.md: "a constant track becomes 2 keys", even where putting
/// its keys back on the grid the other tracks share would compile smaller
/// (here 8 jittery tracks keep all their keys on that grid, and the
/// constant one alone on key times of its own costs a loose block).
#[test]
fn a_constant_track_becomes_two_keys_even_beside_a_kept_grid() {
    let times = "0, 0.1, 0.2, 0.3, 0.4, 0.5";
    let mut tracks: Vec<String> = (0..8)
        .map(|i| {
            let values: Vec<String> = (0..6)
                .map(|k| format!("{}", ((i * 7 + k * 13) % 11) as f64 * 0.37 - 1.0))
                .collect();
            format!(
                r#"{{"name": "j{i}", "kind": "scalar", "times": [{times}], "values": [{}]}}"#,
                values.join(", ")
            )
        })
        .collect();
    tracks.push(format!(
        r#"{{"name": "c", "kind": "scalar", "times": [{times}], "values": [0.25, 0.25, 0.25, 0.25, 0.25, 0.25]}}"#
    ));
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",\n")
    );
    let input = dir().join("constant-beside-grid.json");
    std::fs::write(&input, text).unwrap();
    let out = dir().join("constant-beside-grid-reduced.json");
    reduce_ok(&input, &out, &[]);
    let written = tcb_io::read_clip_doc(&out).unwrap();
    let c = written.tracks.iter().find(|t| t.name == "c").unwrap();
    assert_eq!(c.times.len(), 2, "{:?}", c.times);
}

/// `tcb compress` (docs/tcbc.md): the first 240 frames of the CMU clip
/// packed within a shell tolerance; the summary line; the `.tcbc` plays
/// (runtime and `--scalar` agree), `info` and `bench` read it.
#[test]
fn compresses_a_bvh_within_the_tolerance_and_the_file_plays() {
    let input = short_cmu(240);
    let out = dir().join("short.tcbc");
    let o = tcb_to("compress", &input, &out, &["--tolerance", "0.002"]);
    assert_success(&o);
    let stdout = stdout(&o);
    let line = stdout.lines().last().unwrap();
    let rest = line
        .strip_prefix("compressed: tracks 32, keys 240, values ")
        .expect(line);
    let (_, tail) = rest.split_once(" bits per value, max error ").expect(line);
    let (error, place) = tail.split_once(" (shell, joint ").expect(line);
    let error: f64 = error.parse().expect(line);
    assert!(error > 0.0 && error <= 0.002, "{line}");
    assert!(place.contains(", time "), "{line}");
    let bytes = std::fs::metadata(&out).unwrap().len();
    assert!(line.contains(&format!("bytes {bytes},")), "{line}: {bytes}");
    // The f32 clip of 240 frames takes far more.
    assert!(bytes < 32 * 240 * 4, "{bytes}");
    let times = [0.0, 0.3, 0.51, 1.0, 1.99];
    let runtime = sample_at(&out, &times);
    let reference = sample_with(&out, &times, &["--scalar"]);
    assert_eq!(runtime.len(), times.len());
    for (a, b) in runtime.iter().zip(&reference) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{a:?} {b:?}");
        }
    }
    let o = tcb(&["info", out.to_str().unwrap()]);
    assert_success(&o);
    let info = common::stdout(&o);
    assert!(
        info.contains("bits per value") && info.contains("made by: tcb compress"),
        "{info}"
    );
    let o = tcb(&["bench", out.to_str().unwrap(), "--rounds", "1"]);
    assert_success(&o);
}

/// `tcb reduce` then `tcb compress` (issue 28's composition): the reduced
/// clip's tracks on key times of their own keep them (`info` counts them),
/// the file is within the tolerance of the reduced clip by its own
/// measurement, and runtime and `--scalar` agree on it.
#[test]
fn a_reduced_clip_compresses_with_its_own_key_times() {
    let (reduced, _, _) = reduce_short(
        "composed.json",
        &["--rotation", "hermite", "--speed", "fewest-bytes"],
    );
    let out = dir().join("composed.tcbc");
    let o = tcb_to("compress", &reduced, &out, &["--tolerance", "0.002"]);
    assert_success(&o);
    let line = stdout(&o).lines().last().unwrap().to_string();
    let error: f64 = line
        .split_once(" max error ")
        .and_then(|(_, t)| t.split_once(' '))
        .expect(&line)
        .0
        .parse()
        .expect(&line);
    assert!(
        line.starts_with("compressed: tracks 32, keys 240,") && error <= 0.002,
        "{line}"
    );
    let o = tcb(&["info", out.to_str().unwrap()]);
    assert_success(&o);
    let info = common::stdout(&o);
    let own = info
        .split_once(" tracks (")
        .and_then(|(_, t)| t.split_once(' '))
        .expect(&info)
        .0;
    assert!(own.parse::<usize>().expect(&info) > 0, "{info}");
    let times = [0.0, 0.3, 0.51, 1.0, 1.99];
    let runtime = sample_at(&out, &times);
    let reference = sample_with(&out, &times, &["--scalar"]);
    for (a, b) in runtime.iter().zip(&reference) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{a:?} {b:?}");
        }
    }
}

/// Bad requests and files: one line on stderr, exit 1, nothing written.
#[test]
fn bad_compress_input_is_a_clear_error_and_writes_nothing() {
    let input = short_cmu(40);
    let input = input.to_str().unwrap();
    let out = dir().join("never.tcbc");
    let uneven = file("examples/clips/bounce.json");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![input, "-o", "x.json"], "must end in .tcbc"),
        (
            vec![input, "-o", out.to_str().unwrap(), "--seek-keys", "17"],
            "a multiple of 32",
        ),
        (
            vec![input, "-o", out.to_str().unwrap(), "--tolerance", "-1"],
            "--tolerance",
        ),
        (vec![&uneven, "-o", out.to_str().unwrap()], "even grid"),
        (
            vec!["x.tcbc", "-o", out.to_str().unwrap()],
            "already packed",
        ),
        (
            vec![input, "-o", out.to_str().unwrap(), "--tolerance", "1e-12"],
            "error:",
        ),
    ];
    for (args, want) in cases {
        let mut all = vec!["compress"];
        all.extend(&args);
        let o = tcb(&all);
        let e = stderr(&o);
        assert!(!o.status.success(), "{args:?}");
        assert!(e.contains(want), "{args:?}: {e}");
        assert_eq!(e.lines().filter(|l| l.contains("error")).count(), 1, "{e}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    // A damaged .tcbc: one line, from sample and info alike.
    let good = dir().join("good.tcbc");
    let o = tcb_to("compress", input, &good, &["--tolerance", "0.01"]);
    assert_success(&o);
    let mut bytes = std::fs::read(&good).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 1;
    let bad = dir().join("bad.tcbc");
    std::fs::write(&bad, &bytes).unwrap();
    let o = tcb(&["info", "missing.tcbc"]);
    stderr_has(&o, "missing.tcbc: ");
    for args in [vec!["sample", "--at", "0"], vec!["info"]] {
        let mut all = args.clone();
        all.insert(1, bad.to_str().unwrap());
        let o = tcb(&all);
        assert!(!o.status.success());
        stderr_has(&o, "checksum mismatch");
    }
}
