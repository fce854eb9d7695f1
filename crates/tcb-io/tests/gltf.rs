//! glTF import: the real Khronos sample (bundled in `data/`), and files that
//! claim more than they hold.

mod common;

use common::noise;
use glam::Quat;
use std::path::{Path, PathBuf};
use tcb_io::gltf_import::import;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(name)
}

/// Decode base64 here, independently of the importer.
fn b64(s: &str) -> Vec<u8> {
    let v = |c: u8| {
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
            .bytes()
            .position(|a| a == c)
            .unwrap() as u32
    };
    let s: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::new();
    for chunk in s.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &c)| n | v(c) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[test]
fn simple_skin_samples_as_gltf_linear_slerp() {
    let path = data("simple_skin.gltf");
    let loaded = tcb_io::load(&path).unwrap();
    let clip = &loaded.clip;
    assert_eq!(clip.tracks().len(), 1);
    assert_eq!(clip.tracks()[0].name, "node2.rotation");
    let skeleton = loaded.skeleton.unwrap();
    assert_eq!(skeleton.joints().len(), 3);
    assert_eq!(skeleton.joints()[2].parent, Some(1));

    // The keys, read with the gltf crate's own reader.
    let text = std::fs::read_to_string(&path).unwrap();
    let g = gltf::Gltf::from_slice(text.as_bytes()).unwrap();
    let buffers: Vec<Vec<u8>> = g
        .buffers()
        .map(|b| match b.source() {
            gltf::buffer::Source::Uri(u) => b64(u.split_once(',').unwrap().1),
            _ => unreachable!(),
        })
        .collect();
    let channel = g.animations().next().unwrap().channels().next().unwrap();
    let reader = channel.reader(|b| Some(&buffers[b.index()]));
    let times: Vec<f32> = reader.read_inputs().unwrap().collect();
    let keys: Vec<Quat> = match reader.read_outputs().unwrap() {
        gltf::animation::util::ReadOutputs::Rotations(r) => {
            r.into_f32().map(Quat::from_array).collect()
        }
        _ => unreachable!(),
    };
    assert_eq!(times.len(), 12);

    let mut row = [0.0f32; 4];
    let mut worst = 0.0f32;
    for k in 0..times.len() - 1 {
        for i in 0..=10 {
            let u = i as f32 / 10.0;
            let t = times[k] + u * (times[k + 1] - times[k]);
            clip.sample_into(f64::from(t), &mut row, None);
            // glTF LINEAR rotation: shortest-path slerp, in f64, of the keys
            // as rotations (the file's 0.707 is not quite unit length).
            let (a, b) = (
                keys[k].as_dquat().normalize(),
                keys[k + 1].as_dquat().normalize(),
            );
            let want = a.slerp(b, f64::from(u)).as_quat();
            let got = Quat::from_array(row);
            let d = (got - want).length().min((got + want).length());
            worst = worst.max(d);
        }
    }
    assert!(worst < 1e-5, "worst {worst}");
}

fn gltf_with(accessors: &str, buffer: &[u8]) -> String {
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        // A tiny encoder, for the test's own buffers.
        {
            let a = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
            let mut s = String::new();
            for c in buffer.chunks(3) {
                let n = (u32::from(c[0]) << 16)
                    | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
                    | u32::from(*c.get(2).unwrap_or(&0));
                for k in 0..4 {
                    s.push(if k <= c.len() {
                        a[(n >> (18 - 6 * k)) as usize & 63] as char
                    } else {
                        '='
                    });
                }
            }
            s
        }
    );
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "nodes": [{{"name": "box"}}],
        "buffers": [{{"byteLength": {}, "uri": "{uri}"}}],
        "bufferViews": [{{"buffer": 0, "byteLength": {}}}],
        "accessors": [{accessors}],
        "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 0, "path": "translation"}}}}],
                        "samplers": [{{"input": 0, "output": 1, "interpolation": "LINEAR"}}]}}]}}"#,
        buffer.len(),
        buffer.len()
    )
}

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn a_valid_small_file_imports() {
    let buf = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let acc = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#;
    let g = import(gltf_with(acc, &buf).as_bytes(), None, None, "t").unwrap();
    assert_eq!(g.doc.tracks[0].name, "box.translation");
    assert_eq!(g.doc.tracks[0].values[1], [4.0, 5.0, 6.0, 0.0]);
    let clip = g.doc.build().unwrap();
    let mut row = [0.0f32; 3];
    clip.sample_into(0.5, &mut row, None);
    assert_eq!(row, [2.5, 3.5, 4.5]);
}

