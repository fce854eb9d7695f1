//! Compiling validated tcb-core clips into the runtime layout.
//!
//! Tracks are grouped by identical key times, segment eases and `pre`/`post`
//! modes; a group's channels share one [`FrameBasis`](crate::grid::FrameBasis)
//! per frame. Per group, per stored segment (see [`crate::grid`]), per block
//! of 8 channels, the Hermite controls are stored lane-contiguous as
//! `wide::f32x8` (32-byte aligned, zero-padded; squad in `f64x4`):
//!
//! ```text
//! vectors   [segment][block][P0 P1 M0 M1]                       4 x f32x8
//! hermite   [segment][block][P0 P1 M0 M1][x y z w]             16 x f32x8
//! squad     [segment][half block][q0 n01 alpha01 a n_ab alpha_ab]   16 x f64x4
//! ```
//!
//! `linear` and `step` segments and explicit tangents are folded into the
//! same controls, so the kernels have no per-channel branches. A `hermite`
//! rotation whose segments are all `linear`/`step` is stored as squad (where
//! slerp is exact); one that mixes slerp with curve segments, and squad
//! velocities, are taken from the scalar reference (documented, rare).

use crate::grid::TimeGrid;
use crate::kernel::{HQ_STRIDE, SQ_STRIDE, VEC_STRIDE};
use crate::loose::{Loose, LooseLane};
use crate::pose::PoseLayout;
use glam::DQuat;
use std::collections::HashMap;
use std::sync::Arc;
use tcb_core::ease::SegmentEase;
use tcb_core::rotation::RotationTrack;
use tcb_core::{Extrapolation, Interp, Track, TrackData, TrackKind, Value};
use wide::{f32x8, f64x4};

/// Index of a track in its clip (file order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TrackId(pub usize);

/// Where a track's components live in a [`crate::Pose`] (flat `f32` indices).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackSlot {
    /// Name from the clip.
    pub name: String,
    /// Kind.
    pub kind: TrackKind,
    /// Flat index of each component (`kind.dim()` used).
    pub index: [usize; 4],
}

/// One shared key grid of a compiled clip (see [`Clip::stats`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GridStats {
    /// Keys of the grid.
    pub keys: usize,
    /// Vector channels on it (a vec3 counts 3).
    pub vector_channels: usize,
    /// `hermite` rotations on it.
    pub hermite_rotations: usize,
    /// `squad` (and all-slerp) rotations on it.
    pub squad_rotations: usize,
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
    /// Rotations the scalar reference samples (`hermite` mixing slerp and curve keys).
    pub reference_rotations: usize,
    /// Squad rotations whose velocity the scalar reference gives.
    pub squad_velocity_fallbacks: usize,
    /// [`Clip::memory_bytes`].
    pub bytes: usize,
    /// [`Clip::memory_bytes_compiled`].
    pub bytes_compiled: usize,
    /// [`Clip::bytes_per_frame`].
    pub bytes_per_frame: usize,
}

/// How a rotation track is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum RotLayout {
    Hermite,
    Squad,
    Reference,
}

/// Channels sharing one time grid.
#[derive(Clone, Debug)]
pub(crate) struct Group {
    pub grid: TimeGrid,
    /// Vector channels, hermite and squad rotations (lanes in use).
    pub lanes: [usize; 3],
    pub vec_blocks: usize,
    pub vec: Vec<f32x8>,
    /// `P_{n-1} - P_0` per vector block, when a side is `offset-repeat`.
    pub delta: Vec<f32x8>,
    pub vec_out: usize,
    pub hq_blocks: usize,
    pub hq: Vec<f32x8>,
    pub hq_out: usize,
    pub sq_blocks: usize,
    /// Two halves of 4 lanes per output block of 8.
    pub sq: Vec<f64x4>,
    pub sq_out: usize,
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
    /// Tracks the scalar reference samples (value and velocity).
    pub(crate) reference: Vec<TrackId>,
    /// Squad tracks, whose velocity the scalar reference gives.
    pub(crate) squad_velocity: Vec<TrackId>,
    pub(crate) source: tcb_core::Clip,
}

