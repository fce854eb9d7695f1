//! Tracks on key grids of their own ("loose" tracks), eight at a time.
//!
//! A group of a few channels cannot share its per-frame basis with anyone,
//! and computing a [`FrameBasis`](crate::grid::FrameBasis) per group costs
//! more than evaluating its channels. So vector tracks of small groups are
//! packed one track per lane, eight per block, components as x/y/z/w planes,
//! and everything per frame is done across lanes:
//!
//! 1. Each lane's current segment (window `[ws, we)`, width, ease and
//!    controls) lives in the [`crate::Instance`], packed per block, as
//!    ozz-animation's sampling context does. Forward playback keeps it
//!    current from one list of every `(lane, segment)` in the order playback
//!    needs them (segment k+1 at key time `t_k`, Riot's "keys sorted by the
//!    time they are needed"): a frame loads exactly the segments whose key
//!    it passed, and nothing else. Going back in time, or jumping further
//!    forward than a few keys per lane, is a seek: each lane finds its
//!    segment by binary search.
//! 2. A block whose eight lanes are all inside their keys (most frames)
//!    then needs nothing but `u = (t - ws) / D`, the ease if any lane eases,
//!    and the Hermite rows per lane: no window test, no time mapping.
//! 3. Other blocks run [`tcb_core::simd::extrapolate::map_lanes`] across eight
//!    grids in `f64x4` (pre/post per lane, wrap in f64, selects instead of
//!    branches), reload lanes whose mapped time left their window, and take
//!    the sentinel rows of [`crate::grid::sentinel_rows`].
//!
//! The rows are evaluated by the same [`tcb_core::simd::basis::hermite`] on
//! `f32x8` as every other kernel, from the same f64 `u` as the reference,
//! so the values are the reference's bit for bit. Where `crate::isa` runs
//! the AVX2 instance, blocks inside their keys compute `u`, the ease and
//! the rows on `W8` and `D4`, and every rotation block is normalized on
//! `W8` (one AVX instruction where `wide` runs two SSE2 halves): the same
//! operations, the same bits.
use crate::grid::{LaneRows, TimeGrid, sentinel_rows};
use crate::store::{KEY_STRIDE, per_key};
use tcb_core::Extrapolation;
use tcb_core::ease::{SegmentEase, ease};
use tcb_core::simd::basis::{hermite, hermite_basis, hermite_basis_derivative};
use tcb_core::simd::extrapolate::{ModeLanes, hold_lanes, map_lanes};
use tcb_core::simd::lane::{Lane, Mask};
use tcb_core::track::segment_from;
use wide::{f32x8, f64x4};

/// Padding lanes: a window from -PAD_SPAN to +PAD_SPAN (finite, so u stays
/// finite), zero controls; padding rotations are lanes keyed there. Key
/// times may lie beyond it (up to f64::MAX); there a padding lane's u leaves
/// [0, 1] and its value is whatever the cubic gives, in lanes no accessor,
/// row or blend result reads (a fuzz finding: the window check asserted
/// padding lanes too).
pub(crate) const PAD_SPAN: f64 = 1e300;

/// One loose track.
#[derive(Clone, Debug)]
pub(crate) struct LooseLane {
    /// Per key (and sentinel pseudo-key, see `store::per_key`), per
    /// component: `[P, TO, TI]`, at `key(key * dim + c)`.
    keys: Keys,
    /// Where lane 0 of its first control plane is in the instance's
    /// controls, as f32s (set by [`Loose::new`]).
    ctl_at: u32,
    /// The number of components (1 to 4) where no segment eases or steps
    /// and the keys are f32, so that a real segment loads as
    /// [`LooseState::load_plain`] does; 0 otherwise (set by
    /// [`Loose::new`]). Derivable, but kept: one byte read instead of
    /// three tests per load.
    plain: u8,
    pub grid: TimeGrid,
    /// Components used (1 to 4): a byte, so that the lane stays 128 bytes
    /// wide (a shift per entry of `Loose::order` where 136 takes two
    /// instructions).
    dim: u8,
}

// The stream indexes lanes by a shift (see `LooseLane::dim`).
#[cfg(target_pointer_width = "64")]
const _: () = assert!(std::mem::size_of::<LooseLane>() == 128);

/// A loose lane's keys, in f32 or in 16 bits with a range per component
/// and control (see `crate::quant`; expanded only when a lane crosses a key).
#[derive(Clone, Debug)]
enum Keys {
    F32(Vec<[f32; KEY_STRIDE]>),
    /// Boxed, so that the enum is one `Vec` wide and the lane's hot fields
    /// share a cache line.
    U16(Box<U16Keys>),
}

/// 16-bit keys and their range per component and control.
#[derive(Clone, Debug)]
struct U16Keys {
    q: Vec<[u16; KEY_STRIDE]>,
    min: Vec<[f32; KEY_STRIDE]>,
    scale: Vec<[f32; KEY_STRIDE]>,
}

impl LooseLane {
    /// A lane on `grid` from its components' controls per stored segment
    /// (`[P0, P1, M0, M1]` each, as `crate::compile` builds them for every track),
    /// stored per key.
    pub fn new(grid: TimeGrid, comps: &[&Vec<[f32; 4]>]) -> Self {
        let per: Vec<Vec<[f32; KEY_STRIDE]>> = comps.iter().map(|r| per_key(r)).collect();
        let dim = comps.len();
        let keys = (0..per[0].len() * dim)
            .map(|i| per[i % dim][i / dim])
            .collect();
        LooseLane {
            keys: Keys::F32(keys),
            ctl_at: 0,
            plain: 0,
            grid,
            dim: u8::try_from(dim).expect("1 to 4 components"),
        }
    }

