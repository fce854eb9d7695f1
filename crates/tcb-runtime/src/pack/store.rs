//! A group's controls from a [`Packed`] stream: keys decoded as playback
//! reaches them, tangents derived from their neighbours.
//!
//! An instance keeps the decoded keys (`P`, in the group's planes) of one
//! 32-key segment and the three keys before it, and the predictor's state;
//! a segment from key `a` to `a + 1` needs keys `a - 1 ..= a + 2`. Playback
//! decodes a segment when it first needs one of its keys: its headers, 8
//! lanes at a time in the bytes of a `u64` (`super::header_group`; each
//! plane's lanes then find theirs through `PackedKeys::plane_index`), then
//! three passes that each run without a branch on the data: every lane's residuals
//! unpacked by a function for its width (16 values at a time, a mask and
//! a shift each), then per plane of 8 lanes the prediction and dequantization, key
//! by key, with the predictor in registers, then the rebuilt `w`s. Where
//! the AVX2 instance runs (`crate::isa`), the first two passes are one:
//! each plane's residuals come straight from the stream, 64 bits gathered
//! at each lane's byte for as many keys as every lane has in them, then
//! shifted and masked per lane key by key, from the windows' low 32 bits
//! while they hold the keys (segments whose widths are all at most 25
//! bits; wider ones unpack first); planes whose lanes all predict from
//! the last two keys run a loop of their own, one instruction shorter a
//! key; and a
//! block's start values and deltas are gathered a plane at a time too
//! (`PackedKeys::start_gather`). Forward
//! playback decodes each key once; playing backwards re-decodes from the
//! block's start only when it leaves a segment. Interior tangents are the
//! tangent rule on the two chords,
//!
//! ```text
//! TO_a = (P_a - P_{a-1}) out_a + (P_{a+1} - P_a) out_b       TI_b likewise with in_a, in_b
//! ```
//!
//! in f32 with the weights rounded to f32, as `tcb_core::Track` computes
//! them; keys 0 and n-1 (whose tangents follow the `ends` rule) and the
//! sentinel pseudo-keys are kept in f32. Rotations are decoded as the
//! reference is given them (`tcb_core::RotationTrack::new_as_given`): `w`
//! rebuilt where the track stores three components, not normalized (the
//! kernel normalizes the curve it plays).
//!
//! Where every rotation of the group shares its weights (a clip of one
//! tangent rule, as capture is), interior segments play their rotations
//! from their four keys instead ([`key_row`]: the basis row with the
//! tangents written out, the same kernel), and only the vector planes'
//! tangents are computed: the same curve, rounded otherwise (within a few
//! 1e-7 of the reference, where the contract allows 1e-6), while vectors
//! keep the reference's bits. Rows whose keys may be long
//! ([`KEY_LENGTH2`]), and frames where a rotation's `|p|` is short
//! ([`KEY_FORM_LOW`]), play from the tangents.

use super::{
    BYTES, BitLanes, GROUP, Packed, SEGMENT_KEYS, block_step, header_group, read_bits, unzigzag,
    window,
};
use crate::grid::FrameBasis;
use crate::segment::Segment;
use std::ops::{Add, BitAnd, BitOr, Sub};
use std::sync::Arc;
use tcb_core::simd::basis::{Real, hermite};
use tcb_core::simd::lane::{Lane, Mask};
use wide::{f32x8, i32x8};

/// Sections of a key: `P`, `TO`, `TI`.
const P: usize = 0;
const TO: usize = 1;
const TI: usize = 2;

/// `$f(args)` of the decoder instance that runs here: `v4` where
/// `crate::isa::avx512` says so, else `v3` (callers check
/// `crate::isa::avx2` first).
#[cfg(target_arch = "x86_64")]
macro_rules! instance {
    ($f:ident($($arg:expr),* $(,)?)) => {
        if crate::isa::avx512() {
            v4::$f($($arg),*)
        } else {
            v3::$f($($arg),*)
        }
    };
}

/// The packed controls of one group (see the module docs).
#[derive(Clone, Debug)]
pub(crate) struct PackedKeys {
    pub packed: Arc<Packed>,
    /// Keys (n).
    pub keys: usize,
    pub planes: usize,
    /// Per stream lane, its plane and lane in the group (`8 plane + lane`).
    pub lane_slot: Vec<u32>,
    /// The slots of the stream lanes with headers (not
    /// [`FLAT`](super::FLAT)), in the stream's order.
    pub headed: Vec<u32>,
    /// Their base widths, then 0 to a multiple of [`GROUP`].
    pub headed_base: Vec<u8>,
    /// Per plane, the entry of [`Headers::entry`] each lane's coding is:
    /// its index in `headed`, or `headed_base.len()`, an entry that stays 0
    /// (width 0, order 2: a lane without headers, or not stored).
    pub plane_index: Vec<[i32; 8]>,
    /// Per plane: the quantization step of each lane (0 where not stored).
    pub step: Vec<f32x8>,
    /// Per plane: `in_a, in_b, out_a, out_b` of each lane.
    pub weights: Vec<[f32x8; 4]>,
    /// The planes with a stored lane (the decoder predicts only these).
    pub stored_planes: Vec<u32>,
    /// The first rotation plane; rotation blocks of 4 planes follow.
    pub rot_from: usize,
    /// The weights (`in_a in_b out_a out_b`) every rotation of the group
    /// shares, where they do, each at most 1 in magnitude, and every
    /// center's `|c|^2` is at most [`KEY_LENGTH2`]: then interior segments
    /// play their rotations from their keys ([`PackedKeys::play_keys`]).
    pub key_weights: Option<[f32; 4]>,
    /// Per rotation block: lanes whose `w` is rebuilt (and padding lanes),
    /// as a mask.
    pub rebuild: Vec<f32x8>,
    /// Every lane of every rotation block rebuilds `w` (capture's
    /// rotations do): then `w` is written without a blend.
    pub rebuild_all: bool,
    /// The rotation blocks with a lane whose keys are relative to a center
    /// (`PackTrack::center`): the block, and per plane the centers (the
    /// identity in lanes without one).
    pub center: Vec<(usize, [f32x8; 4])>,
    /// `[P TO TI]` of keys 0, n-1 and the four sentinel pseudo-keys
    /// (`n ..= n+3`), `planes` vectors each.
    pub table: Vec<f32x8>,
    /// Per plane, where the AVX2 instance gathers a block's first two keys
    /// from: each lane's bit after the block's headers and its width, for
    /// the start value, then for the delta (0 and 0 in lanes not stored).
    /// Empty where a width is above [`GATHER_WIDTH`] (the baseline's reads
    /// run then).
    pub start_gather: Vec<[[i32; 8]; 4]>,
    /// The bits of a block's start values and deltas.
    pub start_bits: usize,
}

impl PackedKeys {
    /// Section `j` of table key `e` (0: key 0, 1: key n-1, 2..: sentinels).
    #[inline(always)]
    fn table(&self, e: usize, j: usize) -> &[f32x8] {
        let at = (3 * e + j) * self.planes;
        &self.table[at..at + self.planes]
    }

    /// Heap bytes: the stream and its tables (once per clip) and the rest.
    pub fn heap_bytes(&self) -> usize {
        self.packed.stream_bytes()
            + 4 * (self.lane_slot.len() + self.headed.len())
            + self.headed_base.len()
            + 32 * self.plane_index.len()
            + 32 * (self.step.len() + 4 * self.weights.len() + self.table.len())
            + 128 * self.start_gather.len()
            + 8 * self.rebuild.len()
            + std::mem::size_of::<(usize, [f32x8; 4])>() * self.center.len()
    }

    /// The controls of the segment from key `a` to key `b`: a real segment
    /// (`b = a + 1 < n`) from decoded keys, a sentinel from the table.
    #[inline(always)]
    pub fn segment<'a>(&'a self, a: usize, b: usize, c: &'a mut PackCache) -> Segment<'a> {
        let n = self.keys;
        if a >= n {
            let (ea, eb) = (a - n + 2, b - n + 2);
            return Segment {
                p0: self.table(ea, P),
                m0: self.table(ea, TO),
                p1: self.table(eb, P),
                m1: self.table(eb, TI),
            };
        }
        debug_assert_eq!(b, a + 1, "packed groups have no step segments");
        if c.seg != a {
            let (lo, hi) = (a.saturating_sub(1), (b + 1).min(n - 1));
            c.ensure(self, lo, hi);
            self.tangents(a, b, c);
            c.seg = a;
        }
        let np = self.planes;
        let (m0, m1) = c.m.split_at(np);
        Segment {
            p0: c.ring(a, np),
            m0: if a == 0 { self.table(0, TO) } else { m0 },
            p1: c.ring(b, np),
            m1: if b == n - 1 { self.table(1, TI) } else { m1 },
        }
    }

