//! The SIMD kernels: one stored segment, eight channels per `f32x8`, the
//! frame's rows broadcast. No branch depends on a channel.

use tcb_core::basis::hermite;
use wide::{f32x8, f64x4};

/// `[P0, P1, M0, M1]` of 8 channels.
pub(crate) const VEC_STRIDE: usize = 4;
/// `[P0, P1, M0, M1]` x `[x, y, z, w]` of 8 quaternions.
pub(crate) const HQ_STRIDE: usize = 16;
/// `q0 [x y z w], n01 [x y z], alpha01, a [x y z w], n_ab [x y z], alpha_ab`
/// of 4 quaternions in f64: the two outer slerps of squad as start point, log
/// axis and log angle.
pub(crate) const SQ_STRIDE: usize = 16;

#[inline(always)]
pub(crate) fn splat4(r: [f32; 4]) -> [f32x8; 4] {
    r.map(f32x8::splat)
}

/// Values of vector channels: `h1 P0 + h2 P1 + h3 M0 + h4 M1`, the formula
/// of [`tcb_core::basis::hermite`] itself.
#[inline]
pub(crate) fn vectors(coeffs: &[f32x8], h: &[f32x8; 4], out: &mut [f32x8]) {
    for (c, o) in coeffs.chunks_exact(VEC_STRIDE).zip(out) {
        *o = hermite(h, c[0], c[1], c[2], c[3]);
    }
}

/// Velocities of vector channels: `rate (dh . controls)`.
#[inline]
pub(crate) fn vector_velocities(coeffs: &[f32x8], dh: &[f32x8; 4], rate: f32x8, out: &mut [f32x8]) {
    for (c, o) in coeffs.chunks_exact(VEC_STRIDE).zip(out) {
        *o = hermite(dh, c[0], c[1], c[2], c[3]) * rate;
    }
}

/// `value += cycles * delta` (offset-repeat).
#[inline]
pub(crate) fn offset(delta: &[f32x8], cycles: f32x8, out: &mut [f32x8]) {
    for (d, o) in delta.iter().zip(out) {
        *o += *d * cycles;
    }
}

/// Hermite rotations: four components, then normalized; `vel` gets
/// `d/dt (p/|p|) = (p' - q (q . p')) / |p|`.
#[inline]
pub(crate) fn hermite_quats(
    coeffs: &[f32x8],
    h: &[f32x8; 4],
    dh: &[f32x8; 4],
    rate: f32x8,
    out: &mut [f32x8],
    mut vel: Option<&mut [f32x8]>,
) {
    for (b, c) in coeffs.chunks_exact(HQ_STRIDE).enumerate() {
        let p: [f32x8; 4] =
            std::array::from_fn(|i| hermite(h, c[i], c[4 + i], c[8 + i], c[12 + i]));
        let dp = vel.is_some().then(|| {
            std::array::from_fn(|i| hermite(dh, c[i], c[4 + i], c[8 + i], c[12 + i]) * rate)
        });
        let (q, qv) = normalize(p, dp);
        out[4 * b..4 * b + 4].copy_from_slice(&q);
        if let (Some(vel), Some(qv)) = (vel.as_deref_mut(), qv) {
            vel[4 * b..4 * b + 4].copy_from_slice(&qv);
        }
    }
}

pub(crate) use tcb_core::quat::normalize;

/// [`normalize`] in place over blocks of 4 planes (rotations sampled as
/// loose lanes: the curve and its derivative, then normalized).
pub(crate) fn normalize_blocks(values: &mut [f32x8], mut vel: Option<&mut [f32x8]>) {
    for (b, v) in values.chunks_exact_mut(4).enumerate() {
        let p: [f32x8; 4] = [v[0], v[1], v[2], v[3]];
        let dp = vel
            .as_deref()
            .map(|d| [d[4 * b], d[4 * b + 1], d[4 * b + 2], d[4 * b + 3]]);
        let (q, qv) = normalize(p, dp);
        v.copy_from_slice(&q);
        if let (Some(vel), Some(qv)) = (vel.as_deref_mut(), qv) {
            vel[4 * b..4 * b + 4].copy_from_slice(&qv);
        }
    }
}

pub(crate) use tcb_core::quat::mul as quat_mul;

/// `p exp(s alpha n)`: slerp from `p` along unit axis `n` (log-space angle
/// `alpha`). No division by `sin`, so well conditioned for any angle.
#[inline(always)]
fn slerp_power(p: &[f64x4; 4], n: &[f64x4], alpha: f64x4, s: f64x4) -> [f64x4; 4] {
    let (sin, cos) = (s * alpha).sin_cos();
    quat_mul(p, &[n[0] * sin, n[1] * sin, n[2] * sin, cos])
}

/// Squad of four lanes, in f64: `slerp(slerp(q0, q1, s), slerp(a, b, s),
/// 2s(1-s))`, normalized.
#[inline(always)]
fn squad4(c: &[f64x4], s: f64x4, g: f64x4) -> [f64x4; 4] {
    let q0 = [c[0], c[1], c[2], c[3]];
    let a = [c[8], c[9], c[10], c[11]];
    let p = slerp_power(&q0, &c[4..7], c[7], s);
    let q = slerp_power(&a, &c[12..15], c[15], s);
    // log(p^-1 q) = n alpha, alpha = atan2(|v|, w)
    let r = quat_mul(&[-p[0], -p[1], -p[2], p[3]], &q);
    let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let alpha = len.atan2(r[3]);
    let none = len.simd_eq(f64x4::ZERO);
    let inv = none.select(f64x4::ZERO, f64x4::ONE / len);
    let n = [r[0] * inv, r[1] * inv, r[2] * inv];
    let v = slerp_power(&p, &n, alpha, g);
    let il = f64x4::ONE / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]).sqrt();
    v.map(|x| x * il)
}

/// Squad rotations. Each slerp is written `p exp(s log(p^-1 q))`; the logs of
/// the two outer ones are stored with the segment (axis and angle), the inner
/// one is taken per frame.
///
/// This runs in f64 (four lanes per [`f64x4`], two halves per output block):
/// the inner slerp between nearly opposite quaternions amplifies its inputs'
/// errors by about `1 / sin(angle)`, and f32 controls and arithmetic put the
/// result up to 6e-6 from the reference on such segments.
#[inline]
pub(crate) fn squad_quats(coeffs: &[f64x4], s: f64, out: &mut [f32x8]) {
    let g = f64x4::splat(2.0 * s * (1.0 - s));
    let s = f64x4::splat(s);
    for (c, o) in coeffs
        .chunks_exact(2 * SQ_STRIDE)
        .zip(out.chunks_exact_mut(4))
    {
        let lo = squad4(&c[..SQ_STRIDE], s, g);
        let hi = squad4(&c[SQ_STRIDE..], s, g);
        for i in 0..4 {
            let (l, h) = (lo[i].to_array(), hi[i].to_array());
            o[i] = f32x8::new([
                l[0] as f32,
                l[1] as f32,
                l[2] as f32,
                l[3] as f32,
                h[0] as f32,
                h[1] as f32,
                h[2] as f32,
                h[3] as f32,
            ]);
        }
    }
}

/// Write the identity rotation into quaternion blocks (`reset`).
#[inline]
pub(crate) fn identity(out: &mut [f32x8]) {
    for q in out.chunks_exact_mut(4) {
        q[0] = f32x8::ZERO;
        q[1] = f32x8::ZERO;
        q[2] = f32x8::ZERO;
        q[3] = f32x8::ONE;
    }
}
