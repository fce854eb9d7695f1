//! Packed clips: values-only keys on one even grid, quantized, predicted
//! and bit-packed (`.tcbc`, `docs/tcbc.md`).
//!
//! A track whose keys are evenly spaced and share one set of tension,
//! continuity and bias needs only its values: every interior key's
//! tangents follow from its two neighbours with constant chord weights
//! (`tcb_core::tangent::ChordWeights`). A packed clip stores, per track,
//! one quantization step, times a factor per block of keys
//! ([`BlockScales`]: `step_k`), and the integers `x_k = round(v_k / step_k)`
//! of each stored component (rotations: `x y z` with `w >= 0` rebuilt, or all four
//! where `w` changes sign), coded as
//!
//! ```text
//! block of 64 keys:   x_b (absolute), x_{b+1} - x_b (delta), then per key
//!                     r_k = x_k - (2 x_{k-1} - x_{k-2})          (2nd-order prediction)
//! segment of 32 keys: per component a header (the prediction order, 1 or 2,
//!                     and a width w), then each component's residuals of the
//!                     segment as r_k + 2^(w-1) in w bits
//! ```
//!
//! so playback decodes one key per key it crosses (shifts and adds), and a
//! seek decodes from the start of its 64-key block.
//!
//! Tracks on key times of their own (a reduced clip's, beside the tracks it
//! keeps on the capture's grid) keep their keys ([`LooseTrack`]): f64
//! times, and values (and explicit tangents, where the tangent rule does
//! not give them) in integers of their own steps, decoded at load into the
//! reference's tracks and compiled as any clip's.
//!
//! [`PackSource`] is the description in integers (what the encoder in
//! `tcb-fit` searches over); [`PackSource::to_clip`] is its reference, an
//! ordinary `tcb_core::SourceClip` whose values are the dequantized integers;
//! [`Packed`] is the encoded form and the file. [`crate::Clip::from_packed`]
//! compiles it: the runtime's controls come from decoding keys as playback
//! reaches them, checked at compile time to equal, bit for bit, the controls
//! the reference compiles to.

use std::fmt;
use std::ops::Range;
use tcb_core::params::{Hemisphere, RotationMode, TangentRule, Tcb};
use tcb_core::{
    KeyParams, NamedTrack, RotationTrack, SourceClip, Track, TrackData, TrackKind, TrackSettings,
};

/// Keys per block by default: a block starts from absolute values (a seek
/// decodes from the start of its block); [`Packed::encode_with`] takes
/// another multiple of [`SEGMENT_KEYS`].
pub const BLOCK_KEYS: usize = 64;
/// The largest block.
pub const MAX_BLOCK_KEYS: usize = 1024;
/// Keys per segment: a segment has one residual width per component.
/// 32 rather than 16: on CMU 01_01 at ACL's target, 3.6% more bytes
/// (180,512 against 174,308) for 9.5% fewer decoder instructions a frame
/// (each segment's headers and each plane's coding are read half as
/// often); 64 took 8.8% more bytes for 14% fewer (docs/tcbc.md).
pub const SEGMENT_KEYS: usize = 32;
/// Bits of a width field.
pub(crate) const WIDTH_BITS: u32 = 5;
/// The largest integer magnitude (f32 holds every integer below 2^24).
pub const MAX_INT: i32 = 1 << 24;
/// The most stored components on the grid a packed clip may hold: the
/// decoder keeps, per component, the sum of the residual widths (at most
/// 31 each) before it beside 6 bits of its own, in an `i32`.
pub const MAX_LANES: usize = 1 << 20;
/// The most keys over all tracks a packed clip may hold: decoding in full
/// ([`Packed::from_bytes`], `Clip::verify_packed`, about 50 bytes a key and
/// component with the reference compiled) allocates in proportion to them,
/// so this bounds what a small file of constant tracks can make a reader
/// allocate (CMU 01_01 has 88,064). Loading allocates the grid's times.
pub const MAX_TRACK_KEYS: usize = 1 << 22;

/// A clip in integers: one even grid of `keys` key times from `start`,
/// `interval` apart, and per track a step and the integers of each stored
/// component.
#[derive(Clone, Debug, PartialEq)]
pub struct PackSource {
    /// The clip's name.
    pub name: String,
    /// The first key time.
    pub start: f64,
    /// Seconds between keys (> 0).
    pub interval: f64,
    /// Keys per track (>= 2).
    pub keys: usize,
    /// The tracks on the grid (the stream's), in file order.
    pub tracks: Vec<PackTrack>,
    /// Per block of keys, a factor on the steps of the grid's tracks.
    pub scales: BlockScales,
    /// The tracks on key times of their own ([`LooseTrack`]), each at its
    /// place among all the clip's tracks (`at`, increasing); the grid's
    /// tracks fill the other places in order.
    pub loose: Vec<LooseTrack>,
}

/// Per block of keys, a factor on the step of every track on the grid:
/// where a block's motion leaves the error room, its keys take coarser
/// steps (a block starts from absolute values, so its integers need
/// nothing from the block before). `tcb compress` searches them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BlockScales {
    /// Keys per block: the packed clip's blocks ([`Packed::encode_with`]'s
    /// `block`). Unused with no codes.
    pub keys: usize,
    /// Per block its code `c`: the steps times [`scale_factor`]`(c)`.
    /// Empty: every factor is 1 (a packed clip keeps them empty when every
    /// code is 0).
    pub codes: Vec<u8>,
}

impl BlockScales {
    /// The factor on the steps of key `k`.
    pub fn factor(&self, k: usize) -> f32 {
        let code = match self.keys {
            0 => 0,
            keys => self.codes.get(k / keys).copied().unwrap_or(0),
        };
        scale_factor(code)
    }

    /// A track's step `step` at key `k`: [`block_step`] by the key's
    /// [`factor`](Self::factor).
    pub fn step(&self, step: f32, k: usize) -> f32 {
        block_step(step, self.factor(k))
    }

    /// The same factors, as a packed clip keeps them: none where every
    /// code is 0.
    pub fn canonical(self) -> BlockScales {
        if self.codes.iter().all(|c| *c == 0) {
            BlockScales::default()
        } else {
            self
        }
    }
}

/// The largest step: times the largest factor and the largest integer it
/// stays finite in f32 (`3.4e38 / (4.98 * 2^24)`, about 4e30).
pub const MAX_STEP: f32 = 4e30;

/// The factor of a block's code: `1 + c / 64` (exact in f32: 1 to 4.98 in
/// steps of 1/64).
pub fn scale_factor(code: u8) -> f32 {
    1.0 + f32::from(code) / 64.0
}

/// A track's step in a block whose factor is `factor` (f32, one rounding;
/// the decoder's on 8 lanes).
#[inline(always)]
pub fn block_step<F: std::ops::Mul<Output = F>>(step: F, factor: F) -> F {
    step * factor
}

/// One track of a [`PackSource`].
#[derive(Clone, Debug, PartialEq)]
pub struct PackTrack {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: TrackKind,
    /// Its settings: rotations `hermite`, no `match_speed`; `pre` and `post`
    /// the same for every track of the clip.
    pub settings: TrackSettings,
    /// Tension, continuity and bias of every key.
    pub tcb: Tcb,
    /// Quantization step (finite, > 0): a value is `x as f32 * step_k`,
    /// `step_k` this step in key `k`'s block ([`BlockScales::step`]). At
    /// most [`MAX_STEP`].
    pub step: f32,
    /// Rotations: `x y z` stored, `w >= 0` rebuilt
    /// ([`tcb_core::quat::rebuild_w`]); else every component is stored.
    pub rebuild_w: bool,
    /// Rotations: the unit quaternion `r` the stored keys are relative to.
    /// A key is `r q` ([`tcb_core::quat::mul`] in f32), `q` the stored
    /// components (and rebuilt `w`): a track that turns far from the
    /// identity keeps `w` of `q` away from 0, where rebuilding `w` would
    /// multiply the quantization error (by `1 / w`).
    pub center: Option<[f32; 4]>,
    /// Per stored component, one integer per key (`|x| < 2^24`).
    pub values: Vec<Vec<i32>>,
}

/// A track of a [`PackSource`] on key times of its own.
#[derive(Clone, Debug, PartialEq)]
pub struct LooseTrack {
    /// Its position among all the clip's tracks (file order).
    pub at: usize,
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: TrackKind,
    /// Its settings, as the source had them.
    pub settings: TrackSettings,
    /// Key times (f64, strictly increasing, at least 2).
    pub times: Vec<f64>,
    /// Quantization step of the values (finite, > 0).
    pub step: f32,
    /// Per component (`kind.dim()`), one integer per key (`|x| < 2^24`).
    pub values: Vec<Vec<i32>>,
    /// Explicit tangents, where the track's are not the rule's on its values.
    pub tangents: Option<LooseTangents>,
}

/// The explicit tangents of a [`LooseTrack`] (value per second).
#[derive(Clone, Debug, PartialEq)]
pub struct LooseTangents {
    /// Quantization step (finite, > 0).
    pub step: f32,
    /// Per component, one integer per key: incoming, then outgoing.
    pub incoming: Vec<Vec<i32>>,
    /// As `incoming`.
    pub outgoing: Vec<Vec<i32>>,
}

