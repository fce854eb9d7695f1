//! The bodies of the fuzz targets, shared by `fuzz_targets/` (cargo-fuzz,
//! `RUSTC_BOOTSTRAP=1 cargo fuzz run NAME`) and by the corpus replay test
//! (`crates/tcb-cli/tests/fuzz_corpus.rs`, stable `cargo test`), so the
//! findings stay guarded without nightly.
//!
//! Each body returns quietly on input the library rightly refuses and
//! panics on anything else that is wrong: a panic inside the library, or
//! the runtime disagreeing with the scalar reference (vector channels bit
//! for bit (as numbers: -0 equals 0), rotations within 1e-6, as `crates/tcb-runtime/tests/equivalence.rs`
//! holds them).

use arbitrary::{Arbitrary, Unstructured};
use std::sync::Arc;
use tcb_core::{
    Ends, Extrapolation, Hemisphere, Interp, RotationMode, TangentRule, TrackData, TrackKind,
};
use tcb_io::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};
use tcb_runtime::{BlendMask, Instance};

/// `tcb-clip/1` JSON: parse, build, then play what builds.
pub fn clip_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(doc) = ClipDoc::parse(text)
        && let Ok(clip) = doc.build()
    {
        play(&clip);
    }
}

/// BVH text: parse, convert in both rotation modes, build and play.
pub fn bvh(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(bvh) = tcb_io::bvh::Bvh::parse(text) else {
        return;
    };
    let _ = bvh.skeleton_with_end_sites();
    for mode in [RotationMode::Squad, RotationMode::Hermite] {
        if let Ok(doc) = bvh.to_clip_doc("fuzz", mode)
            && let Ok(clip) = doc.build()
        {
            play(&clip);
        }
    }
}

/// glTF or GLB bytes (no external buffers): import, build and play.
pub fn gltf(data: &[u8]) {
    if let Ok(g) = tcb_io::gltf_import::import(data, None, None, "fuzz")
        && let Ok(clip) = g.doc.build()
    {
        play(&clip);
    }
}

/// A structured clip (every kind, rule, end, ease, interpolation,
/// extrapolation and rotation mode, sane or not) and arbitrary times.
pub fn runtime(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(doc) = arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let mut times = Vec::new();
    while let Ok(t) = arbitrary_time(&mut u) {
        if times.len() == 64 {
            break;
        }
        times.push(t);
    }
    // Half the inputs (by the number of times, so that the corpus reads as
    // before) compile with exact squad velocities.
    let options = tcb_runtime::CompileOptions {
        exact_velocities: times.len() % 2 == 1,
        ..Default::default()
    };
    check(&clip, &times, &options);
}

/// Blending and additive layers with arbitrary weights (NaN, infinite,
/// negative, summing to zero) and masks: never a panic.
pub fn blend(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(doc) = arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let clip = Arc::new(tcb_runtime::Clip::compile(&clip));
    let velocities = bool::arbitrary(&mut u).unwrap_or(false);
    let make = || {
        let i = Instance::new(clip.clone());
        if velocities { i.with_velocities() } else { i }
    };
    let (mut a, mut b) = (make(), make());
    let (Ok(ta), Ok(tb)) = (arbitrary_time(&mut u), arbitrary_time(&mut u)) else {
        return;
    };
    let mut out = a.sample(ta).clone();
    b.sample(tb);
    let weight = |u: &mut Unstructured| arbitrary_f32(u).unwrap_or(0.5);
    let (wa, wb) = (weight(&mut u), weight(&mut u));
    let mask_weights: Vec<f32> = (0..clip.tracks().len()).map(|_| weight(&mut u)).collect();
    let mask = BlendMask::new(&clip, |t| mask_weights[t.index()]);
    let layers = [(a.pose(), wa), (b.pose(), wb)];
    tcb_runtime::blend::blend(&mut out, &layers, None).expect("same layout");
    tcb_runtime::blend::blend(&mut out, &layers, Some(&[&mask, &mask])).expect("same layout");
    tcb_runtime::blend::add(&mut out, a.pose(), b.pose(), wa, Some(&mask)).expect("same layout");
    tcb_runtime::blend::add(&mut out, b.pose(), a.pose(), wb, None).expect("same layout");
    // A mask count that does not match is an error, not a panic.
    assert!(tcb_runtime::blend::blend(&mut out, &layers, Some(&[&mask])).is_err());
}

