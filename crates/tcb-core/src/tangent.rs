//! Incoming and outgoing tangents of every key: the TCB weights, the four
//! tangent rules, speed matching, end conditions and explicit overrides.
//!
//! # Notation
//!
//! ```text
//! A  = P_k - P_{k-1}      source chord         D- = t_k - t_{k-1}    v- = A / D-
//! B  = P_{k+1} - P_k      destination chord    D+ = t_{k+1} - t_k    v+ = B / D+
//!
//! wIA = (1-t)(1-c)(1+b)/2    wIB = (1-t)(1+c)(1-b)/2    (Kochanek & Bartels 1984, eq. 8)
//! wOA = (1-t)(1+c)(1+b)/2    wOB = (1-t)(1-c)(1-b)/2    (Kochanek & Bartels 1984, eq. 9)
//! ```
//!
//! `DS_k` (incoming) and `DD_k` (outgoing) are in value per segment: `DS_k`
//! in units of the segment arriving at key k, `DD_k` of the one leaving it.
//! Time-unit tangents are `TI_k = DS_k / D-`, `TO_k = DD_k / D+`.
//!
//! # Rules
//!
//! *Interpolation*: all four rules give the same tangents on evenly spaced
//! keys; they differ in how they weight the two chords when `D- != D+`.
//!
//! ```text
//! uniform    DS = wIA A + wIB B                          (K&B eqs. 8-9 as printed)
//!            DD = wOA A + wOB B
//! adjusted   DS = 2 D-/(D- + D+) (wIA A + wIB B)         (K&B section 4, eq. 10 with the
//!            DD = 2 D+/(D- + D+) (wOA A + wOB B)          factors the right way round)
//!            continuity_fade: each factor f -> f + |c| (1 - f)              (3ds Max)
//! secant     TI = wIA v- + wIB v+,  TO = wOA v- + wOB v+  (Eberly, eqs. 10-11)
//! parabolic  TI = 2 (wIA D+ v- + wIB D- v+) / (D- + D+)   (non-uniform Catmull-Rom,
//!            TO = 2 (wOA D+ v- + wOB D- v+) / (D- + D+)    Python `splines`)
//! ```
//!
//! *Continuity*: with `c = 0`, `adjusted` makes `|TI_k| = |TO_k|`, so speed
//! does not jump at the key (the paper's eq. 10 as printed swaps the two
//! factors and does not). `match_speed` (Eberly, eqs. 12-13) forces equal
//! speed for any rule and any `c`:
//!
//! ```text
//! TI' = TI 2|TO| / (|TI| + |TO|)      TO' = TO 2|TI| / (|TI| + |TO|)
//! ```
//!
//! *Usage*: `adjusted` (the default) is what LightWave and 3ds Max animators
//! see; `uniform` reproduces the paper's figures on even keys; `secant`
//! matches Eberly's code; `parabolic` with t = c = b = 0 reproduces quadratic
//! data exactly and matches the `splines` package.
//!
//! # Ends
//!
//! ```text
//! copy     key 0: A = B, D- = D+;      key n-1: B = A, D+ = D-;   then the rule
//! zero     key 0: A = 0, D- = D+;      key n-1: B = 0, D+ = D-;   then the rule
//! natural  TO_0 = 3 (P_1 - P_0) / (2 D_0) - TI_1 / 2
//!          TI_{n-1} = 3 (P_{n-1} - P_{n-2}) / (2 D_{n-2}) - TO_{n-2} / 2
//! cyclic   key 0 = key n-1: A = last chord, D- = last interval,
//!          B = first chord, D+ = first interval; DD_0 = DD, DS_{n-1} = DS
//! ```
//!
//! Explicit per-key tangents (`in`, `out`, value per second) replace the rule
//! on their side: `DS_k = D- in_k`, `DD_k = D+ out_k`. Order of application:
//! rule, then `match_speed`, then overrides, then `natural` ends (which read
//! the final interior tangents).

use crate::params::{Ends, TangentRule, Tcb, TrackSettings};
use crate::vector::Vector;

/// The four TCB weights of one key (Kochanek & Bartels 1984, eqs. 8-9).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// Incoming tangent, weight of the source chord A.
    pub in_a: f64,
    /// Incoming tangent, weight of the destination chord B.
    pub in_b: f64,
    /// Outgoing tangent, weight of A.
    pub out_a: f64,
    /// Outgoing tangent, weight of B.
    pub out_b: f64,
}