/// Flat pose indices of component planes x..w of `lane` in blocks of 8
/// lanes, 4 planes a block, from pose block `out`.
pub(crate) fn plane_slots(out: usize, lane: usize) -> [usize; 4] {
    let base = (out + 4 * (lane / 8)) * 8 + lane % 8;
    [base, base + 8, base + 16, base + 24]
}

/// A padding lane of loose rotations: the identity at all times.
fn identity_lane() -> LooseLane {
    let w = [1.0, 1.0, 0.0, 0.0];
    LooseLane {
        grid: TimeGrid {
            times: vec![0.0, 1.0],
            eases: vec![SegmentEase::default()],
            pre: Extrapolation::Constant,
            post: Extrapolation::Constant,
        },
        dim: 4,
        controls: vec![[[0.0; 4], [0.0; 4], [0.0; 4], w]; 3],
    }
}

/// Channel controls over the stored segments `0..=n`.
type Controls = Vec<[f32; 4]>;

fn vector_controls<V: Value>(t: &Track<V>) -> Vec<Controls> {
    let n = t.times().len();
    let segs = t.segments();
    let last = &segs[n - 2];
    let d = t.times()[n - 1] - t.times()[n - 2];
    let end_rate = (last.ease.apply(1.0).1 / d) as f32;
    let (first_v, last_v) = (t.values()[0].to_array(), t.values()[n - 1].to_array());
    let (to, ti) = (t.start_tangent().to_array(), t.end_tangent().to_array());
    (0..V::DIM)
        .map(|c| {
            let mut ctl = Vec::with_capacity(n + 1);
            ctl.push([first_v[c], first_v[c], to[c], 0.0]);
            for s in segs {
                ctl.push([
                    s.p0.to_array()[c],
                    s.p1.to_array()[c],
                    s.m0.to_array()[c],
                    s.m1.to_array()[c],
                ]);
            }
            let arrive = last.m1.to_array()[c] * end_rate;
            ctl.push([last_v[c], last_v[c], ti[c], arrive]);
            ctl
        })
        .collect()
}

fn grid_of(data: &TrackData) -> TimeGrid {
    fn eases<V: Value>(t: &Track<V>) -> Vec<SegmentEase> {
        t.segments().iter().map(|s| s.ease).collect()
    }
    let (eases, settings) = match data {
        TrackData::Scalar(t) => (eases(t), *t.settings()),
        TrackData::Vec2(t) => (eases(t), *t.settings()),
        TrackData::Vec3(t) => (eases(t), *t.settings()),
        TrackData::Vec4(t) => (eases(t), *t.settings()),
        TrackData::Quat(t) => (t.eases().to_vec(), *t.settings()),
    };
    TimeGrid {
        times: data.times().to_vec(),
        eases,
        pre: settings.pre,
        post: settings.post,
    }
}

type GridKey = (Vec<u64>, Vec<(u64, u64)>, Extrapolation, Extrapolation);

fn grid_key(g: &TimeGrid) -> GridKey {
    (
        g.times.iter().map(|t| t.to_bits()).collect(),
        g.eases
            .iter()
            .map(|e| (e.from.to_bits(), e.to.to_bits()))
            .collect(),
        g.pre,
        g.post,
    )
}

fn rot_layout(t: &RotationTrack) -> RotLayout {
    if t.squad_segments().is_some() {
        return RotLayout::Squad;
    }
    let interps = &t.interps()[..t.interps().len() - 1];
    let slerp = interps.contains(&Interp::Linear);
    let curve = interps.contains(&Interp::Curve);
    match (slerp, curve) {
        (false, _) => RotLayout::Hermite,
        (true, false) => RotLayout::Squad,
        (true, true) => RotLayout::Reference,
    }
}

