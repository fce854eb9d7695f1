//! The scalar reference spline for vector values (`f32`, `Vec2`, `Vec3`,
//! `Vec4`): built and validated once, then sampled at any f64 time.

use crate::ease::SegmentEase;
use crate::error::TrackError;
use crate::params::{Ends, Interp, KeyParams, TrackSettings};
use crate::simd::basis::{hermite, hermite_basis, hermite_basis_derivative};
use crate::simd::extrapolate::{Mapped, map_time};
use crate::tangent::{KeyTangents, TangentKey, key_tangents_wrapped};
use crate::vector::{Value, Vector};

/// The Hermite controls of one segment, in value per segment, after the
/// segment's shape is applied: `curve` uses the key tangents
/// (`m0 = DD_k`, `m1 = DS_{k+1}`), `linear` the chord (`m0 = m1 = p1 - p0`),
/// `step` holds (`p1 = p0`, `m0 = m1 = 0`). One evaluation serves all three.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment<V> {
    /// Value at s = 0.
    pub p0: V,
    /// Value at s = 1.
    pub p1: V,
    /// Tangent at s = 0.
    pub m0: V,
    /// Tangent at s = 1.
    pub m1: V,
    /// Re-timing of the segment.
    pub ease: SegmentEase,
    /// The segment's shape (already folded into the controls).
    pub interp: Interp,
}

/// Segment `k` containing `time` and the plain local parameter `u` in [0, 1],
/// for `times` with at least 2 strictly increasing entries. Times before the
/// first key give `(0, 0.0)`, times after the last (and NaN) `(n-2, 1.0)`.
///
/// ```
/// use tcb_core::track::locate;
/// let times = [0.0, 1.0, 3.0];
/// assert_eq!(locate(&times, 2.0), (1, 0.5));
/// assert_eq!(locate(&times, 1.0), (1, 0.0));
/// assert_eq!(locate(&times, 3.0), (1, 1.0));
/// ```
pub fn locate(times: &[f64], time: f64) -> (usize, f64) {
    let k = segment_from(times, time, 0);
    let u = (time - times[k]) / (times[k + 1] - times[k]);
    (k, if u.is_nan() { 1.0 } else { u.clamp(0.0, 1.0) })
}

/// Segment `k` with `times[k] <= time < times[k+1]`, clamped to
/// `0..=n-2` (times before the first key and NaN give 0, times from the
/// last key on give n-2), for `times` with at least 2 strictly increasing
/// entries. The one segment search of the reference and the runtime:
///
/// - segment `hint` and the two after it are tried first, one compare
///   each, so forward playback finds its segment in O(1);
/// - otherwise (a seek) the search starts where `time` would fall if the
///   keys were evenly spaced, which on motion capture is the segment
///   itself or its neighbour, and gallops from there (offsets 1, 2, 4, ...
///   either way), then searches between its last two probes: O(log e) for
///   a guess e keys off, never more than O(log n). A binary search from
///   scratch was 12 dependent loads on the 2752 keys of the CMU capture.
///
/// ```
/// use tcb_core::track::segment_from;
/// let times = [0.0, 1.0, 3.0, 4.0];
/// assert_eq!(segment_from(&times, 3.5, 1), 2); // the next segment
/// assert_eq!(segment_from(&times, 0.5, 2), 0); // a seek back
/// assert_eq!(segment_from(&times, 9.0, 0), 2);
/// ```
#[inline]
pub fn segment_from(times: &[f64], time: f64, hint: usize) -> usize {
    let last = times.len() - 2;
    let k = hint.min(last);
    let forward = times[k] <= time;
    if forward {
        if time < times[k + 1] {
            return k;
        }
        // The next two segments: capture at 120 fps played at 60 moves two
        // keys a frame.
        for s in k + 1..k + 3 {
            if s > last {
                return last;
            }
            if time < times[s + 1] {
                return s;
            }
        }
    }
    let (t0, tn) = (times[0], times[last + 1]);
    if time.is_nan() || time < t0 {
        return 0; // before the keys, or NaN
    }
    if time >= tn {
        return last;
    }
    // Where `time` falls on evenly spaced keys (a saturating cast: 0 for
    // NaN, as when the span overflows), kept on the known side of the hint:
    // past the segments tried going forward, at or before it going back.
    let guess = ((time - t0) / (tn - t0) * (last + 1) as f64) as usize;
    let g = if forward {
        guess.max(k + 3).min(last)
    } else {
        guess.min(k)
    };
    // Nearly even keys (capture, baked output): the guess itself.
    if times[g] <= time && time < times[g + 1] {
        return g;
    }
    gallop(times, time, g)
}