impl PackTrack {
    /// Components stored.
    pub fn stored(&self) -> usize {
        self.kind.dim() - usize::from(self.rebuild_w)
    }

    /// Its `k`-th integers' components as the reference clip is given them
    /// (rotations as given, not normalized: `RotationTrack::new_as_given`),
    /// in steps of `step` (the key's: [`BlockScales::step`]).
    pub fn value(&self, k: usize, step: f32) -> [f32; 4] {
        let mut v = [0.0f32; 4];
        for (c, x) in self.values.iter().enumerate() {
            v[c] = dequantize(x[k], step);
        }
        if self.rebuild_w {
            v[3] = tcb_core::quat::rebuild_w(v[0], v[1], v[2]);
        }
        match self.center {
            Some(r) => tcb_core::quat::mul(&r, &v),
            None => v,
        }
    }
}

/// `x as f32 * step`: the one dequantization, on one value.
#[inline(always)]
pub fn dequantize(x: i32, step: f32) -> f32 {
    dequantize_lanes(wide::i32x8::splat(x), wide::f32x8::splat(step)).to_array()[0]
}

/// [`dequantize`] on 8 lanes (the decoder's).
#[inline(always)]
pub(crate) fn dequantize_lanes<I: IntLanes>(x: I, step: I::Float) -> I::Float {
    x.to_float() * step
}

/// Eight `i32` lanes the decoder dequantizes: `wide::i32x8`, or the AVX2
/// instance's `tcb_core::simd::w8::I8`.
pub(crate) trait IntLanes {
    type Float: std::ops::Mul<Output = Self::Float>;
    /// Each lane as the nearest `f32`.
    fn to_float(self) -> Self::Float;
}

impl IntLanes for wide::i32x8 {
    type Float = wide::f32x8;
    #[inline(always)]
    fn to_float(self) -> wide::f32x8 {
        self.round_float()
    }
}

impl IntLanes for tcb_core::simd::w8::I8 {
    type Float = tcb_core::simd::w8::W8;
    #[inline(always)]
    fn to_float(self) -> Self::Float {
        tcb_core::simd::w8::I8::to_float(self)
    }
}

/// Why a packed clip cannot be built or read: one line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PackError(pub String);

impl fmt::Display for PackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PackError {}

pub(crate) fn err<T>(msg: impl Into<String>) -> Result<T, PackError> {
    Err(PackError(msg.into()))
}

impl PackSource {
    /// The key times.
    pub fn times(&self) -> Vec<f64> {
        (0..self.keys).map(|k| self.time(k)).collect()
    }

    /// Key `k`'s time: `start + k interval` in f64, by the runtime's own
    /// formula for an even grid.
    pub fn time(&self, k: usize) -> f64 {
        crate::grid::even_time(self.start, self.interval, k)
    }

    /// Quantize `clip`'s keys: every track on one even grid (to 1e-6 of the
    /// interval), track `i` with step `steps[i]`; rotations `hermite`,
    /// storing `x y z` where every key's `w` has one sign (the keys negated
    /// where it is negative) and all four otherwise. Key parameters are
    /// not read: the packed tracks have the default tension, continuity and
    /// bias and the clip's settings (a measurement against the source says
    /// how close that is).
    pub fn quantize(clip: &SourceClip, steps: &[f32]) -> Result<PackSource, PackError> {
        KeyValues::sample(clip)?.quantize(steps)
    }

    /// Stored components over all tracks (the stream's lanes).
    pub fn lanes(&self) -> usize {
        self.tracks.iter().map(PackTrack::stored).sum()
    }

    /// Integers stored over all tracks: the grid's keys times its lanes,
    /// and each loose track's values and tangents.
    pub fn stored_values(&self) -> usize {
        let loose: usize = self.loose.iter().map(LooseTrack::stored_values).sum();
        self.keys * self.lanes() + loose
    }

    /// The grid's track `i`'s place among all the clip's tracks.
    pub fn place(&self, i: usize) -> usize {
        // Places taken by loose tracks before it move it on.
        let mut at = i;
        for l in &self.loose {
            if l.at <= at {
                at += 1;
            } else {
                break;
            }
        }
        at
    }

    /// Check what the format and the runtime need (see the field docs).
    pub fn validate(&self) -> Result<(), PackError> {
        self.validate_head()?;
        for t in &self.loose {
            t.validate()?;
        }
        for t in &self.tracks {
            let at = |m: String| err(format!("track {}: {m}", t.name));
            if t.values.len() != t.stored() {
                return at(format!(
                    "{} components given, {} stored",
                    t.values.len(),
                    t.stored()
                ));
            }
            for v in &t.values {
                if v.len() != self.keys {
                    return at(format!("{} values, not {}", v.len(), self.keys));
                }
                if let Some(x) = v.iter().find(|x| x.unsigned_abs() >= MAX_INT as u32) {
                    return at(format!("integer {x} is outside +-2^24"));
                }
            }
        }
        Ok(())
    }

    /// [`validate`](Self::validate) but for the integers: the grid, the
    /// tracks' settings, steps and weights.
    pub(crate) fn validate_head(&self) -> Result<(), PackError> {
        if self.tracks.is_empty() {
            return err("a packed clip with no tracks");
        }
        let loose_keys = self
            .loose
            .iter()
            .fold(0usize, |n, t| n.saturating_add(t.times.len()));
        if self
            .keys
            .saturating_mul(self.tracks.len())
            .saturating_add(loose_keys)
            > MAX_TRACK_KEYS
        {
            return err(format!(
                "{} keys of {} tracks on the grid and {loose_keys} of tracks on their own: a packed clip holds at most {MAX_TRACK_KEYS} track keys (loading compiles them in full)",
                self.keys,
                self.tracks.len()
            ));
        }
        if self.lanes() > MAX_LANES {
            return err(format!(
                "{} stored components on the grid: a packed clip holds at most {MAX_LANES}",
                self.lanes()
            ));
        }
        let s = &self.scales;
        if !s.codes.is_empty() {
            check_block(s.keys)?;
            if s.codes.len() != self.keys.div_ceil(s.keys) {
                return err(format!(
                    "{} step factors for {} keys in blocks of {}",
                    s.codes.len(),
                    self.keys,
                    s.keys
                ));
            }
        }
        let total = self.tracks.len() + self.loose.len();
        let ends = self
            .tracks
            .first()
            .map(|t| (t.settings.pre, t.settings.post));
        for (i, t) in self.loose.iter().enumerate() {
            // Compiled, such a track would join the grid's group.
            let s = &t.settings;
            if t.times.len() == self.keys
                && Some((s.pre, s.post)) == ends
                && (0..self.keys).all(|k| t.times[k].to_bits() == self.time(k).to_bits())
            {
                return err(format!(
                    "track {} is on the grid's key times with its pre and post: it belongs on the grid",
                    t.name
                ));
            }
            let after = i.checked_sub(1).map(|j| self.loose[j].at);
            if t.at >= total || after.is_some_and(|a| t.at <= a) {
                return err(format!(
                    "track {} is placed at {} among {total} tracks (places increase, below the count)",
                    t.name, t.at
                ));
            }
        }
        if self.keys < 2 {
            return err(format!(
                "a packed clip needs 2 keys or more, not {}",
                self.keys
            ));
        }
        if !(self.start.is_finite() && self.interval.is_finite() && self.interval > 0.0) {
            return err(format!(
                "key times start {} interval {}: need finite times and a positive interval",
                self.start, self.interval
            ));
        }
        let last = self.start + (self.keys - 1) as f64 * self.interval;
        if !last.is_finite() {
            return err("the last key time is not finite");
        }
        let first = self
            .tracks
            .first()
            .map(|t| (t.settings.pre, t.settings.post));
        let intervals = Intervals::of(self.keys, |k| self.time(k));
        for t in &self.tracks {
            let at = |m: String| err(format!("track {}: {m}", t.name));
            if t.kind == TrackKind::Quat {
                if t.settings.rotation != RotationMode::Hermite {
                    return at("packed rotations are `hermite`".into());
                }
                if t.settings.hemisphere != Hemisphere::Keep {
                    return at("packed rotations keep their hemisphere (`keep`)".into());
                }
            } else if t.rebuild_w || t.center.is_some() {
                return at("only rotations rebuild w or have a center".into());
            }
            if let Some(r) = t.center {
                let norm: f32 = r.iter().map(|x| x * x).sum();
                // (NaN fails the comparison and is refused too.)
                let unit = (norm - 1.0).abs() <= 1e-5;
                if !unit {
                    return at(format!(
                        "center {r:?} is not a unit quaternion (squared norm {norm})"
                    ));
                }
            }
            if t.settings.match_speed {
                return at("packed tracks have no `match_speed`".into());
            }
            if Some((t.settings.pre, t.settings.post)) != first {
                return at("every packed track has the same pre and post".into());
            }
            if !(t.step.is_finite() && t.step > 0.0) {
                return at(format!("step {} is not a positive number", t.step));
            }
            if t.step > MAX_STEP {
                return at(format!(
                    "step {:e} is above {MAX_STEP:e} (with a block's factor its integers would overflow f32)",
                    t.step
                ));
            }
            if !t.tcb.is_finite() {
                return at("tension, continuity and bias must be finite".into());
            }
            if let Some(k) = intervals.uneven_weights(t) {
                return at(format!(
                    "the key times' f64 differences vary (at key {k}: {} s from {}), so the tangent rule's weights would differ from key to key; start nearer 0, or use the uniform rule",
                    self.interval, self.start
                ));
            }
        }
        Ok(())
    }

