//! Sampled values in structure-of-arrays form, with typed accessors.

use crate::clip::{Clip, TrackId, TrackSlot};
use tcb_core::TrackKind;

/// Where every track lives in a pose; shared by a clip and its poses. Poses
/// can be blended when their layouts are equal.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseLayout {
    /// Each track's flat component indices.
    pub(crate) slots: Vec<TrackSlot>,
    /// Total f32x8 blocks.
    pub(crate) blocks: usize,
    /// First block of each group of 4 blocks holding x, y, z, w planes of 8 rotations.
    pub(crate) quat_blocks: Vec<usize>,
    /// A digest of the above, carried by every [`TrackId`] of this layout
    /// (equal layouts have equal keys).
    pub(crate) key: u64,
    /// Track indices sorted by name (then index: the first of a repeated
    /// name comes first), for lookups in O(log n) at 4 bytes a track.
    by_name: Vec<u32>,
}

impl PoseLayout {
    pub(crate) fn new(slots: Vec<TrackSlot>, blocks: usize, quat_blocks: Vec<usize>) -> Self {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (&slots, blocks, &quat_blocks).hash(&mut h);
        let mut by_name: Vec<u32> = (0..slots.len())
            .map(|i| u32::try_from(i).expect("fewer than 2^32 tracks"))
            .collect();
        by_name.sort_by(|&a, &b| slots[a as usize].name.cmp(&slots[b as usize].name));
        PoseLayout {
            slots,
            blocks,
            quat_blocks,
            key: h.finish(),
            by_name,
        }
    }

    /// The track called `name`.
    pub fn track(&self, name: &str) -> Option<TrackId> {
        let at = self
            .by_name
            .partition_point(|&i| self.slots[i as usize].name.as_str() < name);
        let &i = self.by_name.get(at)?;
        (self.slots[i as usize].name == name).then(|| self.id(i as usize))
    }

    /// Every track, in order (file order for a clip).
    pub fn tracks(&self) -> &[TrackSlot] {
        &self.slots
    }

    /// Every track's id, in the order of [`tracks`](Self::tracks).
    pub fn ids(&self) -> impl Iterator<Item = TrackId> + '_ {
        (0..self.slots.len()).map(|i| self.id(i))
    }

    /// The slot of `track`, or `None` for a track of another layout.
    pub fn slot(&self, track: TrackId) -> Option<&TrackSlot> {
        if track.layout != self.key {
            return None;
        }
        self.slots.get(track.index)
    }

    /// Heap bytes: the slots with their names, the rotation blocks and the
    /// name index.
    pub(crate) fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        let names: usize = self.slots.iter().map(|s| s.name.len()).sum();
        size_of_val(self.slots.as_slice())
            + names
            + size_of_val(self.quat_blocks.as_slice())
            + size_of_val(self.by_name.as_slice())
    }

    /// The id of track `i` (`i` below the track count).
    pub(crate) fn id(&self, index: usize) -> TrackId {
        TrackId {
            index,
            layout: self.key,
        }
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