    /// Plays interior segment `a` to `a + 1` (`0 < a`, `a + 2 < n`; `a`
    /// is `f.segment - 1`) in the key form, where the group has it
    /// ([`key_weights`](Self::key_weights)), into `out` (the group's planes,
    /// vectors then rotations) and `vel` (the same, where velocities are
    /// asked for): the vector planes from the reference's controls (the
    /// tangent rule on the rows of keys `a - 1 ..= a + 2`), the rotation
    /// planes from the four keys with [`key_row`] of the frame's rows.
    /// `false`, with `out` and `vel` not final, at the ends and the
    /// sentinels, where a key of the four may be longer than
    /// [`KEY_LENGTH2`] allows, and where a rotation's `|p|^2` is at most
    /// [`KEY_FORM_LOW`]: then [`segment`](Self::segment) plays it.
    #[inline(always)]
    pub fn play_keys(
        &self,
        f: &FrameBasis,
        c: &mut PackCache,
        out: &mut [f32x8],
        vel: Option<&mut [f32x8]>,
    ) -> bool {
        let Some(w) = self.key_weights else {
            return false;
        };
        let a = f.segment.wrapping_sub(1);
        if a.wrapping_sub(1) >= self.keys.saturating_sub(3) {
            return false;
        }
        c.ensure(self, a - 1, a + 2);
        // Every key read decoded within the bound: key `a - 1` in segment
        // `cur`, or in the one before.
        if !(c.seg_bounded && (a > SEGMENT_KEYS * c.cur || c.before_bounded)) {
            return false;
        }
        let win = key_rows(&c.rows, c.cur, a - 1, 4, self.planes);
        #[cfg(target_arch = "x86_64")]
        if crate::isa::avx2() {
            return instance!(play_keys_here(self, win, f, w, out, vel));
        }
        play_keys_on::<f32x8>(self, win, f, w, out, vel)
    }

    /// `TO_a` and `TI_b` of interior keys into the cache (module docs).
    fn tangents(&self, a: usize, b: usize, c: &mut PackCache) {
        let (np, n) = (self.planes, self.keys);
        if a > 0 && b < n - 1 {
            // Both (all but the end segments): the chord P_b - P_a once,
            // from the rows of keys `a - 1 ..= b + 1`.
            let keys = key_rows(&c.rows, c.cur, a - 1, 4, np);
            let rows = four_rows(keys, np, 0..np);
            let (m0, m1) = c.m.split_at_mut(np);
            #[cfg(target_arch = "x86_64")]
            if crate::isa::avx2() {
                return instance!(interior_tangents_here(rows, &self.weights, m0, m1));
            }
            return interior_tangents::<f32x8>(rows, &self.weights, m0, m1);
        }
        let mut m = std::mem::take(&mut c.m);
        let (m0, m1) = m.split_at_mut(np);
        if a > 0 {
            let (x, y, z) = (c.ring(a - 1, np), c.ring(a, np), c.ring(b, np));
            let rows = x.iter().zip(y).zip(z);
            for ((m, ((x, y), z)), w) in m0.iter_mut().zip(rows).zip(&self.weights) {
                *m = tangent(*y - *x, *z - *y, w[2], w[3]);
            }
        }
        if b < n - 1 {
            let (x, y, z) = (c.ring(a, np), c.ring(b, np), c.ring(b + 1, np));
            let rows = x.iter().zip(y).zip(z);
            for ((m, ((x, y), z)), w) in m1.iter_mut().zip(rows).zip(&self.weights) {
                *m = tangent(*y - *x, *z - *y, w[0], w[1]);
            }
        }
        c.m = m;
    }
}

/// The basis row that plays an interior segment from its four keys
/// ([`PackedKeys::play_keys`]: `P_a`, `P_b`, `P_{a-1}`, `P_{b+1}`, in
/// a segment's `P0 P1 M0 M1`): the hermite row `h` (`P0 P1 M0 M1`) with
/// each tangent written out as [`tangent`] of its chords, weights `w` (`in_a
/// in_b out_a out_b`):
///
/// ```text
/// h0 P_a + h1 P_b + h2 TO_a + h3 TI_b,   TO_a = (P_a - P_{a-1}) out_a + (P_b - P_a) out_b
///                                        TI_b = (P_b - P_a) in_a + (P_{b+1} - P_b) in_b
/// = (h0 + h2 (out_a - out_b) - h3 in_a) P_a + (h1 + h2 out_b + h3 (in_a - in_b)) P_b
///   - h2 out_a P_{a-1} + h3 in_b P_{b+1}
/// ```
///
/// in f64, rounded once. The same curve in other roundings: rotations
/// only (vectors keep the reference's bits).
pub(crate) fn key_row(h: [f32; 4], w: [f32; 4]) -> [f32; 4] {
    let [h0, h1, h2, h3] = h.map(f64::from);
    let [in_a, in_b, out_a, out_b] = w.map(f64::from);
    [
        h0 + h2 * (out_a - out_b) - h3 * in_a,
        h1 + h2 * out_b + h3 * (in_a - in_b),
        -h2 * out_a,
        h3 * in_b,
    ]
    .map(|x| x as f32)
}

/// `|P|^2` of every key that an interior segment's key form reads, before
/// its center, is at most this (checked as keys are decoded), and so is
/// `|c|^2` of every center (checked at compile time): after the center,
/// at most about 1.04. The form plays only where `|p|^2` is above
/// [`KEY_FORM_LOW`]: then
/// its roundings, and the reference's, move the normalized rotation by a
/// few 1e-7 (weights at most 1, so that `key_row`'s coefficients sum to
/// at most 1.6 in magnitude).
pub(crate) const KEY_LENGTH2: f32 = 1.02;

/// See [`KEY_LENGTH2`].
pub(crate) const KEY_FORM_LOW: f32 = 0.81;

/// The tangent rule on a key's two chords (`P_k - P_{k-1}`, `P_{k+1} -
/// P_k`) with its weights, as `tcb_core::Track` computes it in f32.
#[inline(always)]
fn tangent<L: Real>(before: L, after: L, wa: L, wb: L) -> L {
    before * wa + after * wb
}

/// `TO_a` and `TI_b` of a segment whose four keys `a - 1 ..= b + 1` are
/// decoded (`keys`: their rows, a plane per entry of `m0`): each plane's
/// chord `P_b - P_a` once.
#[inline(always)]
fn interior_tangents<L: Plane>(
    [v, x, y, z]: [&[f32x8]; 4],
    weights: &[[f32x8; 4]],
    m0: &mut [f32x8],
    m1: &mut [f32x8],
) {
    let rows = v.iter().zip(x).zip(y.iter().zip(z));
    let out = m0.iter_mut().zip(m1.iter_mut());
    for (((m0, m1), ((v, x), (y, z))), w) in out.zip(rows).zip(weights) {
        let [v, x, y, z] = [L::load(v), L::load(x), L::load(y), L::load(z)];
        let [in_a, in_b, out_a, out_b] = [
            L::load(&w[0]),
            L::load(&w[1]),
            L::load(&w[2]),
            L::load(&w[3]),
        ];
        let (to, ti) = chord_tangents([v, x, y, z], [in_a, in_b, out_a, out_b]);
        *m0 = to.store();
        *m1 = ti.store();
    }
}

/// `TO_a` and `TI_b` of the keys `[v x y z]` (`P_{a-1} ..= P_{b+1}`) with
/// their weights (`in_a in_b out_a out_b`): the chord `P_b - P_a` once.
#[inline(always)]
fn chord_tangents<L: Real>([v, x, y, z]: [L; 4], [in_a, in_b, out_a, out_b]: [L; 4]) -> (L, L) {
    let chord = y - x;
    (
        tangent(x - v, chord, out_a, out_b),
        tangent(chord, z - y, in_a, in_b),
    )
}

/// [`PackedKeys::play_keys`] on the rows `win` of keys `a - 1 ..= a + 2`
/// (`planes` vectors each) with the group's shared weights `w`.
#[inline(always)]
fn play_keys_on<L: Plane>(
    g: &PackedKeys,
    win: &[f32x8],
    f: &FrameBasis,
    w: [f32; 4],
    out: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
) -> bool {
    let (np, r) = (g.planes, g.rot_from);
    let (before, rest) = win.split_at(np);
    let (pa, rest) = rest.split_at(np);
    let (pb, after) = rest.split_at(np);
    let (out_v, out_q) = out.split_at_mut(r);
    let (vel_v, vel_q) = match vel {
        Some(v) => {
            let (v, q) = v.split_at_mut(r);
            (Some(v), Some(q))
        }
        None => (None, None),
    };
    // Rotations first: where the key form does not hold, nothing else
    // was computed for nothing.
    let rotations = Segment {
        p0: &pa[r..],
        m0: &before[r..],
        p1: &pb[r..],
        m1: &after[r..],
    };
    let h = key_row(f.h, w);
    // The derivative's row only where velocities are asked for.
    let dh = if vel_q.is_some() { key_row(f.dh, w) } else { h };
    const LOW: u32 = KEY_FORM_LOW.to_bits();
    if !L::quats::<LOW>(rotations, h, dh, f.rate, out_q, vel_q) {
        return false;
    }
    // Vectors: the reference's controls and kernel formula.
    let rows = before.iter().zip(pa).zip(pb.iter().zip(after));
    let planes = rows.zip(&g.weights).zip(out_v);
    let h = f.h.map(L::splat);
    match vel_v {
        None => {
            for ((((v, x), (y, z)), w), o) in planes {
                let keys = [L::load(v), L::load(x), L::load(y), L::load(z)];
                let (to, ti) = chord_tangents(keys, w.each_ref().map(L::load));
                *o = hermite(&h, keys[1], keys[2], to, ti).store();
            }
        }
        Some(vel_v) => {
            let (dh, rate) = (f.dh.map(L::splat), L::splat(f.rate));
            for (((((v, x), (y, z)), w), o), d) in planes.zip(vel_v) {
                let keys = [L::load(v), L::load(x), L::load(y), L::load(z)];
                let (to, ti) = chord_tangents(keys, w.each_ref().map(L::load));
                *o = hermite(&h, keys[1], keys[2], to, ti).store();
                *d = crate::kernel::velocity(&dh, keys[1], keys[2], to, ti, rate).store();
            }
        }
    }
    true
}