    /// The reference: an ordinary clip whose keys are the dequantized
    /// values (what `tcb sample --scalar` plays, and what the runtime's
    /// decoded keys are checked against).
    pub fn to_clip(&self) -> Result<SourceClip, PackError> {
        self.validate()?;
        self.reference(&(0..self.keys).collect::<Vec<_>>())
    }

    /// The reference on the keys `keys` (the values' keys, in order): all
    /// of them for [`to_clip`](Self::to_clip), or a few (a loader's, see
    /// `crate::compile`).
    pub(crate) fn reference(&self, keys: &[usize]) -> Result<SourceClip, PackError> {
        let times: Vec<f64> = keys.iter().map(|&k| self.time(k)).collect();
        let mut tracks = Vec::with_capacity(self.tracks.len() + self.loose.len());
        let mut loose = self.loose.iter().peekable();
        for t in &self.tracks {
            while let Some(l) = loose.next_if(|l| l.at == tracks.len()) {
                tracks.push(l.reference()?);
            }
            let (s, n) = (&t.settings, times.len());
            let vals: Vec<[f32; 4]> = (keys.iter().enumerate())
                .map(|(i, &k)| t.value(i, self.scales.step(t.step, k)))
                .collect();
            let e = |e: tcb_core::TrackError| PackError(format!("track {}: {e}", t.name));
            let times = times.to_vec();
            let data = match t.kind {
                TrackKind::Scalar => {
                    let v = vals.iter().map(|v| v[0]).collect();
                    TrackData::Scalar(
                        Track::new(times.clone(), v, key_params(t.tcb, n), s).map_err(e)?,
                    )
                }
                TrackKind::Vec2 => {
                    let v = vals.iter().map(|v| glam::Vec2::new(v[0], v[1])).collect();
                    TrackData::Vec2(
                        Track::new(times.clone(), v, key_params(t.tcb, n), s).map_err(e)?,
                    )
                }
                TrackKind::Vec3 => {
                    let v = vals
                        .iter()
                        .map(|v| glam::Vec3::new(v[0], v[1], v[2]))
                        .collect();
                    TrackData::Vec3(
                        Track::new(times.clone(), v, key_params(t.tcb, n), s).map_err(e)?,
                    )
                }
                TrackKind::Vec4 => {
                    let v = vals.iter().map(|v| glam::Vec4::from_array(*v)).collect();
                    TrackData::Vec4(
                        Track::new(times.clone(), v, key_params(t.tcb, n), s).map_err(e)?,
                    )
                }
                TrackKind::Quat => {
                    let v = vals.iter().map(|v| glam::Quat::from_array(*v)).collect();
                    // As given: the decoder's keys are these, not normalized.
                    let r = RotationTrack::new_as_given(times.clone(), v, key_params(t.tcb, n), s);
                    TrackData::Quat(r.map_err(e)?)
                }
            };
            tracks.push(NamedTrack {
                name: t.name.clone(),
                data,
            });
        }
        for l in loose {
            tracks.push(l.reference()?);
        }
        SourceClip::new(self.name.clone(), tracks)
            .map_err(|d| PackError(format!("track {} appears twice", d.0)))
    }
}

/// A clip's key values on its even grid, as [`PackSource::quantize`] packs
/// them: sampled once, so that a search over steps quantizes again without
/// sampling again (`tcb compress`).
#[derive(Clone, Debug)]
pub struct KeyValues {
    name: String,
    start: f64,
    interval: f64,
    keys: usize,
    /// The tracks on the grid, in file order.
    tracks: Vec<TrackKeys>,
    /// The tracks on key times of their own, in file order.
    loose: Vec<loose::LooseKeys>,
}

/// One track of [`KeyValues`].
#[derive(Clone, Debug)]
struct TrackKeys {
    name: String,
    kind: TrackKind,
    settings: TrackSettings,
    /// Per key, the components (rotations on one hemisphere, with `w >= 0`
    /// where every key's `w` has one sign).
    values: Vec<[f32; 4]>,
    /// A rotation whose `w` keeps one sign: stored as `x y z` if it can be.
    one_sign: bool,
    /// What `values` are relative to (rotations): [`PackTrack::center`].
    center: Option<[f32; 4]>,
}

impl KeyValues {
    /// Sample `clip` at its keys. The grid is the key times of the track
    /// with the most keys (the first such), which must be evenly spaced (to
    /// 1e-6 of the interval); every track with those keys is packed on it,
    /// and the others keep their own keys ([`LooseTrack`]: a reduced clip's
    /// tracks).
    pub fn sample(clip: &SourceClip) -> Result<KeyValues, PackError> {
        let Some(most) = clip.tracks().iter().max_by_key(|t| t.data.times().len()) else {
            return err("a packed clip needs a track");
        };
        // (`max_by_key` keeps the last of equals: take the first.)
        let n = most.data.times().len();
        let first = clip.tracks().iter().find(|t| t.data.times().len() == n);
        let times = first.map_or(&[][..], |t| t.data.times()).to_vec();
        if n < 2 {
            return err("a packed clip needs 2 keys or more");
        }
        let (start, interval) = (times[0], (times[n - 1] - times[0]) / (n - 1) as f64);
        let on_grid =
            |t: &f64, k: usize| (t - (start + k as f64 * interval)).abs() <= 1e-6 * interval;
        for (k, t) in times.iter().enumerate() {
            if !on_grid(t, k) {
                return err(format!(
                    "key time {t} s (number {k} of the {n} of track {}, the track with the most keys) is not on an even grid of {interval} s from {start} s: a packed clip keeps its longest tracks on one grid of evenly spaced keys (capture, baked animation); sample it on such a grid first",
                    first.map_or("", |t| t.name.as_str())
                ));
            }
        }
        let mut tracks = Vec::with_capacity(clip.tracks().len());
        let mut loose = Vec::new();
        // The grid's tracks share `pre` and `post`: the first one's.
        let mut ends = None;
        for (at, t) in clip.tracks().iter().enumerate() {
            let own = t.data.times();
            let s = t.data.settings();
            let on = own.len() == n && own.iter().enumerate().all(|(k, x)| on_grid(x, k));
            if !on || *ends.get_or_insert((s.pre, s.post)) != (s.pre, s.post) {
                loose.push(loose::LooseKeys::of(at, t)?);
                continue;
            }
            let kind = t.data.kind();
            let mut values: Vec<[f32; 4]> = own
                .iter()
                .map(|&time| {
                    let mut v = [0.0f32; 4];
                    t.data.sample_into(time, &mut v[..kind.dim()], None);
                    v
                })
                .collect();
            let mut settings = *t.data.settings();
            settings.match_speed = false;
            let mut one_sign = false;
            let mut center = None;
            if kind == TrackKind::Quat {
                settings.rotation = RotationMode::Hermite;
                // The keys are made continuous here, before rounding; kept
                // as stored, so that the reference flips none the decoder
                // does not (rounding can leave a dot product just below 0
                // between keys half a turn apart).
                settings.hemisphere = Hemisphere::Keep;
                for k in 1..n {
                    let d: f32 = (0..4).map(|c| values[k][c] * values[k - 1][c]).sum();
                    if d < 0.0 {
                        values[k] = values[k].map(|x| -x);
                    }
                }
                if !values.iter().all(|v| v[3] > 0.0) && !values.iter().all(|v| v[3] < 0.0) {
                    center = relative_to_center(&mut values);
                }
                let pos = values.iter().all(|v| v[3] > 0.0);
                let neg = values.iter().all(|v| v[3] < 0.0);
                if neg {
                    values.iter_mut().for_each(|v| *v = v.map(|x| -x));
                }
                one_sign = pos || neg;
            }
            tracks.push(TrackKeys {
                name: t.name.clone(),
                kind,
                settings,
                values,
                one_sign,
                center,
            });
        }
        Ok(KeyValues {
            name: clip.name().to_string(),
            start,
            interval,
            keys: n,
            tracks,
            loose,
        })
    }

    /// Tracks, on the grid and not.
    pub fn track_count(&self) -> usize {
        self.tracks.len() + self.loose.len()
    }

    /// Keys of the grid.
    pub fn grid_keys(&self) -> usize {
        self.keys
    }

    /// Track `i` (file order): on the grid (its index there) or loose.
    fn which(&self, i: usize) -> Result<usize, &loose::LooseKeys> {
        match self.loose.binary_search_by_key(&i, |l| l.at) {
            Ok(j) => Err(&self.loose[j]),
            Err(before) => Ok(i - before),
        }
    }

    /// Track `i`'s largest magnitude over its components and keys (file
    /// order).
    pub fn largest(&self, i: usize) -> f32 {
        let t = match self.which(i) {
            Ok(g) => &self.tracks[g],
            Err(l) => return l.largest(),
        };
        let dim = t.kind.dim();
        t.values
            .iter()
            .flat_map(|v| v[..dim].iter().map(|x| x.abs()))
            .fold(0.0, f32::max)
    }

