//! The `tcb` command as a user runs it: output format, options, and every
//! bad input of the clip-format contract.

mod common;

use common::{assert_success, file, scratch, stderr, stderr_has, stdout, tcb, tcb_to};
use std::path::PathBuf;

/// The bundled example clips' folder.
fn examples() -> PathBuf {
    common::root().join("examples/clips")
}

/// A bundled example clip, as an argument.
fn example(name: &str) -> String {
    file(&format!("examples/clips/{name}"))
}

/// `text` written to `name` in this binary's scratch folder.
fn temp_clip(name: &str, text: &str) -> PathBuf {
    let path = scratch("cli-test").join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A one-track clip around `track` (a JSON object body), with `defaults`.
fn clip_with(defaults: &str, track: &str) -> String {
    format!(
        r#"{{"format": "tcb-clip/1", "name": "t", "defaults": {{{defaults}}}, "tracks": [
            {{"name": "ok", "kind": "scalar", "times": [0, 1], "values": [0, 1]}},
            {{"name": "bad", {track}}}]}}"#
    )
}

#[test]
fn header_and_columns_follow_the_contract() {
    let o = tcb(&["sample", &example("bounce.json"), "--at", "0,0.25,1.5"]);
    assert_success(&o);
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[0],
        "time,ball.position.x,ball.position.y,ball.position.z,ball.squash,\
         ball.rotation.x,ball.rotation.y,ball.rotation.z,ball.rotation.w"
    );
    assert_eq!(lines.len(), 4);
    assert_eq!(lines[1], "0,0,0,0,1,0,0,0,1");
    assert!(lines[3].starts_with("1.5,"));
    assert!(o.stderr.is_empty());
}

#[test]
fn velocity_columns_follow_the_value_columns() {
    let o = tcb(&[
        "sample",
        &example("bounce.json"),
        "--at",
        "0.25",
        "--velocity",
    ]);
    assert!(o.status.success());
    let out = stdout(&o);
    let header: Vec<&str> = out.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 1 + 2 * 8);
    assert_eq!(header[9], "ball.position.x.d");
    assert_eq!(header[12], "ball.squash.d");
    // ball.squash goes from 1 to 0.6 over 1.25 s, copy ends: a straight line.
    let row: Vec<f32> = out
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert!((row[12] - (-0.32)).abs() < 1e-6);
}

#[test]
fn fps_grid_includes_the_end_when_on_it() {
    let o = tcb(&["sample", &example("bounce.json"), "--fps", "4"]);
    let out = stdout(&o);
    let times: Vec<&str> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(
        times,
        ["0", "0.25", "0.5", "0.75", "1", "1.25", "1.5", "1.75", "2"]
    );
    let o = tcb(&[
        "sample",
        &example("bounce.json"),
        "--fps",
        "2",
        "--from",
        "-1",
        "--to",
        "0.9",
    ]);
    let out = stdout(&o);
    let times: Vec<&str> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(times, ["-1", "-0.5", "0", "0.5"]);
}

#[test]
fn inbetweens_use_the_union_of_key_times() {
    // bounce: keys at 0, 0.5, 1.25, 2 (and 0, 1.25): one inbetween each.
    let o = tcb(&["sample", &example("bounce.json"), "--inbetweens", "1"]);
    let out = stdout(&o);
    let times: Vec<&str> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(times, ["0", "0.25", "0.5", "0.875", "1.25", "1.625", "2"]);
}

#[test]
fn negative_huge_and_non_finite_times_work_as_written() {
    let o = tcb(&[
        "sample",
        &example("spin.json"),
        "--at",
        "-2.5,0,1e6,nan,inf,-inf,1e300",
    ]);
    assert_success(&o);
    assert_eq!(stdout(&o).lines().count(), 8);
    // spin repeats with period 2: 1e6 is a whole number of periods.
    let rows: Vec<String> = stdout(&o).lines().map(str::to_owned).collect();
    assert_eq!(
        rows[2].split_once(',').unwrap().1,
        rows[3].split_once(',').unwrap().1
    );
}

