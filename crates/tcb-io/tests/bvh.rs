//! BVH import against the real CMU file (bundled in `data/`) and against
//! the damaged files motion capture arrives as.

mod common;

use common::noise;
use glam::{DQuat, Quat};
use std::path::{Path, PathBuf};
use tcb_io::bvh::Bvh;
use tcb_io::{ErrorKind, Format, ImportOptions, load_bytes, load_with};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(name)
}

/// The channel layout and rows, read here independently of `tcb_io::bvh`:
/// per joint with channels, its name and channel names; then the rows.
/// Joint name and channel names.
type Layout = Vec<(String, Vec<String>)>;

fn raw(text: &str) -> (Layout, Vec<Vec<f64>>, f64) {
    let mut joints = Vec::new();
    let mut name = String::new();
    let mut lines = text.lines();
    for line in lines.by_ref() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"ROOT") | Some(&"JOINT") => name = w[1].to_string(),
            Some(&"CHANNELS") => {
                joints.push((name.clone(), w[2..].iter().map(|s| s.to_string()).collect()))
            }
            Some(&"MOTION") => break,
            _ => {}
        }
    }
    lines.next();
    let dt: f64 = lines
        .next()
        .unwrap()
        .split(':')
        .nth(1)
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    (joints, rows, dt)
}

fn close_quat(a: Quat, b: DQuat) -> f64 {
    let a = a.as_dquat();
    let d = (a - b)
        .to_array()
        .iter()
        .map(|x| x.abs())
        .fold(0.0, f64::max);
    let e = (a + b)
        .to_array()
        .iter()
        .map(|x| x.abs())
        .fold(0.0, f64::max);
    d.min(e)
}

#[test]
fn cmu_every_frame_reproduced() {
    for mode in [
        tcb_core::RotationMode::Squad,
        tcb_core::RotationMode::Hermite,
    ] {
        let path = data("cmu-01_01.bvh");
        let text = std::fs::read_to_string(&path).unwrap();
        let (joints, rows, dt) = raw(&text);
        assert_eq!(rows.len(), 2752);
        let options = ImportOptions::default().rotation(mode);
        let loaded = load_with(&path, &options).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let clip = &loaded.clip;
        // 31 joints and 7 End Sites as leaf joints `<parent>_end`.
        let skeleton = loaded.skeleton.as_ref().unwrap();
        assert_eq!(skeleton.joints().len(), 31 + 7);
        assert_eq!(
            skeleton.joints()[31..]
                .iter()
                .filter(|j| j.name.ends_with("_end"))
                .count(),
            7
        );
        assert_eq!(clip.channel_count(), 3 + 31 * 4);
        let mut row = vec![0.0f32; clip.channel_count()];
        let (mut worst_t, mut worst_q) = (0.0f64, 0.0f64);
        for (f, values) in rows.iter().enumerate() {
            clip.sample_into(f as f64 * dt, &mut row, None);
            let mut col = 0; // into `values`
            let mut out = 0; // into `row`
            for (_, channels) in &joints {
                let mut q = DQuat::IDENTITY;
                let mut has_pos = false;
                let mut pos = [0.0f64; 3];
                for c in channels {
                    let v = values[col];
                    col += 1;
                    let axis = match &c[..1] {
                        "X" => 0,
                        "Y" => 1,
                        _ => 2,
                    };
                    if c.ends_with("position") {
                        has_pos = true;
                        pos[axis] = v;
                    } else {
                        let r = v.to_radians();
                        q *= [
                            DQuat::from_rotation_x(r),
                            DQuat::from_rotation_y(r),
                            DQuat::from_rotation_z(r),
                        ][axis];
                    }
                }
                if has_pos {
                    for (i, p) in pos.iter().enumerate() {
                        worst_t =
                            worst_t.max((f64::from(row[out + i]) - p).abs() / p.abs().max(1.0));
                    }
                    out += 3;
                }
                let got = Quat::from_slice(&row[out..out + 4]);
                worst_q = worst_q.max(close_quat(got, q));
                out += 4;
            }
        }
        assert!(
            worst_t <= 1e-5,
            "{mode:?}: translation off by {worst_t} (relative)"
        );
        assert!(worst_q <= 1e-5, "{mode:?}: rotation off by {worst_q}");
        println!("{mode:?}: worst translation {worst_t:e}, rotation {worst_q:e}");
    }
}

