//! Sampled values in structure-of-arrays form, with typed accessors.

use crate::clip::Clip;
use crate::layout::{PoseLayout, TrackId, TrackSlot};
use glam::{Quat, Vec2, Vec3, Vec4};
use std::sync::Arc;
use tcb_core::TrackKind;
use wide::f32x8;

/// The output of sampling a [`Clip`]: blocks of 8 channels as `f32x8`, laid
/// out by the clip's groups (vectors component-interleaved in track order,
/// rotations as x/y/z/w planes of 8). Read it through the typed accessors,
/// or [`Pose::write_row`] for the clip's column order.
#[derive(Clone, Debug)]
pub struct Pose {
    pub(crate) layout: Arc<PoseLayout>,
    pub(crate) values: Vec<f32x8>,
    pub(crate) velocities: Option<Vec<f32x8>>,
}

macro_rules! accessors {
    ($($value:ident, $velocity:ident, $kind:ident, $t:ty, $make:expr;)+) => {$(
        #[doc = concat!("The value of a `", stringify!($value), "` track; `None` when `track` is of another kind or of another layout.")]
        pub fn $value(&self, track: TrackId) -> Option<$t> {
            self.components(&self.values, track, TrackKind::$kind).map($make)
        }

        #[doc = concat!("The d/dt of a `", stringify!($value), "` track; `None` when the pose carries no velocities ([`Pose::has_velocities`]: an instance made `with_velocities` samples them), or `track` is of another kind or of another layout.")]
        pub fn $velocity(&self, track: TrackId) -> Option<$t> {
            self.components(self.velocities.as_ref()?, track, TrackKind::$kind).map($make)
        }
    )+};
}

impl Pose {
    /// A pose for `clip` (zeros), without velocities.
    pub fn new(clip: &Clip) -> Self {
        Pose {
            layout: clip.layout.clone(),
            values: vec![f32x8::ZERO; clip.layout.blocks],
            velocities: None,
        }
    }

    /// This pose with room for velocities (zero until sampled), so that
    /// blending into it carries them.
    #[must_use]
    pub fn with_velocities(mut self) -> Self {
        self.add_velocities();
        self
    }

    /// Room for velocities, zero, unless there is already.
    pub(crate) fn add_velocities(&mut self) {
        if self.velocities.is_none() {
            self.velocities = Some(vec![f32x8::ZERO; self.values.len()]);
        }
    }

    /// The layout (shared with its clip).
    pub fn layout(&self) -> &Arc<PoseLayout> {
        &self.layout
    }

    /// Whether this pose carries velocities.
    pub fn has_velocities(&self) -> bool {
        self.velocities.is_some()
    }

    /// All channels as flat `f32` (layout order, padding lanes included).
    pub fn as_slice(&self) -> &[f32] {
        bytemuck::cast_slice(&self.values)
    }

    /// The components of `track` in `data` if it is of this layout and of `kind`.
    fn components(&self, data: &[f32x8], track: TrackId, kind: TrackKind) -> Option<[f32; 4]> {
        let slot = self.layout.slot(track).filter(|s| s.kind == kind)?;
        Some(Self::slot_components(data, slot))
    }

    /// The components of a slot of this pose's layout.
    pub(crate) fn slot_components(data: &[f32x8], slot: &TrackSlot) -> [f32; 4] {
        let flat: &[f32] = bytemuck::cast_slice(data);
        let mut out = [0.0; 4];
        for (o, &i) in out.iter_mut().zip(&slot.index).take(slot.kind.dim()) {
            *o = flat[i];
        }
        out
    }

    accessors! {
        scalar, scalar_velocity, Scalar, f32, |a: [f32; 4]| a[0];
        vec2, vec2_velocity, Vec2, Vec2, |a: [f32; 4]| Vec2::new(a[0], a[1]);
        vec3, vec3_velocity, Vec3, Vec3, |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        vec4, vec4_velocity, Vec4, Vec4, Vec4::from_array;
        quat, quat_velocity, Quat, Quat, Quat::from_array;
    }

    /// The angular velocity of a rotation track in rad/s, as a vector in
    /// the frame the rotation maps into (a joint's parent):
    /// `omega = 2 q' conj(q)` (its vector part; zero without velocities).
    ///
    /// ```
    /// # use std::sync::Arc;
    /// // A quarter turn about z per second.
    /// let text = r#"{"format": "tcb-clip/1", "tracks": [{"name": "r", "kind": "quat", "times": [0, 1],
    ///   "values": [[0, 0, 0, 1], [0, 0, 0.70710678, 0.70710678]],
    ///   "keys": [{"interp": "linear"}, {"interp": "linear"}]}]}"#;
    /// let clip = Arc::new(tcb_runtime::Clip::compile(&tcb_io::ClipDoc::parse(text).unwrap().build().unwrap()));
    /// let mut inst = tcb_runtime::Instance::new(clip.clone()).with_velocities();
    /// let w = inst.sample(0.3).angular_velocity(clip.track("r").unwrap()).unwrap();
    /// assert!((w - glam::Vec3::new(0.0, 0.0, std::f32::consts::FRAC_PI_2)).length() < 1e-5);
    /// ```
    pub fn angular_velocity(&self, track: TrackId) -> Option<Vec3> {
        let (q, dq) = (self.quat(track)?, self.quat_velocity(track)?);
        Some(Vec3::from_array(tcb_core::quat::angular_velocity(
            &q.to_array(),
            &dq.to_array(),
        )))
    }

    /// Every track's components in file order (the CSV columns of
    /// `tcb sample`), and velocities after them if `velocities` is given.
    pub fn write_row(&self, values: &mut [f32], velocities: Option<&mut [f32]>) {
        self.gather(&self.values, values);
        if let (Some(out), Some(v)) = (velocities, &self.velocities) {
            self.gather(v, out);
        }
    }

    /// Every track's components of `data`, in file order, into `out`.
    fn gather(&self, data: &[f32x8], out: &mut [f32]) {
        let flat: &[f32] = bytemuck::cast_slice(data);
        let indices = self
            .layout
            .slots
            .iter()
            .flat_map(|s| &s.index[..s.kind.dim()]);
        for (o, &i) in out.iter_mut().zip(indices) {
            *o = flat[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names are found through the sorted index: each of many, the first
    /// of a repeated one, none for a missing one.
    #[test]
    fn tracks_by_name() {
        let slot = |n: &str| TrackSlot {
            name: n.into(),
            kind: TrackKind::Scalar,
            index: [0; 4],
        };
        let mut slots: Vec<TrackSlot> = (0..300).rev().map(|i| slot(&format!("t{i}"))).collect();
        slots.push(slot("t7"));
        let layout = PoseLayout::new(slots, 1, Vec::new());
        for i in 0..300 {
            let id = layout.track(&format!("t{i}")).unwrap();
            assert_eq!(id.index(), 299 - i);
        }
        assert_eq!(layout.track("t7").unwrap().index(), 292);
        assert_eq!(layout.track("t300"), None);
        assert_eq!(layout.track(""), None);
    }
}