    /// Components used (1 to 4).
    #[inline(always)]
    pub fn dim(&self) -> usize {
        usize::from(self.dim)
    }

    /// Entry `i` (`key * dim + c`) of the keys.
    #[inline]
    pub fn key(&self, i: usize) -> [f32; KEY_STRIDE] {
        match &self.keys {
            Keys::F32(k) => k[i],
            Keys::U16(u) => {
                let U16Keys { q, min, scale } = &**u;
                let c = i % self.dim();
                std::array::from_fn(|j| {
                    crate::quant::dequantize16(min[c][j], f32::from(q[i][j]), scale[c][j])
                })
            }
        }
    }

    /// Heap bytes of the keys.
    fn key_bytes(&self) -> usize {
        use std::mem::size_of_val;
        match &self.keys {
            Keys::F32(k) => size_of_val(k.as_slice()),
            Keys::U16(u) => {
                size_of::<U16Keys>()
                    + size_of_val(u.q.as_slice())
                    + size_of_val(u.min.as_slice())
                    + size_of_val(u.scale.as_slice())
            }
        }
    }

    /// Store the keys in 16 bits (as `crate::quant` does for groups) and
    /// return, per component, the largest error made on `[P, TO, TI]`; or,
    /// where a range or an error is not finite (values or tangents beyond
    /// f32), keep them in f32 and return `None`.
    pub fn quantize(&mut self) -> Option<Vec<[f32; KEY_STRIDE]>> {
        let Keys::F32(keys) = &self.keys else {
            return Some(vec![[0.0; KEY_STRIDE]; self.dim()]);
        };
        let dim = self.dim();
        let mut min = vec![[f32::INFINITY; KEY_STRIDE]; dim];
        let mut max = vec![[f32::NEG_INFINITY; KEY_STRIDE]; dim];
        for (i, k) in keys.iter().enumerate() {
            for j in 0..KEY_STRIDE {
                min[i % dim][j] = min[i % dim][j].min(k[j]);
                max[i % dim][j] = max[i % dim][j].max(k[j]);
            }
        }
        let scale: Vec<[f32; KEY_STRIDE]> = (0..dim)
            .map(|c| std::array::from_fn(|j| crate::quant::step_of(min[c][j], max[c][j])))
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
                    let back = crate::quant::dequantize16(lo, f32::from(q), s);
                    *e = crate::quant::worse(*e, (back - k[j]).abs());
                    q
                })
            })
            .collect();
        let finite = |v: &[[f32; KEY_STRIDE]]| v.iter().flatten().all(|x| x.is_finite());
        if !(finite(&min) && finite(&scale) && finite(&error)) {
            return None;
        }
        self.keys = Keys::U16(Box::new(U16Keys { q, min, scale }));
        Some(error)
    }

    /// `[P0, P1, M0, M1]` of each component from keys `ka` and `kb` (see
    /// `TimeGrid::key_pair`) into the lane's planes of the instance's controls
    /// (`ctl`, as f32s; see [`put_controls`]).
    #[inline(always)]
    fn segment(&self, ka: usize, kb: usize, ctl: &mut [f32]) {
        // One copy per dimension, so that each is straight-line code.
        match self.dim() {
            1 => self.segment_of::<1>(ka, kb, ctl),
            2 => self.segment_of::<2>(ka, kb, ctl),
            3 => self.segment_of::<3>(ka, kb, ctl),
            _ => self.segment_of::<4>(ka, kb, ctl),
        }
    }

    #[inline(always)]
    fn segment_of<const N: usize>(&self, ka: usize, kb: usize, ctl: &mut [f32]) {
        let (a, b): ([[f32; KEY_STRIDE]; N], [[f32; KEY_STRIDE]; N]) = match &self.keys {
            Keys::F32(k) => (
                k[ka * N..][..N].try_into().expect("N components"),
                k[kb * N..][..N].try_into().expect("N components"),
            ),
            Keys::U16(_) => (
                std::array::from_fn(|c| self.key(ka * N + c)),
                std::array::from_fn(|c| self.key(kb * N + c)),
            ),
        };
        put_controls(&mut ctl[self.ctl_at as usize..], a, b);
    }
}

/// A segment's controls from its keys `a` and `b` (`[P, TO, TI]` per
/// component) into one lane's planes: component `c`'s `[P0, P1, M0, M1]` at
/// `32 c + 8 p` from the start of `out` (planes of 8 lanes, as f32s).
#[inline(always)]
fn put_controls<const N: usize>(
    out: &mut [f32],
    a: [[f32; KEY_STRIDE]; N],
    b: [[f32; KEY_STRIDE]; N],
) {
    let out = &mut out[..32 * N - 7];
    for c in 0..N {
        out[32 * c] = a[c][0];
        out[32 * c + 8] = b[c][0];
        out[32 * c + 16] = a[c][1];
        out[32 * c + 24] = b[c][2];
    }
}

/// The loose tracks of a clip and their per-lane constants.
#[derive(Clone, Debug, Default)]
pub(crate) struct Loose {
    pub lanes: Vec<LooseLane>,
    /// Whether any block stores a non-finite control (`Block::unbounded`).
    unbounded: bool,
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
    /// What each frame reads of a block.
    block: Vec<Block>,
    /// The instance's controls: planes in all.
    ctl_planes: usize,
    /// Every `(lane, stored segment)` in the order forward playback needs
    /// them: segment `k + 1` (the post sentinel for the last key) at key
    /// time `t_k`, ordered by that time.
    order: Vec<[u32; 2]>,
    /// A forward step longer than this seeks rather than streams: the
    /// span in which forward playback passes, on average, twice as many
    /// entries of `order` as there are lanes, plus 64 (a seek loads each
    /// lane once; streaming that far would cost more).
    seek_after: f64,
}

