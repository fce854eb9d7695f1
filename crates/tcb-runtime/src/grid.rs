//! Key-time grids, playback cursors and the per-frame basis.
//!
//! Every channel of a [`crate::Clip`] group shares one grid: its key times,
//! the ease of each segment, and its `pre`/`post` modes. Once per frame and
//! group, [`TimeGrid::frame`] turns the sample time into a [`FrameBasis`]:
//! which stored segment to read and the Hermite rows to weight it with. The
//! kernels then do nothing but multiply-adds.
//!
//! Stored segments are numbered `0 ..= n`: `0` is the *pre sentinel*
//! (`P0 = P_0`, `M0 = TO_0`), `1 ..= n-1` are the real segments, `n` is the
//! *post sentinel* (`P0 = P_{n-1}`, `M0 = TI_{n-1}`, `M1` = the velocity
//! arriving at the last key). Holding an end key, extrapolating along a
//! line, resetting to zero and sampling exactly at the last key are all a
//! choice of rows on these, with no branch per channel:
//!
//! ```text
//! inside, segment k      segment k+1   h = H(s)          dh = H'(s), rate = ds/du / D_k
//! exactly at t_{n-1}     n             h = [1 0 0 0]     dh = [0 0 0 1], rate = 1
//! hold first / last      0 / n         h = [1 0 0 0]     rate = 0
//! linear, dt from key    0 / n         h = [1 0 dt 0]    dh = [0 0 1 0], rate = 1
//! reset                  0             h = [0 0 0 0]     rate = 0
//! ```
//!
//! `rate` carries the direction of `oscillate` (-1 on backward legs).

use tcb_core::Extrapolation;
use tcb_core::ease::SegmentEase;
use tcb_core::simd::basis::{hermite_basis, hermite_basis_derivative};
use tcb_core::simd::extrapolate::{Mapped, map_time};
use tcb_core::simd::lane::Lane;
use tcb_core::track::segment_from;

/// A grid's key times (n >= 2, strictly increasing): listed, or an even
/// grid, `start + k * interval` in f64, which keeps no list: a packed
/// clip's (a `.tcbc` file's memory does not grow with the keys it claims),
/// and any group's whose listed times are exactly that
/// ([`KeyTimes::from_times`]). Loose lanes keep theirs listed.
#[derive(Clone, Debug, PartialEq)]
pub enum KeyTimes {
    Listed(Vec<f64>),
    Even {
        start: f64,
        interval: f64,
        keys: usize,
        /// `1 / interval`: where a time falls, by a product (checked
        /// against the keys' times, so its rounding does not matter).
        per: f64,
    },
}

impl KeyTimes {
    /// The even grid of `keys` times from `start`, `interval` apart.
    pub fn even(start: f64, interval: f64, keys: usize) -> KeyTimes {
        KeyTimes::Even {
            start,
            interval,
            keys,
            per: 1.0 / interval,
        }
    }

    /// Number of keys.
    #[inline]
    pub fn len(&self) -> usize {
        match self {
            KeyTimes::Listed(t) => t.len(),
            KeyTimes::Even { keys, .. } => *keys,
        }
    }

    /// Key `k`'s time.
    #[inline(always)]
    pub fn at(&self, k: usize) -> f64 {
        match self {
            KeyTimes::Listed(t) => t[k],
            KeyTimes::Even {
                start, interval, ..
            } => even_time(*start, *interval, k),
        }
    }

    /// The listed times; empty for an even grid (only groups have one,
    /// and only loose lanes, whose times stay listed, read this).
    pub fn listed(&self) -> &[f64] {
        match self {
            KeyTimes::Listed(t) => t,
            KeyTimes::Even { .. } => {
                debug_assert!(false, "an even grid has no list of times");
                &[]
            }
        }
    }

    /// `times` (n >= 2, strictly increasing) as an even grid where every
    /// key is [`even_time`]`(t_0, t_1 - t_0, k)` bit for bit (a BVH's
    /// `k * Frame Time`, baked output), else as listed. The same times
    /// either way; an even grid finds a random time by one quotient where a
    /// list searches, and keeps no list.
    pub fn from_times(times: Vec<f64>) -> KeyTimes {
        if let [start, t1, ..] = times[..] {
            let interval = t1 - start;
            let even =
                |(k, t): (usize, &f64)| even_time(start, interval, k).to_bits() == t.to_bits();
            if interval > 0.0 && interval.is_finite() && times.iter().enumerate().all(even) {
                return KeyTimes::even(start, interval, times.len());
            }
        }
        KeyTimes::Listed(times)
    }

