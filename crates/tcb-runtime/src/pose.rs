//! Sampled values in structure-of-arrays form, with typed accessors.

use crate::clip::{Clip, TrackId, TrackSlot};

/// Where every track lives in a pose; shared by a clip and its poses. Poses
/// can be blended when their layouts are equal.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseLayout {
    /// Each track's flat component indices.
    pub slots: Vec<TrackSlot>,
    /// Total f32x8 blocks.
    pub blocks: usize,
    /// First block of each group of 4 blocks holding x, y, z, w planes of 8 rotations.
    pub quat_blocks: Vec<usize>,
}
impl PoseLayout {
    /// The track called `name`.
    pub fn track(&self, name: &str) -> Option<TrackId> {
        self.slots.iter().position(|s| s.name == name).map(TrackId)
    }
}

use glam::{Quat, Vec2, Vec3, Vec4};
use std::sync::Arc;
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
    ($($value:ident, $velocity:ident, $t:ty, $n:literal, $make:expr;)+) => {$(
        #[doc = concat!("The value of a `", stringify!($value), "` track.")]
        pub fn $value(&self, track: TrackId) -> $t {
            let a = self.components(&self.values, track);
            ($make)(a)
        }

        #[doc = concat!("The d/dt of a `", stringify!($value), "` track (zero without velocities).")]
        pub fn $velocity(&self, track: TrackId) -> $t {
            match &self.velocities {
                Some(v) => ($make)(self.components(v, track)),
                None => ($make)([0.0; 4]),
            }
        }
    )+};
}

impl Pose {
    /// A pose for `clip`, with room for velocities if asked.
    pub fn new(clip: &Clip, velocities: bool) -> Self {
        let blocks = clip.layout.blocks;
        Pose {
            layout: clip.layout.clone(),
            values: vec![f32x8::ZERO; blocks],
            velocities: velocities.then(|| vec![f32x8::ZERO; blocks]),
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

    fn components(&self, data: &[f32x8], track: TrackId) -> [f32; 4] {
        let flat: &[f32] = bytemuck::cast_slice(data);
        let slot = &self.layout.slots[track.0];
        let mut out = [0.0; 4];
        for (o, &i) in out.iter_mut().zip(&slot.index).take(slot.kind.dim()) {
            *o = flat[i];
        }
        out
    }

    accessors! {
        scalar, scalar_velocity, f32, 1, |a: [f32; 4]| a[0];
        vec2, vec2_velocity, Vec2, 2, |a: [f32; 4]| Vec2::new(a[0], a[1]);
        vec3, vec3_velocity, Vec3, 3, |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        vec4, vec4_velocity, Vec4, 4, Vec4::from_array;
        quat, quat_velocity, Quat, 4, Quat::from_array;
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
    /// let mut inst = tcb_runtime::Instance::new(clip.clone(), true);
    /// let w = inst.sample(0.3).angular_velocity(clip.track("r").unwrap());
    /// assert!((w - glam::Vec3::new(0.0, 0.0, std::f32::consts::FRAC_PI_2)).length() < 1e-5);
    /// ```
    pub fn angular_velocity(&self, track: TrackId) -> Vec3 {
        let (q, dq) = (self.quat(track), self.quat_velocity(track));
        Vec3::from_array(tcb_core::quat::angular_velocity(
            &q.to_array(),
            &dq.to_array(),
        ))
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
