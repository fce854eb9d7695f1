//! Slerp and squad in power form, with their derivative, over [`Lane`]s:
//! the one copy the reference (`f64`) and the runtime's exact path
//! (`f64x4`) share.
//!
//! Each slerp is written `p exp(s L)`, `L = log(p^-1 q)` = `alpha n` (unit
//! axis `n`, angle `alpha`). The outer two slerps of a squad segment keep
//! their `p`, `n`, `alpha` as controls; the inner one is taken at `s`:
//!
//! ```text
//! P(s) = q0 exp(s alpha n)      R(s) = a exp(s beta m)      g(s) = 2 s (1 - s)
//! D = P^-1 R = (v sin th, cos th)      squad(s) = P exp(g th v)
//! P' = P (alpha n)    R' = R (beta m)    D' = -(alpha n) D + D (beta m)
//! th' = D_w (v . D_v') - |D_v| D_w'      (th v)' = (D_v' - v (v . D_v')) th / |D_v| + v th'
//! X = g th v:  exp(X)' = ((X' - v phi') sin(phi)/phi + v cos(phi) phi', -sin(phi) phi'),  phi = g th
//! squad' = P' exp(X) + P exp(X)'
//! ```
//!
//! No division by `sin` of an outer angle, so it is well conditioned for
//! any angle; where `D` is nearly `-1` (the inner slerp's ends nearly
//! opposite) its axis is ill-conditioned, which is why the runtime runs this
//! in f64.

use crate::quat::mul;
use crate::simd::lane::Lane;
use glam::{DQuat, DVec3};

/// `log` of a unit quaternion: `(v sin(th/2), cos(th/2)) -> v th/2`.
pub fn quat_log(q: DQuat) -> DVec3 {
    let v = DVec3::new(q.x, q.y, q.z);
    let sin = v.length();
    if sin == 0.0 {
        return DVec3::ZERO;
    }
    v * (sin.atan2(q.w) / sin)
}

/// `exp` of a pure quaternion: `v -> (v/|v| sin|v|, cos|v|)`.
pub fn quat_exp(v: DVec3) -> DQuat {
    let th = v.length();
    // sin(th)/th, by its series where th is tiny.
    let sinc = if th < 1e-6 {
        1.0 - th * th / 6.0
    } else {
        th.sin() / th
    };
    let xyz = v * sinc;
    DQuat::from_xyzw(xyz.x, xyz.y, xyz.z, th.cos())
}

/// Controls of one squad segment: `q0 [x y z w], n [x y z], alpha, a [x y z w], m [x y z], beta`.
pub const CONTROLS: usize = 16;

/// `p`, then the unit axis and angle of `log(p^-1 q)`, so that
/// `slerp(p, q, s) = p exp(s alpha n)` (no hemisphere flip).
pub fn slerp_controls(p: DQuat, q: DQuat) -> [f64; 8] {
    let v = quat_log(p.conjugate() * q);
    let alpha = v.length();
    let n = if alpha > 0.0 { v / alpha } else { DVec3::ZERO };
    [p.x, p.y, p.z, p.w, n.x, n.y, n.z, alpha]
}

/// The controls of `squad(q0, q1, a, b, s)` (see [`CONTROLS`]).
pub fn controls(q0: DQuat, q1: DQuat, a: DQuat, b: DQuat) -> [f64; CONTROLS] {
    let mut c = [0.0; CONTROLS];
    c[..8].copy_from_slice(&slerp_controls(q0, q1));
    c[8..].copy_from_slice(&slerp_controls(a, b));
    c
}

/// `p exp(s alpha n)`.
#[inline(always)]
pub fn slerp_power<L: Lane>(p: &[L; 4], n: &[L; 3], alpha: L, s: L) -> [L; 4] {
    let (sin, cos) = (s * alpha).sin_cos();
    mul(p, &[n[0] * sin, n[1] * sin, n[2] * sin, cos])
}