/// The predictor one key on: from the last key `x`, its step `d` (`x`
/// minus the key before it) and the residual `z` as stored (its low bits,
/// whatever lies above them), for a plane's coding `[trend, low, bias]`
/// (`trend` from the order, `low` and `bias` from the width,
/// `super::width_lanes`), the next key and its step. Order 2 (`trend` -1)
/// predicts the line through the last two keys, the last step again;
/// order 1 (`trend` 0) the last key. Wrapping arithmetic: the key is
/// `x + (d & trend) + residual` whatever the grouping, and carrying the
/// step makes each key one addition after the last.
#[inline(always)]
fn predict<I>(x: I, d: I, z: I, [trend, low, bias]: [I; 3]) -> (I, I)
where
    I: Copy + Add<Output = I> + Sub<Output = I> + BitAnd<Output = I>,
{
    let d = (d & trend) + ((z & low) - bias);
    (x + d, d)
}

/// A block's first two keys (the predictor's state after them) from its
/// start values and deltas: key 0 is the start value, key 1 key 0 plus
/// the delta; a block of one key (`keys` 1) has the start value twice.
#[inline(always)]
fn block_start_keys<I: Copy + Add<Output = I>>(start: I, delta: I, keys: usize) -> [I; 2] {
    [start, if keys > 1 { start + delta } else { start }]
}

/// Rebuild `w` of the rotations that store three components, and turn
/// the keys of rotations with a center by it (`PackTrack::value`), in the
/// rows `rows` (`planes` vectors each). Returns whether every key's
/// `|q|^2` before its center is at most [`KEY_LENGTH2`] (not NaN).
#[inline(always)]
fn rebuild_rows<L: Plane>(g: &PackedKeys, rows: &mut [f32x8]) -> bool {
    if g.rebuild_all {
        rebuild_rows_on::<L, true>(g, rows)
    } else {
        rebuild_rows_on::<L, false>(g, rows)
    }
}

/// [`rebuild_rows`], with `ALL` where every lane rebuilds `w`
/// ([`PackedKeys::rebuild_all`]: the stored `w` is neither read nor
/// blended, about 3 instructions a block and key).
#[inline(always)]
fn rebuild_rows_on<L: Plane, const ALL: bool>(g: &PackedKeys, rows: &mut [f32x8]) -> bool {
    let limit = L::splat(KEY_LENGTH2);
    let mut bounded = L::splat(0.0).le(limit);
    for row in rows.chunks_exact_mut(g.planes) {
        let rot = &mut row[g.rot_from..];
        for (block, mask) in rot.chunks_exact_mut(4).zip(&g.rebuild) {
            let [x, y, z] = [L::load(&block[0]), L::load(&block[1]), L::load(&block[2])];
            let rebuilt = tcb_core::quat::rebuild_w(x, y, z);
            let w = if ALL {
                rebuilt
            } else {
                L::blend(mask, rebuilt, L::load(&block[3]))
            };
            block[3] = w.store();
            // Where every lane rebuilds `w`, `|q|^2` passes the bound
            // exactly where `|xyz|^2` does (`w` is 0 where `|xyz|^2` is at
            // least 1, and `|q|^2` about 1 elsewhere): the sum `rebuild_w`
            // took, two instructions rather than four.
            let length2 = if ALL {
                x * x + y * y + z * z
            } else {
                x * x + y * y + z * z + w * w
            };
            bounded = bounded & length2.le(limit);
        }
        for (b, c) in &g.center {
            if let Some(block) = rot.get_mut(4 * b..4 * b + 4) {
                let c = [
                    L::load(&c[0]),
                    L::load(&c[1]),
                    L::load(&c[2]),
                    L::load(&c[3]),
                ];
                let q = [
                    L::load(&block[0]),
                    L::load(&block[1]),
                    L::load(&block[2]),
                    L::load(&block[3]),
                ];
                let q = tcb_core::quat::mul(&c, &q);
                for (o, q) in block.iter_mut().zip(q) {
                    *o = q.store();
                }
            }
        }
    }
    bounded.all()
}

/// Eight `f32` lanes the decoder computes on, kept as `f32x8` in the rows:
/// `f32x8` itself, or the AVX2 instance's `W8`.
trait Plane: Lane {
    fn load(x: &f32x8) -> Self;
    fn store(self) -> f32x8;
    /// `a` in the lanes where `mask` has every bit set, else `b`.
    fn blend(mask: &f32x8, a: Self, b: Self) -> Self;
    /// [`crate::kernel::quats_above`] without its rescaling, in this lane
    /// type's instance.
    #[inline(always)]
    fn quats<const LOW: u32>(
        c: Segment,
        h: [f32; 4],
        dh: [f32; 4],
        rate: f32,
        out: &mut [f32x8],
        vel: Option<&mut [f32x8]>,
    ) -> bool {
        crate::kernel::quats_above::<LOW, false>(c, h, dh, rate, out, vel)
    }
}

impl Plane for f32x8 {
    #[inline(always)]
    fn load(x: &f32x8) -> Self {
        *x
    }
    #[inline(always)]
    fn store(self) -> f32x8 {
        self
    }
    #[inline(always)]
    fn blend(mask: &f32x8, a: Self, b: Self) -> Self {
        (*mask & a) | (!*mask & b)
    }
}

/// Rows of the decoded keys' window: the three keys before the current
/// segment, its [`SEGMENT_KEYS`] keys, and 2 spare rows (a segment's
/// residuals are unpacked 16 at a time, from row 2 at a block's start).
const BEFORE: usize = 3;
const ROWS: usize = BEFORE + SEGMENT_KEYS + 2;
// The baseline unpacks 16 residuals a lane at a time, from row 2 at a
// block's start: whole passes of 16 must end inside the rows.
const _: () = assert!(
    SEGMENT_KEYS.is_multiple_of(16) && ROWS >= BEFORE + 2 + (SEGMENT_KEYS - 2).next_multiple_of(16)
);

/// Per residual width (the index), how many residuals `bits` bits hold; a
/// segment's keys for width 0 (the AVX2 decoder's chunks and groups).
#[cfg(target_arch = "x86_64")]
const fn keys_in(bits: usize) -> [u8; 32] {
    let mut t = [SEGMENT_KEYS as u8; 32];
    let mut w = 1;
    while w < 32 {
        t[w] = (bits / w) as u8;
        w += 1;
    }
    t
}

/// One instance's decoding state for a [`PackedKeys`] group.
#[derive(Clone, Debug)]
pub(crate) struct PackCache {
    /// The segment whose keys `rows` holds (`usize::MAX`: none).
    cur: usize,
    /// The first key whose row is valid (the three before `cur`'s first
    /// key, or, after a seek, the first key decoded).
    valid: usize,
    /// The first key of the segment whose tangents `m` holds (`usize::MAX`
    /// once the rows move: `decode_to`).
    seg: usize,
    /// Whether every rotation key of segment `cur` (decoded so far) has
    /// `|P|^2` at most [`KEY_LENGTH2`], and whether every key of segment
    /// `cur - 1` has, where the rows hold its last keys. Per segment, so
    /// that forward playback and a seek decide alike.
    seg_bounded: bool,
    before_bounded: bool,
    /// The stream's bit after segment `cur` (where the next one starts).
    pos: usize,
    /// Per stream lane with headers (`PackedKeys::headed`), as the
    /// segment `cur`'s headers give them.
    headers: Headers,
    /// Per plane, how its lanes code the segment `cur`.
    coding: Vec<PlaneCoding>,
    /// The factor on the steps in the block of segment `cur`
    /// ([`crate::pack::BlockScales`]).
    factor: f32,
    /// The predictor: the last two keys' integers, per plane.
    x0: Vec<i32x8>,
    x1: Vec<i32x8>,
    /// Keys `SEGMENT_KEYS * cur - 3 ..` in `ROWS` rows of `planes` vectors (see
    /// [`ROWS`]); while a segment is decoded, a row holds its residuals
    /// (as `i32`) until the prediction replaces them with the key.
    rows: Vec<f32x8>,
    /// `TO_a` then `TI_b` of the segment `seg`.
    m: Vec<f32x8>,
}

impl PackedKeys {
    /// A cache for [`segment`](Self::segment), per instance.
    pub fn cache(&self) -> PackCache {
        let np = self.planes;
        PackCache {
            cur: usize::MAX,
            valid: 0,
            seg: usize::MAX,
            seg_bounded: false,
            before_bounded: false,
            pos: 0,
            headers: Headers {
                width: self.headed_base.clone(),
                entry: vec![0; self.headed_base.len() + 1],
            },
            coding: vec![PlaneCoding::default(); np],
            factor: 1.0,
            x0: vec![i32x8::ZERO; np],
            x1: vec![i32x8::ZERO; np],
            rows: vec![f32x8::ZERO; ROWS * np],
            m: vec![f32x8::ZERO; 2 * np],
        }
    }
}

/// Planes `planes` of each of the four rows of `keys` (`np` vectors a
/// row). Written out: `[0, 1, 2, 3].map(..)` was not always inlined, and
/// then cost a call and a loop a frame.
#[inline(always)]
fn four_rows(keys: &[f32x8], np: usize, planes: std::ops::Range<usize>) -> [&[f32x8]; 4] {
    let (s, e) = (planes.start, planes.end);
    [
        &keys[s..e],
        &keys[np + s..np + e],
        &keys[2 * np + s..2 * np + e],
        &keys[3 * np + s..3 * np + e],
    ]
}

/// The rows of keys `k .. k + count` in a cache's `rows` (`PackCache::rows`,
/// holding segment `cur`; decoded, as [`PackCache::ring`]'s), `np` vectors
/// each. A free function, so that a caller may borrow the cache's tangents
/// mutably beside them.
#[inline(always)]
fn key_rows(rows: &[f32x8], cur: usize, k: usize, count: usize, np: usize) -> &[f32x8] {
    let at = (k + BEFORE - SEGMENT_KEYS * cur) * np;
    &rows[at..at + count * np]
}