/// `p` followed by the unit axis and angle of `log(p^-1 q)`, so that
/// `slerp(p, q, s) = p exp(s angle axis)` (plain slerp, no hemisphere flip).
fn slerp_controls(p: DQuat, q: DQuat) -> [f64; 8] {
    let v = tcb_core::rotation::quat_log(p.conjugate() * q);
    let alpha = v.length();
    let n = if alpha > 0.0 {
        v / alpha
    } else {
        glam::DVec3::ZERO
    };
    [p.x, p.y, p.z, p.w, n.x, n.y, n.z, alpha]
}

/// Squad controls over stored segments `0..=n` (see [`slerp_controls`]).
fn squad_controls(t: &RotationTrack) -> Vec<[f64; SQ_STRIDE]> {
    let keys: Vec<DQuat> = t.values().iter().map(|q| q.as_dquat()).collect();
    let n = keys.len();
    let quads: Vec<[DQuat; 4]> = match t.squad_segments() {
        Some(segs) => segs.iter().map(|s| [s.q0, s.q1, s.a, s.b]).collect(),
        None => (0..n - 1)
            .map(|k| match t.interps()[k] {
                Interp::Step => [keys[k]; 4],
                _ => [keys[k], keys[k + 1], keys[k], keys[k + 1]],
            })
            .collect(),
    };
    let mut out = Vec::with_capacity(n + 1);
    let mut push = |q: [DQuat; 4]| {
        let mut c = [0.0f64; SQ_STRIDE];
        c[..8].copy_from_slice(&slerp_controls(q[0], q[1]));
        c[8..].copy_from_slice(&slerp_controls(q[2], q[3]));
        out.push(c);
    };
    push([keys[0]; 4]);
    for q in quads {
        push(q);
    }
    push([keys[n - 1]; 4]);
    out
}

/// Lay per-lane control rows into blocks of `N` lanes (`f32x8`: 8,
/// `f64x4`: 4), `blocks` of them:
/// `out[(seg * blocks + b) * width + j]` lane `l` = `rows[b * N + l][seg][j]`;
/// lanes past the last row get `pad`.
fn pack_lanes<T: Copy + Default, L: Clone, const N: usize, const W: usize>(
    rows: &[Vec<[T; W]>],
    segments: usize,
    blocks: usize,
    pad: [T; W],
    make: fn([T; N]) -> L,
) -> Vec<L> {
    let mut out = Vec::with_capacity(segments * blocks * W);
    for seg in 0..segments {
        for b in 0..blocks {
            for j in 0..W {
                let lanes: [T; N] =
                    std::array::from_fn(|l| rows.get(b * N + l).map_or(pad[j], |r| r[seg][j]));
                out.push(make(lanes));
            }
        }
    }
    out
}

/// [`pack_lanes`] into `f32x8` blocks.
fn pack<const W: usize>(rows: &[Vec<[f32; W]>], segments: usize, pad: [f32; W]) -> Vec<f32x8> {
    pack_lanes(rows, segments, rows.len().div_ceil(8), pad, f32x8::new)
}

/// [`pack_lanes`] into `f64x4` half blocks, two per block of 8 channels.
fn pack_f64<const W: usize>(rows: &[Vec<[f64; W]>], segments: usize, pad: [f64; W]) -> Vec<f64x4> {
    pack_lanes(rows, segments, 2 * rows.len().div_ceil(8), pad, f64x4::new)
}

/// Controls of an unused rotation lane: the identity, so that padding lanes
/// normalize to a finite value, not 0/0. `w` sits at index 3 of the first and
/// of the second quaternion of a row (P0 and P1 for hermite, q0 and a for squad).
fn identity_pad(second_w: usize) -> [f32; 16] {
    let mut pad = [0.0; 16];
    pad[3] = 1.0;
    pad[second_w] = 1.0;
    pad
}