#[test]
fn absurd_files_are_errors_not_panics() {
    let buf = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let cases = [
        // A billion keys in 32 bytes.
        (
            r#"{"bufferView": 0, "componentType": 5126, "count": 1000000000, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#,
            "do not fit in buffer view 0",
        ),
        // A count at u32::MAX (its byte length overflows 32 bits).
        (
            r#"{"bufferView": 0, "componentType": 5126, "count": 4294967295, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#,
            "do not fit in buffer view 0",
        ),
        // An offset past the end.
        (
            r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 24, "componentType": 5126, "count": 2, "type": "VEC3"}"#,
            "do not fit in buffer view 0",
        ),
        // Outputs of the wrong shape.
        (
            r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC2"}"#,
            "is Vec2, expected Vec3",
        ),
        // Fewer output rows than keys.
        (
            r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 1, "type": "VEC3"}"#,
            "2 input times but 1 output elements",
        ),
        // Integer times.
        (
            r#"{"bufferView": 0, "componentType": 5125, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#,
            "not normalized",
        ),
    ];
    for (acc, want) in cases {
        let err = import(gltf_with(acc, &buf).as_bytes(), None, None, "t")
            .unwrap_err()
            .to_string();
        assert!(err.contains(want), "{err}");
    }
    // A buffer shorter than it says.
    let text = gltf_with(
        r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
           {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#,
        &buf,
    )
    .replace(r#""byteLength": 32, "uri""#, r#""byteLength": 4000000000, "uri""#);
    let err = import(text.as_bytes(), None, None, "t")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("32 bytes, but the file says 4000000000"),
        "{err}"
    );
    // JSON that is not glTF; a GLB cut short: the parser's own words.
    let err = import(b"{\"asset\": 1}", None, None, "t").unwrap_err();
    assert!(
        err.to_string().starts_with("not a valid glTF 2.0 file: "),
        "{err}"
    );
    let err = import(b"glTF\x02\x00\x00\x00\xff\xff\xff\xff", None, None, "t").unwrap_err();
    assert!(
        err.to_string().starts_with("not a valid glTF 2.0 file: "),
        "{err}"
    );
    // An animation that is not there.
    let ok = gltf_with(cases[0].0.replace("1000000000", "2").as_str(), &buf);
    let err = import(ok.as_bytes(), None, Some("run"), "t")
        .unwrap_err()
        .to_string();
    assert_eq!(err, "no animation 'run' (the file has: 0)");
}

/// A mesh whose POSITION accessor does not exist is refused with a message;
/// the `gltf` crate's own validation panics on it (found by fuzzing).
#[test]
fn a_missing_position_accessor_is_an_error_not_a_panic() {
    let text = r#"{"asset": {"version": "2.0"},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}}]}],
        "animations": []}"#;
    let Err(e) = import(text.as_bytes(), None, None, "x") else {
        panic!("accepted")
    };
    assert!(
        e.to_string()
            .contains("meshes[0].primitives[0].attributes.POSITION is accessor 1"),
        "{e}"
    );
}

