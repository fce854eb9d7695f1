//! Quaternion formulas over [`Lane`]s, planes `[x, y, z, w]`: the one copy
//! the reference (`f64`) and the runtime's kernels (`f32x8`, `f64x4`) share.
//!
//! ```text
//! a b   Hamilton product
//! q = p / |p|              q' = (p' - q (q . p')) / |p|      normalize, with velocity
//! omega = 2 vec(q' conj(q))                                  angular velocity
//! ```

use crate::simd::basis::Real;
use crate::simd::lane::Lane;

/// The Hamilton product `a b`.
#[inline(always)]
pub fn mul<R: Real>(a: &[R; 4], b: &[R; 4]) -> [R; 4] {
    [
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ]
}

/// `p / |p|` and, given `p'`, its derivative `(p' - q (q . p')) / |p|`
/// (a curve `p` through 4-space, normalized: `hermite` rotations).
///
/// ```
/// let (q, v) = tcb_core::quat::normalize([0.0f64, 0.0, 0.0, 2.0], Some([1.0, 0.0, 0.0, 1.0]));
/// assert_eq!(q, [0.0, 0.0, 0.0, 1.0]);
/// assert_eq!(v, Some([0.5, 0.0, 0.0, 0.0])); // only the part across q, over |p|
/// ```
#[inline(always)]
pub fn normalize<L: Lane>(p: [L; 4], dp: Option<[L; 4]>) -> ([L; 4], Option<[L; 4]>) {
    let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
    let inv = L::of(1.0) / len;
    // Written out, without closures: the AVX2 kernels call this inside
    // `#[target_feature]` functions (see `crate::simd::w8`).
    let q = [p[0] * inv, p[1] * inv, p[2] * inv, p[3] * inv];
    let qv = match dp {
        Some(dp) => {
            let qd = q[0] * dp[0] + q[1] * dp[1] + q[2] * dp[2] + q[3] * dp[3];
            Some([
                (dp[0] - q[0] * qd) * inv,
                (dp[1] - q[1] * qd) * inv,
                (dp[2] - q[2] * qd) * inv,
                (dp[3] - q[3] * qd) * inv,
            ])
        }
        None => None,
    };
    (q, qv)
}

/// A rotation key made unit length as a track stores it: `p / |p|` with
/// `|p| = sqrt(x x + y y + z z + w w)` summed in that order and each
/// component divided (not multiplied by a reciprocal), as
/// [`crate::RotationTrack::new`] normalizes its keys (in `f64`).
///
/// ```
/// assert_eq!(tcb_core::quat::unit_key([0.0f64, 0.0, 3.0, 4.0]), [0.0, 0.0, 0.6, 0.8]);
/// ```
#[inline(always)]
pub fn unit_key<L: Lane>(p: [L; 4]) -> [L; 4] {
    let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
    [p[0] / len, p[1] / len, p[2] / len, p[3] / len]
}

/// The `w` of a unit quaternion from its `x y z` (`w >= 0`), as a packed
/// clip stores three components of a rotation: `sqrt(max(0, 1 - |xyz|^2))`
/// in `f32`, summed `x x + y y + z z` in that order. The one copy the
/// encoder (`f32`) and the decoder (`f32x8`) use.
///
/// ```
/// assert_eq!(tcb_core::quat::rebuild_w(0.6f32, 0.0, 0.0), 0.8);
/// ```
#[inline(always)]
pub fn rebuild_w<L: Lane>(x: L, y: L, z: L) -> L {
    let s = L::of(1.0) - (x * x + y * y + z * z);
    L::select(s.lt(L::of(0.0)), L::of(0.0), s).sqrt()
}

/// The angular velocity of a unit quaternion `q` with component derivative
/// `dq`, as a vector in the frame `q` maps into: `2 vec(dq conj(q))`
/// (radians per unit of time).
///
/// ```
/// // A quarter turn about z per second, at the identity.
/// let w = tcb_core::quat::angular_velocity(&[0.0f64, 0.0, 0.0, 1.0], &[0.0, 0.0, 0.25 * std::f64::consts::PI, 0.0]);
/// assert!((w[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && w[0] == 0.0);
/// ```
#[inline(always)]
pub fn angular_velocity<R: Real>(q: &[R; 4], dq: &[R; 4]) -> [R; 3] {
    let zero = R::splat(0.0);
    let w = mul(dq, &[zero - q[0], zero - q[1], zero - q[2], q[3]]);
    [w[0] + w[0], w[1] + w[1], w[2] + w[2]]
}
