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

/// Joints, parents before children.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skeleton {
    /// The joints.
    pub joints: Vec<Joint>,
}

impl Skeleton {
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
    /// let skeleton = Skeleton { joints: vec![
    ///     Joint { name: "hip".into(), parent: None, rest: at(1.0) },
    ///     Joint { name: "knee".into(), parent: Some(0), rest: at(2.0) },
    /// ]};
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
