//! Rotation tracks: TCB on unit quaternions.
//!
//! Values are `[x, y, z, w]`, normalized when the track is built; each key is
//! flipped to the hemisphere of the previous one (`q_k = -q_k` where
//! `dot(q_{k-1}, q_k) < 0`), so every chord is the short way round.
//!
//! # `squad` (default; 3D Studio / 3ds Max TCB rotation)
//!
//! The tangent rules, ends and weights of [`crate::tangent`] applied to
//! log-space chords:
//!
//! ```text
//! log((v sin(th/2), cos(th/2))) = v th/2
//! A = log(q_{k-1}^-1 q_k)      B = log(q_k^-1 q_{k+1})      -> DS_k, DD_k (log space)
//! a_k = q_k exp((DD_k - B) / 2)          b_k = q_k exp((A - DS_k) / 2)
//! segment k: squad(s) = slerp(slerp(q_k, q_{k+1}, s), slerp(a_k, b_{k+1}, s), 2s(1-s))
//! ```
//!
//! (plain slerp, no hemisphere flip inside). With t = c = b = 0 on even keys
//! this is Shoemake's squad. `natural` ends and explicit tangents are not
//! defined for it.
//!
//! # `hermite` (glTF CUBICSPLINE style)
//!
//! The four components form a [`Track<Vec4>`](crate::Track) with every rule,
//! end and override; the result is normalized.
//!
//! In both modes `interp: linear` is slerp and `step` holds. The reference
//! works in f64 and returns f32 quaternions. Velocities are d/dt of the
//! output quaternion's components, from the analytic derivative of the
//! power form ([`crate::simd::squad`]).

use crate::ease::SegmentEase;
use crate::error::TrackError;
use crate::params::{
    Ends, Extrapolation, Hemisphere, Interp, KeyParams, RotationMode, TrackSettings,
};
use crate::simd::extrapolate::{Mapped, map_time};
use crate::tangent::{TangentKey, key_tangents};
use crate::track::{Track, check_keys, keys_or_default, locate, segment_eases};
use glam::{DQuat, DVec3, DVec4, Quat, Vec4};

pub use crate::simd::squad::{quat_exp, quat_log};

/// Spherical linear interpolation without hemisphere correction,
/// `p exp(s log(p^-1 q))` ([`crate::simd::squad::slerp_power`]). Any `s` is
/// allowed (it extrapolates along the arc).
pub fn slerp(p: DQuat, q: DQuat, s: f64) -> DQuat {
    let c = crate::simd::squad::slerp_controls(p, q);
    DQuat::from_array(crate::simd::squad::slerp_power(
        &[c[0], c[1], c[2], c[3]],
        &[c[4], c[5], c[6]],
        c[7],
        s,
    ))
}

/// `squad(q0, q1, a, b, s) = slerp(slerp(q0, q1, s), slerp(a, b, s), 2s(1-s))`
/// ([`crate::simd::squad::squad`]).
pub fn squad(q0: DQuat, q1: DQuat, a: DQuat, b: DQuat, s: f64) -> DQuat {
    DQuat::from_array(crate::simd::squad::squad(
        &crate::simd::squad::controls(q0, q1, a, b),
        s,
    ))
}

/// One `squad` segment: `squad(q0, q1, a, b, s)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SquadSegment {
    /// `q_k`.
    pub q0: DQuat,
    /// `q_{k+1}`.
    pub q1: DQuat,
    /// `a_k` (`q_k` for `linear`, all four `q_k` for `step`).
    pub a: DQuat,
    /// `b_{k+1}`.
    pub b: DQuat,
    /// Re-timing of the segment.
    pub ease: SegmentEase,
    /// The segment's shape (already folded into the controls).
    pub interp: Interp,
}

impl SquadSegment {
    /// Its power-form controls ([`crate::simd::squad::controls`]).
    pub fn controls(&self) -> [f64; crate::simd::squad::CONTROLS] {
        crate::simd::squad::controls(self.q0, self.q1, self.a, self.b)
    }

    /// The segment at `s`.
    pub fn at(&self, s: f64) -> DQuat {
        DQuat::from_array(crate::simd::squad::squad(&self.controls(), s))
    }