impl PackCache {
    /// Key `k`'s row (decoded: `valid <= k` and in or before `cur`).
    #[inline(always)]
    fn ring(&self, k: usize, np: usize) -> &[f32x8] {
        key_rows(&self.rows, self.cur, k, 1, np)
    }

    /// Decode until keys `lo ..= hi` (at most 4, `hi` in the segment after
    /// `lo`'s at most) have rows: on from the segment decoded last, or
    /// from the start of `lo`'s block.
    #[inline(always)]
    fn ensure(&mut self, g: &PackedKeys, lo: usize, hi: usize) {
        let to = hi / SEGMENT_KEYS;
        if self.cur != to || lo < self.valid {
            self.decode_to(g, lo, to);
        }
    }

    /// [`ensure`](Self::ensure)'s decoding, out of line: segments up to
    /// `to`, from the one after `cur` or from the start of `lo`'s block.
    #[inline(never)]
    fn decode_to(&mut self, g: &PackedKeys, lo: usize, to: usize) {
        // The rows move: the tangents `m` hold may be of keys no longer in
        // them.
        self.seg = usize::MAX;
        // A block's first segment needs nothing before it.
        let restart = (lo - lo % g.packed.block) / SEGMENT_KEYS;
        let from = if self.cur < to && self.cur + 1 >= restart {
            self.cur + 1
        } else {
            restart
        };
        for j in from..=to {
            self.decode_segment(g, j);
        }
        debug_assert!(lo >= self.valid && self.cur == to);
    }

    /// Decode segment `j` into the rows (after segment `j - 1`, or at a
    /// block's start): its headers, a block's start values and deltas,
    /// every lane's residuals, then per plane the prediction and
    /// dequantization, key by key, and the rebuilt `w`s.
    fn decode_segment(&mut self, g: &PackedKeys, j: usize) {
        let (np, n, s) = (g.planes, g.keys, j * SEGMENT_KEYS);
        let block = s.is_multiple_of(g.packed.block);
        debug_assert!(block || self.cur.wrapping_add(1) == j);
        // The three keys before: the last rows of segment j - 1.
        self.before_bounded = if self.cur.wrapping_add(1) == j {
            self.rows
                .copy_within(SEGMENT_KEYS * np..(SEGMENT_KEYS + BEFORE) * np, 0);
            self.valid = self.valid.max(s.saturating_sub(BEFORE));
            self.seg_bounded
        } else {
            self.valid = s;
            false
        };
        self.seg_bounded = true;
        self.cur = j;
        let words: &[u64] = &g.packed.stream;
        let mut pos = if block {
            g.packed.block_at[s / g.packed.block] as usize
        } else {
            self.pos
        };
        if block {
            // A block's first headers code against the lanes' base widths.
            self.headers.width.copy_from_slice(&g.headed_base);
            self.factor = g.packed.head.scales.factor(s);
        }
        let keys = (s + SEGMENT_KEYS).min(n) - s;
        // A block's first two keys come from its start values and deltas.
        let first = if block { 2.min(keys) } else { 0 };
        // Per lane: its width, trend, and the sum of the widths before it
        // (its first residual lies that many times `keys - first` bits
        // after the residuals' start: the AVX2 instance's gather).
        let (before, narrow);
        #[cfg(target_arch = "x86_64")]
        let read = if crate::isa::avx2() {
            instance!(headers_here(&mut self.headers, words, pos, g.headed.len()))
        } else {
            self.headers
                .read::<i32x8, super::Portable>(words, pos, g.headed.len())
        };
        #[cfg(not(target_arch = "x86_64"))]
        let read = self
            .headers
            .read::<i32x8, super::Portable>(words, pos, g.headed.len());
        (pos, before, narrow) = read;
        if block {
            let written = self.block_start(g, &mut pos, keys);
            debug_assert_eq!(written, first);
        }
        // The AVX2 instance reads a plane's residuals straight from the
        // stream (gathers of 64 bits from each lane's byte), where every
        // width has room in 32 bits and the segment's last bit lies 64 bits
        // before the stream's end.
        let last = pos + before * (keys - first);
        let gather =
            crate::isa::avx2() && narrow && last + 64 <= (64 * words.len()).min(i32::MAX as usize);
        if !gather {
            // Residuals: each lane of a width above 0, 16 keys at a time (those past
            // the segment's keys land in spare rows, or in rows no key
            // reads) into the rows as i32; the width's low bits mask the
            // rest.
            let stride = 8 * np;
            let rows: &mut [i32] = bytemuck::cast_slice_mut(&mut self.rows);
            let base = (BEFORE + first) * stride;
            let mut at = pos;
            for (&w, &slot) in self.headers.width.iter().zip(&g.headed) {
                if w > 0 {
                    // 16 at a time, as many times as the segment has keys.
                    for half in (0..keys - first).step_by(16) {
                        let out = &mut rows[base + half * stride + slot as usize..];
                        UNPACK[w as usize](words, at + w as usize * half, out, stride);
                    }
                    at += w as usize * (keys - first);
                }
            }
            self.plane_codings(g);
        }
        let rows = &mut self.rows[(BEFORE + first) * np..(BEFORE + keys) * np];
        #[cfg(target_arch = "x86_64")]
        if gather {
            // SAFETY: `gather` holds only where AVX2 runs (and `instance!`
            // takes `v4` only where AVX-512 does), and every lane's
            // residuals end at or before `last` (each lane's start is the
            // sum of the widths before it times `keys - first` bits after
            // `pos`, and `last` is `pos` plus the sum over all; lanes
            // without headers start at `pos` with width 0), which is 64
            // bits before the stream's end and below i32::MAX; every
            // index of `plane_index` is at most the length of
            // `headed_base` (`compile::packed`), below `headers.entry`'s.
            #[allow(unsafe_code)]
            unsafe {
                let (x0, x1, f) = (&mut self.x0, &mut self.x1, self.factor);
                instance!(predict_gathered_here(
                    g,
                    &self.headers,
                    pos,
                    f,
                    x0,
                    x1,
                    rows
                ));
            }
        }
        if !gather {
            for &p in &g.stored_planes {
                let p = p as usize;
                // The last key and its step.
                let (mut x, mut d) = (self.x1[p], self.x1[p] - self.x0[p]);
                let c = &self.coding[p];
                let (low, bias) = super::width_lanes(i32x8::from(c.width));
                let coding = [i32x8::from(c.trend), low, bias];
                let step = block_step(g.step[p], f32x8::splat(self.factor));
                for row in rows.chunks_exact_mut(np) {
                    let v = &mut row[p];
                    (x, d) = predict(x, d, bytemuck::cast(*v), coding);
                    *v = super::dequantize_lanes(x, step);
                }
                (self.x0[p], self.x1[p]) = (x - d, x);
            }
        }
        self.rebuild(g, first..keys);
        self.pos = last;
    }

    /// Each stored plane's coding from the headers ([`entry_fields`]).
    fn plane_codings(&mut self, g: &PackedKeys) {
        let h = &self.headers;
        for &p in &g.stored_planes {
            let mut e = [0; 8];
            for (e, &i) in e.iter_mut().zip(&g.plane_index[p as usize]) {
                *e = h.entry[i as usize];
            }
            let [width, trend, _] = entry_fields(i32x8::new(e));
            self.coding[p as usize] = PlaneCoding {
                trend: trend.to_array(),
                width: width.to_array(),
            };
        }
    }

    /// A block's first two keys (its start values, then the deltas) into
    /// rows `BEFORE` and `BEFORE + 1` and the predictor; returns the rows
    /// written (2, or 1 for a last block of one key).
    fn block_start(&mut self, g: &PackedKeys, pos: &mut usize, keys: usize) -> usize {
        let np = g.planes;
        let words: &[u64] = &g.packed.stream;
        let first = 2.min(keys);
        #[cfg(target_arch = "x86_64")]
        if crate::isa::avx2()
            && !g.start_gather.is_empty()
            && *pos + g.start_bits + 32 <= (64 * words.len()).min(i32::MAX as usize)
        {
            let rows = &mut self.rows[BEFORE * np..(BEFORE + first) * np];
            // SAFETY: AVX2 runs (AVX-512 too where `instance!` takes
            // `v4`), and every lane's start value and delta end
            // at or before `pos + start_bits` (`start_gather`'s bits are
            // sums of the widths before them), which is 32 bits before the
            // stream's end and below i32::MAX.
            #[allow(unsafe_code)]
            unsafe {
                let (x0, x1, f) = (&mut self.x0, &mut self.x1, self.factor);
                instance!(block_start_gathered_here(g, *pos, f, x0, x1, rows));
            }
            *pos += g.start_bits;
            self.rebuild(g, 0..first);
            return first;
        }
        // Every lane's start value into `x0`, then its delta into `x1`.
        for (bits, out) in [
            (&g.packed.abs_bits, &mut self.x0),
            (&g.packed.delta_bits, &mut self.x1),
        ] {
            out.fill(i32x8::ZERO);
            let flat: &mut [i32] = bytemuck::cast_slice_mut(out);
            for (&w, &slot) in bits.iter().zip(&g.lane_slot) {
                flat[slot as usize] = unzigzag(read_bits(words, *pos, u32::from(w)));
                *pos += usize::from(w);
            }
        }
        let (row0, row1) = self.rows[BEFORE * np..(BEFORE + first) * np].split_at_mut(np);
        let state = self.x0.iter_mut().zip(&mut self.x1).zip(&g.step);
        for (p, ((x0, x1), step)) in state.enumerate() {
            let step = &block_step(*step, f32x8::splat(self.factor));
            let [k0, k1] = block_start_keys(*x0, *x1, first);
            row0[p] = super::dequantize_lanes(k0, *step);
            if let Some(row) = row1.get_mut(p) {
                *row = super::dequantize_lanes(k1, *step);
            }
            (*x0, *x1) = (k0, k1);
        }
        self.rebuild(g, 0..first);
        first
    }

