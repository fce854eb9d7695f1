//! Issue 11's API point, tried on every public constructor and field of
//! tcb-core that existed before it: whatever a caller passes, a
//! constructor returns an error or a value whose use (sampling at any
//! time, composing a skeleton) does not panic.

use glam::{Affine3A, DAffine3, Quat, Vec3};
use tcb_core::ease::SegmentEase;
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_core::{
    Ease, Ends, Extrapolation, Hemisphere, Interp, KeyParams, NamedTrack, RotationMode,
    RotationTrack, SourceClip, TangentRule, Tcb, Track, TrackData, TrackSettings,
};

const TIMES: [f64; 4] = [f64::NAN, f64::INFINITY, -1e300, 1e300];

fn every_setting() -> Vec<TrackSettings> {
    let mut out = Vec::new();
    for &tangent_rule in TangentRule::ALL {
        for &ends in Ends::ALL {
            for &pre in Extrapolation::ALL {
                for &rotation in RotationMode::ALL {
                    for &hemisphere in Hemisphere::ALL {
                        for (match_speed, continuity_fade) in [(false, true), (true, false)] {
                            out.push(TrackSettings {
                                tangent_rule,
                                ends,
                                match_speed,
                                continuity_fade,
                                pre,
                                post: Extrapolation::ALL[out.len() % Extrapolation::ALL.len()],
                                rotation,
                                hemisphere,
                            });
                        }
                    }
                }
            }
        }
    }
    out
}

/// Keys of every kind a caller could write, sane or not.
fn odd_keys<V: Copy>(tangent: V, n: usize) -> Vec<Vec<KeyParams<V>>> {
    let key = |tcb: Tcb, ease: Ease, interp: Interp, t: Option<V>| KeyParams {
        tcb,
        ease,
        interp,
        tangent_in: t,
        tangent_out: t,
    };
    vec![
        Vec::new(),
        vec![KeyParams::default(); n + 1],
        vec![
            key(
                Tcb::new(f64::NAN, 0.0, 0.0),
                Ease::NONE,
                Interp::Curve,
                None
            );
            n
        ],
        vec![
            key(
                Tcb::new(1e300, -1e300, 1e300),
                Ease::NONE,
                Interp::Step,
                None
            );
            n
        ],
        vec![
            key(
                Tcb::DEFAULT,
                Ease {
                    to: -1.0,
                    from: 2.0
                },
                Interp::Linear,
                None
            );
            n
        ],
        vec![
            key(
                Tcb::DEFAULT,
                Ease {
                    to: f64::NAN,
                    from: 0.5
                },
                Interp::Curve,
                None
            );
            n
        ],
        vec![
            key(
                Tcb::DEFAULT,
                Ease { to: 1.0, from: 1.0 },
                Interp::Curve,
                Some(tangent)
            );
            n
        ],
    ]
}

/// `Track::new` and `RotationTrack::new` under every setting and odd keys:
/// an error, or a track that samples anywhere without a panic.
#[test]
fn tracks_refuse_or_sample() {
    let times = vec![0.0, 1.0, 1.0 + 1e-12, 3.0];
    let bad_times = [
        vec![],
        vec![0.0],
        vec![0.0, f64::NAN],
        vec![1.0, 0.0],
        vec![0.0, 1e308, -1e308],
    ];
    for s in every_setting() {
        for keys in odd_keys(Vec3::splat(f32::MAX), 4) {
            let values = vec![Vec3::ZERO, Vec3::X, Vec3::MAX, Vec3::ZERO];
            if let Ok(t) = Track::new(times.clone(), values, keys, &s) {
                for time in TIMES {
                    let _ = t.sample_with_velocity(time);
                }
            }
        }
        for keys in odd_keys(Quat::from_xyzw(1e30, 0.0, 0.0, 1.0), 4) {
            let q = vec![
                Quat::IDENTITY,
                Quat::from_rotation_x(3.1),
                Quat::from_xyzw(0.0, 0.0, 0.0, -1.0),
                Quat::IDENTITY,
            ];
            if let Ok(t) = RotationTrack::new(times.clone(), q, keys, &s) {
                for time in TIMES {
                    let _ = t.sample_with_velocity(time);
                }
            }
        }
        for t in &bad_times {
            let n = t.len();
            assert!(
                Track::new(t.clone(), vec![1.0f32; n], Vec::new(), &s).is_err(),
                "{t:?}"
            );
            assert!(
                RotationTrack::new(t.clone(), vec![Quat::IDENTITY; n], Vec::new(), &s).is_err(),
                "{t:?}"
            );
        }
        assert!(Track::new(vec![0.0, 1.0], vec![1.0f32, f32::NAN], Vec::new(), &s).is_err());
        assert!(Track::new(vec![0.0, 1.0], vec![1.0f32], Vec::new(), &s).is_err());
        assert!(
            RotationTrack::new(
                vec![0.0, 1.0],
                vec![Quat::IDENTITY, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)],
                Vec::new(),
                &s
            )
            .is_err()
        );
    }
}

