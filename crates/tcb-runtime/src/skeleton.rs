//! Binding a joint hierarchy to a clip: from a sampled [`Pose`] to local
//! and model-space joint transforms.

use crate::clip::Clip;
use crate::layout::{PoseLayout, TrackId};
use crate::pose::Pose;
use glam::Affine3A;
use tcb_core::TrackKind;
use tcb_core::skeleton::{Skeleton, Transform};

/// A [`Skeleton`] with each joint's tracks found in a clip: `<joint>.translation`
/// (vec3), `<joint>.rotation` (quat), `<joint>.scale` (vec3). Parts no track
/// animates keep the joint's rest transform.
///
/// ```
/// use std::sync::Arc;
/// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
/// # /*
/// let path = "data/cmu-01_01.bvh"; // from the repository's root
/// # */
/// let loaded = tcb_io::load(path).unwrap();
/// let clip = Arc::new(tcb_runtime::Clip::compile(&loaded.clip));
/// let binding = tcb_runtime::SkeletonBinding::new(loaded.skeleton.unwrap(), &clip);
/// let mut instance = tcb_runtime::Instance::new(clip);
/// let mut local = vec![Default::default(); binding.skeleton().joints().len()];
/// let mut model = vec![glam::Affine3A::IDENTITY; local.len()];
/// binding.model_transforms(instance.sample(1.0), &mut local, &mut model);
/// assert!(model.iter().all(|m| m.is_finite()));
/// ```
#[derive(Clone, Debug)]
pub struct SkeletonBinding {
    skeleton: Skeleton,
    /// Per joint: translation, rotation, scale tracks.
    tracks: Vec<[Option<TrackId>; 3]>,
}

impl SkeletonBinding {
    /// Find each joint's tracks in `clip` (by name and kind).
    pub fn new(skeleton: Skeleton, clip: &Clip) -> Self {
        SkeletonBinding::for_layout(skeleton, clip.layout())
    }

    /// Find each joint's tracks in poses of `layout` (a clip's or a
    /// [`Rig`](crate::Rig)'s).
    pub fn for_layout(skeleton: Skeleton, layout: &PoseLayout) -> Self {
        let find = |name: String, kind: TrackKind| {
            layout
                .track(&name)
                .filter(|&t| layout.slot(t).is_some_and(|s| s.kind == kind))
        };
        let tracks = skeleton
            .joints()
            .iter()
            .map(|j| {
                [
                    find(format!("{}.translation", j.name), TrackKind::Vec3),
                    find(format!("{}.rotation", j.name), TrackKind::Quat),
                    find(format!("{}.scale", j.name), TrackKind::Vec3),
                ]
            })
            .collect();
        SkeletonBinding { skeleton, tracks }
    }

    /// The hierarchy.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Number of joints with at least one animated part.
    pub fn animated_joints(&self) -> usize {
        self.tracks
            .iter()
            .filter(|t| t.iter().any(Option::is_some))
            .count()
    }

    /// Each joint's transform relative to its parent. `out` has one entry
    /// per joint. Parts the binding's layout does not animate keep the rest
    /// transform's, as does everything of a `pose` of another layout.
    #[inline]
    pub fn local_transforms(&self, pose: &Pose, out: &mut [Transform]) {
        for ((joint, tracks), o) in self.skeleton.joints().iter().zip(&self.tracks).zip(out) {
            let rest = &joint.rest;
            *o = Transform {
                translation: tracks[0]
                    .and_then(|t| pose.vec3(t))
                    .unwrap_or(rest.translation),
                rotation: tracks[1]
                    .and_then(|t| pose.quat(t))
                    .unwrap_or(rest.rotation),
                scale: tracks[2].and_then(|t| pose.vec3(t)).unwrap_or(rest.scale),
            };
        }
    }

    /// Local transforms into `local`, and model-space ones into `model`.
    #[inline]
    pub fn model_transforms(&self, pose: &Pose, local: &mut [Transform], model: &mut [Affine3A]) {
        self.local_transforms(pose, local);
        self.skeleton.model_transforms(local, model);
    }
}