#[inline(always)]
fn conj<L: Lane>(q: &[L; 4]) -> [L; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

/// The squad segment with controls `c` at `s` (unit up to rounding).
#[inline(always)]
pub fn squad<L: Lane>(c: &[L; CONTROLS], s: L) -> [L; 4] {
    let g = L::of(2.0) * s * (L::of(1.0) - s);
    let p = slerp_power(&[c[0], c[1], c[2], c[3]], &[c[4], c[5], c[6]], c[7], s);
    let r = slerp_power(
        &[c[8], c[9], c[10], c[11]],
        &[c[12], c[13], c[14]],
        c[15],
        s,
    );
    let d = mul(&conj(&p), &r);
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let th = len.atan2(d[3]);
    let inv = L::select(len.eq(L::of(0.0)), L::of(0.0), L::of(1.0) / len);
    slerp_power(&p, &[d[0] * inv, d[1] * inv, d[2] * inv], th, g)
}

/// [`squad`] and its derivative with respect to `s` (module docs).
#[inline(always)]
pub fn squad_with_derivative<L: Lane>(c: &[L; CONTROLS], s: L) -> ([L; 4], [L; 4]) {
    let (zero, one, two) = (L::of(0.0), L::of(1.0), L::of(2.0));
    let g = two * s * (one - s);
    let dg = two * (one - two * s);
    let (n, m) = ([c[4], c[5], c[6]], [c[12], c[13], c[14]]);
    let p = slerp_power(&[c[0], c[1], c[2], c[3]], &n, c[7], s);
    let r = slerp_power(&[c[8], c[9], c[10], c[11]], &m, c[15], s);
    let dp = mul(&p, &[n[0] * c[7], n[1] * c[7], n[2] * c[7], zero]);
    let dr = mul(&r, &[m[0] * c[15], m[1] * c[15], m[2] * c[15], zero]);
    let d = mul(&conj(&p), &r);
    let dd: [L; 4] = {
        let a = mul(&conj(&dp), &r);
        let b = mul(&conj(&p), &dr);
        std::array::from_fn(|i| a[i] + b[i])
    };
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let th = len.atan2(d[3]);
    let flat = len.eq(zero);
    let inv = L::select(flat, zero, one / len);
    let ratio = L::select(flat, one, th * inv);
    let v = [d[0] * inv, d[1] * inv, d[2] * inv];
    let vd = v[0] * dd[0] + v[1] * dd[1] + v[2] * dd[2];
    let dth = d[3] * vd - len * dd[3];
    let dl: [L; 3] = std::array::from_fn(|i| (dd[i] - v[i] * vd) * ratio + v[i] * dth);
    let phi = g * th;
    let (sin, cos) = phi.sin_cos();
    let dphi = dg * th + g * dth;
    let sinc = L::select(phi.eq(zero), one, sin / phi);
    let w = [v[0] * sin, v[1] * sin, v[2] * sin, cos];
    let dx: [L; 3] = std::array::from_fn(|i| dg * (v[i] * th) + g * dl[i]);
    let dw = [
        (dx[0] - v[0] * dphi) * sinc + v[0] * cos * dphi,
        (dx[1] - v[1] * dphi) * sinc + v[1] * cos * dphi,
        (dx[2] - v[2] * dphi) * sinc + v[2] * cos * dphi,
        -(sin * dphi),
    ];
    let q = mul(&p, &w);
    let dq: [L; 4] = {
        let a = mul(&dp, &w);
        let b = mul(&p, &dw);
        std::array::from_fn(|i| a[i] + b[i])
    };
    (q, dq)
}

/// [`squad`] at `s` normalized, and with `derivative` the derivative of the
/// normalized curve with respect to `s` ([`crate::quat::normalize`]): what
/// the reference samples and the runtime's exact path evaluates.
#[inline(always)]
pub fn unit<L: Lane>(c: &[L; CONTROLS], s: L, derivative: bool) -> ([L; 4], Option<[L; 4]>) {
    if derivative {
        let (q, dq) = squad_with_derivative(c, s);
        crate::quat::normalize(q, Some(dq))
    } else {
        crate::quat::normalize(squad(c, s), None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn random_quat(seed: &mut u64) -> DQuat {
        DQuat::from_xyzw(lcg(seed), lcg(seed), lcg(seed), lcg(seed)).normalize()
    }

    /// The analytic derivative against a five-point difference of the value,
    /// on random segments, keys up to 180 degrees apart and nearly equal ones.
    #[test]
    fn derivative_matches_a_five_point_difference() {
        let mut seed = 7;
        let mut worst = 0.0f64;
        for case in 0..400 {
            let q0 = random_quat(&mut seed);
            let spread = [1.0, 0.3, 1e-3, 1e-7][case % 4];
            let near = |seed: &mut u64| {
                DQuat::from_scaled_axis(DVec3::new(lcg(seed), lcg(seed), lcg(seed)) * spread * 3.0)
            };
            let (q1, a, b) = (
                q0 * near(&mut seed),
                q0 * near(&mut seed),
                q0 * near(&mut seed),
            );
            let c = controls(q0, q1, a, b);
            let f = |s: f64| DVec4::from_array(squad(&c, s));
            for i in 1..10 {
                let s = i as f64 / 10.0;
                let h = 1e-4;
                let fd =
                    (f(s - 2.0 * h) - f(s + 2.0 * h) + (f(s + h) - f(s - h)) * 8.0) / (12.0 * h);
                let (q, d) = squad_with_derivative(&c, s);
                assert_eq!(q, squad(&c, s));
                let e = (DVec4::from_array(d) - fd).length() / (1.0 + fd.length());
                worst = worst.max(e);
                assert!(e < 1e-7, "case {case} s {s}: {d:?} vs {fd}");
            }
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn ends_are_the_keys() {
        let q0 = DQuat::from_rotation_z(0.3);
        let q1 = DQuat::from_rotation_x(2.0);
        let c = controls(q0, q1, q0 * DQuat::from_rotation_y(0.2), q1);
        assert!((DQuat::from_array(squad(&c, 0.0)) - q0).length() < 1e-15);
        assert!((DQuat::from_array(squad(&c, 1.0)) - q1).length() < 1e-15);
    }
}