    /// The unit rotation at `s` and its derivative with respect to `s`.
    pub fn with_derivative(&self, s: f64) -> (DQuat, DVec4) {
        unit_with_derivative(&self.controls(), s)
    }
}

/// Squad (or slerp, as squad with `a = q0`, `b = q1`) at `s`, normalized, and
/// the derivative of the normalized curve with respect to `s`.
fn unit_with_derivative(c: &[f64; crate::simd::squad::CONTROLS], s: f64) -> (DQuat, DVec4) {
    let (q, dq) = crate::simd::squad::unit(c, s, true);
    (
        DQuat::from_array(q),
        DVec4::from_array(dq.expect("asked for")),
    )
}

#[derive(Clone, Debug, PartialEq)]
enum Shape {
    Squad(Vec<SquadSegment>),
    Hermite(Track<Vec4>),
}

/// A validated rotation track.
///
/// ```
/// use glam::Quat;
/// use tcb_core::{RotationTrack, TrackSettings};
/// let track = RotationTrack::new(
///     vec![0.0, 1.0, 2.0],
///     vec![Quat::IDENTITY, Quat::from_rotation_z(1.0), Quat::from_rotation_z(0.5)],
///     vec![],
///     &TrackSettings::default(), // squad
/// )
/// .unwrap();
/// let q = track.sample(0.5);
/// assert!((q.length() - 1.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct RotationTrack {
    times: Vec<f64>,
    keys: Vec<DQuat>,
    values: Vec<Quat>,
    interps: Vec<Interp>,
    eases: Vec<SegmentEase>,
    shape: Shape,
    settings: TrackSettings,
}

impl RotationTrack {
    /// Build a rotation track; `settings.rotation` chooses the mode.
    /// Quaternions are normalized and, unless `settings.hemisphere` is
    /// [`Hemisphere::Keep`], made hemisphere-consistent.
    pub fn new(
        times: Vec<f64>,
        values: Vec<Quat>,
        keys: Vec<KeyParams<Quat>>,
        settings: &TrackSettings,
    ) -> Result<Self, TrackError> {
        Self::build(times, values, keys, settings, true)
    }

    /// [`RotationTrack::new`] with the keys used as given, not normalized
    /// (still refused if zero or not finite): for keys that are unit length
    /// to the precision they were stored at, such as a packed clip's
    /// dequantized keys (`tcb_runtime::pack`), whose decoder then need not
    /// normalize them. `hermite` playback normalizes the curve, as always.
    ///
    /// ```
    /// use glam::Quat;
    /// use tcb_core::{RotationMode, RotationTrack, TrackSettings};
    /// let settings = TrackSettings { rotation: RotationMode::Hermite, ..Default::default() };
    /// let q = Quat::from_xyzw(0.0, 0.0, 0.6, 0.8001);
    /// let t = RotationTrack::new_as_given(vec![0.0, 1.0], vec![q, q], vec![], &settings).unwrap();
    /// assert_eq!(t.values()[0], q);
    /// ```
    pub fn new_as_given(
        times: Vec<f64>,
        values: Vec<Quat>,
        keys: Vec<KeyParams<Quat>>,
        settings: &TrackSettings,
    ) -> Result<Self, TrackError> {
        Self::build(times, values, keys, settings, false)
    }

    fn build(
        times: Vec<f64>,
        values: Vec<Quat>,
        keys: Vec<KeyParams<Quat>>,
        settings: &TrackSettings,
        normalize: bool,
    ) -> Result<Self, TrackError> {
        check_keys(&times, values.len(), &keys, settings.ends, Quat::is_finite)?;
        check_rotation_settings(&keys, settings)?;
        let n = times.len();
        let mut keys = keys_or_default(keys, n);
        let qs = unit_keys(&values, &mut keys, settings.hemisphere, normalize)?;
        if settings.ends == Ends::Cyclic {
            let (a, b) = (DVec4::from(qs[0]), DVec4::from(qs[n - 1]));
            if (a - b).length().min((a + b).length()) > 1e-6 {
                return Err(TrackError::CyclicNotClosed { key: n - 1 });
            }
        }
        let values: Vec<Quat> = qs.iter().map(|q| q.as_quat()).collect();
        let eases: Vec<SegmentEase> = segment_eases(&keys).collect();
        let interps: Vec<Interp> = keys.iter().map(|k| k.interp).collect();

        let shape = if settings.rotation == RotationMode::Squad {
            Shape::Squad(squad_segments(&times, &qs, &keys, &eases, settings))
        } else {
            Shape::Hermite(hermite_shape(&times, &qs, &values, &keys, settings)?)
        };
        Ok(RotationTrack {
            times,
            keys: qs,
            values,
            interps,
            eases,
            shape,
            settings: *settings,
        })
    }

