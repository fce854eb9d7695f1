//! Compiling validated tcb-core clips into the runtime layout.
//!
//! Tracks are grouped by identical key times, segment eases and `pre`/`post`
//! modes; a group's channels share one `grid::FrameBasis`
//! per frame. Per group, per key (and sentinel pseudo-key, see
//! `per_key`), the Hermite controls are stored lane-contiguous as
//! `wide::f32x8` planes (32-byte aligned, unused lanes zero or, for
//! rotations, the identity), vector blocks first, then rotation blocks
//! (see `crate::store`):
//!
//! ```text
//! vectors     [key][P TO (TI)][block]                    1 plane each
//! rotations   [key][P TO (TI)][block][x y z w]           4 planes each, normalized after
//! exact       per (segment, block) where needed: squad in power form, 2 x 16 x f64x4
//! ```
//!
//! `TI` is stored only where it differs from `TO` (it seldom does on evenly
//! spaced keys), and a segment reads `P0 TO0` of its first key and `P1 TI1`
//! of its second.
//!
//! `linear` and `step` segments and explicit tangents are folded into the
//! same controls, so the kernels have no per-channel branches. Every
//! rotation mode compiles to the same cubic form: `hermite` curves as they
//! are, squad and slerp segments as the cubic through their ends with
//! their end derivatives, checked against the f64 formula when the clip is
//! compiled (see `rotation_controls`); the few segments where that cubic
//! would miss (large turns between keys) are evaluated exactly, lane by
//! lane under a mask, from [`tcb_core::simd::squad`] in `f64x4`. Nothing falls
//! back to the scalar reference.

use crate::grid::TimeGrid;
use crate::group::Group;
use crate::layout::{PoseLayout, TrackId, TrackSlot};
use crate::loose::Loose;
use crate::pack::Packed;
use std::sync::Arc;

/// One shared key grid of a compiled clip (see [`Clip::stats`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GridStats {
    /// Keys of the grid.
    pub keys: usize,
    /// Vector channels on it (a vec3 counts 3).
    pub vector_channels: usize,
    /// Rotations on it (any mode).
    pub rotations: usize,
    /// Keys whose incoming tangents are stored apart from their outgoing
    /// ones (in some bit of some channel they differ); the others store one.
    pub keys_with_own_incoming: usize,
}

/// The layout and size of a compiled clip (see [`Clip::stats`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClipStats {
    /// Grids whose channels share one basis per frame.
    pub grids: Vec<GridStats>,
    /// Vector tracks on key times of their own (loose lanes).
    pub loose_vector_tracks: usize,
    /// `hermite` rotations on key times of their own (loose lanes).
    pub loose_rotation_tracks: usize,
    /// Keys of the loose lanes, all counted (what forward playback over
    /// the clip crosses, each crossing a load).
    pub loose_keys: usize,
    /// Rotation segments (per track) evaluated exactly, in f64 squad,
    /// because the compiled cubic would miss the reference there.
    pub exact_segments: usize,
    /// Of those, the segments whose cubic misses only the velocity: an
    /// instance without velocities takes the cubic there.
    pub exact_for_velocity_only: usize,
    /// [`Clip::memory_bytes`].
    pub bytes: usize,
    /// [`Clip::bytes_per_frame`].
    pub bytes_per_frame: usize,
}

/// A compiled clip: immutable, `Send + Sync`, shared between instances by `Arc`.
#[derive(Clone, Debug)]
pub struct Clip {
    pub(crate) name: String,
    pub(crate) groups: Vec<Group>,
    pub(crate) layout: Arc<PoseLayout>,
    /// Vector tracks of small groups, one lane each.
    pub(crate) loose: Loose,
    /// Hermite rotations of small groups, one lane each (4 component
    /// planes, normalized after sampling; padded to whole blocks with
    /// constant identity lanes).
    pub(crate) loose_rot: Loose,
    /// Real tracks among `loose_rot`'s lanes (the rest are padding).
    pub(crate) loose_rot_tracks: usize,
    pub(crate) time_range: Option<(f64, f64)>,
    /// Per track: the bound on the error quantization adds (0 without).
    pub(crate) quant_error: Vec<f32>,
    /// Per track: its keys are stored in 16 bits.
    pub(crate) quantized: Vec<bool>,
    /// The packed clip it was compiled from (`crate::pack`), whose stream
    /// its group decodes.
    pub(crate) packed: Option<Arc<Packed>>,
}

impl Clip {
    /// The clip's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The track called `name`.
    pub fn track(&self, name: &str) -> Option<TrackId> {
        self.layout.track(name)
    }

    /// Every track's slot, in file order.
    pub fn tracks(&self) -> &[TrackSlot] {
        &self.layout.slots
    }

    /// The layout of this clip's poses.
    pub fn layout(&self) -> &Arc<PoseLayout> {
        &self.layout
    }

    /// Number of time grids whose channels share one basis per frame.
    pub fn group_count(&self) -> usize {
        self.groups.len()
    }