impl Weights {
    /// The weights for tension, continuity and bias.
    ///
    /// ```
    /// use tcb_core::{Tcb, tangent::Weights};
    /// let w = Weights::new(Tcb::DEFAULT);
    /// assert_eq!((w.in_a, w.in_b, w.out_a, w.out_b), (0.5, 0.5, 0.5, 0.5));
    /// let corner = Weights::new(Tcb::LINEAR); // c = -1
    /// assert_eq!((corner.in_a, corner.in_b, corner.out_a, corner.out_b), (1.0, 0.0, 0.0, 1.0));
    /// ```
    pub fn new(tcb: Tcb) -> Self {
        let (t, c, b) = (tcb.tension, tcb.continuity, tcb.bias);
        Weights {
            in_a: (1.0 - t) * (1.0 - c) * (1.0 + b) / 2.0,
            in_b: (1.0 - t) * (1.0 + c) * (1.0 - b) / 2.0,
            out_a: (1.0 - t) * (1.0 + c) * (1.0 + b) / 2.0,
            out_b: (1.0 - t) * (1.0 - c) * (1.0 - b) / 2.0,
        }
    }
}

/// What a rule reduces to at one key: `DS = in_a A + in_b B`,
/// `DD = out_a A + out_b B`, with A, B the chords and DS, DD in value per
/// segment. Every rule is linear in the chords, so this is all of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChordWeights {
    /// Coefficient of A in DS.
    pub in_a: f64,
    /// Coefficient of B in DS.
    pub in_b: f64,
    /// Coefficient of A in DD.
    pub out_a: f64,
    /// Coefficient of B in DD.
    pub out_b: f64,
}

impl ChordWeights {
    /// The coefficients of `rule` at a key with parameters `tcb` between
    /// intervals `d_in` (D-) and `d_out` (D+), both positive.
    ///
    /// ```
    /// use tcb_core::{Tcb, TangentRule, tangent::ChordWeights};
    /// // Even spacing: every rule agrees.
    /// let a = ChordWeights::new(TangentRule::Adjusted, Tcb::DEFAULT, 1.0, 1.0);
    /// let s = ChordWeights::new(TangentRule::Secant, Tcb::DEFAULT, 1.0, 1.0);
    /// assert_eq!(a, s);
    /// // adjusted, D- = 1, D+ = 3: DS is scaled by 2/4, DD by 6/4.
    /// let a = ChordWeights::new(TangentRule::Adjusted, Tcb::DEFAULT, 1.0, 3.0);
    /// assert_eq!((a.in_a, a.out_b), (0.25, 0.75));
    /// ```
    pub fn new(rule: TangentRule, tcb: Tcb, d_in: f64, d_out: f64) -> Self {
        Self::weights(rule, false, tcb, d_in, d_out)
    }

    /// [`ChordWeights::new`] with the track setting `continuity_fade`
    /// (math.md): the `adjusted` rule's step-size factors fade towards 1 as
    /// |c| grows; the other rules are as in `new`.
    ///
    /// ```
    /// use tcb_core::{Tcb, TangentRule, tangent::ChordWeights};
    /// let c = Tcb::new(0.0, -1.0, 0.0);
    /// let faded = ChordWeights::with_continuity_fade(TangentRule::Adjusted, c, 1.0, 3.0);
    /// assert_eq!(faded, ChordWeights::new(TangentRule::Uniform, c, 1.0, 3.0));
    /// ```
    pub fn with_continuity_fade(rule: TangentRule, tcb: Tcb, d_in: f64, d_out: f64) -> Self {
        Self::weights(rule, true, tcb, d_in, d_out)
    }

