//! Blending poses: vectors lerp, rotations nlerp with hemisphere correction,
//! per-track masks, lanes with no weight.

use glam::{Quat, Vec3};
use std::sync::Arc;
use tcb_runtime::{BlendMask, Clip, Instance, blend};

fn clip() -> Arc<Clip> {
    // Rotations on a shared grid (squad and hermite) and a vector track; the
    // loose scalar track has its own grid.
    let text = r#"{"format": "tcb-clip/1", "tracks": [
      {"name": "pos", "kind": "vec3", "times": [0, 1, 2], "values": [[0, 0, 0], [2, 4, 6], [4, 0, 2]]},
      {"name": "rot", "kind": "quat", "times": [0, 1, 2], "values": [[0, 0, 0, 1], [0, 0, 0.7071068, 0.7071068], [0, 0, 1, 0]]},
      {"name": "rot_h", "kind": "quat", "rotation": "hermite", "times": [0, 1, 2], "values": [[0, 0, 0, 1], [0.7071068, 0, 0, 0.7071068], [1, 0, 0, 0]]},
      {"name": "x", "kind": "scalar", "times": [0, 3], "values": [10, 40]}
    ]}"#;
    Arc::new(Clip::compile(
        &tcb_io::ClipDoc::parse(text).unwrap().build().unwrap(),
    ))
}

fn close(a: Quat, b: Quat) -> bool {
    (a - b).length().min((a + b).length()) < 1e-5
}

#[test]
fn weighted_blend_by_hand() {
    let clip = clip();
    let (pos, rot, rot_h, x) = ["pos", "rot", "rot_h", "x"]
        .map(|n| clip.track(n).unwrap())
        .into();
    let mut a = Instance::new(clip.clone());
    let mut b = Instance::new(clip.clone());
    a.sample(0.0);
    b.sample(2.0);
    let mut out = a.pose().clone();
    blend(&mut out, &[(a.pose(), 3.0), (b.pose(), 1.0)], None).unwrap();
    // Vectors: (3 a + 1 b) / 4.
    assert!(
        (out.vec3(pos).unwrap() - Vec3::new(1.0, 0.0, 0.5))
            .abs()
            .max_element()
            < 1e-6
    );
    let xb = b.pose().scalar(x).unwrap();
    assert!((out.scalar(x).unwrap() - (3.0 * 10.0 + xb) / 4.0).abs() < 1e-5);
    // Rotations: identity and a half turn about z (given as [0,0,1,0]):
    // nlerp(3 * I + 1 * q) normalized.
    let want = (Quat::IDENTITY * 3.0 + Quat::from_xyzw(0.0, 0.0, 1.0, 0.0)).normalize();
    assert!(
        close(out.quat(rot).unwrap(), want),
        "{} {}",
        out.quat(rot).unwrap(),
        want
    );
    let want = (Quat::IDENTITY * 3.0 + Quat::from_xyzw(1.0, 0.0, 0.0, 0.0)).normalize();
    assert!(close(out.quat(rot_h).unwrap(), want));
}

#[test]
fn hemisphere_correction() {
    let clip = clip();
    let (rot, rot_h) = (clip.track("rot").unwrap(), clip.track("rot_h").unwrap());
    let mut a = Instance::new(clip.clone());
    let mut b = Instance::new(clip.clone());
    a.sample(1.0);
    b.sample(0.4);
    // b with every rotation negated (same rotations): a single layer of weight -1.
    let mut flipped = b.pose().clone();
    blend(&mut flipped, &[(b.pose(), -1.0)], None).unwrap();
    assert!(flipped.quat(rot).unwrap().dot(b.pose().quat(rot).unwrap()) < -0.99);
    let (mut plain, mut corrected) = (a.pose().clone(), a.pose().clone());
    blend(&mut plain, &[(a.pose(), 0.6), (b.pose(), 0.4)], None).unwrap();
    blend(&mut corrected, &[(a.pose(), 0.6), (&flipped, 0.4)], None).unwrap();
    for t in [rot, rot_h] {
        assert!(
            close(plain.quat(t).unwrap(), corrected.quat(t).unwrap()),
            "{} {}",
            plain.quat(t).unwrap(),
            corrected.quat(t).unwrap()
        );
    }
}

