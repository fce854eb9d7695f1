//! The cubic Hermite basis (Kochanek & Bartels 1984, eq. 2), written once for
//! any [`Real`] lane type so that the scalar reference and SIMD kernels run
//! the same operations in the same order.
//!
//! ```text
//! P(s) = h1(s) P_k + h2(s) P_{k+1} + h3(s) M0 + h4(s) M1,   s in [0, 1]
//! h1 = 2s^3 - 3s^2 + 1    h2 = -2s^3 + 3s^2    h3 = s^3 - 2s^2 + s    h4 = s^3 - s^2
//! [h1 h2 h3 h4] = [s^3 s^2 s 1] . H
//! ```
//!
//! The row depends only on `s`: it is computed once per sample time and
//! shared by every channel on the same key times (the paper's "s.h is
//! calculated only once per frame").

use std::ops::{Add, Mul, Sub};

/// A lane of arithmetic: `f32`, `f64` (the key-reduction fitter), or a SIMD
/// vector of `f32` (`wide::f32x8`).
///
/// Only `+`, `-` and `*` are used (no fused multiply-add), so a formula run
/// on `f32` and on `f32x8` gives the same bits in every lane.
pub trait Real: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    /// Every lane set to `x`.
    fn splat(x: f32) -> Self;
}

impl Real for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
}

impl Real for f64 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        f64::from(x)
    }
}

impl Real for wide::f64x4 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        wide::f64x4::splat(f64::from(x))
    }
}

impl Real for wide::f32x8 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        wide::f32x8::splat(x)
    }
}

/// `[h1, h2, h3, h4]` at `s`.
///
/// ```
/// use tcb_core::simd::basis::hermite_basis;
/// assert_eq!(hermite_basis(0.0f32), [1.0, 0.0, 0.0, 0.0]);
/// assert_eq!(hermite_basis(1.0f32), [0.0, 1.0, 0.0, 0.0]);
/// assert_eq!(hermite_basis(0.5f32), [0.5, 0.5, 0.125, -0.125]);
/// ```
#[inline(always)]
pub fn hermite_basis<R: Real>(s: R) -> [R; 4] {
    let s2 = s * s;
    let s3 = s2 * s;
    let two = R::splat(2.0);
    let three = R::splat(3.0);
    [
        two * s3 - three * s2 + R::splat(1.0),
        three * s2 - two * s3,
        s3 - two * s2 + s,
        s3 - s2,
    ]
}

/// `[h1', h2', h3', h4']`, the derivatives with respect to `s`.
#[inline(always)]
pub fn hermite_basis_derivative<R: Real>(s: R) -> [R; 4] {
    let s2 = s * s;
    let six = R::splat(6.0);
    let three = R::splat(3.0);
    [
        six * s2 - six * s,
        six * s - six * s2,
        three * s2 - R::splat(4.0) * s + R::splat(1.0),
        three * s2 - R::splat(2.0) * s,
    ]
}

/// `h1 p0 + h2 p1 + h3 m0 + h4 m1`, summed left to right.
#[inline(always)]
pub fn hermite<R: Real>(h: &[R; 4], p0: R, p1: R, m0: R, m1: R) -> R {
    h[0] * p0 + h[1] * p1 + h[2] * m0 + h[3] * m1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_sums_to_one_and_reproduces_lines() {
        for i in 0..=16 {
            let s = i as f32 / 16.0;
            let h = hermite_basis(s);
            assert!((h[0] + h[1] - 1.0).abs() < 1e-6);
            // M0 = M1 = P1 - P0 gives the chord at constant speed.
            let p = hermite(&h, 2.0, 5.0, 3.0, 3.0);
            assert!((p - (2.0 + 3.0 * s)).abs() < 1e-6);
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let f = |s: f64| {
            let h = hermite_basis(s as f32);
            hermite(&h, 1.0, -2.0, 4.0, 0.5) as f64
        };
        for i in 1..8 {
            let s = i as f64 / 8.0;
            let d = hermite_basis_derivative(s as f32);
            let fd = (f(s + 1e-3) - f(s - 1e-3)) / 2e-3;
            assert!((hermite(&d, 1.0, -2.0, 4.0, 0.5) as f64 - fd).abs() < 1e-3);
        }
        assert_eq!(hermite_basis_derivative(0.0f32), [0.0, 0.0, 1.0, 0.0]);
        assert_eq!(hermite_basis_derivative(1.0f32), [0.0, 0.0, 0.0, 1.0]);
    }
}