    fn weights(rule: TangentRule, continuity_fade: bool, tcb: Tcb, d_in: f64, d_out: f64) -> Self {
        let w = Weights::new(tcb);
        let sum = d_in + d_out;
        match rule {
            TangentRule::Uniform => ChordWeights {
                in_a: w.in_a,
                in_b: w.in_b,
                out_a: w.out_a,
                out_b: w.out_b,
            },
            TangentRule::Adjusted => {
                let mut f_in = 2.0 * d_in / sum;
                let mut f_out = 2.0 * d_out / sum;
                if continuity_fade {
                    let c = tcb.continuity.abs();
                    f_in += c * (1.0 - f_in);
                    f_out += c * (1.0 - f_out);
                }
                ChordWeights {
                    in_a: f_in * w.in_a,
                    in_b: f_in * w.in_b,
                    out_a: f_out * w.out_a,
                    out_b: f_out * w.out_b,
                }
            }
            // DS = D- (wIA A/D- + wIB B/D+),  DD = D+ (wOA A/D- + wOB B/D+)
            TangentRule::Secant => ChordWeights {
                in_a: w.in_a,
                in_b: w.in_b * d_in / d_out,
                out_a: w.out_a * d_out / d_in,
                out_b: w.out_b,
            },
            // DS = D- 2 (wIA D+ A/D- + wIB D- B/D+) / (D- + D+),  DD likewise with D+
            TangentRule::Parabolic => ChordWeights {
                in_a: 2.0 * w.in_a * d_out / sum,
                in_b: 2.0 * w.in_b * d_in * d_in / (d_out * sum),
                out_a: 2.0 * w.out_a * d_out * d_out / (d_in * sum),
                out_b: 2.0 * w.out_b * d_in / sum,
            },
        }
    }

    /// `(DS, DD)` for chords `a` (arriving) and `b` (leaving).
    pub fn apply<V: Vector>(&self, a: V, b: V) -> (V, V) {
        (
            a.combine(self.in_a, b, self.in_b),
            a.combine(self.out_a, b, self.out_b),
        )
    }
}

/// Eberly's speed matching (eqs. 12-13) on per-segment tangents `ds`, `dd`
/// between intervals `d_in`, `d_out`: afterwards `|ds/d_in| = |dd/d_out|`.
/// Unchanged where both are zero.
pub fn match_speed<V: Vector>(ds: V, dd: V, d_in: f64, d_out: f64) -> (V, V) {
    let ti = ds.norm() / d_in;
    let to = dd.norm() / d_out;
    let sum = ti + to;
    if sum == 0.0 || !sum.is_finite() {
        return (ds, dd);
    }
    (ds.scale(2.0 * to / sum), dd.scale(2.0 * ti / sum))
}

/// The incoming (`DS_k`) and outgoing (`DD_k`) tangent of one key, in value
/// per segment (of the segment arriving, resp. leaving).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyTangents<V> {
    /// `DS_k`.
    pub incoming: V,
    /// `DD_k`.
    pub outgoing: V,
}

/// What the tangent computation needs of one key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentKey<V> {
    /// Tension, continuity, bias.
    pub tcb: Tcb,
    /// Explicit incoming tangent, value per second.
    pub tangent_in: Option<V>,
    /// Explicit outgoing tangent, value per second.
    pub tangent_out: Option<V>,
}

/// `DS_k`, `DD_k` of every key of a track.
///
/// `times` has n >= 2 strictly increasing entries, `chords[k]` is the chord
/// of segment k (`P_{k+1} - P_k`, or a log-difference for rotations; n - 1 of
/// them), `keys` has n entries; `None` when the lengths say otherwise.
/// `Ends::Cyclic` needs a closed track; the caller checks that.
pub fn key_tangents<V: Vector>(
    times: &[f64],
    chords: &[V],
    keys: &[TangentKey<V>],
    settings: &TrackSettings,
) -> Option<Vec<KeyTangents<V>>> {
    key_tangents_wrapped(times, chords, keys, settings, 1.0)
}