    /// Quantize: track `i` in steps of `steps[i]`; a rotation whose `w`
    /// keeps one sign stores `x y z` unless its rounded keys would leave one
    /// hemisphere.
    pub fn quantize(&self, steps: &[f32]) -> Result<PackSource, PackError> {
        self.quantize_scaled(steps, &BlockScales::default())
    }

    /// [`quantize`](Self::quantize), the grid's steps in each block times
    /// its factor in `scales`.
    pub fn quantize_scaled(
        &self,
        steps: &[f32],
        scales: &BlockScales,
    ) -> Result<PackSource, PackError> {
        if steps.len() != self.track_count() {
            return err(format!(
                "{} steps for {} tracks",
                steps.len(),
                self.track_count()
            ));
        }
        let mut tracks = Vec::with_capacity(self.tracks.len());
        let mut loose = Vec::with_capacity(self.loose.len());
        for (i, &step) in steps.iter().enumerate() {
            let t = match self.which(i) {
                Ok(g) => &self.tracks[g],
                Err(l) => {
                    loose.push(l.quantize(step)?);
                    continue;
                }
            };
            let q = |k: usize, x: f32| {
                let step = scales.step(step, k);
                let v = (f64::from(x) / f64::from(step)).round();
                if v.abs() >= f64::from(MAX_INT) || v.is_nan() {
                    Err(PackError(format!(
                        "track {}: step {step} is too fine for {x}",
                        t.name
                    )))
                } else {
                    Ok(v as i32)
                }
            };
            let ints = |stored: usize| {
                (0..stored)
                    .map(|c| {
                        t.values
                            .iter()
                            .enumerate()
                            .map(|(k, v)| q(k, v[c]))
                            .collect::<Result<Vec<i32>, _>>()
                    })
                    .collect::<Result<Vec<_>, _>>()
            };
            let xyz = if t.one_sign { Some(ints(3)?) } else { None };
            let (rebuild_w, values) = match xyz {
                Some(xyz) if one_hemisphere(&xyz, step, scales) => (true, xyz),
                _ => (false, ints(t.kind.dim())?),
            };
            tracks.push(PackTrack {
                name: t.name.clone(),
                kind: t.kind,
                settings: t.settings,
                tcb: Tcb::DEFAULT,
                step,
                rebuild_w,
                center: t.center,
                values,
            });
        }
        let source = PackSource {
            name: self.name.clone(),
            start: self.start,
            interval: self.interval,
            keys: self.keys,
            tracks,
            scales: scales.clone().canonical(),
            loose,
        };
        source.validate_head()?;
        Ok(source)
    }
}

/// The smallest `w` [`relative_to_center`] accepts: nearer 0, rebuilding
/// `w` would multiply the quantization error by more than 20.
const CENTER_MIN_W: f64 = 0.05;

/// The keys (continuous, unit) of a rotation whose `w` changes sign (which
/// would store all four components) relative to their normalized mean
/// `r`: each becomes `conj(r) q` (f64, rounded to f32), and `r` (in f32,
/// as the decoder multiplies by it) is returned, where every `w` is then
/// at least [`CENTER_MIN_W`]. Else the keys are left as they are. (Only
/// there: centering every rotation that turns far from the identity saved
/// 0.6% of CMU 01_01's bytes and cost the decoder 14% more instructions,
/// docs/tcbc.md.)
fn relative_to_center(values: &mut [[f32; 4]]) -> Option<[f32; 4]> {
    let mut mean = [0.0f64; 4];
    for v in values.iter() {
        for c in 0..4 {
            mean[c] += f64::from(v[c]);
        }
    }
    let norm = mean.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return None;
    }
    let r = mean.map(|x| (x / norm) as f32);
    let r64 = r.map(f64::from);
    let norm = r64.iter().map(|x| x * x).sum::<f64>().sqrt();
    let conj = [
        -r64[0] / norm,
        -r64[1] / norm,
        -r64[2] / norm,
        r64[3] / norm,
    ];
    let moved: Vec<[f64; 4]> = values
        .iter()
        .map(|v| tcb_core::quat::mul(&conj, &v.map(f64::from)))
        .collect();
    if moved.iter().any(|q| q[3] < CENTER_MIN_W) {
        return None;
    }
    for (v, q) in values.iter_mut().zip(&moved) {
        *v = q.map(|x| x as f32);
    }
    Some(r)
}

/// Whether a rotation stored as `x y z` (integers per component, `w`
/// rebuilt) keeps one hemisphere from key to key, as the track keeps its
/// keys (dot products in f64): else the track would flip a key, and it
/// stores all four components.
fn one_hemisphere(xyz: &[Vec<i32>], step: f32, scales: &BlockScales) -> bool {
    let key = |k: usize| {
        let step = scales.step(step, k);
        let [x, y, z] = [0, 1, 2].map(|c| dequantize(xyz[c][k], step));
        [x, y, z, tcb_core::quat::rebuild_w(x, y, z)].map(f64::from)
    };
    let mut prev = key(0);
    for k in 1..xyz[0].len() {
        let q = key(k);
        if (0..4).map(|c| prev[c] * q[c]).sum::<f64>() < 0.0 {
            return false;
        }
        prev = q;
    }
    true
}

/// A block size the format takes.
pub(crate) fn check_block(block: usize) -> Result<(), PackError> {
    if !(SEGMENT_KEYS..=MAX_BLOCK_KEYS).contains(&block) || !block.is_multiple_of(SEGMENT_KEYS) {
        return err(format!(
            "blocks of {block} keys: a multiple of {SEGMENT_KEYS} up to {MAX_BLOCK_KEYS}"
        ));
    }
    Ok(())
}

/// The tangent rule's chord weights of `t` at key `k` of `times`, rounded to
/// f32 as `tcb_core::Vector::scale` rounds them: `[in_a, in_b, out_a, out_b]`.
pub(crate) fn key_weights(times: &[f64], t: &PackTrack, k: usize) -> [f32; 4] {
    chord_weights(t, times[k] - times[k - 1], times[k + 1] - times[k])
}

/// [`key_weights`] of a key between intervals `d_in` and `d_out`.
fn chord_weights(t: &PackTrack, d_in: f64, d_out: f64) -> [f32; 4] {
    use tcb_core::tangent::ChordWeights;
    let s = &t.settings;
    let cw = if s.continuity_fade {
        ChordWeights::with_continuity_fade(s.tangent_rule, t.tcb, d_in, d_out)
    } else {
        ChordWeights::new(s.tangent_rule, t.tcb, d_in, d_out)
    };
    [cw.in_a, cw.in_b, cw.out_a, cw.out_b].map(|x| x as f32)
}

/// The distinct `(d_in, d_out)` pairs of a grid's interior keys (their f64
/// intervals differ in their last bits far from 0), each with the first key
/// that has it: a track's weights are checked once per pair, not per key.
struct Intervals {
    /// `(d_in, d_out, first key)`, key 1's first.
    pairs: Vec<(f64, f64, usize)>,
}

impl Intervals {
    /// Of `keys` keys at times `time(k)` (not a list: a loader allocates
    /// per distinct pair, not per key).
    fn of(keys: usize, time: impl Fn(usize) -> f64) -> Intervals {
        let mut seen = std::collections::HashMap::new();
        let mut pairs = Vec::new();
        for k in 1..keys.saturating_sub(1) {
            let (before, at, after) = (time(k - 1), time(k), time(k + 1));
            let (d_in, d_out) = (at - before, after - at);
            seen.entry((d_in.to_bits(), d_out.to_bits()))
                .or_insert_with(|| {
                    pairs.push((d_in, d_out, k));
                });
        }
        Intervals { pairs }
    }

    /// The first interior key whose weights differ from key 1's (every rule
    /// but `uniform` weighs by the intervals), or `None`.
    fn uneven_weights(&self, t: &PackTrack) -> Option<usize> {
        if t.settings.tangent_rule == TangentRule::Uniform {
            return None;
        }
        let (&(d_in, d_out, _), rest) = self.pairs.split_first()?;
        let first = chord_weights(t, d_in, d_out);
        rest.iter()
            .filter(|(i, o, _)| chord_weights(t, *i, *o) != first)
            .map(|p| p.2)
            .min()
    }
}

/// `n` keys with `tcb` (none: the defaults).
fn key_params<V: Copy>(tcb: Tcb, n: usize) -> Vec<KeyParams<V>> {
    if tcb == Tcb::DEFAULT {
        return Vec::new();
    }
    let key = KeyParams {
        tcb,
        ..KeyParams::default()
    };
    vec![key; n]
}

/// A width's coding in each lane of `w` (widths 0 to 31): the low `w`
/// bits, which hold a residual, and what the residual is stored above,
/// `2^(w - 1)` (0 for width 0, nothing stored). A residual `r` of width
/// `w` is stored as `r + bias` in `0 .. 2^w` (the range of a zigzag code
/// of `w` bits): the decoder subtracts it 8 lanes at a time, where undoing
/// a zigzag code takes four operations. The encoder runs this on `i32`,
/// the decoder on a plane's widths (`wide::i32x8`, or the AVX2 instance's
/// `I8`).
#[inline(always)]
pub(crate) fn width_lanes<I: BitLanes>(w: I) -> (I, I) {
    let bit = I::ONE.shl_each(w);
    (bit.sub_wrapping(I::ONE), bit.half())
}

/// Bits a zigzag-coded value takes.
fn bits_of(z: u32) -> u32 {
    32 - z.leading_zeros()
}

