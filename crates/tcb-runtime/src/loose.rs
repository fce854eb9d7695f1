//! Tracks on key grids of their own ("loose" tracks), eight at a time.
//!
//! A group of a few channels cannot share its per-frame basis with anyone,
//! and computing a [`FrameBasis`](crate::grid::FrameBasis) per group costs
//! more than evaluating its channels. So vector tracks of small groups are
//! packed one track per lane, eight per block, components as x/y/z/w planes,
//! and everything per frame is done across lanes:
//!
//! 1. `map_time` for eight grids at once in `f64x4` (pre/post per lane,
//!    wrap in f64, selects instead of branches);
//! 2. each lane keeps a window `[ws, we)` of the stored segment it last
//!    used and that segment's controls (in the [`crate::Instance`], so they
//!    stay contiguous and cached, as ozz-animation does); a lane whose mapped
//!    time left its window is refreshed, scalar, only when it crosses a key;
//! 3. `u`, ease, and the Hermite rows per lane, then the same
//!    [`tcb_core::basis::hermite`] on `f32x8` as every other kernel.
//!
//! The stored segments and sentinel rows are those of [`crate::grid`]; the
//! time mapping is [`tcb_core::extrapolate::map_lanes`], the reference's own.

use crate::clip::{key_pair, per_key};
use crate::grid::{TimeGrid, sentinel_rows};
use crate::kernel::KEY_STRIDE;
use tcb_core::Extrapolation;
use tcb_core::basis::{hermite, hermite_basis, hermite_basis_derivative};
use tcb_core::ease::ease;
use tcb_core::extrapolate::{ModeLanes, map_lanes};
use tcb_core::track::segment_from;
use wide::{f32x8, f64x4};

/// Controls per block: 4 component planes x `[P0, P1, M0, M1]`.
const CTL: usize = 16;

/// Padding lanes: keys at -PAD_SPAN and +PAD_SPAN (finite, so u stays finite),
/// zero controls.
const PAD_SPAN: f64 = 1e300;

/// One loose track.
#[derive(Clone, Debug)]
pub(crate) struct LooseLane {
    pub grid: TimeGrid,
    /// Components used (1 to 4).
    pub dim: usize,
    /// Per key (and sentinel pseudo-key, see `clip::per_key`), per
    /// component: `[P, TO, TI]`, at `key(key * dim + c)`.
    keys: Keys,
}

/// A loose lane's keys, in f32 or in 16 bits with a range per component
/// and control (see [`crate::quant`]; expanded only when a lane crosses a key).
#[derive(Clone, Debug)]
enum Keys {
    F32(Vec<[f32; KEY_STRIDE]>),
    U16 {
        q: Vec<[u16; KEY_STRIDE]>,
        min: Vec<[f32; KEY_STRIDE]>,
        scale: Vec<[f32; KEY_STRIDE]>,
    },
}

impl LooseLane {
    /// A lane on `grid` from its components' controls per stored segment
    /// (`[P0, P1, M0, M1]` each, as `clip.rs` builds them for every track),
    /// stored per key.
    pub fn new(grid: TimeGrid, comps: &[&Vec<[f32; 4]>]) -> Self {
        let per: Vec<Vec<[f32; KEY_STRIDE]>> = comps.iter().map(|r| per_key(r)).collect();
        let dim = comps.len();
        let keys = (0..per[0].len() * dim)
            .map(|i| per[i % dim][i / dim])
            .collect();
        LooseLane {
            grid,
            dim,
            keys: Keys::F32(keys),
        }
    }

    /// Entry `i` (`key * dim + c`) of the keys.
    #[inline]
    pub fn key(&self, i: usize) -> [f32; KEY_STRIDE] {
        match &self.keys {
            Keys::F32(k) => k[i],
            Keys::U16 { q, min, scale } => {
                let c = i % self.dim;
                std::array::from_fn(|j| min[c][j] + f32::from(q[i][j]) * scale[c][j])
            }
        }
    }

    /// Heap bytes of the keys.
    fn key_bytes(&self) -> usize {
        use std::mem::size_of_val;
        match &self.keys {
            Keys::F32(k) => size_of_val(k.as_slice()),
            Keys::U16 { q, min, scale } => {
                size_of_val(q.as_slice())
                    + size_of_val(min.as_slice())
                    + size_of_val(scale.as_slice())
            }
        }
    }