    /// Heap bytes this track owns.
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.times.as_slice())
            + std::mem::size_of_val(self.keys.as_slice())
            + std::mem::size_of_val(self.values.as_slice())
            + std::mem::size_of_val(self.interps.as_slice())
            + std::mem::size_of_val(self.eases.as_slice())
            + match &self.shape {
                Shape::Squad(s) => std::mem::size_of_val(s.as_slice()),
                Shape::Hermite(t) => t.heap_bytes(),
            }
    }

    /// Key times.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Key rotations, normalized (and hemisphere-consistent unless the
    /// track keeps them as written).
    pub fn values(&self) -> &[Quat] {
        &self.values
    }

    /// Key rotations in f64, as the reference interpolates them ([`values`]
    /// rounded them to f32). Slerp between keys more than 90 degrees apart,
    /// which tracks that keep their hemispheres have, amplifies that
    /// rounding: interpolate these.
    ///
    /// [`values`]: RotationTrack::values
    pub fn keys(&self) -> &[DQuat] {
        &self.keys
    }

    /// The settings the track was built with.
    pub fn settings(&self) -> &TrackSettings {
        &self.settings
    }

    /// Ease of each segment.
    pub fn eases(&self) -> &[SegmentEase] {
        &self.eases
    }

    /// Shape of the segment leaving each key.
    pub fn interps(&self) -> &[Interp] {
        &self.interps
    }

    /// The squad segments (`None` for `hermite` tracks).
    pub fn squad_segments(&self) -> Option<&[SquadSegment]> {
        match &self.shape {
            Shape::Squad(s) => Some(s),
            Shape::Hermite(_) => None,
        }
    }

    /// The four-component track (`None` for `squad` tracks).
    pub fn hermite_track(&self) -> Option<&Track<Vec4>> {
        match &self.shape {
            Shape::Hermite(t) => Some(t),
            Shape::Squad(_) => None,
        }
    }

    /// First and last key time.
    pub fn time_range(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// The rotation at `time` (any f64; see [`crate::simd::extrapolate`]).
    pub fn sample(&self, time: f64) -> Quat {
        self.sample_with_velocity(time).0
    }

    /// The rotation and the d/dt of its four components.
    pub fn sample_with_velocity(&self, time: f64) -> (Quat, Vec4) {
        let (t0, tn) = self.time_range();
        let n = self.times.len();
        let (q, d) = match map_time(time, t0, tn, self.settings.pre, self.settings.post) {
            Mapped::Inside {
                time, direction, ..
            } => {
                let (q, d) = self.evaluate(time);
                (q, d * direction)
            }
            Mapped::Hold { last } => (self.keys[if last { n - 1 } else { 0 }], DVec4::ZERO),
            // Linear extrapolation is rejected at build time.
            Mapped::Reset | Mapped::Line { .. } => (DQuat::IDENTITY, DVec4::ZERO),
        };
        (q.as_quat(), d.as_vec4())
    }

    fn evaluate(&self, time: f64) -> (DQuat, DVec4) {
        let (k, u) = locate(&self.times, time);
        // The last key itself: the time decides, not `u`, which rounds to
        // 1 one ulp before a key far from the one before it.
        if time >= self.times[k + 1] && self.interps[k] == Interp::Step {
            return (self.keys[k + 1], DVec4::ZERO);
        }
        let (s, ds_du) = self.eases[k].apply(u);
        let rate = ds_du / (self.times[k + 1] - self.times[k]);
        match (self.interps[k], &self.shape) {
            (Interp::Step, _) => (self.keys[k], DVec4::ZERO),
            (_, Shape::Squad(segs)) => {
                let (q, d) = segs[k].with_derivative(s);
                (q, d * rate)
            }
            (Interp::Linear, Shape::Hermite(_)) => {
                let (q0, q1) = (self.keys[k], self.keys[k + 1]);
                let (q, d) = unit_with_derivative(&crate::simd::squad::controls(q0, q1, q0, q1), s);
                (q, d * rate)
            }
            (_, Shape::Hermite(track)) => {
                // The time is already mapped into the keys: evaluate the
                // curve there, rather than through `sample_with_velocity`,
                // which would map it again (a time that rounding left a hair
                // past the last key would wrap to the first under `repeat`).
                let (p, dp) = track.evaluate(time);
                let (p, dp) = (p.as_dvec4(), dp.as_dvec4());
                if p.length() == 0.0 {
                    return (self.keys[k], DVec4::ZERO);
                }
                let (q, dq) = crate::quat::normalize(p.to_array(), Some(dp.to_array()));
                (
                    DQuat::from_array(q),
                    DVec4::from_array(dq.expect("asked for")),
                )
            }
        }
    }
}