    /// [`rebuild_rows`] on the segment's rows `rows`.
    fn rebuild(&mut self, g: &PackedKeys, rows: std::ops::Range<usize>) {
        let np = g.planes;
        let rows = &mut self.rows[(BEFORE + rows.start) * np..(BEFORE + rows.end) * np];
        #[cfg(target_arch = "x86_64")]
        let bounded = if crate::isa::avx2() {
            instance!(rebuild_rows_here(g, rows))
        } else {
            rebuild_rows::<f32x8>(g, rows)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let bounded = rebuild_rows::<f32x8>(g, rows);
        self.seg_bounded &= bounded;
    }
}

/// What a segment's headers say of the stream's lanes with headers
/// (`PackedKeys::headed`, in groups of [`GROUP`]; then the two entries of
/// `PackedKeys::headed_base` no header writes).
#[derive(Clone, Debug)]
pub(crate) struct Headers {
    /// The residuals' width (what the next segment's codes are against).
    width: Vec<u8>,
    /// [`entry`]: what a plane's lane finds at its
    /// `PackedKeys::plane_index` (then one entry that stays 0).
    entry: Vec<i32>,
}

/// Lanes' entries in [`Headers::entry`]: each one's width (at most 31),
/// `order1` (1 where the prediction order is 1, the last value; 0 for 2,
/// the line through the last two) and its first bit in the segment (the
/// sum of the widths before it, below 2^25: `pack::MAX_LANES`), from the
/// bytes of a header group ([`header_group`]) and the sum of the widths
/// of the groups before.
#[inline(always)]
fn entry<L: EntryLanes>(width: u64, order1: u64, start: u64, sum: i32) -> L {
    L::bytes(width) | L::bytes(order1).shl::<5>() | (L::splat(sum) + L::bytes(start)).shl::<6>()
}

/// Eight `i32` lanes [`entry`] computes in: `i32x8`, or the AVX2
/// instance's registers.
pub(crate) trait EntryLanes: Copy + Add<Output = Self> + BitOr<Output = Self> {
    /// The 8 bytes of `x`, little-endian, as lanes.
    fn bytes(x: u64) -> Self;
    fn splat(x: i32) -> Self;
    fn shl<const N: i32>(self) -> Self;
    fn to_array(self) -> [i32; 8];
}

impl EntryLanes for i32x8 {
    #[inline(always)]
    fn bytes(x: u64) -> Self {
        i32x8::new(x.to_le_bytes().map(i32::from))
    }
    #[inline(always)]
    fn splat(x: i32) -> Self {
        i32x8::splat(x)
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        self << N
    }
    #[inline(always)]
    fn to_array(self) -> [i32; 8] {
        i32x8::to_array(self)
    }
}

/// [`entry`] undone in each lane: `[width, trend, start]`, `trend` -1 for
/// order 2 and 0 for order 1 (as [`predict`] takes it).
#[inline(always)]
fn entry_fields<I: BitLanes>(e: I) -> [I; 3] {
    [
        e & I::splat(31),
        (e.shr::<5>() & I::ONE) - I::ONE,
        e.shr::<6>(),
    ]
}

impl Headers {
    /// A segment's headers of `headed` lanes from bit `pos` of `words`,
    /// coded against the widths here ([`header_group`]): the bit after
    /// them, the sum of the widths, and whether each is at most
    /// [`GATHER_WIDTH`].
    #[inline(always)]
    fn read<L: EntryLanes, S: super::Spread>(
        &mut self,
        words: &[u64],
        pos: usize,
        headed: usize,
    ) -> (usize, usize, bool) {
        let (mut sum, mut wide) = (0usize, 0u64);
        // The groups' fixed parts, then the widths coded whole.
        let mut tail = pos + 3 * headed;
        for at in (0..headed).step_by(GROUP) {
            let k = (headed - at).min(GROUP);
            let lanes = at..at + GROUP;
            let width = &mut self.width[lanes.clone()];
            let before = u64::from_le_bytes(width.try_into().expect("8 lanes"));
            let fixed = window(words, pos + 3 * at);
            let read = header_group::<S>(fixed, window(words, tail), k, before);
            tail += super::WIDTH_BITS as usize * read.whole;
            width.copy_from_slice(&read.width.to_le_bytes());
            // The sums of the widths up to each byte (at most 248).
            let sums = read.width.wrapping_mul(BYTES);
            let start = sums << 8;
            let e: L = entry(read.width, read.order1, start, sum as i32);
            self.entry[lanes].copy_from_slice(&e.to_array());
            sum += (sums >> 56) as usize;
            // A top bit where a width is above GATHER_WIDTH.
            wide |= read.width + (0x80 - 1 - u64::from(GATHER_WIDTH)) * BYTES;
        }
        (tail, sum, wide & (0x80 * BYTES) == 0)
    }
}

/// How the 8 lanes of a plane code a segment.
#[derive(Clone, Copy, Debug, Default)]
struct PlaneCoding {
    /// -1 in lanes predicted by the line through their last two values
    /// (order 2), 0 in lanes predicted by the last.
    trend: [i32; 8],
    /// The residuals' width (0: none stored, the lane on its prediction).
    width: [i32; 8],
}

/// The widest residual a gather of 32 bits from its first byte holds.
pub(crate) const GATHER_WIDTH: u32 = 25;

#[cfg(target_arch = "x86_64")]
impl Plane for tcb_core::simd::w8::W8 {
    // Through AVX vectors: a loop of these is not vectorized again
    // across its iterations (LLVM's loop vectorizer does, on arrays,
    // with a gather per operand), as the group kernels' rotation loop
    // loads (`kernel::v3`; their vector loop stays on arrays, which
    // LLVM unrolls).
    #[inline(always)]
    fn load(x: &f32x8) -> Self {
        let v: std::arch::x86_64::__m256 = bytemuck::cast(*x);
        Self(bytemuck::cast(v))
    }
    #[inline(always)]
    fn store(self) -> f32x8 {
        let v: std::arch::x86_64::__m256 = bytemuck::cast(self.0);
        bytemuck::cast(v)
    }
    #[inline(always)]
    fn blend(mask: &f32x8, a: Self, b: Self) -> Self {
        use std::arch::x86_64::{__m256, _mm256_blendv_ps};
        // The masks are all ones or all zeros per lane, so the sign
        // bit `vblendvps` reads decides as the whole mask would.
        let (m, a, b): (__m256, __m256, __m256) = (
            bytemuck::cast(*mask),
            bytemuck::cast(a.0),
            bytemuck::cast(b.0),
        );
        // SAFETY: `W8`'s `Plane` runs only inside the decoder instances'
        // `#[target_feature]` functions (`decoder_instance!`), all with AVX2.
        #[allow(unsafe_code)]
        Self(bytemuck::cast(unsafe { _mm256_blendv_ps(b, a, m) }))
    }
    /// Without velocities, the AVX2 kernel's loop in line (in the
    /// instances, which have AVX2 and FMA): its call took about 35
    /// instructions a frame.
    #[inline(always)]
    fn quats<const LOW: u32>(
        c: Segment,
        h: [f32; 4],
        dh: [f32; 4],
        rate: f32,
        out: &mut [f32x8],
        vel: Option<&mut [f32x8]>,
    ) -> bool {
        match vel {
            None => crate::kernel::quats_inline::<LOW>(c, h, out),
            vel => crate::kernel::quats_above::<LOW, false>(c, h, dh, rate, out, vel),
        }
    }
}

/// `$t`'s operator `$tr` as the AVX2 intrinsic `$f`. The intrinsics
/// need AVX2, which every caller has: a `V` or an `F` (private types
/// with private fields, one pair per [`decoder_instance!`]) is made and
/// used only inside its instance's `#[target_feature]` functions (AVX2
/// and FMA at least), `predict_gathered` and `headers` (through
/// `Headers::read::<V>`), into which these methods inline. Keep it so:
/// the methods are safe to call, so a new caller outside such a function
/// would compile and run AVX2 instructions on any CPU.
macro_rules! avx_op {
    ($t:ident, $tr:ident, $m:ident, $f:ident) => {
        impl std::ops::$tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $m(self, o: $t) -> $t {
                // SAFETY: only used inside `predict_gathered` and
                // `headers`, which run where AVX2 does (above).
                #[allow(unsafe_code)]
                $t(unsafe { $f(self.0, o.0) })
            }
        }
    };
}

