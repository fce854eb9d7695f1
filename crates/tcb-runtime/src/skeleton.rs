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
/// binding.model_transforms(instance.sample(1.0), &mut local, &mut model)?;
/// assert!(model.iter().all(|m| m.is_finite()));
/// # Ok::<(), tcb_runtime::BindingError>(())
/// ```
///
/// A binding remembers the layout it was made for: a pose of another
/// layout (another clip's, or a rig's where the binding was made for a
/// clip) is [`BindingError::OtherLayout`], not the rest pose; bind a rig's
/// poses with [`for_layout`](Self::for_layout).
#[derive(Clone, Debug)]
pub struct SkeletonBinding {
    skeleton: Skeleton,
    /// Per joint: translation, rotation, scale tracks.
    tracks: Vec<[Option<TrackId>; 3]>,
    /// The layout's key (`PoseLayout::key`).
    layout: u64,
}

/// Why a [`SkeletonBinding`] cannot bind a pose: one line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BindingError {
    /// The pose is of another layout than the binding was made for.
    OtherLayout,
    /// A slice of transforms of another length than the skeleton's joints.
    OutputLength {
        /// The skeleton's joints.
        joints: usize,
        /// Transforms given.
        given: usize,
    },
}

impl std::fmt::Display for BindingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BindingError::OtherLayout => f.write_str(
                "the pose is of another layout than the skeleton binding's; make the binding \
                 for the poses it will read (SkeletonBinding::for_layout(skeleton, pose.layout()))",
            ),
            BindingError::OutputLength { joints, given } => write!(
                f,
                "{given} transforms given for a skeleton of {joints} joints"
            ),
        }
    }
}

impl std::error::Error for BindingError {}

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
        SkeletonBinding {
            skeleton,
            tracks,
            layout: layout.key,
        }
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

    /// Each joint's transform relative to its parent, one per joint into
    /// `out`. Parts the binding's layout does not animate keep the rest
    /// transform's. A pose of another layout, or an `out` of another
    /// length than the joints, is an error (and `out` is left as it was).
    #[inline]
    pub fn local_transforms(&self, pose: &Pose, out: &mut [Transform]) -> Result<(), BindingError> {
        self.check(pose, out.len())?;
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
        Ok(())
    }

    /// Local transforms into `local`, and model-space ones into `model`
    /// (both one per joint; errors as [`local_transforms`](Self::local_transforms),
    /// checked before anything is written).
    #[inline]
    pub fn model_transforms(
        &self,
        pose: &Pose,
        local: &mut [Transform],
        model: &mut [Affine3A],
    ) -> Result<(), BindingError> {
        self.check(pose, model.len())?;
        self.local_transforms(pose, local)?;
        self.skeleton.model_transforms(local, model);
        Ok(())
    }

    /// `pose` is of the binding's layout and `given` is the joint count.
    fn check(&self, pose: &Pose, given: usize) -> Result<(), BindingError> {
        if pose.layout().key != self.layout {
            return Err(BindingError::OtherLayout);
        }
        let joints = self.skeleton.joints().len();
        if given != joints {
            return Err(BindingError::OutputLength { joints, given });
        }
        Ok(())
    }
}
