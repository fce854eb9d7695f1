//! What can be wrong with a track's data. Checked once, when a track is
//! built; sampling a built track cannot fail.

use crate::params::Extrapolation;
use std::fmt;

/// A track that cannot be built, with the key at fault where there is one.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum TrackError {
    /// Fewer than 2 keys (cyclic tracks need 3).
    TooFewKeys {
        /// Keys given.
        count: usize,
        /// Keys needed.
        needed: usize,
    },
    /// A per-key list whose length is not the number of keys.
    LengthMismatch {
        /// Which list (`values`, `keys`).
        what: &'static str,
        /// The number of times.
        expected: usize,
        /// Its length.
        found: usize,
    },
    /// A key time that is NaN or infinite.
    NonFiniteTime {
        /// The key.
        key: usize,
    },
    /// A key time not greater than the one before it.
    NonIncreasingTime {
        /// The key.
        key: usize,
        /// Its time.
        time: f64,
        /// The previous key's time.
        previous: f64,
    },
    /// The keys span more time than an f64 can hold.
    TimeSpanTooLarge,
    /// A value (or explicit tangent) with a NaN or infinite component.
    NonFiniteValue {
        /// The key.
        key: usize,
        /// `value`, `in` or `out`.
        what: &'static str,
    },
    /// A tension, continuity or bias that is NaN or infinite.
    NonFiniteTcb {
        /// The key.
        key: usize,
    },
    /// An ease value outside [0, 1].
    EaseOutOfRange {
        /// The key.
        key: usize,
        /// `[to, from]`.
        ease: [f64; 2],
    },
    /// A quaternion of zero length.
    ZeroQuaternion {
        /// The key.
        key: usize,
    },
    /// `cyclic` ends on a track whose last value is not its first.
    CyclicNotClosed {
        /// The last key.
        key: usize,
    },
    /// `natural` ends on a `squad` rotation.
    NaturalOnSquad,
    /// Explicit `in`/`out` tangents on a `squad` rotation.
    TangentOnSquad {
        /// The key.
        key: usize,
    },
    /// `linear` or `offset-repeat` extrapolation on a rotation.
    ExtrapolationOnRotation {
        /// `pre` or `post`.
        side: &'static str,
        /// The mode.
        mode: Extrapolation,
    },
}

impl TrackError {
    /// The key at fault, if one is.
    pub fn key(&self) -> Option<usize> {
        match *self {
            TrackError::NonFiniteTime { key }
            | TrackError::NonIncreasingTime { key, .. }
            | TrackError::NonFiniteValue { key, .. }
            | TrackError::NonFiniteTcb { key }
            | TrackError::EaseOutOfRange { key, .. }
            | TrackError::ZeroQuaternion { key }
            | TrackError::CyclicNotClosed { key }
            | TrackError::TangentOnSquad { key } => Some(key),
            _ => None,
        }
    }
}

impl fmt::Display for TrackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(key) = self.key() {
            write!(f, "key {key}: ")?;
        }
        match self {
            TrackError::TooFewKeys { count, needed } => {
                write!(f, "{count} key(s); at least {needed} are needed")
            }
            TrackError::LengthMismatch {
                what,
                expected,
                found,
            } => write!(f, "{found} {what} for {expected} times"),
            TrackError::NonFiniteTime { .. } => write!(f, "time is not a finite number"),
            TrackError::NonIncreasingTime { time, previous, .. } => write!(
                f,
                "time {time} is not after the previous key's time {previous} (times must strictly increase)"
            ),
            TrackError::TimeSpanTooLarge => {
                write!(f, "the keys span more time than can be represented")
            }
            TrackError::NonFiniteValue { what, .. } => {
                write!(f, "{what} has a component that is not a finite f32")
            }
            TrackError::NonFiniteTcb { .. } => write!(f, "tcb has a value that is not finite"),
            TrackError::EaseOutOfRange { ease, .. } => {
                write!(f, "ease [{}, {}] is outside [0, 1]", ease[0], ease[1])
            }
            TrackError::ZeroQuaternion { .. } => write!(f, "quaternion has zero length"),
            TrackError::CyclicNotClosed { .. } => write!(
                f,
                "ends \"cyclic\" needs the last value to equal the first (within 1e-6)"
            ),
            TrackError::NaturalOnSquad => write!(
                f,
                "ends \"natural\" is not defined for \"squad\" rotations (use rotation \"hermite\")"
            ),
            TrackError::TangentOnSquad { .. } => write!(
                f,
                "explicit in/out tangents need rotation \"hermite\", not \"squad\""
            ),
            TrackError::ExtrapolationOnRotation { side, mode } => {
                write!(f, "{side} \"{mode}\" is not defined for rotations")
            }
        }
    }
}

impl std::error::Error for TrackError {}