/// The decoder compiled for x86-64 features `$features` (AVX2 and FMA at
/// least), run where `crate::isa` chose it (`instance!`); `$detected()`
/// says whether the CPU has them (what the debug checks read):
/// the same formulas ([`predict`], `dequantize_lanes`, [`rebuild_rows`],
/// [`interior_tangents`]) on `tcb_core::simd::w8`'s `I8` and `W8`, and
/// each key's residuals of a plane gathered straight from the stream.
/// One body, instantiated per feature set, so the instances are the same
/// code.
macro_rules! decoder_instance {
    ($name:ident, $features:literal, $detected:path) => {
        mod $name {
            use crate::grid::FrameBasis;
            use crate::pack::store::{
                Headers, PackedKeys, block_start_keys, entry_fields, interior_tangents,
                play_keys_on, predict, rebuild_rows,
            };
            use crate::pack::{block_step, dequantize_lanes, unzigzag_lanes, width_lanes};
            use std::arch::x86_64::{
                __m256, __m256i, _mm_cvtsi64_si128, _mm_cvtsi128_si32, _mm_max_epu32,
                _mm_shuffle_epi32, _mm256_add_epi32, _mm256_and_si256, _mm256_castps_si256,
                _mm256_castsi256_ps, _mm256_castsi256_si128, _mm256_cvtepi32_ps,
                _mm256_cvtepu8_epi32, _mm256_extracti128_si256, _mm256_i32gather_epi32,
                _mm256_i64gather_epi64, _mm256_movemask_ps, _mm256_mul_ps, _mm256_mullo_epi32,
                _mm256_or_si256, _mm256_set1_epi32, _mm256_set1_ps, _mm256_setzero_si256,
                _mm256_shuffle_ps, _mm256_slli_epi32, _mm256_sllv_epi32, _mm256_srli_epi32,
                _mm256_srlv_epi32, _mm256_srlv_epi64, _mm256_sub_epi32, _mm256_unpackhi_epi32,
                _mm256_unpacklo_epi32, _mm256_xor_si256, _pdep_u64,
            };
            use tcb_core::simd::w8::{I8, W8};
            use wide::{f32x8, i32x8};

            // SAFETY (every `_here`): the caller came here where
            // `crate::isa` chose this instance, which it does only where the
            // CPU has its features (`$detected`).

            /// [`interior_tangents`] in this instance.
            #[inline(always)]
            pub(super) fn interior_tangents_here(
                keys: [&[f32x8]; 4],
                weights: &[[f32x8; 4]],
                m0: &mut [f32x8],
                m1: &mut [f32x8],
            ) {
                debug_assert!($detected());
                #[allow(unsafe_code)]
                unsafe {
                    tangents(keys, weights, m0, m1)
                }
            }

            #[target_feature(enable = $features)]
            fn tangents(
                keys: [&[f32x8]; 4],
                weights: &[[f32x8; 4]],
                m0: &mut [f32x8],
                m1: &mut [f32x8],
            ) {
                interior_tangents::<W8>(keys, weights, m0, m1);
            }

            /// [`play_keys_on`] in this instance.
            #[inline(always)]
            pub(super) fn play_keys_here(
                g: &PackedKeys,
                win: &[f32x8],
                f: &FrameBasis,
                w: [f32; 4],
                out: &mut [f32x8],
                vel: Option<&mut [f32x8]>,
            ) -> bool {
                debug_assert!($detected());
                #[allow(unsafe_code)]
                unsafe {
                    play(g, win, f, w, out, vel)
                }
            }

            #[target_feature(enable = $features)]
            fn play(
                g: &PackedKeys,
                win: &[f32x8],
                f: &FrameBasis,
                w: [f32; 4],
                out: &mut [f32x8],
                vel: Option<&mut [f32x8]>,
            ) -> bool {
                play_keys_on::<W8>(g, win, f, w, out, vel)
            }

            /// [`Headers::read`] compiled for this instance.
            #[inline(always)]
            pub(super) fn headers_here(
                h: &mut Headers,
                words: &[u64],
                pos: usize,
                headed: usize,
            ) -> (usize, usize, bool) {
                debug_assert!($detected());
                #[allow(unsafe_code)]
                unsafe {
                    headers(h, words, pos, headed)
                }
            }

            #[target_feature(enable = $features)]
            fn headers(
                h: &mut Headers,
                words: &[u64],
                pos: usize,
                headed: usize,
            ) -> (usize, usize, bool) {
                if crate::isa::fast_pdep() {
                    h.read::<V, Pdep>(words, pos, headed)
                } else {
                    h.read::<V, crate::pack::Portable>(words, pos, headed)
                }
            }

            /// [`rebuild_rows`] in this instance.
            #[inline(always)]
            pub(super) fn rebuild_rows_here(g: &PackedKeys, rows: &mut [f32x8]) -> bool {
                debug_assert!($detected());
                #[allow(unsafe_code)]
                unsafe {
                    rebuild(g, rows)
                }
            }

            #[target_feature(enable = $features)]
            fn rebuild(g: &PackedKeys, rows: &mut [f32x8]) -> bool {
                rebuild_rows::<W8>(g, rows)
            }

            /// The prediction and dequantization of the rows `rows` (keys
            /// `first..keys` of the segment, `planes` vectors each), the residuals
            /// gathered from the stream at the bits `base + start * k` (`k =
            /// rows.len() / planes` keys), each plane's coding gathered from the
            /// headers `h` at `g.plane_index`.
            ///
            /// # Safety
            ///
            /// `$detected()` is true (the CPU has this instance's features),
            /// every index `i` of `g.plane_index` is below the length of
            /// `h.entry`, and for every lane the sum of the
            /// widths before it and its own, times `k`, plus `base` is
            /// at most `64 * g.packed.stream.len() - 64` and below `i32::MAX`
            /// (each gather reads 8 bytes from the byte of a lane's bit).
            #[inline(always)]
            #[allow(unsafe_code)]
            pub(super) unsafe fn predict_gathered_here(
                g: &PackedKeys,
                h: &Headers,
                base: usize,
                factor: f32,
                x0: &mut [i32x8],
                x1: &mut [i32x8],
                rows: &mut [f32x8],
            ) {
                debug_assert!($detected());
                // SAFETY: the caller's (above).
                unsafe { predict_gathered(g, h, base as i32, factor, x0, x1, rows) }
            }

            #[inline(always)]
            fn m(x: [i32; 8]) -> __m256i {
                bytemuck::cast(x)
            }

            /// The 32 bits from each lane's bit `bit` of `bytes` (bit `p` is bit
            /// `p % 8` of byte `p / 8`; fewer where they pass a byte's top, the
            /// caller masks what it reads): gathered from the lane's byte, shifted
            /// by the rest.
            ///
            /// # Safety
            ///
            /// Each lane's `bit` is at least 0 and `bit / 8 + 4` at most
            /// `bytes.len()`.
            #[inline]
            #[target_feature(enable = $features)]
            #[allow(unsafe_code)]
            unsafe fn bits_at(bytes: &[u8], bit: __m256i) -> I8 {
                // SAFETY: the caller's: each 4-byte read is inside `bytes`.
                #[allow(unsafe_code)]
                let word = unsafe {
                    _mm256_i32gather_epi32::<1>(bytes.as_ptr().cast(), _mm256_srli_epi32::<3>(bit))
                };
                let seven = _mm256_set1_epi32(7);
                I8(bytemuck::cast(_mm256_srlv_epi32(
                    word,
                    _mm256_and_si256(bit, seven),
                )))
            }

            /// A block's first keys into `rows` (its first, and its second where
            /// `rows` has two) and the predictor: each plane's start values and
            /// deltas gathered from the bits `base + g.start_gather[p]`, as the
            /// baseline's `block_start` reads them one lane at a time.
            ///
            /// # Safety
            ///
            /// `$detected()` is true (the CPU has this instance's features),
            /// `g.start_gather` is not empty, and
            /// `base + g.start_bits + 32` is at most `64 * g.packed.stream.len()`
            /// and below `i32::MAX`.
            #[inline(always)]
            #[allow(unsafe_code)]
            pub(super) unsafe fn block_start_gathered_here(
                g: &PackedKeys,
                base: usize,
                factor: f32,
                x0: &mut [i32x8],
                x1: &mut [i32x8],
                rows: &mut [f32x8],
            ) {
                debug_assert!($detected() && !g.start_gather.is_empty());
                // SAFETY: the caller's (above).
                unsafe { block_start_gathered(g, base as i32, factor, x0, x1, rows) }
            }

            #[target_feature(enable = $features)]
            fn block_start_gathered(
                g: &PackedKeys,
                base: i32,
                factor: f32,
                x0: &mut [i32x8],
                x1: &mut [i32x8],
                rows: &mut [f32x8],
            ) {
                let np = g.planes;
                let bytes: &[u8] = bytemuck::cast_slice(&g.packed.stream);
                let base = _mm256_set1_epi32(base);
                let keys = rows.len() / np;
                let (row0, row1) = rows.split_at_mut(np);
                let planes = g.start_gather.iter().zip(&g.step);
                for (p, ([abs_at, abs_w, delta_at, delta_w], step)) in planes.enumerate() {
                    let read = |at: &[i32; 8], w: &[i32; 8]| {
                        let bit = _mm256_add_epi32(base, m(*at));
                        // SAFETY: every lane's bit ends at or before `base +
                        // start_bits`, 32 bits before the stream's end
                        // (`block_start_gathered_here`).
                        #[allow(unsafe_code)]
                        let z = unsafe { bits_at(bytes, bit) };
                        unzigzag_lanes(z & width_lanes(I8(*w)).0)
                    };
                    let (start, delta) = (read(abs_at, abs_w), read(delta_at, delta_w));
                    let step = block_step(W8(step.to_array()), W8([factor; 8]));
                    let [k0, k1] = block_start_keys(start, delta, keys);
                    row0[p] = f32x8::new(dequantize_lanes(k0, step).0);
                    if let Some(row) = row1.get_mut(p) {
                        *row = f32x8::new(dequantize_lanes(k1, step).0);
                    }
                    (x0[p], x1[p]) = (i32x8::new(k0.0), i32x8::new(k1.0));
                }
            }

            #[target_feature(enable = $features)]
            fn predict_gathered(
                g: &PackedKeys,
                h: &Headers,
                base: i32,
                factor: f32,
                x0: &mut [i32x8],
                x1: &mut [i32x8],
                rows: &mut [f32x8],
            ) {
                let np = g.planes;
                let n = rows.len() / np;
                if n == 0 {
                    // A block's segment of at most two keys: its start
                    // values and deltas gave them all (the predictor as it
                    // was).
                    return;
                }
                let bytes: &[u8] = bytemuck::cast_slice(&g.packed.stream);
                let base = _mm256_set1_epi32(base);
                let keys = _mm256_set1_epi32(n as i32);
                // A plane's coding, first bit and first 64 bits per lane. The
                // next plane's are read before the current plane's keys run, so
                // that its gathers (the entries, then the residuals at the bits
                // they give) wait behind work rather than ahead of it.
                let setup = |p: usize| {
                    // SAFETY: the caller's, every index inside `h.entry`.
                    #[allow(unsafe_code)]
                    let e = unsafe {
                        _mm256_i32gather_epi32::<4>(h.entry.as_ptr(), m(g.plane_index[p]))
                    };
                    let [width, trend, start] = entry_fields(V(e));
                    let bit = _mm256_add_epi32(base, _mm256_mullo_epi32(start.0, keys));
                    // SAFETY: as below.
                    #[allow(unsafe_code)]
                    let words = unsafe { read_shifted(bytes, bit) };
                    (width, trend, bit, words)
                };
                let planes = &g.stored_planes;
                let mut next = planes.first().map(|&p| setup(p as usize));
                for (i, &p) in planes.iter().enumerate() {
                    let p = p as usize;
                    let Some((width, trend, mut bit, mut words)) = next else {
                        break;
                    };
                    next = planes.get(i + 1).map(|&p| setup(p as usize));
                    let (low, bias) = width_lanes(width);
                    let code = [trend, low, bias];
                    let width = width.0;
                    let widest = widest(width) as usize & 31;
                    // Keys whose residuals every lane has in the 57 bits after the
                    // first one's byte: one 8-byte read per lane serves them all.
                    let per = KEYS_IN_57_BITS[widest] as usize;
                    // Keys whose residuals every lane has in the low 32 bits
                    // of its window: taken from one set of low words, each
                    // key shifting them on by its width (one instruction
                    // where moving the two halves of the 64-bit windows and
                    // taking their low words again is three).
                    let group = KEYS_IN_32_BITS[widest] as usize;
                    let group_q =
                        halves(_mm256_mullo_epi32(width, _mm256_set1_epi32(group as i32)));
                    // The bits a chunk of `per` keys takes (each chunk that
                    // ends before the last key has `per`).
                    let chunk_bits = _mm256_mullo_epi32(width, _mm256_set1_epi32(per as i32));
                    // The last key and its step.
                    let (a, b) = (V(bytemuck::cast(x0[p])), V(bytemuck::cast(x1[p])));
                    let (mut x, mut d) = (b, b - a);
                    let step = block_step(F(bytemuck::cast(g.step[p])), F(_mm256_set1_ps(factor)));
                    // Row `r`'s vector of plane `p`: `rows[r * np + p]`,
                    // written through `out`, `np` vectors on per key.
                    assert!(p < np && rows.len() == n * np, "a stored plane");
                    // SAFETY: `p < np <= rows.len()` (`n >= 1` above).
                    #[allow(unsafe_code)]
                    let mut out = unsafe { rows.as_mut_ptr().add(p) };
                    // One key from the low words `low`: the prediction and
                    // the key written. SAFETY (of `out`'s write): before key `r`
                    // (`r < n`: the groups' keys add up to `n`), `out` is
                    // `rows[r * np + p]`, inside `rows`. After the last key
                    // it points `p` vectors past the end and is not read:
                    // `wrapping_add` makes no claim about where it points.
                    macro_rules! key {
                        ($low:expr, $code:expr) => {
                            (x, d) = predict(x, d, V($low), $code);
                            #[allow(unsafe_code)]
                            unsafe {
                                out.write(bytemuck::cast(dequantize_lanes(x, step).0));
                                out = out.wrapping_add(np);
                            }
                        };
                    }
                    // The plane's keys, chunk by chunk, with the coding `$code`.
                    macro_rules! keys {
                        ($code:expr) => {
                            let mut left = n;
                            loop {
                                let k = per.min(left);
                                left -= k;
                                // The chunk's keys, `group` at a time (the last group
                                // may have fewer): each group's last key leaves its
                                // low words unshifted, and the chunk's last group its
                                // windows (the next chunk reads its own).
                                let mut rest = k;
                                loop {
                                    let keys = group.min(rest);
                                    rest -= keys;
                                    let mut low = low_words(words);
                                    for _ in 1..keys {
                                        key!(low, $code);
                                        low = _mm256_srlv_epi32(low, width);
                                    }
                                    key!(low, $code);
                                    if rest == 0 {
                                        break;
                                    }
                                    for (w, s) in words.iter_mut().zip(group_q) {
                                        *w = _mm256_srlv_epi64(*w, s);
                                    }
                                }
                                if left == 0 {
                                    break;
                                }
                                debug_assert_eq!(k, per, "a chunk before the last");
                                bit = _mm256_add_epi32(bit, chunk_bits);
                                // SAFETY: every lane's bit is below the bound of
                                // `predict_gathered_here`'s contract, 64 bits before the
                                // end of `bytes`, so each 8-byte read is inside it.
                                #[allow(unsafe_code)]
                                {
                                    words = unsafe { read_shifted(bytes, bit) };
                                }
                            }
                        };
                    }
                    // Where every lane predicts from the last two keys (order
                    // 2, about half of CMU's planes and segments), its step
                    // `d & trend` is `d`: a constant mask LLVM folds, one
                    // instruction less a key and a shorter chain from key to key.
                    if _mm256_movemask_ps(_mm256_castsi256_ps(trend.0)) == 0xff {
                        keys!([V(_mm256_set1_epi32(-1)), low, bias]);
                    } else {
                        keys!(code);
                    }
                    (x0[p], x1[p]) = (bytemuck::cast((x - d).0), bytemuck::cast(x.0));
                }
            }

            /// Eight `i32` lanes in an AVX register, for [`predict`] and
            /// `dequantize_lanes` in the decoder's loop over keys: `I8`'s arrays
            /// there leave LLVM rebuilding loop-invariant vectors lane by lane.
            /// Each operation is the one AVX2 instruction of `I8`'s (wrapping).
            #[derive(Clone, Copy)]
            struct V(__m256i);

            /// Eight `f32` lanes in an AVX register, `V`'s floats.
            #[derive(Clone, Copy)]
            struct F(__m256);

            avx_op!(V, Add, add, _mm256_add_epi32);
            avx_op!(V, Sub, sub, _mm256_sub_epi32);
            avx_op!(V, BitAnd, bitand, _mm256_and_si256);
            avx_op!(V, BitOr, bitor, _mm256_or_si256);
            avx_op!(V, BitXor, bitxor, _mm256_xor_si256);
            avx_op!(F, Mul, mul, _mm256_mul_ps);

            impl super::EntryLanes for V {
                #[inline(always)]
                fn bytes(x: u64) -> V {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    V(unsafe { _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(x as i64)) })
                }
                #[inline(always)]
                fn splat(x: i32) -> V {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    V(unsafe { _mm256_set1_epi32(x) })
                }
                #[inline(always)]
                fn shl<const N: i32>(self) -> V {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    V(unsafe { _mm256_slli_epi32::<N>(self.0) })
                }
                #[inline(always)]
                fn to_array(self) -> [i32; 8] {
                    bytemuck::cast(self.0)
                }
            }

            // A plane's coding computed on `V` rather than `I8`: on `I8`'s
            // arrays LLVM's vectorizer joined the three fields of
            // `entry_fields` into 512-bit operations in the AVX-512
            // instance, and one 512-bit instruction in a loop slows the
            // 256-bit work around it on Intel cores (their vector port 1
            // stops while 512-bit work is in flight).
            impl crate::pack::BitLanes for V {
                // SAFETY: plain bits, the layout of `__m256i`.
                #[allow(unsafe_code)]
                const ZERO: V = V(unsafe { std::mem::transmute::<[i32; 8], __m256i>([0; 8]) });
                #[allow(unsafe_code)]
                const ONE: V = V(unsafe { std::mem::transmute::<[i32; 8], __m256i>([1; 8]) });
                #[inline(always)]
                fn splat(x: i32) -> V {
                    <V as super::EntryLanes>::splat(x)
                }
                #[inline(always)]
                fn shr<const N: u32>(self) -> V {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    V(unsafe { _mm256_srlv_epi32(self.0, _mm256_set1_epi32(N as i32)) })
                }
                #[inline(always)]
                fn half(self) -> V {
                    self.shr::<1>()
                }
                #[inline(always)]
                fn shl_each(self, n: V) -> V {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    V(unsafe { _mm256_sllv_epi32(self.0, n.0) })
                }
                #[inline(always)]
                fn sub_wrapping(self, o: V) -> V {
                    self - o
                }
            }

            /// [`crate::pack::Spread`] with BMI2's `pdep`, for `headers`
            /// (which runs where this instance's features, BMI2 among them,
            /// are: as `avx_op`'s).
            struct Pdep;

            impl crate::pack::Spread for Pdep {
                #[inline(always)]
                fn spread1(x: u64) -> u64 {
                    // SAFETY: as `avx_op`'s (BMI2).
                    #[allow(unsafe_code)]
                    unsafe {
                        _pdep_u64(x, crate::pack::BYTES)
                    }
                }
                #[inline(always)]
                fn spread2(x: u64) -> u64 {
                    // SAFETY: as `avx_op`'s (BMI2).
                    #[allow(unsafe_code)]
                    unsafe {
                        _pdep_u64(x, 3 * crate::pack::BYTES)
                    }
                }
                #[inline(always)]
                fn whole_widths(tails: u64, whole: u64) -> u64 {
                    let mask = whole * ((1 << crate::pack::WIDTH_BITS) - 1);
                    // SAFETY: as `avx_op`'s (BMI2).
                    #[allow(unsafe_code)]
                    unsafe {
                        _pdep_u64(tails, mask)
                    }
                }
            }

            /// `Pdep` is `Portable` on every input either takes.
            #[cfg(test)]
            #[test]
            fn pdep_spreads_as_the_portable_code() {
                use crate::pack::{Portable, Spread};
                #[target_feature(enable = $features)]
                fn check() {
                    for x in 0..1u64 << 8 {
                        assert_eq!(Pdep::spread1(x), Portable::spread1(x), "{x:#x}");
                    }
                    for x in 0..1u64 << 16 {
                        assert_eq!(Pdep::spread2(x), Portable::spread2(x), "{x:#x}");
                    }
                    // Every set of lanes with widths coded whole, from
                    // tails of random bits.
                    let mut t = 0x9e37_79b9_7f4a_7c15u64;
                    for lanes in 0..1u64 << 8 {
                        let whole = Portable::spread1(lanes);
                        t = t.rotate_left(23).wrapping_mul(0x2545_f491_4f6c_dd1d);
                        let want = Portable::whole_widths(t, whole);
                        assert_eq!(Pdep::whole_widths(t, whole), want, "{lanes:#x}");
                    }
                }
                if $detected() {
                    // SAFETY: the CPU has this instance's features.
                    #[allow(unsafe_code)]
                    unsafe {
                        check()
                    }
                }
            }

            impl crate::pack::IntLanes for V {
                type Float = F;
                #[inline(always)]
                fn to_float(self) -> F {
                    // SAFETY: as `avx_op`'s.
                    #[allow(unsafe_code)]
                    F(unsafe { _mm256_cvtepi32_ps(self.0) })
                }
            }

            /// Each lane's 64 bits from the byte of its bit `bit`, shifted to it,
            /// in two halves of 4 lanes (as u64s).
            ///
            /// # Safety
            ///
            /// Each lane's `bit / 8 + 8` is at most `bytes.len()`.
            #[inline]
            #[target_feature(enable = $features)]
            #[allow(unsafe_code)]
            unsafe fn read_shifted(bytes: &[u8], bit: __m256i) -> [__m256i; 2] {
                let byte = halves(_mm256_srli_epi32::<3>(bit));
                let shift = halves(_mm256_and_si256(bit, _mm256_set1_epi32(7)));
                // SAFETY: the caller's.
                let words = unsafe { [read64(bytes, byte[0]), read64(bytes, byte[1])] };
                [
                    _mm256_srlv_epi64(words[0], shift[0]),
                    _mm256_srlv_epi64(words[1], shift[1]),
                ]
            }

            /// How many residuals of a width (at most 25) 57 bits hold: 64 bits
            /// read from the byte of the first one's bit hold at least 57 after it.
            const KEYS_IN_57_BITS: [u8; 32] = super::keys_in(57);

            /// How many residuals of a width the low 32 bits of a window hold.
            const KEYS_IN_32_BITS: [u8; 32] = super::keys_in(32);

            /// The largest of the 8 lanes of `x` (as u32).
            #[inline]
            #[target_feature(enable = $features)]
            fn widest(x: __m256i) -> u32 {
                let x = _mm_max_epu32(_mm256_castsi256_si128(x), _mm256_extracti128_si256::<1>(x));
                let x = _mm_max_epu32(x, _mm_shuffle_epi32::<0b01_00_11_10>(x));
                let x = _mm_max_epu32(x, _mm_shuffle_epi32::<0b10_11_00_01>(x));
                _mm_cvtsi128_si32(x) as u32
            }

            /// The 8 lanes of `x` as two halves of 4 lanes, each widened to u64:
            /// lanes 0, 1, 4 and 5, then 2, 3, 6 and 7 (the order in which
            /// [`low_words`] takes them back with one shuffle).
            #[inline]
            #[target_feature(enable = $features)]
            fn halves(x: __m256i) -> [__m256i; 2] {
                let zero = _mm256_setzero_si256();
                [
                    _mm256_unpacklo_epi32(x, zero),
                    _mm256_unpackhi_epi32(x, zero),
                ]
            }

            /// The low 32 bits of each u64 of two [`halves`], as 8 lanes.
            #[inline]
            #[target_feature(enable = $features)]
            fn low_words([lo, hi]: [__m256i; 2]) -> __m256i {
                // Per 128 bits: lo's two low words, then hi's.
                let mixed = _mm256_shuffle_ps::<0b10_00_10_00>(
                    _mm256_castsi256_ps(lo),
                    _mm256_castsi256_ps(hi),
                );
                _mm256_castps_si256(mixed)
            }

            /// 8 bytes from `bytes` at each of 4 byte offsets (`at`, as u64).
            ///
            /// # Safety
            ///
            /// Each offset plus 8 is at most `bytes.len()`.
            #[inline]
            #[target_feature(enable = $features)]
            #[allow(unsafe_code)]
            unsafe fn read64(bytes: &[u8], at: __m256i) -> __m256i {
                // SAFETY: the caller's: each 8-byte read is inside `bytes`.
                unsafe { _mm256_i64gather_epi64::<1>(bytes.as_ptr().cast(), at) }
            }
        }
    };
}

