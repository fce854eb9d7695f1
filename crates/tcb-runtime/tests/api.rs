//! Issue 11's API point, tried on every public constructor and field the
//! runtime had before it: none makes a value whose later use panics or
//! lies. Handles of another clip, accessors of the wrong kind, masks and
//! layers of another layout, rigs with bad rest values, playback speeds
//! that are not numbers, and slices of the wrong length are refused
//! (`None`, `Err`) or do what the docs say.

use glam::{Quat, Vec3};
use std::sync::Arc;
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_core::{NamedTrack, RotationTrack, Track, TrackData, TrackKind, TrackSettings};
use tcb_runtime::blend::{BlendError, add};
use tcb_runtime::{
    BlendMask, Clip, CompileOptions, Instance, Playback, Pose, Rig, RigError, RigTrack,
    SkeletonBinding, blend,
};

fn clip(names: &[&str]) -> Arc<Clip> {
    let t = vec![0.0, 1.0, 2.0];
    let tracks = names
        .iter()
        .map(|n| NamedTrack {
            name: (*n).into(),
            data: if n.ends_with(".rotation") {
                TrackData::Quat(
                    RotationTrack::new(
                        t.clone(),
                        vec![Quat::IDENTITY, Quat::from_rotation_z(1.0), Quat::IDENTITY],
                        Vec::new(),
                        &TrackSettings::default(),
                    )
                    .expect("valid"),
                )
            } else {
                TrackData::Vec3(
                    Track::new(
                        t.clone(),
                        vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                        Vec::new(),
                        &TrackSettings::default(),
                    )
                    .expect("valid"),
                )
            },
        })
        .collect();
    Arc::new(Clip::compile(
        &tcb_core::SourceClip::new("c", tracks).expect("unique names"),
    ))
}

/// A `TrackId` (once `TrackId(pub usize)`) of one clip says nothing about
/// another clip's pose, and an accessor of the wrong kind (once
/// `Pose::vec3` on a rotation returned x, y, z) is `None`.
#[test]
fn handles_of_another_clip_and_accessors_of_the_wrong_kind_are_none() {
    let a = clip(&["a.translation", "a.rotation"]);
    let b = clip(&["b.rotation", "b.translation", "c.translation"]);
    let mut ia = Instance::new(a.clone()).with_velocities();
    let mut ib = Instance::new(b.clone());
    let (pa, pb) = (ia.sample(0.5).clone(), ib.sample(0.5).clone());
    let (ta, ra) = (
        a.track("a.translation").unwrap(),
        a.track("a.rotation").unwrap(),
    );
    assert!(pa.vec3(ta).is_some() && pa.quat(ra).is_some());
    assert_eq!(pa.quat(ta), None);
    assert_eq!(pa.vec3(ra), None);
    assert_eq!(pa.scalar(ta), None);
    assert_eq!(pa.vec4(ra), None);
    for id in a.layout().ids() {
        assert_eq!(pb.vec3(id), None);
        assert_eq!(pb.quat(id), None);
        assert_eq!(pb.quat_velocity(id), None);
        assert_eq!(pb.angular_velocity(id), None);
        assert!(b.layout().slot(id).is_none());
    }
    // No velocities sampled: none to read.
    let c = b.track("c.translation").unwrap();
    assert_eq!(pb.vec3_velocity(c), None);
    assert!(pa.vec3_velocity(ta).is_some());
    assert_eq!(a.quantization_error(ta), Some(0.0));
    assert_eq!(b.quantization_error(ta), None);
}

/// `write_row` writes what fits (once it indexed past the end).
#[test]
fn rows_of_any_length() {
    let a = clip(&["a.translation", "a.rotation"]);
    let mut i = Instance::new(a).with_velocities();
    let pose = i.sample(0.5);
    let mut short = [f32::NAN; 2];
    pose.write_row(&mut short, Some(&mut []));
    assert!(short.iter().all(|x| x.is_finite()));
    let mut long = [f32::NAN; 20];
    pose.write_row(&mut long, None);
    assert!(long[..7].iter().all(|x| x.is_finite()) && long[7..].iter().all(|x| x.is_nan()));
}