fn squad_segments(
    times: &[f64],
    qs: &[DQuat],
    keys: &[KeyParams<Quat>],
    eases: &[SegmentEase],
    settings: &TrackSettings,
) -> Vec<SquadSegment> {
    let n = qs.len();
    let chords: Vec<DVec3> = qs
        .windows(2)
        .map(|w| quat_log(w[0].conjugate() * w[1]))
        .collect();
    let tkeys: Vec<TangentKey<DVec3>> = keys
        .iter()
        .map(|k| TangentKey {
            tcb: k.tcb,
            tangent_in: None,
            tangent_out: None,
        })
        .collect();
    let tangents = key_tangents(times, &chords, &tkeys, settings)
        .expect("one chord per segment and one key per time, as built above");
    // Source chord A of key k (the wrap chord at key 0 of a cyclic track) and
    // destination chord B.
    let cyclic = settings.ends == Ends::Cyclic;
    let a_chord = |k: usize| {
        if k > 0 {
            chords[k - 1]
        } else if cyclic {
            chords[n - 2]
        } else {
            chords[0]
        }
    };
    (0..n - 1)
        .map(|k| {
            let (q0, q1) = (qs[k], qs[k + 1]);
            let a = q0 * quat_exp((tangents[k].outgoing - chords[k]) / 2.0);
            let b = q1 * quat_exp((a_chord(k + 1) - tangents[k + 1].incoming) / 2.0);
            let interp = keys[k].interp;
            let (q1, a, b) = match interp {
                Interp::Curve => (q1, a, b),
                Interp::Linear => (q1, q0, q1),
                Interp::Step => (q0, q0, q0),
            };
            SquadSegment {
                q0,
                q1,
                a,
                b,
                ease: eases[k],
                interp,
            }
        })
        .collect()
}

/// The settings a rotation track cannot have: `linear` or `offset-repeat`
/// extrapolation, and under `squad` natural ends or explicit tangents.
fn check_rotation_settings(
    keys: &[KeyParams<Quat>],
    settings: &TrackSettings,
) -> Result<(), TrackError> {
    for (side, mode) in [("pre", settings.pre), ("post", settings.post)] {
        if matches!(mode, Extrapolation::Linear | Extrapolation::OffsetRepeat) {
            return Err(TrackError::ExtrapolationOnRotation { side, mode });
        }
    }
    let squad_mode = settings.rotation == RotationMode::Squad;
    if squad_mode && settings.ends == Ends::Natural {
        return Err(TrackError::NaturalOnSquad);
    }
    if squad_mode
        && let Some(key) = keys
            .iter()
            .position(|k| k.tangent_in.is_some() || k.tangent_out.is_some())
    {
        return Err(TrackError::TangentOnSquad { key });
    }
    Ok(())
}

