//! Poses in rig order: two different clips of the CMU rig (the dense clip,
//! and a copy whose root translation has its own key times, one rotation in
//! `hermite` mode and one joint's rotation missing) blend, cross-fade and
//! add as the reference samples blended by hand say.

use glam::{DQuat, DVec4, Quat};
use std::sync::Arc;
use tcb_core::{RotationMode, TrackKind};
use tcb_runtime::blend::{BlendError, add};
use tcb_runtime::{BlendMask, Clip, Instance, Rig, RigError, TrackId, blend};

const BVH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
const MISSING: &str = "LeftArm.rotation";

struct Setup {
    rig: Arc<Rig>,
    a: tcb_core::SourceClip,
    b: tcb_core::SourceClip,
    ca: Arc<Clip>,
    cb: Arc<Clip>,
}

fn setup() -> Setup {
    let loaded = tcb_io::load(BVH).unwrap();
    let rig = Arc::new(Rig::from_skeleton(loaded.skeleton.as_ref().unwrap()).unwrap());
    let mut doc = loaded.doc.clone();
    // Only the first 400 frames, to keep the test quick.
    for t in &mut doc.tracks {
        t.times.truncate(400);
        t.values.truncate(400);
        t.keys.truncate(400);
    }
    let a = doc.build().unwrap();
    let mut other = doc.clone();
    other.tracks.retain(|t| t.name != MISSING);
    let root = &mut other.tracks[0];
    assert_eq!(root.name, "Hips.translation");
    let keep: Vec<usize> = (0..root.times.len()).step_by(3).collect();
    root.times = keep.iter().map(|&i| root.times[i]).collect();
    root.values = keep.iter().map(|&i| root.values[i]).collect();
    let spine = other
        .tracks
        .iter_mut()
        .find(|t| t.name == "Spine.rotation")
        .unwrap();
    spine.settings.rotation = Some(RotationMode::Hermite);
    let b = other.build().unwrap();
    let (ca, cb) = (Arc::new(Clip::compile(&a)), Arc::new(Clip::compile(&b)));
    assert_ne!(
        ca.layout(),
        cb.layout(),
        "the clips must differ in layout for this test to mean anything"
    );
    Setup { rig, a, b, ca, cb }
}

/// The reference value of rig track `name` in `clip` at `time`, or its rest.
fn reference(rig: &Rig, clip: &tcb_core::SourceClip, name: &str, time: f64) -> [f64; 4] {
    let mut v = [0.0f32; 4];
    match clip.tracks().iter().find(|t| t.name == name) {
        Some(t) => t.data.sample_into(time, &mut v, None),
        None => v = rig.tracks()[rig.track(name).unwrap().index()].rest,
    }
    v.map(f64::from)
}

/// Blend by hand, in f64: weighted mean, rotations hemisphere-corrected
/// against the first layer and normalized.
fn by_hand(kind: TrackKind, layers: &[([f64; 4], f64)]) -> [f64; 4] {
    let q0 = DVec4::from_array(layers[0].0);
    let mut acc = DVec4::ZERO;
    let mut sum = 0.0;
    for (v, w) in layers {
        let v = DVec4::from_array(*v);
        let sign = if kind == TrackKind::Quat && q0.dot(v) < 0.0 {
            -1.0
        } else {
            1.0
        };
        acc += v * w * sign;
        sum += w;
    }
    if sum == 0.0 {
        layers[0].0 // no weight: the first layer's value, as documented
    } else if kind == TrackKind::Quat {
        acc.normalize().to_array()
    } else {
        (acc / sum).to_array()
    }
}

/// A rig track's value (the skeleton's vector tracks are all vec3).
/// The id of rig track `i`.
fn id_of(rig: &Rig, i: usize) -> TrackId {
    rig.layout().ids().nth(i).unwrap()
}

fn got(pose: &tcb_runtime::Pose, id: TrackId, kind: TrackKind) -> [f64; 4] {
    let v = match kind {
        TrackKind::Quat => pose.quat(id).unwrap().to_array(),
        _ => pose.vec3(id).unwrap().extend(0.0).to_array(),
    };
    v.map(f64::from)
}

fn distance(kind: TrackKind, a: [f64; 4], b: [f64; 4]) -> f64 {
    let (a, b) = (DVec4::from_array(a), DVec4::from_array(b));
    match kind {
        TrackKind::Quat => (a - b).length().min((a + b).length()),
        _ => (a - b).abs().max_element() / (1.0 + b.abs().max_element()),
    }
}