const SMALL: &str = "HIERARCHY\nROOT hip\n{\n\tOFFSET 1 2 3\n\tCHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation\n\tJOINT knee\n\t{\n\t\tOFFSET 0 -1 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -1 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n1 2 3 90 0 0 10 20 30\n2 4 6 0 90 0 -10 -20 -30\n";

#[test]
fn euler_order_as_listed() {
    let bvh = Bvh::parse(SMALL).unwrap();
    assert_eq!(bvh.frame_count(), 3);
    assert_eq!(bvh.end_sites().len(), 1);
    let (_, q) = bvh.local(1, 1).unwrap();
    let r = |d: f64| d.to_radians();
    // Zrotation Xrotation Yrotation: qz * qx * qy, intrinsic.
    let want = DQuat::from_rotation_z(r(10.0))
        * DQuat::from_rotation_x(r(20.0))
        * DQuat::from_rotation_y(r(30.0));
    assert!(close_quat(q.as_quat(), want) < 1e-7);
    // And the same as glam's intrinsic Euler convention.
    let glam_q = DQuat::from_euler(glam::EulerRot::ZXY, r(10.0), r(20.0), r(30.0));
    assert!(close_quat(q.as_quat(), glam_q) < 1e-7);
    let (t, _) = bvh.local(2, 0).unwrap();
    assert_eq!(t.to_array(), [2.0, 4.0, 6.0]);
}

#[test]
fn crlf_tabs_and_trailing_blank_lines_read_the_same() {
    let crlf = SMALL.replace('\n', "\r\n").replace(' ', " \t") + "\r\n\r\n   \r\n";
    let a = Bvh::parse(SMALL).unwrap();
    let b = Bvh::parse(&crlf).unwrap();
    assert_eq!(a.values(), b.values());
    assert_eq!(a.skeleton(), b.skeleton());
    assert!(b.warnings().is_empty());
}