/// The keys in f64, checked (finite, not zero), made unit where
/// `normalize`, and under `nearest` each flipped into the hemisphere of
/// the one before (with its explicit tangents, which describe the curve
/// through the value as given).
fn unit_keys(
    values: &[Quat],
    keys: &mut [KeyParams<Quat>],
    hemisphere: Hemisphere,
    normalize: bool,
) -> Result<Vec<DQuat>, TrackError> {
    let mut qs: Vec<DQuat> = Vec::with_capacity(values.len());
    for (key, q) in values.iter().enumerate() {
        let v = DVec4::new(q.x.into(), q.y.into(), q.z.into(), q.w.into());
        if !v.is_finite() {
            return Err(TrackError::NonFiniteValue { key, what: "value" });
        }
        let len = v.length();
        if len == 0.0 || !len.is_finite() {
            return Err(TrackError::ZeroQuaternion { key });
        }
        let mut v = if normalize {
            DVec4::from_array(crate::quat::unit_key(v.to_array()))
        } else {
            v
        };
        if hemisphere == Hemisphere::Nearest
            && let Some(prev) = qs.last()
            && DVec4::from(*prev).dot(v) < 0.0
        {
            v = -v;
            let k = &mut keys[key];
            k.tangent_in = k.tangent_in.map(|t| -t);
            k.tangent_out = k.tangent_out.map(|t| -t);
        }
        qs.push(DQuat::from_vec4(v));
    }
    Ok(qs)
}

