//! Joint hierarchies as importers find them (BVH, glTF): names, parents and
//! rest transforms. Binding one to a sampled pose is the runtime's job
//! (`tcb_runtime::SkeletonBinding`).

use glam::{Affine3A, DAffine3, Quat, Vec3};

/// A local transform: scale, then rotation, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Translation relative to the parent.
    pub translation: Vec3,
    /// Rotation relative to the parent.
    pub rotation: Quat,
    /// Scale.
    pub scale: Vec3,
}

impl Transform {
    /// No translation, rotation or scale.
    pub const IDENTITY: Transform = Transform {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: Vec3::ONE,
    };

    /// As an affine matrix.
    pub fn to_affine(&self) -> Affine3A {
        Affine3A::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// As an affine matrix in f64 (the rotation normalized in f64).
    pub fn to_daffine(&self) -> DAffine3 {
        DAffine3::from_scale_rotation_translation(
            self.scale.as_dvec3(),
            self.rotation.as_dquat().normalize(),
            self.translation.as_dvec3(),
        )
    }
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

/// One joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name; animation tracks are `<name>.translation`, `<name>.rotation`,
    /// `<name>.scale`.
    pub name: String,
    /// Index of the parent joint, always lower than this joint's own.
    pub parent: Option<usize>,
    /// The transform where no track animates it (BVH: the `OFFSET`).
    pub rest: Transform,
}

/// Joints, parents before children: every joint's parent comes before it
/// ([`Skeleton::new`] and [`Skeleton::push`] refuse anything else), so one
/// pass in order composes model-space transforms.
///
/// ```compile_fail
/// // The joints are private: only `new` and `push`, which check the order, build one.
/// let s = tcb_core::skeleton::Skeleton { joints: Vec::new() };
/// ```
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skeleton {
    joints: Vec<Joint>,
}

/// A joint whose parent does not come before it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SkeletonError {
    /// The joint's index.
    pub joint: usize,
    /// Its name.
    pub name: String,
    /// Its parent's index (not below `joint`).
    pub parent: usize,
}

impl std::fmt::Display for SkeletonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "joint {} ({:?}) has parent {}, which does not come before it: list parents before their children",
            self.joint, self.name, self.parent
        )
    }
}

impl std::error::Error for SkeletonError {}

impl Skeleton {
    /// A skeleton of `joints`, each one's parent before it.
    ///
    /// ```
    /// use tcb_core::skeleton::{Joint, Skeleton, Transform};
    /// let joint = |name: &str, parent| Joint { name: name.into(), parent, rest: Transform::IDENTITY };
    /// assert!(Skeleton::new(vec![joint("hip", None), joint("knee", Some(0))]).is_ok());
    /// let e = Skeleton::new(vec![joint("knee", Some(1)), joint("hip", None)]).unwrap_err();
    /// assert_eq!((e.joint, e.parent), (0, 1));
    /// ```
    pub fn new(joints: Vec<Joint>) -> Result<Skeleton, SkeletonError> {
        let mut s = Skeleton {
            joints: Vec::with_capacity(joints.len()),
        };
        for j in joints {
            s.push(j)?;
        }
        Ok(s)
    }

    /// Add a joint after the others (its parent, if any, already in);
    /// returns its index.
    pub fn push(&mut self, joint: Joint) -> Result<usize, SkeletonError> {
        let i = self.joints.len();
        if let Some(p) = joint.parent.filter(|&p| p >= i) {
            return Err(SkeletonError {
                joint: i,
                name: joint.name,
                parent: p,
            });
        }
        self.joints.push(joint);
        Ok(i)
    }

    /// The joints, parents before children.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Joint `i`'s rest transform, to change (its place in the hierarchy
    /// cannot be).
    pub fn rest_mut(&mut self, i: usize) -> Option<&mut Transform> {
        self.joints.get_mut(i).map(|j| &mut j.rest)
    }

    /// The joints, given back.
    pub fn into_joints(self) -> Vec<Joint> {
        self.joints
    }
    /// The index of the joint called `name`.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Model-space transforms from local ones (`out[i] = out[parent] * local[i]`).
    /// `local` and `out` have one entry per joint.
    ///
    /// ```
    /// use glam::{Quat, Vec3};
    /// use tcb_core::skeleton::{Joint, Skeleton, Transform};
    /// let at = |x: f32| Transform { translation: Vec3::new(x, 0.0, 0.0), ..Transform::IDENTITY };
    /// let skeleton = Skeleton::new(vec![
    ///     Joint { name: "hip".into(), parent: None, rest: at(1.0) },
    ///     Joint { name: "knee".into(), parent: Some(0), rest: at(2.0) },
    /// ]).unwrap();
    /// let local = [at(1.0), at(2.0)];
    /// let mut model = [glam::Affine3A::IDENTITY; 2];
    /// skeleton.model_transforms(&local, &mut model);
    /// assert_eq!(model[1].translation, glam::Vec3A::new(3.0, 0.0, 0.0));
    /// ```
    pub fn model_transforms(&self, local: &[Transform], out: &mut [Affine3A]) {
        self.compose(local, out, Transform::to_affine);
    }

    /// [`Skeleton::model_transforms`] in f64: composing a long chain adds no
    /// f32 rounding (what model-space error measures need).
    pub fn model_transforms_f64(&self, local: &[Transform], out: &mut [DAffine3]) {
        self.compose(local, out, Transform::to_daffine);
    }

    /// `out[i] = out[parent] * m(local[i])`, parents first.
    fn compose<M: Copy + std::ops::Mul<Output = M>>(
        &self,
        local: &[Transform],
        out: &mut [M],
        m: impl Fn(&Transform) -> M,
    ) {
        for (i, joint) in self
            .joints
            .iter()
            .enumerate()
            .take(local.len().min(out.len()))
        {
            let m = m(&local[i]);
            out[i] = match joint.parent {
                Some(p) if p < i => out[p] * m,
                _ => m,
            };
        }
    }
}
