//! The SIMD kernels: one stored segment, eight channels per `f32x8`, the
//! frame's rows broadcast. No branch depends on a channel.

use tcb_core::basis::hermite;
use wide::{f32x8, f64x4};

/// `[P0, P1, M0, M1]` of 8 channels.
pub(crate) const VEC_STRIDE: usize = 4;
/// `[P0, P1, M0, M1]` x `[x, y, z, w]` of 8 quaternions.
pub(crate) const HQ_STRIDE: usize = 16;
/// `q0 [x y z w], n01 [x y z], alpha01, a [x y z w], n_ab [x y z], alpha_ab`
/// of 4 quaternions in f64 ([`tcb_core::squad::CONTROLS`]): the two outer
/// slerps of squad as start point, log axis and log angle.
pub(crate) const SQ_STRIDE: usize = tcb_core::squad::CONTROLS;

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

/// The lanes of `e.mask` in one rotation block (4 planes), exactly: squad
/// in f64 ([`tcb_core::squad`]) at `s`, normalized, velocity times `rate`.
///
/// This runs in f64 (four lanes per [`f64x4`], two halves per block): the
/// inner slerp between nearly opposite quaternions amplifies its inputs'
/// errors by about `1 / sin(angle)`, and in f32 such segments miss 1e-6.
#[inline]
pub(crate) fn exact_quats(
    e: &crate::clip::Exact,
    s: f64,
    rate: f32,
    out: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
) {
    use tcb_core::squad::{CONTROLS, squad, squad_with_derivative};
    let s = f64x4::splat(s);
    let rate = f64x4::splat(f64::from(rate));
    let want_v = vel.is_some();
    let mut q = [[0.0f32; 8]; 4];
    let mut dq = [[0.0f32; 8]; 4];
    for h in 0..2 {
        let c: &[f64x4; CONTROLS] = e.controls[h * CONTROLS..(h + 1) * CONTROLS]
            .try_into()
            .expect("16 controls");
        let (v, d) = if want_v {
            let (v, d) = squad_with_derivative(c, s);
            (v, Some(d.map(|x| x * rate)))
        } else {
            (squad(c, s), None)
        };
        let (v, d) = normalize(v, d);
        for i in 0..4 {
            let a = v[i].to_array();
            let b = d.map_or([0.0; 4], |d| d[i].to_array());
            for l in 0..4 {
                q[i][4 * h + l] = a[l] as f32;
                dq[i][4 * h + l] = b[l] as f32;
            }
        }
    }
    for i in 0..4 {
        out[i] = e.mask.select(f32x8::new(q[i]), out[i]);
    }
    if let Some(vel) = vel {
        for i in 0..4 {
            vel[i] = e.mask.select(f32x8::new(dq[i]), vel[i]);
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