/// An animation channel aimed at a node that does not exist is refused with
/// a message; the `gltf` crate's `target().node()` unwraps it (found by
/// fuzzing).
#[test]
fn a_missing_target_node_is_an_error_not_a_panic() {
    let buf = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let acc = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#;
    let text = gltf_with(acc, &buf).replace(r#""node": 0"#, r#""node": 5"#);
    let Err(e) = import(text.as_bytes(), None, None, "x") else {
        panic!("accepted")
    };
    assert!(
        e.to_string()
            .contains("animations[0].channels[0].target.node is node 5, but the file has 1 nodes"),
        "{e}"
    );
}

/// A channel target path the file format does not know (an extension's, or
/// a typo) is refused with a message; the `gltf` crate's `property()`
/// unwraps it (found by fuzzing).
#[test]
fn an_unknown_target_path_is_an_error_not_a_panic() {
    let buf = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let acc = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#;
    let text = gltf_with(acc, &buf).replace(r#""path": "translation""#, r#""path": "translashun""#);
    let Err(e) = import(text.as_bytes(), None, None, "x") else {
        panic!("accepted")
    };
    assert!(
        e.to_string().contains("target.path is not translation"),
        "{e}"
    );
}

/// A CUBICSPLINE rotation whose second key is stored with the other sign:
/// viewers interpolate the stored components (the glTF spec's cubic, then
/// normalize), so the import keeps them as written (`hemisphere: keep`)
/// and plays the same long way round.
#[test]
fn sign_changing_cubicspline_rotations_play_as_stored() {
    let (s, c) = (15f32.to_radians().sin(), 15f32.to_radians().cos());
    let v0 = [0.0, 0.0, 0.0, 1.0];
    let v1 = [0.0, 0.0, -s, -c];
    let zero = [0.0f32; 4];
    let mut out = vec![0.0f32, 1.0];
    for e in [zero, v0, zero, zero, v1, zero] {
        out.extend_from_slice(&e);
    }
    let acc = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 6, "type": "VEC4"}"#;
    let text = gltf_with(acc, &floats(&out))
        .replace(r#""path": "translation""#, r#""path": "rotation""#)
        .replace(r#""LINEAR""#, r#""CUBICSPLINE""#);
    let g = import(text.as_bytes(), None, None, "t").unwrap();
    assert_eq!(
        g.doc.tracks[0].settings.hemisphere,
        Some(tcb_core::Hemisphere::Keep)
    );
    let clip = g.doc.build().unwrap();
    for i in 0..=20 {
        let u = f64::from(i) / 20.0;
        let (a, b) = (
            2.0 * u.powi(3) - 3.0 * u * u + 1.0,
            -2.0 * u.powi(3) + 3.0 * u * u,
        );
        let p: Vec<f64> = (0..4)
            .map(|k| a * f64::from(v0[k]) + b * f64::from(v1[k]))
            .collect();
        let len = p.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut row = [0.0f32; 4];
        clip.sample_into(u, &mut row, None);
        for k in 0..4 {
            let want = p[k] / len;
            assert!(
                (f64::from(row[k]) - want).abs() < 1e-5,
                "u {u} component {k}: {} vs {want}",
                row[k]
            );
        }
    }
    // Half way it is far from the short way's half way (the keys are the
    // identity and 30 degrees about z).
    let mut row = [0.0f32; 4];
    clip.sample_into(0.5, &mut row, None);
    let short = Quat::from_rotation_z(15f32.to_radians());
    assert!(Quat::from_array(row).dot(short).abs() < 0.2, "{row:?}");
}

/// Sparse accessors (core glTF 2.0; gltf-transform writes them for morph
/// animation): the listed elements replace the base, which is zeros when
/// the accessor has no buffer view.
#[test]
fn sparse_accessors_import() {
    let mut buf = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 7.0, 8.0, 9.0, 4.0, 5.0, 6.0]);
    buf.extend_from_slice(&1u32.to_le_bytes());
    let sparse = |index_offset: usize| {
        format!(
            r#""sparse": {{"count": 1, "indices": {{"bufferView": 0, "byteOffset": {index_offset}, "componentType": 5125}},
                          "values": {{"bufferView": 0, "byteOffset": 32}}}}"#
        )
    };
    let input = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]}"#;
    let sample = |acc: String| -> Result<[f32; 3], String> {
        let g =
            import(gltf_with(&acc, &buf).as_bytes(), None, None, "t").map_err(|e| e.to_string())?;
        let clip = g.doc.build().unwrap();
        let mut row = [0.0f32; 3];
        clip.sample_into(0.5, &mut row, None);
        Ok(row)
    };
    // No base: key 0 is zero, key 1 is (4, 5, 6).
    let no_base = format!(
        r#"{input}, {{"componentType": 5126, "count": 2, "type": "VEC3", {}}}"#,
        sparse(44)
    );
    assert_eq!(sample(no_base).unwrap(), [2.0, 2.5, 3.0]);
    // A base of (1, 2, 3), (7, 8, 9) with element 1 replaced.
    let with_base = format!(
        r#"{input}, {{"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3", {}}}"#,
        sparse(44)
    );
    assert_eq!(sample(with_base).unwrap(), [2.5, 3.5, 4.5]);
    // An index beyond the accessor (the u32 at byte 40 is 6.0's bits) and
    // indices past the view are errors that say so.
    let bad = format!(
        r#"{input}, {{"componentType": 5126, "count": 2, "type": "VEC3", {}}}"#,
        sparse(40)
    );
    let err = sample(bad).unwrap_err();
    assert!(err.contains("sparse index 0 is"), "{err}");
    let outside = format!(
        r#"{input}, {{"componentType": 5126, "count": 2, "type": "VEC3", {}}}"#,
        sparse(46)
    );
    let err = sample(outside).unwrap_err();
    assert!(err.contains("sparse indices do not fit"), "{err}");
    // A view-less sparse accessor claiming 4 billion elements is refused
    // before anything is allocated.
    let huge = format!(
        r#"{input}, {{"componentType": 5126, "count": 4000000000, "type": "VEC3", {}}}"#,
        sparse(44)
    );
    let err = sample(huge).unwrap_err();
    assert!(err.contains("no buffer view (at most 16777216)"), "{err}");
}