fn zigzag(x: i32) -> u32 {
    ((x << 1) ^ (x >> 31)) as u32
}

#[inline(always)]
pub(crate) fn unzigzag(z: u32) -> i32 {
    unzigzag_lanes(z as i32)
}

/// [`zigzag`] undone in each lane of `z` (the code's bits as `i32`).
#[inline(always)]
pub(crate) fn unzigzag_lanes<I: BitLanes>(z: I) -> I {
    z.half() ^ (I::ZERO - (z & I::ONE))
}

/// Integer lanes [`unzigzag_lanes`] and [`width_lanes`] run on: `i32`,
/// `wide::i32x8` and the AVX2 instance's `I8` (wrapping arithmetic).
pub(crate) trait BitLanes:
    Copy
    + std::ops::BitAnd<Output = Self>
    + std::ops::BitXor<Output = Self>
    + std::ops::Sub<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    /// `x` in every lane.
    fn splat(x: i32) -> Self;
    /// Each lane shifted right by `N` bits, as unsigned.
    fn shr<const N: u32>(self) -> Self;
    /// Each lane shifted right by one bit, as unsigned.
    fn half(self) -> Self;
    /// Each lane shifted left by the bits in the same lane of `n` (0 to
    /// 31).
    fn shl_each(self, n: Self) -> Self;
    /// `self - o`, wrapping in every build (`i32`'s `-` checks in debug).
    fn sub_wrapping(self, o: Self) -> Self;
}

impl BitLanes for i32 {
    const ZERO: i32 = 0;
    const ONE: i32 = 1;
    #[inline(always)]
    fn splat(x: i32) -> i32 {
        x
    }
    #[inline(always)]
    fn shr<const N: u32>(self) -> i32 {
        ((self as u32) >> N) as i32
    }
    #[inline(always)]
    fn half(self) -> i32 {
        self.shr::<1>()
    }
    #[inline(always)]
    fn shl_each(self, n: i32) -> i32 {
        self.wrapping_shl(n as u32)
    }
    #[inline(always)]
    fn sub_wrapping(self, o: i32) -> i32 {
        self.wrapping_sub(o)
    }
}

impl BitLanes for wide::i32x8 {
    const ZERO: Self = wide::i32x8::ZERO;
    const ONE: Self = wide::i32x8::ONE;
    #[inline(always)]
    fn splat(x: i32) -> Self {
        wide::i32x8::splat(x)
    }
    #[inline(always)]
    fn shr<const N: u32>(self) -> Self {
        let u: wide::u32x8 = bytemuck::cast(self);
        bytemuck::cast(u >> N)
    }
    #[inline(always)]
    fn half(self) -> Self {
        self.shr::<1>()
    }
    #[inline(always)]
    fn shl_each(self, n: Self) -> Self {
        let (u, n): (wide::u32x8, wide::u32x8) = (bytemuck::cast(self), bytemuck::cast(n));
        bytemuck::cast(u << n)
    }
    #[inline(always)]
    fn sub_wrapping(self, o: Self) -> Self {
        self - o
    }
}

impl BitLanes for tcb_core::simd::w8::I8 {
    const ZERO: Self = tcb_core::simd::w8::I8([0; 8]);
    const ONE: Self = tcb_core::simd::w8::I8([1; 8]);
    #[inline(always)]
    fn splat(x: i32) -> Self {
        tcb_core::simd::w8::I8([x; 8])
    }
    #[inline(always)]
    fn shr<const N: u32>(self) -> Self {
        self.shr_logical::<N>()
    }
    #[inline(always)]
    fn half(self) -> Self {
        self.shr_logical::<1>()
    }
    #[inline(always)]
    fn shl_each(self, n: Self) -> Self {
        self.shl_each(n)
    }
    #[inline(always)]
    fn sub_wrapping(self, o: Self) -> Self {
        self - o
    }
}

/// Bits written least significant first.
struct BitWriter {
    bytes: Vec<u8>,
    bits: usize,
}

impl BitWriter {
    fn put(&mut self, v: u32, w: u32) {
        debug_assert!(w <= 32 && (w == 32 || v >> w == 0));
        for i in 0..w {
            if self.bits.is_multiple_of(8) {
                self.bytes.push(0);
            }
            let bit = (v >> i) & 1;
            *self.bytes.last_mut().expect("pushed above") |= (bit as u8) << (self.bits % 8);
            self.bits += 1;
        }
    }
}

/// Per lane, the widths of its blocks' start values and deltas (the
/// largest over the clip's blocks).
fn block_start_widths(lanes: &[&Vec<i32>], n: usize, block: usize) -> (Vec<u8>, Vec<u8>) {
    let mut abs_bits = vec![0u8; lanes.len()];
    let mut delta_bits = vec![0u8; lanes.len()];
    for (l, x) in lanes.iter().enumerate() {
        for b in (0..n).step_by(block) {
            abs_bits[l] = abs_bits[l].max(bits_of(zigzag(code(x, b, 2, block))) as u8);
            if b + 1 < n {
                delta_bits[l] = delta_bits[l].max(bits_of(zigzag(code(x, b + 1, 2, block))) as u8);
            }
        }
    }
    (abs_bits, delta_bits)
}

/// Per lane, the prediction order whose residuals over the segment of
/// `keys` take fewer bits (2 on a tie), and that width.
fn segment_orders(lanes: &[&Vec<i32>], keys: Range<usize>, block: usize) -> Vec<(u32, u32)> {
    let width = |x: &[i32], order| {
        keys.clone()
            .filter(|k| k % block >= 2)
            .map(|k| bits_of(zigzag(code(x, k, order, block))))
            .max()
            .unwrap_or(0)
    };
    lanes
        .iter()
        .map(|x| {
            let (w2, w1) = (width(x, 2), width(x, 1));
            if w1 < w2 { (1, w1) } else { (2, w2) }
        })
        .collect()
}

/// A bit position as the segment table keeps it.
fn bit_offset(bits: usize) -> Result<u32, PackError> {
    u32::try_from(bits).map_err(|_| PackError("the packed stream exceeds 2^32 bits".into()))
}

/// The one error of a stream that stops before its values do.
fn ends_early<T>() -> Result<T, PackError> {
    err("the packed stream ends early")
}

/// `w` bits (at most 32) at bit `pos` of `words` (bit `p` is bit `p % 64`
/// of word `p / 64`), which end with two words of padding.
#[inline(always)]
pub(crate) fn read_bits(words: &[u64], pos: usize, w: u32) -> u32 {
    (window(words, pos) & ((1u64 << w) - 1)) as u32
}

/// The 64 bits from bit `pos` on.
#[inline(always)]
pub(crate) fn window(words: &[u64], pos: usize) -> u64 {
    let (i, o) = (pos >> 6, (pos & 63) as u32);
    let pair = &words[i..i + 2];
    (pair[0] >> o) | ((pair[1] << 1) << (63 - o))
}

/// Words of zeros after a stream's: the runtime's decoder reads 16 values
/// of up to 31 bits from any bit of the stream (`store::unpack16`), in
/// 64-bit windows of two words.
pub(crate) const STREAM_PAD: usize = 10;

/// Bytes (little-endian, padded with zeros) as words, plus
/// [`STREAM_PAD`] words of padding.
pub(crate) fn to_words(bytes: &[u8]) -> Vec<u64> {
    // Sized once: the stream is the largest thing a loader allocates.
    let mut words = Vec::with_capacity(bytes.len().div_ceil(8) + STREAM_PAD);
    words.extend(bytes.chunks(8).map(|c| {
        let mut b = [0u8; 8];
        b[..c.len()].copy_from_slice(c);
        u64::from_le_bytes(b)
    }));
    words.extend([0; STREAM_PAD]);
    words
}

/// The encoded clip (see the module docs): the description without its
/// integers, per lane the widths of block starts, per segment its first
/// bit, and the stream.
#[derive(Clone, Debug, PartialEq)]
pub struct Packed {
    pub(crate) head: PackSource,
    /// Keys per block.
    pub(crate) block: usize,
    /// Per lane: bits of the zigzag absolute value and delta at block starts.
    pub(crate) abs_bits: Vec<u8>,
    pub(crate) delta_bits: Vec<u8>,
    /// Per lane: the width its header codes against at a block's start.
    pub(crate) base_width: Vec<u8>,
    /// Per block its first bit (kept in the file, so that what a reader
    /// allocates for it is part of what it read).
    pub(crate) block_at: Vec<u32>,
    /// The stream's length in bits.
    pub(crate) bits: usize,
    /// The bits as words, then two words of zeros; its length in bytes.
    pub(crate) stream: Vec<u64>,
    pub(crate) stream_len: usize,
    /// What made it (`tcb compress`'s options and measured error), for
    /// `tcb info`: free text, kept in the file.
    pub note: String,
    /// The skeleton the clip animates, if it has one (`tcb compress` keeps
    /// the input's): kept in the file, so that a `.tcbc` plays on its
    /// figure alone.
    pub skeleton: Option<tcb_core::skeleton::Skeleton>,
}