    /// These times as [`from_times`](Self::from_times) keeps them: an
    /// even grid where a list is one (the list moved, not copied).
    pub fn into_even(self) -> KeyTimes {
        match self {
            KeyTimes::Listed(t) => KeyTimes::from_times(t),
            even => even,
        }
    }

    /// Every key's time.
    pub fn to_vec(&self) -> Vec<f64> {
        (0..self.len()).map(|k| self.at(k)).collect()
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        match self {
            KeyTimes::Listed(t) => std::mem::size_of_val(t.as_slice()),
            KeyTimes::Even { .. } => 0,
        }
    }

    /// Segment k with `at(k) <= time < at(k+1)`, 0 before the keys (or for
    /// NaN), the last at or after the last key: for listed times from the
    /// hint ([`tcb_core::track::segment_from`]), for even ones from where
    /// `time` falls, then checked against the keys' own times.
    #[inline]
    fn locate(&self, time: f64, hint: usize) -> usize {
        let (start, interval, keys, per) = match self {
            KeyTimes::Listed(t) => return segment_from(t, time, hint),
            KeyTimes::Even {
                start,
                interval,
                keys,
                per,
            } => (*start, *interval, *keys, *per),
        };
        // Where `time` falls (a saturating cast: 0 for NaN), by a product
        // rather than a division (on the frame's critical path), checked
        // against the keys' own times: no loop, so no vectorized search,
        // and the caller's times of the segment are these.
        let k = ((((time - start) * per) as i64).max(0) as usize).min(keys - 2);
        if even_time(start, interval, k) <= time && time < even_time(start, interval, k + 1) {
            k
        } else {
            self.locate_near(time, k)
        }
    }

    /// [`locate`](Self::locate) on an even grid where the quotient's
    /// segment `k` is not the one: before the keys (or NaN), after them,
    /// or a key either way for the quotient's rounding, else bisection.
    #[cold]
    fn locate_near(&self, time: f64, k: usize) -> usize {
        let last = self.len() - 2;
        if time.is_nan() || time < self.at(0) {
            return 0;
        }
        if time >= self.at(last + 1) {
            return last;
        }
        let k = if k > 0 && self.at(k) > time {
            k - 1
        } else if k < last && self.at(k + 1) <= time {
            k + 1
        } else {
            k
        };
        if self.at(k) <= time && time < self.at(k + 1) {
            k
        } else {
            self.bisect(time, last)
        }
    }

    /// [`locate`](Self::locate) by bisection, for times that the quotient
    /// places more than a key off.
    #[cold]
    fn bisect(&self, time: f64, last: usize) -> usize {
        let (mut lo, mut hi) = (0, last);
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            if self.at(mid) <= time {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        lo
    }
}

/// Key `k`'s time on an even grid: `start + k interval` in f64, what
/// `tcb compress` writes and the runtime plays (one formula for both).
/// (`k as i64 as f64` is `k as f64` for every key count a clip can have,
/// in one instruction where `usize` takes ten.)
#[inline(always)]
pub(crate) fn even_time(start: f64, interval: f64, k: usize) -> f64 {
    start + k as i64 as f64 * interval
}

/// Key times, segment eases and extrapolation shared by a group of channels.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeGrid {
    /// Key times.
    pub times: KeyTimes,
    /// Ease of each of the n-1 segments, or empty when no segment eases.
    pub eases: Vec<SegmentEase>,
    /// Whether each of the n-1 segments is `step` in every channel of the
    /// group (played at `s = 0`, so they hold the segment's first key), or
    /// empty when none is.
    pub steps: Vec<bool>,
    /// Before the first key.
    pub pre: Extrapolation,
    /// After the last key.
    pub post: Extrapolation,
}

/// What one frame of one group reads: a stored segment and the rows to
/// weight its controls with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameBasis {
    /// Stored segment (`0` pre sentinel, `1..n` real, `n` post sentinel).
    pub segment: usize,
    /// Eased local parameter, kept in f64 for slerp-based rotations.
    pub s: f64,
    /// Value row `[h1 h2 h3 h4]`.
    pub h: [f32; 4],
    /// Derivative row before scaling by `rate`.
    pub dh: [f32; 4],
    /// d/dt = `rate * (dh . controls)`; includes the `oscillate` direction.
    pub rate: f32,
    /// Whole cycles of `offset-repeat` to add, times `P_{n-1} - P_0`.
    pub cycles: f32,
    /// `reset` extrapolation: zero, identity for rotations.
    pub reset: bool,
}