/// [`key_tangents`] for a cyclic track whose last value is `wrap_sign`
/// times its first: a `hermite` rotation that turns a full 360 degrees ends
/// on `-q_0`, the same rotation. Each lap is then the previous one negated,
/// so key 0's source chord is `wrap_sign A`, and `DS_{n-1}` (in the last
/// key's sign) is `wrap_sign DS`.
pub fn key_tangents_wrapped<V: Vector>(
    times: &[f64],
    chords: &[V],
    keys: &[TangentKey<V>],
    settings: &TrackSettings,
    wrap_sign: f64,
) -> Option<Vec<KeyTangents<V>>> {
    let n = times.len();
    if n < 2 || chords.len() != n - 1 || keys.len() != n {
        return None;
    }
    let interval = |k: usize| times[k + 1] - times[k];
    let rule = |tcb: Tcb, a: V, b: V, d_in: f64, d_out: f64, speed: bool| {
        let (ds, dd) = ChordWeights::weights(
            settings.tangent_rule,
            settings.continuity_fade,
            tcb,
            d_in,
            d_out,
        )
        .apply(a, b);
        if speed && settings.match_speed {
            match_speed(ds, dd, d_in, d_out)
        } else {
            (ds, dd)
        }
    };

    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let tcb = keys[k].tcb;
        let first = k == 0;
        let last = k == n - 1;
        let (ds, dd, d_in, d_out) = if !first && !last {
            let (d_in, d_out) = (interval(k - 1), interval(k));
            let (ds, dd) = rule(tcb, chords[k - 1], chords[k], d_in, d_out, true);
            (ds, dd, d_in, d_out)
        } else if settings.ends == Ends::Cyclic {
            // Key 0 and key n-1 are one key, with key 0's parameters.
            let (d_in, d_out) = (interval(n - 2), interval(0));
            let a = chords[n - 2].scale(wrap_sign);
            let (ds, dd) = rule(keys[0].tcb, a, chords[0], d_in, d_out, true);
            let ds = if last { ds.scale(wrap_sign) } else { ds };
            (ds, dd, d_in, d_out)
        } else {
            // copy, zero, and the provisional value of natural ends.
            let (chord, d) = if first {
                (chords[0], interval(0))
            } else {
                (chords[n - 2], interval(n - 2))
            };
            let missing = if settings.ends == Ends::Zero {
                V::ZERO
            } else {
                chord
            };
            let (a, b) = if first {
                (missing, chord)
            } else {
                (chord, missing)
            };
            let (ds, dd) = rule(tcb, a, b, d, d, false);
            (ds, dd, d, d)
        };
        let key = &keys[k];
        let ds = key.tangent_in.map_or(ds, |v| v.scale(d_in));
        let dd = key.tangent_out.map_or(dd, |v| v.scale(d_out));
        out.push(KeyTangents {
            incoming: ds,
            outgoing: dd,
        });
    }

    if settings.ends == Ends::Natural {
        natural_ends(chords, keys, &mut out);
    }
    Some(out)
}