/// Layers and masks of another layout are errors, never silently skipped.
#[test]
fn layers_and_masks_of_another_layout_are_errors() {
    let a = clip(&["a.translation", "a.rotation"]);
    let b = clip(&["b.rotation"]);
    let (mut ia, mut ib) = (Instance::new(a.clone()), Instance::new(b.clone()));
    let mut out = Pose::new(&a);
    let (pa, pb) = (ia.sample(0.2).clone(), ib.sample(0.2).clone());
    assert_eq!(
        blend(&mut out, &[(&pa, 0.5), (&pb, 0.5)], None),
        Err(BlendError::Layout { layer: 1 })
    );
    let mask_b = BlendMask::new(&b, |_| 1.0);
    let mask_a = BlendMask::new(&a, |_| f32::NAN);
    assert!(blend(&mut out, &[(&pa, 1.0)], Some(&[&mask_b])).is_err());
    assert!(blend(&mut out, &[(&pa, 1.0)], Some(&[&mask_a, &mask_a])).is_err());
    assert!(mask_a.times(&mask_b).is_err());
    assert!(add(&mut out, &pa, &pb, 1.0, None).is_err());
    assert!(add(&mut out, &pa, &pa, 1.0, Some(&mask_b)).is_err());
    // NaN weights are the caller's numbers, not a panic.
    blend(&mut out, &[(&pa, f32::NAN)], Some(&[&mask_a])).unwrap();
}

/// A rig refuses repeated names and rest values that are not finite or
/// not a rotation, and a clip whose track has the rig's name but another
/// kind; playback refuses speeds that are not numbers.
#[test]
fn rigs_and_playback_refuse_bad_values() {
    let track = |name: &str, kind, rest| RigTrack {
        name: name.into(),
        kind,
        rest,
    };
    assert!(matches!(
        Rig::new(vec![
            track("a", TrackKind::Vec3, [0.0; 4]),
            track("a", TrackKind::Vec3, [0.0; 4])
        ]),
        Err(RigError::Duplicate(_))
    ));
    assert!(matches!(
        Rig::new(vec![track("a", TrackKind::Vec3, [f32::NAN, 0.0, 0.0, 0.0])]),
        Err(RigError::BadRest(_))
    ));
    assert!(matches!(
        Rig::new(vec![track("a", TrackKind::Quat, [0.0; 4])]),
        Err(RigError::BadRest(_))
    ));
    let rig = Arc::new(
        Rig::new(vec![track("a.rotation", TrackKind::Vec3, [0.0; 4])]).expect("a valid rig"),
    );
    assert!(Instance::with_rig(clip(&["a.rotation"]), &rig).is_err());
    let mut i = Instance::new(clip(&["a.rotation"]));
    for speed in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(i.set_playback(Playback::Loop, speed).is_err());
    }
    assert_eq!(i.playback(), (Playback::Clip, 1.0));
    i.set_playback(Playback::PingPong, -2.5).unwrap();
    for t in [f64::NAN, f64::INFINITY, -1e300, 1e300] {
        i.sample(t);
    }
}

/// A skeleton whose parents are not before their joints cannot be made
/// (`Skeleton::new` refuses it); one that names a joint twice or tracks of
/// other kinds still binds and composes without a panic, into slices of
/// any length.
#[test]
fn skeletons_of_any_shape_bind_and_compose() {
    let a = clip(&["a.translation", "b.rotation", "c.rotation"]);
    let joint = |name: &str, parent| Joint {
        name: name.into(),
        parent,
        rest: Transform::IDENTITY,
    };
    assert!(Skeleton::new(vec![joint("a", Some(5)), joint("b", None)]).is_err());
    let skeleton = Skeleton::new(vec![
        joint("c", None),
        joint("b", Some(0)),
        joint("a", Some(0)),
        joint("a", Some(1)),
    ])
    .unwrap();
    let binding = SkeletonBinding::new(skeleton, &a);
    let mut i = Instance::new(a);
    let pose = i.sample(0.7);
    for n in [0, 2, 4, 9] {
        let mut local = vec![Transform::IDENTITY; n];
        let mut model = vec![glam::Affine3A::IDENTITY; n.saturating_sub(1)];
        // Slices of another length than the 4 joints are refused.
        assert!(
            binding
                .model_transforms(pose, &mut local, &mut model)
                .is_err()
        );
    }
}

/// Quantized compilation of values spanning all of f32 (the range
/// overflows f64 nowhere, and f32 per channel) stays finite.
#[test]
fn quantizing_extreme_ranges() {
    let t = vec![0.0, 1.0];
    let v = Track::new(
        t,
        vec![Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)],
        Vec::new(),
        &TrackSettings::default(),
    )
    .expect("finite values");
    let src = tcb_core::SourceClip::new(
        "q",
        vec![NamedTrack {
            name: "v".into(),
            data: TrackData::Vec3(v),
        }],
    )
    .expect("one track");
    let c = Arc::new(Clip::compile_with(
        &src,
        &CompileOptions::default().quantize(true),
    ));
    let id = c.track("v").unwrap();
    let plain = Arc::new(Clip::compile(&src));
    keeps_its_bound(&c, &plain, id);
}