impl Clip {
    /// Compile a validated clip.
    ///
    /// ```
    /// let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
    ///   {"name": "x", "kind": "vec3", "times": [0, 1], "values": [[0, 0, 0], [1, 2, 3]]}]}"#)
    ///     .unwrap().build().unwrap();
    /// let clip = tcb_runtime::Clip::compile(&clip);
    /// assert_eq!(clip.track("x").map(|t| t.0), Some(0));
    /// ```
    pub fn compile(source: &tcb_core::Clip) -> Self {
        let mut group_of: HashMap<GridKey, usize> = HashMap::new();
        let mut grids: Vec<TimeGrid> = Vec::new();
        // Per group: vector channel rows (track, component), hermite rows, squad rows.
        let mut vec_rows: Vec<Vec<(usize, usize, Controls)>> = Vec::new();
        // Hermite rotations: per component (x, y, z, w), as vectors keep them.
        let mut hq_rows: Vec<Vec<(usize, Vec<Controls>)>> = Vec::new();
        let mut sq_rows: Vec<Vec<(usize, Vec<[f64; SQ_STRIDE]>)>> = Vec::new();
        let mut reference = Vec::new();
        let mut squad_velocity = Vec::new();
        for (i, t) in source.tracks.iter().enumerate() {
            if let TrackData::Quat(r) = &t.data
                && rot_layout(r) == RotLayout::Reference
            {
                reference.push(TrackId(i));
                continue;
            }
            let grid = grid_of(&t.data);
            let g = *group_of.entry(grid_key(&grid)).or_insert_with(|| {
                grids.push(grid);
                vec_rows.push(Vec::new());
                hq_rows.push(Vec::new());
                sq_rows.push(Vec::new());
                grids.len() - 1
            });
            let mut vectors = |ctl: Vec<Controls>| {
                for (c, rows) in ctl.into_iter().enumerate() {
                    vec_rows[g].push((i, c, rows));
                }
            };
            match &t.data {
                TrackData::Scalar(v) => vectors(vector_controls(v)),
                TrackData::Vec2(v) => vectors(vector_controls(v)),
                TrackData::Vec3(v) => vectors(vector_controls(v)),
                TrackData::Vec4(v) => vectors(vector_controls(v)),
                TrackData::Quat(r) => match rot_layout(r) {
                    RotLayout::Hermite => {
                        let comps = vector_controls(r.hermite_track().expect("hermite"));
                        hq_rows[g].push((i, comps));
                    }
                    _ => {
                        squad_velocity.push(TrackId(i));
                        sq_rows[g].push((i, squad_controls(r)));
                    }
                },
            }
        }

        // Small groups of vector channels only: one lane per track (see loose.rs).
        let mut loose_lanes: Vec<(usize, LooseLane)> = Vec::new();
        let mut loose_rots: Vec<(usize, LooseLane)> = Vec::new();
        let mut keep = vec![true; grids.len()];
        for g in 0..grids.len() {
            // Small groups of hermite rotations only (reset, which gives the
            // identity rather than zero, stays on the group path).
            let resets = [grids[g].pre, grids[g].post].contains(&Extrapolation::Reset);
            if vec_rows[g].is_empty()
                && sq_rows[g].is_empty()
                && !hq_rows[g].is_empty()
                && hq_rows[g].len() < 8
                && !resets
            {
                keep[g] = false;
                for (track, comps) in &hq_rows[g] {
                    let comps: Vec<&Controls> = comps.iter().collect();
                    loose_rots.push((*track, LooseLane::new(grids[g].clone(), &comps)));
                }
                continue;
            }
            if hq_rows[g].is_empty() && sq_rows[g].is_empty() && vec_rows[g].len() < 8 {
                keep[g] = false;
                let mut by_track: Vec<(usize, Vec<&Controls>)> = Vec::new();
                for (track, _, rows) in &vec_rows[g] {
                    match by_track.last_mut() {
                        Some((t, comps)) if t == track => comps.push(rows),
                        _ => by_track.push((*track, vec![rows])),
                    }
                }
                for (track, comps) in by_track {
                    loose_lanes.push((track, LooseLane::new(grids[g].clone(), &comps)));
                }
            }
        }

        let mut slots: Vec<TrackSlot> = source
            .tracks
            .iter()
            .map(|t| TrackSlot {
                name: t.name.clone(),
                kind: t.data.kind(),
                index: [0; 4],
            })
            .collect();
        let mut groups = Vec::with_capacity(grids.len());
        let mut quat_blocks = Vec::new();
        let mut at = 0usize; // pose block
        for (g, grid) in grids.into_iter().enumerate() {
            if !keep[g] {
                continue;
            }
            let segments = grid.times.len() + 1;
            let vrows: Vec<Controls> = vec_rows[g].iter().map(|r| r.2.clone()).collect();
            let vec_blocks = vrows.len().div_ceil(8);
            let vec_out = at;
            for (lane, (track, comp, _)) in vec_rows[g].iter().enumerate() {
                slots[*track].index[*comp] = vec_out * 8 + lane;
            }
            at += vec_blocks;
            let delta = if [grid.pre, grid.post].contains(&Extrapolation::OffsetRepeat) {
                let d: Vec<Vec<[f32; 1]>> = vrows
                    .iter()
                    .map(|r| vec![[r[segments - 1][0] - r[0][0]]])
                    .collect();
                pack(&d, 1, [0.0])
            } else {
                Vec::new()
            };
            let quats = |tracks: &[usize],
                         at: &mut usize,
                         slots: &mut Vec<TrackSlot>,
                         quat_blocks: &mut Vec<usize>| {
                let blocks = tracks.len().div_ceil(8);
                let out = *at;
                for (lane, track) in tracks.iter().enumerate() {
                    slots[*track].index = plane_slots(out, lane);
                }
                for b in 0..blocks {
                    quat_blocks.push(out + 4 * b);
                }
                *at += 4 * blocks;
                (blocks, out)
            };
            let ids: Vec<usize> = hq_rows[g].iter().map(|r| r.0).collect();
            let (hq_blocks, hq_out) = quats(&ids, &mut at, &mut slots, &mut quat_blocks);
            let ids: Vec<usize> = sq_rows[g].iter().map(|r| r.0).collect();
            let (sq_blocks, sq_out) = quats(&ids, &mut at, &mut slots, &mut quat_blocks);
            // [P0 P1 M0 M1] x [x y z w] per stored segment.
            let hrows: Vec<Vec<[f32; HQ_STRIDE]>> = hq_rows[g]
                .iter()
                .map(|(_, comps)| {
                    (0..comps[0].len())
                        .map(|seg| std::array::from_fn(|k| comps[k % 4][seg][k / 4]))
                        .collect()
                })
                .collect();
            let srows: Vec<_> = sq_rows[g].iter().map(|r| r.1.clone()).collect();
            groups.push(Group {
                lanes: [vrows.len(), hq_rows[g].len(), sq_rows[g].len()],
                vec: pack(&vrows, segments, [0.0; VEC_STRIDE]),
                delta,
                vec_blocks,
                vec_out,
                hq: pack(&hrows, segments, identity_pad(7)),
                hq_blocks,
                hq_out,
                sq: pack_f64(&srows, segments, identity_pad(11).map(f64::from)),
                sq_blocks,
                sq_out,
                grid,
            });
        }
        // Loose tracks: planes of 8 lanes, like rotations.
        for (lane, (track, _)) in loose_lanes.iter().enumerate() {
            slots[*track].index = plane_slots(at, lane);
        }
        let loose = Loose::new(loose_lanes.into_iter().map(|(_, l)| l).collect(), at);
        at += 4 * loose.blocks;
        // Loose rotations: planes of 8 lanes, blended as rotations.
        for (lane, (track, _)) in loose_rots.iter().enumerate() {
            slots[*track].index = plane_slots(at, lane);
        }
        let loose_rot_tracks = loose_rots.len();
        let mut rot_lanes: Vec<LooseLane> = loose_rots.into_iter().map(|(_, l)| l).collect();
        while !rot_lanes.len().is_multiple_of(8) {
            rot_lanes.push(identity_lane());
        }
        let loose_rot = Loose::new(rot_lanes, at);
        for b in 0..loose_rot.blocks {
            quat_blocks.push(at + 4 * b);
        }
        at += 4 * loose_rot.blocks;
        // Reference-sampled rotations: four consecutive floats each.
        let mut loose_quats = Vec::new();
        if !reference.is_empty() {
            for (j, id) in reference.iter().enumerate() {
                let base = at * 8 + 4 * j;
                slots[id.0].index = [base, base + 1, base + 2, base + 3];
                loose_quats.push(base);
            }
            at += (4 * reference.len()).div_ceil(8);
        }
        Clip {
            name: source.name.clone(),
            groups,
            layout: Arc::new(PoseLayout {
                slots,
                blocks: at,
                quat_blocks,
                loose_quats,
            }),
            loose,
            loose_rot,
            loose_rot_tracks,
            reference,
            squad_velocity,
            source: source.clone(),
        }
    }

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

