//! Export to glTF, import again, sample: exact tracks match the original to
//! 1e-5, resampled ones within the error the export reported.

use tcb_io::gltf_export::{Container, export};
use tcb_io::gltf_import::import;

const CLIP: &str = r#"{"format": "tcb-clip/1", "name": "rt",
 "tracks": [
  {"name": "hip.translation", "kind": "vec3", "times": [0, 0.4, 1.1, 2], "values": [[0,0,0],[1,2,0],[2,0,1],[3,1,0]], "keys": [{}, {"tcb": [0.3, -0.5, 0.2]}, {}, {"interp": "linear"}]},
  {"name": "hip.rotation", "kind": "quat", "times": [0, 0.5, 1.25, 2], "values": [[0,0,0,1],[0,0,0.3826834,0.9238795],[0.5,0,0.5,0.7071068],[0,0,1,0]]},
  {"name": "arm.rotation", "kind": "quat", "rotation": "hermite", "tangent_rule": "uniform", "times": [0, 0.5, 1.25, 2], "values": [[0,0,0,1],[0,0,0.3826834,0.9238795],[0.5,0,0.5,0.7071068],[0,0,1,0]], "keys": [{}, {"tcb": [0, 0.5, -0.5]}, {}, {}]},
  {"name": "arm.scale", "kind": "vec3", "times": [0, 1, 2], "values": [[1,1,1],[2,2,2],[1,1,1]], "keys": [{"ease": [0, 0.5]}, {"ease": [0.5, 0]}, {}]},
  {"name": "leg.translation", "kind": "vec3", "times": [0, 0.3, 2], "values": [[0,0,0],[1,1,1],[0,2,0]], "keys": [{}, {"out": [5, 0, 0]}, {}], "ends": "natural"},
  {"name": "face.weights.0", "kind": "scalar", "times": [0, 1, 2], "values": [0, 1, 0], "keys": [{"interp": "step"}, {"interp": "step"}, {}]},
  {"name": "face.weights.1", "kind": "scalar", "times": [0, 1, 2], "values": [1, 0.5, 0], "keys": [{"interp": "step"}, {"interp": "step"}, {}]}
 ]}"#;

fn round_trip(
    clip: &tcb_core::SourceClip,
    container: Container,
    max_error: f64,
) -> (tcb_core::SourceClip, tcb_io::gltf_export::ExportReport) {
    let options = tcb_io::gltf_export::ExportOptions::default().max_error(max_error);
    let (bytes, report) = export(clip, None, container, &options).unwrap();
    let back = import(&bytes, None, None, "rt").unwrap();
    (back.doc.build().unwrap(), report)
}

/// Largest difference per track (relative to max(1, |value|); rotations up to sign).
fn compare(
    a: &tcb_core::SourceClip,
    b: &tcb_core::SourceClip,
    times: impl Iterator<Item = f64>,
) -> Vec<f64> {
    let mut worst = vec![0.0f64; a.tracks().len()];
    let (mut va, mut vb) = (
        vec![0.0f32; a.channel_count()],
        vec![0.0f32; b.channel_count()],
    );
    for t in times {
        a.sample_into(t, &mut va, None);
        b.sample_into(t, &mut vb, None);
        let mut at = 0;
        for (i, track) in a.tracks().iter().enumerate() {
            // Same track in `b`, by name (glTF groups channels by node).
            let mut bt = 0;
            for other in b.tracks() {
                if other.name == track.name {
                    break;
                }
                bt += other.data.kind().dim();
            }
            let dim = track.data.kind().dim();
            let d = |s: f32| {
                (0..dim)
                    .map(|c| {
                        f64::from((va[at + c] - s * vb[bt + c]).abs() / va[at + c].abs().max(1.0))
                    })
                    .fold(0.0, f64::max)
            };
            let e = if track.data.kind() == tcb_core::TrackKind::Quat {
                d(1.0).min(d(-1.0))
            } else {
                d(1.0)
            };
            worst[i] = worst[i].max(e);
            at += dim;
        }
    }
    worst
}

