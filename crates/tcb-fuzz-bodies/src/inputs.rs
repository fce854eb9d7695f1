//! Arbitrary inputs the targets share: clips (as documents), times,
//! values, `tcb reduce`'s input; and the comparisons they check with.
//! (A module of its own, so that the targets' modules import it and the
//! crate root re-exports them, one way.)

use arbitrary::{Arbitrary, Unstructured};
use tcb_core::{Ends, Extrapolation, Hemisphere, Interp, RotationMode, TangentRule, TrackKind};
use tcb_io::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};

/// Equal as numbers (the equivalence tests' `==`: -0 equals 0), NaN
/// equal to any NaN.
pub(crate) fn same(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
}

/// Up to sign, within 1e-6 (relative above 1).
pub(crate) fn assert_rotation(got: &[f32], want: &[f32], name: &str, t: f64) {
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

/// A rotation's velocity (`[value, velocity]` of the runtime and of the
/// reference) against the reference's, as [`assert_rotation`] holds its
/// value: the same sign (a quaternion and its negation are one rotation),
/// within 1e-4 of the larger of 1, the velocity's largest component and
/// `rate`, the key rate times the playback speed (per second of play).
/// An error of the contract's size in the keys' rows moves a velocity by
/// about `rate` times it.
pub(crate) fn assert_rotation_velocity(
    [got, got_v]: [&[f32]; 2],
    [want, want_v]: [&[f32]; 2],
    rate: f64,
    name: &str,
    t: f64,
) {
    if want.iter().chain(want_v).any(|x| !x.is_finite()) || !rate.is_finite() {
        return;
    }
    let dot: f32 = got.iter().zip(want).map(|(g, w)| g * w).sum();
    let sign = if dot < 0.0 { -1.0 } else { 1.0 };
    let largest = want_v.iter().fold(1.0f64, |m, w| m.max(f64::from(w.abs())));
    let allowed = 1e-4 * largest.max(rate);
    assert!(
        got_v
            .iter()
            .zip(want_v)
            .all(|(g, w)| f64::from(g * sign - w).abs() <= allowed),
        "{name} at {t}: runtime velocity {got_v:?}, reference {want_v:?} (allowed {allowed:e})"
    );
}

/// Mostly nice numbers (where the interesting paths are), sometimes any f32.
pub(crate) fn arbitrary_f32(u: &mut Unstructured) -> arbitrary::Result<f32> {
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

pub(crate) fn some<'a, T>(
    u: &mut Unstructured<'a>,
    f: impl FnOnce(&mut Unstructured<'a>) -> arbitrary::Result<T>,
) -> arbitrary::Result<Option<T>> {
    Ok(if bool::arbitrary(u)? {
        Some(f(u)?)
    } else {
        None
    })
}

pub(crate) fn tcb3(u: &mut Unstructured) -> arbitrary::Result<[f64; 3]> {
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
pub(crate) fn settings(u: &mut Unstructured) -> arbitrary::Result<SettingsDoc> {
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

pub(crate) fn value(u: &mut Unstructured) -> arbitrary::Result<[f32; 4]> {
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
    let mut tracks: Vec<TrackDoc> = Vec::new();
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
        // Now and then the key times of the track before (a shared grid),
        // or one value held (a constant track, which a reduced clip keeps
        // at 2 keys and the compiler may move into a group's free lane).
        if let Some(before) = tracks.last().filter(|_| u.ratio(1, 4u8).unwrap_or(false)) {
            times.clone_from(&before.times);
        }
        let n = times.len();
        let mut values = (0..n)
            .map(|_| value(u))
            .collect::<arbitrary::Result<Vec<_>>>()?;
        if u.ratio(1, 4u8)? {
            let first = values[0];
            values.fill(first);
        }
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

/// `tcb reduce`'s input, as the `reduce` and `reduce_readback` targets
/// draw it: a structured clip (built), sometimes a skeleton whose joints
/// its tracks animate, and arbitrary options.
pub(crate) type ReduceInput = (
    ClipDoc,
    tcb_core::SourceClip,
    Option<tcb_core::skeleton::Skeleton>,
    tcb_fit::ReduceOptions,
);

pub(crate) fn reduce_input(u: &mut Unstructured) -> Option<ReduceInput> {
    use tcb_fit::{Knots, Metric, ReduceOptions, Speed, Tangents};
    let mut doc = arbitrary_doc(u).ok()?;
    let skeleton = arbitrary_skeleton(u, &mut doc);
    let clip = doc.build().ok()?;
    let number = option_number;
    let options = ReduceOptions::default()
        .tolerance(number(u))
        .shell(number(u))
        .metric(
            *u.choose(&[None, Some(Metric::Shell), Some(Metric::Value)])
                .unwrap_or(&None),
        )
        .rotation_tolerance(number(u))
        .knots(
            *u.choose(&[Knots::Track, Knots::Joint, Knots::Clip])
                .unwrap_or(&Knots::Track),
        )
        .tangents(
            *u.choose(&[Tangents::Explicit, Tangents::Derived, Tangents::Best])
                .unwrap_or(&Tangents::Best),
        )
        .speed(
            *u.choose(&[Speed::Balanced, Speed::NeverSlower, Speed::FewestBytes])
                .unwrap_or(&Speed::Balanced),
        );
    Some((doc, clip, skeleton, options))
}

/// Sometimes (else `None`) a skeleton whose joints `doc`'s tracks animate:
/// track `i` renamed `j{i}.rotation`, `.translation`, `.scale` or
/// `.weight` by its kind, joint `j{i}` under an earlier joint at a drawn
/// rest offset.
pub(crate) fn arbitrary_skeleton(
    u: &mut Unstructured,
    doc: &mut ClipDoc,
) -> Option<tcb_core::skeleton::Skeleton> {
    use tcb_core::skeleton::{Joint, Skeleton, Transform};
    if bool::arbitrary(u).unwrap_or(false) {
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
            let [x, y, z, _] = value(u).unwrap_or_default();
            joints.push(Joint {
                name: format!("j{i}"),
                parent,
                rest: Transform {
                    translation: glam::Vec3::new(x, y, z),
                    ..Transform::IDENTITY
                },
            });
        }
        Some(Skeleton::new(joints).unwrap())
    } else {
        None
    }
}

/// An option's number: none (the default), any f64, or one of 1/1024 to 4.
pub(crate) fn option_number(u: &mut Unstructured) -> Option<f64> {
    match u.int_in_range(0..=3u8).unwrap_or(0) {
        0 => None,
        1 => f64::arbitrary(u).ok(),
        _ => Some(f64::from(u.int_in_range(1..=4096u16).unwrap_or(1)) / 1024.0),
    }
}

/// `played` measured afresh against `clip` (compiled) at every check time
/// of the contract, by the metric and values of `settings` (`shell` with
/// `skeleton`, else `value`): what the `reduce_readback` and `compress`
/// targets hold a written clip to.
pub(crate) fn measure_again(
    clip: &tcb_core::SourceClip,
    skeleton: Option<&tcb_core::skeleton::Skeleton>,
    played: &std::sync::Arc<tcb_runtime::Clip>,
    settings: &tcb_fit::reduce::Settings,
) -> tcb_fit::metric::Measured {
    use tcb_fit::metric;
    let reference = std::sync::Arc::new(tcb_runtime::Clip::compile(clip));
    let times = metric::check_times(clip);
    let s = settings;
    match (s.metric, skeleton) {
        (tcb_fit::Metric::Shell, Some(sk)) => {
            metric::shell_error(sk, &reference, played, &times, s.shell, s.tolerance)
        }
        _ => metric::value_error(
            clip,
            &metric::play(&reference, &times),
            played,
            &times,
            s.tolerance,
            s.rotation_tolerance,
        ),
    }
}
