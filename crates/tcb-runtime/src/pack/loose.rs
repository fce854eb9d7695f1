//! Tracks on key times of their own in a packed clip: what `tcb reduce`
//! leaves beside the tracks it keeps on the capture's grid (`tcb reduce`
//! then `tcb compress`).
//!
//! Such a track keeps its keys: its times as f64, its values in integers
//! of its own quantization step, and, where its tangents are not the
//! tangent rule's on its values (a reduced vector track's explicit
//! tangents), its incoming and outgoing tangents in integers of a second
//! step. In the file each component is a base and a width, then one
//! `width`-bit offset from the base per key. Loading decodes them once
//! into an ordinary track of the reference (`PackSource::to_clip`), which
//! the compiler lays out as it lays out any clip's (loose lanes, or a group
//! of tracks sharing those times): such tracks are played from f32
//! controls, 12 bytes per key and component.

use super::{LooseTangents, LooseTrack, MAX_INT, PackError, dequantize, err};
use glam::{Quat, Vec2, Vec3, Vec4};
use tcb_core::params::{Interp, KeyParams, RotationMode};
use tcb_core::{
    NamedTrack, RotationTrack, Track, TrackData, TrackKind, TrackSettings, Value, ease::SegmentEase,
};

impl LooseTrack {
    /// Integers stored (each key's value and tangents, every component).
    pub fn stored_values(&self) -> usize {
        let per_key = if self.tangents.is_some() { 3 } else { 1 };
        self.times.len() * self.kind.dim() * per_key
    }

    /// Check the track: times, settings, steps and integers.
    pub(crate) fn validate(&self) -> Result<(), PackError> {
        let at = |m: String| err(format!("track {}: {m}", self.name));
        let n = self.times.len();
        if n < 2 {
            return at(format!("{n} keys (at least 2)"));
        }
        if let Some(k) = (0..n).find(|&k| !self.times[k].is_finite()) {
            return at(format!("key {k}'s time is not finite"));
        }
        if let Some(k) = (1..n).find(|&k| self.times[k] <= self.times[k - 1]) {
            return at(format!("key {k}'s time does not increase"));
        }
        let dim = self.kind.dim();
        let mut ints = vec![(self.step, &self.values)];
        if let Some(t) = &self.tangents {
            if self.kind == TrackKind::Quat && self.settings.rotation != RotationMode::Hermite {
                return at("explicit tangents on a rotation that is not `hermite`".into());
            }
            ints.push((t.step, &t.incoming));
            ints.push((t.step, &t.outgoing));
        }
        for (step, comps) in ints {
            if !(step.is_finite() && step > 0.0) {
                return at(format!("step {step} is not a positive number"));
            }
            if comps.len() != dim || comps.iter().any(|c| c.len() != n) {
                return at(format!(
                    "integers for {dim} components of {n} keys expected"
                ));
            }
            if let Some(x) = comps
                .iter()
                .flatten()
                .find(|x| x.unsigned_abs() >= MAX_INT as u32)
            {
                return at(format!("integer {x} is outside +-2^24"));
            }
        }
        Ok(())
    }

    /// The reference track: the dequantized keys, with their explicit
    /// tangents if any, else the tangent rule with default parameters.
    pub(crate) fn reference(&self) -> Result<NamedTrack, PackError> {
        let n = self.times.len();
        let keys = |c: &[Vec<i32>], step: f32| -> Vec<[f32; 4]> {
            (0..n)
                .map(|k| {
                    let mut v = [0.0f32; 4];
                    for (x, comp) in v.iter_mut().zip(c) {
                        *x = dequantize(comp[k], step);
                    }
                    v
                })
                .collect()
        };
        let values = keys(&self.values, self.step);
        // Explicit tangents on every key, or none (the rule's).
        let p: Vec<KeyParams<[f32; 4]>> = match &self.tangents {
            None => Vec::new(),
            Some(t) => {
                let (i, o) = (keys(&t.incoming, t.step), keys(&t.outgoing, t.step));
                (0..n)
                    .map(|k| KeyParams {
                        tangent_in: Some(i[k]),
                        tangent_out: Some(o[k]),
                        ..KeyParams::default()
                    })
                    .collect()
            }
        };
        let e = |e: tcb_core::TrackError| PackError(format!("track {}: {e}", self.name));
        let (times, s) = (self.times.clone(), &self.settings);
        let data = match self.kind {
            TrackKind::Scalar => {
                TrackData::Scalar(vector::<f32>(times, &values, &p, s).map_err(e)?)
            }
            TrackKind::Vec2 => TrackData::Vec2(vector::<Vec2>(times, &values, &p, s).map_err(e)?),
            TrackKind::Vec3 => TrackData::Vec3(vector::<Vec3>(times, &values, &p, s).map_err(e)?),
            TrackKind::Vec4 => TrackData::Vec4(vector::<Vec4>(times, &values, &p, s).map_err(e)?),
            TrackKind::Quat => {
                let q = values.iter().map(|v| Quat::from_array(*v)).collect();
                let p = p.iter().map(|k| lift(k, Quat::from_array)).collect();
                TrackData::Quat(RotationTrack::new(times, q, p, s).map_err(e)?)
            }
        };
        Ok(NamedTrack {
            name: self.name.clone(),
            data,
        })
    }
}

