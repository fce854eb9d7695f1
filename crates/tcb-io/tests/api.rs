//! Issue 11's API point, tried on every public constructor and field of
//! tcb-io that existed before it. The documents (`ClipDoc`, `TrackDoc`,
//! `KeyDoc`, `SettingsDoc`) keep public fields on purpose: they are the
//! file as written, and `build` is where they are checked, so a document
//! that disagrees with itself is an error there, never a panic. `Bvh`'s
//! fields became accessors (a hand-made one could index past its rows).

use std::path::Path;
use tcb_core::{Interp, TrackKind};
use tcb_io::gltf_export::{Container, ExportOptions, export};
use tcb_io::{ClipDoc, ImportOptions, KeyDoc, SettingsDoc, TrackDoc};

fn track(kind: TrackKind, times: Vec<f64>, values: Vec<[f32; 4]>, keys: Vec<KeyDoc>) -> TrackDoc {
    TrackDoc {
        name: "t".into(),
        kind,
        times,
        values,
        keys,
        settings: SettingsDoc::default(),
    }
}

/// Documents that disagree with themselves: errors from `build`, and
/// `to_json` writes whatever they hold.
#[test]
fn documents_that_disagree_are_build_errors() {
    let v = |x: f32| [x, 0.0, 0.0, 1.0];
    let key = KeyDoc {
        tcb: Some([f64::NAN, 0.0, 0.0]),
        ease: Some([2.0, -1.0]),
        interp: Some(Interp::Step),
        tangent_in: Some([f32::INFINITY; 4]),
        tangent_out: None,
    };
    let cases = [
        track(TrackKind::Scalar, vec![0.0, 1.0], vec![v(0.0)], vec![]),
        track(
            TrackKind::Vec3,
            vec![0.0, 1.0],
            vec![v(0.0), v(1.0)],
            vec![KeyDoc::default()],
        ),
        track(
            TrackKind::Vec3,
            vec![0.0, 1.0],
            vec![v(0.0), v(1.0)],
            vec![key.clone(), key],
        ),
        track(
            TrackKind::Quat,
            vec![0.0, 1.0],
            vec![[0.0; 4], v(1.0)],
            vec![],
        ),
        track(
            TrackKind::Vec2,
            vec![1.0, 0.0],
            vec![v(0.0), v(1.0)],
            vec![],
        ),
        track(
            TrackKind::Vec4,
            vec![0.0, f64::NAN],
            vec![v(0.0), v(1.0)],
            vec![],
        ),
        track(
            TrackKind::Scalar,
            vec![0.0, 1.0],
            vec![v(f32::NAN), v(1.0)],
            vec![],
        ),
        track(TrackKind::Scalar, vec![], vec![], vec![]),
    ];
    for t in cases {
        let doc = ClipDoc {
            name: "d".into(),
            tracks: vec![t.clone()],
            ..ClipDoc::default()
        };
        assert!(doc.build().is_err(), "{t:?}");
        let _ = doc.to_json();
    }
    let twice = ClipDoc {
        tracks: vec![
            track(
                TrackKind::Scalar,
                vec![0.0, 1.0],
                vec![v(0.0), v(1.0)],
                vec![],
            ),
            track(
                TrackKind::Scalar,
                vec![0.0, 1.0],
                vec![v(0.0), v(1.0)],
                vec![],
            ),
        ],
        ..ClipDoc::default()
    };
    let err = twice.build().unwrap_err().to_string();
    assert!(err.contains("already used"), "{err}");
}

/// A `Bvh` comes only from `parse`; `local` beyond its frames or joints is
/// `None`.
#[test]
fn bvh_parts_are_read_through_accessors() {
    let text = "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Xrotation Yrotation Zrotation\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n1 2 3\n4 5 6\n";
    let bvh = tcb_io::bvh::Bvh::parse(text).unwrap();
    assert_eq!((bvh.frame_count(), bvh.channels().len()), (2, 1));
    assert!(bvh.local(1, 0).is_some());
    assert!(bvh.local(2, 0).is_none());
    assert!(bvh.local(0, 1).is_none());
    assert!(bvh.local(usize::MAX, usize::MAX).is_none());
}

/// Export options out of range, and import limits of zero: errors or a
/// valid file, never a panic.
#[test]
fn options_out_of_range() {
    let doc = ClipDoc {
        tracks: vec![track(
            TrackKind::Vec3,
            vec![0.0, 1.0, 2.0],
            vec![[0.0; 4], [1.0; 4], [0.0; 4]],
            vec![],
        )],
        ..ClipDoc::default()
    };
    let clip = doc.build().unwrap();
    for max_error in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
        let options = ExportOptions::default()
            .max_error(max_error)
            .rename(vec![("t".into(), "t".into()), ("u".into(), "t".into())]);
        for container in [Container::Gltf, Container::Glb] {
            let _ = export(&clip, None, container, &options);
        }
    }
    let options = ImportOptions::default()
        .max_file_bytes(0)
        .animation(Some("no such animation".into()));
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    for file in ["simple_skin.gltf", "cmu-01_01.bvh"] {
        let err = tcb_io::load_with(data.join(file), &options)
            .unwrap_err()
            .to_string();
        assert!(err.contains("max_file_bytes"), "{err}");
    }
    let err = tcb_io::load_with(
        data.join("simple_skin.gltf"),
        &ImportOptions::default().animation(Some("no such animation".into())),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("no such animation"), "{err}");
}