#[test]
fn clips_of_one_rig_cross_fade_as_their_reference_samples_do() {
    let s = setup();
    let mut ia = Instance::with_rig(s.ca.clone(), &s.rig).unwrap();
    let mut ib = Instance::with_rig(s.cb.clone(), &s.rig).unwrap();
    assert!(Arc::ptr_eq(ia.pose().layout(), ib.pose().layout()));
    let mut out = s.rig.rest_pose();
    let mask_b = ib.coverage_mask();
    let missing = s.rig.track(MISSING).unwrap();
    let mut worst = 0.0f64;
    for frame in 0..=60 {
        let fade = frame as f64 / 60.0;
        let (ta, tb) = (0.3 + frame as f64 / 120.0, 2.9 - frame as f64 / 97.0);
        ia.sample(ta);
        ib.sample(tb);
        let layers = [(ia.pose(), (1.0 - fade) as f32), (ib.pose(), fade as f32)];
        for masked in [false, true] {
            let all = ia.coverage_mask();
            let masks = [&all, &mask_b];
            blend(&mut out, &layers, masked.then_some(&masks[..])).unwrap();
            for (i, t) in s.rig.tracks().iter().enumerate() {
                let wb = if masked && id_of(&s.rig, i) == missing {
                    0.0
                } else {
                    fade
                };
                let want = by_hand(
                    t.kind,
                    &[
                        (reference(&s.rig, &s.a, &t.name, ta), 1.0 - fade),
                        (reference(&s.rig, &s.b, &t.name, tb), wb),
                    ],
                );
                let e = distance(t.kind, got(&out, id_of(&s.rig, i), t.kind), want);
                assert!(
                    e < 2e-5,
                    "{} at fade {fade} (masked {masked}): {:?} vs {want:?}",
                    t.name,
                    got(&out, id_of(&s.rig, i), t.kind)
                );
                worst = worst.max(e);
            }
        }
    }
    assert!(worst > 0.0);
}

#[test]
fn additive_layers_match_by_hand_and_carry_velocity() {
    let s = setup();
    let mut base = Instance::with_rig(s.ca.clone(), &s.rig)
        .unwrap()
        .with_velocities();
    let mut layer = Instance::with_rig(s.cb.clone(), &s.rig)
        .unwrap()
        .with_velocities();
    // A fixed reference pose: no velocities, so a constant.
    let mut refer = Instance::with_rig(s.cb.clone(), &s.rig).unwrap();
    let (tr, w) = (0.5, 0.6);
    let mask = BlendMask::for_layout(
        s.rig.layout(),
        |t| if t.index() % 5 == 0 { 0.5 } else { 1.0 },
    );
    let run = |base: &mut Instance, layer: &mut Instance, refer: &mut Instance, t: f64| {
        let mut out = base.sample(t).clone();
        layer.sample(t + 0.7);
        refer.sample(tr);
        add(&mut out, layer.pose(), refer.pose(), w as f32, Some(&mask)).unwrap();
        out
    };
    for t in [0.4, 1.25, 2.5] {
        let out = run(&mut base, &mut layer, &mut refer, t);
        for (i, rt) in s.rig.tracks().iter().enumerate() {
            let wm = if i % 5 == 0 { 0.5 * w } else { w };
            let a = reference(&s.rig, &s.a, &rt.name, t);
            let l = reference(&s.rig, &s.b, &rt.name, t + 0.7);
            let r = reference(&s.rig, &s.b, &rt.name, tr);
            let want = if rt.kind == TrackKind::Quat {
                let q = |v: [f64; 4]| DQuat::from_array(v);
                let mut d = q(l) * q(r).conjugate();
                if d.w < 0.0 {
                    d = -d;
                }
                let n = DQuat::from_xyzw(wm * d.x, wm * d.y, wm * d.z, 1.0 - wm + wm * d.w);
                (n.normalize() * q(a)).to_array()
            } else {
                std::array::from_fn(|c| a[c] + wm * (l[c] - r[c]))
            };
            let e = distance(rt.kind, got(&out, id_of(&s.rig, i), rt.kind), want);
            assert!(e < 2e-5, "{} at {t}: {e}", rt.name);
        }
        // Velocities: against a central difference of the added pose (mocap
        // curves bend fast: h = 1e-3 is 9% off on the base clip alone).
        let h = 1e-4;
        let (mut b2, mut l2, mut r2) = (base.clone(), layer.clone(), refer.clone());
        let after = run(&mut b2, &mut l2, &mut r2, t + h);
        let before = run(&mut b2, &mut l2, &mut r2, t - h);
        for (i, rt) in s.rig.tracks().iter().enumerate() {
            let id = id_of(&s.rig, i);
            let (v, fd) = if rt.kind == TrackKind::Quat {
                let (p, m) = (after.quat(id).unwrap(), before.quat(id).unwrap());
                let m = if p.dot(m) < 0.0 { -m } else { m };
                (out.quat_velocity(id).unwrap(), (p - m) * (0.5 / h as f32))
            } else {
                let fd = (after.vec3(id).unwrap() - before.vec3(id).unwrap()) * (0.5 / h as f32);
                (
                    Quat::from_xyzw(
                        out.vec3_velocity(id).unwrap().x,
                        out.vec3_velocity(id).unwrap().y,
                        out.vec3_velocity(id).unwrap().z,
                        0.0,
                    ),
                    Quat::from_xyzw(fd.x, fd.y, fd.z, 0.0),
                )
            };
            let e = (v.xyz() - fd.xyz()).length() + (v.w - fd.w).abs();
            let scale = 1.0 + fd.xyz().length();
            assert!(e / scale < 2e-2, "{} velocity at {t}: {v} vs {fd}", rt.name);
        }
    }
}