/// Issue 29, class 4: a quantized track samples within the bound it states
/// (finite), or is kept in f32 and says so (`Clip::is_quantized`); a NaN or
/// infinite bound is never dropped by a `max`.
fn keeps_its_bound(q: &Arc<Clip>, plain: &Arc<Clip>, id: tcb_runtime::TrackId) {
    let bound = q.quantization_error(id).unwrap();
    assert!(bound.is_finite(), "stated bound {bound}");
    let (mut a, mut b) = (Instance::new(q.clone()), Instance::new(plain.clone()));
    for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
        let (x, y) = (a.sample(t).vec3(id).unwrap(), b.sample(t).vec3(id).unwrap());
        if !y.is_finite() {
            continue; // tangents beyond f32 (max - min of two keys): no f32 value to keep
        }
        assert!(x.is_finite(), "at {t}: {x} (f32: {y})");
        let off = (x - y).abs().max_element();
        assert!(off <= bound * 1.0001, "at {t}: {off} off, bound {bound}");
    }
    if q.is_quantized(id) == Some(false) {
        assert_eq!(bound, 0.0, "kept in f32: no quantization error");
    }
}

/// Ranges beyond f32 on a loose lane and in a group: each track samples
/// within its stated bound or is kept in f32.
#[test]
fn quantizing_ranges_beyond_f32() {
    let times = vec![0.0, 0.25, 0.75, 1.0];
    let track = |name: String, v: [f32; 4]| NamedTrack {
        name,
        data: TrackData::Vec3(
            Track::new(
                times.clone(),
                v.map(Vec3::splat).to_vec(),
                Vec::new(),
                &TrackSettings::default(),
            )
            .expect("finite values"),
        ),
    };
    // A range of 3.6e38 (beyond f32::MAX) whose chords and tangents are not.
    let extreme = [-1.8e38, 0.0, 1.8e38, 1.8e38];
    for others in [0, 3] {
        // One track alone is a loose lane; with 3 more (12 channels) a group.
        let mut tracks = vec![track("v".into(), extreme)];
        tracks.extend((0..others).map(|i| track(format!("o{i}"), [0.0, 1.0, 2.0, 1.0])));
        let src = tcb_core::SourceClip::new("q", tracks).expect("unique names");
        let q = Arc::new(Clip::compile_with(
            &src,
            &CompileOptions::default().quantize(true),
        ));
        let plain = Arc::new(Clip::compile(&src));
        for id in q.layout().ids() {
            keeps_its_bound(&q, &plain, id);
        }
    }
}

/// Sampling into the caller's slice: the pose's channels in its tracks'
/// order (the rig's with a rig), as `write_row` gives them; another length
/// is an error and nothing is sampled.
#[test]
fn sampling_into_a_callers_slice() {
    let c = clip(&["a.position", "b.rotation", "c.position"]);
    let mut inst = Instance::new(c.clone());
    let mut out = vec![f32::NAN; c.channel_count()];
    inst.sample_to(0.4, &mut out).unwrap();
    let mut want = vec![0.0; c.channel_count()];
    Instance::new(c.clone())
        .sample(0.4)
        .write_row(&mut want, None);
    assert_eq!(out, want);
    let e = inst.sample_to(1.5, &mut out[..9]).unwrap_err();
    assert_eq!((e.given, e.want), (9, 10));
    assert_eq!(out, want, "nothing written");
    // Through a rig: its order, with a track the clip lacks at its rest value.
    let mut tracks = Rig::from_clip(&c).unwrap().tracks().to_vec();
    tracks.insert(
        0,
        RigTrack {
            name: "extra".into(),
            kind: TrackKind::Scalar,
            rest: [7.0, 0.0, 0.0, 0.0],
        },
    );
    let rig = Arc::new(Rig::new(tracks).unwrap());
    let mut r = Instance::with_rig(c.clone(), &rig).unwrap();
    let mut row = vec![0.0; 11];
    r.sample_to(0.4, &mut row).unwrap();
    assert_eq!(row[0], 7.0);
    assert_eq!(row[1..], want[..]);
}