fn error(text: &str) -> String {
    match Bvh::parse(text) {
        Ok(_) => panic!("parsed: {text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn frame_count_disagreeing_with_rows_is_a_warning() {
    let more = SMALL.replace("Frames: 3", "Frames: 1000000000");
    let bvh = Bvh::parse(&more).unwrap();
    assert_eq!(bvh.frame_count(), 3);
    assert_eq!(
        bvh.warnings(),
        ["line 17: the header says Frames: 1000000000 but 3 rows follow; read the 3 rows"]
    );
    let fewer = SMALL.replace("Frames: 3", "Frames: 2");
    assert_eq!(Bvh::parse(&fewer).unwrap().frame_count(), 3);
}

#[test]
fn damaged_files_are_clear_errors_naming_the_line() {
    // A row cut short (the file truncated mid-row).
    let cut = &SMALL[..SMALL.len() - 8];
    assert_eq!(
        error(cut),
        "line 21: frame 2 has 7 values, expected 9 (truncated or malformed row)"
    );
    // A row with too many values.
    assert_eq!(
        error(&SMALL.replace("0 0 0 0 0 0 0 0 0\n", "0 0 0 0 0 0 0 0 0 0\n")),
        "line 19: frame 0 has more than 9 values (one per channel)"
    );
    // Not a number, with the channel it was for.
    assert_eq!(
        error(&SMALL.replace("1 2 3 90", "1 2 3 nan")),
        "line 20: frame 1, channel 3 (hip Xrotation): 'nan' is not a finite number"
    );
    assert_eq!(
        error(&SMALL.replace(
            "Xrotation Yrotation Zrotation",
            "Xrotation Yrotation Wrotation"
        )),
        "line 5: unknown channel 'Wrotation' (expected Xposition … Zrotation)"
    );
    assert_eq!(
        error(&SMALL.replace("CHANNELS 3", "CHANNELS 1000000000")),
        "line 9: CHANNELS 1000000000: at most 6 (X/Y/Z position and rotation)"
    );
    assert_eq!(
        error(&SMALL.replace("MOTION", "MOTON")),
        "line 21: no MOTION section"
    );
    assert_eq!(
        error(&SMALL.replace("Frame Time: 0.1", "Frame Time: 0")),
        "line 18: Frame Time '0' is not a positive number of seconds"
    );
    assert_eq!(
        error(&SMALL.replace("\t}\n}\nMOTION", "\t}\nMOTION")),
        "line 15: the hierarchy ends with joints not closed by '}'"
    );
    assert_eq!(
        error(&SMALL.replace("JOINT knee", "JOINT hip")),
        "line 6: a second joint named 'hip'"
    );
    assert_eq!(error(""), "not a BVH file: it is empty");
    assert_eq!(
        error("MOTION\n"),
        "not a BVH file: it starts with 'MOTION', not HIERARCHY"
    );
    let header_only = &SMALL[..SMALL.find("Frames").unwrap()];
    assert_eq!(error(header_only), "line 16: 'Frames' missing after MOTION");
}

/// A file that is not text, or text that does not start with HIERARCHY,
/// is "not a BVH file", saying why (not UTF-8's own wording, nor "no
/// MOTION section" for a file that never was one).
#[test]
fn files_that_are_not_bvh_say_so() {
    let dir = std::env::temp_dir().join(format!("tcb-not-bvh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("x.bvh");
    std::fs::write(&path, noise(512)).unwrap();
    let err = tcb_io::load(&path).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Import(_)), "{err:?}");
    let text = err.to_string();
    let want = format!("{}: not a BVH file: not text (byte 0x", path.display());
    assert!(text.starts_with(&want), "{text}");
    assert!(text.ends_with(" is not UTF-8)"), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
    // A zip archive: ASCII, then a byte that is not UTF-8.
    let options = ImportOptions::default();
    let zip = b"PK\x03\x04\x14\0\0\0\x08\0\xa5\x5b";
    let err = load_bytes(zip, Format::Bvh, "x", &options).unwrap_err();
    assert_eq!(
        err.to_string(),
        "not a BVH file: not text (byte 0xA5 at offset 10 is not UTF-8)"
    );
    // Text, but not BVH.
    let json = r#"{"format": "tcb-clip/1", "tracks": []}"#;
    assert_eq!(
        error(json),
        "not a BVH file: it starts with '{\"format\":', not HIERARCHY"
    );
    assert_eq!(
        error(&"x".repeat(100)),
        "not a BVH file: it starts with 'xxxxxxxxxxxxxxxxxxxx…', not HIERARCHY"
    );
    assert_eq!(error(" \r\n\t"), "not a BVH file: it is empty");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A BVH file with a byte that is not UTF-8 (a Latin-1 joint name) is a
/// BVH file: the error names the line and the byte.
#[test]
fn a_bvh_file_with_a_byte_that_is_not_utf8_names_its_line() {
    let at = SMALL.find("knee").unwrap() + 2;
    let mut bytes = SMALL.as_bytes().to_vec();
    bytes[at] = 0xe9; // 'é' in Latin-1
    let err = load_bytes(&bytes, Format::Bvh, "x", &ImportOptions::default()).unwrap_err();
    assert!(
        matches!(err.kind, ErrorKind::Syntax { line: 6, .. }),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        format!("line 6: byte 0xE9 at offset {at} is not UTF-8 (BVH is read as UTF-8 text)")
    );
}

/// A byte-order mark before HIERARCHY (Windows editors write one) is skipped.
#[test]
fn a_byte_order_mark_is_skipped() {
    let with_bom = format!("\u{feff}{SMALL}");
    let a = Bvh::parse(SMALL).unwrap();
    let b = Bvh::parse(&with_bom).unwrap();
    assert_eq!(a.values(), b.values());
    assert_eq!(a.skeleton(), b.skeleton());
    let loaded = load_bytes(
        with_bom.as_bytes(),
        Format::Bvh,
        "x",
        &ImportOptions::default(),
    )
    .unwrap();
    assert_eq!(loaded.clip.channel_count(), 3 + 2 * 4);
}

#[test]
fn errors_from_files_name_the_file_and_nothing_is_written() {
    let dir = std::env::temp_dir().join(format!("tcb-bvh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cut.bvh");
    std::fs::write(&path, &SMALL[..SMALL.len() - 8]).unwrap();
    let err = tcb_io::load(&path).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Syntax { line: 21, .. }));
    assert!(
        err.to_string().starts_with(&path.display().to_string()),
        "{err}"
    );
    let one = dir.join("one.bvh");
    std::fs::write(
        &one,
        SMALL
            .replace("Frames: 3", "Frames: 1")
            .lines()
            .take(19)
            .collect::<Vec<_>>()
            .join("\n"),
    )
    .unwrap();
    let err = tcb_io::load(&one).unwrap_err().to_string();
    assert!(
        err.ends_with("1 frame(s) of motion: a clip needs at least 2"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A 2 GB file is refused unread, naming the limit (the file is sparse:
/// nothing is written to disk); `ImportOptions::max_file_bytes` sets it.
#[test]
fn files_above_the_size_limit_are_refused_unread() {
    let dir = std::env::temp_dir().join(format!("tcb-limit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for ext in ["bvh", "json", "gltf"] {
        let path = dir.join(format!("huge.{ext}"));
        let f = std::fs::File::create(&path).unwrap();
        f.set_len(2 << 30).unwrap();
        let e = tcb_io::load(&path).expect_err("refused");
        let text = e.to_string();
        assert!(
            text.contains("2147483648 bytes; files above 1073741824 bytes are refused"),
            "{text}"
        );
        let small = ImportOptions::default().max_file_bytes(1000);
        std::fs::write(&path, vec![b' '; 2000]).unwrap();
        let e = load_with(&path, &small).expect_err("refused");
        assert!(e.to_string().contains("files above 1000 bytes"), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file without an extension says so, rather than "unknown file type '.'".
#[test]
fn a_file_without_an_extension_says_so() {
    let dir = std::env::temp_dir().join(format!("tcb-noext-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("clip");
    std::fs::write(&path, "{}").unwrap();
    let e = tcb_io::load(&path).expect_err("refused");
    assert!(
        e.to_string().contains("no file extension to tell its type"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A hierarchy nested 100,000 deep is refused at the limit, naming it; one
/// at the limit reads.
#[test]
fn deep_hierarchies_are_refused() {
    let nested = |depth: usize| {
        let mut text = String::from("HIERARCHY\n");
        for i in 0..depth {
            let word = if i == 0 { "ROOT" } else { "JOINT" };
            text.push_str(&format!(
                "{word} j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Zrotation\n"
            ));
        }
        text.push_str(&"}\n".repeat(depth));
        text.push_str("MOTION\nFrames: 2\nFrame Time: 0.1\n");
        for _ in 0..2 {
            text.push_str(&"1 ".repeat(depth));
            text.push('\n');
        }
        text
    };
    let max = tcb_io::bvh::MAX_DEPTH;
    let err = tcb_io::bvh::Bvh::parse(&nested(100_000))
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        format!(
            "line {}: joints nested deeper than {max} (the limit; rigs are tens deep)",
            2 + 4 * max
        )
    );
    let ok = tcb_io::bvh::Bvh::parse(&nested(max)).unwrap();
    assert_eq!(ok.skeleton().joints().len(), max);
}
