//! A group's controls from a [`Packed`] stream: keys decoded as playback
//! reaches them, tangents derived from their neighbours.
//!
//! An instance keeps the last four decoded keys (`P`, in the group's planes)
//! and the predictor's state; a segment from key `a` to `a + 1` needs keys
//! `a - 1 ..= a + 2`, so forward playback decodes one key per key it
//! crosses. Interior tangents are the tangent rule on the two chords,
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

use super::{Packed, SEGMENT_KEYS, read_bits, read_header, unzigzag, window};
use crate::segment::Segment;
use std::sync::Arc;
use wide::{f32x8, i32x8};

/// Sections of a key: `P`, `TO`, `TI`.
const P: usize = 0;
const TO: usize = 1;
const TI: usize = 2;

/// The packed controls of one group (see the module docs).
#[derive(Clone, Debug)]
pub(crate) struct PackedKeys {
    pub packed: Arc<Packed>,
    /// Keys (n).
    pub keys: usize,
    pub planes: usize,
    /// Per stream lane, its plane and lane in the group (`8 plane + lane`).
    pub lane_slot: Vec<u32>,
    /// Per plane: the quantization step of each lane (0 where not stored).
    pub step: Vec<f32x8>,
    /// Per plane: `in_a, in_b, out_a, out_b` of each lane.
    pub weights: Vec<[f32x8; 4]>,
    /// The first rotation plane; rotation blocks of 4 planes follow.
    pub rot_from: usize,
    /// Per rotation block: lanes whose `w` is rebuilt (and padding lanes),
    /// as a mask.
    pub rebuild: Vec<f32x8>,
    /// `[P TO TI]` of keys 0, n-1 and the four sentinel pseudo-keys
    /// (`n ..= n+3`), `planes` vectors each.
    pub table: Vec<f32x8>,
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
            + 4 * self.lane_slot.len()
            + 32 * (self.step.len() + 4 * self.weights.len() + self.table.len())
            + 8 * self.rebuild.len()
    }

    /// A cache for [`segment`](Self::segment), per instance.
    pub fn cache(&self) -> PackCache {
        let lanes = self.lane_slot.len();
        PackCache {
            seg: usize::MAX,
            next: 0,
            first: 0,
            reads: vec![LaneRead::default(); lanes],
            res: vec![i32x8::ZERO; SEGMENT_KEYS * self.planes],
            trend: vec![i32x8::ZERO; self.planes],
            abs: vec![0; lanes],
            delta: vec![0; lanes],
            flat: vec![i32x8::ZERO; self.planes],
            x0: vec![i32x8::ZERO; self.planes],
            x1: vec![i32x8::ZERO; self.planes],
            p: vec![f32x8::ZERO; 4 * self.planes],
            m: vec![f32x8::ZERO; 2 * self.planes],
        }
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

    /// `TO_a` and `TI_b` of interior keys into the cache (module docs).
    fn tangents(&self, a: usize, b: usize, c: &mut PackCache) {
        let (np, n) = (self.planes, self.keys);
        let ring = |k: usize| (k & 3) * np;
        let (m0, m1) = c.m.split_at_mut(np);
        let p = &c.p;
        if a > 0 {
            let (x, y, z) = (ring(a - 1), ring(a), ring(b));
            let rows = p[x..x + np].iter().zip(&p[y..y + np]).zip(&p[z..z + np]);
            for ((m, ((x, y), z)), w) in m0.iter_mut().zip(rows).zip(&self.weights) {
                *m = (*y - *x) * w[2] + (*z - *y) * w[3];
            }
        }
        if b < n - 1 {
            let (x, y, z) = (ring(a), ring(b), ring(b + 1));
            let rows = p[x..x + np].iter().zip(&p[y..y + np]).zip(&p[z..z + np]);
            for ((m, ((x, y), z)), w) in m1.iter_mut().zip(rows).zip(&self.weights) {
                *m = (*y - *x) * w[0] + (*z - *y) * w[1];
            }
        }
    }
}