/// Per key, its components.
type Keys = Vec<[f32; 4]>;
/// A key's incoming and outgoing tangents.
type InOut = ([f32; 4], [f32; 4]);

/// Key parameters of another value type.
fn lift<V, W>(k: &KeyParams<V>, f: impl Fn(V) -> W) -> KeyParams<W>
where
    V: Copy,
{
    KeyParams {
        tcb: k.tcb,
        ease: k.ease,
        interp: k.interp,
        tangent_in: k.tangent_in.map(&f),
        tangent_out: k.tangent_out.map(&f),
    }
}

/// A vector track from keys given as arrays.
fn vector<V: Value>(
    times: Vec<f64>,
    values: &[[f32; 4]],
    params: &[KeyParams<[f32; 4]>],
    settings: &TrackSettings,
) -> Result<Track<V>, tcb_core::TrackError> {
    let v = values.iter().map(|a| V::from_array(*a)).collect();
    let p = params.iter().map(|k| lift(k, V::from_array)).collect();
    Track::new(times, v, p, settings)
}

/// A source track to keep on its own key times, before quantization
/// ([`super::KeyValues`]).
#[derive(Clone, Debug)]
pub(crate) struct LooseKeys {
    pub at: usize,
    pub name: String,
    pub kind: TrackKind,
    pub settings: TrackSettings,
    pub times: Vec<f64>,
    pub values: Vec<[f32; 4]>,
    /// Explicit tangents (incoming, outgoing), where the rule's on the
    /// values are not the track's.
    pub tangents: Option<(Keys, Keys)>,
}

impl LooseKeys {
    /// Track `at` of a clip, `t`: its keys, and its tangents where the rule
    /// does not give them. Refused (naming the track) where a packed clip
    /// cannot hold it: eases and `linear` or `step` segments, and tangents
    /// that neither the rule nor explicit tangents give (a `squad` or
    /// `slerp` rotation with parameters other than the defaults).
    pub fn of(at: usize, t: &NamedTrack) -> Result<LooseKeys, PackError> {
        let refuse = |why: &str| {
            err(format!(
                "track {} is on key times of its own and {why}, which a packed clip does not store: bake it on the clip's grid first (tcb sample), or reduce without it",
                t.name
            ))
        };
        let (values, tangents, rule_ok) = match &t.data {
            TrackData::Scalar(tr) => vector_keys(tr),
            TrackData::Vec2(tr) => vector_keys(tr),
            TrackData::Vec3(tr) => vector_keys(tr),
            TrackData::Vec4(tr) => vector_keys(tr),
            TrackData::Quat(r) => {
                let mut segments = r.eases().iter().zip(r.interps());
                if !segments.all(|(e, i)| *e == SegmentEase::default() && *i == Interp::Curve) {
                    return refuse("has eases, `linear` or `step` segments");
                }
                let values: Vec<[f32; 4]> = r.values().iter().map(|q| q.to_array()).collect();
                match r.hermite_track() {
                    Some(h) => {
                        let (_, tangents, rule_ok) = vector_keys(h);
                        (values, tangents, rule_ok)
                    }
                    None => {
                        // `squad` or `slerp`: the reference keeps the mode
                        // with default parameters, which must play the
                        // track (checked halfway through each segment).
                        let again = RotationTrack::new(
                            r.times().to_vec(),
                            r.values().to_vec(),
                            Vec::new(),
                            r.settings(),
                        );
                        let same = again.is_ok_and(|a| {
                            r.times().windows(2).all(|w| {
                                let t = 0.5 * (w[0] + w[1]);
                                a.sample(t).dot(r.sample(t)).abs() >= 1.0 - 1e-6
                            })
                        });
                        if !same {
                            return refuse(
                                "its `squad` or `slerp` keys have parameters other than the defaults",
                            );
                        }
                        (values, Vec::new(), true)
                    }
                }
            }
        };
        if let Some(segments) = segments_plain(&t.data)
            && !segments
        {
            return refuse("has eases, `linear` or `step` segments");
        }
        let tangents = (!rule_ok).then(|| {
            let i = tangents.iter().map(|k| k.0).collect();
            let o = tangents.iter().map(|k| k.1).collect();
            (i, o)
        });
        Ok(LooseKeys {
            at,
            name: t.name.clone(),
            kind: t.data.kind(),
            settings: *t.data.settings(),
            times: t.data.times().to_vec(),
            values,
            tangents,
        })
    }