/// The constants of one block of 8 loose lanes that every frame reads.
#[derive(Clone, Debug)]
struct Block {
    /// The latest first key and the earliest last key of its lanes: at
    /// times between them every lane is inside its keys.
    inner: [f64; 2],
    /// Whether any lane has an eased segment.
    eased: bool,
    /// Whether every lane's `pre` and `post` are `constant`: outside its
    /// keys a lane then holds an end key ([`hold_lanes`]).
    hold: bool,
    /// Whether any lane stores a non-finite control (a tangent that
    /// overflowed f32): at a segment's end its value is then selected, not
    /// summed (`0 x inf`).
    unbounded: bool,
    /// Its planes in the instance's controls (`[P0, P1, M0, M1]` per
    /// component in use, the widest track's dimension).
    ctl: std::ops::Range<usize>,
}

/// Lane or segment index as stored in [`Loose::order`] and
/// `LooseState::seg`.
fn index_u32(i: usize) -> u32 {
    u32::try_from(i).expect("fewer than 2^32 loose lanes and keys")
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
                    + l.grid.times.heap_bytes()
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
            + size_of_val(self.block.as_slice())
            + size_of_val(self.order.as_slice())
    }

    pub fn new(mut lanes: Vec<LooseLane>, out: usize) -> Self {
        let blocks = lanes.len().div_ceil(8);
        let lane = |i: usize| lanes.get(i);
        let half = |f: &dyn Fn(&LooseLane) -> f64, pad: f64| -> Vec<f64x4> {
            (0..2 * blocks)
                .map(|h| f64x4::new(std::array::from_fn(|l| lane(4 * h + l).map_or(pad, f))))
                .collect()
        };
        let first = |l: &LooseLane| l.grid.times.at(0);
        let last = |l: &LooseLane| l.grid.times.at(l.grid.times.len() - 1);
        let t0 = half(&first, 0.0);
        let tn = half(&last, 1.0);
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
        let delta = offset_deltas(&lanes, blocks);
        let block_lanes = |b: usize| (8 * b..8 * b + 8).filter_map(lane);
        let mut ctl_planes = 0;
        let block: Vec<Block> = (0..blocks)
            .map(|b| {
                let planes = 4 * block_lanes(b).map(|l| l.dim()).max().unwrap_or(0);
                ctl_planes += planes;
                Block {
                    inner: [
                        block_lanes(b).map(first).fold(f64::NEG_INFINITY, f64::max),
                        block_lanes(b).map(last).fold(f64::INFINITY, f64::min),
                    ],
                    eased: block_lanes(b).any(|l| l.grid.eases.iter().any(|e| !e.is_none())),
                    hold: block_lanes(b).all(|l| {
                        l.grid.pre == Extrapolation::Constant
                            && l.grid.post == Extrapolation::Constant
                    }),
                    unbounded: block_lanes(b).any(|l| match &l.keys {
                        Keys::F32(k) => k.iter().flatten().any(|x| !x.is_finite()),
                        // Quantized lanes are finite (quant keeps the rest in f32).
                        Keys::U16(_) => false,
                    }),
                    ctl: ctl_planes - planes..ctl_planes,
                }
            })
            .collect();
        for (l, lane) in lanes.iter_mut().enumerate() {
            let ctl: &Block = &block[l / 8];
            lane.ctl_at = index_u32(8 * ctl.ctl.start + l % 8);
            let g = &lane.grid;
            let plain = g.eases.iter().all(|e| e.is_none()) && !g.steps.contains(&true);
            lane.plain = match lane.keys {
                Keys::F32(_) if plain => lane.dim,
                _ => 0,
            };
        }
        let (order, seek_after) = key_order(&lanes);
        Loose {
            unbounded: block.iter().any(|b| b.unbounded),
            seek_after,
            block,
            ctl_planes,
            order,
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

    /// The time at which forward playback reaches entry `i` of `order`
    /// (infinity past the end).
    #[inline]
    fn order_time(&self, i: usize) -> f64 {
        match self.order.get(i) {
            Some(&[l, seg]) => self.lanes[l as usize].grid.times.at(seg as usize - 1),
            None => f64::INFINITY,
        }
    }
}

/// The segments four lanes have loaded. Plain old data (`repr(C)`), so
/// that a load writes one lane's window through `f64`s ([`window_at`]).
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Half {
    /// Window start and width (`t_{k+1} - t_k`, 1 on sentinels): what
    /// every frame reads.
    ws: f64x4,
    d: f64x4,
    /// Window end, ease from and to.
    we: f64x4,
    from: f64x4,
    to: f64x4,
}

/// Where lane `l`'s `Half::ws` is in `LooseState::half` as `f64`s (`d`
/// and `we` are 4 and 8 after it): 20 per half block, its lanes in order.
#[inline(always)]
fn window_at(l: usize) -> usize {
    l / 4 * 20 + l % 4
}

/// Per-instance state of the loose tracks: each lane's window, width,
/// ease and controls, written lane by lane only when a lane crosses a
/// key and read four or eight lanes at a time; and where forward playback is
/// in [`Loose::order`].
#[derive(Clone, Debug)]
pub(crate) struct LooseState {
    /// Per block, its lanes 0-3 and 4-7: the segments they have loaded,
    /// as every frame reads them.
    half: Vec<[Half; 2]>,
    /// Per lane: the stored segment it has loaded (`u32::MAX` before the
    /// first).
    seg: Vec<u32>,
    /// Per block (`Block::ctl`): `[P0, P1, M0, M1]` per component.
    ctl: Vec<f32x8>,
    /// The next entry of `Loose::order` and its time.
    next: usize,
    next_time: f64,
    /// The time last sampled (NaN before the first sample: a seek).
    last: f64,
}

impl LooseState {
    pub fn new(loose: &Loose) -> Self {
        // Every lane starts on a window spanning all time with zero
        // controls: padding lanes keep it, real lanes are loaded by the
        // first sample (a seek).
        let half = Half {
            ws: f64x4::splat(-PAD_SPAN),
            d: f64x4::splat(2.0 * PAD_SPAN),
            we: f64x4::splat(PAD_SPAN),
            from: f64x4::ZERO,
            to: f64x4::ZERO,
        };
        LooseState {
            half: vec![[half; 2]; loose.blocks],
            seg: vec![u32::MAX; loose.lanes.len()],
            ctl: vec![f32x8::ZERO; loose.ctl_planes],
            next: 0,
            next_time: loose.order_time(0),
            last: f64::NAN,
        }
    }

    /// Load stored segment `seg` of lane `l` into its window, ease and
    /// controls (what `TimeGrid::key_pair` says, without its general match: this runs
    /// each time a lane crosses a key).
    #[inline(never)]
    fn load(&mut self, loose: &Loose, l: usize, seg: usize) {
        self.load_inline(loose, l, seg);
    }

    /// [`Self::load`], inlined where forward playback loads.
    #[inline(always)]
    fn load_inline(&mut self, loose: &Loose, l: usize, seg: usize) {
        let lane = &loose.lanes[l];
        let t = lane.grid.times.listed();
        let n = t.len();
        let (ws, we, d, ease, ka, kb) = if let Some(&[a, b]) = seg
            .checked_sub(1)
            .and_then(|k| t.get(k..k + 2))
            .map(|w| <&[f64; 2]>::try_from(w).expect("two times"))
        {
            let k = seg - 1;
            // A `step` segment is played at u = 0 (its width infinite),
            // as the per-group frame plays it (`TimeGrid::real`): it holds
            // its first key exactly, with rate 0.
            let step = lane.grid.is_step(k);
            (
                a,
                b,
                if step { f64::INFINITY } else { b - a },
                lane.grid.ease(k),
                k,
                if step { 0 } else { seg },
            )
        } else if seg == 0 {
            (f64::NEG_INFINITY, t[0], 1.0, Default::default(), n, n + 1)
        } else {
            (
                t[n - 1],
                f64::INFINITY,
                1.0,
                Default::default(),
                n + 2,
                n + 3,
            )
        };
        debug_assert_eq!((ka, kb), lane.grid.key_pair(seg));
        self.set_window(l, seg, [ws, we, d], Some(ease));
        lane.segment(ka, kb, bytemuck::cast_slice_mut(&mut self.ctl));
    }

    /// Lane `l`'s window `[ws, we)` and width `d`, its ease (`None` leaves
    /// the none every load of a plain lane writes), rate and stored segment.
    #[inline(always)]
    fn set_window(
        &mut self,
        l: usize,
        seg: usize,
        [ws, we, d]: [f64; 3],
        ease: Option<SegmentEase>,
    ) {
        let window: &mut [f64] = bytemuck::cast_slice_mut(&mut self.half);
        let at = window_at(l);
        let Some(window) = window.get_mut(at..at + 17) else {
            unreachable!("a lane's window is in the instance")
        };
        window[0] = ws;
        window[4] = d;
        window[8] = we;
        if let Some(e) = ease {
            window[12] = e.from();
            window[16] = e.to();
        }
        self.seg[l] = index_u32(seg);
    }

    /// The stored segment for mapped time `tm` (within the keys, or the
    /// sentinels beyond them); the one after `current` first, as forward
    /// playback wants.
    fn segment_for(lane: &LooseLane, current: usize, tm: f64) -> usize {
        let t = lane.grid.times.listed();
        let n = t.len();
        if tm < t[0] {
            0
        } else if tm >= t[n - 1] {
            n
        } else {
            segment_from(t, tm, current.wrapping_sub(1)) + 1
        }
    }

    /// Bring every lane to `time`: forward, the segments of `Loose::order`
    /// it passed; otherwise a seek. Afterwards each lane whose keys hold
    /// `time` (`t_0 <= time < t_{n-1}`) has the segment containing it.
    #[inline]
    fn advance(&mut self, loose: &Loose, time: f64) {
        // Forward (never NaN: a NaN time or a NaN `last` seeks).
        if time >= self.last {
            if time >= self.next_time {
                if time - self.last > loose.seek_after {
                    self.seek(loose, time);
                } else {
                    self.stream(loose, time);
                }
            }
        } else {
            self.seek(loose, time);
        }
        self.last = time;
    }

    /// Load the entries of `Loose::order` up to `time`; more than a few
    /// per lane and a seek is cheaper (out of line: most frames cross no
    /// key, or only a few).
    #[inline(never)]
    fn stream(&mut self, loose: &Loose, time: f64) {
        // In registers, stored once: the loads write through `self`.
        let first = self.next;
        let seek_at = 4 * loose.lanes.len() + 64;
        let order = loose.order.get(first..).unwrap_or_default();
        for (i, &[l, seg]) in order.iter().enumerate() {
            let (l, seg) = (l as usize, seg as usize);
            let lane = &loose.lanes[l];
            let t = lane.grid.times.listed();
            // The entry's time is its segment's first key (`seg >= 1`).
            let Some(&start) = t.get(seg.wrapping_sub(1)) else {
                unreachable!("an entry's segment starts at a key")
            };
            if time < start {
                self.next = first + i;
                self.next_time = start;
                return;
            }
            if i == seek_at {
                return self.seek(loose, time);
            }
            match t.get(seg) {
                // A lane that also passed the segment's end has its next
                // entry due in this same loop (dense keys, sampled at a
                // lower rate): only the last one is loaded.
                Some(&end) if time >= end => {}
                Some(&end) => self.load_real(loose, l, seg, start, end),
                None => self.load_inline(loose, l, seg),
            }
        }
        self.next = loose.order.len();
        // `next_time` is infinite past the end, which an infinite `time` passes.
        self.next_time = f64::INFINITY;
    }

    /// [`Self::load_inline`] for real segment `seg` (window `[ws, we)`):
    /// [`Self::load_plain`] where the lane allows it.
    #[inline(always)]
    fn load_real(&mut self, loose: &Loose, l: usize, seg: usize, ws: f64, we: f64) {
        let lane = &loose.lanes[l];
        match (&lane.keys, lane.plain) {
            (Keys::F32(k), 1) => self.load_plain::<1>(lane, l, seg, ws, we, k),
            (Keys::F32(k), 2) => self.load_plain::<2>(lane, l, seg, ws, we, k),
            (Keys::F32(k), 3) => self.load_plain::<3>(lane, l, seg, ws, we, k),
            (Keys::F32(k), 4) => self.load_plain::<4>(lane, l, seg, ws, we, k),
            _ => self.load_inline(loose, l, seg),
        }
    }

    /// [`Self::load_inline`] for real segment `seg` (window `[ws, we)`) of
    /// a lane with `N` components, no ease and no step, and keys `k` in
    /// f32: what forward playback loads nearly every time, in straight-line
    /// code (one range check each for the window, the loaded segment, the
    /// keys and the controls).
    #[inline(always)]
    fn load_plain<const N: usize>(
        &mut self,
        lane: &LooseLane,
        l: usize,
        seg: usize,
        ws: f64,
        we: f64,
        k: &[[f32; KEY_STRIDE]],
    ) {
        debug_assert!(usize::from(lane.plain) == N && lane.dim() == N && seg >= 1);
        debug_assert_eq!((seg - 1, seg), lane.grid.key_pair(seg));
        self.set_window(l, seg, [ws, we, we - ws], None);
        // Keys `seg - 1` and `seg`, `N` components each (`seg` is at most
        // the key count, which is far below `usize::MAX / 4`).
        let Some(keys) = k.get((seg - 1) * N..(seg + 1) * N) else {
            unreachable!("a real segment's keys are the lane's")
        };
        let (a, b) = keys.split_at(N);
        let ctl: &mut [f32] = bytemuck::cast_slice_mut(&mut self.ctl);
        let at = lane.ctl_at as usize;
        let Some(out) = ctl.get_mut(at..at + 32 * N - 7) else {
            unreachable!("a lane's controls are in the instance")
        };
        put_controls::<N>(
            out,
            a.try_into().expect("N components"),
            b.try_into().expect("N components"),
        );
    }

    /// Every lane's segment at `time` by binary search, and the position
    /// in `Loose::order` after every entry at or before `time`.
    #[inline(never)]
    fn seek(&mut self, loose: &Loose, time: f64) {
        self.next = loose.order.partition_point(|&[l, seg]| {
            loose.lanes[l as usize].grid.times.at(seg as usize - 1) <= time
        });
        self.next_time = loose.order_time(self.next);
        for (l, lane) in loose.lanes.iter().enumerate() {
            // A plain binary search: on keys at times of their own it costs
            // fewer instructions than `segment_from`'s gallop from where
            // even keys would put `time` (`sparse-seek`: 13.5M against
            // 10.9M), and snapshots of every lane's segment each mean key
            // spacing saved only 8% more for 9.5% more bytes. A NaN `time`
            // finds the pre sentinel, which the frame's refresh replaces.
            let t = lane.grid.times.listed();
            let seg = t.partition_point(|&k| k <= time);
            match seg.checked_sub(1).and_then(|k| t.get(k..k + 2)) {
                Some(&[ws, we]) => self.load_real(loose, l, seg, ws, we),
                _ => self.load(loose, l, seg),
            }
        }
    }
}

/// Rows of one block, per lane.
struct Rows {
    /// Lanes at a real segment's end (`s = 1`, basis `[0, 1, 0, 0]`).
    end: f32x8,
    h: [f32x8; 4],
    dh: [f32x8; 4],
    rate: f32x8,
    cycles: f32x8,
    any_cycles: bool,
}

/// Two halves as one `f32x8`, each lane rounded as `as f32` does
/// (the compiler makes it `cvtpd2ps`).
#[inline(always)]
fn f32x8_of(a: f64x4, b: f64x4) -> f32x8 {
    f32x8::new(narrow8(bytemuck::cast(a), bytemuck::cast(b)))
}

/// Eight `f64` (two halves) rounded to `f32` as `as f32` does: one
/// formula for [`f32x8_of`] and the AVX2 instance's `narrow`. Written out
/// (see `tcb_core::simd::w8`).
#[inline(always)]
fn narrow8(a: [f64; 4], b: [f64; 4]) -> [f32; 8] {
    [
        a[0] as f32,
        a[1] as f32,
        a[2] as f32,
        a[3] as f32,
        b[0] as f32,
        b[1] as f32,
        b[2] as f32,
        b[3] as f32,
    ]
}

fn mask_of(a: f64x4, b: f64x4) -> f32x8 {
    let bits = a.to_bitmask() | (b.to_bitmask() << 4);
    f32x8::new(std::array::from_fn(|i| {
        f32::from_bits(if bits >> i & 1 == 1 { u32::MAX } else { 0 })
    }))
}

/// Reload the lanes of half block `i` whose window does not hold `tm`.
#[inline(always)]
fn refresh(loose: &Loose, st: &mut LooseState, i: usize, tm: f64x4) {
    let half = &st.half[i / 2][i % 2];
    let ok = half.ws.simd_le(tm) & tm.simd_lt(half.we);
    let stale = !ok.to_bitmask() & 0xf;
    if stale != 0 {
        load_stale(loose, st, i, tm, stale);
    }
}

/// Load the lanes of half block `i` set in `stale` (out of line: rare).
#[inline(never)]
fn load_stale(loose: &Loose, st: &mut LooseState, i: usize, tm: f64x4, mut stale: u32) {
    while stale != 0 {
        let k = stale.trailing_zeros() as usize;
        stale &= stale - 1;
        let l = 4 * i + k;
        if l < loose.lanes.len() {
            let current = st.seg[l] as usize;
            let seg = LooseState::segment_for(&loose.lanes[l], current, tm.to_array()[k]);
            st.load(loose, l, seg);
        }
    }
}

/// The lanes a block's kernel computes on: `wide`'s, as the build compiled
/// them ([`Wide`]), or `tcb_core::simd::w8`'s, whose element-wise loops
/// become AVX instructions in the AVX2 instance (`v3`). Either runs the
/// same IEEE operations per lane in the same order (arithmetic, square
/// roots, compares, selects and conversions; the kernel calls no
/// `sin_cos` or `atan2`, whose polynomials differ): the same bits.
trait Lanes {
    /// Eight `f32`.
    type F: Lane;
    /// Four `f64`.
    type D: Lane;
    fn d(x: f64x4) -> Self::D;
    fn f(x: &f32x8) -> Self::F;
    fn store(x: Self::F) -> f32x8;
    /// Two halves as eight lanes, each rounded as `as f32` does.
    fn narrow(a: Self::D, b: Self::D) -> Self::F;
}

/// `wide`'s lanes, as the build compiled them.
struct Wide;

impl Lanes for Wide {
    type F = f32x8;
    type D = f64x4;
    #[inline(always)]
    fn d(x: f64x4) -> f64x4 {
        x
    }
    #[inline(always)]
    fn f(x: &f32x8) -> f32x8 {
        *x
    }
    #[inline(always)]
    fn store(x: f32x8) -> f32x8 {
        x
    }
    #[inline(always)]
    fn narrow(a: f64x4, b: f64x4) -> f32x8 {
        f32x8_of(a, b)
    }
}

/// `s` of a block (its two halves) when every lane is inside its keys,
/// `t_0 <= time < t_{n-1}`, and so (after [`LooseState::advance`]) inside
/// the segment it holds: `u` and the ease, nothing else; and with
/// `velocity` its rate, the reference's `(ds/du / D) as f32` (0 without).
#[inline(always)]
fn inside<K: Lanes>(eased: bool, half: &[Half; 2], time: f64, velocity: bool) -> (K::F, K::F) {
    let t = K::D::of(time);
    // `t - ws` is at least 0 and at most `we - ws = D`, so `u` is already
    // within the [0, 1] the reference clamps it to. Written out, without
    // closures (see `tcb_core::simd::w8`).
    let d = [K::d(half[0].d), K::d(half[1].d)];
    let u = [(t - K::d(half[0].ws)) / d[0], (t - K::d(half[1].ws)) / d[1]];
    if eased {
        let e0 = ease(u[0], K::d(half[0].from), K::d(half[0].to));
        let e1 = ease(u[1], K::d(half[1].from), K::d(half[1].to));
        let rate = if velocity {
            K::narrow(e0.1 / d[0], e1.1 / d[1])
        } else {
            K::F::of(0.0)
        };
        (K::narrow(e0.0, e1.0), rate)
    } else if velocity {
        // The same rate with `ds/du = 1`. Written as one expression for
        // both branches (`ds / d`), it cost `sparse` 2.3% more instructions
        // in SSE2.
        let one = K::D::of(1.0);
        (K::narrow(u[0], u[1]), K::narrow(one / d[0], one / d[1]))
    } else {
        (K::narrow(u[0], u[1]), K::F::of(0.0))
    }
}

/// Rows for block `b` at `time` (any f64), reloading lanes whose mapped
/// time left their window; `HOLD` where every lane's modes are `constant`
/// (`Block::hold`).
#[inline(never)]
fn rows_mapped<const HOLD: bool>(
    loose: &Loose,
    st: &mut LooseState,
    b: usize,
    time: f64,
    velocity: bool,
) -> Rows {
    // Hot (a block whose lanes left their keys, per frame), kept whole:
    // two halves of 4 lanes in f64 feed one f32x8 row computation.
    let t = f64x4::splat(time);
    let zero = f64x4::ZERO;
    let one = f64x4::ONE;
    let mut out_tm = [zero; 2];
    let (mut line, mut reset, mut hold) = ([zero; 2], [zero; 2], [zero; 2]);
    let mut dir = [one; 2];
    let mut cycles = [zero; 2];
    let mut dt = [zero; 2];
    for h in 0..2 {
        let i = 2 * b + h;
        let m = if HOLD {
            hold_lanes(t, loose.t0[i], loose.tn[i])
        } else {
            map_lanes(t, loose.t0[i], loose.tn[i], &loose.pre[i], &loose.post[i])
        };
        // Lanes outside the keys read a sentinel: 0 before, n after. A
        // time mapped inside but rounded below the first key (`oscillate`
        // over a huge span) is the first segment at u = 0, as the
        // reference's clamp of u makes it (and as `TimeGrid::frame` finds).
        let beyond = m
            .last
            .select(f64x4::splat(f64::MAX), f64x4::splat(-f64::MAX));
        out_tm[h] = m.inside.select(m.time.max(loose.t0[i]), beyond);
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
        let Half {
            ws,
            d,
            we,
            from: a,
            to: e,
        } = st.half[b][h];
        let is_real =
            ws.simd_gt(f64x4::splat(f64::NEG_INFINITY)) & we.simd_lt(f64x4::splat(f64::INFINITY));
        let u = is_real.select(((out_tm[h] - ws) / d).max(zero).min(one), zero);
        let (ss, dsdu) = if loose.block[b].eased {
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
        LaneRows {
            real: realm,
            line,
            reset,
            hold,
            s: s32,
            rate: f32x8_of(rate[0], rate[1]),
            dir: dirs,
            dt: f32x8_of(dt[0], dt[1]),
        },
        velocity,
    );
    Rows {
        // Lanes not in a real segment have `s = 0`.
        end: s32.simd_eq(f32x8::ONE),
        h,
        dh,
        rate,
        any_cycles: cyc.simd_ne(f32x8::ZERO).any(),
        cycles: cyc,
    }
}

/// Sample every loose track at `time` into its pose planes.
///
/// `ROTATIONS`: the lanes are rotations, each block normalized
/// ([`normalize`]) as soon as it is evaluated.
#[inline(always)]
pub(crate) fn sample<const ROTATIONS: bool>(
    loose: &Loose,
    st: &mut LooseState,
    time: f64,
    values: &mut [f32x8],
    velocities: Option<&mut [f32x8]>,
) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::isa::Avx2Kernels::now() {
        return v3::sample_here::<ROTATIONS>(avx2, loose, st, time, values, velocities);
    }
    sample_wide::<ROTATIONS>(loose, st, time, values, velocities);
}

/// [`sample`] on `wide`'s lanes as built (out of line, as the AVX2
/// instance is).
#[inline(never)]
fn sample_wide<const ROTATIONS: bool>(
    loose: &Loose,
    st: &mut LooseState,
    time: f64,
    values: &mut [f32x8],
    velocities: Option<&mut [f32x8]>,
) {
    sample_on::<ROTATIONS, Wide>(loose, st, time, values, velocities);
}

/// [`sample`] on the lanes of `K`.
#[inline(always)]
fn sample_on<const ROTATIONS: bool, K: Lanes>(
    loose: &Loose,
    st: &mut LooseState,
    time: f64,
    values: &mut [f32x8],
    velocities: Option<&mut [f32x8]>,
) {
    // Once per frame, so that the blocks' loop of the usual set (finite
    // controls) has no test for the other.
    if loose.unbounded {
        sample_blocks::<ROTATIONS, true, K>(loose, st, time, values, velocities);
    } else {
        sample_blocks::<ROTATIONS, false, K>(loose, st, time, values, velocities);
    }
}

/// [`sample`], with `UNBOUNDED` where some block stores a non-finite
/// control.
#[inline(always)]
fn sample_blocks<const ROTATIONS: bool, const UNBOUNDED: bool, K: Lanes>(
    loose: &Loose,
    st: &mut LooseState,
    time: f64,
    values: &mut [f32x8],
    velocities: Option<&mut [f32x8]>,
) {
    st.advance(loose, time);
    let planes = loose.out..loose.out + 4 * loose.blocks;
    let values = &mut values[planes.clone()];
    let mut velocities = velocities.map(|v| &mut v[planes]);
    let velocity = velocities.is_some();
    for (b, info) in loose.block.iter().enumerate() {
        let out = 4 * b..4 * b + 4;
        if time >= info.inner[0] && time < info.inner[1] {
            let half = &st.half[b];
            // Every real lane holds `time` (padding lanes span +-PAD_SPAN
            // only: beyond it their u leaves [0, 1], which nobody reads).
            debug_assert!((8 * b..loose.lanes.len().min(8 * b + 8)).all(|l| {
                let h = &half[(l % 8) / 4];
                let i = l % 4;
                h.ws.to_array()[i] <= time && time < h.we.to_array()[i]
            }));
            let (s, rate) = inside::<K>(info.eased, half, time, velocity);
            let ctl = &st.ctl[info.ctl.clone()];
            let h = hermite_basis(s);
            for (k, o) in ctl.chunks_exact(4).zip(&mut values[out.clone()]) {
                let v = hermite(&h, K::f(&k[0]), K::f(&k[1]), K::f(&k[2]), K::f(&k[3]));
                *o = K::store(v);
            }
            if UNBOUNDED && info.unbounded {
                // At a segment's end the value is its key, as the reference
                // has it, even beside a tangent that overflowed f32 (0 x inf).
                let at_end = Lane::eq(s, K::F::of(1.0));
                for (k, o) in ctl.chunks_exact(4).zip(&mut values[out.clone()]) {
                    *o = K::store(Lane::select(at_end, K::f(&k[1]), K::f(o)));
                }
            }
            if let Some(vel) = velocities.as_deref_mut() {
                let dh = hermite_basis_derivative(s);
                for (k, o) in ctl.chunks_exact(4).zip(&mut vel[out.clone()]) {
                    let v = hermite(&dh, K::f(&k[0]), K::f(&k[1]), K::f(&k[2]), K::f(&k[3]));
                    *o = K::store(v * rate);
                }
            }
            if ROTATIONS {
                normalize::<K>(values, velocities.as_deref_mut(), out);
            }
            continue;
        }
        let rows = if info.hold {
            rows_mapped::<true>(loose, st, b, time, velocities.is_some())
        } else {
            rows_mapped::<false>(loose, st, b, time, velocities.is_some())
        };
        let ctl = &st.ctl[info.ctl.clone()];
        for (c, k) in ctl.chunks_exact(4).enumerate() {
            let mut v = hermite(&rows.h, k[0], k[1], k[2], k[3]);
            if UNBOUNDED && info.unbounded {
                // As inside the keys: at a segment's end, the key.
                v = Lane::select(rows.end, k[1], v);
            }
            if rows.any_cycles {
                v += loose.delta[4 * b + c] * rows.cycles;
            }
            values[out.start + c] = v;
            if let Some(vel) = velocities.as_deref_mut() {
                vel[out.start + c] = hermite(&rows.dh, k[0], k[1], k[2], k[3]) * rows.rate;
            }
        }
        if ROTATIONS {
            normalize::<K>(values, velocities.as_deref_mut(), out);
        }
    }
}

/// Normalize the rotation block at planes `out` (and its velocities) on
/// the lanes of `K` (out of range, through
/// [`crate::kernel::renormalize_scaled`]). Matches rather than
/// `Option::map`: no closure passed to a generic function in the AVX2
/// instance (see `tcb_core::simd::w8`).
#[inline(always)]
#[allow(clippy::manual_map)]
fn normalize<K: Lanes>(
    values: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
    out: std::ops::Range<usize>,
) {
    fn block(v: &mut [f32x8], out: std::ops::Range<usize>) -> &mut [f32x8; 4] {
        (&mut v[out]).try_into().expect("4 planes")
    }
    let v = block(values, out.clone());
    let mut vel = match vel {
        Some(d) => Some(block(d, out)),
        None => None,
    };
    let raw = *v;
    let load = |x: &[f32x8; 4]| [K::f(&x[0]), K::f(&x[1]), K::f(&x[2]), K::f(&x[3])];
    let p = load(&raw);
    let raw_dp = vel.as_deref().copied();
    let dp = match &raw_dp {
        Some(d) => Some(load(d)),
        None => None,
    };
    let (q, qv) = crate::kernel::normalize(p, dp);
    *v = [
        K::store(q[0]),
        K::store(q[1]),
        K::store(q[2]),
        K::store(q[3]),
    ];
    if let (Some(d), Some(qv)) = (vel.as_deref_mut(), qv) {
        *d = [
            K::store(qv[0]),
            K::store(qv[1]),
            K::store(qv[2]),
            K::store(qv[3]),
        ];
    }
    if !crate::kernel::in_range(&p, crate::kernel::F32_RANGE[0]).all() {
        let vel = match vel {
            Some(d) => Some(d.as_mut_slice()),
            None => None,
        };
        crate::kernel::renormalize_scaled(&raw, raw_dp.as_ref(), v, vel);
    }
}

/// The AVX2 + FMA instance of the blocks' kernel (see `crate::isa`): the
/// same code on `tcb_core::simd::w8`'s `W8` and `D4`.
#[cfg(target_arch = "x86_64")]
mod v3 {
    use crate::loose::{Lanes, Loose, LooseState, narrow8, sample_on};
    use tcb_core::simd::w8::{D4, W8};
    use wide::{f32x8, f64x4};

    /// `W8` and `D4`.
    pub(super) struct Avx2;

    impl Lanes for Avx2 {
        type F = W8;
        type D = D4;
        #[inline(always)]
        fn d(x: f64x4) -> D4 {
            D4(x.to_array())
        }
        #[inline(always)]
        fn f(x: &f32x8) -> W8 {
            W8(x.to_array())
        }
        #[inline(always)]
        fn store(x: W8) -> f32x8 {
            f32x8::new(x.0)
        }
        #[inline(always)]
        fn narrow(a: D4, b: D4) -> W8 {
            W8(narrow8(a.0, b.0))
        }
    }

    /// [`crate::loose::sample`], where `crate::isa::avx2_kernels` said so
    /// (the token).
    #[inline(always)]
    pub(super) fn sample_here<const ROTATIONS: bool>(
        _: crate::isa::Avx2Kernels,
        loose: &Loose,
        st: &mut LooseState,
        time: f64,
        values: &mut [f32x8],
        velocities: Option<&mut [f32x8]>,
    ) {
        // SAFETY: an `Avx2Kernels` exists only where `crate::isa` detected
        // AVX2 and FMA on this CPU.
        #[allow(unsafe_code)]
        unsafe {
            sample::<ROTATIONS>(loose, st, time, values, velocities)
        }
    }

    #[target_feature(enable = "avx2,fma")]
    fn sample<const ROTATIONS: bool>(
        loose: &Loose,
        st: &mut LooseState,
        time: f64,
        values: &mut [f32x8],
        velocities: Option<&mut [f32x8]>,
    ) {
        sample_on::<ROTATIONS, Avx2>(loose, st, time, values, velocities);
    }
}

/// `P_{n-1} - P_0` of each lane and component, per block of 8 lanes and
/// plane (what `offset-repeat` adds per cycle).
fn offset_deltas(lanes: &[LooseLane], blocks: usize) -> Vec<f32x8> {
    let mut delta = vec![f32x8::ZERO; 4 * blocks];
    for b in 0..blocks {
        for c in 0..4 {
            delta[4 * b + c] = f32x8::new(std::array::from_fn(|l| {
                lanes.get(8 * b + l).map_or(0.0, |x| {
                    if c >= x.dim() {
                        return 0.0;
                    }
                    let n = x.grid.times.len();
                    x.key((n - 1) * x.dim() + c)[0] - x.key(c)[0]
                })
            }));
        }
    }
    delta
}

/// Every lane's segments `[lane, segment]` in the order forward playback
/// first needs them (by the segment's start time, then lane), and the
/// time after which a jump is a seek rather than a walk along them.
fn key_order(lanes: &[LooseLane]) -> (Vec<[u32; 2]>, f64) {
    let mut order: Vec<(f64, u32, u32)> = lanes
        .iter()
        .enumerate()
        .flat_map(|(l, x)| {
            let t = x.grid.times.listed();
            (1..=t.len()).map(move |seg| (t[seg - 1], index_u32(l), index_u32(seg)))
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let seek_after = match (order.first(), order.last()) {
        (Some(a), Some(b)) => (b.0 - a.0) * (2 * lanes.len() + 64) as f64 / order.len() as f64,
        _ => f64::INFINITY,
    };
    (
        order.into_iter().map(|(_, l, s)| [l, s]).collect(),
        seek_after,
    )
}
