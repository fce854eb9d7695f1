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
//! lane under a mask, from [`tcb_core::squad`] in `f64x4`. Nothing falls
//! back to the scalar reference.

use crate::grid::TimeGrid;
use crate::kernel::{HQ_STRIDE, KEY_STRIDE, SQ_STRIDE};
use crate::loose::{Loose, LooseLane};
use crate::pack::Packed;
use crate::pose::PoseLayout;
use crate::store::KeyStore;
use std::collections::HashMap;
use std::sync::Arc;
use tcb_core::ease::SegmentEase;
use tcb_core::rotation::RotationTrack;
use tcb_core::{Extrapolation, Interp, Track, TrackData, TrackKind, Value};
use wide::{f32x8, f64x4};

/// A track of one pose layout (a clip's, or a [`Rig`](crate::Rig)'s), as
/// [`Clip::track`], [`PoseLayout::track`] or [`PoseLayout::ids`] give it.
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

/// Channels sharing one time grid.
#[derive(Clone, Debug)]
pub(crate) struct Group {
    pub grid: TimeGrid,
    /// Vector channels and rotations (lanes in use), exact entries.
    pub lanes: [usize; 3],
    /// Vector blocks (one plane each), then rotation blocks (four planes
    /// each) from pose block `vec_out` on.
    pub vec_blocks: usize,
    pub hq_blocks: usize,
    pub vec_out: usize,
    /// Their controls per key, f32 or quantized.
    pub keys: KeyStore,
    /// `P_{n-1} - P_0` per vector block, when a side is `offset-repeat`.
    pub delta: Vec<f32x8>,
    /// Per stored segment `k`, its entries of `exact`: `exact_at[k]..exact_at[k + 1]`
    /// (empty when `exact` is).
    pub exact_at: Vec<u32>,
    /// Rotation blocks evaluated exactly (squad in f64) on some segment.
    pub exact: Vec<Exact>,
    /// The squad controls `exact` entries read (`Exact::controls`): the
    /// pieces of a split segment share their segment's.
    pub exact_controls: Vec<[f64x4; 2 * SQ_STRIDE]>,
}

/// One rotation block on one stored segment, evaluated exactly: the lanes
/// of `mask` take squad in f64 from `Group::exact_controls[controls]` (two
/// halves of 4 lanes; the other lanes hold the identity and are not used).
/// The lanes of `value_mask` are those whose cubic misses the values; the
/// others miss only the velocities, so an instance without velocities
/// leaves them to the cubic (and skips entries whose `value_mask` is
/// empty). `piece` (`[a, w]`) places the stored segment in the squad
/// segment, `s = a + w u`: `[0, 1]` but for a piece of a split segment
/// (`split_rotation`, which splits only the rotation of a group of one, so
/// one `piece` serves the block).
#[derive(Clone, Debug)]
pub(crate) struct Exact {
    pub mask: f32x8,
    pub value_mask: f32x8,
    pub piece: [f64; 2],
    pub block: u32,
    pub controls: u32,
    pub values: bool,
}

/// The exact entries of one group's rotations, per stored segment: offsets
/// per stored segment, the entries, and the squad controls they read.
fn exact_table(
    rows: &[(usize, RotationControls)],
    segments: usize,
) -> (Vec<u32>, Vec<Exact>, Vec<[f64x4; 2 * SQ_STRIDE]>) {
    let identity = {
        let mut c = [0.0; SQ_STRIDE];
        c[3] = 1.0;
        c[11] = 1.0;
        c
    };
    let mut at = Vec::with_capacity(segments + 1);
    let mut out = Vec::new();
    let mut pool: Vec<[f64x4; 2 * SQ_STRIDE]> = Vec::new();
    for seg in 0..segments {
        at.push(out.len() as u32);
        for (b, block) in rows.chunks(8).enumerate() {
            if block.iter().all(|r| r.1.exact[seg].is_none()) {
                continue;
            }
            let lane = |l: usize| block.get(l).and_then(|r| r.1.exact[seg]);
            let values = |l: usize| lane(l).is_some() && !block[l].1.velocity_only[seg];
            let mask_of = |f: &dyn Fn(usize) -> bool| {
                f32x8::new(std::array::from_fn(|l| {
                    f32::from_bits(if f(l) { u32::MAX } else { 0 })
                }))
            };
            let mask = mask_of(&|l| lane(l).is_some());
            let value_mask = mask_of(&values);
            let controls: [f64x4; 2 * SQ_STRIDE] = std::array::from_fn(|k| {
                let (half, j) = (k / SQ_STRIDE, k % SQ_STRIDE);
                f64x4::new(std::array::from_fn(|l| {
                    lane(4 * half + l).unwrap_or(identity)[j]
                }))
            });
            let same = |a: &[f64x4; 2 * SQ_STRIDE]| {
                (0..2 * SQ_STRIDE).all(|k| a[k].to_array() == controls[k].to_array())
            };
            if !pool.last().is_some_and(same) {
                pool.push(controls);
            }
            let mut pieces = block
                .iter()
                .filter(|r| r.1.exact[seg].is_some())
                .map(|r| r.1.piece[seg]);
            let piece = pieces.next().expect("a lane of the entry is exact");
            debug_assert!(pieces.all(|p| p == piece), "one piece per block");
            out.push(Exact {
                mask,
                value_mask,
                piece,
                block: u32::try_from(b).expect("fewer than 2^32 blocks"),
                controls: u32::try_from(pool.len() - 1).expect("fewer than 2^32 entries"),
                values: value_mask.any(),
            });
        }
    }
    at.push(out.len() as u32);
    if out.is_empty() {
        at = Vec::new(); // nothing exact: no table to keep
    }
    (at, out, pool)
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
    /// The packed clip it was compiled from (`crate::pack`), whose stream
    /// its group decodes.
    pub(crate) packed: Option<Arc<Packed>>,
}