/// `natural` ends in per-segment units: with `TO_0 = DD_0 / D_0` and
/// `TI_1 = DS_1 / D_0`, `TO_0 = 3 C_0 / (2 D_0) - TI_1 / 2` is
/// `DD_0 = 1.5 C_0 - 0.5 DS_1`; likewise `DS_{n-1} = 1.5 C_{n-2} - 0.5 DD_{n-2}`.
/// With n = 2 the two equations are solved together (the straight chord
/// when neither end has an explicit tangent).
fn natural_ends<V: Vector>(chords: &[V], keys: &[TangentKey<V>], out: &mut [KeyTangents<V>]) {
    let n = out.len();
    let first_free = keys[0].tangent_out.is_none();
    let last_free = keys[n - 1].tangent_in.is_none();
    let first_chord = chords[0];
    let last_chord = chords[n - 2];
    if n == 2 && first_free && last_free {
        out[0].outgoing = first_chord;
        out[1].incoming = first_chord;
        return;
    }
    if first_free {
        out[0].outgoing = first_chord.combine(1.5, out[1].incoming, -0.5);
    }
    if last_free {
        out[n - 1].incoming = last_chord.combine(1.5, out[n - 2].outgoing, -0.5);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tangents of well-formed inputs (every test's are).
    fn key_tangents<V: Vector>(
        times: &[f64],
        chords: &[V],
        keys: &[TangentKey<V>],
        settings: &TrackSettings,
    ) -> Vec<KeyTangents<V>> {
        super::key_tangents(times, chords, keys, settings).expect("well-formed inputs")
    }

    #[test]
    fn key_tangents_refuse_lengths_that_disagree() {
        let k = [TangentKey {
            tcb: Tcb::DEFAULT,
            tangent_in: None,
            tangent_out: None,
        }; 3];
        let s = TrackSettings::default();
        assert!(super::key_tangents(&[0.0, 1.0, 2.0], &[1.0f32, 2.0], &k, &s).is_some());
        assert!(super::key_tangents(&[0.0, 1.0, 2.0], &[1.0f32], &k, &s).is_none());
        assert!(super::key_tangents(&[0.0, 1.0], &[1.0f32], &k, &s).is_none());
        assert!(super::key_tangents::<f32>(&[0.0], &[], &k[..1], &s).is_none());
        assert!(super::key_tangents::<f32>(&[], &[], &[], &s).is_none());
    }
    use crate::params::TrackSettings;

    fn keys(tcbs: &[Tcb]) -> Vec<TangentKey<f32>> {
        tcbs.iter()
            .map(|&tcb| TangentKey {
                tcb,
                tangent_in: None,
                tangent_out: None,
            })
            .collect()
    }

    fn settings(rule: TangentRule, ends: Ends) -> TrackSettings {
        TrackSettings {
            tangent_rule: rule,
            ends,
            ..TrackSettings::default()
        }
    }

    #[test]
    fn tension_one_gives_zero_tangents() {
        let w = Weights::new(Tcb::STOP);
        assert_eq!((w.in_a, w.in_b, w.out_a, w.out_b), (0.0, 0.0, 0.0, 0.0));
    }

    #[test]
    fn tension_minus_one_doubles() {
        let w = Weights::new(Tcb::new(-1.0, 0.0, 0.0));
        assert_eq!((w.in_a, w.in_b, w.out_a, w.out_b), (1.0, 1.0, 1.0, 1.0));
    }

    #[test]
    fn bias_one_takes_the_source_chord() {
        let w = Weights::new(Tcb::new(0.0, 0.0, 1.0));
        assert_eq!((w.in_a, w.in_b, w.out_a, w.out_b), (1.0, 0.0, 1.0, 0.0));
    }

    #[test]
    fn rules_by_hand_on_uneven_keys() {
        // D- = 1, D+ = 3, t = c = b = 0, A = 2, B = 6 (v- = 2, v+ = 2).
        let (a, b) = (2.0f32, 6.0f32);
        let ds_dd = |rule| ChordWeights::new(rule, Tcb::DEFAULT, 1.0, 3.0).apply(a, b);
        // uniform: (A + B)/2 both sides.
        assert_eq!(ds_dd(TangentRule::Uniform), (4.0, 4.0));
        // adjusted: 2*1/4 * 4 = 2, 2*3/4 * 4 = 6 -> TI = 2, TO = 2.
        assert_eq!(ds_dd(TangentRule::Adjusted), (2.0, 6.0));
        // secant: TI = TO = (2 + 2)/2 = 2 -> DS = 2, DD = 6.
        assert_eq!(ds_dd(TangentRule::Secant), (2.0, 6.0));
        // parabolic: TI = 2 (0.5*3*2 + 0.5*1*2)/4 = 2 -> DS = 2, DD = 6.
        assert_eq!(ds_dd(TangentRule::Parabolic), (2.0, 6.0));
    }

    #[test]
    fn rules_differ_on_a_bend() {
        // D- = 1, D+ = 3, A = 1 (v- = 1), B = 9 (v+ = 3).
        let ds_dd = |rule| ChordWeights::new(rule, Tcb::DEFAULT, 1.0, 3.0).apply(1.0f64, 9.0);
        assert_eq!(ds_dd(TangentRule::Uniform), (5.0, 5.0));
        assert_eq!(ds_dd(TangentRule::Adjusted), (2.5, 7.5));
        // secant: TI = TO = 2 -> DS = 2, DD = 6
        assert_eq!(ds_dd(TangentRule::Secant), (2.0, 6.0));
        // parabolic: TI = TO = 2 (0.5*3*1 + 0.5*1*3)/4 = 1.5 -> DS = 1.5, DD = 4.5
        assert_eq!(ds_dd(TangentRule::Parabolic), (1.5, 4.5));
    }

    #[test]
    fn continuity_fade_removes_the_adjustment_at_c_minus_one() {
        let tcb = Tcb::new(0.0, -1.0, 0.0);
        let faded = ChordWeights::with_continuity_fade(TangentRule::Adjusted, tcb, 1.0, 3.0);
        let plain = ChordWeights::new(TangentRule::Uniform, tcb, 1.0, 3.0);
        assert_eq!(faded, plain);
        // c = -0.5: f_in = 0.5 -> 0.75, f_out = 1.5 -> 1.25.
        let tcb = Tcb::new(0.0, -0.5, 0.0);
        let w = Weights::new(tcb);
        let faded = ChordWeights::with_continuity_fade(TangentRule::Adjusted, tcb, 1.0, 3.0);
        assert_eq!(faded.in_a, 0.75 * w.in_a);
        assert_eq!(faded.out_b, 1.25 * w.out_b);
    }

    #[test]
    fn match_speed_by_hand() {
        // TI = 1 (ds 1 over 1 s), TO = 3 (dd 6 over 2 s): both become 1.5.
        let (ds, dd) = match_speed(1.0f64, 6.0, 1.0, 2.0);
        assert_eq!((ds, dd), (1.5, 3.0));
        assert_eq!(match_speed(0.0f64, 0.0, 1.0, 2.0), (0.0, 0.0));
    }

    #[test]
    fn ends_by_hand() {
        // Keys 0, 1, 3 at times 0, 1, 2: chords 1 and 2, even spacing.
        let times = [0.0, 1.0, 2.0];
        let chords = [1.0f32, 2.0];
        let k = keys(&[Tcb::DEFAULT; 3]);
        let run = |ends| key_tangents(&times, &chords, &k, &settings(TangentRule::Uniform, ends));
        let copy = run(Ends::Copy);
        assert_eq!(copy[0].outgoing, 1.0);
        assert_eq!(copy[1].incoming, 1.5);
        assert_eq!(copy[2].incoming, 2.0);
        let zero = run(Ends::Zero);
        assert_eq!(zero[0].outgoing, 0.5);
        assert_eq!(zero[2].incoming, 1.0);
        let natural = run(Ends::Natural);
        // DD_0 = 1.5*1 - 0.5*1.5 = 0.75, DS_2 = 1.5*2 - 0.5*1.5 = 2.25
        assert_eq!(natural[0].outgoing, 0.75);
        assert_eq!(natural[2].incoming, 2.25);
    }

    #[test]
    fn cyclic_uses_the_wrap_chords_and_key_zero_parameters() {
        // 0 -> 1 -> 3 -> 0 at times 0, 1, 2, 4.
        let times = [0.0, 1.0, 2.0, 4.0];
        let chords = [1.0f32, 2.0, -3.0];
        let mut k = keys(&[Tcb::DEFAULT; 4]);
        k[3].tcb = Tcb::STOP; // ignored: key 3 is key 0
        let t = key_tangents(
            &times,
            &chords,
            &k,
            &settings(TangentRule::Uniform, Ends::Cyclic),
        );
        // A = -3, B = 1: (A + B)/2 = -1.
        assert_eq!(t[0].outgoing, -1.0);
        assert_eq!(t[3].incoming, -1.0);
    }

    #[test]
    fn natural_with_two_keys_is_the_chord() {
        let t = key_tangents(
            &[0.0, 2.0],
            &[4.0f32],
            &keys(&[Tcb::STOP, Tcb::OVERSHOOT]),
            &settings(TangentRule::Adjusted, Ends::Natural),
        );
        assert_eq!((t[0].outgoing, t[1].incoming), (4.0, 4.0));
    }

    #[test]
    fn two_keys_copy_and_zero_use_each_key_own_tcb() {
        let k = keys(&[Tcb::new(0.5, 0.0, 0.0), Tcb::new(0.0, 0.0, 0.0)]);
        let copy = key_tangents(
            &[0.0, 1.0],
            &[2.0f32],
            &k,
            &settings(TangentRule::Adjusted, Ends::Copy),
        );
        assert_eq!((copy[0].outgoing, copy[1].incoming), (1.0, 2.0));
        let zero = key_tangents(
            &[0.0, 1.0],
            &[2.0f32],
            &k,
            &settings(TangentRule::Adjusted, Ends::Zero),
        );
        assert_eq!((zero[0].outgoing, zero[1].incoming), (0.5, 1.0));
    }

    #[test]
    fn overrides_replace_the_rule_in_time_units() {
        let mut k = keys(&[Tcb::DEFAULT; 3]);
        k[1].tangent_in = Some(10.0);
        k[1].tangent_out = Some(-1.0);
        let t = key_tangents(
            &[0.0, 2.0, 5.0],
            &[1.0f32, 1.0],
            &k,
            &TrackSettings::default(),
        );
        assert_eq!(t[1].incoming, 20.0);
        assert_eq!(t[1].outgoing, -3.0);
    }
}
