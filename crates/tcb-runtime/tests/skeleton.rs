//! The skeleton binding on the real CMU clip: model-space joint positions
//! from the runtime equal those composed in f64 from the BVH channels.

use glam::{DAffine3, DVec3};
use std::sync::Arc;
use tcb_io::bvh::Bvh;
use tcb_runtime::{Clip, Instance, SkeletonBinding};

#[test]
fn cmu_model_space_positions_match_the_bvh() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let bvh = Bvh::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    let doc = bvh
        .to_clip_doc("cmu", tcb_core::RotationMode::Hermite)
        .unwrap();
    let clip = Arc::new(Clip::compile(&doc.build().unwrap()));
    let binding = SkeletonBinding::new(bvh.skeleton().clone(), &clip);
    assert_eq!(binding.animated_joints(), 31);
    let mut instance = Instance::new(clip);
    let n = bvh.skeleton().joints().len();
    let mut local = vec![Default::default(); n];
    let mut model = vec![glam::Affine3A::IDENTITY; n];
    let mut want = vec![DAffine3::IDENTITY; n];
    let mut worst = 0.0f64;
    for frame in (0..bvh.frame_count()).step_by(7) {
        binding.model_transforms(
            instance.sample(frame as f64 * bvh.frame_time()),
            &mut local,
            &mut model,
        );
        for (j, joint) in bvh.skeleton().joints().iter().enumerate() {
            let (t, q) = bvh.local(frame, j).expect("a frame and joint of the file");
            let m = DAffine3::from_rotation_translation(q, t);
            want[j] = joint.parent.map_or(m, |p| want[p] * m);
            let got = DVec3::from(model[j].translation.to_array().map(f64::from));
            let err = (got - want[j].translation).length() / want[j].translation.length().max(1.0);
            worst = worst.max(err);
        }
    }
    assert!(worst < 1e-5, "worst relative position error {worst}");
}