/// `tcb reduce`'s input: a structured clip, sometimes with a skeleton whose
/// joints its tracks animate (for the `shell` metric), and arbitrary
/// options. Never a panic; a reduction that succeeds is within its
/// tolerance by its own measurement, and what it writes reads back and
/// builds.
pub fn reduce(data: &[u8]) {
    use tcb_core::skeleton::{Joint, Skeleton, Transform};
    use tcb_fit::{Knots, Metric, ReduceOptions, Tangents};
    let mut u = Unstructured::new(data);
    let Ok(mut doc) = arbitrary_doc(&mut u) else {
        return;
    };
    let skeleton = if bool::arbitrary(&mut u).unwrap_or(false) {
        let mut joints = Vec::new();
        for (i, track) in doc.tracks.iter_mut().enumerate() {
            let channel = match track.kind {
                TrackKind::Quat => "rotation",
                TrackKind::Vec3 if i % 2 == 0 => "translation",
                TrackKind::Vec3 => "scale",
                _ => "weight",
            };
            track.name = format!("j{i}.{channel}");
            let parent = match i {
                0 => None,
                _ => u.int_in_range(0..=i).ok().filter(|p| *p < i),
            };
            let [x, y, z, _] = value(&mut u).unwrap_or_default();
            joints.push(Joint {
                name: format!("j{i}"),
                parent,
                rest: Transform {
                    translation: glam::Vec3::new(x, y, z),
                    ..Transform::IDENTITY
                },
            });
        }
        Some(Skeleton { joints })
    } else {
        None
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let number = |u: &mut Unstructured| -> Option<f64> {
        match u.int_in_range(0..=3u8).unwrap_or(0) {
            0 => None,
            1 => f64::arbitrary(u).ok(),
            _ => Some(f64::from(u.int_in_range(1..=4096u16).unwrap_or(1)) / 1024.0),
        }
    };
    let options = ReduceOptions {
        tolerance: number(&mut u),
        shell: number(&mut u),
        metric: *u
            .choose(&[None, Some(Metric::Shell), Some(Metric::Value)])
            .unwrap_or(&None),
        rotation_tolerance: number(&mut u),
        knots: *u
            .choose(&[Knots::Track, Knots::Joint, Knots::Clip])
            .unwrap_or(&Knots::Track),
        tangents: *u
            .choose(&[Tangents::Explicit, Tangents::Derived, Tangents::Best])
            .unwrap_or(&Tangents::Best),
    };
    let input = tcb_fit::reduce::Input {
        doc: &doc,
        clip: &clip,
        skeleton: skeleton.as_ref(),
    };
    if let Ok(r) = tcb_fit::reduce(input, &options, &|_, _| {}) {
        // The worst is the largest error over its own limit (`value`:
        // rotations against the rotation tolerance, in degrees).
        assert!(
            r.worst.ratio <= 1.0,
            "reduced beyond its tolerance: {:?} ({:?})",
            r.worst,
            r.settings
        );
        let back = ClipDoc::parse(&r.doc.to_json()).expect("the reduced clip reads back");
        back.build().expect("the reduced clip builds");
    }
}

/// Play a clip that built at its key times, between them, beyond them and
/// at the awkward times, against the reference.
fn play(clip: &tcb_core::Clip) {
    let mut times = clip.key_times();
    times.truncate(200);
    if let Some((a, b)) = clip.time_range() {
        let mid: Vec<f64> = times.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        times.extend(mid);
        times.extend([a - 1.0, b + 1.0, b + 7.3 * (b - a)]);
    }
    times.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e300, 1e300]);
    check(clip, &times, &tcb_runtime::CompileOptions::default());
}