#[test]
fn exact_tracks_round_trip_and_resampled_ones_hold_their_bound() {
    let clip = tcb_io::ClipDoc::parse(CLIP).unwrap().build().unwrap();
    for container in [Container::Gltf, Container::Glb] {
        let (back, report) = round_trip(&clip, container, 1e-5);
        assert_eq!(back.tracks().len(), clip.tracks().len());
        // Dense, and off the keys (f32 key times in glTF: stay inside).
        let worst = compare(&clip, &back, (0..=4001).map(|i| i as f64 * 2.0 / 4001.0));
        for (track, w) in report.tracks.iter().zip(&worst) {
            match track.error() {
                None => assert!(*w <= 1e-5, "{}: exact, but off by {w}", track.name),
                Some(e) => {
                    assert!(e <= 1e-5, "{}: reported {e}", track.name);
                    assert!(*w <= e + 1e-5, "{}: reported {e}, off by {w}", track.name);
                }
            }
        }
        let names = |f: &dyn Fn(&tcb_io::gltf_export::TrackExport) -> bool| -> Vec<&str> {
            report
                .tracks
                .iter()
                .filter(|t| f(t))
                .map(|t| t.name.as_str())
                .collect()
        };
        // Written as they are: all but squad and ease.
        assert_eq!(
            names(&|t| t.resampled_error.is_none()),
            [
                "hip.translation",
                "arm.rotation",
                "leg.translation",
                "face.weights.0",
                "face.weights.1"
            ]
        );
        // Exact: on key times that are f32s too (0.4, 1.1 and 0.3 are not).
        assert_eq!(
            names(&|t| t.error().is_none()),
            ["arm.rotation", "face.weights.0", "face.weights.1"]
        );
    }
}

#[test]
fn cmu_hermite_round_trips_as_it_is_and_within_its_report() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
    let clip = tcb_io::load_with(path, &options).unwrap().clip;
    let (back, report) = round_trip(&clip, Container::Glb, 1e-5);
    // Every curve is written as it is; the frame times (k * 0.0083333) are
    // not f32s, and glTF's f32 times move them (at 22.9 s, by up to 1e-6
    // s, which moves a fast joint by about 1e-5): that is reported.
    assert!(report.tracks.iter().all(|t| t.resampled_error.is_none()));
    assert!(report.tracks.iter().all(|t| t.time_rounding.is_some()));
    let reported = report.max_error();
    assert!(reported > 1e-6 && reported < 1e-4, "{reported}");
    let times = clip.key_times();
    let worst = compare(
        &clip,
        &back,
        times
            .windows(2)
            .flat_map(|w| [w[0], 0.3 * w[0] + 0.7 * w[1]]),
    );
    for (track, w) in report.tracks.iter().zip(&worst) {
        let e = track.error().unwrap();
        assert!(*w <= e, "{}: reported {e}, off by {w}", track.name);
    }
    // Compare the curves at the same local parameter, each on its own key
    // times: the same curves.
    let (ka, kb) = (clip.key_times(), back.key_times());
    assert_eq!(ka.len(), kb.len());
    let (mut va, mut vb) = (
        vec![0.0f32; clip.channel_count()],
        vec![0.0f32; back.channel_count()],
    );
    let mut worst = 0.0f32;
    for k in (0..ka.len() - 1).step_by(3) {
        for u in [0.0, 0.3, 0.5, 0.9] {
            clip.sample_into(ka[k] + u * (ka[k + 1] - ka[k]), &mut va, None);
            back.sample_into(kb[k] + u * (kb[k + 1] - kb[k]), &mut vb, None);
            for (a, b) in va.iter().zip(&vb) {
                worst = worst.max((a - b).abs() / a.abs().max(1.0));
            }
        }
    }
    assert!(worst <= 1e-5, "{worst}");
}

