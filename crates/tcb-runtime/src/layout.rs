//! Where every track lives in a pose: the layout a clip (or a rig) and
//! its poses share, and the ids that name its tracks.

use tcb_core::TrackKind;

/// A track of one pose layout (a clip's, or a [`Rig`](crate::Rig)'s), as
/// [`Clip::track`](crate::Clip::track), [`PoseLayout::track`] or [`PoseLayout::ids`] give it.
/// It remembers its layout: a [`crate::Pose`] of another layout answers
/// `None` to it rather than another track's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TrackId {
    pub(crate) index: usize,
    pub(crate) layout: u64,
}

impl TrackId {
    /// Its position in the layout's tracks (file order for a clip).
    pub fn index(self) -> usize {
        self.index
    }
}

/// A track of a pose layout: its name and kind (and, inside the crate,
/// where its components live in a [`crate::Pose`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct TrackSlot {
    pub(crate) name: String,
    pub(crate) kind: TrackKind,
    /// Flat index of each component (`kind.dim()` used).
    pub(crate) index: [usize; 4],
}

impl TrackSlot {
    /// Name from the clip (or the rig).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Kind.
    pub fn kind(&self) -> TrackKind {
        self.kind
    }
}

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

/// Flat pose indices of component planes x..w of `lane` in blocks of 8
/// lanes, 4 planes a block, from pose block `out`.
pub(crate) fn plane_slots(out: usize, lane: usize) -> [usize; 4] {
    let base = (out + 4 * (lane / 8)) * 8 + lane % 8;
    [base, base + 8, base + 16, base + 24]
}