/// [`segment_from`] inside the keys (`times[0] <= time < times[n-1]`),
/// galloping from segment `g` towards `time` in either direction, then
/// searching between the last two probes.
#[inline]
fn gallop(times: &[f64], time: f64, g: usize) -> usize {
    if times[g] <= time {
        let rest = &times[g..];
        let mut hi = 1;
        while hi < rest.len() && rest[hi] <= time {
            hi *= 2;
        }
        let lo = hi / 2;
        let p = lo + rest[lo..hi.min(rest.len())].partition_point(|&t| t <= time);
        g + p - 1
    } else {
        // times[g] > time >= times[0]: back by 1, 2, 4, ... until a key at
        // or before `time` (key 0 at the latest).
        let mut d = 1;
        while d <= g && times[g - d] > time {
            d *= 2;
        }
        let (lo, hi) = (g.saturating_sub(d), g - d / 2);
        lo + times[lo..=hi].partition_point(|&t| t <= time) - 1
    }
}

/// Check what every track needs of its times and per-key parameters.
pub(crate) fn check_keys<V: Copy>(
    times: &[f64],
    values: usize,
    keys: &[KeyParams<V>],
    ends: Ends,
    finite: impl Fn(V) -> bool,
) -> Result<(), TrackError> {
    let n = times.len();
    let needed = if ends == Ends::Cyclic { 3 } else { 2 };
    if n < needed {
        return Err(TrackError::TooFewKeys { count: n, needed });
    }
    if values != n {
        return Err(TrackError::LengthMismatch {
            what: "values",
            expected: n,
            found: values,
        });
    }
    if !keys.is_empty() && keys.len() != n {
        return Err(TrackError::LengthMismatch {
            what: "keys",
            expected: n,
            found: keys.len(),
        });
    }
    for (key, &t) in times.iter().enumerate() {
        if !t.is_finite() {
            return Err(TrackError::NonFiniteTime { key });
        }
        if key > 0 && t <= times[key - 1] {
            return Err(TrackError::NonIncreasingTime {
                key,
                time: t,
                previous: times[key - 1],
            });
        }
    }
    if !(times[n - 1] - times[0]).is_finite() {
        return Err(TrackError::TimeSpanTooLarge);
    }
    for (key, p) in keys.iter().enumerate() {
        if !p.tcb.is_finite() {
            return Err(TrackError::NonFiniteTcb { key });
        }
        if !p.ease.is_valid() {
            return Err(TrackError::EaseOutOfRange {
                key,
                ease: [p.ease.to, p.ease.from],
            });
        }
        for (what, t) in [("in", p.tangent_in), ("out", p.tangent_out)] {
            if t.is_some_and(|t| !finite(t)) {
                return Err(TrackError::NonFiniteValue { key, what });
            }
        }
    }
    Ok(())
}

/// `keys`, or n default keys when it is empty.
pub(crate) fn keys_or_default<V: Copy>(keys: Vec<KeyParams<V>>, n: usize) -> Vec<KeyParams<V>> {
    if keys.is_empty() {
        vec![KeyParams::default(); n]
    } else {
        keys
    }
}

/// Ease of every segment from its keys' ease-from and ease-to.
pub(crate) fn segment_eases<V>(keys: &[KeyParams<V>]) -> impl Iterator<Item = SegmentEase> + '_ {
    keys.windows(2)
        .map(|w| SegmentEase::new(w[0].ease.from, w[1].ease.to))
}

/// `|a - b| <= 1e-6 max(1, |a|, |b|)`: the closure test of `cyclic` ends.
pub(crate) fn nearly_equal<V: Vector>(a: V, b: V) -> bool {
    a.sub(b).norm() <= 1e-6 * a.norm().max(b.norm()).max(1.0)
}

