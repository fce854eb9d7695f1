//! Outside the keys: mapping any f64 sample time to what the track gives.
//!
//! With `L = t_{n-1} - t_0`, `m = floor((time - t_0) / L)`,
//! `r = (time - t_0) - m L`:
//!
//! ```text
//! constant        the end key's value
//! reset           zero (identity for rotations)
//! repeat          the value at t_0 + r
//! oscillate       the value at t_0 + r for even m, at t_{n-1} - r for odd m
//! offset-repeat   the value at t_0 + r plus m (P_{n-1} - P_0)
//! linear          P_0 + TO_0 (time - t_0) before, P_{n-1} + TI_{n-1} (time - t_{n-1}) after
//! ```
//!
//! The wrap is done in f64, before anything becomes f32, so a loop sampled
//! at 1e6 s is as exact as one sampled at 1 s.
//!
//! Times that are not finite never fail: NaN gives the first key's value and
//! an infinite time the value of the end key on its side (as `constant`
//! would, or zero for `reset`), all with zero velocity.

use crate::params::Extrapolation;

/// Where a sample time lands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapped {
    /// Evaluate the keys at `time` in `[t_0, t_{n-1}]`; multiply the
    /// velocity by `direction` (-1 on the backward legs of `oscillate`) and
    /// add `cycles (P_{n-1} - P_0)` to the value (non-zero only for
    /// `offset-repeat`).
    Inside {
        /// The time inside the keys.
        time: f64,
        /// +1 or -1.
        direction: f64,
        /// Whole cycles to offset by.
        cycles: f64,
    },
    /// The first (`last == false`) or last key's value, zero velocity.
    Hold {
        /// Which end.
        last: bool,
    },
    /// Zero (identity rotation), zero velocity.
    Reset,
    /// Along the end tangent, `dt` seconds from the end key.
    Line {
        /// Which end.
        last: bool,
        /// Seconds from that key (negative before the first).
        dt: f64,
    },
}

/// Map `time` for a track with keys spanning `[t0, tn]`.
///
/// ```
/// use tcb_core::{Extrapolation as E, extrapolate::{map_time, Mapped}};
/// let m = map_time(5.5, 0.0, 2.0, E::Constant, E::Oscillate);
/// // m = 2 (even), r = 1.5
/// assert_eq!(m, Mapped::Inside { time: 1.5, direction: 1.0, cycles: 0.0 });
/// let m = map_time(3.5, 0.0, 2.0, E::Constant, E::Oscillate);
/// // m = 1 (odd): backwards from t_{n-1}
/// assert_eq!(m, Mapped::Inside { time: 0.5, direction: -1.0, cycles: 0.0 });
/// ```
pub fn map_time(time: f64, t0: f64, tn: f64, pre: Extrapolation, post: Extrapolation) -> Mapped {
    if time.is_nan() {
        return Mapped::Hold { last: false };
    }
    if (t0..=tn).contains(&time) {
        return Mapped::Inside {
            time,
            direction: 1.0,
            cycles: 0.0,
        };
    }
    let after = time > tn;
    let mode = if after { post } else { pre };
    if time.is_infinite() {
        return match mode {
            Extrapolation::Reset => Mapped::Reset,
            _ => Mapped::Hold { last: after },
        };
    }
    match mode {
        Extrapolation::Constant => Mapped::Hold { last: after },
        Extrapolation::Reset => Mapped::Reset,
        Extrapolation::Linear => Mapped::Line {
            last: after,
            dt: if after { time - tn } else { time - t0 },
        },
        Extrapolation::Repeat | Extrapolation::Oscillate | Extrapolation::OffsetRepeat => {
            let len = tn - t0;
            let m = ((time - t0) / len).floor();
            // Rounding can push r a hair outside [0, L].
            let r = ((time - t0) - m * len).clamp(0.0, len);
            match mode {
                Extrapolation::Oscillate if m.rem_euclid(2.0) == 1.0 => Mapped::Inside {
                    time: tn - r,
                    direction: -1.0,
                    cycles: 0.0,
                },
                Extrapolation::OffsetRepeat => Mapped::Inside {
                    time: t0 + r,
                    direction: 1.0,
                    cycles: m,
                },
                _ => Mapped::Inside {
                    time: t0 + r,
                    direction: 1.0,
                    cycles: 0.0,
                },
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Extrapolation as E;

    fn inside(time: f64, direction: f64, cycles: f64) -> Mapped {
        Mapped::Inside {
            time,
            direction,
            cycles,
        }
    }

    #[test]
    fn every_mode_by_hand() {
        // keys from 1 to 3 (L = 2)
        let m = |t, mode| map_time(t, 1.0, 3.0, mode, mode);
        assert_eq!(m(2.0, E::Reset), inside(2.0, 1.0, 0.0));
        assert_eq!(m(0.0, E::Constant), Mapped::Hold { last: false });
        assert_eq!(m(4.0, E::Constant), Mapped::Hold { last: true });
        assert_eq!(m(4.0, E::Reset), Mapped::Reset);
        assert_eq!(
            m(4.0, E::Linear),
            Mapped::Line {
                last: true,
                dt: 1.0
            }
        );
        assert_eq!(
            m(0.5, E::Linear),
            Mapped::Line {
                last: false,
                dt: -0.5
            }
        );
        assert_eq!(m(3.5, E::Repeat), inside(1.5, 1.0, 0.0));
        assert_eq!(m(0.5, E::Repeat), inside(2.5, 1.0, 0.0));
        assert_eq!(m(7.5, E::OffsetRepeat), inside(1.5, 1.0, 3.0));
        assert_eq!(m(0.5, E::OffsetRepeat), inside(2.5, 1.0, -1.0));
        // oscillate, t_0 != 0: m = 1 -> backwards from 3.
        assert_eq!(m(3.5, E::Oscillate), inside(2.5, -1.0, 0.0));
        assert_eq!(m(5.5, E::Oscillate), inside(1.5, 1.0, 0.0));
        // before: m = -1 (odd) -> backwards.
        assert_eq!(m(0.5, E::Oscillate), inside(1.5, -1.0, 0.0));
    }

    #[test]
    fn huge_times_wrap_exactly() {
        let m = map_time(1e6 + 0.25, 0.0, 2.0, E::Repeat, E::Repeat);
        assert_eq!(m, inside(0.25, 1.0, 0.0));
    }

    #[test]
    fn non_finite_times() {
        for mode in E::ALL {
            assert_eq!(
                map_time(f64::NAN, 0.0, 1.0, *mode, *mode),
                Mapped::Hold { last: false }
            );
            let inf = map_time(f64::INFINITY, 0.0, 1.0, *mode, *mode);
            let neg = map_time(f64::NEG_INFINITY, 0.0, 1.0, *mode, *mode);
            if *mode == E::Reset {
                assert_eq!((inf, neg), (Mapped::Reset, Mapped::Reset));
            } else {
                assert_eq!(inf, Mapped::Hold { last: true });
                assert_eq!(neg, Mapped::Hold { last: false });
            }
        }
    }
}