/// Where a group's playback is: the last real segment found. Forward
/// playback finds the next segment in O(1); a seek falls back to binary
/// search.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cursor(usize);

impl TimeGrid {
    /// Number of keys.
    pub fn keys(&self) -> usize {
        self.times.len()
    }

    /// The ease of segment `k`.
    #[inline]
    pub fn ease(&self, k: usize) -> SegmentEase {
        self.eases.get(k).copied().unwrap_or_default()
    }

    /// Whether segment `k` is `step`.
    #[inline]
    pub fn is_step(&self, k: usize) -> bool {
        self.steps.get(k).copied().unwrap_or(false)
    }

    /// The two keys stored segment `seg` reads: `(a, b)` with
    /// `P0 = a.P, M0 = a.TO, P1 = b.P, M1 = b.TI`. A `step` segment is played
    /// at `s = 0` (basis `[1, 0, 0, 0]`), and its `b` is key 0, whose `TI` is
    /// zero: its own key's `TI` belongs to the segment before and may be
    /// infinite, and `0 * inf` would be NaN.
    #[inline]
    pub fn key_pair(&self, seg: usize) -> (usize, usize) {
        let n = self.times.len();
        match seg {
            0 => (n, n + 1),
            s if s == n => (n + 2, n + 3),
            s if self.is_step(s - 1) => (s - 1, 0),
            s => (s - 1, s),
        }
    }

    /// The same grid with `eases` and `steps` emptied where they say nothing.
    pub fn compact(mut self) -> Self {
        if self.eases.iter().all(SegmentEase::is_none) {
            self.eases = Vec::new();
        }
        if !self.steps.contains(&true) {
            self.steps = Vec::new();
        }
        self
    }

    /// Segment k with `times[k] <= time < times[k+1]`: listed times from
    /// the cursor ([`tcb_core::track::segment_from`]), even ones from where
    /// `time` falls (the cursor only records the answer).
    #[inline]
    fn locate(&self, time: f64, cursor: &mut Cursor) -> usize {
        cursor.0 = self.times.locate(time, cursor.0);
        cursor.0
    }

    /// Stored segment, eased `s` and rate (times `dir`) for a `time` inside
    /// the keys (`t_0 <= time < t_{n-1}`). A `step` segment is played at
    /// `s = 0` with rate 0: the basis there is exactly `[1, 0, 0, 0]`, so
    /// the value is its first key exactly (math.md: it "stays P_k"), and
    /// its velocity is zero (its `M0` is zero; [`crate::clip::key_pair`]
    /// gives it a finite `M1`).
    #[inline(always)]
    fn real(&self, time: f64, cursor: &mut Cursor, dir: f32) -> (usize, f64, f32) {
        let k = self.locate(time, cursor);
        let (tk, tk1) = (self.times.at(k), self.times.at(k + 1));
        let d = tk1 - tk;
        let u = ((time - tk) / d).clamp(0.0, 1.0);
        // Most grids ease nowhere (`compact` empties the list): no lookup.
        let (eased, ds_du) = if self.eases.is_empty() {
            (u, 1.0)
        } else {
            self.ease(k).apply(u)
        };
        // Selects, not a branch: almost no grid has step segments.
        let hold = !self.steps.is_empty() && self.is_step(k);
        let (eased, ds_du) = if hold { (0.0, 0.0) } else { (eased, ds_du) };
        (k + 1, eased, (ds_du / d) as f32 * dir)
    }

    /// The basis for `time` (any f64), advancing `cursor`. Out of line: once
    /// a group per frame, and inlined into the caller it takes registers the
    /// kernels' loop needs (+1 instruction per block in `wide`).
    #[inline(never)]
    pub fn frame(&self, time: f64, cursor: &mut Cursor) -> FrameBasis {
        // Hot (once per group per frame), kept whole: the fast path for a
        // time inside the keys returns before the table's rows below.
        let n = self.times.len();
        let (t0, tn) = (self.times.at(0), self.times.at(n - 1));
        // Most frames are inside the keys, where every mode passes the time
        // through (`map_time`'s own first answer): the rows of a real
        // segment, the table below with its other rows known to be off.
        if t0 <= time && time < tn {
            let (segment, s, rate) = self.real(time, cursor, 1.0);
            let (h, dh, rate) = sentinel_rows(
                LaneRows {
                    real: true,
                    line: false,
                    reset: false,
                    hold: false,
                    s: s as f32,
                    rate,
                    dir: 1.0,
                    dt: 0.0,
                },
                true,
            );
            return FrameBasis {
                segment,
                s,
                h,
                dh,
                rate,
                cycles: 0.0,
                reset: false,
            };
        }
        self.frame_outside(time, cursor)
    }