    /// The largest magnitude over its components and keys.
    pub fn largest(&self) -> f32 {
        let dim = self.kind.dim();
        self.values
            .iter()
            .flat_map(|v| v[..dim].iter().map(|x| x.abs()))
            .fold(0.0, f32::max)
    }

    /// Quantized in steps of `step` (its tangents in steps of `step` over
    /// its longest interval, so that a tangent's rounding moves the curve
    /// about as much as a value's, or coarser where their integers would
    /// reach 2^22).
    pub fn quantize(&self, step: f32) -> Result<LooseTrack, PackError> {
        let dim = self.kind.dim();
        let ints = |keys: &[[f32; 4]], step: f32| -> Result<Vec<Vec<i32>>, PackError> {
            (0..dim)
                .map(|c| {
                    keys.iter()
                        .map(|v| {
                            let x = (f64::from(v[c]) / f64::from(step)).round();
                            if x.abs() >= f64::from(MAX_INT) || x.is_nan() {
                                err(format!(
                                    "track {}: step {step} is too fine for {}",
                                    self.name, v[c]
                                ))
                            } else {
                                Ok(x as i32)
                            }
                        })
                        .collect()
                })
                .collect()
        };
        let longest = self
            .times
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(0.0f64, f64::max);
        let tangents = match &self.tangents {
            None => None,
            Some((i, o)) => {
                // No finer than keeps the largest tangent's integer below
                // 2^22 (as the search keeps the values').
                let largest = i
                    .iter()
                    .chain(o)
                    .flat_map(|v| v[..dim].iter().map(|x| f64::from(x.abs())))
                    .fold(0.0f64, f64::max);
                let step = (f64::from(step) / longest).max(largest / f64::from(1u32 << 22)) as f32;
                if !(step.is_finite() && step > 0.0) {
                    return err(format!(
                        "track {}: no tangent step for intervals up to {longest} s",
                        self.name
                    ));
                }
                Some(LooseTangents {
                    step,
                    incoming: ints(i, step)?,
                    outgoing: ints(o, step)?,
                })
            }
        };
        Ok(LooseTrack {
            at: self.at,
            name: self.name.clone(),
            kind: self.kind,
            settings: self.settings,
            times: self.times.clone(),
            step,
            values: ints(&self.values, step)?,
            tangents,
        })
    }
}

/// Whether a vector track's segments are all plain curves without eases
/// (`None` for rotations, checked apart).
fn segments_plain(data: &TrackData) -> Option<bool> {
    fn plain<V: Value>(t: &Track<V>) -> bool {
        t.segments()
            .iter()
            .all(|s| s.ease == SegmentEase::default() && s.interp == Interp::Curve)
    }
    match data {
        TrackData::Scalar(t) => Some(plain(t)),
        TrackData::Vec2(t) => Some(plain(t)),
        TrackData::Vec3(t) => Some(plain(t)),
        TrackData::Vec4(t) => Some(plain(t)),
        TrackData::Quat(_) => None,
    }
}

/// A vector track's values and tangents as arrays, and whether the tangent
/// rule with default parameters gives its tangents from its values (to
/// 1e-6 of their size: the reference then derives them, as the runtime of
/// a packed group does).
fn vector_keys<V: Value>(t: &Track<V>) -> (Keys, Vec<InOut>, bool) {
    let values: Vec<[f32; 4]> = t.values().iter().map(|v| v.to_array()).collect();
    let tangents: Vec<([f32; 4], [f32; 4])> = t
        .tangents()
        .iter()
        .map(|k| (k.incoming.to_array(), k.outgoing.to_array()))
        .collect();
    let rule = Track::new(
        t.times().to_vec(),
        t.values().to_vec(),
        Vec::new(),
        t.settings(),
    );
    let rule_ok = rule.is_ok_and(|r| {
        r.tangents().iter().zip(&tangents).all(|(a, b)| {
            let (ai, ao) = (a.incoming.to_array(), a.outgoing.to_array());
            (0..4).all(|c| close(ai[c], b.0[c]) && close(ao[c], b.1[c]))
        })
    });
    (values, tangents, rule_ok)
}

/// Equal to 1e-6 of their size.
fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1e-6)
}