    /// Store the keys in 16 bits (as [`crate::quant`] does for groups) and
    /// return, per component, the largest error made on `[P, TO, TI]`.
    pub fn quantize(&mut self) -> Vec<[f32; KEY_STRIDE]> {
        let Keys::F32(keys) = &self.keys else {
            return vec![[0.0; KEY_STRIDE]; self.dim];
        };
        let dim = self.dim;
        let mut min = vec![[f32::INFINITY; KEY_STRIDE]; dim];
        let mut max = vec![[f32::NEG_INFINITY; KEY_STRIDE]; dim];
        for (i, k) in keys.iter().enumerate() {
            for j in 0..KEY_STRIDE {
                min[i % dim][j] = min[i % dim][j].min(k[j]);
                max[i % dim][j] = max[i % dim][j].max(k[j]);
            }
        }
        let scale: Vec<[f32; KEY_STRIDE]> = (0..dim)
            .map(|c| std::array::from_fn(|j| (max[c][j] - min[c][j]) / 65535.0))
            .collect();
        let mut error = vec![[0.0f32; KEY_STRIDE]; dim];
        let q = keys
            .iter()
            .enumerate()
            .map(|(i, k)| {
                let c = i % dim;
                std::array::from_fn(|j| {
                    let (lo, s) = (min[c][j], scale[c][j]);
                    let q = if s > 0.0 {
                        ((k[j] - lo) / s).round().clamp(0.0, 65535.0) as u16
                    } else {
                        0
                    };
                    let e = &mut error[c][j];
                    *e = e.max((lo + f32::from(q) * s - k[j]).abs());
                    q
                })
            })
            .collect();
        self.keys = Keys::U16 { q, min, scale };
        error
    }

    /// `[P0, P1, M0, M1]` of every component on stored segment `seg`
    /// (components past `dim` zero).
    #[inline]
    fn segment(&self, seg: usize) -> [[f32; 4]; 4] {
        let (ka, kb) = key_pair(&self.grid, seg);
        let n = self.grid.times.len();
        // A step segment reads its first key twice; that key's TI belongs
        // to the segment before.
        let step = (1..n).contains(&seg) && self.grid.is_step(seg - 1);
        std::array::from_fn(|c| {
            if c < self.dim {
                let (a, b) = (self.key(ka * self.dim + c), self.key(kb * self.dim + c));
                [a[0], b[0], a[1], if step { 0.0 } else { b[2] }]
            } else {
                [0.0; 4]
            }
        })
    }
}

/// The loose tracks of a clip and their per-lane constants.
#[derive(Clone, Debug, Default)]
pub(crate) struct Loose {
    pub lanes: Vec<LooseLane>,
    pub blocks: usize,
    /// First pose block (4 planes per block).
    pub out: usize,
    /// Per half block (4 lanes): first key, last key, pre and post modes.
    t0: Vec<f64x4>,
    tn: Vec<f64x4>,
    pre: Vec<ModeLanes<f64x4>>,
    post: Vec<ModeLanes<f64x4>>,
    /// `P_{n-1} - P_0` per block and component plane (offset-repeat).
    delta: Vec<f32x8>,
    /// Whether any lane of a block has an eased segment.
    eased: Vec<bool>,
    /// Component planes in use per block (the widest track's dimension).
    dims: Vec<usize>,
}