/// Where one stream lane's residual is in a key's row of the current
/// segment, and its width.
#[derive(Clone, Copy, Debug, Default)]
struct LaneRead {
    slot: u32,
    width: u32,
}

/// One instance's decoding state for a [`PackedKeys`] group.
#[derive(Clone, Debug)]
pub(crate) struct PackCache {
    /// The first key of the segment whose tangents `m` holds.
    seg: usize,
    /// The next key to decode, and the first decoded since the last seek.
    next: usize,
    first: usize,
    /// Per stream lane: its plane slot and this segment's width.
    reads: Vec<LaneRead>,
    /// This segment's residuals, zigzag-coded: per key of the segment, per
    /// plane (a key's row is contiguous, in the group's planes).
    res: Vec<i32x8>,
    /// Per plane: all ones in lanes predicted by the line through their
    /// last two values (order 2), zeros in lanes predicted by the last.
    trend: Vec<i32x8>,
    /// Per stream lane: this block's start and delta.
    abs: Vec<i32>,
    delta: Vec<i32>,
    /// Integers of one key in the group's planes (scratch).
    flat: Vec<i32x8>,
    /// The predictor: the last two keys' integers, per plane.
    x0: Vec<i32x8>,
    x1: Vec<i32x8>,
    /// The last four decoded keys (key k in slot k & 3), `planes` each.
    p: Vec<f32x8>,
    /// `TO_a` then `TI_b` of the segment `seg`.
    m: Vec<f32x8>,
}

impl PackCache {
    #[inline(always)]
    fn ring(&self, k: usize, np: usize) -> &[f32x8] {
        let at = (k & 3) * np;
        &self.p[at..at + np]
    }

    /// Decode until keys `lo ..= hi` (at most 4) are in the ring: forward
    /// from the last key decoded, or from the start of `lo`'s block.
    fn ensure(&mut self, g: &PackedKeys, lo: usize, hi: usize) {
        let start = lo - lo % g.packed.block;
        let ok = if lo >= self.next {
            self.next >= start
        } else {
            lo >= self.first.max(self.next.saturating_sub(4))
        };
        if !ok {
            self.next = start;
            self.first = start;
        }
        while self.next <= hi {
            self.decode_next(g);
        }
    }

    /// Decode key `next` into the ring.
    fn decode_next(&mut self, g: &PackedKeys) {
        let (k, np) = (self.next, g.planes);
        let in_block = k % g.packed.block;
        if k.is_multiple_of(SEGMENT_KEYS) {
            self.enter_segment(g, k, in_block == 0);
        }
        let ring = (k & 3) * np;
        let out = &mut self.p[ring..ring + np];
        let (x0, x1) = (&mut self.x0[..np], &mut self.x1[..np]);
        let step = &g.step[..np];
        if in_block < 2 {
            // The block's start values, then its deltas.
            let from = if in_block == 0 {
                &self.abs
            } else {
                &self.delta
            };
            scatter(&g.lane_slot, from, bytemuck::cast_slice_mut(&mut self.flat));
            let start = i32x8::splat(-i32::from(in_block == 0));
            for p in 0..np {
                let x = (x1[p] & !start) + self.flat[p];
                x0[p] = x1[p];
                x1[p] = x;
                out[p] = super::dequantize_lanes(x, step[p]);
            }
        } else {
            // The key's row of residuals: the prediction (the last value,
            // plus the last difference where the order is 2) plus the
            // unzigzagged residual (widths below 32: the shift's sign bit
            // is 0).
            let row = &self.res[(k % SEGMENT_KEYS) * np..][..np];
            let trend = &self.trend[..np];
            for p in 0..np {
                let (a, b, r) = (x0[p], x1[p], row[p]);
                let x = b + ((b - a) & trend[p]) + ((r >> 1) ^ (i32x8::ZERO - (r & 1)));
                x0[p] = b;
                x1[p] = x;
                out[p] = super::dequantize_lanes(x, step[p]);
            }
        }
        let rot = &mut out[g.rot_from..];
        for (block, mask) in rot.chunks_exact_mut(4).zip(&g.rebuild) {
            let w = tcb_core::quat::rebuild_w(block[0], block[1], block[2]);
            block[3] = (*mask & w) | (!*mask & block[3]);
        }
        self.next = k + 1;
    }