#[test]
fn scalar_flag_gives_the_same_numbers() {
    // Vector channels are bit-identical between the runtime and the reference.
    let a = tcb(&[
        "sample",
        &example("careen.json"),
        "--fps",
        "30",
        "--velocity",
    ]);
    let b = tcb(&[
        "sample",
        &example("careen.json"),
        "--fps",
        "30",
        "--velocity",
        "--scalar",
    ]);
    assert!(a.status.success() && b.status.success());
    assert_eq!(stdout(&a), stdout(&b));
    // Rotations agree to ~1e-6.
    let a = tcb(&["sample", &example("spin.json"), "--fps", "30"]);
    let b = tcb(&["sample", &example("spin.json"), "--fps", "30", "--scalar"]);
    for (la, lb) in stdout(&a).lines().zip(stdout(&b).lines()).skip(1) {
        for (x, y) in la.split(',').zip(lb.split(',')) {
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            assert!((x - y).abs() <= 1e-6, "{la}\n{lb}");
        }
    }
}

/// The contract's check (`tools/check/check.py`): every value and velocity
/// of the runtime's `tcb sample --velocity` within 1e-5 of the reference's
/// (relative, absolute below 1), here on dense squad motion capture, where
/// the cubic a game loop plays for squad is 1.5e-4 off in a velocity
/// component (`CompileOptions::exact_velocities`).
#[test]
fn sampled_squad_velocities_are_the_references() {
    let at = "0.1,1.2345,2.277074225,6.4833333,10.73125,14.752083";
    let run = |scalar: bool| {
        let mut args = vec!["sample", "--at", at, "--velocity"];
        let bvh = data("cmu-01_01.bvh");
        args.insert(1, &bvh);
        if scalar {
            args.push("--scalar");
        }
        let o = tcb(&args);
        assert_success(&o);
        stdout(&o)
    };
    let (a, b) = (run(false), run(true));
    assert_eq!(a.lines().next(), b.lines().next());
    let mut worst: f64 = 0.0;
    for (la, lb) in a.lines().zip(b.lines()).skip(1) {
        for (x, y) in la.split(',').zip(lb.split(',')) {
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            worst = worst.max((x - y).abs() / y.abs().max(1.0));
        }
    }
    assert!(worst <= 1e-5, "worst relative difference {worst}");
}

#[test]
fn usage_errors() {
    for args in [
        vec!["sample", "x.json"],
        vec!["sample", "x.json", "--at", "0", "--fps", "3"],
    ] {
        let o = tcb(&args);
        assert!(!o.status.success());
        assert!(o.stdout.is_empty());
    }
    let clip = example("bounce.json");
    for (args, message) in [
        (vec!["--at", "0,x"], "--at: \"x\" is not a number"),
        (vec!["--fps", "0"], "--fps must be a positive number"),
        (vec!["--fps", "-3"], "--fps must be a positive number"),
        (
            vec!["--fps", "30", "--from", "2", "--to", "1"],
            "is before --from",
        ),
        (
            vec!["--at", "0", "--from", "1"],
            "--from and --to go with --fps",
        ),
        (
            vec!["--fps", "1e12", "--to", "1e6"],
            "sample times requested",
        ),
        // Too many to count in 64 bits: said so, not as 2^64 - 1 of them.
        (
            vec!["--fps", "1e300"],
            "--fps 1e300 over 0 to 2 s asks for more than 100000000 sample times",
        ),
    ] {
        let mut all = vec!["sample", clip.as_str()];
        all.extend(args);
        let o = tcb(&all);
        assert!(!o.status.success(), "{all:?}");
        assert!(o.stdout.is_empty(), "{all:?}");
        assert!(stderr(&o).contains(message), "{all:?}: {}", stderr(&o));
    }
}