    /// Number of tracks sampled as loose lanes (their own time grid, mapped
    /// eight tracks at a time).
    pub fn loose_track_count(&self) -> usize {
        self.loose.lanes.len() + self.loose_rot_tracks
    }

    /// The bound on what quantization moves `track`'s samples inside its
    /// keys, in the track's units (0 for a clip compiled without it; `None`
    /// for a track of another layout): `e_P + 4/27 (e_TO + e_TI)` with
    /// `e_*` the largest error rounding made on its stored positions and
    /// tangents (a sample is `h1 P0 + h2 P1 + h3 M0 + h4 M1`, `|h3|, |h4| <=
    /// 4/27`), for rotations times what normalizing can grow it (about 2).
    pub fn quantization_error(&self, track: TrackId) -> Option<f32> {
        self.layout.slot(track)?;
        Some(self.quant_error.get(track.index).copied().unwrap_or(0.0))
    }

    /// Whether `track`'s keys are stored in 16 bits (`None` for a track of
    /// another layout): false without [`CompileOptions::quantize`], and for
    /// a track whose range 16 bits cannot span within a finite bound
    /// (values or tangents beyond f32 in its keys), which quantizing keeps
    /// in f32 (with its group).
    ///
    /// [`CompileOptions::quantize`]: crate::CompileOptions::quantize
    pub fn is_quantized(&self, track: TrackId) -> Option<bool> {
        self.layout.slot(track)?;
        Some(self.quantized.get(track.index).copied().unwrap_or(false))
    }

    /// First and last key time over all tracks.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        self.time_range
    }

    /// Values per sample, as [`tcb_core::SourceClip::channel_count`] (a rotation counts 4).
    pub fn channel_count(&self) -> usize {
        self.layout.slots.iter().map(|s| s.kind.dim()).sum()
    }

    /// Heap bytes of the compiled clip, counted from its buffers' lengths:
    /// the kernels' controls, the time grids and the pose layout. It keeps
    /// no copy of the source clip.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::{size_of, size_of_val};
        let grid = |g: &TimeGrid| {
            g.times.heap_bytes() + size_of_val(g.eases.as_slice()) + size_of_val(g.steps.as_slice())
        };
        let groups: usize = self
            .groups
            .iter()
            .map(|g| {
                size_of::<Group>()
                    + grid(&g.grid)
                    + g.keys.heap_bytes()
                    + size_of_val(g.delta.as_slice())
                    + g.exact.heap_bytes()
            })
            .sum();
        let loose = self.loose.heap_bytes() + self.loose_rot.heap_bytes();
        self.name.len() + groups + loose + self.layout.heap_bytes()
    }

    /// How the clip was laid out: its shared grids, loose tracks and
    /// reference fallbacks, and its bytes (what `tcb info` prints).
    pub fn stats(&self) -> ClipStats {
        ClipStats {
            grids: self
                .groups
                .iter()
                .map(|g| GridStats {
                    keys_with_own_incoming: g.keys.own_ti(g.grid.keys()),
                    keys: g.grid.keys(),
                    vector_channels: g.vector_channels,
                    rotations: g.rotations,
                })
                .collect(),
            loose_vector_tracks: self.loose.lanes.len(),
            loose_rotation_tracks: self.loose_rot_tracks,
            // (the identity lanes that pad rotations to whole blocks, after
            // the tracks' lanes, are not tracks)
            loose_keys: (self.loose.lanes.iter())
                .chain(&self.loose_rot.lanes[..self.loose_rot_tracks])
                .map(|lane| lane.grid.keys())
                .sum(),
            exact_segments: self
                .groups
                .iter()
                .flat_map(|g| &g.exact.entries)
                .map(|e| e.mask.to_bitmask().count_ones() as usize)
                .sum(),
            exact_for_velocity_only: self
                .groups
                .iter()
                .flat_map(|g| &g.exact.entries)
                .map(|e| (e.mask.to_bitmask() & !e.value_mask.to_bitmask()).count_ones() as usize)
                .sum(),
            bytes: self.memory_bytes(),
            bytes_per_frame: self.bytes_per_frame(),
        }
    }

    /// Bytes of coefficients the kernels read per frame when every group is
    /// inside its keys (one stored segment per group).
    pub fn bytes_per_frame(&self) -> usize {
        self.groups
            .iter()
            .map(|g| {
                let bytes = if g.keys.quantized() { 16 } else { 32 };
                4 * g.keys.planes() * bytes
            })
            .sum()
    }

    /// The `.tcbc` bytes of a clip compiled from a packed one; `None` for
    /// others (compile them with `tcb compress` first).
    pub fn to_bytes(&self) -> Option<Vec<u8>> {
        self.packed.as_ref().map(|p| p.to_bytes())
    }

    /// The packed clip this clip was compiled from, if any.
    pub fn packed(&self) -> Option<&Arc<Packed>> {
        self.packed.as_ref()
    }
}