/// Choices made when a clip is compiled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CompileOptions {
    /// Store the controls in 16 bits per component with a per-channel
    /// range (see [`crate::quant`] for the error bound,
    /// [`Clip::quantization_error`] for each track's). Tracks on their own
    /// key times are expanded only when they cross a key.
    pub quantize: bool,
    /// Evaluate every squad (and slerp) segment's velocity by squad's own
    /// formula in f64, as the kernel does where the cubic misses, instead
    /// of by the cubic that plays its values. The cubic's velocity is
    /// checked at 17 points of each segment to 5e-5 of the rotation's
    /// fastest component (1.5e-4 off in one CMU component of 0.15); this
    /// one is the reference's to about 1e-7, for tools that print or compare velocities (`tcb sample
    /// --velocity`). Instances without velocities are unchanged; instances
    /// with velocities run squad in f64 (values and velocities) on every such
    /// segment, and the clip stores its squad controls (about 1 KB per block
    /// of 8 rotations per segment: the CMU capture compiles to 15.6 MB
    /// instead of 3.8).
    pub exact_velocities: bool,
}

/// Flat pose indices of component planes x..w of `lane` in blocks of 8
/// lanes, 4 planes a block, from pose block `out`.
pub(crate) fn plane_slots(out: usize, lane: usize) -> [usize; 4] {
    let base = (out + 4 * (lane / 8)) * 8 + lane % 8;
    [base, base + 8, base + 16, base + 24]
}

/// A padding lane of loose rotations: the identity at all times.
fn identity_lane() -> LooseLane {
    let grid = TimeGrid {
        times: vec![-crate::loose::PAD_SPAN, crate::loose::PAD_SPAN],
        eases: vec![SegmentEase::default()],
        steps: vec![false],
        pre: Extrapolation::Constant,
        post: Extrapolation::Constant,
    };
    let zero: Controls = vec![[0.0; 4]; 3];
    let w: Controls = vec![[1.0, 1.0, 0.0, 0.0]; 3];
    LooseLane::new(grid, &[&zero, &zero, &zero, &w])
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
    fn segs<V: Value>(t: &Track<V>) -> (Vec<SegmentEase>, Vec<bool>) {
        let s = t.segments();
        (
            s.iter().map(|s| s.ease).collect(),
            s.iter().map(|s| s.interp == Interp::Step).collect(),
        )
    }
    let ((eases, steps), settings) = match data {
        TrackData::Scalar(t) => (segs(t), *t.settings()),
        TrackData::Vec2(t) => (segs(t), *t.settings()),
        TrackData::Vec3(t) => (segs(t), *t.settings()),
        TrackData::Vec4(t) => (segs(t), *t.settings()),
        TrackData::Quat(t) => {
            let n = t.times().len();
            let steps = t.interps()[..n - 1]
                .iter()
                .map(|i| *i == Interp::Step)
                .collect();
            ((t.eases().to_vec(), steps), *t.settings())
        }
    };
    TimeGrid {
        times: data.times().to_vec(),
        eases,
        steps,
        pre: settings.pre,
        post: settings.post,
    }
    .compact()
}

type GridKey = (
    Vec<u64>,
    Vec<(u64, u64)>,
    Vec<bool>,
    Extrapolation,
    Extrapolation,
);

fn grid_key(g: &TimeGrid) -> GridKey {
    (
        g.times.iter().map(|t| t.to_bits()).collect(),
        g.eases
            .iter()
            .map(|e| (e.from().to_bits(), e.to().to_bits()))
            .collect(),
        g.steps.clone(),
        g.pre,
        g.post,
    )
}