/// The runtime against the reference at `times`, played forward as given
/// and by a fresh instance per time (a seek), which must agree bit for bit.
fn check(clip: &tcb_core::Clip, times: &[f64], options: &tcb_runtime::CompileOptions) {
    let compiled = Arc::new(tcb_runtime::Clip::compile_with(clip, options));
    let n = clip.channel_count();
    let mut playing = Instance::new(compiled.clone()).with_velocities();
    let (mut got, mut got_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    let (mut want, mut want_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    for &t in times {
        let pose = playing.sample(t).clone();
        let mut fresh = Instance::new(compiled.clone()).with_velocities();
        assert!(
            same(pose.as_slice(), fresh.sample(t).as_slice()),
            "forward playback differs from a seek at {t}"
        );
        pose.write_row(&mut got, Some(&mut got_v));
        clip.sample_into(t, &mut want, Some(&mut want_v));
        let mut at = 0;
        for track in clip.tracks() {
            let dim = track.data.kind().dim();
            let r = at..at + dim;
            at += dim;
            if let TrackData::Quat(_) = track.data {
                assert_rotation(&got[r.clone()], &want[r], &track.name, t);
                continue;
            }
            // Where the reference itself is not finite (tangents that
            // overflow f32 make its curve NaN), the runtime may be better.
            for (what, got, want) in [("value", &got, &want), ("velocity", &got_v, &want_v)] {
                let (g, w) = (&got[r.clone()], &want[r.clone()]);
                assert!(
                    w.iter().any(|x| !x.is_finite()) || same(g, w),
                    "{} {what} at {t}: runtime {g:?}, reference {w:?}",
                    track.name
                );
            }
        }
    }
}

/// Equal as numbers (the equivalence tests' `==`: -0 equals 0), NaN
/// equal to any NaN.
fn same(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
}

/// Up to sign, within 1e-6 (relative above 1).
fn assert_rotation(got: &[f32], want: &[f32], name: &str, t: f64) {
    if want.iter().any(|x| !x.is_finite()) {
        return;
    }
    let close = |sign: f32| {
        got.iter()
            .zip(want)
            .all(|(g, w)| (g * sign - w).abs() <= 1e-6 * w.abs().max(1.0))
    };
    assert!(
        close(1.0) || close(-1.0),
        "{name} at {t}: runtime {got:?}, reference {want:?}"
    );
}

/// Mostly nice numbers (where the interesting paths are), sometimes any f32.
fn arbitrary_f32(u: &mut Unstructured) -> arbitrary::Result<f32> {
    Ok(match u.int_in_range(0..=7u8)? {
        0 => f32::arbitrary(u)?,
        _ => f32::from(i16::arbitrary(u)?) / 4096.0,
    })
}

/// Mostly times around the keys, sometimes anything (NaN and infinities included).
pub fn arbitrary_time(u: &mut Unstructured) -> arbitrary::Result<f64> {
    if u.is_empty() {
        return Err(arbitrary::Error::NotEnoughData);
    }
    Ok(match u.int_in_range(0..=7u8)? {
        0 => f64::arbitrary(u)?,
        1 => *u.choose(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0])?,
        _ => f64::from(i16::arbitrary(u)?) / 1024.0,
    })
}

fn some<'a, T>(
    u: &mut Unstructured<'a>,
    f: impl FnOnce(&mut Unstructured<'a>) -> arbitrary::Result<T>,
) -> arbitrary::Result<Option<T>> {
    Ok(if bool::arbitrary(u)? {
        Some(f(u)?)
    } else {
        None
    })
}

fn tcb3(u: &mut Unstructured) -> arbitrary::Result<[f64; 3]> {
    let mut x = || -> arbitrary::Result<f64> {
        Ok(match u.int_in_range(0..=7u8)? {
            0 => f64::arbitrary(u)?,
            _ => f64::from(i8::arbitrary(u)?) / 100.0,
        })
    };
    Ok([x()?, x()?, x()?])
}

// `bool::arbitrary` itself is not general enough over the lifetimes `some` asks for.
#[allow(clippy::redundant_closure)]
fn settings(u: &mut Unstructured) -> arbitrary::Result<SettingsDoc> {
    Ok(SettingsDoc {
        tangent_rule: some(u, |u| u.choose(TangentRule::ALL).copied())?,
        ends: some(u, |u| u.choose(Ends::ALL).copied())?,
        match_speed: some(u, |u| bool::arbitrary(u))?,
        continuity_fade: some(u, |u| bool::arbitrary(u))?,
        tcb: some(u, tcb3)?,
        pre: some(u, |u| u.choose(Extrapolation::ALL).copied())?,
        post: some(u, |u| u.choose(Extrapolation::ALL).copied())?,
        rotation: some(u, |u| u.choose(RotationMode::ALL).copied())?,
        hemisphere: some(u, |u| u.choose(Hemisphere::ALL).copied())?,
    })
}

fn value(u: &mut Unstructured) -> arbitrary::Result<[f32; 4]> {
    Ok([
        arbitrary_f32(u)?,
        arbitrary_f32(u)?,
        arbitrary_f32(u)?,
        arbitrary_f32(u)?,
    ])
}

/// A clip document of 1 to 6 tracks of 1 to 9 keys; `build` refuses what is invalid.
pub fn arbitrary_doc(u: &mut Unstructured) -> arbitrary::Result<ClipDoc> {
    let kinds = [
        TrackKind::Scalar,
        TrackKind::Vec2,
        TrackKind::Vec3,
        TrackKind::Vec4,
        TrackKind::Quat,
    ];
    let defaults = settings(u)?;
    let mut tracks = Vec::new();
    for i in 0..u.int_in_range(1..=6u8)? {
        let kind = *u.choose(&kinds)?;
        let n = u.int_in_range(1..=9usize)?;
        let mut t = f64::from(i8::arbitrary(u)?) / 8.0;
        let mut times = Vec::with_capacity(n);
        for _ in 0..n {
            times.push(t);
            t += match u.int_in_range(0..=15u8)? {
                0 => f64::arbitrary(u)?,
                1 => 1e-9,
                _ => f64::from(u8::arbitrary(u)?) / 64.0 + 1.0 / 128.0,
            };
        }
        let values = (0..n)
            .map(|_| value(u))
            .collect::<arbitrary::Result<Vec<_>>>()?;
        let keys = if bool::arbitrary(u)? {
            (0..n)
                .map(|_| {
                    Ok(KeyDoc {
                        tcb: some(u, tcb3)?,
                        ease: some(u, |u| {
                            Ok([
                                f64::from(u8::arbitrary(u)?) / 128.0,
                                f64::from(u8::arbitrary(u)?) / 128.0,
                            ])
                        })?,
                        interp: some(u, |u| u.choose(Interp::ALL).copied())?,
                        tangent_in: some(u, value)?,
                        tangent_out: some(u, value)?,
                    })
                })
                .collect::<arbitrary::Result<Vec<_>>>()?
        } else {
            Vec::new()
        };
        tracks.push(TrackDoc {
            name: format!("t{i}"),
            kind,
            times,
            values,
            keys,
            settings: settings(u)?,
        });
    }
    Ok(ClipDoc {
        name: "fuzz".into(),
        defaults,
        tracks,
        skeleton: None,
    })
}
