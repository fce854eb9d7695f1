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
use crate::simd::lane::{Lane, Mask};

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
/// use tcb_core::{Extrapolation as E, simd::extrapolate::{map_time, Mapped}};
/// let m = map_time(5.5, 0.0, 2.0, E::Constant, E::Oscillate);
/// // m = 2 (even), r = 1.5
/// assert_eq!(m, Mapped::Inside { time: 1.5, direction: 1.0, cycles: 0.0 });
/// let m = map_time(3.5, 0.0, 2.0, E::Constant, E::Oscillate);
/// // m = 1 (odd): backwards from t_{n-1}
/// assert_eq!(m, Mapped::Inside { time: 0.5, direction: -1.0, cycles: 0.0 });
/// ```
#[inline]
pub fn map_time(time: f64, t0: f64, tn: f64, pre: Extrapolation, post: Extrapolation) -> Mapped {
    // Inside the keys `map_lanes` passes the time through unchanged; say so
    // without computing every mode's answer (one lane has nothing to share).
    if (t0..=tn).contains(&time) {
        return Mapped::Inside {
            time,
            direction: 1.0,
            cycles: 0.0,
        };
    }
    let l = map_lanes(time, t0, tn, &ModeLanes::of(pre), &ModeLanes::of(post));
    if l.inside {
        Mapped::Inside {
            time: l.time,
            direction: l.direction,
            cycles: l.cycles,
        }
    } else if l.reset {
        Mapped::Reset
    } else if l.line {
        Mapped::Line {
            last: l.last,
            dt: l.dt,
        }
    } else {
        Mapped::Hold { last: l.last }
    }
}

/// An extrapolation mode per lane, as one mask per mode (exactly one set in
/// each lane), so that [`map_lanes`] selects instead of branching.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeLanes<M> {
    /// `constant`.
    pub constant: M,
    /// `reset`.
    pub reset: M,
    /// `repeat`.
    pub repeat: M,
    /// `oscillate`.
    pub oscillate: M,
    /// `offset-repeat`.
    pub offset_repeat: M,
    /// `linear`.
    pub linear: M,
}

impl ModeLanes<bool> {
    /// One lane of `mode`.
    pub fn of(mode: Extrapolation) -> Self {
        use Extrapolation as E;
        ModeLanes {
            constant: mode == E::Constant,
            reset: mode == E::Reset,
            repeat: mode == E::Repeat,
            oscillate: mode == E::Oscillate,
            offset_repeat: mode == E::OffsetRepeat,
            linear: mode == E::Linear,
        }
    }
}

impl<M: Mask> ModeLanes<M> {
    /// Lanes of `lanes` modes, built from one lane each (`make` turns the
    /// lanes' booleans into a mask).
    pub fn from_lanes<const N: usize>(
        lanes: [Extrapolation; N],
        make: impl Fn([bool; N]) -> M,
    ) -> Self {
        let one = lanes.map(ModeLanes::of);
        let m = |f: fn(&ModeLanes<bool>) -> bool| make(std::array::from_fn(|i| f(&one[i])));
        ModeLanes {
            constant: m(|x| x.constant),
            reset: m(|x| x.reset),
            repeat: m(|x| x.repeat),
            oscillate: m(|x| x.oscillate),
            offset_repeat: m(|x| x.offset_repeat),
            linear: m(|x| x.linear),
        }
    }

    /// `post` where `after`, else `pre`.
    #[inline(always)]
    fn pick(after: M, pre: &Self, post: &Self) -> Self {
        let p = |a: M, b: M| (after & b) | (!after & a);
        ModeLanes {
            constant: p(pre.constant, post.constant),
            reset: p(pre.reset, post.reset),
            repeat: p(pre.repeat, post.repeat),
            oscillate: p(pre.oscillate, post.oscillate),
            offset_repeat: p(pre.offset_repeat, post.offset_repeat),
            linear: p(pre.linear, post.linear),
        }
    }
}

/// Where sample times land, lane by lane: the select form of [`Mapped`].
/// In each lane exactly one of `inside`, `hold`, `reset`, `line` is set.
#[derive(Clone, Copy, Debug)]
pub struct MappedLanes<L: Lane> {
    /// Evaluate the keys at `time` (with `direction` and `cycles`).
    pub inside: L::Mask,
    /// The end key's value (`last` says which), zero velocity.
    pub hold: L::Mask,
    /// Zero (identity for rotations).
    pub reset: L::Mask,
    /// Along the end tangent, `dt` from the end key `last` says.
    pub line: L::Mask,
    /// For `hold` and `line`: the last key (else the first).
    pub last: L::Mask,
    /// The time inside the keys.
    pub time: L,
    /// +1, or -1 on the backward legs of `oscillate`.
    pub direction: L,
    /// Whole cycles of `offset-repeat`.
    pub cycles: L,
    /// Seconds from the end key (negative before the first).
    pub dt: L,
}