/// A channel's controls per key, `[P, TO, TI]` (`TO_k` = `M0` of segment
/// k, `TI_k` = `M1` of segment k-1; nothing is stored twice), for the n
/// keys, then the sentinels as four pseudo-keys `pre_a pre_b post_a post_b`
/// that give back `[P0, P1, M0, M1]` of stored segments 0 and n the same
/// way (see [`key_pair`]).
pub(crate) fn per_key(rows: &Controls) -> Vec<[f32; KEY_STRIDE]> {
    let n = rows.len() - 1;
    let mut out: Vec<[f32; KEY_STRIDE]> = (0..n)
        .map(|k| {
            let p = if k < n - 1 {
                rows[k + 1][0]
            } else {
                rows[n][0]
            };
            let to = if k < n - 1 { rows[k + 1][2] } else { 0.0 };
            let ti = if k > 0 { rows[k][3] } else { 0.0 };
            [p, to, ti]
        })
        .collect();
    // The sentinels are read only through the fixed rows of `grid.rs` (hold,
    // reset, line, at the last key), whose zeros must not meet an infinite
    // tangent (a key whose parameters overflow f32): there, 0 * inf would
    // be NaN where the reference returns the key, or zero.
    let finite = |x: f32| {
        if x.is_nan() {
            0.0
        } else {
            x.clamp(-f32::MAX, f32::MAX)
        }
    };
    for r in [rows[0], rows[n]].map(|r| r.map(finite)) {
        out.push([r[0], r[2], 0.0]);
        out.push([r[1], 0.0, r[3]]);
    }
    out
}

/// The two keys stored segment `seg` of `grid` reads: `(a, b)` with
/// `P0 = a.P, M0 = a.TO, P1 = b.P, M1 = b.TI`. A `step` segment is played
/// at `s = 0` (basis `[1, 0, 0, 0]`), and its `b` is key 0, whose `TI` is
/// zero: its own key's `TI` belongs to the segment before and may be
/// infinite, and `0 * inf` would be NaN.
#[inline]
pub(crate) fn key_pair(grid: &TimeGrid, seg: usize) -> (usize, usize) {
    let n = grid.times.len();
    match seg {
        0 => (n, n + 1),
        s if s == n => (n + 2, n + 3),
        s if grid.is_step(s - 1) => (s - 1, 0),
        s => (s - 1, s),
    }
}

/// A rotation's hermite controls per component over the stored segments
/// `0..=n`, and per stored segment the exact squad controls where the cubic
/// misses the reference (`None` where it holds).
#[derive(Clone)]
struct RotationControls {
    comps: Vec<Controls>,
    exact: Vec<Option<[f64; SQ_STRIDE]>>,
    /// Per stored segment: its cubic holds the values, and misses only
    /// the velocities (meaningful where `exact` is set).
    velocity_only: Vec<bool>,
    /// Per stored segment `[a, w]`: it is `s` in `[a, a + w]` of the squad
    /// segment `exact` holds (`[0, 1]` but for pieces of a split segment).
    piece: Vec<[f64; 2]>,
}

/// Largest rotation component error the compiled cubic may have (the
/// runtime is held to 1e-6; this leaves room between check points).
const CUBIC_VALUE_TOL: f32 = 4e-7;
/// Largest velocity error of the cubic (per component), relative to
/// `max(1, |velocity|)` with `|velocity|` the rotation's largest component
/// velocity: half the 1e-4 of its speed the runtime is held to, leaving
/// room between check points. On the CMU capture (squad) it makes 457
/// segments exact for velocities only (3.783 MB); 2e-5 would make 1273
/// (4.351 MB) and 1e-5 6277 (8.242 MB), as f32 cancellation in
/// `6 (P1 - P0)` alone reaches about 1e-5 there; held per component instead
/// (relative to each component's own velocity, which crosses zero), 5e-5
/// doubled `sparse-rotations`' instructions and quadrupled its bytes.
const CUBIC_VELOCITY_TOL: f32 = 5e-5;