/// Per key of a block, the integer a lane codes: the block's first value,
/// its delta, then the residual of the prediction of `order` (1: the last
/// value; 2: the line through the last two).
#[inline(always)]
fn code(x: &[i32], k: usize, order: u32, block: usize) -> i32 {
    match (k % block, order) {
        (0, _) => x[k],
        (1, _) | (_, 1) => x[k].wrapping_sub(x[k - 1]),
        _ => x[k]
            .wrapping_sub(x[k - 1].wrapping_mul(2))
            .wrapping_add(x[k - 2]),
    }
}

/// A lane's base width that says it has no headers: every segment of it
/// is coded with width 0 on the line through its last two values (order
/// 2), a line per block (constant tracks, above all).
pub(crate) const FLAT: u8 = 1 << WIDTH_BITS;

/// Per lane, the width that makes the headers of the blocks' first
/// segments (`chosen` per segment, `every` segments a block) shortest, or
/// [`FLAT`].
fn base_widths(chosen: &[Vec<(u32, u32)>], every: usize, lanes: usize) -> Vec<u8> {
    (0..lanes)
        .map(|l| {
            if chosen.iter().all(|c| c[l] == (2, 0)) {
                return FLAT;
            }
            let cost = |b: u32| -> usize {
                chosen
                    .iter()
                    .step_by(every)
                    .map(|c| width_code_bits(c[l].1, b))
                    .sum()
            };
            (0..1u32 << WIDTH_BITS)
                .min_by_key(|&b| cost(b))
                .unwrap_or(0) as u8
        })
        .collect()
}

/// A component's width code ([`put_headers`]) for `width` after `before`:
/// 0 the same, 1 one more, 2 one less, 3 another (given whole).
fn width_code(width: u32, before: u32) -> u32 {
    match width.abs_diff(before) {
        0 => 0,
        1 if width > before => 1,
        1 => 2,
        _ => 3,
    }
}

/// Bits of [`width_code`] for `width` after `before`, with the width
/// given whole (the order bit aside).
fn width_code_bits(width: u32, before: u32) -> usize {
    2 + if width_code(width, before) == 3 {
        WIDTH_BITS as usize
    } else {
        0
    }
}

/// Components per header group: a segment's headers come 8 components at
/// a time, each group's fixed part read with one 64-bit window.
pub(crate) const GROUP: usize = 8;

/// A segment's headers ([`Packed::encode_with`]): `headers` holds per
/// component with headers, in the stream's order, `(order, width, width
/// before)`. In groups of 8 (the last maybe fewer, `k`), each group's
/// fixed part: `k` bits of prediction orders (bit `i` is component `i`'s,
/// 0 for order 2, 1 for order 1), then `k` 2-bit width codes against the
/// component's width in the segment before (at a block's start, where a
/// seek starts, its base width): 0 the same, 1 one more, 2 one less, 3
/// another. Then, after every group's fixed part, the widths of the codes
/// 3 in [`WIDTH_BITS`] bits each, in component order. A group's fixed part
/// lies `3 x` the components before it after the first, so that the groups
/// read without waiting for each other.
fn put_headers(w: &mut BitWriter, headers: &[(u32, u32, u32)]) {
    for group in headers.chunks(GROUP) {
        for &(order, _, _) in group {
            w.put(2 - order, 1);
        }
        for &(_, width, before) in group {
            w.put(width_code(width, before), 2);
        }
    }
    for &(_, width, before) in headers {
        if width_code(width, before) == 3 {
            w.put(width, WIDTH_BITS);
        }
    }
}

/// Eight byte lanes in a `u64`: lane `i` is byte `i` (little-endian).
pub(crate) const BYTES: u64 = 0x0101_0101_0101_0101;

/// Bit `i` of `x` (`i < 8`) into byte `i`.
#[inline(always)]
fn spread1(x: u64) -> u64 {
    let x = (x | (x << 28)) & 0x0000_000f_0000_000f;
    let x = (x | (x << 14)) & 0x0003_0003_0003_0003;
    (x | (x << 7)) & BYTES
}

/// The 2-bit field `i` of `x` (`i < 8`) into byte `i`.
#[inline(always)]
fn spread2(x: u64) -> u64 {
    let x = (x | (x << 24)) & 0x0000_00ff_0000_00ff;
    let x = (x | (x << 12)) & 0x000f_000f_000f_000f;
    (x | (x << 6)) & (3 * BYTES)
}

/// How [`header_group`] spreads bit fields into bytes: [`Portable`]'s
/// shifts and masks, or BMI2's `pdep` in the decoder's instances (the
/// same function: their tests compare every input).
pub(crate) trait Spread {
    /// Bit `i` of `x` (`i < 8`) into byte `i`.
    fn spread1(x: u64) -> u64;
    /// The 2-bit field `i` of `x` (`i < 8`) into byte `i`.
    fn spread2(x: u64) -> u64;
    /// The widths coded whole, `WIDTH_BITS` each from the low bits of
    /// `tails`, one per byte where `whole` has 1, in order (`pdep` into
    /// those bytes' low bits).
    fn whole_widths(tails: u64, whole: u64) -> u64;
}

/// [`Spread`] in shifts and masks, on any CPU.
pub(crate) struct Portable;

impl Spread for Portable {
    #[inline(always)]
    fn spread1(x: u64) -> u64 {
        spread1(x)
    }
    #[inline(always)]
    fn spread2(x: u64) -> u64 {
        spread2(x)
    }
    #[inline(always)]
    fn whole_widths(tails: u64, whole: u64) -> u64 {
        let (mut given, mut tails, mut lanes) = (0, tails, whole);
        while lanes != 0 {
            given |= (tails & ((1 << WIDTH_BITS) - 1)) << lanes.trailing_zeros();
            tails >>= WIDTH_BITS;
            lanes &= lanes - 1;
        }
        given
    }
}

/// One header group as read ([`header_group`]), a byte per component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HeaderGroup {
    /// Widths (a byte above 31 is a width out of range: the reader checks).
    pub width: u64,
    /// 1 where the prediction order is 1, 0 where it is 2.
    pub order1: u64,
    /// The widths it took from the widths coded whole.
    pub whole: usize,
}

/// The headers of a group of `k` components ([`put_headers`]): its fixed
/// part in the low bits of `fixed`, the widths coded whole from the low
/// bits of `tails` on, the components' widths before in the bytes of
/// `before` (each at most 63; 0 in bytes `k..`, which stay 0). Eight
/// lanes at a time in the bytes of a `u64`, by shifts, masks and adds, and
/// a step per width coded whole: the one rule of the reference reader and
/// of both decoders.
#[inline(always)]
pub(crate) fn header_group<S: Spread>(
    fixed: u64,
    tails: u64,
    k: usize,
    before: u64,
) -> HeaderGroup {
    debug_assert!((1..=GROUP).contains(&k));
    let order1 = S::spread1(fixed & ((1 << k) - 1));
    let code = S::spread2((fixed >> k) & ((1 << (2 * k)) - 1));
    let (lo, hi) = (code & BYTES, (code >> 1) & BYTES);
    let whole = lo & hi;
    // Codes 1 and 2 (one more, one less), each byte kept from its
    // neighbours by a top bit set before and cleared after.
    let top = 0x80 * BYTES;
    let near = (((before | top) + (lo ^ whole)) - (hi ^ whole)) ^ top;
    // Code 3: the widths coded whole, one per such lane in order.
    let given = S::whole_widths(tails, whole);
    HeaderGroup {
        width: (near & !(0xff * whole)) | given,
        order1,
        whole: whole.count_ones() as usize,
    }
}

impl Packed {
    /// Encode `source` (validated first) in blocks of [`BLOCK_KEYS`].
    pub fn encode(source: &PackSource) -> Result<Packed, PackError> {
        Packed::encode_with(source, BLOCK_KEYS)
    }