    /// The validated clip this was compiled from.
    pub fn source(&self) -> &tcb_core::Clip {
        &self.source
    }

    /// First and last key time over all tracks.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        self.source.time_range()
    }

    /// Heap bytes of the compiled clip, counted from its buffers' lengths:
    /// the kernels' controls, the time grids, the pose layout, and the copy
    /// of the validated source clip it keeps (see
    /// [`memory_bytes_compiled`](Self::memory_bytes_compiled) without it).
    pub fn memory_bytes(&self) -> usize {
        self.memory_bytes_compiled() + self.source.heap_bytes()
    }

    /// [`memory_bytes`](Self::memory_bytes) without the source clip's copy.
    pub fn memory_bytes_compiled(&self) -> usize {
        use std::mem::{size_of, size_of_val};
        let grid = |g: &TimeGrid| size_of_val(g.times.as_slice()) + size_of_val(g.eases.as_slice());
        let groups: usize = self
            .groups
            .iter()
            .map(|g| {
                size_of::<Group>()
                    + grid(&g.grid)
                    + size_of_val(g.vec.as_slice())
                    + size_of_val(g.delta.as_slice())
                    + size_of_val(g.hq.as_slice())
                    + size_of_val(g.sq.as_slice())
            })
            .sum();
        let loose = self.loose.heap_bytes() + self.loose_rot.heap_bytes();
        let layout = self
            .layout
            .slots
            .iter()
            .map(|s| size_of::<TrackSlot>() + s.name.len())
            .sum::<usize>()
            + size_of_val(self.layout.quat_blocks.as_slice())
            + size_of_val(self.layout.loose_quats.as_slice());
        self.name.len()
            + groups
            + loose
            + layout
            + size_of_val(self.reference.as_slice())
            + size_of_val(self.squad_velocity.as_slice())
    }

    /// How the clip was laid out: its shared grids, loose tracks and
    /// reference fallbacks, and its bytes (what `tcb info` prints).
    pub fn stats(&self) -> ClipStats {
        ClipStats {
            grids: self
                .groups
                .iter()
                .map(|g| GridStats {
                    keys: g.grid.keys(),
                    vector_channels: g.lanes[0],
                    hermite_rotations: g.lanes[1],
                    squad_rotations: g.lanes[2],
                })
                .collect(),
            loose_vector_tracks: self.loose.lanes.len(),
            loose_rotation_tracks: self.loose_rot_tracks,
            reference_rotations: self.reference.len(),
            squad_velocity_fallbacks: self.squad_velocity.len(),
            bytes: self.memory_bytes(),
            bytes_compiled: self.memory_bytes_compiled(),
            bytes_per_frame: self.bytes_per_frame(),
        }
    }

    /// Bytes of coefficients the kernels read per frame when every group is
    /// inside its keys (one stored segment per group).
    pub fn bytes_per_frame(&self) -> usize {
        self.groups
            .iter()
            .map(|g| {
                (g.vec_blocks * VEC_STRIDE + g.hq_blocks * HQ_STRIDE + g.sq_blocks * 2 * SQ_STRIDE)
                    * 32
            })
            .sum()
    }
}