/// `tcb_core::SourceClip` (once public fields): `SourceClip::new` refuses a repeated
/// track name, the one invariant its fields skipped.
#[test]
fn clips_refuse_repeated_names() {
    let t = || NamedTrack {
        name: "x".into(),
        data: TrackData::Scalar(
            Track::new(
                vec![0.0, 1.0],
                vec![0.0, 1.0],
                Vec::new(),
                &TrackSettings::default(),
            )
            .expect("valid"),
        ),
    };
    let e = SourceClip::new("c", vec![t(), t()]).unwrap_err();
    assert_eq!(e.0, "x");
    let clip = SourceClip::new("c", vec![t()]).expect("one track");
    let mut row = [0.0f32; 1];
    for time in TIMES {
        clip.sample_into(time, &mut row, None);
    }
    // Rows of the wrong length are filled as far as they go.
    clip.sample_into(0.5, &mut [], Some(&mut [0.0; 7]));
}

/// `SegmentEase` (once public fields that skipped its normalization):
/// `new` clamps to [0, 1] and maps NaN to 0, so `apply` stays in [0, 1].
#[test]
fn segment_eases_are_normalized() {
    for (a, e) in [
        (f64::NAN, 0.5),
        (-3.0, 9.0),
        (f64::INFINITY, f64::NEG_INFINITY),
        (0.7, 0.7),
    ] {
        let ease = SegmentEase::new(a, e);
        assert!((0.0..=1.0).contains(&ease.from()) && (0.0..=1.0).contains(&ease.to()));
        for u in [0.0, 0.3, 0.5, 1.0] {
            let (s, ds) = ease.apply(u);
            assert!(
                (0.0..=1.0).contains(&s) && ds.is_finite(),
                "{a} {e} {u}: {s} {ds}"
            );
        }
    }
}

/// A skeleton's parents come before their joints: a parent at or after
/// its joint (itself, a loop, one not there) is refused by the constructor
/// and by `push`, with the joint named; valid skeletons compose with slices
/// of any length without a panic.
#[test]
fn skeletons_keep_parents_before_children() {
    let joint = |parent| Joint {
        name: "j".into(),
        parent,
        rest: Transform::IDENTITY,
    };
    for (joints, at) in [
        (vec![joint(Some(0))], 0),
        (vec![joint(None), joint(Some(7))], 1),
        (vec![joint(None), joint(Some(2)), joint(Some(1))], 1),
    ] {
        let e = Skeleton::new(joints).unwrap_err();
        assert_eq!(e.joint, at);
        assert!(
            e.to_string().contains("parents before their children"),
            "{e}"
        );
    }
    let mut s = Skeleton::new(vec![joint(None), joint(Some(0)), joint(Some(1))]).unwrap();
    assert!(s.push(joint(Some(3))).is_err());
    assert_eq!(s.push(joint(Some(2))), Ok(3));
    assert_eq!(s.joints().len(), 4);
    for n in [0, 1, 4, 9] {
        let local = vec![Transform::IDENTITY; n];
        s.model_transforms(&local, &mut vec![Affine3A::IDENTITY; 4]);
        s.model_transforms_f64(&local, &mut vec![DAffine3::IDENTITY; n / 2]);
    }
}