/// Buffer URIs stay inside the asset's folder (clip-format.md): `..`, an
/// absolute path and a symbolic link out of it are refused unless allowed,
/// as is anything but a regular file; a missing or short file is named.
#[test]
fn buffer_uris_stay_inside_the_assets_folder() {
    let root = std::env::temp_dir().join(format!("tcb-uri-test-{}", std::process::id()));
    let asset = root.join("asset");
    std::fs::create_dir_all(&asset).unwrap();
    let data = floats(&[0.0, 1.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    std::fs::write(root.join("outside.bin"), &data).unwrap();
    std::fs::write(asset.join("inside.bin"), &data).unwrap();
    std::fs::write(asset.join("short.bin"), &data[..5]).unwrap();
    let acc = r#"{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 0, "byteOffset": 8, "componentType": 5126, "count": 2, "type": "VEC3"}"#;
    let with_uri = |uri: &str| {
        let text = gltf_with(acc, &data);
        let at = text.find("data:").unwrap();
        let end = at + text[at..].find('"').unwrap();
        format!("{}{uri}{}", &text[..at], &text[end..])
    };
    let load = |name: &str, uri: &str, allow: bool| {
        let path = asset.join(name);
        std::fs::write(&path, with_uri(uri)).unwrap();
        let options = tcb_io::ImportOptions::default().allow_outside_paths(allow);
        tcb_io::load_with(&path, &options)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    load("inside.gltf", "inside.bin", false).unwrap();
    let outside = root.join("outside.bin");
    for (name, uri) in [
        ("up.gltf", "../outside.bin".to_string()),
        ("abs.gltf", outside.to_string_lossy().into_owned()),
    ] {
        let e = load(name, &uri, false).unwrap_err();
        assert!(
            e.contains(&format!(
                "buffer 0 ('{uri}'): is outside the glTF file's folder"
            )),
            "{e}"
        );
        load(name, &uri, true).unwrap();
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, asset.join("link.bin")).unwrap();
        let e = load("link.gltf", "link.bin", false).unwrap_err();
        assert!(e.contains("is outside the glTF file's folder"), "{e}");
        assert!(e.contains("it resolves to"), "{e}");
        if std::process::Command::new("mkfifo")
            .arg(asset.join("fifo.bin"))
            .status()
            .is_ok_and(|s| s.success())
        {
            let e = load("fifo.gltf", "fifo.bin", false).unwrap_err();
            assert!(e.contains("fifo.bin is not a regular file"), "{e}");
        }
    }
    let e = load("short.gltf", "short.bin", false).unwrap_err();
    assert!(
        e.contains("short.bin has 5 bytes but the buffer's byteLength is 32"),
        "{e}"
    );
    let e = load("missing.gltf", "missing.bin", false).unwrap_err();
    assert!(
        e.contains("buffer 0 ('missing.bin'):") && e.contains("missing.bin: No such file"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A GLB header whose length field is below the header's own 12 bytes:
/// the `gltf` crate (1.4.1) subtracts 12 from it and overflows (a panic in
/// debug builds), so the importer checks it first (found by the `gltf`
/// fuzz target: `fuzz/corpus/gltf/crash-glb-length-below-header`).
#[test]
fn a_glb_length_below_its_header_is_an_error_not_a_panic() {
    let bytes = b"glTF{\n{\x0e\0\0\0\0\0\0\0\x0d\x01\0\0U";
    let err = tcb_io::gltf_import::import(bytes, None, None, "x")
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        "not a valid glTF 2.0 file: the GLB header says the file is 0 bytes, less than its own 12-byte header"
    );
    let mut glb = b"glTF\x02\0\0\0".to_vec();
    glb.extend(11u32.to_le_bytes());
    let err = tcb_io::gltf_import::import(&glb, None, None, "x")
        .unwrap_err()
        .to_string();
    assert!(err.contains("says the file is 11 bytes"), "{err}");
}

/// A file with neither the GLB magic nor a JSON object's `{` first is "not
/// a glTF file", rather than the JSON parser's "expected value at line 1
/// column 1" for bytes that were never JSON.
#[test]
fn files_that_are_not_gltf_say_so() {
    const NOT_GLTF: &str =
        "not a glTF file: neither binary glTF (no \"glTF\" magic) nor glTF JSON (no '{' first)";
    let dir = std::env::temp_dir().join(format!("tcb-not-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("x.glb");
    std::fs::write(&path, noise(512)).unwrap();
    let err = tcb_io::load(&path).unwrap_err().to_string();
    assert_eq!(err, format!("{}: {NOT_GLTF}", path.display()));
    for bytes in [
        &b""[..],
        b" \n",
        b"HIERARCHY\nROOT hip\n",
        b"glT",
        b"[1, 2]",
    ] {
        let err = import(bytes, None, None, "t").unwrap_err().to_string();
        assert_eq!(err, NOT_GLTF, "{bytes:?}");
    }
    // JSON after whitespace or a byte-order mark is JSON: the parser says
    // what is wrong with it.
    for bytes in [&b" \r\n\t{\"asset\": 1}"[..], b"\xef\xbb\xbf{}"] {
        let err = import(bytes, None, None, "t").unwrap_err().to_string();
        assert!(err.starts_with("not a valid glTF 2.0 file: "), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