    /// [`frame`](Self::frame) for a time outside the keys (or NaN), out of
    /// line: the registers its table takes would otherwise be saved and
    /// restored on every frame.
    #[cold]
    #[inline(never)]
    fn frame_outside(&self, time: f64, cursor: &mut Cursor) -> FrameBasis {
        let n = self.times.len();
        let (t0, tn) = (self.times.at(0), self.times.at(n - 1));
        // Which row of the table (module docs), and the stored segment.
        let (mut real, mut line, mut reset, mut hold) = (false, false, false, false);
        let (mut s, mut rate, mut dir, mut dt, mut cyc) = (0.0f64, 0.0f32, 1.0f32, 0.0f32, 0.0f32);
        let segment = match map_time(time, t0, tn, self.pre, self.post) {
            Mapped::Inside {
                time,
                direction,
                cycles,
            } => {
                dir = direction as f32;
                cyc = cycles as f32;
                if time >= tn {
                    n
                } else {
                    let segment;
                    (segment, s, rate) = self.real(time, cursor, dir);
                    real = true;
                    segment
                }
            }
            Mapped::Hold { last } => {
                hold = true;
                if last { n } else { 0 }
            }
            Mapped::Reset => {
                reset = true;
                0
            }
            Mapped::Line { last, dt: d } => {
                (line, dt) = (true, d as f32);
                if last { n } else { 0 }
            }
        };
        let (h, dh, rate) = sentinel_rows(
            LaneRows {
                real,
                line,
                reset,
                hold,
                s: s as f32,
                rate,
                dir,
                dt,
            },
            true,
        );
        FrameBasis {
            segment,
            s,
            h,
            dh,
            rate,
            cycles: cyc,
            reset,
        }
    }
}

/// Where each lane of a frame is, for [`sentinel_rows`]: which row of the
/// table in the module docs it takes, and the numbers that row reads.
pub(crate) struct LaneRows<L: Lane> {
    /// Inside a real segment, at `s` (`step` segments at `s = 0`, rate 0).
    pub real: L::Mask,
    /// On a linear extrapolation, `dt` past the end key.
    pub line: L::Mask,
    /// Reset to the identity (or zero).
    pub reset: L::Mask,
    /// Holding an end key.
    pub hold: L::Mask,
    /// The segment parameter of real lanes.
    pub s: L,
    /// ds/dt of real lanes, the direction in it.
    pub rate: L,
    /// The direction of lanes exactly at the last key (`oscillate`'s sign).
    pub dir: L,
    /// Seconds past the end key of `line` lanes.
    pub dt: L,
}