    /// Encode `source` in blocks of `block` keys (a multiple of
    /// [`SEGMENT_KEYS`], at most [`MAX_BLOCK_KEYS`]): a seek decodes up to
    /// `block - 1` keys; smaller blocks seek faster and take more bytes.
    /// Factors on the steps ([`PackSource::scales`]) must be per `block`
    /// keys.
    pub fn encode_with(source: &PackSource, block: usize) -> Result<Packed, PackError> {
        check_block(block)?;
        source.validate()?;
        if source.scales.codes.iter().any(|c| *c > 0) && source.scales.keys != block {
            return err(format!(
                "step factors per {} keys for blocks of {block}",
                source.scales.keys
            ));
        }
        let n = source.keys;
        let lanes: Vec<&Vec<i32>> = source.tracks.iter().flat_map(|t| t.values.iter()).collect();
        let (abs_bits, delta_bits) = block_start_widths(&lanes, n, block);
        let chosen: Vec<Vec<(u32, u32)>> = (0..n)
            .step_by(SEGMENT_KEYS)
            .map(|s| segment_orders(&lanes, s..(s + SEGMENT_KEYS).min(n), block))
            .collect();
        let base_width = base_widths(&chosen, block / SEGMENT_KEYS, lanes.len());
        let mut w = BitWriter {
            bytes: Vec::new(),
            bits: 0,
        };
        let mut block_at = Vec::with_capacity(n.div_ceil(block));
        let mut widths = vec![0u32; lanes.len()];
        for (s, chosen) in (0..n).step_by(SEGMENT_KEYS).zip(&chosen) {
            if s % block == 0 {
                block_at.push(bit_offset(w.bits)?);
            }
            let mut headers = Vec::with_capacity(chosen.len());
            for (l, &(order, wd)) in chosen.iter().enumerate() {
                if wd >= 1 << WIDTH_BITS {
                    return err("a residual needs more than 31 bits");
                }
                if base_width[l] == FLAT {
                    continue;
                }
                let before = if s % block == 0 {
                    base_width[l].into()
                } else {
                    widths[l]
                };
                headers.push((order, wd, before));
                widths[l] = wd;
            }
            put_headers(&mut w, &headers);
            if s % block == 0 {
                for (l, x) in lanes.iter().enumerate() {
                    w.put(zigzag(code(x, s, 2, block)), u32::from(abs_bits[l]));
                }
                for (l, x) in lanes.iter().enumerate() {
                    let d = if s + 1 < n {
                        zigzag(code(x, s + 1, 2, block))
                    } else {
                        0
                    };
                    w.put(d, u32::from(delta_bits[l]));
                }
            }
            // Lane by lane: a lane's residuals of the segment are contiguous.
            let end = (s + SEGMENT_KEYS).min(n);
            for (x, &(order, wd)) in lanes.iter().zip(chosen) {
                let (low, bias) = width_lanes(wd as i32);
                for k in (s..end).filter(|k| k % block >= 2) {
                    let stored = code(x, k, order, block).wrapping_add(bias);
                    w.put((stored & low) as u32, wd);
                }
            }
        }
        let bits = w.bits;
        bit_offset(bits)?;
        let stream_len = w.bytes.len();
        let stream = to_words(&w.bytes);
        let mut head = source.clone();
        for t in &mut head.tracks {
            t.values = Vec::new();
        }
        head.scales = head.scales.canonical();
        Ok(Packed {
            head,
            block,
            abs_bits,
            delta_bits,
            base_width,
            block_at,
            bits,
            stream,
            stream_len,
            note: String::new(),
            skeleton: None,
        })
    }

    /// Decode every key: the description in integers (also the check of a
    /// file read: every width, length and integer is validated).
    pub fn decode(&self) -> Result<PackSource, PackError> {
        let n = self.head.keys;
        let mut x: Vec<Vec<i32>> = (0..self.abs_bits.len())
            .map(|_| Vec::with_capacity(n))
            .collect();
        self.walk(0..self.segments(), Some(&mut x))?;
        let mut source = self.head.clone();
        let mut lanes = x.into_iter();
        for t in &mut source.tracks {
            t.values = lanes.by_ref().take(t.stored()).collect();
        }
        source.validate()?;
        Ok(source)
    }

    /// The stream's length in bits, from its structure walked from bit 0
    /// without decoding a key: every segment's headers checked (widths in
    /// range), every block starting where the block table says, and the
    /// stream's bytes just enough for its bits. What a reader needs for the
    /// runtime never to read past the stream or take a width of 32 bits or
    /// more; the integers themselves are [`decode`](Self::decode)'s to
    /// check. Allocates per lane, not per key.
    pub(crate) fn stream_structure(&self) -> Result<usize, PackError> {
        let (n, lanes) = (self.head.keys, self.abs_bits.len());
        let (mut widths, mut orders) = (vec![0u32; lanes], vec![2u32; lanes]);
        let per_block = self.block / SEGMENT_KEYS;
        if self.block_at.len() != n.div_ceil(self.block) {
            return err(format!(
                "{} block offsets for {} blocks",
                self.block_at.len(),
                n.div_ceil(self.block)
            ));
        }
        let mut pos = 0;
        // A stream that ends early says how many keys it was to hold.
        let short = |e: PackError| {
            if e.0 == ends_early::<()>().unwrap_err().0 {
                PackError(format!(
                    "the packed stream ends before its {n} keys of {lanes} lanes do"
                ))
            } else {
                e
            }
        };
        for j in 0..self.segments() {
            if j % per_block == 0 {
                self.check_block_at(j / per_block, pos)?;
            }
            self.segment_headers(j, &mut pos, &mut widths, &mut orders)
                .map_err(short)?;
            let s = j * SEGMENT_KEYS;
            self.skip_segment(s..(s + SEGMENT_KEYS).min(n), &widths, &mut pos)
                .map_err(short)?;
        }
        if pos.div_ceil(8) != self.stream_len {
            return err(format!(
                "the packed stream has {} bytes for {pos} bits",
                self.stream_len
            ));
        }
        Ok(pos)
    }

    /// Whether block `b` starts at bit `pos`, as the block table says.
    fn check_block_at(&self, b: usize, pos: usize) -> Result<(), PackError> {
        match self.block_at.get(b) {
            Some(&at) if at as usize == pos => Ok(()),
            at => err(format!(
                "block {b} starts at bit {pos} of the packed stream, the table says {at:?}"
            )),
        }
    }

    /// Segments of the stream (32 keys each, the last maybe fewer).
    fn segments(&self) -> usize {
        self.head.keys.div_ceil(SEGMENT_KEYS)
    }

    /// The integers of keys `at` (ascending): per stored lane, one per key
    /// of `at`, decoding only the segments that hold them (from their
    /// block's start).
    pub(crate) fn decode_keys(&self, at: &[usize]) -> Result<Vec<Vec<i32>>, PackError> {
        let lanes = self.abs_bits.len();
        let mut out: Vec<Vec<i32>> = vec![Vec::with_capacity(at.len()); lanes];
        let mut x: Vec<Vec<i32>> = vec![Vec::new(); lanes];
        let mut from = usize::MAX; // first key decoded into `x`
        for &k in at {
            if k >= self.head.keys {
                return err(format!("key {k} of {}", self.head.keys));
            }
            let have = from <= k && k < from + x[0].len();
            if !have {
                let first = k / self.block * self.block;
                let last_seg = k / SEGMENT_KEYS;
                x.iter_mut().for_each(Vec::clear);
                self.walk(first / SEGMENT_KEYS..last_seg + 1, Some(&mut x))?;
                from = first;
            }
            for (o, xl) in out.iter_mut().zip(&x) {
                o.push(xl[k - from]);
            }
        }
        Ok(out)
    }

    /// Walk segments `segs` of the stream (the first at a block's start),
    /// checking each one's headers and length against the segment table;
    /// with `x`, decoding their keys into it (per lane, from the first
    /// segment's first key), else stepping over them.
    fn walk(&self, segs: Range<usize>, mut x: Option<&mut [Vec<i32>]>) -> Result<(), PackError> {
        let n = self.head.keys;
        let lanes = self.abs_bits.len();
        let first_key = segs.start * SEGMENT_KEYS;
        debug_assert!(first_key.is_multiple_of(self.block));
        let mut widths = vec![0u32; lanes];
        let mut orders = vec![2u32; lanes];
        let per_block = self.block / SEGMENT_KEYS;
        // From the table's entry, but the stream's first segment from bit 0.
        let mut pos = if segs.start == 0 {
            0
        } else {
            self.block_at[segs.start / per_block] as usize
        };
        for j in segs.clone() {
            if j % per_block == 0 {
                self.check_block_at(j / per_block, pos)?;
            }
            self.segment_headers(j, &mut pos, &mut widths, &mut orders)?;
            let s = j * SEGMENT_KEYS;
            let keys = s..(s + SEGMENT_KEYS).min(n);
            match x.as_deref_mut() {
                Some(x) => self.segment_keys(keys, first_key, &widths, &orders, &mut pos, x)?,
                None => self.skip_segment(keys, &widths, &mut pos)?,
            }
        }
        let end = if segs.end == self.segments() {
            Some(self.bits)
        } else if segs.end.is_multiple_of(per_block) {
            self.block_at.get(segs.end / per_block).map(|&b| b as usize)
        } else {
            None
        };
        if end.is_some_and(|end| end != pos) {
            return err("the packed stream's length disagrees with its table");
        }
        Ok(())
    }

    /// Segment `j`'s headers from bit `pos`: each lane's prediction order
    /// and width (coded against the segment before, or at a block's start
    /// against the lane's base width), checked.
    fn segment_headers(
        &self,
        j: usize,
        pos: &mut usize,
        widths: &mut [u32],
        orders: &mut [u32],
    ) -> Result<(), PackError> {
        let block_start = (j * SEGMENT_KEYS).is_multiple_of(self.block);
        let headed = self.base_width.iter().filter(|&&b| b != FLAT).count();
        // The groups' fixed parts, then the widths coded whole.
        let mut at = [*pos, pos.saturating_add(3 * headed)];
        let mut group = [0usize; GROUP];
        let mut k = 0;
        for (l, &base) in self.base_width.iter().enumerate() {
            if base == FLAT {
                (orders[l], widths[l]) = (2, 0);
                continue;
            }
            if block_start {
                widths[l] = u32::from(base);
            }
            group[k] = l;
            k += 1;
            if k == GROUP {
                self.header_group_at(j, &group, &mut at, widths, orders)?;
                k = 0;
            }
        }
        if k > 0 {
            self.header_group_at(j, &group[..k], &mut at, widths, orders)?;
        }
        *pos = at[1];
        if *pos > self.stream_len * 8 {
            return ends_early();
        }
        Ok(())
    }