/// Every rotation as hermite controls (normalized after, like `hermite`
/// rotations): curve segments of a `hermite` track as they are; squad and
/// slerp segments as the cubic through their ends with their end
/// derivatives, checked at 17 points of the segment in the kernel's own f32
/// arithmetic against the f64 formula (value and velocity). Segments where
/// the cubic misses keep their squad controls, and the kernel evaluates
/// those lanes exactly ([`kernel::exact_quats`]).
fn rotation_controls(t: &RotationTrack, exact_velocities: bool) -> RotationControls {
    let keys = t.keys();
    let n = keys.len();
    let interps = t.interps();
    let mut comps = match t.hermite_track() {
        Some(h) => vector_controls(h),
        None => vec![vec![[0.0; 4]; n + 1]; 4],
    };
    let mut exact = vec![None; n + 1];
    let mut velocity_only = vec![false; n + 1];
    let squad = t.squad_segments();
    for k in 0..n - 1 {
        let c = match squad {
            Some(segs) => segs[k].controls(),
            None if interps[k] == Interp::Linear => {
                tcb_core::squad::controls(keys[k], keys[k + 1], keys[k], keys[k + 1])
            }
            None => continue, // a hermite curve or step segment: exact as it is
        };
        // The ends are the keys themselves (stored once per key, see `per_key`).
        let (_, d0) = tcb_core::squad::squad_with_derivative(&c, 0.0);
        let (_, d1) = tcb_core::squad::squad_with_derivative(&c, 1.0);
        let next = if interps[k] == Interp::Step { k } else { k + 1 };
        let (q0, q1) = (keys[k].to_array(), keys[next].to_array());
        let mut ctl: [[f32; 4]; 4] =
            std::array::from_fn(|i| [q0[i], q1[i], d0[i], d1[i]].map(finite_f32));
        let max_rate = 2.0 / (t.times()[k + 1] - t.times()[k]);
        let mut holds = cubic_holds(&c, &ctl, max_rate, (0.0, 1.0));
        // Where the cubic through squad's end derivatives misses the values,
        // tangents fitted to the values may hold them (an instance without
        // velocities then plays the cubic; one with velocities plays squad
        // exactly). Not the last segment: the post sentinel's arriving
        // velocity is its M1.
        if !holds.values && k + 2 < n {
            let fitted = fitted_tangents(&c, &ctl);
            let h = cubic_holds(&c, &fitted, max_rate, (0.0, 1.0));
            if h.values {
                (ctl, holds) = (fitted, h);
            }
        }
        holds.velocities &= !exact_velocities;
        for (i, comp) in comps.iter_mut().enumerate() {
            comp[k + 1] = ctl[i];
        }
        if !holds.both() {
            exact[k + 1] = Some(c);
            velocity_only[k + 1] = holds.values;
        }
    }
    // Sentinels: hold the end keys; the post one carries the velocity
    // arriving at the last key (as `vector_controls` does).
    let (first, last) = (keys[0].to_array(), keys[n - 1].to_array());
    let d = t.times()[n - 1] - t.times()[n - 2];
    let end_rate = (t.eases()[n - 2].apply(1.0).1 / d) as f32;
    for (i, comp) in comps.iter_mut().enumerate() {
        comp[0] = [first[i] as f32, first[i] as f32, 0.0, 0.0];
        let arrive = finite_f32(f64::from(comp[n - 1][3]) * f64::from(end_rate));
        comp[n] = [last[i] as f32, last[i] as f32, 0.0, arrive];
    }
    RotationControls {
        comps,
        exact,
        velocity_only,
        piece: vec![[0.0, 1.0]; n + 1],
    }
}

/// `ctl` with its tangents (`M0`, `M1` of each component) fitted to squad's
/// values over the segment in least squares, its ends kept: the cubic then
/// follows the curve more closely than the one through its end
/// derivatives, and its velocity less.
fn fitted_tangents(c: &[f64; SQ_STRIDE], ctl: &[[f32; 4]; 4]) -> [[f32; 4]; 4] {
    use tcb_core::basis::hermite_basis;
    const POINTS: usize = 64;
    let (mut a11, mut a12, mut a22) = (0.0f64, 0.0f64, 0.0f64);
    let mut rhs = [[0.0f64; 2]; 4];
    for j in 1..POINTS {
        let s = j as f64 / POINTS as f64;
        let (q, _) = tcb_core::squad::unit(c, s, false);
        let h = hermite_basis(s);
        a11 += h[2] * h[2];
        a12 += h[2] * h[3];
        a22 += h[3] * h[3];
        for (i, r) in rhs.iter_mut().enumerate() {
            let rest = q[i] - h[0] * f64::from(ctl[i][0]) - h[1] * f64::from(ctl[i][1]);
            r[0] += h[2] * rest;
            r[1] += h[3] * rest;
        }
    }
    let det = a11 * a22 - a12 * a12;
    std::array::from_fn(|i| {
        let [b1, b2] = rhs[i];
        let m0 = (a22 * b1 - a12 * b2) / det;
        let m1 = (a11 * b2 - a12 * b1) / det;
        [ctl[i][0], ctl[i][1], finite_f32(m0), finite_f32(m1)]
    })
}

/// How much normalizing can grow an error of a rotation's cubic:
/// `|d(p / |p|)| <= 2 |dp| / |p|`, so `2 / min(1, |p|)` with `|p|` the
/// smallest length of its cubic pieces (sampled at 33 points per segment,
/// with 5% to spare between them). Near 2 for curves close to unit length;
/// large where a curve between keys on opposite hemispheres, kept as
/// written, passes near zero.
fn normalize_gain(rot: &RotationControls) -> f32 {
    use tcb_core::basis::{hermite, hermite_basis};
    let n = rot.comps[0].len();
    let mut least = 1.0f32;
    for s in 1..n - 1 {
        if rot.exact[s].is_some() && !rot.velocity_only[s] {
            continue; // evaluated exactly, not as this cubic
        }
        for j in 0..=32 {
            let h = hermite_basis(j as f32 / 32.0);
            let len2: f32 = (0..4)
                .map(|c| {
                    let k = rot.comps[c][s];
                    hermite(&h, k[0], k[1], k[2], k[3]).powi(2)
                })
                .sum();
            least = least.min(len2.sqrt());
        }
    }
    2.0 / (0.95 * least).max(1e-6)
}