// AVX2, FMA and the bit instructions of x86-64-v3 (`crate::isa::avx2`).
#[cfg(target_arch = "x86_64")]
decoder_instance!(v3, "avx2,fma,bmi1,bmi2,lzcnt,popcnt", crate::isa::cpu_avx2);
// The same code where AVX-512 F, VL, BW and DQ were detected too
// (`crate::isa::avx512`): 32 registers and AVX-512's instructions to
// compile to, on 256-bit registers only (`tools/check/no-512-bit.sh`);
// about 8% less time a frame on `character-compressed-acl` on Zen 4, the
// same as the AVX2 instance on an Intel Xeon with AVX-512.
#[cfg(target_arch = "x86_64")]
decoder_instance!(
    v4,
    "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq",
    crate::isa::cpu_avx512
);

/// Unpacks 16 values of one width (the index) from a bit position of a
/// stream into `out[i * stride]`, as stored (`super::width_lanes`' bias above their
/// value).
type Unpack = fn(&[u64], usize, &mut [i32], usize);

/// One function per width, each unrolled: a 64-bit window holds `64 / W`
/// values, taken with a mask and a shift.
const UNPACK: [Unpack; 32] = {
    macro_rules! widths {
        ($($w:literal)*) => { [unpack_none as Unpack, $(unpack16::<$w> as Unpack),*] };
    }
    widths!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)
};