    /// At the first key of a segment: its headers (and, starting a block,
    /// the block's start values and deltas) and every lane's residuals of
    /// the segment, into `res` by key and plane lane; each lane's
    /// prediction order.
    fn enter_segment(&mut self, g: &PackedKeys, k: usize, block: bool) {
        let s: &[u64] = &g.packed.stream;
        let mut pos = g.packed.seg_at[k / SEGMENT_KEYS] as usize;
        let flat: &mut [i32] = bytemuck::cast_slice_mut(&mut self.flat);
        for (r, &slot) in self.reads.iter_mut().zip(&g.lane_slot) {
            let before = if block { 0 } else { r.width };
            let (order, w, used) = read_header(s, pos, before);
            pos += used;
            *r = LaneRead { slot, width: w };
            flat[slot as usize] = if order == 2 { -1 } else { 0 };
        }
        self.trend.copy_from_slice(&self.flat);
        if block {
            for (x, &w) in self.abs.iter_mut().zip(&g.packed.abs_bits) {
                *x = unzigzag(read_bits(s, pos, u32::from(w)));
                pos += usize::from(w);
            }
            for (x, &w) in self.delta.iter_mut().zip(&g.packed.delta_bits) {
                *x = unzigzag(read_bits(s, pos, u32::from(w)));
                pos += usize::from(w);
            }
        }
        // Rows: the segment's keys after the block's first two.
        let end = (k + SEGMENT_KEYS).min(g.keys);
        let first = if block { 2.min(end - k) } else { 0 };
        read_segment(
            s,
            pos,
            &self.reads,
            first..end - k,
            bytemuck::cast_slice_mut(&mut self.res),
            8 * g.planes,
        );
    }
}

/// Each lane's residuals of one segment (contiguous, in the lane's width)
/// from bit `pos` of `words` into `res`, still zigzag-coded, at
/// `row * stride + slot` for the segment's `rows` (its keys after a
/// block's first two): as many values from each 64-bit window as it holds.
/// (A function of slices alone, out of line, so that its loop keeps its
/// pointers in registers.)
#[inline(never)]
fn read_segment(
    words: &[u64],
    mut pos: usize,
    reads: &[LaneRead],
    rows: std::ops::Range<usize>,
    res: &mut [i32],
    stride: usize,
) {
    let count = rows.len();
    if count == 0 {
        return;
    }
    for r in reads {
        let (w, slot) = (r.width as usize, r.slot as usize);
        let first = rows.start * stride + slot;
        // Every store below lands in `res` (checked once, not per value).
        let Some(lane) = res.get_mut(first..=first + (count - 1) * stride) else {
            continue;
        };
        if w == 0 {
            lane.iter_mut().step_by(stride).for_each(|x| *x = 0);
            continue;
        }
        let (per, mask) = (PER_WINDOW[w] as usize, (1u64 << w) - 1);
        let end = pos + count * w;
        let (mut at, mut i) = (pos, 0);
        while i < lane.len() {
            let mut win = window(words, at);
            let stop = (i + per * stride).min(lane.len());
            while i < stop {
                lane[i] = (win & mask) as i32;
                win >>= w;
                i += stride;
            }
            at += per * w;
        }
        pos = end;
    }
}

/// `64 / w`: the values of width `w` one 64-bit window holds.
const PER_WINDOW: [u8; 33] = {
    let mut t = [0u8; 33];
    let mut w = 1;
    while w <= 32 {
        t[w] = (64 / w) as u8;
        w += 1;
    }
    t
};

/// Stream lanes' integers into their plane lanes.
#[inline(always)]
fn scatter(slots: &[u32], x: &[i32], flat: &mut [i32]) {
    for (&s, &v) in slots.iter().zip(x) {
        flat[s as usize] = v;
    }
}
