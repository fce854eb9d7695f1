//! Per-key and per-track parameters: tension, continuity, bias, ease, segment
//! shape, tangent rule, end condition, extrapolation and rotation mode.
//!
//! Every enum here has a stable lower-case name (the one the clip file uses),
//! available through `name()` and `FromStr`.

use std::fmt;
use std::str::FromStr;

/// Tension, continuity and bias of one key (Kochanek & Bartels 1984, section 3).
///
/// ```text
/// t =  1: zero tangent (the curve stops at the key)   t = -1: tangent doubled
/// c = -1: corner (incoming = source chord, outgoing = destination chord)
/// b =  1: tangent from the source chord (overshoot)   b = -1: from the destination
/// ```
///
/// Values are usually in [-1, 1]; values beyond are allowed (the paper's
/// animators used them), non-finite values are rejected when a track is built.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Tcb {
    /// Tension `t`.
    pub tension: f64,
    /// Continuity `c`.
    pub continuity: f64,
    /// Bias `b`.
    pub bias: f64,
}

impl Tcb {
    /// t = c = b = 0: the Catmull-Rom spline on evenly spaced keys.
    pub const DEFAULT: Tcb = Tcb::new(0.0, 0.0, 0.0);
    /// The paper's section 5 example of overshoot: t = -0.3, c = 0, b = 1.
    pub const OVERSHOOT: Tcb = Tcb::new(-0.3, 0.0, 1.0);
    /// c = -1: incoming tangent = source chord, outgoing = destination chord;
    /// with the `uniform` rule on every key this is linear interpolation.
    pub const LINEAR: Tcb = Tcb::new(0.0, -1.0, 0.0);
    /// t = 1: zero tangents, the motion eases in and out of the key.
    pub const STOP: Tcb = Tcb::new(1.0, 0.0, 0.0);

    /// Tension, continuity, bias.
    pub const fn new(tension: f64, continuity: f64, bias: f64) -> Self {
        Tcb {
            tension,
            continuity,
            bias,
        }
    }

    /// `[t, c, b]` as the clip file writes it.
    pub const fn from_array(a: [f64; 3]) -> Self {
        Tcb::new(a[0], a[1], a[2])
    }

    /// `[t, c, b]`.
    pub const fn to_array(self) -> [f64; 3] {
        [self.tension, self.continuity, self.bias]
    }

    /// All three finite.
    pub fn is_finite(self) -> bool {
        self.tension.is_finite() && self.continuity.is_finite() && self.bias.is_finite()
    }
}

/// 3ds Max "ease to" / "ease from" of a key, each in [0, 1].
///
/// Segment k uses `a = from_k` (leaving key k) and `e = to_{k+1}` (arriving
/// at key k+1); see [`crate::ease`].
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Ease {
    /// Ease to: slow down when arriving at this key.
    pub to: f64,
    /// Ease from: start slowly when leaving this key.
    pub from: f64,
}

impl Ease {
    /// No easing.
    pub const NONE: Ease = Ease { to: 0.0, from: 0.0 };

    /// `[to, from]` as the clip file writes it.
    pub const fn from_array(a: [f64; 2]) -> Self {
        Ease {
            to: a[0],
            from: a[1],
        }
    }

    /// Both in [0, 1] (and so finite).
    pub fn is_valid(self) -> bool {
        (0.0..=1.0).contains(&self.to) && (0.0..=1.0).contains(&self.from)
    }
}

macro_rules! named_enum {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $variant:ident = $text:literal,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
        #[non_exhaustive]
        pub enum $name {
            $($(#[$vmeta])* $variant,)+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant,)+];

            /// The lower-case name the clip file uses.
            pub const fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)+
                }
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $name {
            type Err = UnknownName;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                match s {
                    $($text => Ok($name::$variant),)+
                    _ => Err(UnknownName {
                        what: stringify!($name),
                        expected: &[$($text,)+],
                    }),
                }
            }
        }
    };
}

/// A name that is not one of an enum's values.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownName {
    /// The enum's Rust name.
    pub what: &'static str,
    /// The names it accepts.
    pub expected: &'static [&'static str],
}

impl fmt::Display for UnknownName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "expected one of: {}", self.expected.join(", "))
    }
}

impl std::error::Error for UnknownName {}

named_enum! {
    /// How a key's incoming and outgoing tangents are weighted by the key
    /// spacing. All four agree on evenly spaced keys; see [`crate::tangent`].
    TangentRule {
        /// Kochanek & Bartels eqs. 8-9 as printed, ignoring key spacing.
        Uniform = "uniform",
        /// The paper's section 4 step-size adjustment with intervals for
        /// inbetween counts (LightWave, 3ds Max); keeps speed continuous at c = 0.
        #[default]
        Adjusted = "adjusted",
        /// Eberly's non-uniform TCB: weights applied to secant slopes.
        Secant = "secant",
        /// Non-uniform Catmull-Rom weighting (Python `splines` package).
        Parabolic = "parabolic",
    }
}

