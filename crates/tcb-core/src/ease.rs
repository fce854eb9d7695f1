//! 3ds Max ease to / ease from: re-timing along a segment without changing
//! its path.
//!
//! For segment k take `a = from_k` and `e = to_{k+1}`. If `a + e > 1`
//! divide both by `a + e`; if both are 0 nothing changes; else with
//! `K = 1 / (2 - a - e)` and `u` the plain local parameter:
//!
//! ```text
//! s = K u^2 / a              u < a
//! s = K (2u - a)             a <= u < 1 - e   (u <= 1 where e = 0)
//! s = 1 - K (1 - u)^2 / e    u >= 1 - e, e > 0
//! ```
//!
//! The speed along the path rises linearly from zero over the first `a` of
//! the segment, is constant in the middle, and falls linearly to zero over the
//! last `e`.

use crate::simd::lane::Lane;

/// The ease of one segment, normalized so that `from + to <= 1` (its
/// fields are private so that nothing makes one that is not).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SegmentEase {
    /// `a`: ease leaving the segment's first key.
    from: f64,
    /// `e`: ease arriving at the segment's second key.
    to: f64,
}

impl SegmentEase {
    /// From `from_k` of the first key and `to_{k+1}` of the second, each
    /// taken into [0, 1] (NaN as 0; track building refuses such eases
    /// before they get here), then normalized.
    pub fn new(from: f64, to: f64) -> Self {
        let unit = |x: f64| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        let (from, to) = (unit(from), unit(to));
        let sum = from + to;
        if sum > 1.0 {
            SegmentEase {
                from: from / sum,
                to: to / sum,
            }
        } else {
            SegmentEase { from, to }
        }
    }

    /// `a`: ease leaving the segment's first key.
    #[inline]
    pub fn from(&self) -> f64 {
        self.from
    }

    /// `e`: ease arriving at the segment's second key.
    #[inline]
    pub fn to(&self) -> f64 {
        self.to
    }

    /// No easing on this segment.
    #[inline]
    pub fn is_none(&self) -> bool {
        self.from == 0.0 && self.to == 0.0
    }

    /// `(s, ds/du)` for the plain local parameter `u` in [0, 1].
    ///
    /// ```
    /// use tcb_core::ease::SegmentEase;
    /// let e = SegmentEase::new(0.5, 0.0); // ease from half the segment
    /// assert_eq!(e.apply(0.0), (0.0, 0.0));
    /// assert_eq!(e.apply(0.5).0, 1.0 / 3.0);
    /// assert_eq!(e.apply(1.0).0, 1.0);
    /// ```
    #[inline]
    pub fn apply(&self, u: f64) -> (f64, f64) {
        if self.is_none() {
            return (u, 1.0); // what `ease` selects for no ease, without the rest
        }
        ease(u, self.from, self.to)
    }
}

/// `(s, ds/du)` of the ease `a = from`, `e = to` (normalized, `a + e <= 1`)
/// at `u`, in any [`Lane`]: the one formula of the module docs for the
/// reference (`f64`) and the runtime's lanes (`f64x4`).
#[inline(always)]
pub fn ease<L: Lane>(u: L, a: L, e: L) -> (L, L) {
    let (zero, one, two) = (L::of(0.0), L::of(1.0), L::of(2.0));
    let none = a.eq(zero) & e.eq(zero);
    let k = one / (two - a - e);
    let w = one - u;
    let first = u.lt(a);
    let last = e.gt(zero) & u.ge(one - e);
    let s = L::select(
        first,
        k * u * u / a,
        L::select(last, one - k * w * w / e, k * (two * u - a)),
    );
    let d = L::select(
        first,
        two * k * u / a,
        L::select(last, two * k * w / e, two * k),
    );
    (L::select(none, u, s), L::select(none, one, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn by_hand() {
        // a = 0.25, e = 0.25: K = 2/3.
        let e = SegmentEase::new(0.25, 0.25);
        let (s, d) = e.apply(0.125);
        assert!((s - 2.0 / 3.0 * 0.015625 / 0.25).abs() < 1e-15);
        assert!((d - 2.0 * 2.0 / 3.0 * 0.5).abs() < 1e-15);
        assert!((e.apply(0.5).0 - 0.5).abs() < 1e-15);
        assert_eq!(e.apply(1.0), (1.0, 0.0));
        // Middle speed 2K = 4/3.
        assert!((e.apply(0.5).1 - 4.0 / 3.0).abs() < 1e-15);
    }

    /// What `new` used to pass through (a public field or argument out of
    /// [0, 1], NaN) ends up as a normalized ease whose `apply` stays in
    /// [0, 1].
    #[test]
    fn out_of_range_arguments_stay_an_ease() {
        for (a, e) in [
            (-1.0, 0.5),
            (2.0, 3.0),
            (f64::NAN, 0.2),
            (0.3, f64::INFINITY),
        ] {
            let ease = SegmentEase::new(a, e);
            assert!((0.0..=1.0).contains(&ease.from()) && (0.0..=1.0).contains(&ease.to()));
            assert!(ease.from() + ease.to() <= 1.0);
            for u in [0.0, 0.3, 0.7, 1.0] {
                let (s, d) = ease.apply(u);
                assert!(
                    (0.0..=1.0).contains(&s) && d.is_finite(),
                    "{a} {e} {u}: {s} {d}"
                );
            }
        }
    }

    #[test]
    fn over_one_is_normalized() {
        let e = SegmentEase::new(1.0, 1.0);
        assert_eq!((e.from, e.to), (0.5, 0.5));
        // K = 1: s = 2u^2 on the first half.
        assert_eq!(e.apply(0.25).0, 0.125);
        assert_eq!(e.apply(0.75).0, 0.875);
    }

    #[test]
    fn continuous_and_monotone() {
        for &(a, b) in &[
            (0.3, 0.0),
            (0.0, 0.6),
            (0.2, 0.7),
            (1.0, 0.0),
            (0.0, 1.0),
            (0.9, 0.9),
        ] {
            let e = SegmentEase::new(a, b);
            let mut prev = 0.0;
            for i in 0..=1000 {
                let u = i as f64 / 1000.0;
                let (s, d) = e.apply(u);
                assert!(s >= prev - 1e-12, "{a} {b} at {u}");
                assert!((s - prev).abs() < 3e-3 && d >= 0.0);
                prev = s;
            }
            assert!((prev - 1.0).abs() < 1e-12);
        }
    }
}