/// A validated TCB spline over values of type `V`.
///
/// ```
/// use glam::Vec3;
/// use tcb_core::{Track, TrackSettings};
///
/// let track = Track::new(
///     vec![0.0, 0.5, 1.25, 2.0],
///     vec![Vec3::ZERO, Vec3::new(1.0, 2.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.0)],
///     vec![],                      // default key parameters
///     &TrackSettings::default(),   // adjusted rule, copy ends, constant extrapolation
/// )
/// .unwrap();
/// assert_eq!(track.sample(0.5), Vec3::new(1.0, 2.0, 0.0)); // passes through its keys
/// let (_, velocity) = track.sample_with_velocity(1.0);
/// assert!(velocity.x > 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Track<V> {
    times: Vec<f64>,
    values: Vec<V>,
    tangents: Vec<KeyTangents<V>>,
    segments: Vec<Segment<V>>,
    settings: TrackSettings,
}

impl<V: Value> Track<V> {
    /// Build a track from key times (seconds, strictly increasing), values,
    /// and per-key parameters (`keys` empty for defaults, else one per key).
    ///
    /// `settings.rotation` is ignored. Errors name the key at fault.
    pub fn new(
        times: Vec<f64>,
        values: Vec<V>,
        keys: Vec<KeyParams<V>>,
        settings: &TrackSettings,
    ) -> Result<Self, TrackError> {
        Self::new_wrapped(times, values, keys, settings, 1.0)
    }

    /// [`Track::new`] for a cyclic track whose last value is `wrap_sign`
    /// times its first (see [`crate::tangent::key_tangents_wrapped`]).
    pub(crate) fn new_wrapped(
        times: Vec<f64>,
        values: Vec<V>,
        keys: Vec<KeyParams<V>>,
        settings: &TrackSettings,
        wrap_sign: f64,
    ) -> Result<Self, TrackError> {
        check_keys(&times, values.len(), &keys, settings.ends, V::is_finite)?;
        let n = times.len();
        for (key, v) in values.iter().enumerate() {
            if !v.is_finite() {
                return Err(TrackError::NonFiniteValue { key, what: "value" });
            }
        }
        if settings.ends == Ends::Cyclic && !nearly_equal(values[0], values[n - 1].scale(wrap_sign))
        {
            return Err(TrackError::CyclicNotClosed { key: n - 1 });
        }
        let keys = keys_or_default(keys, n);
        let chords: Vec<V> = values.windows(2).map(|w| w[1].sub(w[0])).collect();
        let tangent_keys: Vec<TangentKey<V>> = keys
            .iter()
            .map(|k| TangentKey {
                tcb: k.tcb,
                tangent_in: k.tangent_in,
                tangent_out: k.tangent_out,
            })
            .collect();
        let tangents = key_tangents_wrapped(&times, &chords, &tangent_keys, settings, wrap_sign)
            .expect("one chord per segment and one key per time, as checked above");
        let segments = segment_eases(&keys)
            .enumerate()
            .map(|(k, ease)| {
                let (p0, p1) = (values[k], values[k + 1]);
                let interp = keys[k].interp;
                let (p1, m0, m1) = match interp {
                    Interp::Curve => (p1, tangents[k].outgoing, tangents[k + 1].incoming),
                    Interp::Linear => (p1, chords[k], chords[k]),
                    Interp::Step => (p0, V::ZERO, V::ZERO),
                };
                Segment {
                    p0,
                    p1,
                    m0,
                    m1,
                    ease,
                    interp,
                }
            })
            .collect();
        Ok(Track {
            times,
            values,
            tangents,
            segments,
            settings: *settings,
        })
    }