/// `x` in f32, finite: beyond f32's range the largest finite f32 of its
/// sign, NaN as 0. Rotation controls come from f64 (squad's derivatives,
/// tangents of keys with huge parameters); an infinite one would turn the
/// zero of a hold row into NaN. Segments whose cubic this changes miss
/// [`cubic_holds`] and are evaluated exactly.
fn finite_f32(x: f64) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    }
}

/// What [`cubic_holds`] found.
#[derive(Clone, Copy, Debug)]
struct Holds {
    values: bool,
    velocities: bool,
}

impl Holds {
    fn both(self) -> bool {
        self.values && self.velocities
    }
}

/// Whether the normalized cubic `ctl` (per component `[P0, P1, M0, M1]`,
/// evaluated as the kernel does, in f32) follows the squad `c` from `s = a`
/// to `b` within [`CUBIC_VALUE_TOL`] and [`CUBIC_VELOCITY_TOL`] at 17
/// points: values and velocities apart.
fn cubic_holds(
    c: &[f64; SQ_STRIDE],
    ctl: &[[f32; 4]; 4],
    max_rate: f64,
    (a, b): (f64, f64),
) -> Holds {
    use tcb_core::basis::{hermite, hermite_basis, hermite_basis_derivative};
    let mut holds = Holds {
        values: true,
        velocities: true,
    };
    for j in 0..=16 {
        let s = j as f64 / 16.0;
        let (q, dq) = tcb_core::squad::unit(c, a + (b - a) * s, true);
        let dq = dq.expect("asked for").map(|x| x * (b - a));
        let (h, dh) = (hermite_basis(s as f32), hermite_basis_derivative(s as f32));
        let p = ctl.map(|k| hermite(&h, k[0], k[1], k[2], k[3]));
        let dp = ctl.map(|k| hermite(&dh, k[0], k[1], k[2], k[3]));
        let (a, da) = tcb_core::quat::normalize(p, Some(dp));
        let da = da.expect("asked for");
        let rate = max_rate as f32;
        let speed = (0..4)
            .map(|i| (dq[i] as f32 * rate).abs())
            .fold(1.0f32, f32::max);
        holds.values &= (0..4).all(|i| (a[i] - q[i] as f32).abs() <= CUBIC_VALUE_TOL);
        holds.velocities &=
            (0..4).all(|i| ((da[i] - dq[i] as f32) * rate).abs() <= CUBIC_VELOCITY_TOL * speed);
        if !holds.values && !holds.velocities {
            break;
        }
    }
    holds
}

