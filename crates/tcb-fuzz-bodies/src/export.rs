//! The `export` target: a structured clip exported to glTF, imported back
//! (as `tcb import` reads it) and compared with what the export reported.

use arbitrary::Unstructured;
use tcb_core::{NamedTrack, SourceClip, TrackKind};
use tcb_io::ClipDoc;
use tcb_io::gltf_export::{Container, ExportOptions, ExportReport, export as export_gltf};

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
    let Some(read) = export_and_read_back(&clip, container, &options) else {
        return;
    };
    let (back, report) = read.unwrap_or_else(|e| panic!("{e} ({container:?})"));
    assert_eq!(
        back.tracks().len(),
        clip.tracks().len(),
        "tracks read back ({container:?})"
    );
    let check = check_times(&mut u, &clip, &back);
    let misses = read_back_misses(&clip, &back, &report, |_| check.clone());
    assert!(
        misses.is_empty(),
        "read back beyond the report ({container:?}, max_error {max_error}): {misses:#?}"
    );
}

/// `clip` exported as `container` with `options`, imported back (as `tcb
/// import` reads it) and built, with the export's report: `None` where the
/// export refuses the clip (it must say why), `Err` where what it wrote
/// does not import or build.
pub fn export_and_read_back(
    clip: &SourceClip,
    container: Container,
    options: &ExportOptions,
) -> Option<Result<(SourceClip, ExportReport), String>> {
    let (bytes, report) = match export_gltf(clip, None, container, options) {
        Ok(r) => r,
        Err(e) => {
            assert!(!e.to_string().is_empty(), "a refusal without a message");
            return None;
        }
    };
    let back = tcb_io::gltf_import::import(&bytes, None, None, "fuzz")
        .map_err(|e| format!("an export that cannot be read back: {e}"))
        .and_then(|g| {
            g.doc
                .build()
                .map_err(|e| format!("an export that imports but does not build: {e}"))
        });
    Some(back.map(|back| (back, report)))
}

/// The tracks of `clip` that `back` (its export, read back) does not follow
/// within the error `report` states for them plus 1e-5 (an exact track:
/// within 1e-5): one line each, at its worst time. Each track is compared
/// at those of `times(track)` inside its keys where its value is finite,
/// each channel relative to max(1, |value|), rotations up to sign, a NaN
/// difference the worst; tracks are paired with `back`'s and with the
/// report's by name (glTF groups channels by node, so `back`'s order is
/// not the clip's).
pub fn read_back_misses(
    clip: &SourceClip,
    back: &SourceClip,
    report: &ExportReport,
    times: impl Fn(&NamedTrack) -> Vec<f64>,
) -> Vec<String> {
    let mut misses = Vec::new();
    for track in clip.tracks() {
        let Some(read) = back.tracks().iter().find(|o| o.name == track.name) else {
            misses.push(format!("{}: not read back", track.name));
            continue;
        };
        let stated = report
            .tracks
            .iter()
            .find(|r| r.name == track.name)
            .expect("every track reported")
            .error();
        let (kind, keys) = (track.data.kind(), track.data.times());
        let inside = keys[0]..=keys[keys.len() - 1];
        let (mut a, mut b) = ([0.0f32; 4], [0.0f32; 4]);
        let dim = kind.dim();
        let mut worst: Option<(f64, f64, [f32; 4], [f32; 4])> = None;
        for t in times(track) {
            if !inside.contains(&t) {
                continue;
            }
            track.data.sample_into(t, &mut a[..dim], None);
            if a[..dim].iter().any(|x| !x.is_finite()) {
                continue;
            }
            read.data.sample_into(t, &mut b[..dim], None);
            let e = read_back_error(&a[..dim], &b[..dim], kind);
            if worst.is_none_or(|(w, ..)| e.is_nan() || e > w) {
                worst = Some((e, t, a, b));
            }
        }
        if let Some((e, t, a, b)) = worst
            && (e.is_nan() || e > stated.unwrap_or(0.0) + 1e-5)
        {
            misses.push(format!(
                "{} at {t}: {:?} read back as {:?}, off by {e:e}, reported {stated:?}",
                track.name,
                &a[..dim],
                &b[..dim]
            ));
        }
    }
    misses
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
