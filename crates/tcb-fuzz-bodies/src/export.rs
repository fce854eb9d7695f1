//! The `export` target: a structured clip exported to glTF, imported back
//! (as `tcb import` reads it) and compared with what the export reported.

use arbitrary::Unstructured;
use tcb_core::{SourceClip, TrackKind};
use tcb_io::ClipDoc;
use tcb_io::gltf_export::{Container, ExportOptions, export as export_gltf};

/// A structured clip (as `runtime`'s) whose tracks are named for glTF
/// targets (`n<i>.translation` or `.scale` for vec3, `.rotation` for
/// rotations, `m.weights.<j>` for scalars; vec2 and vec4 tracks mostly
/// made vec3, sometimes kept to be refused), exported to `.gltf` or
/// `.glb` at a chosen `max_error`. An export is either refused with a
/// message, or it imports and builds, with the same tracks, and inside
/// each track's keys reads back within the error it reported for that
/// track (relative to max(1, |value|), rotations up to sign) plus 1e-5 (an
/// exact track: within 1e-5), at the keys of both clips, 7 points between
/// each two of them and a few edge times.
pub fn export(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(mut doc) = crate::inputs::arbitrary_doc(&mut u) else {
        return;
    };
    name_for_gltf(&mut doc, &mut u);
    let Ok(clip) = doc.build() else {
        return;
    };
    let container = if u.ratio(1, 2u8).unwrap_or(false) {
        Container::Glb
    } else {
        Container::Gltf
    };
    let max_error = *u.choose(&[1e-5, 1e-3, 1e-7, 0.1]).unwrap_or(&1e-5);
    let options = ExportOptions::default().max_error(max_error);
    let (bytes, report) = match export_gltf(&clip, None, container, &options) {
        Ok(r) => r,
        Err(e) => {
            assert!(!e.to_string().is_empty(), "a refusal without a message");
            return;
        }
    };
    let back = read_back(&bytes, container);
    assert_eq!(
        back.tracks().len(),
        clip.tracks().len(),
        "tracks read back ({container:?})"
    );
    let check = check_times(&mut u, &clip, &back);
    let offsets = offsets_in(&clip, &back);
    let (mut va, mut vb) = (
        vec![0.0f32; clip.channel_count()],
        vec![0.0f32; back.channel_count()],
    );
    for &t in &check {
        clip.sample_into(t, &mut va, None);
        back.sample_into(t, &mut vb, None);
        let mut at = 0;
        for (track, &bt) in clip.tracks().iter().zip(&offsets) {
            let dim = track.data.kind().dim();
            let a = &va[at..at + dim];
            at += dim;
            let keys = track.data.times();
            if !(keys[0]..=keys[keys.len() - 1]).contains(&t) || a.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let b = &vb[bt..bt + dim];
            let e = read_back_error(a, b, track.data.kind());
            // By name: the report's order is not the clip's when there are
            // weight tracks (see `crates/tcb-io/tests/export_read_back.rs`).
            let stated = report
                .tracks
                .iter()
                .find(|r| r.name == track.name)
                .expect("every track reported")
                .error();
            assert!(
                e <= stated.unwrap_or(0.0) + 1e-5,
                "{} at {t} ({container:?}, max_error {max_error}): {a:?} read back as {b:?}, \
                 off by {e}, reported {stated:?}",
                track.name
            );
        }
    }
}

/// Names the tracks for glTF targets: vec2 and vec4 tracks mostly made
/// vec3 (1 in 16 kept, to be refused), vec3 a node's scale (1 in 3) or
/// translation, rotations a node's rotation, scalars the mesh's weights in
/// order.
fn name_for_gltf(doc: &mut ClipDoc, u: &mut Unstructured) {
    let mut weights = 0;
    for (i, t) in doc.tracks.iter_mut().enumerate() {
        if matches!(t.kind, TrackKind::Vec2 | TrackKind::Vec4) && !u.ratio(1, 16u8).unwrap_or(false)
        {
            t.kind = TrackKind::Vec3;
        }
        t.name = match t.kind {
            TrackKind::Vec3 if u.ratio(1, 3u8).unwrap_or(false) => format!("n{i}.scale"),
            TrackKind::Vec3 => format!("n{i}.translation"),
            TrackKind::Quat => format!("n{i}.rotation"),
            TrackKind::Scalar => {
                weights += 1;
                format!("m.weights.{}", weights - 1)
            }
            _ => format!("n{i}.other"),
        };
    }
}

/// The exported bytes imported (as `tcb import` reads them) and built;
/// panics if either step fails.
fn read_back(bytes: &[u8], container: Container) -> SourceClip {
    match tcb_io::gltf_import::import(bytes, None, None, "fuzz") {
        Ok(g) => g.doc.build().unwrap_or_else(|e| {
            panic!("an export that imports but does not build: {e} ({container:?})")
        }),
        Err(e) => panic!("an export that cannot be read back: {e} ({container:?})"),
    }
}

/// The times to compare at: the keys of both clips, 7 points between each
/// two of them, and a few edge times.
fn check_times(u: &mut Unstructured, clip: &SourceClip, back: &SourceClip) -> Vec<f64> {
    let mut times = clip.key_times();
    times.extend(back.key_times());
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut check: Vec<f64> = Vec::new();
    for w in times.windows(2) {
        check.extend((0..8).map(|i| w[0] + (w[1] - w[0]) * f64::from(i) / 8.0));
    }
    check.extend(times.last());
    check.extend(crate::edges::edge_times(u, &times, 16));
    check
}

/// Where each of `clip`'s tracks starts in `back`'s rows (glTF groups
/// channels by node); panics on a track not read back.
fn offsets_in(clip: &SourceClip, back: &SourceClip) -> Vec<usize> {
    clip.tracks()
        .iter()
        .map(|t| {
            let mut at = 0;
            for other in back.tracks() {
                if other.name == t.name {
                    return at;
                }
                at += other.data.kind().dim();
            }
            panic!("track {} not read back", t.name)
        })
        .collect()
}

/// How far `b` (read back) is from `a` (exported): the largest channel
/// difference relative to max(1, |a|), rotations up to sign; NaN if any
/// channel's difference is NaN.
fn read_back_error(a: &[f32], b: &[f32], kind: TrackKind) -> f64 {
    let d = |s: f32| {
        a.iter()
            .zip(b)
            .map(|(&x, &y)| f64::from((x - s * y).abs() / x.abs().max(1.0)))
            // NaN kept: a NaN read back is as far off as can be.
            .fold(0.0, |m: f64, x| if x.is_nan() || x > m { x } else { m })
    };
    if kind == TrackKind::Quat {
        let (p, n) = (d(1.0), d(-1.0));
        if p.is_nan() || n.is_nan() {
            f64::NAN
        } else {
            p.min(n)
        }
    } else {
        d(1.0)
    }
}