/// A rotation whose segments the cubic misses (`exact`), split: each such
/// segment becomes 2, 4, 8 or 16 equal pieces, each the cubic through
/// squad's values and derivatives at its ends, the fewest that pass
/// [`cubic_holds`]. The keys of the result are the track's own plus the
/// split points. Segments that cannot be split stay as they were, exact: an
/// eased or step segment, one too short to split, or one where 16 pieces
/// still miss.
///
/// For a loose lane (`on_group` false), pieces must hold values and
/// velocities, and a result with no exact segment left needs no f64 per
/// frame. On a group (`on_group` true), pieces need only hold the values:
/// they keep the segment's squad for velocities (`piece` says where they
/// lie in it), so an instance that samples velocities gets them in f64 as
/// before and one that does not plays cubics; segments whose cubic misses
/// only the velocities stay as they are.
fn split_rotation(
    grid: &TimeGrid,
    rot: &RotationControls,
    on_group: bool,
) -> (TimeGrid, RotationControls) {
    let n = grid.times.len();
    let mut times = vec![grid.times[0]];
    let (mut eases, mut steps) = (Vec::new(), Vec::new());
    let mut out = RotationControls {
        comps: rot.comps.iter().map(|c| vec![c[0]]).collect(),
        exact: vec![None],
        velocity_only: vec![false],
        piece: vec![[0.0, 1.0]],
    };
    let push = |out: &mut RotationControls, ctl: [[f32; 4]; 4], exact, velocity_only, piece| {
        for (c, ctl) in out.comps.iter_mut().zip(ctl) {
            c.push(ctl);
        }
        out.exact.push(exact);
        out.velocity_only.push(velocity_only);
        out.piece.push(piece);
    };
    for k in 0..n - 1 {
        let (t0, t1) = (grid.times[k], grid.times[k + 1]);
        let pieces = rot.exact[k + 1]
            .filter(|_| grid.ease(k).is_none() && !grid.is_step(k))
            .filter(|_| !(on_group && rot.velocity_only[k + 1]))
            .and_then(|c| {
                [2usize, 4, 8, 16].into_iter().find_map(|m| {
                    let w = 1.0 / m as f64;
                    // Split times strictly increasing (not so in f64 on
                    // keys a few ulps apart).
                    let at = |j: usize| split_time(t0, t1, j, m);
                    if (1..=m).any(|j| at(j) <= at(j - 1)) {
                        return None;
                    }
                    (0..m)
                        .map(|j| {
                            let (a, b) = (j as f64 * w, (j + 1) as f64 * w);
                            let (qa, da) = tcb_core::squad::squad_with_derivative(&c, a);
                            let (qb, db) = tcb_core::squad::squad_with_derivative(&c, b);
                            let ctl: [[f32; 4]; 4] = std::array::from_fn(|i| {
                                // The segment's own ends stay its keys.
                                let p0 = if j == 0 {
                                    rot.comps[i][k + 1][0]
                                } else {
                                    qa[i] as f32
                                };
                                let p1 = if j + 1 == m {
                                    rot.comps[i][k + 1][1]
                                } else {
                                    qb[i] as f32
                                };
                                [p0, p1, (w * da[i]) as f32, (w * db[i]) as f32]
                            });
                            let holds = cubic_holds(&c, &ctl, 2.0 / (w * (t1 - t0)), (a, b));
                            let enough = if on_group { holds.values } else { holds.both() };
                            enough.then_some((ctl, [a, w]))
                        })
                        .collect::<Option<Vec<_>>>()
                })
            });
        let Some(pieces) = pieces else {
            times.push(t1);
            eases.push(grid.ease(k));
            steps.push(grid.is_step(k));
            let ctl = std::array::from_fn(|i| rot.comps[i][k + 1]);
            let (exact, vo) = (rot.exact[k + 1], rot.velocity_only[k + 1]);
            push(&mut out, ctl, exact, vo, rot.piece[k + 1]);
            continue;
        };
        let m = pieces.len();
        // On a group, squad gives the pieces' velocities, as it did for the
        // whole segment (the cubic's, within 5e-5 of the speed, may be 1e-5
        // off, which `tcb sample --velocity` is checked to); a loose lane's
        // pieces hold both.
        let exact = rot.exact[k + 1].filter(|_| on_group);
        for (j, (ctl, piece)) in pieces.into_iter().enumerate() {
            times.push(split_time(t0, t1, j + 1, m));
            eases.push(SegmentEase::default());
            steps.push(false);
            push(&mut out, ctl, exact, exact.is_some(), piece);
        }
    }
    let ctl = std::array::from_fn(|i| rot.comps[i][n]);
    push(&mut out, ctl, None, false, [0.0, 1.0]);
    let grid = TimeGrid {
        times,
        eases,
        steps,
        pre: grid.pre,
        post: grid.post,
    };
    (grid.compact(), out)
}