/// A `hermite` rotation's curve: its components as a vec4 track, wrapped
/// with the sign that joins a cyclic track's ends.
fn hermite_shape(
    times: &[f64],
    qs: &[DQuat],
    values: &[Quat],
    keys: &[KeyParams<Quat>],
    settings: &TrackSettings,
) -> Result<Track<Vec4>, TrackError> {
    let n = times.len();
    let as_vec4 = |q: Quat| Vec4::new(q.x, q.y, q.z, q.w);
    let vkeys = keys
        .iter()
        .map(|k| KeyParams {
            tcb: k.tcb,
            ease: k.ease,
            interp: k.interp,
            tangent_in: k.tangent_in.map(as_vec4),
            tangent_out: k.tangent_out.map(as_vec4),
        })
        .collect();
    let vs = values.iter().map(|&q| as_vec4(q)).collect();
    let wrap_sign = if settings.ends == Ends::Cyclic && qs[0].dot(qs[n - 1]) < 0.0 {
        -1.0
    } else {
        1.0
    };
    Track::new_wrapped(times.to_vec(), vs, vkeys, settings, wrap_sign)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Tcb;

    /// `repeat` maps 1.36e138 to `t0 + r`, which rounding leaves a hair past
    /// the last key (-0.5781249989999999 against -0.578124999). A `hermite`
    /// rotation evaluated its curve through `Track::sample_with_velocity`,
    /// which mapped that time again and wrapped it to the first key; the
    /// runtime (one mapping, `u` clamped) gave the last key (found by the
    /// `runtime` fuzz target).
    #[test]
    fn a_time_mapped_past_the_last_key_is_not_mapped_again() {
        let times = vec![
            -3.625,
            -3.0703125,
            -2.34375,
            -1.8671875,
            -0.578125,
            -0.578124999,
        ];
        let q = [
            [7.0686035, 1.5070801, 2.8857422, 3.9448242],
            [1.590332, 1.4650879, -2.5888672, -6.1728516],
            [6.0126953, 2.011963, 2.239746, -2.4262695],
            [-2.7609863; 4],
            [-2.7609863; 4],
            [-2.7609863, 3.9890137, -4.284912, 1.1933594],
        ]
        .map(|v| Quat::from_array(v).normalize());
        let settings = TrackSettings {
            rotation: RotationMode::Hermite,
            post: crate::Extrapolation::Repeat,
            ..TrackSettings::default()
        };
        let track = RotationTrack::new(times, q.to_vec(), Vec::new(), &settings).unwrap();
        let t = 1.3599676637654653e138;
        let mapped = match crate::simd::extrapolate::map_time(
            t,
            -3.625,
            -0.578124999,
            settings.pre,
            settings.post,
        ) {
            crate::simd::extrapolate::Mapped::Inside { time, .. } => time,
            other => panic!("{other:?}"),
        };
        assert!(mapped > -0.578124999, "{mapped}");
        let (got, last) = (track.sample(t), track.sample(-0.578124999));
        assert!(
            got.abs_diff_eq(last, 1e-6) || got.abs_diff_eq(-last, 1e-6),
            "{got:?} against {last:?}"
        );
    }

    /// As `Track`'s: a final `step` segment holds its key until the last
    /// key's time, also where `u` rounds to 1 one ulp before it.
    #[test]
    fn a_final_step_holds_its_key_until_the_last_keys_time() {
        let times = vec![-6.75, -4.1640625, -1.046875];
        let q = [
            Quat::IDENTITY,
            Quat::from_rotation_y(1.0),
            Quat::from_rotation_x(2.0),
        ];
        let mut keys = vec![KeyParams::default(); 3];
        keys[1].interp = Interp::Step;
        for rotation in [RotationMode::Squad, RotationMode::Hermite] {
            let settings = TrackSettings {
                rotation,
                ..TrackSettings::default()
            };
            let track =
                RotationTrack::new(times.clone(), q.to_vec(), keys.clone(), &settings).unwrap();
            let before = f64::next_down(-1.046875);
            assert_eq!(locate(&times, before).1, 1.0, "u rounds to 1 there");
            assert!(close_f32(track.sample(before), q[1]), "{rotation:?}");
            assert!(close_f32(track.sample(-1.046875), q[2]), "{rotation:?}");
        }
    }

    fn close_f32(a: Quat, b: Quat) -> bool {
        close(a.as_dquat(), b.as_dquat(), 1e-6)
    }

    fn close(a: DQuat, b: DQuat, tol: f64) -> bool {
        let (a, b) = (DVec4::from(a), DVec4::from(b));
        (a - b).length().min((a + b).length()) < tol
    }

    #[test]
    fn log_exp_round_trip() {
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 2.5);
        assert!(close(quat_exp(quat_log(q)), q, 1e-14));
        let v = quat_log(q);
        assert!((v.length() - 1.25).abs() < 1e-14);
        assert_eq!(quat_log(DQuat::IDENTITY), DVec3::ZERO);
    }

    #[test]
    fn slerp_by_hand() {
        let p = DQuat::IDENTITY;
        let q = DQuat::from_rotation_z(1.0);
        assert!(close(
            slerp(p, q, 0.25),
            DQuat::from_rotation_z(0.25),
            1e-14
        ));
        assert!(close(slerp(p, p, 0.7), p, 1e-15));
        // No hemisphere flip: slerp to -q goes the long way.
        let long = slerp(p, -q, 0.5);
        assert!(!close(long, DQuat::from_rotation_z(0.5), 1e-3));
    }

    #[test]
    fn hemisphere_keep_uses_keys_and_tangents_as_written() {
        let q1 = Quat::from_rotation_z(0.5);
        let mut keys = vec![KeyParams::default(); 2];
        keys[1].tangent_in = Some(Quat::from_xyzw(0.0, 0.0, 0.1, 0.0));
        let settings = TrackSettings {
            rotation: RotationMode::Hermite,
            hemisphere: Hemisphere::Keep,
            ..TrackSettings::default()
        };
        let t =
            RotationTrack::new(vec![0.0, 1.0], vec![Quat::IDENTITY, -q1], keys, &settings).unwrap();
        assert_eq!(t.values()[1], -q1);
        let h = t.hermite_track().unwrap();
        assert_eq!(h.values()[1], Vec4::from_array((-q1).to_array()));
        // Nearest flips the key and its tangent.
        let nearest = TrackSettings {
            hemisphere: Hemisphere::Nearest,
            ..settings
        };
        let mut keys = vec![KeyParams::default(); 2];
        keys[1].tangent_in = Some(Quat::from_xyzw(0.0, 0.0, 0.1, 0.0));
        let t =
            RotationTrack::new(vec![0.0, 1.0], vec![Quat::IDENTITY, -q1], keys, &nearest).unwrap();
        assert_eq!(t.values()[1], q1);
        // Squad with keep goes the long way: half way is not the short half.
        let squad = TrackSettings {
            rotation: RotationMode::Squad,
            hemisphere: Hemisphere::Keep,
            ..TrackSettings::default()
        };
        let t =
            RotationTrack::new(vec![0.0, 1.0], vec![Quat::IDENTITY, -q1], vec![], &squad).unwrap();
        assert!(t.sample(0.5).dot(Quat::from_rotation_z(0.25)).abs() < 0.5);
    }

    #[test]
    fn hemisphere_flip_at_load() {
        let q1 = Quat::from_rotation_z(0.5);
        let t = RotationTrack::new(
            vec![0.0, 1.0],
            vec![Quat::IDENTITY, -q1],
            vec![],
            &TrackSettings::default(),
        )
        .unwrap();
        assert!(t.values()[1].dot(Quat::IDENTITY) > 0.0);
        let mid = t.sample(0.5);
        assert!(close_f32(mid, Quat::from_rotation_z(0.25)));
    }

    #[test]
    fn two_key_squad_is_slerp_for_default_tcb() {
        // Copy ends with one chord: DD_0 = DS_1 = B, so a_0 = q0, b_1 = q1.
        let q1 = Quat::from_rotation_y(1.2);
        let t = RotationTrack::new(
            vec![0.0, 2.0],
            vec![Quat::IDENTITY, q1],
            vec![],
            &TrackSettings::default(),
        )
        .unwrap();
        for i in 0..=8 {
            let s = i as f32 / 8.0;
            let q = t.sample(2.0 * s as f64);
            assert!(close_f32(q, Quat::from_rotation_y(1.2 * s)));
        }
        let (_, d) = t.sample_with_velocity(1.0);
        // |dq/dt| = angular speed / 2 = 0.6 / 2
        assert!((d.length() - 0.3).abs() < 1e-6);
    }

    #[test]
    fn rejections() {
        let s = TrackSettings {
            ends: Ends::Natural,
            ..Default::default()
        };
        let q = vec![Quat::IDENTITY, Quat::from_rotation_x(1.0)];
        assert_eq!(
            RotationTrack::new(vec![0.0, 1.0], q.clone(), vec![], &s).unwrap_err(),
            TrackError::NaturalOnSquad
        );
        let s = TrackSettings {
            post: Extrapolation::Linear,
            ..Default::default()
        };
        assert!(matches!(
            RotationTrack::new(vec![0.0, 1.0], q.clone(), vec![], &s).unwrap_err(),
            TrackError::ExtrapolationOnRotation { side: "post", .. }
        ));
        let zero = vec![Quat::IDENTITY, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)];
        assert_eq!(
            RotationTrack::new(vec![0.0, 1.0], zero, vec![], &TrackSettings::default())
                .unwrap_err(),
            TrackError::ZeroQuaternion { key: 1 }
        );
        let mut keys = vec![KeyParams::default(); 2];
        keys[1].tangent_in = Some(Quat::IDENTITY);
        assert_eq!(
            RotationTrack::new(vec![0.0, 1.0], q, keys, &TrackSettings::default()).unwrap_err(),
            TrackError::TangentOnSquad { key: 1 }
        );
    }

    #[test]
    fn hermite_full_turn_loop_is_smooth_across_the_wrap() {
        // A spin about z: 0, 120, 240, 360 degrees; q(360) = -q(0).
        let s = TrackSettings {
            ends: Ends::Cyclic,
            rotation: RotationMode::Hermite,
            post: Extrapolation::Repeat,
            ..Default::default()
        };
        let turn = |deg: f32| Quat::from_rotation_z(deg.to_radians());
        let q = vec![turn(0.0), turn(120.0), turn(240.0), turn(360.0)];
        let t = RotationTrack::new(vec![0.0, 1.0, 2.0, 3.0], q, vec![], &s).unwrap();
        // Angular speed is the same just before and just after the wrap.
        let speed = |time: f64| t.sample_with_velocity(time).1.length();
        assert!((speed(3.0 - 1e-9) - speed(3.0 + 1e-9)).abs() < 1e-4);
        assert!((speed(0.0) - speed(3.0)).abs() < 1e-4);
        // And symmetric: the middle of the lap is a third of a turn from each end.
        assert!(close_f32(t.sample(1.5), turn(180.0)));
    }

    #[test]
    fn cyclic_up_to_sign() {
        let s = TrackSettings {
            ends: Ends::Cyclic,
            ..Default::default()
        };
        let q = vec![
            Quat::IDENTITY,
            Quat::from_rotation_x(1.0),
            Quat::from_rotation_x(2.0),
            -Quat::IDENTITY,
        ];
        let keys = vec![KeyParams::with_tcb(Tcb::DEFAULT); 4];
        assert!(RotationTrack::new(vec![0.0, 1.0, 2.0, 3.0], q, keys, &s).is_ok());
    }
}