    /// Heap bytes this track owns (times, values, tangents, segments).
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.times.as_slice())
            + std::mem::size_of_val(self.values.as_slice())
            + std::mem::size_of_val(self.tangents.as_slice())
            + std::mem::size_of_val(self.segments.as_slice())
    }

    /// Key times.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Key values.
    pub fn values(&self) -> &[V] {
        &self.values
    }

    /// `DS_k`, `DD_k` of every key (value per segment).
    pub fn tangents(&self) -> &[KeyTangents<V>] {
        &self.tangents
    }

    /// The Hermite controls of every segment.
    pub fn segments(&self) -> &[Segment<V>] {
        &self.segments
    }

    /// The settings the track was built with.
    pub fn settings(&self) -> &TrackSettings {
        &self.settings
    }

    /// First and last key time.
    pub fn time_range(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// Time-unit outgoing tangent of the first key, `TO_0 = DD_0 / D_0`.
    pub fn start_tangent(&self) -> V {
        self.tangents[0]
            .outgoing
            .scale(1.0 / (self.times[1] - self.times[0]))
    }

    /// Time-unit incoming tangent of the last key, `TI_{n-1} = DS_{n-1} / D_{n-2}`.
    pub fn end_tangent(&self) -> V {
        let n = self.times.len();
        self.tangents[n - 1]
            .incoming
            .scale(1.0 / (self.times[n - 1] - self.times[n - 2]))
    }

    /// The value at `time` (seconds; any f64, see [`crate::simd::extrapolate`]).
    pub fn sample(&self, time: f64) -> V {
        self.sample_with_velocity(time).0
    }

    /// The value and its derivative with respect to time (value per second).
    ///
    /// At a key the velocity is that of the segment leaving it; at the last
    /// key, that of the segment arriving.
    pub fn sample_with_velocity(&self, time: f64) -> (V, V) {
        let (t0, tn) = self.time_range();
        let n = self.values.len();
        match map_time(time, t0, tn, self.settings.pre, self.settings.post) {
            Mapped::Inside {
                time,
                direction,
                cycles,
            } => {
                let (mut value, velocity) = self.evaluate(time);
                if cycles != 0.0 {
                    value = value.add(self.values[n - 1].sub(self.values[0]).scale(cycles));
                }
                (value, velocity.scale(direction))
            }
            Mapped::Hold { last } => (self.values[if last { n - 1 } else { 0 }], V::ZERO),
            Mapped::Reset => (V::ZERO, V::ZERO),
            Mapped::Line { last: false, dt } => {
                let v = self.start_tangent();
                (self.values[0].add(v.scale(dt)), v)
            }
            Mapped::Line { last: true, dt } => {
                let v = self.end_tangent();
                (self.values[n - 1].add(v.scale(dt)), v)
            }
        }
    }

    /// Value and velocity at a time inside the keys (`u` clamped to the
    /// segment where rounding left it a hair outside).
    pub(crate) fn evaluate(&self, time: f64) -> (V, V) {
        let (k, u) = locate(&self.times, time);
        let seg = &self.segments[k];
        // A `step` segment stays P_k (math.md) exactly, at rate 0: as the
        // runtime plays it, at s = 0, where the basis is [1, 0, 0, 0]. (The
        // last key itself, below, still wins at the end.)
        let (s, ds_du) = match seg.interp {
            Interp::Step => (0.0, 0.0),
            _ => seg.ease.apply(u),
        };
        let s = s as f32;
        let h = hermite_basis(s);
        let dh = hermite_basis_derivative(s);
        let rate = (ds_du / (self.times[k + 1] - self.times[k])) as f32;
        let (p0, p1, m0, m1) = (
            seg.p0.to_array(),
            seg.p1.to_array(),
            seg.m0.to_array(),
            seg.m1.to_array(),
        );
        let mut value = [0.0f32; 4];
        let mut velocity = [0.0f32; 4];
        for i in 0..V::DIM {
            value[i] = hermite(&h, p0[i], p1[i], m0[i], m1[i]);
            velocity[i] = hermite(&dh, p0[i], p1[i], m0[i], m1[i]) * rate;
        }
        let value = if time >= self.times[k + 1] {
            // The last key itself (a `step` segment would still hold P_{n-2}).
            // The time decides, not `u`: one ulp before a key 3.1 s after
            // the last but one, `u` rounds to 1, and a final `step` still
            // holds its key there (issue 29 class 2).
            self.values[k + 1]
        } else if s == 1.0 {
            // At the segment's end (basis [0, 1, 0, 0]) the value is its
            // key, also beside a tangent that overflowed f32, where the sum
            // would be 0 x inf = NaN; the runtime copies the key there too.
            seg.p1
        } else {
            V::from_array(value)
        };
        (value, V::from_array(velocity))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{Ease, Extrapolation, TangentRule, Tcb};

    fn scalar(
        times: &[f64],
        values: &[f32],
        keys: Vec<KeyParams<f32>>,
        s: TrackSettings,
    ) -> Track<f32> {
        Track::new(times.to_vec(), values.to_vec(), keys, &s).unwrap()
    }

    #[test]
    fn hermite_by_hand() {
        // Keys 0 -> 1 -> 0 at 0, 1, 2, uniform, copy: DD_0 = 1, DS_1 = DD_1 = 0, DS_2 = -1.
        let s = TrackSettings {
            tangent_rule: TangentRule::Uniform,
            ..Default::default()
        };
        let t = scalar(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0], vec![], s);
        // s = 0.5: h = [.5 .5 .125 -.125] -> 0.5 + 0.125*1 = 0.625
        assert_eq!(t.sample(0.5), 0.625);
        assert_eq!(t.sample(1.5), 0.625);
        let (_, v) = t.sample_with_velocity(0.0);
        assert_eq!(v, 1.0);
        let (_, v) = t.sample_with_velocity(1.0);
        assert_eq!(v, 0.0);
        let (_, v) = t.sample_with_velocity(2.0);
        assert_eq!(v, -1.0);
    }

    /// math.md: a `step` segment's value "stays P_k": exactly, not the
    /// Hermite sum `h0 P + h1 P`, which rounds (0.1 came back as
    /// 0.10000001 at 22 of 50 times, and a switch channel keyed 1.0 would
    /// not hold 1.0).
    #[test]
    fn step_segments_hold_their_key_exactly() {
        let mut keys = vec![KeyParams::default(); 3];
        keys[0].interp = Interp::Step;
        let t = scalar(
            &[0.0, 1.0, 2.0],
            &[0.1, 0.7, 0.3],
            keys,
            TrackSettings::default(),
        );
        for i in 0..1000 {
            let (v, d) = t.sample_with_velocity(f64::from(i) / 1000.0);
            assert_eq!((v, d), (0.1, 0.0), "at {}", f64::from(i) / 1000.0);
        }
    }

    /// A final `step` segment holds its key until the last key's time:
    /// one ulp before a last key 3.1 s after the one before, `u` rounds to
    /// 1, and the value was the last key already (the `playback` fuzz
    /// target, issue 29 class 2; the runtime held the step's key).
    #[test]
    fn a_final_step_holds_its_key_until_the_last_keys_time() {
        let mut keys = vec![KeyParams::default(); 3];
        keys[1].interp = Interp::Step;
        let times = [-6.75, -4.1640625, -1.046875];
        let t = scalar(&times, &[0.5, 2.0, 7.0], keys, TrackSettings::default());
        let before = f64::next_down(-1.046875);
        assert_eq!(locate(&times, before), (1, 1.0), "u rounds to 1 there");
        assert_eq!(t.sample_with_velocity(before), (2.0, 0.0));
        assert_eq!(t.sample(-1.046875), 7.0);
    }

    #[test]
    fn linear_and_step_segments() {
        let mut keys = vec![KeyParams::default(); 3];
        keys[0].interp = Interp::Linear;
        keys[1].interp = Interp::Step;
        let t = scalar(
            &[0.0, 2.0, 3.0],
            &[0.0, 4.0, 10.0],
            keys,
            TrackSettings::default(),
        );
        assert_eq!(t.sample(0.5), 1.0);
        assert_eq!(t.sample_with_velocity(0.5).1, 2.0);
        assert_eq!(t.sample(2.5), 4.0);
        assert_eq!(t.sample_with_velocity(2.5).1, 0.0);
        assert_eq!(t.sample(3.0), 10.0);
        assert_eq!(t.sample(2.999), 4.0);
    }

    #[test]
    fn ease_keeps_the_path_changes_the_timing() {
        let mut keys = vec![KeyParams::default(); 2];
        keys[0].ease = Ease { to: 0.0, from: 1.0 };
        let plain = scalar(&[0.0, 1.0], &[0.0, 1.0], vec![], TrackSettings::default());
        let eased = scalar(&[0.0, 1.0], &[0.0, 1.0], keys, TrackSettings::default());
        // a = 1, e = 0: K = 1, s = u^2.
        assert_eq!(eased.sample(0.5), plain.sample(0.25));
        assert_eq!(eased.sample_with_velocity(0.0).1, 0.0);
        // ds/du = 2u = 1 at u = 0.5; plain speed 1 on this straight segment.
        assert!((eased.sample_with_velocity(0.5).1 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn extrapolation_by_hand() {
        let with = |pre, post| {
            let s = TrackSettings {
                pre,
                post,
                ..Default::default()
            };
            scalar(&[1.0, 2.0, 3.0], &[1.0, 3.0, 2.0], vec![], s)
        };
        let t = with(Extrapolation::Constant, Extrapolation::Reset);
        assert_eq!(t.sample_with_velocity(0.0), (1.0, 0.0));
        assert_eq!(t.sample_with_velocity(9.0), (0.0, 0.0));
        let t = with(Extrapolation::Linear, Extrapolation::Linear);
        // copy ends, adjusted, even: DD_0 = B = 2, DS_2 = A = -1.
        assert_eq!(t.sample_with_velocity(0.0), (-1.0, 2.0));
        assert_eq!(t.sample_with_velocity(5.0), (0.0, -1.0));
        let t = with(Extrapolation::OffsetRepeat, Extrapolation::OffsetRepeat);
        assert_eq!(t.sample(4.0), 3.0 + 1.0);
        assert_eq!(t.sample(0.0), 3.0 - 1.0);
        let t = with(Extrapolation::Oscillate, Extrapolation::Oscillate);
        assert_eq!(t.sample(3.5), t.sample(2.5));
        assert_eq!(
            t.sample_with_velocity(3.5).1,
            -t.sample_with_velocity(2.5).1
        );
        let t = with(Extrapolation::Repeat, Extrapolation::Repeat);
        assert_eq!(t.sample(1e6 + 1.5), t.sample(1.5));
    }

    #[test]
    fn any_time_is_safe() {
        let t = scalar(
            &[0.0, 1.0],
            &[2.0, 3.0],
            vec![KeyParams::with_tcb(Tcb::OVERSHOOT); 2],
            TrackSettings::default(),
        );
        for time in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            -0.0,
            1e-300,
        ] {
            let (v, d) = t.sample_with_velocity(time);
            assert!(v.is_finite() && d.is_finite(), "{time}");
        }
        assert_eq!(t.sample(f64::NAN), 2.0);
    }

    #[test]
    fn rejects_bad_keys() {
        let s = TrackSettings::default();
        let e = Track::new(vec![0.0], vec![1.0f32], vec![], &s).unwrap_err();
        assert_eq!(
            e,
            TrackError::TooFewKeys {
                count: 1,
                needed: 2
            }
        );
        let e = Track::new(vec![0.0, 0.0], vec![1.0f32, 2.0], vec![], &s).unwrap_err();
        assert_eq!(e.key(), Some(1));
        let e = Track::new(vec![0.0, 1.0], vec![1.0f32, f32::NAN], vec![], &s).unwrap_err();
        assert_eq!(
            e,
            TrackError::NonFiniteValue {
                key: 1,
                what: "value"
            }
        );
        let e = Track::new(vec![0.0, 1.0], vec![1.0f32], vec![], &s).unwrap_err();
        assert!(matches!(
            e,
            TrackError::LengthMismatch { what: "values", .. }
        ));
        let mut keys = vec![KeyParams::default(); 2];
        keys[1].ease = Ease { to: 1.5, from: 0.0 };
        let e = Track::new(vec![0.0, 1.0], vec![1.0f32, 2.0], keys, &s).unwrap_err();
        assert_eq!(e.key(), Some(1));
        let cyc = TrackSettings {
            ends: Ends::Cyclic,
            ..s
        };
        let e = Track::new(vec![0.0, 1.0, 2.0], vec![1.0f32, 2.0, 1.5], vec![], &cyc).unwrap_err();
        assert_eq!(e, TrackError::CyclicNotClosed { key: 2 });
        assert!(Track::new(vec![0.0, 1.0, 2.0], vec![1.0f32, 2.0, 1.0], vec![], &cyc).is_ok());
        let e = Track::new(vec![-1e308, 1e308], vec![1.0f32, 2.0], vec![], &s).unwrap_err();
        assert_eq!(e, TrackError::TimeSpanTooLarge);
    }
}