/// [`map_time`] for any [`Lane`]: each lane its own time, key span and
/// modes. The one formula of the module docs, for the reference (one
/// `f64` lane) and for the runtime's tracks on their own key times (`f64x4`).
#[inline(always)]
pub fn map_lanes<L: Lane>(
    time: L,
    t0: L,
    tn: L,
    pre: &ModeLanes<L::Mask>,
    post: &ModeLanes<L::Mask>,
) -> MappedLanes<L> {
    let (zero, one, two) = (L::of(0.0), L::of(1.0), L::of(2.0));
    let nan = !time.eq(time);
    let within = time.ge(t0) & time.le(tn);
    let (before, after) = (time.lt(t0), time.gt(tn));
    let infinite = time.abs().eq(L::of(f64::INFINITY));
    let mode = ModeLanes::pick(after, pre, post);
    // Finite and outside the keys (NaN is neither before nor after).
    let out = (before | after) & !infinite;
    let len = tn - t0;
    let rel = time - t0;
    let m = (rel / len).floor();
    // Rounding can push r a hair outside [0, L]; near the ends of f64,
    // `time - t0` overflows to an infinity and r is NaN: such a time (its
    // place in the cycle lost to rounding anyway) wraps to the first key.
    let r = rel - m * len;
    let r = L::select(r.eq(r), r.clamp_to(zero, len), zero);
    let odd = (m - (m * L::of(0.5)).floor() * two).eq(one);
    let back = out & mode.oscillate & odd;
    let wraps = out & (mode.repeat | mode.oscillate | mode.offset_repeat);
    let inside = within | wraps;
    let reset = (out | infinite) & mode.reset & !nan;
    let line = out & mode.linear;
    MappedLanes {
        inside,
        hold: !(inside | reset | line),
        reset,
        line,
        last: after,
        time: L::select(within, time, L::select(back, tn - r, t0 + r)),
        direction: L::select(back, L::of(-1.0), one),
        cycles: L::select(out & mode.offset_repeat, m, zero),
        dt: L::select(after, time - tn, time - t0),
    }
}

/// [`map_lanes`] where every lane's `pre` and `post` are `constant` (the
/// default): the time itself inside the keys, a hold of the end key
/// elsewhere (NaN too), without the other modes' arithmetic. `time`
/// outside the keys and `dt` are left as the time and zero: only modes
/// that are not there read them. Every other field is `map_lanes`'s
/// (`hold_lanes_is_map_lanes_of_constant`).
#[inline(always)]
pub fn hold_lanes<L: Lane>(time: L, t0: L, tn: L) -> MappedLanes<L> {
    let within = time.ge(t0) & time.le(tn);
    let none = within & !within;
    MappedLanes {
        inside: within,
        hold: !within,
        reset: none,
        line: none,
        last: time.gt(tn),
        time,
        direction: L::of(1.0),
        cycles: L::of(0.0),
        dt: L::of(0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Extrapolation as E;

    #[test]
    fn hold_lanes_is_map_lanes_of_constant() {
        let c = ModeLanes::of(E::Constant);
        let times = [
            -f64::INFINITY,
            -f64::MAX,
            -1.0,
            0.0,
            0.5,
            1.0,
            2.0,
            3.0,
            3.0 + f64::EPSILON,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        for (t0, tn) in [(0.0, 1.0), (1.0, 3.0), (-1e300, 1e300), (2.0, 2.0)] {
            for time in times {
                let (m, h) = (map_lanes(time, t0, tn, &c, &c), hold_lanes(time, t0, tn));
                let at = format!("{time} in [{t0}, {tn}]");
                assert_eq!(
                    (m.inside, m.hold, m.reset, m.line, m.last),
                    (h.inside, h.hold, h.reset, h.line, h.last),
                    "{at}"
                );
                assert_eq!((m.direction, m.cycles), (h.direction, h.cycles), "{at}");
                if m.inside {
                    assert_eq!(m.time.to_bits(), h.time.to_bits(), "{at}");
                }
            }
        }
    }

    fn inside(time: f64, direction: f64, cycles: f64) -> Mapped {
        Mapped::Inside {
            time,
            direction,
            cycles,
        }
    }

    /// Near -f64::MAX, `time - t0` overflows (issue 29): the wrapping
    /// modes land on the first key, not on a NaN time.
    #[test]
    fn a_finite_time_whose_offset_overflows_wraps_to_the_first_key() {
        for mode in [E::Repeat, E::Oscillate, E::OffsetRepeat] {
            match map_time(-f64::MAX, 1e300, 3e300, mode, mode) {
                Mapped::Inside { time, .. } => assert_eq!(time, 1e300, "{mode:?}"),
                m => panic!("{mode:?}: {m:?}"),
            }
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