/// Width 0: nothing stored (the decoder masks such lanes' residuals).
fn unpack_none(_: &[u64], _: usize, _: &mut [i32], _: usize) {}

/// 16 values of `W` bits from bit `pos` of `words` into `out[i * stride]`.
/// The stream ends with enough words of padding for 16 values from any
/// bit of it ([`super::STREAM_PAD`]); a window past them (a stream not
/// checked) writes nothing.
fn unpack16<const W: usize>(words: &[u64], pos: usize, out: &mut [i32], stride: usize) {
    let Some(src) = words.get(pos >> 6..(pos >> 6) + super::STREAM_PAD) else {
        return;
    };
    let src: &[u64; super::STREAM_PAD] = src.try_into().expect("sliced to the length");
    let (o, per, mask) = (pos & 63, 64 / W, (1u64 << W) - 1);
    // Into registers first (indices known at compile time, no checks),
    // then one store per row.
    let mut v = [0i32; 16];
    let mut i = 0;
    while i < 16 {
        let (at, sh) = ((o + i * W) >> 6, ((o + i * W) & 63) as u32);
        let mut win = (src[at] >> sh) | ((src[at + 1] << 1) << (63 - sh));
        let mut j = 0;
        while j < per && i + j < 16 {
            v[i + j] = (win & mask) as i32;
            win >>= W;
            j += 1;
        }
        i += per;
    }
    for (row, v) in out.chunks_mut(stride).zip(v) {
        if let Some(x) = row.first_mut() {
            *x = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{key_row, tangent};
    use tcb_core::simd::basis::{hermite, hermite_basis, hermite_basis_derivative};

    /// [`key_row`] plays the curve of the tangents it writes out: at
    /// random parameters, keys and weights (at most 1), its sum of four
    /// keys is the hermite of the keys and their tangents (both in f32)
    /// within a few roundings; at the segment's ends it is the key itself.
    #[test]
    fn key_row_is_the_tangents_curve() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst = 0.0f32;
        for _ in 0..20_000 {
            let p = [next(), next(), next(), next()].map(|v| v as f32);
            let w = [next(), next(), next(), next()].map(|v| v as f32);
            let s = (next() * 0.5 + 0.5) as f32;
            let [before, pa, pb, after] = p;
            let [in_a, in_b, out_a, out_b] = w;
            let to = tangent(pa - before, pb - pa, out_a, out_b);
            let ti = tangent(pb - pa, after - pb, in_a, in_b);
            for h in [hermite_basis(s), hermite_basis_derivative(s)] {
                let want = hermite(&h, pa, pb, to, ti);
                let got = hermite(&key_row(h, w), pa, pb, before, after);
                worst = worst.max((got - want).abs());
            }
        }
        assert!(worst < 2e-6, "{worst}");
        let w = [0.5, 0.25, -0.75, 1.0];
        assert_eq!(key_row([1.0, 0.0, 0.0, 0.0], w), [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(key_row([0.0, 1.0, 0.0, 0.0], w), [0.0, 1.0, 0.0, 0.0]);
    }
}