#[test]
fn what_gltf_cannot_hold_is_reported_or_refused() {
    let with = |extra: &str| {
        tcb_io::ClipDoc::parse(&CLIP.replace(
            r#""name": "hip.translation","#,
            &format!(r#""name": "hip.translation", {extra}"#),
        ))
        .unwrap()
        .build()
        .unwrap()
    };
    let (_, report) = export(
        &with(r#""post": "repeat","#),
        None,
        Container::Glb,
        &Default::default(),
    )
    .unwrap();
    assert_eq!(
        report.notes,
        ["track 'hip.translation': post 'repeat' is not expressible; glTF holds the end value"]
    );
    let bad = tcb_io::ClipDoc::parse(&CLIP.replace("hip.translation", "hip.squash"))
        .unwrap()
        .build()
        .unwrap();
    let err = export(&bad, None, Container::Glb, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("track 'hip.squash' (vec3) has no glTF target"),
        "{err}"
    );
    let gap = tcb_io::ClipDoc::parse(&CLIP.replace("face.weights.1", "face.weights.2"))
        .unwrap()
        .build()
        .unwrap();
    assert!(
        export(&gap, None, Container::Glb, &Default::default())
            .unwrap_err()
            .to_string()
            .contains("without gaps")
    );
}

/// Import, export with the skeleton, import again: the same joints (by
/// name), parents, rest transforms and motion.
fn hierarchy_round_trips(path: &str) {
    let first = tcb_io::load(path).unwrap();
    let skeleton = first.skeleton.clone().expect("importers fill the skeleton");
    let (bytes, _) = export(
        &first.clip,
        Some(&skeleton),
        Container::Glb,
        &Default::default(),
    )
    .unwrap();
    let again = import(&bytes, None, None, "rt").unwrap();
    let back = &again.skeleton;
    assert_eq!(back.joints().len(), skeleton.joints().len(), "{path}");
    for joint in skeleton.joints() {
        let b = &back.joints()[back.joint(&joint.name).expect("joint kept")];
        let name = |s: &tcb_core::skeleton::Skeleton, p: Option<usize>| {
            p.map(|p| s.joints()[p].name.clone())
        };
        assert_eq!(
            name(back, b.parent),
            name(&skeleton, joint.parent),
            "{path}: parent of {}",
            joint.name
        );
        let r = &joint.rest;
        let close = |a: glam::Vec3, b: glam::Vec3| {
            (a - b).abs().max_element() <= 1e-6 * a.abs().max_element().max(1.0)
        };
        assert!(
            close(r.translation, b.rest.translation),
            "{path}: {} translation",
            joint.name
        );
        assert!(close(r.scale, b.rest.scale), "{path}: {} scale", joint.name);
        assert!(
            r.rotation.normalize().dot(b.rest.rotation).abs() > 1.0 - 1e-6,
            "{path}: {} rotation",
            joint.name
        );
    }
    let clip = again.doc.build().unwrap();
    let (start, end) = first.clip.time_range().unwrap();
    let worst = compare(
        &first.clip,
        &clip,
        (0..=500).map(|i| start + (end - start) * f64::from(i) / 500.0),
    );
    // Squad is resampled within the default 1e-5.
    assert!(worst.iter().all(|w| *w <= 2e-5), "{path}: {worst:?}");
}

#[test]
fn bvh_hierarchy_rest_pose_and_motion_round_trip() {
    hierarchy_round_trips(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/cmu-01_01.bvh"
    ));
}

#[test]
fn gltf_hierarchy_rest_pose_and_motion_round_trip() {
    hierarchy_round_trips(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/simple_skin.gltf"
    ));
}

#[test]
fn unused_tangents_are_zero() {
    // The first key's in-tangent and the last key's out-tangent, exact and
    // resampled.
    let clip = tcb_io::ClipDoc::parse(CLIP).unwrap().build().unwrap();
    let (bytes, _) = export(&clip, None, Container::Glb, &Default::default()).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let mut cubic = 0;
    for anim in gltf.document.animations() {
        for ch in anim.channels() {
            if ch.sampler().interpolation() != gltf::animation::Interpolation::CubicSpline {
                continue;
            }
            let out = ch.sampler().output();
            let view = out.view().unwrap();
            let at = view.offset() + out.offset();
            let floats: Vec<f32> = blob[at..at + view.length()]
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            let width = floats.len() / out.count();
            let n = out.count() / 3;
            let first_in = &floats[..width];
            let last_out = &floats[(3 * n - 1) * width..];
            assert!(first_in.iter().all(|x| *x == 0.0), "{first_in:?}");
            assert!(last_out.iter().all(|x| *x == 0.0), "{last_out:?}");
            cubic += 1;
        }
    }
    assert!(cubic >= 4, "{cubic} cubic samplers");
}

/// A clip of one `a.translation` track at `times`, a wave of values with
/// the default (curve) keys, so that its keys are exported as they are.
fn at_times(times: &[f64]) -> tcb_core::SourceClip {
    let times: Vec<String> = times.iter().map(|t| format!("{t:?}")).collect();
    let values: Vec<String> = (0..times.len())
        .map(|k| format!("[{}, {}, 0]", (k % 3) as f32, (k % 2) as f32 * 2.0))
        .collect();
    tcb_io::ClipDoc::parse(&format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{{"name": "a.translation", "kind": "vec3",
          "times": [{}], "values": [{}]}}]}}"#,
        times.join(", "),
        values.join(", ")
    ))
    .unwrap()
    .build()
    .unwrap()
}

/// glTF's key times are f32 (issue 29, class 6): times beyond its range,
/// and distinct times that are one time in f32, cannot be written; the
/// error says why, and what to do, on one line.
#[test]
fn key_times_gltf_cannot_hold_are_refused() {
    let cases = [
        (
            vec![0.0, 1.0, 1e39],
            "track 'a.translation': key 2 is at 1e39 s, beyond glTF's key times (f32, at most 3.4028235e38 s); scale or shift the clip's times into that range before exporting",
        ),
        (
            vec![0.0, 1e8, 1e8 + 1.0, 1e8 + 8.0],
            "track 'a.translation': keys 1 and 2 (at 100000000 and 100000001 s) are one time in glTF's f32 key times (8 s apart at that time); shift the clip's times toward 0, or space those keys further apart, before exporting",
        ),
    ];
    for (times, message) in cases {
        for container in [Container::Gltf, Container::Glb] {
            let err = export(&at_times(&times), None, container, &Default::default())
                .map(|_| "exported".to_string())
                .unwrap_or_else(|e| e.to_string());
            assert_eq!(err, message);
        }
    }
}