/// A default `tcb` that is not finite is refused even where every key
/// states its own (found by the `reduce` fuzz target: the reducer wrote such
/// a track's keys without their own tcb, and JSON cannot hold NaN, so the
/// clip written did not read back). A document that builds writes and
/// reads back as it is.
#[test]
fn a_default_tcb_that_is_not_finite_is_refused_where_it_is_unused() {
    let keys = vec![
        KeyDoc {
            tcb: Some([0.0; 3]),
            ..KeyDoc::default()
        };
        2
    ];
    let mut t = track(
        TrackKind::Scalar,
        vec![0.0, 1.0],
        vec![[0.0; 4], [1.0; 4]],
        keys,
    );
    t.settings.tcb = Some([0.0, f64::NAN, 0.0]);
    let doc = ClipDoc {
        tracks: vec![t.clone()],
        ..ClipDoc::default()
    };
    let err = doc.build().unwrap_err().to_string();
    assert_eq!(err, "track 't': tcb [0, NaN, 0] is not finite");
    t.settings.tcb = None;
    let doc = ClipDoc {
        defaults: SettingsDoc {
            tcb: Some([f64::INFINITY, 0.0, 0.0]),
            ..SettingsDoc::default()
        },
        tracks: vec![t],
        ..ClipDoc::default()
    };
    let err = doc.build().unwrap_err().to_string();
    assert_eq!(err, "defaults: tcb [inf, 0, 0] is not finite");
}

/// Issue 30's trap: every function of tcb-io that takes a file path takes
/// anything that is one (`&str`, `String`, `&Path`, `PathBuf`), as std's
/// own file functions do.
#[test]
fn path_taking_functions_accept_any_path_type() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let bvh = format!("{root}data/cmu-01_01.bvh");
    let a = tcb_io::load(bvh.as_str()).unwrap();
    let b = tcb_io::load(&bvh).unwrap();
    let c = tcb_io::load(Path::new(&bvh)).unwrap();
    let d = tcb_io::load_with(std::path::PathBuf::from(&bvh), &ImportOptions::default()).unwrap();
    assert!([&b, &c, &d].iter().all(|l| l.doc == a.doc));

    let dir = std::env::temp_dir().join(format!("tcb-io-api-paths-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = format!("{}/clip.json", dir.display());
    tcb_io::write_clip_doc(&a.doc, json.as_str()).unwrap();
    assert_eq!(tcb_io::read_clip_doc(json.clone()).unwrap(), a.doc);
    assert_eq!(
        tcb_io::load_clip(&json).unwrap().tracks().len(),
        a.clip.tracks().len()
    );
    let glb = format!("{}/clip.glb", dir.display());
    assert_eq!(Container::for_path(&glb), Container::Glb);
    tcb_io::gltf_export::export_file(&a.clip, None, glb.as_str(), &ExportOptions::default())
        .unwrap();
    tcb_io::write_atomically(format!("{}/bytes", dir.display()), b"x").unwrap();
    let e = tcb_io::Error::import("no").in_file("x.json");
    assert_eq!(e.to_string(), "x.json: no");
}

/// Issue 30's trap, the other half: `tcb_io::load` of a BVH and
/// `Bvh::parse(..)` name the same joints at the same indices. `load` (and
/// `Bvh::to_clip_doc`) add one leaf joint `<parent>_end` per End Site
/// after them (`Bvh::skeleton_with_end_sites`); `Bvh::skeleton` is the
/// joints with channels alone, as `Bvh::local` and `Bvh::channels` index
/// them. That difference is what this test pins.
#[test]
fn load_and_parse_give_the_same_joints_and_name_the_end_sites() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let loaded = tcb_io::load(path).unwrap();
    let skeleton = loaded.skeleton.unwrap();
    let bvh = tcb_io::bvh::Bvh::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(skeleton, bvh.skeleton_with_end_sites());
    assert_eq!(loaded.doc.skeleton.as_ref(), Some(&skeleton));
    let joints = &bvh.skeleton().joints();
    assert_eq!((joints.len(), bvh.end_sites().len()), (31, 7));
    assert_eq!(&skeleton.joints()[..joints.len()], &joints[..]);
    for (end, &(parent, offset)) in skeleton.joints()[joints.len()..]
        .iter()
        .zip(bvh.end_sites())
    {
        assert_eq!(end.name, format!("{}_end", joints[parent].name));
        assert_eq!(end.parent, Some(parent));
        assert_eq!(end.rest.translation, offset);
    }
}