/// Time `j` of `m` (`t0` at 0, `t1` exactly at `m`) splitting `[t0, t1]`
/// into equal pieces.
fn split_time(t0: f64, t1: f64, j: usize, m: usize) -> f64 {
    if j == m {
        t1
    } else {
        t0 + (t1 - t0) * (j as f64 / m as f64)
    }
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

/// Controls of an unused rotation lane: the identity (`P.w = 1`), so that
/// padding lanes normalize to a finite value, not 0/0.
const IDENTITY_PAD: [f32; HQ_STRIDE] = {
    let mut pad = [0.0; HQ_STRIDE];
    pad[3] = 1.0;
    pad
};

impl Clip {
    /// Compile a validated clip.
    ///
    /// ```
    /// let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
    ///   {"name": "x", "kind": "vec3", "times": [0, 1], "values": [[0, 0, 0], [1, 2, 3]]}]}"#)
    ///     .unwrap().build().unwrap();
    /// let clip = tcb_runtime::Clip::compile(&clip);
    /// assert_eq!(clip.track("x").map(|t| t.index()), Some(0));
    /// ```
    pub fn compile(source: &tcb_core::Clip) -> Self {
        Clip::compile_with(source, &CompileOptions::default())
    }

    /// [`compile`](Self::compile) with options (quantization).
    ///
    /// ```
    /// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    /// # /*
    /// let path = "data/cmu-01_01.bvh"; // from the repository's root
    /// # */
    /// let source = tcb_io::load(path).unwrap().clip;
    /// let plain = tcb_runtime::Clip::compile(&source);
    /// let options = tcb_runtime::CompileOptions { quantize: true, ..Default::default() };
    /// let small = tcb_runtime::Clip::compile_with(&source, &options);
    /// assert!(small.memory_bytes() * 3 < plain.memory_bytes() * 2);
    /// let hips = small.track("Hips.translation").unwrap();
    /// assert!(small.quantization_error(hips).unwrap() < 1e-3); // in the clip's units
    /// ```
    pub fn compile_with(source: &tcb_core::Clip, options: &CompileOptions) -> Self {
        Clip::compile_impl(source, options, false)
    }

    /// [`compile_with`](Self::compile_with); with `groups_only`, small
    /// groups stay groups rather than loose lanes (a packed clip's one group).
    pub(crate) fn compile_impl(
        source: &tcb_core::Clip,
        options: &CompileOptions,
        groups_only: bool,
    ) -> Self {
        let mut group_of: HashMap<GridKey, usize> = HashMap::new();
        let mut grids: Vec<TimeGrid> = Vec::new();
        // Per group: vector channel rows (track, component) and rotation rows.
        let mut vec_rows: Vec<Vec<(usize, usize, Controls)>> = Vec::new();
        let mut hq_rows: Vec<Vec<(usize, RotationControls)>> = Vec::new();
        for (i, t) in source.tracks().iter().enumerate() {
            let grid = grid_of(&t.data);
            let g = *group_of.entry(grid_key(&grid)).or_insert_with(|| {
                grids.push(grid);
                vec_rows.push(Vec::new());
                hq_rows.push(Vec::new());
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
                TrackData::Quat(r) => {
                    hq_rows[g].push((i, rotation_controls(r, options.exact_velocities)))
                }
            }
        }

        // How much normalizing can grow a quantization error of each
        // rotation (before its rows are moved into loose lanes).
        let mut rot_gain = vec![2.0f32; source.tracks().len()];
        if options.quantize {
            for (track, rot) in hq_rows.iter().flatten() {
                rot_gain[*track] = normalize_gain(rot);
            }
        }
        // Small groups of vector channels only: one lane per track (see loose.rs).
        let mut loose_lanes: Vec<(usize, LooseLane)> = Vec::new();
        let mut loose_rots: Vec<(usize, LooseLane)> = Vec::new();
        let mut keep = vec![true; grids.len()];
        for g in 0..grids.len() {
            // Small groups of rotations only (reset, which gives the
            // identity rather than zero, stays on the group path). A
            // rotation with exact segments (see `rotation_controls`) goes
            // as the cubic pieces of `split_rotation`, or stays too.
            let resets = [grids[g].pre, grids[g].post].contains(&Extrapolation::Reset);
            if groups_only {
                continue;
            }
            if vec_rows[g].is_empty() && !hq_rows[g].is_empty() && hq_rows[g].len() < 8 && !resets {
                let split: Vec<(TimeGrid, RotationControls)> = hq_rows[g]
                    .iter()
                    .map(|(_, rot)| {
                        // Loose pieces play their cubic's velocity: not
                        // with `exact_velocities`.
                        if rot.exact.iter().all(Option::is_none) || options.exact_velocities {
                            (grids[g].clone(), rot.clone())
                        } else {
                            split_rotation(&grids[g], rot, false)
                        }
                    })
                    .collect();
                if split
                    .iter()
                    .all(|(_, r)| r.exact.iter().all(Option::is_none))
                {
                    keep[g] = false;
                    for ((track, _), (grid, rot)) in hq_rows[g].iter().zip(split) {
                        let comps: Vec<&Controls> = rot.comps.iter().collect();
                        loose_rots.push((*track, LooseLane::new(grid, &comps)));
                    }
                    continue;
                }
                // A rotation with segments no split holds stays a group of
                // its own, split where pieces hold the values, so that
                // squad runs in f64 for values only inside the segments
                // left (and for velocities where they were before).
                if let [(_, rot)] = hq_rows[g].as_mut_slice() {
                    (grids[g], *rot) = split_rotation(&grids[g], rot, true);
                }
            }
            if hq_rows[g].is_empty() && vec_rows[g].len() < 8 {
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
            .tracks()
            .iter()
            .map(|t| TrackSlot {
                name: t.name.clone(),
                kind: t.data.kind(),
                index: [0; 4],
            })
            .collect();
        let mut groups = Vec::with_capacity(grids.len());
        let mut quant_error = vec![0.0f32; source.tracks().len()];
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
            debug_assert_eq!(hq_out, vec_out + vec_blocks, "rotations follow the vectors");
            // [P TO TI] x [x y z w] per key (and sentinel pseudo-key).
            let hrows: Vec<Vec<[f32; HQ_STRIDE]>> = hq_rows[g]
                .iter()
                .map(|(_, rot)| {
                    let keys: Vec<Vec<[f32; KEY_STRIDE]>> = rot.comps.iter().map(per_key).collect();
                    (0..keys[0].len())
                        .map(|k| std::array::from_fn(|j| keys[j % 4][k][j / 4]))
                        .collect()
                })
                .collect();
            let vkeys: Vec<Vec<[f32; KEY_STRIDE]>> = vrows.iter().map(per_key).collect();
            let keys = grid.times.len() + 4;
            let (exact_at, exact, exact_controls) = exact_table(&hq_rows[g], segments);
            // Plane p, control j (P TO TI) of key k: vector blocks, then
            // rotation blocks of 4 planes (x y z w); unused lanes 0, or the
            // identity for rotations.
            let control = |k: usize, j: usize, p: usize| {
                f32x8::new(std::array::from_fn(|l| {
                    if p < vec_blocks {
                        vkeys.get(8 * p + l).map_or(0.0, |r| r[k][j])
                    } else {
                        let (b, c) = ((p - vec_blocks) / 4, (p - vec_blocks) % 4);
                        let pad = IDENTITY_PAD[4 * j + c];
                        hrows.get(8 * b + l).map_or(pad, |r| r[k][4 * j + c])
                    }
                }))
            };
            let planes = vec_blocks + 4 * hq_blocks;
            let (store, err) = KeyStore::new(keys, planes, options.quantize, control);
            if let Some(err) = err {
                let e = |j: usize, lane: usize, plane: usize| err[j][plane][lane % 8];
                for (lane, (track, _, _)) in vec_rows[g].iter().enumerate() {
                    let p = lane / 8;
                    let bound = e(0, lane, p) + 4.0 / 27.0 * (e(1, lane, p) + e(2, lane, p));
                    quant_error[*track] = quant_error[*track].max(bound);
                }
                for (lane, (track, rot)) in hq_rows[g].iter().enumerate() {
                    let bound = (0..4)
                        .map(|c| {
                            let p = vec_blocks + 4 * (lane / 8) + c;
                            e(0, lane, p) + 4.0 / 27.0 * (e(1, lane, p) + e(2, lane, p))
                        })
                        .fold(0.0f32, f32::max);
                    let bound = bound * normalize_gain(rot);
                    quant_error[*track] = quant_error[*track].max(bound);
                }
            }
            groups.push(Group {
                lanes: [vrows.len(), hq_rows[g].len(), exact.len()],
                exact_at,
                exact,
                exact_controls,
                keys: store,
                delta,
                vec_blocks,
                vec_out,
                hq_blocks,
                grid,
            });
        }
        // Loose tracks: planes of 8 lanes, like rotations.
        for (lane, (track, _)) in loose_lanes.iter().enumerate() {
            slots[*track].index = plane_slots(at, lane);
        }
        // Quantized: loose lanes too (expanded only on key crossings).
        let mut quantize_lane = |track: usize, lane: &mut LooseLane, gain: f32| {
            if options.quantize {
                let bound = lane
                    .quantize()
                    .iter()
                    .map(|e| e[0] + 4.0 / 27.0 * (e[1] + e[2]))
                    .fold(0.0f32, f32::max);
                quant_error[track] = gain * bound;
            }
        };
        for (track, lane) in &mut loose_lanes {
            quantize_lane(*track, lane, 1.0);
        }
        for (track, lane) in &mut loose_rots {
            quantize_lane(*track, lane, rot_gain[*track]);
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
        Clip {
            name: source.name().to_string(),
            groups,
            layout: Arc::new(PoseLayout::new(slots, at, quat_blocks)),
            loose,
            loose_rot,
            loose_rot_tracks,
            time_range: source.time_range(),
            quant_error,
            packed: None,
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

    /// The bound on what quantization moves `track`'s samples inside its
    /// keys, in the track's units (0 for a clip compiled without it; `None`
    /// for a track of another layout); see [`crate::quant`].
    pub fn quantization_error(&self, track: TrackId) -> Option<f32> {
        self.layout.slot(track)?;
        Some(self.quant_error.get(track.index).copied().unwrap_or(0.0))
    }

    /// First and last key time over all tracks.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        self.time_range
    }

    /// Values per sample, as [`tcb_core::Clip::channel_count`] (a rotation counts 4).
    pub fn channel_count(&self) -> usize {
        self.layout.slots.iter().map(|s| s.kind.dim()).sum()
    }

    /// Heap bytes of the compiled clip, counted from its buffers' lengths:
    /// the kernels' controls, the time grids and the pose layout. It keeps
    /// no copy of the source clip.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::{size_of, size_of_val};
        let grid = |g: &TimeGrid| {
            size_of_val(g.times.as_slice())
                + size_of_val(g.eases.as_slice())
                + size_of_val(g.steps.as_slice())
        };
        let groups: usize = self
            .groups
            .iter()
            .map(|g| {
                size_of::<Group>()
                    + grid(&g.grid)
                    + g.keys.heap_bytes()
                    + size_of_val(g.delta.as_slice())
                    + size_of_val(g.exact_at.as_slice())
                    + size_of_val(g.exact.as_slice())
                    + size_of_val(g.exact_controls.as_slice())
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
                    vector_channels: g.lanes[0],
                    rotations: g.lanes[1],
                })
                .collect(),
            loose_vector_tracks: self.loose.lanes.len(),
            loose_rotation_tracks: self.loose_rot_tracks,
            exact_segments: self
                .groups
                .iter()
                .flat_map(|g| &g.exact)
                .map(|e| e.mask.to_bitmask().count_ones() as usize)
                .sum(),
            exact_for_velocity_only: self
                .groups
                .iter()
                .flat_map(|g| &g.exact)
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
}