/// The rows of the table in the module docs, for any lane type: lanes in
/// a `real` segment take the basis at `s` (`step` segments come with
/// `s = 0` and rate 0, so they hold their first key) and `rate` (with the
/// direction in it); `line`, `reset` and `hold` lanes their fixed rows; the
/// rest are exactly at the last key (`dir` carries `oscillate`'s sign).
/// The one copy for the per-group frame (`f32`) and the loose lanes
/// (`f32x8`). Without `velocity`, the derivative row is zeros.
#[inline(always)]
pub(crate) fn sentinel_rows<L: Lane>(at: LaneRows<L>, velocity: bool) -> ([L; 4], [L; 4], L) {
    let LaneRows {
        real,
        line,
        reset,
        hold,
        s,
        rate,
        dir,
        dt,
    } = at;
    let (z, o) = (L::of(0.0), L::of(1.0));
    let at_end = !(real | line | reset | hold);
    let hb = hermite_basis(s);
    let db = if velocity {
        hermite_basis_derivative(s)
    } else {
        [z; 4]
    };
    (
        [
            L::select(real, hb[0], L::select(reset, z, o)),
            L::select(real, hb[1], z),
            L::select(real, hb[2], L::select(line, dt, z)),
            L::select(real, hb[3], z),
        ],
        [
            L::select(real, db[0], z),
            L::select(real, db[1], z),
            L::select(real, db[2], L::select(line, o, z)),
            L::select(real, db[3], L::select(at_end, o, z)),
        ],
        L::select(real, rate, L::select(line, o, L::select(at_end, dir, z))),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(pre: Extrapolation, post: Extrapolation) -> TimeGrid {
        TimeGrid {
            times: KeyTimes::Listed(vec![0.0, 1.0, 3.0, 4.0]),
            eases: vec![SegmentEase::default(); 3],
            steps: vec![false; 3],
            pre,
            post,
        }
    }

    #[test]
    fn cursor_moves_forward_and_seeks() {
        let g = grid(Extrapolation::Constant, Extrapolation::Constant);
        let mut c = Cursor::default();
        assert_eq!(g.frame(0.5, &mut c).segment, 1);
        assert_eq!(g.frame(1.5, &mut c).segment, 2);
        assert_eq!(c, Cursor(1));
        assert_eq!(g.frame(3.5, &mut c).segment, 3);
        assert_eq!(g.frame(0.2, &mut c).segment, 1);
        assert_eq!(g.frame(3.9, &mut c).segment, 3);
        assert_eq!(g.frame(1.0, &mut c).segment, 2);
    }

    /// An even grid finds the segment the list of its times gives, at and
    /// one ulp either side of every key, between keys and outside them,
    /// where its times round unevenly (far from 0) too.
    #[test]
    fn even_times_locate_as_their_list() {
        for (start, interval, keys) in [
            (0.0, 1.0 / 120.0, 50),
            (1e6, 1.0 / 30.0, 40),
            (-3.5, 0.1, 7),
            (5.0, 0.25, 2),
            // 1 / interval overflows to infinity.
            (0.0, 5e-324, 3),
            (-1e308, 1e308, 3),
            // Times that cross powers of two, where the sums round unevenly.
            (1024.0 - 1e-10, 0.1, 50),
        ] {
            let even = KeyTimes::even(start, interval, keys);
            let listed = KeyTimes::Listed(even.to_vec());
            let mut probes = vec![f64::NAN, f64::NEG_INFINITY, f64::INFINITY, start - 1.0];
            for k in 0..keys {
                let t = even.at(k);
                probes.extend([t, t.next_up(), t.next_down(), t + 0.37 * interval]);
            }
            for t in probes {
                for hint in [0, keys / 2, keys] {
                    assert_eq!(
                        even.locate(t, hint),
                        listed.locate(t, hint),
                        "{t} from {start}"
                    );
                }
            }
        }
    }

    /// A list of `k * dt` (a BVH's frames) becomes an even grid with the
    /// same times; lists that are not that bit for bit stay lists.
    #[test]
    fn even_lists_become_even_grids() {
        let bvh: Vec<f64> = (0..2752).map(|k| k as f64 * 0.008333).collect();
        let even = KeyTimes::from_times(bvh.clone());
        assert!(matches!(even, KeyTimes::Even { keys: 2752, .. }));
        assert_eq!(even.to_vec(), bvh);
        assert_eq!(even.heap_bytes(), 0);
        let mut off = bvh.clone();
        off[2000] = off[2000].next_up();
        let uneven = [
            off,
            vec![0.0, 1.0, 3.0],
            vec![0.0, 0.1, 0.2, 0.30000000000000004 + 1e-12],
        ];
        for t in uneven {
            assert_eq!(KeyTimes::from_times(t.clone()), KeyTimes::Listed(t));
        }
        assert!(matches!(
            KeyTimes::from_times(vec![2.0, 2.5]),
            KeyTimes::Even { keys: 2, .. }
        ));
    }

    #[test]
    fn sentinels() {
        let g = grid(Extrapolation::Linear, Extrapolation::Constant);
        let mut c = Cursor::default();
        let f = g.frame(4.0, &mut c);
        assert_eq!(
            (f.segment, f.h, f.dh, f.rate),
            (4, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], 1.0)
        );
        let f = g.frame(9.0, &mut c);
        assert_eq!((f.segment, f.rate), (4, 0.0));
        let f = g.frame(-2.0, &mut c);
        assert_eq!(
            (f.segment, f.h, f.dh),
            (0, [1.0, 0.0, -2.0, 0.0], [0.0, 0.0, 1.0, 0.0])
        );
        let g = grid(Extrapolation::Reset, Extrapolation::Oscillate);
        let f = g.frame(-1.0, &mut c);
        assert!(f.reset && f.h == [0.0; 4]);
        let f = g.frame(4.5, &mut c);
        assert_eq!((f.segment, f.rate), (3, -1.0));
    }
}