    /// The headers of the components `group` (lanes, at most [`GROUP`]) of
    /// segment `j`, its fixed part at bit `at[0]` and its widths coded
    /// whole from `at[1]` on (both advanced), coded against `widths`: their
    /// orders and widths, checked.
    fn header_group_at(
        &self,
        j: usize,
        group: &[usize],
        at: &mut [usize; 2],
        widths: &mut [u32],
        orders: &mut [u32],
    ) -> Result<(), PackError> {
        let bits = self.stream_len * 8;
        if at[1] > bits {
            return ends_early();
        }
        let mut before = [0u8; GROUP];
        for (b, &l) in before.iter_mut().zip(group) {
            // A base width above 32 is the file's error; as a width it is
            // out of range below.
            *b = widths[l].min(63) as u8;
        }
        let (fixed, tails) = (window(&self.stream, at[0]), window(&self.stream, at[1]));
        let read = header_group::<Portable>(fixed, tails, group.len(), u64::from_le_bytes(before));
        let (width, order1) = (read.width.to_le_bytes(), read.order1.to_le_bytes());
        for (i, &l) in group.iter().enumerate() {
            if width[i] >= 1 << WIDTH_BITS {
                return err(format!("segment {j}: a width out of range"));
            }
            (orders[l], widths[l]) = (2 - u32::from(order1[i]), u32::from(width[i]));
        }
        at[0] += 3 * group.len();
        at[1] += WIDTH_BITS as usize * read.whole;
        Ok(())
    }

    /// Keys of a segment coded as residuals (not a block's first two).
    fn residual_keys(&self, keys: &Range<usize>) -> usize {
        keys.clone().filter(|k| k % self.block >= 2).count()
    }

    /// Step `pos` over the values of the segment of `keys`, checked.
    fn skip_segment(
        &self,
        keys: Range<usize>,
        widths: &[u32],
        pos: &mut usize,
    ) -> Result<(), PackError> {
        let rows = self.residual_keys(&keys);
        let mut skip = widths.iter().map(|w| *w as usize * rows).sum::<usize>();
        if keys.start.is_multiple_of(self.block) {
            let sum = |b: &[u8]| b.iter().map(|b| usize::from(*b)).sum::<usize>();
            skip += sum(&self.abs_bits) + sum(&self.delta_bits);
        }
        *pos += skip;
        if *pos > self.stream_len * 8 {
            return ends_early();
        }
        Ok(())
    }

    /// Decode the values of the segment of `keys` from bit `pos` onto each
    /// lane of `x` (whose first entry is key `first_key`): a block's start
    /// values and deltas, then the residuals on the prediction.
    fn segment_keys(
        &self,
        keys: Range<usize>,
        first_key: usize,
        widths: &[u32],
        orders: &[u32],
        pos: &mut usize,
        x: &mut [Vec<i32>],
    ) -> Result<(), PackError> {
        let (n, bits) = (self.head.keys, self.stream_len * 8);
        let s = keys.start;
        let mut take = |w: u32| -> Result<u32, PackError> {
            if *pos + w as usize > bits {
                return ends_early();
            }
            let v = read_bits(&self.stream, *pos, w);
            *pos += w as usize;
            Ok(v)
        };
        if s.is_multiple_of(self.block) {
            for (l, xl) in x.iter_mut().enumerate() {
                xl.push(unzigzag(take(u32::from(self.abs_bits[l]))?));
            }
            for (l, xl) in x.iter_mut().enumerate() {
                let d = unzigzag(take(u32::from(self.delta_bits[l]))?);
                if s + 1 < n {
                    let v = xl[s - first_key].wrapping_add(d);
                    xl.push(v);
                }
            }
        }
        for (l, xl) in x.iter_mut().enumerate() {
            for k in keys.clone().filter(|k| k % self.block >= 2) {
                let r = (take(widths[l])? as i32).wrapping_sub(width_lanes(widths[l] as i32).1);
                let i = k - first_key;
                let trend = if orders[l] == 2 {
                    xl[i - 1].wrapping_sub(xl[i - 2])
                } else {
                    0
                };
                let v = xl[i - 1].wrapping_add(trend).wrapping_add(r);
                xl.push(v);
            }
        }
        Ok(())
    }

    /// Keys per block (a seek decodes up to this many less one).
    pub fn block_keys(&self) -> usize {
        self.block
    }

    /// The description (integers not included).
    pub fn head(&self) -> &PackSource {
        &self.head
    }

    /// Bytes of the encoded stream and its tables (what a runtime keeps).
    pub fn stream_bytes(&self) -> usize {
        8 * self.stream.len()
            + 4 * self.block_at.len()
            + self.head.scales.codes.len()
            + 3 * self.abs_bits.len()
    }

    /// Bits of the residuals, widths and block starts.
    pub fn stream_bits(&self) -> usize {
        self.bits
    }
}

/// The first 8 bytes of a `.tcbc` file.
pub const MAGIC: [u8; 8] = *b"TCBC\0\r\n\x1a";
/// The format version this build writes and reads (version 8: a factor
/// on the grid's steps per block of keys; version 7: a
/// segment's headers in groups of 8 components, of fixed-length codes;
/// version 6: tracks on key times of their own beside the grid's; version 5: a table of
/// where each block starts; version 4: rotations whose `w` changes sign
/// kept relative to a center, constant components without headers; older
/// versions are refused with a one-line error).
pub const VERSION: u32 = 8;

mod file;
mod loose;
pub(crate) mod store;

#[cfg(test)]
mod tests {
    use super::{BitWriter, GROUP, Portable, WIDTH_BITS, header_group, put_headers, width_lanes};
    use tcb_core::simd::w8::I8;

    /// Headers of 1 to 24 components (up to 3 groups), as written, read
    /// back group by group: every code, up to 8 widths coded whole in a
    /// group (40 bits of them).
    #[test]
    fn a_header_group_reads_back_as_written() {
        let mut seed = 0x9e37_79b9_u32;
        let mut next = |m: u32| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed % m
        };
        for case in 0..4000 {
            let n = 1 + case % (3 * GROUP);
            let headers: Vec<(u32, u32, u32)> = (0..n)
                .map(|_| {
                    let before = next(32);
                    let width = match next(4) {
                        0 => before,
                        1 => (before + 1).min(31),
                        2 => before.saturating_sub(1),
                        _ if case % 7 == 0 => (before + 2 + next(29)) % 32,
                        _ => next(32),
                    };
                    (1 + next(2), width, before)
                })
                .collect();
            let mut w = BitWriter {
                bytes: Vec::new(),
                bits: 0,
            };
            w.put(next(1 << 9), 9);
            put_headers(&mut w, &headers);
            let written = w.bits - 9;
            w.put(u32::MAX, 32);
            let words = super::to_words(&w.bytes);
            let mut at = [9, 9 + 3 * n];
            for group in headers.chunks(GROUP) {
                let k = group.len();
                let mut before = [0; 8];
                for (b, h) in before.iter_mut().zip(group) {
                    *b = h.2 as u8;
                }
                let (fixed, tails) = (super::window(&words, at[0]), super::window(&words, at[1]));
                let read = header_group::<Portable>(fixed, tails, k, u64::from_le_bytes(before));
                let (o, wd) = (read.order1.to_le_bytes(), read.width.to_le_bytes());
                for (i, h) in group.iter().enumerate() {
                    assert_eq!((o[i], wd[i]), ((2 - h.0) as u8, h.1 as u8), "{headers:?}");
                }
                assert!(wd[k..].iter().all(|&x| x == 0), "padding of {headers:?}");
                at[0] += 3 * k;
                at[1] += WIDTH_BITS as usize * read.whole;
            }
            assert_eq!(at[1] - 9, written, "bits of {headers:?}");
        }
    }

    /// A width coded one more than 31 or one less than 0 reads as a byte
    /// above 31 (the reader's error), and leaves its neighbours as they are.
    #[test]
    fn a_header_group_out_of_range_shows() {
        // Three lanes: one less than 0, one more than 31, the same 5.
        let v = (2 << 3) | (1 << 5);
        let read = header_group::<Portable>(v, 0, 3, u64::from_le_bytes([0, 31, 5, 0, 0, 0, 0, 0]));
        let wd = read.width.to_le_bytes();
        assert!(wd[0] > 31 && wd[1] > 31, "{wd:?}");
        assert_eq!(wd[2..], [5, 0, 0, 0, 0, 0]);
        assert_eq!(read.whole, 0);
    }

    /// The low bits and the bias of every width, on each lane type.
    #[test]
    fn width_lanes_is_one_rule_on_every_lane_type() {
        for w in 0..32u32 {
            let (low, b) = width_lanes(w as i32);
            assert_eq!(low as u32 as u64, (1u64 << w) - 1, "low bits of width {w}");
            let want = if w == 0 { 0 } else { 1u64 << (w - 1) };
            assert_eq!(b as u32 as u64, want, "bias of width {w}");
        }
        let ws = [[0, 1, 2, 3, 4, 5, 6, 7], [31, 30, 25, 17, 16, 9, 8, 0]];
        for w in ws {
            let one = w.map(width_lanes::<i32>);
            let (low, b) = width_lanes(wide::i32x8::new(w));
            assert_eq!(low.to_array(), one.map(|x| x.0));
            assert_eq!(b.to_array(), one.map(|x| x.1));
            let (low, b) = width_lanes(I8(w));
            assert_eq!(low.0, one.map(|x| x.0));
            assert_eq!(b.0, one.map(|x| x.1));
        }
    }
}