impl Loose {
    /// Heap bytes: the lanes (grids and controls) and the per-block tables.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::{size_of, size_of_val};
        let lanes: usize = self
            .lanes
            .iter()
            .map(|l| {
                size_of::<LooseLane>()
                    + size_of_val(l.grid.times.as_slice())
                    + size_of_val(l.grid.eases.as_slice())
                    + size_of_val(l.grid.steps.as_slice())
                    + l.key_bytes()
            })
            .sum();
        lanes
            + size_of_val(self.t0.as_slice())
            + size_of_val(self.tn.as_slice())
            + size_of_val(self.pre.as_slice())
            + size_of_val(self.post.as_slice())
            + size_of_val(self.delta.as_slice())
            + size_of_val(self.eased.as_slice())
            + size_of_val(self.dims.as_slice())
    }

    pub fn new(lanes: Vec<LooseLane>, out: usize) -> Self {
        let blocks = lanes.len().div_ceil(8);
        let lane = |i: usize| lanes.get(i);
        let half = |f: &dyn Fn(&LooseLane) -> f64, pad: f64| -> Vec<f64x4> {
            (0..2 * blocks)
                .map(|h| f64x4::new(std::array::from_fn(|l| lane(4 * h + l).map_or(pad, f))))
                .collect()
        };
        let t0 = half(&|l| l.grid.times[0], 0.0);
        let tn = half(&|l| l.grid.times[l.grid.times.len() - 1], 1.0);
        let modes = |f: fn(&LooseLane) -> Extrapolation| -> Vec<ModeLanes<f64x4>> {
            (0..2 * blocks)
                .map(|h| {
                    let m =
                        std::array::from_fn(|l| lane(4 * h + l).map_or(Extrapolation::Constant, f));
                    ModeLanes::from_lanes(m, |b: [bool; 4]| {
                        f64x4::new(b.map(|x| f64::from_bits(if x { u64::MAX } else { 0 })))
                    })
                })
                .collect()
        };
        let pre = modes(|l| l.grid.pre);
        let post = modes(|l| l.grid.post);
        let mut delta = vec![f32x8::ZERO; 4 * blocks];
        for b in 0..blocks {
            for c in 0..4 {
                delta[4 * b + c] = f32x8::new(std::array::from_fn(|l| {
                    lane(8 * b + l).map_or(0.0, |x| {
                        if c >= x.dim {
                            return 0.0;
                        }
                        let n = x.grid.times.len();
                        x.key((n - 1) * x.dim + c)[0] - x.key(c)[0]
                    })
                }));
            }
        }
        let eased = (0..blocks)
            .map(|b| {
                (8 * b..8 * b + 8)
                    .filter_map(lane)
                    .any(|l| l.grid.eases.iter().any(|e| !e.is_none()))
            })
            .collect();
        let dims = (0..blocks)
            .map(|b| {
                (8 * b..8 * b + 8)
                    .filter_map(lane)
                    .map(|l| l.dim)
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        Loose {
            dims,
            eased,
            lanes,
            blocks,
            out,
            t0,
            tn,
            pre,
            post,
            delta,
        }
    }
}

/// Per-instance state of the loose tracks: each lane's window, ease and
/// controls, written lane by lane only when a lane crosses a key and read
/// four lanes at a time.
#[derive(Clone, Debug)]
pub(crate) struct LooseState {
    /// Per half block (4 lanes): window start and end, ease from and to.
    ws: Vec<f64x4>,
    we: Vec<f64x4>,
    ease_from: Vec<f64x4>,
    ease_to: Vec<f64x4>,
    seg: Vec<usize>,
    ctl: Vec<f32x8>,
}

/// Set lane `l` of half blocks `v`.
#[inline(always)]
fn set_lane(v: &mut [f64x4], l: usize, x: f64) {
    bytemuck::cast_slice_mut::<f64x4, f64>(v)[l] = x;
}

impl LooseState {
    pub fn new(loose: &Loose) -> Self {
        let lanes = loose.blocks * 8;
        // Real lanes start with an empty window (refreshed on first use);
        // padding lanes with one spanning all time and zero controls.
        let real = loose.lanes.len();
        let fill = |inside: f64, pad: f64| -> Vec<f64x4> {
            (0..lanes / 4)
                .map(|h| {
                    f64x4::new(std::array::from_fn(|i| {
                        if 4 * h + i < real { inside } else { pad }
                    }))
                })
                .collect()
        };
        LooseState {
            ws: fill(f64::INFINITY, -PAD_SPAN),
            we: fill(f64::NEG_INFINITY, PAD_SPAN),
            ease_from: vec![f64x4::ZERO; lanes / 4],
            ease_to: vec![f64x4::ZERO; lanes / 4],
            seg: vec![usize::MAX; lanes],
            ctl: vec![f32x8::ZERO; loose.blocks * CTL],
        }
    }

    /// Load stored segment `seg` of lane `l` into its window, ease and controls.
    fn load(&mut self, loose: &Loose, l: usize, seg: usize) {
        let lane = &loose.lanes[l];
        let t = &lane.grid.times;
        let n = t.len();
        let (ws, we) = match seg {
            0 => (f64::NEG_INFINITY, t[0]),
            s if s == n => (t[n - 1], f64::INFINITY),
            s => (t[s - 1], t[s]),
        };
        let ease = if (1..n).contains(&seg) {
            lane.grid.ease(seg - 1)
        } else {
            Default::default()
        };
        set_lane(&mut self.ws, l, ws);
        set_lane(&mut self.we, l, we);
        set_lane(&mut self.ease_from, l, ease.from);
        set_lane(&mut self.ease_to, l, ease.to);
        self.seg[l] = seg;
        let (b, i) = (l / 8, l % 8);
        let ctl: &mut [f32] = bytemuck::cast_slice_mut(&mut self.ctl[b * CTL..(b + 1) * CTL]);
        let src = lane.segment(seg);
        // Only the components the track has (the rest stay zero).
        for (c, src) in src.iter().enumerate().take(lane.dim) {
            for j in 0..4 {
                ctl[(4 * c + j) * 8 + i] = src[j];
            }
        }
    }

    /// The stored segment for mapped time `tm` (within the keys, or the
    /// sentinels beyond them); the one after `current` first, as forward
    /// playback wants.
    fn segment_for(lane: &LooseLane, current: usize, tm: f64) -> usize {
        let t = &lane.grid.times;
        let n = t.len();
        if tm < t[0] {
            0
        } else if tm >= t[n - 1] {
            n
        } else {
            segment_from(t, tm, current.wrapping_sub(1)) + 1
        }
    }
}

/// The derivative rows, only when velocities are wanted.
#[inline(always)]
fn derivative_rows(s: f32x8, velocity: bool) -> [f32x8; 4] {
    if velocity {
        hermite_basis_derivative(s)
    } else {
        [f32x8::ZERO; 4]
    }
}

/// Rows of one block, per lane.
struct Rows {
    h: [f32x8; 4],
    dh: [f32x8; 4],
    rate: f32x8,
    cycles: f32x8,
    any_cycles: bool,
}

#[inline(always)]
fn f32x8_of(a: f64x4, b: f64x4) -> f32x8 {
    let (a, b) = (a.to_array(), b.to_array());
    f32x8::new(std::array::from_fn(|i| {
        if i < 4 { a[i] as f32 } else { b[i - 4] as f32 }
    }))
}

fn mask_of(a: f64x4, b: f64x4) -> f32x8 {
    let bits = a.to_bitmask() | (b.to_bitmask() << 4);
    f32x8::new(std::array::from_fn(|i| {
        f32::from_bits(if bits >> i & 1 == 1 { u32::MAX } else { 0 })
    }))
}

/// Refresh the lanes of half block `i` whose window does not hold `tm`
/// (forward playback: a lane at a time, when it crosses a key).
#[inline(always)]
fn refresh(loose: &Loose, st: &mut LooseState, i: usize, tm: f64x4) {
    let ok = st.ws[i].simd_le(tm) & tm.simd_lt(st.we[i]);
    let stale = !ok.to_bitmask() & 0xf;
    if stale != 0 {
        load_stale(loose, st, i, tm, stale);
    }
}

/// Load the lanes of half block `i` set in `stale` (out of line: most
/// frames cross no key).
#[inline(never)]
fn load_stale(loose: &Loose, st: &mut LooseState, i: usize, tm: f64x4, mut stale: u32) {
    while stale != 0 {
        let k = stale.trailing_zeros() as usize;
        stale &= stale - 1;
        let l = 4 * i + k;
        if l < loose.lanes.len() {
            let seg = LooseState::segment_for(&loose.lanes[l], st.seg[l], tm.to_array()[k]);
            st.load(loose, l, seg);
        }
    }
}

/// Rows for block `b` when every lane is inside its keys, `t_0 <= time < t_{n-1}`:
/// no extrapolation and no sentinel, just `u`, ease and the basis.
#[inline(always)]
fn rows_inside(loose: &Loose, st: &mut LooseState, b: usize, t: f64x4, velocity: bool) -> Rows {
    let one = f64x4::ONE;
    let mut s = [f64x4::ZERO; 2];
    let mut rate = [f64x4::ZERO; 2];
    for h in 0..2 {
        let i = 2 * b + h;
        refresh(loose, st, i, t);
        let (ws, we) = (st.ws[i], st.we[i]);
        let d = we - ws;
        let u = ((t - ws) / d).max(f64x4::ZERO).min(one);
        let (ss, dsdu) = if loose.eased[b] {
            ease(u, st.ease_from[i], st.ease_to[i])
        } else {
            (u, one)
        };
        s[h] = ss;
        rate[h] = dsdu / d;
    }
    let s32 = f32x8_of(s[0], s[1]);
    Rows {
        h: hermite_basis(s32),
        dh: derivative_rows(s32, velocity),
        rate: f32x8_of(rate[0], rate[1]),
        cycles: f32x8::ZERO,
        any_cycles: false,
    }
}

/// Rows for block `b` at `time` (any f64), refreshing lanes that left their window.
#[inline(always)]
fn rows_simd(loose: &Loose, st: &mut LooseState, b: usize, time: f64, velocity: bool) -> Rows {
    let t = f64x4::splat(time);
    let inside = |i: usize| (t.simd_ge(loose.t0[i]) & t.simd_lt(loose.tn[i])).all();
    if inside(2 * b) && inside(2 * b + 1) {
        return rows_inside(loose, st, b, t, velocity);
    }
    let zero = f64x4::ZERO;
    let one = f64x4::ONE;
    let mut out_tm = [zero; 2];
    let (mut line, mut reset, mut hold) = ([zero; 2], [zero; 2], [zero; 2]);
    let mut dir = [one; 2];
    let mut cycles = [zero; 2];
    let mut dt = [zero; 2];
    for h in 0..2 {
        let i = 2 * b + h;
        let m = map_lanes(t, loose.t0[i], loose.tn[i], &loose.pre[i], &loose.post[i]);
        // Lanes outside the keys read a sentinel: 0 before, n after.
        let beyond = m
            .last
            .select(f64x4::splat(f64::MAX), f64x4::splat(-f64::MAX));
        out_tm[h] = m.inside.select(m.time, beyond);
        dir[h] = m.direction;
        cycles[h] = m.cycles;
        dt[h] = m.dt;
        line[h] = m.line;
        reset[h] = m.reset;
        hold[h] = m.hold;
    }
    for (h, &tm) in out_tm.iter().enumerate() {
        refresh(loose, st, 2 * b + h, tm);
    }
    // u, ease, rates per lane (f64), for lanes in real segments.
    let mut s = [zero; 2];
    let mut rate = [zero; 2];
    let mut real = [zero; 2];
    for h in 0..2 {
        let i = 2 * b + h;
        let (ws, we) = (st.ws[i], st.we[i]);
        let is_real =
            ws.simd_gt(f64x4::splat(f64::NEG_INFINITY)) & we.simd_lt(f64x4::splat(f64::INFINITY));
        let d = is_real.select(we - ws, one);
        let u = is_real.select(((out_tm[h] - ws) / d).max(zero).min(one), zero);
        let (a, e) = (st.ease_from[i], st.ease_to[i]);
        let (ss, dsdu) = if loose.eased[b] {
            ease(u, a, e)
        } else {
            (u, one)
        };
        s[h] = ss;
        rate[h] = dsdu / d * dir[h];
        real[h] = is_real;
    }
    let realm = mask_of(real[0], real[1]);
    let line = mask_of(line[0], line[1]);
    let reset = mask_of(reset[0], reset[1]);
    let hold = mask_of(hold[0], hold[1]);
    let s32 = f32x8_of(s[0], s[1]);
    let dirs = f32x8_of(dir[0], dir[1]);
    let cyc = f32x8_of(cycles[0], cycles[1]);
    let (h, dh, rate) = sentinel_rows(
        realm,
        line,
        reset,
        hold,
        f32x8::ZERO, // step segments: M1 is zero in the lane's cached controls
        s32,
        f32x8_of(rate[0], rate[1]),
        dirs,
        f32x8_of(dt[0], dt[1]),
        velocity,
    );
    Rows {
        h,
        dh,
        rate,
        any_cycles: cyc.simd_ne(f32x8::ZERO).any(),
        cycles: cyc,
    }
}

/// Sample every loose track at `time` into its pose planes.
pub(crate) fn sample(
    loose: &Loose,
    st: &mut LooseState,
    time: f64,
    values: &mut [f32x8],
    mut velocities: Option<&mut [f32x8]>,
) {
    for b in 0..loose.blocks {
        let rows = rows_simd(loose, st, b, time, velocities.is_some());
        let ctl = &st.ctl[b * CTL..(b + 1) * CTL];
        let out = loose.out + 4 * b;
        for c in 0..loose.dims[b] {
            let k = &ctl[4 * c..4 * c + 4];
            let mut v = hermite(&rows.h, k[0], k[1], k[2], k[3]);
            if rows.any_cycles {
                v += loose.delta[4 * b + c] * rows.cycles;
            }
            values[out + c] = v;
            if let Some(vel) = velocities.as_deref_mut() {
                vel[out + c] = hermite(&rows.dh, k[0], k[1], k[2], k[3]) * rows.rate;
            }
        }
    }
}
