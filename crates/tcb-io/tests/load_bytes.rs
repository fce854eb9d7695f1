//! `load_bytes` (bytes and a format, no path: an engine's asset reader)
//! gives what `load` gives for the same file, and says what it cannot do.

use std::path::{Path, PathBuf};
use tcb_io::{Format, ImportOptions, load, load_bytes};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(name)
}

/// Same document, clip and skeleton as `load` on the file.
fn same_as_load(path: &Path, format: Format, clip_name: &str) {
    let name = path.display();
    let from_file = load(path).unwrap();
    let bytes = std::fs::read(path).unwrap();
    let from_bytes = load_bytes(&bytes, format, clip_name, &ImportOptions::default()).unwrap();
    assert_eq!(from_bytes.doc.to_json(), from_file.doc.to_json(), "{name}");
    assert_eq!(from_bytes.skeleton, from_file.skeleton, "{name}");
    let (a, b) = (&from_bytes.clip, &from_file.clip);
    assert_eq!(a.tracks().len(), b.tracks().len());
    let (mut ra, mut rb) = (
        vec![0.0f32; a.channel_count()],
        vec![0.0f32; b.channel_count()],
    );
    a.sample_into(1.25, &mut ra, None);
    b.sample_into(1.25, &mut rb, None);
    assert_eq!(ra, rb, "{name}");
    // Warnings are the file's, without its name.
    assert_eq!(from_bytes.warnings.len(), from_file.warnings.len());
}

#[test]
fn bytes_load_as_the_file_does() {
    same_as_load(&data("data/cmu-01_01.bvh"), Format::Bvh, "cmu-01_01");
    same_as_load(&data("examples/clips/bounce.json"), Format::Json, "ignored");
    same_as_load(&data("data/simple_skin.gltf"), Format::Gltf, "simple_skin");
}

#[test]
fn a_glb_loads_from_bytes() {
    let loaded = load(data("data/cmu-01_01.bvh")).unwrap();
    let (glb, _) = tcb_io::gltf_export::export(
        &loaded.clip,
        loaded.skeleton.as_ref(),
        tcb_io::gltf_export::Container::Glb,
        &tcb_io::gltf_export::ExportOptions::default(),
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("tcb-io-load-bytes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cmu.glb");
    std::fs::write(&path, &glb).unwrap();
    same_as_load(&path, Format::Gltf, "cmu");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn what_bytes_cannot_do_is_an_error() {
    let options = ImportOptions::default();
    // External buffer files: no folder to find them in.
    let gltf = br#"{"asset": {"version": "2.0"},
        "buffers": [{"uri": "anim.bin", "byteLength": 8}]}"#;
    let err = load_bytes(gltf, Format::Gltf, "x", &options).unwrap_err();
    assert!(err.location.file.is_none());
    // The size limit.
    let small = options.clone().max_file_bytes(4);
    let err = load_bytes(b"HIERARCHY", Format::Bvh, "x", &small).unwrap_err();
    assert!(err.to_string().contains("max_file_bytes"), "{err}");
    // Not text.
    let err = load_bytes(&[0xff, 0xfe], Format::Json, "x", &options).unwrap_err();
    assert!(err.to_string().contains("UTF-8"), "{err}");
    // The file name, when the caller has one.
    let err = load_bytes(b"{}", Format::Json, "x", &options)
        .unwrap_err()
        .in_file("clips/x.json");
    assert!(err.to_string().starts_with("clips/x.json: "), "{err}");
}
