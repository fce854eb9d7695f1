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
        binding
            .model_transforms(
                instance.sample(frame as f64 * bvh.frame_time()),
                &mut local,
                &mut model,
            )
            .unwrap();
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

/// A binding fed a pose of another layout, or slices of another length than
/// its joints, is an error (it used to give the rest pose, or stop early,
/// without a word).
#[test]
fn a_pose_of_another_layout_or_a_short_slice_is_an_error() {
    use tcb_runtime::BindingError;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let bvh = Bvh::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    let doc = bvh
        .to_clip_doc("cmu", tcb_core::RotationMode::Hermite)
        .unwrap();
    let source = doc.build().unwrap();
    let clip = Arc::new(Clip::compile(&source));
    let binding = SkeletonBinding::new(bvh.skeleton().clone(), &clip);
    let n = bvh.skeleton().joints().len();
    let mut local = vec![Default::default(); n];
    let mut model = vec![glam::Affine3A::IDENTITY; n];

    // A clip of the same joints but one track fewer: another layout.
    let tracks = source.clone().into_tracks();
    let fewer = tracks.into_iter().filter(|t| t.name != "Head.rotation");
    let fewer = tcb_core::SourceClip::new("fewer", fewer.collect()).unwrap();
    let mut other = Instance::new(Arc::new(Clip::compile(&fewer)));
    let err = binding
        .model_transforms(other.sample(1.0), &mut local, &mut model)
        .unwrap_err();
    assert_eq!(err, BindingError::OtherLayout);
    assert!(err.to_string().contains("for_layout"), "{err}");

    let mut instance = Instance::new(clip.clone());
    let pose = instance.sample(1.0).clone();
    let err = binding
        .local_transforms(&pose, &mut local[..n - 1])
        .unwrap_err();
    assert_eq!(
        err,
        BindingError::OutputLength {
            joints: n,
            given: n - 1
        }
    );
    assert!(
        binding
            .model_transforms(&pose, &mut local, &mut model[..3])
            .is_err()
    );
    binding
        .model_transforms(&pose, &mut local, &mut model)
        .unwrap();
    // Bound through the layout itself, the same pose binds.
    let again = SkeletonBinding::for_layout(bvh.skeleton().clone(), pose.layout());
    again
        .model_transforms(&pose, &mut local, &mut model)
        .unwrap();
}