/// The largest difference between the clip and its export read back by
/// `tcb import`, at the clip's keys, the f32 times glTF stores and 7
/// points between each two of those, clamped into the clip's keys (glTF
/// holds the end values).
fn read_back_error(clip: &tcb_core::SourceClip, container: Container) -> (f64, ExportReport) {
    let (bytes, report) = export(clip, None, container, &Default::default()).unwrap();
    let back = import(&bytes, None, None, "rt")
        .unwrap()
        .doc
        .build()
        .unwrap();
    let mut times: Vec<f64> = clip.key_times();
    times.extend(back.key_times());
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut check = Vec::new();
    for w in times.windows(2) {
        check.extend((0..8).map(|i| w[0] + (w[1] - w[0]) * f64::from(i) / 8.0));
    }
    check.push(*times.last().unwrap());
    let worst = compare(clip, &back, check.into_iter())
        .into_iter()
        .fold(0.0, f64::max);
    (worst, report)
}

use tcb_io::gltf_export::ExportReport;

/// Keys at a million seconds move by up to 0.025 s in f32 (a quarter of
/// their 0.1 s spacing): the export is not exact, and says how far off.
#[test]
fn keys_moved_by_f32_times_are_reported_and_read_back_within_it() {
    let clip = at_times(&[1e6, 1e6 + 0.1, 1e6 + 0.2, 1e6 + 0.3, 1e6 + 0.4]);
    for container in [Container::Gltf, Container::Glb] {
        let (worst, report) = read_back_error(&clip, container);
        let track = &report.tracks[0];
        assert!(worst > 1e-3, "{worst}: the keys did move");
        let reported = track.error().expect("not exact: its keys moved");
        assert!(
            worst <= reported,
            "reads back {worst} off, reported {reported}"
        );
        assert!(reported <= 2.0 * worst, "{reported} for {worst}");
        let rounding = track.time_rounding.expect("keys moved");
        // 1e6 + 0.1 is stored as 1e6 + 0.125 (f32 steps of 1/16 s there).
        assert!(
            (rounding.largest_shift - 0.025).abs() < 1e-6,
            "{rounding:?}"
        );
        assert_eq!(report.max_error(), reported);
        assert_eq!(report.notes.len(), 1, "{:?}", report.notes);
        assert!(
            report.notes[0]
                .starts_with("track 'a.translation': glTF's f32 key times move its keys by up to"),
            "{:?}",
            report.notes
        );
    }
}

/// Key times that are f32s export exactly; others, even slightly off
/// (0.1 s is not an f32), are measured, and read back within what is
/// reported.
#[test]
fn only_f32_key_times_are_exact() {
    let exact = at_times(&[0.0, 0.25, 0.5, 1.0]);
    let (worst, report) = read_back_error(&exact, Container::Glb);
    assert_eq!(report.tracks[0].error(), None);
    assert_eq!(report.tracks[0].time_rounding, None);
    assert!(worst <= 1e-6, "{worst}");
    let near = at_times(&[0.0, 0.1, 0.2, 0.3]);
    let (worst, report) = read_back_error(&near, Container::Glb);
    let reported = report.tracks[0].error().expect("0.1 moves in f32");
    assert!(worst <= reported, "{worst} > {reported}");
    assert!(reported < 1e-5, "{reported}");
    assert!(report.notes.is_empty(), "{:?}", report.notes);
}

/// A squad rotation on keys one f32 step apart (1/16 s at 1e6 s): its
/// resampling cannot split them (the pieces' knots would be one f32
/// time), so it keeps whole segments, reads back, and says how far off.
#[test]
fn resampling_does_not_split_below_f32_time_steps() {
    let clip = tcb_io::ClipDoc::parse(
        r#"{"format": "tcb-clip/1", "tracks": [{"name": "a.rotation", "kind": "quat",
          "times": [1000000, 1000000.0625, 1000000.125],
          "values": [[0, 0, 0, 1], [0, 0, 0.7071068, 0.7071068], [0.5, 0.5, 0.5, 0.5]]}]}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let (bytes, report) = export(&clip, None, Container::Glb, &Default::default()).unwrap();
    let back = import(&bytes, None, None, "rt")
        .unwrap()
        .doc
        .build()
        .unwrap();
    assert_eq!(back.key_times(), clip.key_times());
    let reported = report.tracks[0].error().unwrap();
    let worst = compare(
        &clip,
        &back,
        (0..=64).map(|i| 1e6 + 0.125 * f64::from(i) / 64.0),
    )[0];
    assert!(worst <= reported, "{worst} > {reported}");
}