named_enum! {
    /// What stands in for the missing neighbour at the first and last key;
    /// see [`crate::tangent`].
    Ends {
        /// The missing chord copies the existing one (3D Studio / 3ds Max).
        #[default]
        Copy = "copy",
        /// The missing chord is zero (the paper's suggestion, Eberly's code).
        Zero = "zero",
        /// Second derivative zero at the ends.
        Natural = "natural",
        /// Closed loop: the last key is the first key again.
        Cyclic = "cyclic",
    }
}

named_enum! {
    /// Shape of the segment leaving a key.
    Interp {
        /// The Hermite cubic with the key's TCB tangents.
        #[default]
        Curve = "curve",
        /// The straight chord at constant speed (slerp for rotations).
        Linear = "linear",
        /// Holds the key's value until the next key.
        Step = "step",
    }
}

named_enum! {
    /// What a track gives before its first key (`pre`) or after its last (`post`).
    Extrapolation {
        /// The end key's value.
        #[default]
        Constant = "constant",
        /// Zero (identity for rotations).
        Reset = "reset",
        /// The track again, from its first key.
        Repeat = "repeat",
        /// The track forwards, then backwards, then forwards...
        Oscillate = "oscillate",
        /// Repeat, each cycle shifted by the last key minus the first (not for rotations).
        OffsetRepeat = "offset-repeat",
        /// Straight line along the end tangent (not for rotations).
        Linear = "linear",
    }
}

named_enum! {
    /// How rotation (quaternion) tracks are interpolated.
    RotationMode {
        /// 3ds Max-style TCB on quaternions: squad with TCB inner quadrangle points.
        #[default]
        Squad = "squad",
        /// The four components as a vector track, normalized (glTF CUBICSPLINE style).
        Hermite = "hermite",
    }
}

named_enum! {
    /// Whether a rotation track's keys are moved to one hemisphere at load.
    Hemisphere {
        /// Each key is flipped to the hemisphere of the previous one
        /// (`q_k = -q_k` where `dot(q_{k-1}, q_k) < 0`), its explicit
        /// tangents with it, so every segment takes the short way.
        #[default]
        Nearest = "nearest",
        /// Keys and their tangents are used exactly as written (glTF
        /// `CUBICSPLINE` rotations, which viewers interpolate as stored).
        Keep = "keep",
    }
}

/// Track-wide settings; the clip file's `defaults`, overridable per track.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TrackSettings {
    /// Tangent rule.
    pub tangent_rule: TangentRule,
    /// End condition.
    pub ends: Ends,
    /// Eberly's speed matching at interior keys (eqs. 12-13).
    pub match_speed: bool,
    /// 3ds Max: fade the `adjusted` factors out as |c| goes to 1.
    pub continuity_fade: bool,
    /// Before the first key.
    pub pre: Extrapolation,
    /// After the last key.
    pub post: Extrapolation,
    /// Rotation tracks only.
    pub rotation: RotationMode,
    /// Rotation tracks only: flip keys to one hemisphere at load, or keep them.
    pub hemisphere: Hemisphere,
}

/// Per-key parameters of a track with values of type `V`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyParams<V> {
    /// Tension, continuity, bias.
    pub tcb: Tcb,
    /// Ease to / ease from.
    pub ease: Ease,
    /// Shape of the segment leaving this key.
    pub interp: Interp,
    /// Explicit incoming tangent, value per second (replaces the rule).
    pub tangent_in: Option<V>,
    /// Explicit outgoing tangent, value per second (replaces the rule).
    pub tangent_out: Option<V>,
}

impl<V> Default for KeyParams<V> {
    fn default() -> Self {
        KeyParams {
            tcb: Tcb::DEFAULT,
            ease: Ease::NONE,
            interp: Interp::Curve,
            tangent_in: None,
            tangent_out: None,
        }
    }
}

impl<V> KeyParams<V> {
    /// Default parameters with the given tension, continuity and bias.
    pub fn with_tcb(tcb: Tcb) -> Self {
        KeyParams {
            tcb,
            ..Self::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for r in TangentRule::ALL {
            assert_eq!(r.name().parse::<TangentRule>().unwrap(), *r);
        }
        for e in Extrapolation::ALL {
            assert_eq!(e.name().parse::<Extrapolation>().unwrap(), *e);
        }
        assert_eq!(
            "offset-repeat".parse::<Extrapolation>(),
            Ok(Extrapolation::OffsetRepeat)
        );
        let err = "Adjusted".parse::<TangentRule>().unwrap_err();
        assert_eq!(
            err.to_string(),
            "expected one of: uniform, adjusted, secant, parabolic"
        );
    }

    #[test]
    fn defaults_are_the_contract_defaults() {
        let s = TrackSettings::default();
        assert_eq!(s.tangent_rule, TangentRule::Adjusted);
        assert_eq!(s.ends, Ends::Copy);
        assert_eq!(s.pre, Extrapolation::Constant);
        assert_eq!(s.rotation, RotationMode::Squad);
        assert!(!s.match_speed && !s.continuity_fade);
    }
}