#[test]
fn angular_velocity_matches_the_turn_between_frames() {
    let s = setup();
    let mut inst = Instance::with_rig(s.ca.clone(), &s.rig)
        .unwrap()
        .with_velocities();
    let id = s.rig.track("LeftForeArm.rotation").unwrap();
    let h = 1e-4;
    for t in [0.5, 1.0, 2.0] {
        let w = inst.sample(t).angular_velocity(id).unwrap();
        let q1 = inst.sample(t + h).quat(id).unwrap().as_dquat();
        let q0 = inst.sample(t - h).quat(id).unwrap().as_dquat();
        let (axis, angle) = (q1 * q0.conjugate()).to_axis_angle();
        let fd = (axis * angle / (2.0 * h)).as_vec3();
        assert!(
            (w - fd).length() < 1e-2 * (1.0 + fd.length()),
            "{w} vs {fd}"
        );
    }
}

#[test]
fn other_rigs_and_unknown_tracks_are_refused() {
    let s = setup();
    // A clip with a track the rig does not have, or of another kind.
    let text = |kind: &str, name: &str| {
        format!(
            r#"{{"format": "tcb-clip/1", "tracks": [{{"name": "{name}", "kind": "{kind}", "times": [0, 1], "values": [{v}, {v}]}}]}}"#,
            v = if kind == "scalar" {
                "1"
            } else {
                "[0, 0, 0, 1]"
            }
        )
    };
    let compile = |t: String| {
        Arc::new(Clip::compile(
            &tcb_io::ClipDoc::parse(&t).unwrap().build().unwrap(),
        ))
    };
    let err = Instance::with_rig(compile(text("scalar", "blink")), &s.rig).err();
    assert_eq!(err, Some(RigError::NotInRig("blink".into())));
    let err = Instance::with_rig(compile(text("scalar", "Hips.rotation")), &s.rig).err();
    assert_eq!(
        err,
        Some(RigError::Kind {
            track: "Hips.rotation".into(),
            clip: TrackKind::Scalar,
            rig: TrackKind::Quat
        })
    );
    // A pose of another rig (here: the tracks of clip b, no End Sites or
    // scales) is refused, by blend and by add, and nothing is written.
    let other = Arc::new(Rig::from_clip(&s.cb).unwrap());
    let mut ia = Instance::with_rig(s.ca.clone(), &s.rig).unwrap();
    let mut ib = Instance::with_rig(s.cb.clone(), &other).unwrap();
    let mut out = s.rig.rest_pose();
    let before = out.clone();
    ia.sample(1.0);
    ib.sample(1.0);
    assert_eq!(
        blend(&mut out, &[(ia.pose(), 0.5), (ib.pose(), 0.5)], None),
        Err(BlendError::Layout { layer: 1 })
    );
    assert_eq!(
        add(&mut out, ib.pose(), ia.pose(), 0.5, None),
        Err(BlendError::Layout { layer: 0 })
    );
    assert_eq!(out.as_slice(), before.as_slice());
}