#[test]
fn every_bad_input_is_one_clear_line_and_no_csv() {
    // Kept whole: a case table, one row per bad input and the line it must print.
    let q = r#""kind": "quat", "times": [0, 1, 2], "values": [[0,0,0,1],[0,0,0.5,0.8660254],[0,0,0,1]]"#;
    let cases: Vec<(&str, String, &str, &str)> = vec![
        (
            "few keys",
            clip_with("", r#""kind": "scalar", "times": [0], "values": [1]"#),
            "track 'bad'",
            "at least 2",
        ),
        (
            "times not increasing",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1, 1], "values": [1, 2, 3]"#,
            ),
            "track 'bad': key 2",
            "not after",
        ),
        (
            "lengths disagree",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1, 2], "values": [1, 2]"#,
            ),
            "track 'bad'",
            "2 values for 3 times",
        ),
        (
            "keys length",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{}]"#,
            ),
            "track 'bad'",
            "1 keys for 2 times",
        ),
        (
            "wrong shape",
            clip_with(
                "",
                r#""kind": "vec3", "times": [0, 1], "values": [[1, 2, 3], [1, 2]]"#,
            ),
            "track 'bad': key 1",
            "must have 3 numbers",
        ),
        (
            "scalar given an array",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [[1], 2]"#,
            ),
            "track 'bad': key 0",
            "must be a number",
        ),
        (
            "non-finite value",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 1e999]"#,
            ),
            "track 'bad': key 1",
            "not a finite",
        ),
        (
            "value beyond f32",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 1e300]"#,
            ),
            "track 'bad': key 1",
            "not a finite f32",
        ),
        (
            "non-finite time",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1e999], "values": [1, 2]"#,
            ),
            "track 'bad': key 1",
            "not a finite",
        ),
        (
            "non-finite tcb",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{}, {"tcb": [0, 1e999, 0]}]"#,
            ),
            "track 'bad': key 1",
            "tcb",
        ),
        (
            "unknown rule",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "tangent_rule": "catmull""#,
            ),
            "track 'bad'",
            "unknown tangent_rule \"catmull\"",
        ),
        (
            "unknown interp",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{"interp": "cubic"}, {}]"#,
            ),
            "track 'bad': key 0",
            "unknown interp",
        ),
        (
            "unknown kind",
            clip_with("", r#""kind": "vec5", "times": [0, 1], "values": [1, 2]"#),
            "track 'bad'",
            "unknown kind",
        ),
        (
            "unknown default",
            clip_with(
                r#""ends": "open""#,
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2]"#,
            ),
            "",
            "unknown ends",
        ),
        (
            "unknown field",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "tension": 1"#,
            ),
            "track 'bad'",
            "unknown field \"tension\"",
        ),
        (
            "zero quaternion",
            clip_with(
                "",
                r#""kind": "quat", "times": [0, 1], "values": [[0,0,0,1],[0,0,0,0]]"#,
            ),
            "track 'bad': key 1",
            "zero length",
        ),
        (
            "cyclic not closed",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1, 2], "values": [1, 2, 3], "ends": "cyclic""#,
            ),
            "track 'bad': key 2",
            "cyclic",
        ),
        (
            "cyclic rotation not closed",
            clip_with(
                "",
                &format!(
                    r#"{}, "ends": "cyclic""#,
                    q.replace("[0,0,0,1]]", "[0,0,1,0]]")
                ),
            ),
            "track 'bad': key 2",
            "cyclic",
        ),
        (
            "cyclic rotation closed up to sign is fine",
            clip_with(
                "",
                &format!(
                    r#"{}, "ends": "cyclic""#,
                    q.replace("[0,0,0,1]]", "[0,0,0,-1]]")
                ),
            ),
            "",
            "",
        ),
        (
            "natural on squad",
            clip_with("", &format!(r#"{q}, "ends": "natural""#)),
            "track 'bad'",
            "natural",
        ),
        (
            "linear on rotation",
            clip_with("", &format!(r#"{q}, "post": "linear""#)),
            "track 'bad'",
            "post \"linear\"",
        ),
        (
            "offset-repeat on rotation",
            clip_with(r#""pre": "offset-repeat""#, q),
            "track 'bad'",
            "pre \"offset-repeat\"",
        ),
        (
            "ease out of range",
            clip_with(
                "",
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{"ease": [0, -0.5]}, {}]"#,
            ),
            "track 'bad': key 0",
            "ease",
        ),
        (
            "missing format",
            r#"{"tracks": []}"#.to_owned(),
            "",
            "format",
        ),
        (
            "not json",
            r#"{"format": "tcb-clip/1", "tracks": [}"#.to_owned(),
            "",
            "line 1",
        ),
        (
            "duplicate names",
            r#"{"format": "tcb-clip/1", "tracks": [
                {"name": "a", "kind": "scalar", "times": [0, 1], "values": [0, 1]},
                {"name": "a", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#
                .to_owned(),
            "track 'a'",
            "already used",
        ),
    ];
    for (what, text, location, message) in cases {
        let path = temp_clip(&format!("{}.json", what.replace(' ', "_")), &text);
        let o = tcb(&["sample", path.to_str().unwrap(), "--fps", "10"]);
        let err = stderr(&o);
        if message.is_empty() {
            assert!(o.status.success(), "{what}: {err}");
            continue;
        }
        assert!(!o.status.success(), "{what}: accepted");
        assert!(o.stdout.is_empty(), "{what}: wrote {}", stdout(&o));
        assert_eq!(err.lines().count(), 1, "{what}: {err}");
        assert!(
            err.contains(path.file_name().unwrap().to_str().unwrap()),
            "{what}: no file name: {err}"
        );
        assert!(
            err.contains(location),
            "{what}: expected {location:?} in {err}"
        );
        assert!(
            err.contains(message),
            "{what}: expected {message:?} in {err}"
        );
    }
}

/// The commands that play `.tcbc` too name it among the types they read,
/// and say so of a directory.
#[test]
fn unknown_inputs_name_every_type_the_command_reads() {
    let dir = scratch("cli-unknown-input");
    let txt = dir.join("notes.txt");
    std::fs::write(&txt, "not a clip").unwrap();
    let folder = dir.join("clips");
    std::fs::create_dir_all(&folder).unwrap();
    let svg = dir.join("never.svg");
    for args in [
        vec!["sample", txt.to_str().unwrap(), "--at", "1"],
        vec!["info", txt.to_str().unwrap()],
        vec!["plot", txt.to_str().unwrap(), "-o", svg.to_str().unwrap()],
    ] {
        let o = tcb(&args);
        assert!(!o.status.success(), "{args:?}: accepted");
        stderr_has(
            &o,
            "notes.txt: unknown file type '.txt' (expected .json, .bvh, .gltf, .glb or .tcbc)",
        );
        assert_eq!(stderr(&o).lines().count(), 1, "{args:?}");
    }
    let o = tcb(&["sample", folder.to_str().unwrap(), "--at", "1"]);
    stderr_has(&o, "clips: a directory, not a clip file");
    assert!(!svg.exists());
}

/// A name with a line break and a terminal escape in it (JSON allows
/// both) is printed escaped: the error stays one line, and the terminal is
/// not told anything.
#[test]
fn control_characters_in_names_are_escaped_in_errors() {
    let text = r#"{"format": "tcb-clip/1", "name": "t", "tracks": [
        {"name": "bad\nname\u001b[31m", "kind": "scalar", "times": [0], "values": [1]}]}"#;
    let path = temp_clip("control_name.json", text);
    let o = tcb(&["sample", path.to_str().unwrap(), "--fps", "10"]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains('\u{1b}'), "{err:?}");
    assert!(err.contains(r"bad\nname\u{1b}[31m"), "{err}");
}

/// Random bytes named `.bvh` or `.glb` are "not a BVH file" or "not a glTF
/// file", one line, rather than a UTF-8 or JSON parser's wording.
#[test]
fn random_bytes_are_not_a_bvh_or_gltf_file() {
    let dir = scratch("cli-not-a-clip");
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let noise: Vec<u8> = (0..512)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect();
    for (name, message) in [
        ("x.bvh", "x.bvh: not a BVH file: not text (byte 0x"),
        (
            "x.glb",
            "x.glb: not a glTF file: neither binary glTF (no \"glTF\" magic) nor glTF JSON",
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, &noise).unwrap();
        let o = tcb(&["sample", path.to_str().unwrap(), "--fps", "10"]);
        assert!(!o.status.success(), "{name}: accepted");
        assert!(o.stdout.is_empty(), "{name}: wrote {}", stdout(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{name}: {}", stderr(&o));
        stderr_has(&o, message);
    }
}

#[test]
fn tcb_beyond_one_is_allowed() {
    let text = clip_with(
        "",
        r#""kind": "scalar", "times": [0, 1, 2], "values": [1, 2, 0], "keys": [{}, {"tcb": [-2, 1.5, 3]}, {}]"#,
    );
    let path = temp_clip("beyond.json", &text);
    let o = tcb(&["sample", path.to_str().unwrap(), "--at", "0.5,1.5"]);
    assert_success(&o);
}

/// A file of the repository's `data/`, as an argument.
fn data(name: &str) -> String {
    file(&format!("data/{name}"))
}

#[test]
fn import_and_export_round_trip_through_the_command() {
    let dir = scratch("cli-test");
    let clip = dir.join("skin.json");
    let o = tcb_to("import", data("simple_skin.gltf"), &clip, &[]);
    assert_success(&o);
    stderr_has(&o, "1 tracks, 12 keys");
    let glb = dir.join("skin.glb");
    let o = tcb_to("export", &clip, &glb, &[]);
    assert_success(&o);
    // LINEAR slerp goes back as LINEAR, exactly.
    stderr_has(&o, "1 exact, 0 resampled");
    let a = tcb(&["sample", clip.to_str().unwrap(), "--fps", "7"]);
    let b = tcb(&["sample", glb.to_str().unwrap(), "--fps", "7"]);
    for (x, y) in stdout(&a).lines().zip(stdout(&b).lines()).skip(1) {
        for (u, v) in x.split(',').zip(y.split(',')).skip(1) {
            let (u, v): (f32, f32) = (u.parse().unwrap(), v.parse().unwrap());
            assert!((u - v).abs() < 2e-5, "{x} vs {y}");
        }
    }
}

#[test]
fn import_and_export_errors_write_nothing() {
    let dir = scratch("cli-test");
    let out = dir.join("never.json");
    let bad = temp_clip(
        "cut.bvh",
        "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Xrotation Yrotation Zrotation\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n1 2 3\n4 5\n",
    );
    let o = tcb_to("import", &bad, &out, &[]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).ends_with(
            "cut.bvh: line 11: frame 1 has 2 values, expected 3 (truncated or malformed row)\n"
        ),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = tcb_to(
        "import",
        data("simple_skin.gltf"),
        &out,
        &["--rotation", "hermite"],
    );
    stderr_has(&o, "--rotation is for BVH files");
    let o = tcb_to(
        "import",
        data("simple_skin.gltf"),
        &out,
        &["--animation", "walk"],
    );
    stderr_has(&o, "no animation 'walk' (the file has: 0)");
    assert!(!out.exists());
    let glb = dir.join("never.glb");
    let o = tcb_to("export", example("bounce.json"), &glb, &[]);
    stderr_has(&o, "track 'ball.position' (vec3) has no glTF target");
    assert!(!glb.exists());
    let o = tcb_to("export", example("bounce.json"), dir.join("x.fbx"), &[]);
    stderr_has(&o, "must end in .glb or .gltf");
    // A clip file is JSON: written under another name it would not load
    // back as what its name says.
    let bvh = dir.join("never.bvh");
    let o = tcb_to("import", data("simple_skin.gltf"), &bvh, &[]);
    stderr_has(&o, "never.bvh: the output must end in .json");
    assert!(!bvh.exists());
}

/// An error above `--max-error` that the f32 key times' note names is
/// warned of once, not again as the read-back's error (the same number
/// twice read as two problems), and in a few digits.
#[test]
fn export_warns_of_one_error_once() {
    let dir = scratch("cli-test");
    let glb = dir.join("cmu-once.glb");
    let o = tcb_to("export", data("cmu-01_01.bvh"), &glb, &[]);
    assert_success(&o);
    let err = stderr(&o);
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(warnings[0].contains("glTF's f32 key times"), "{err}");
    // 4 significant digits, not 17.
    let digits = |w: &str| {
        w.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
            .filter(|x| x.contains('e') && x.contains('.'))
            .map(|x| x.split('e').next().unwrap_or("").len())
            .max()
            .unwrap_or(0)
    };
    assert!(digits(&err) <= 6, "{err}");
}

#[test]
fn export_renames_tracks_and_prints_one_summary_line() {
    let dir = scratch("cli-test");
    let glb = dir.join("bounce-renamed.glb");
    // Refused without renames, with the way out in the message.
    let o = tcb_to("export", example("bounce.json"), &glb, &[]);
    assert!(!o.status.success());
    stderr_has(&o, "--rename 'ball.position=ball.translation'");
    assert!(!glb.exists());
    let o = tcb_to(
        "export",
        example("bounce.json"),
        &glb,
        &[
            "--rename",
            "ball.position=ball.translation",
            "--rename",
            "ball.squash=ball.weights.0",
        ],
    );
    assert_success(&o);
    let err = stderr(&o);
    let wrote: Vec<&str> = err.lines().filter(|l| l.contains("wrote")).collect();
    assert_eq!(wrote.len(), 1, "{err}");
    assert!(
        wrote[0].contains("3 tracks, 1 exact, 2 resampled (max error"),
        "{err}"
    );
    assert!(!err.contains("tcb: resampled"), "{err}");
    // The morph weight comes back under its new name.
    let o = tcb(&["sample", glb.to_str().unwrap(), "--at", "0.5"]);
    assert_success(&o);
    assert!(
        stdout(&o).starts_with("time,ball.translation.x"),
        "{}",
        stdout(&o)
    );
    assert!(stdout(&o).contains("ball.weights.0"), "{}", stdout(&o));
    for bad in ["nope=x", "ball.position", "=x"] {
        let o = tcb_to(
            "export",
            example("bounce.json"),
            dir.join("never2.glb"),
            &["--rename", bad],
        );
        assert!(!o.status.success(), "{bad}");
        assert!(stderr(&o).contains("--rename"), "{bad}: {}", stderr(&o));
    }
    assert!(!dir.join("never2.glb").exists());
}

#[test]
fn plot_draws_every_bundled_file_and_refuses_bad_arguments() {
    let dir = scratch("cli-test");
    let out = dir.join("plot.svg");
    let mut inputs: Vec<String> = std::fs::read_dir(examples())
        .unwrap()
        .map(|e| e.unwrap().path().to_string_lossy().into_owned())
        .filter(|p| p.ends_with(".json"))
        .collect();
    inputs.sort();
    inputs.push(data("cmu-01_01.bvh"));
    inputs.push(data("simple_skin.gltf"));
    for input in &inputs {
        for extra in [&[][..], &["--velocity"], &["--speed"]] {
            let _ = std::fs::remove_file(&out);
            // Any clip, any kind of track: each kind gets a panel.
            let o = tcb_to("plot", input, &out, extra);
            assert!(o.status.success(), "{input} {extra:?}: {}", stderr(&o));
            let svg = std::fs::read_to_string(&out).unwrap();
            assert!(
                svg.starts_with("<svg") && svg.contains("time (s)"),
                "{input}"
            );
        }
    }
    let o = tcb_to(
        "plot",
        example("careen.json"),
        &out,
        &["--path", "--inbetweens", "4"],
    );
    assert_success(&o);
    let o = tcb_to(
        "plot",
        example("spin.json"),
        &out,
        &["--track", "top.squad", "--components"],
    );
    assert_success(&o);
    let never = dir.join("never.svg");
    for (args, message) in [
        (
            vec!["--track", "ball.nope"],
            "no track 'ball.nope' (the clip has: ball.position",
        ),
        (
            vec!["--from", "2", "--to", "1"],
            "--from 2 --to 1: the time range is empty",
        ),
        (
            vec!["--track", "ball.squash", "--path"],
            "'ball.squash' is scalar",
        ),
        (
            vec!["--path", "--components", "x,q"],
            "--components x,q: two different components",
        ),
    ] {
        let o = tcb_to("plot", example("bounce.json"), &never, &args);
        assert!(!o.status.success(), "{args:?}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(!never.exists());
    }
    let o = tcb_to("plot", example("bounce.json"), dir.join("x.png"), &[]);
    stderr_has(&o, "the output must end in .svg");
}

#[test]
fn plot_draws_a_panel_per_kind_and_skips_what_path_cannot_draw_in_one_line() {
    let dir = scratch("cli-plot");
    let out = dir.join("bounce.svg");
    let plot = |input: &str, extra: &[&str]| {
        let _ = std::fs::remove_file(&out);
        let o = tcb_to("plot", input, &out, extra);
        assert!(o.status.success(), "{input} {extra:?}: {}", stderr(&o));
        (std::fs::read_to_string(&out).unwrap(), stderr(&o))
    };
    // bounce.json has a vector, a rotation and a scalar track.
    let bounce = example("bounce.json");
    for extra in [&[][..], &["--velocity"], &["--speed"]] {
        let (svg, err) = plot(&bounce, extra);
        for panel in ["vector tracks", "rotation tracks", "scalar tracks"] {
            assert!(svg.contains(panel), "{extra:?}: no {panel}");
        }
        assert_eq!(err.lines().count(), 1, "{extra:?}: {err}");
    }
    // --path draws the vector track, and names what it skipped in one line.
    let (svg, err) = plot(&bounce, &["--path"]);
    assert!(svg.contains("ball.position") && !svg.contains("rotation tracks"));
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 2, "{err}");
    assert!(
        lines[0].starts_with("tcb: --path draws two components (x, y)")
            && lines[0].ends_with("skipping 'ball.squash' (scalar), 'ball.rotation' (quat)"),
        "{err}"
    );
    assert!(lines[1].starts_with("tcb: wrote "), "{err}");
    // A Y-up rig's path is drawn on the ground: x and z.
    let (svg, err) = plot(&data("cmu-01_01.bvh"), &["--path"]);
    assert!(svg.contains("z (component z)"), "{err}");
    assert!(err.contains("skipping 31 quat tracks"), "{err}");
    let (svg, _) = plot(&data("cmu-01_01.bvh"), &["--path", "--components", "x,y"]);
    assert!(svg.contains("y (component y)"));
    // A big clip: the first tracks of each kind, said in one line.
    let (svg, err) = plot(&data("cmu-01_01.bvh"), &[]);
    assert!(svg.contains("vector tracks") && svg.contains("rotation tracks"));
    assert!(
        err.contains("plotting the first 4 of 31 rotation tracks (choose others with --track)"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_buffer_outside_the_assets_folder_needs_allow_outside_paths() {
    let dir = scratch("cli-test").join("outside-test");
    let asset = dir.join("asset");
    std::fs::create_dir_all(&asset).unwrap();
    let times_and_values: Vec<u8> = [0.0f32, 1.0, 0.0, 1.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    std::fs::write(dir.join("data.bin"), &times_and_values).unwrap();
    let gltf = r#"{"asset": {"version": "2.0"}, "nodes": [{"name": "a"}],
      "buffers": [{"byteLength": 16, "uri": "../data.bin"}],
      "bufferViews": [{"buffer": 0, "byteLength": 16}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                    {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "SCALAR"}],
      "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
                      "samplers": [{"input": 0, "output": 1}]}]}"#;
    let file = asset.join("up.gltf");
    std::fs::write(&file, gltf).unwrap();
    let out = dir.join("up.json");
    let o = tcb_to("import", &file, &out, &[]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("buffer 0 ('../data.bin'): is outside the glTF file's folder (allow it with --allow-outside-paths"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = tcb_to("import", &file, &out, &["--allow-outside-paths"]);
    assert_success(&o);
    assert!(out.exists());
}

#[test]
fn figures_from_a_wrong_root_create_nothing() {
    let dir = scratch("cli-test").join("never-figures");
    let _ = std::fs::remove_dir_all(&dir);
    let o = tcb(&[
        "figures",
        "-o",
        dir.to_str().unwrap(),
        "--root",
        "/no/such/repo",
    ]);
    assert!(!o.status.success());
    stderr_has(&o, "tension.json");
    assert!(!dir.exists());
}