#[test]
fn masks_weigh_tracks_separately() {
    let clip = clip();
    let (pos, x) = (clip.track("pos").unwrap(), clip.track("x").unwrap());
    let mut a = Instance::new(clip.clone());
    let mut b = Instance::new(clip.clone());
    a.sample(0.0);
    b.sample(1.0);
    // Layer b affects only "pos"; "x" keeps layer a's value.
    let only_pos = BlendMask::new(&clip, |t| if t == pos { 1.0 } else { 0.0 });
    let all = BlendMask::new(&clip, |_| 1.0);
    let mut out = a.pose().clone();
    blend(
        &mut out,
        &[(a.pose(), 1.0), (b.pose(), 1.0)],
        Some(&[&all, &only_pos]),
    )
    .unwrap();
    assert!(
        (out.vec3(pos).unwrap() - Vec3::new(1.0, 2.0, 3.0))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(out.scalar(x).unwrap(), a.pose().scalar(x).unwrap());
    // No weight at all: the first layer's values.
    let none = BlendMask::new(&clip, |_| 0.0);
    blend(
        &mut out,
        &[(b.pose(), 1.0), (a.pose(), 1.0)],
        Some(&[&none, &none]),
    )
    .unwrap();
    assert_eq!(out.vec3(pos).unwrap(), b.pose().vec3(pos).unwrap());
}

#[test]
fn layers_of_another_clip_with_the_same_layout_blend_others_are_refused() {
    let (one, two) = (clip(), clip()); // compiled twice: equal layouts, different Arcs
    let pos = one.track("pos").unwrap();
    let mut a = Instance::new(one.clone());
    let mut b = Instance::new(two);
    a.sample(0.0);
    b.sample(1.0);
    let mut out = a.pose().clone();
    blend(&mut out, &[(a.pose(), 1.0), (b.pose(), 1.0)], None).unwrap();
    assert!(
        (out.vec3(pos).unwrap() - Vec3::new(1.0, 2.0, 3.0))
            .abs()
            .max_element()
            < 1e-6
    );
    // A pose of a clip with other tracks is refused, and nothing is written.
    let other = tcb_io::ClipDoc::parse(
        r#"{"format": "tcb-clip/1", "tracks": [{"name": "pos", "kind": "vec3", "times": [0, 1], "values": [[9, 9, 9], [9, 9, 9]]}]}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let mut c = Instance::new(Arc::new(Clip::compile(&other)));
    c.sample(0.5);
    let before = out.clone();
    assert_eq!(
        blend(&mut out, &[(a.pose(), 1.0), (c.pose(), 1.0)], None),
        Err(tcb_runtime::blend::BlendError::Layout { layer: 1 })
    );
    assert_eq!(out.as_slice(), before.as_slice());
    // So is a mask of another layout, or a mask count that does not match.
    let foreign = BlendMask::new(&Arc::new(Clip::compile(&other)), |_| 1.0);
    let own = BlendMask::new(&one, |_| 1.0);
    assert_eq!(
        blend(
            &mut out,
            &[(a.pose(), 1.0), (b.pose(), 1.0)],
            Some(&[&own, &foreign])
        ),
        Err(tcb_runtime::blend::BlendError::Mask { layer: 1 })
    );
    assert_eq!(
        blend(&mut out, &[(a.pose(), 1.0), (b.pose(), 1.0)], Some(&[&own])),
        Err(tcb_runtime::blend::BlendError::MaskCount {
            layers: 2,
            masks: 1
        })
    );
    assert_eq!(out.as_slice(), before.as_slice());
}

/// Velocities blend with the values' weights, masks included: vectors
/// `sum w_i m_i v_i / sum w_i m_i`, rotations the weighted sum of their
/// derivatives (signs as the values) over the same sum.
#[test]
fn masked_velocities_by_hand() {
    let clip = clip();
    let (pos, rot, x) = ["pos", "rot", "x"].map(|n| clip.track(n).unwrap()).into();
    let mut a = Instance::new(clip.clone()).with_velocities();
    let mut b = Instance::new(clip.clone()).with_velocities();
    a.sample(0.3);
    b.sample(1.6);
    let half_pos = BlendMask::new(&clip, |t| if t == pos { 0.5 } else { 1.0 });
    let all = BlendMask::new(&clip, |_| 1.0);
    let mut out = a.pose().clone();
    let (wa, wb) = (0.25f32, 0.75f32);
    blend(
        &mut out,
        &[(a.pose(), wa), (b.pose(), wb)],
        Some(&[&all, &half_pos]),
    )
    .unwrap();
    let (pa, pb) = (a.pose(), b.pose());
    let want = (pa.vec3_velocity(pos).unwrap() * wa + pb.vec3_velocity(pos).unwrap() * wb * 0.5)
        / (wa + wb * 0.5);
    assert!((out.vec3_velocity(pos).unwrap() - want).abs().max_element() < 1e-5);
    let want =
        (pa.scalar_velocity(x).unwrap() * wa + pb.scalar_velocity(x).unwrap() * wb) / (wa + wb);
    assert!((out.scalar_velocity(x).unwrap() - want).abs() < 1e-5);
    let sign = pa.quat(rot).unwrap().dot(pb.quat(rot).unwrap()).signum();
    let want = (pa.quat_velocity(rot).unwrap() * wa + pb.quat_velocity(rot).unwrap() * wb * sign)
        / (wa + wb);
    assert!(
        (out.quat_velocity(rot).unwrap() - want).length() < 1e-5,
        "{} {}",
        out.quat_velocity(rot).unwrap(),
        want
    );
    // Values too, with the mask.
    let want = (pa.vec3(pos).unwrap() * wa + pb.vec3(pos).unwrap() * wb * 0.5) / (wa + wb * 0.5);
    assert!((out.vec3(pos).unwrap() - want).abs().max_element() < 1e-5);
}

/// Issue 29, class 7: weights whose sum is a denormal (2e-40) divided into
/// the layers gave inf. Below `blend::MIN_WEIGHT_SUM` a lane keeps the
/// first layer's value, as at a sum of zero; above it the blend is the
/// weighted mean, finite.
#[test]
fn weights_near_zero_keep_the_first_layer() {
    let clip = clip();
    let (pos, rot) = (clip.track("pos").unwrap(), clip.track("rot").unwrap());
    let mut a = Instance::new(clip.clone()).with_velocities();
    let mut b = Instance::new(clip.clone()).with_velocities();
    a.sample(0.5);
    b.sample(1.5);
    let mut out = a.pose().clone();
    for w in [
        2e-40f32,
        1e-38,
        -2e-40,
        tcb_runtime::blend::MIN_WEIGHT_SUM / 2.0,
    ] {
        blend(&mut out, &[(a.pose(), w), (b.pose(), 0.0)], None).unwrap();
        assert_eq!(out.vec3(pos), a.pose().vec3(pos), "{w}");
        assert_eq!(out.quat(rot), a.pose().quat(rot), "{w}");
        assert_eq!(out.vec3_velocity(pos), a.pose().vec3_velocity(pos), "{w}");
    }
    let w = tcb_runtime::blend::MIN_WEIGHT_SUM;
    blend(&mut out, &[(a.pose(), w), (b.pose(), w)], None).unwrap();
    let mean = (a.pose().vec3(pos).unwrap() + b.pose().vec3(pos).unwrap()) / 2.0;
    assert!((out.vec3(pos).unwrap() - mean).length() < 1e-5);
    assert!(out.quat(rot).unwrap().is_finite());
}
