//! The SIMD kernels: one stored segment, eight channels per `f32x8`, the
//! frame's rows broadcast. No branch depends on a channel.

use crate::exact::{Exact, SQ_STRIDE};
use crate::segment::Segment;
use tcb_core::simd::basis::{Real, hermite};
use tcb_core::simd::lane::Lane;
use wide::{f32x8, f64x4};

#[inline(always)]
pub(crate) fn splat4(r: [f32; 4]) -> [f32x8; 4] {
    r.map(f32x8::splat)
}

/// Values of vector channels on segment `c` (one plane per block):
/// `h1 P0 + h2 P1 + h3 M0 + h4 M1`, the formula of
/// [`tcb_core::simd::basis::hermite`] itself.
///
/// The kernels take the frame's rows as numbers and splat them where their
/// loop starts, so that nothing of 8 lanes is live between them (with the
/// rows splatted once for all, an unrelated change to `sample_into` made
/// `wide` 11% more instructions, reloading the rows from the stack in
/// every block: SSE2 has 16 registers, and `h`, `dh` and `rate` as
/// `f32x8` are 18 of them).
#[inline]
pub(crate) fn vectors(c: Segment, h: [f32; 4], out: &mut [f32x8]) {
    // One block stays here, inlined: the AVX2 instance's call and setup
    // cost more than its one block saves (a character's root translation:
    // `character-hermite` 2.6% fewer instructions so).
    #[cfg(target_arch = "x86_64")]
    if out.len() > 1
        && let Some(avx2) = crate::isa::Avx2Kernels::now()
    {
        return v3::vectors_here(avx2, c, h, out);
    }
    let h = &splat4(h);
    let keys = c.p0.iter().zip(c.p1).zip(c.m0).zip(c.m1);
    for ((((p0, p1), m0), m1), o) in keys.zip(out) {
        *o = hermite(h, *p0, *p1, *m0, *m1);
    }
}

/// Velocities of vector channels: `rate (dh . controls)`.
#[inline]
pub(crate) fn vector_velocities(c: Segment, dh: [f32; 4], rate: f32, out: &mut [f32x8]) {
    let (dh, rate) = (&splat4(dh), f32x8::splat(rate));
    let keys = c.p0.iter().zip(c.p1).zip(c.m0).zip(c.m1);
    for ((((p0, p1), m0), m1), o) in keys.zip(out) {
        *o = velocity(dh, *p0, *p1, *m0, *m1, rate);
    }
}

/// A vector channel's velocity from its controls: `rate (dh . controls)`.
#[inline(always)]
pub(crate) fn velocity<L: Real>(dh: &[L; 4], p0: L, p1: L, m0: L, m1: L, rate: L) -> L {
    hermite(dh, p0, p1, m0, m1) * rate
}

/// `value += cycles * delta` (offset-repeat).
#[inline]
pub(crate) fn offset(delta: &[f32x8], cycles: f32x8, out: &mut [f32x8]) {
    for (d, o) in delta.iter().zip(out) {
        *o += *d * cycles;
    }
}

/// Rotations on segment `c` (four planes per block, `x y z w`): four
/// components, then normalized; `vel` gets
/// `d/dt (p/|p|) = (p' - q (q . p')) / |p|`.
///
/// Whether `|p|^2` stays well inside f32's range is checked for every lane
/// but acted on once per call: the rare segment where some lane leaves it
/// (explicit tangents of 1e36, say) is redone block by block, cold.
#[inline(always)]
pub(crate) fn hermite_quats(
    c: Segment,
    rows: [f32; 4],
    rows_d: [f32; 4],
    rate_s: f32,
    out: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
) {
    const LOW: u32 = F32_RANGE[0].to_bits();
    quats_above::<LOW, true>(c, rows, rows_d, rate_s, out, vel);
}

/// `|p|^2` where [`normalize`] may run as it is: well inside f32's range.
pub(crate) const F32_RANGE: [f32; 2] = [1e-30, 1e30];

/// [`hermite_quats`], the lanes' `|p|^2` checked to be above
/// `f32::from_bits(LOW)` (and below [`F32_RANGE`]'s top): where some lane's
/// is not, with `RESCALE` the cold path ([`rescale_quats`]) redoes its
/// block, and without it `out` (and `vel`) are not final and the result
/// is `false`.
#[inline(always)]
pub(crate) fn quats_above<const LOW: u32, const RESCALE: bool>(
    c: Segment,
    rows: [f32; 4],
    rows_d: [f32; 4],
    rate_s: f32,
    out: &mut [f32x8],
    mut vel: Option<&mut [f32x8]>,
) -> bool {
    let low = f32::from_bits(LOW);
    #[cfg(target_arch = "x86_64")]
    if vel.is_none()
        && let Some(avx2) = crate::isa::Avx2Kernels::now()
    {
        let ok = v3::quats_here::<LOW>(avx2, c, rows, out);
        if RESCALE && !ok {
            rescale_quats(c, rows, rows_d, rate_s, out, vel);
        }
        return ok;
    }
    let (h, dh, rate) = (&splat4(rows), &splat4(rows_d), f32x8::splat(rate_s));
    let keys = quat_keys(c);
    let blocks = out.as_chunks_mut::<4>().0;
    let mut ok = f32x8::splat(f32::from_bits(u32::MAX));
    // One loop with velocities and one without, the block written once.
    match vel.as_deref_mut() {
        None => {
            for (k, o) in keys.zip(blocks) {
                ok &= hermite_quat_block(k, h, None, o, None, low);
            }
        }
        Some(vel) => {
            let vel = vel.as_chunks_mut::<4>().0;
            for ((k, o), v) in keys.zip(blocks).zip(vel) {
                ok &= hermite_quat_block(k, h, Some((dh, rate)), o, Some(v), low);
            }
        }
    }
    if RESCALE && ok.to_bitmask() != 0xff {
        rescale_quats(c, rows, rows_d, rate_s, out, vel);
    }
    ok.to_bitmask() == 0xff
}

/// `P0 P1 M0 M1` of one rotation block (four planes each).
type QuatKeys<'a> = (
    ((&'a [f32x8; 4], &'a [f32x8; 4]), &'a [f32x8; 4]),
    &'a [f32x8; 4],
);

/// The rotation blocks of segment `c`.
#[inline(always)]
fn quat_keys(c: Segment) -> impl Iterator<Item = QuatKeys> {
    c.p0.as_chunks::<4>()
        .0
        .iter()
        .zip(c.p1.as_chunks::<4>().0)
        .zip(c.m0.as_chunks::<4>().0)
        .zip(c.m1.as_chunks::<4>().0)
}

/// The cubic of one rotation block and, with `dh`, its derivative times `rate`.
#[inline(always)]
fn quat_curve(
    (((p0, p1), m0), m1): QuatKeys,
    h: &[f32x8; 4],
    dh: Option<(&[f32x8; 4], f32x8)>,
) -> ([f32x8; 4], Option<[f32x8; 4]>) {
    // Written out, without closures (see `tcb_core::simd::w8`).
    let curve = |h: &[f32x8; 4]| {
        [
            hermite(h, p0[0], p1[0], m0[0], m1[0]),
            hermite(h, p0[1], p1[1], m0[1], m1[1]),
            hermite(h, p0[2], p1[2], m0[2], m1[2]),
            hermite(h, p0[3], p1[3], m0[3], m1[3]),
        ]
    };
    let p = curve(h);
    let dp = match dh {
        Some((dh, rate)) => {
            let d = curve(dh);
            Some([d[0] * rate, d[1] * rate, d[2] * rate, d[3] * rate])
        }
        None => None,
    };
    (p, dp)
}

/// One block of [`quats_above`]: 8 rotations. Returns the lanes whose
/// `|p|^2` is in range ([`in_range`] from `low`).
#[inline(always)]
fn hermite_quat_block(
    k: QuatKeys,
    h: &[f32x8; 4],
    dh: Option<(&[f32x8; 4], f32x8)>,
    out: &mut [f32x8; 4],
    vel: Option<&mut [f32x8; 4]>,
    low: f32,
) -> f32x8 {
    let (p, dp) = quat_curve(k, h, dh);
    let (q, qv) = normalize(p, dp);
    *out = q;
    if let (Some(v), Some(qv)) = (vel, qv) {
        *v = qv;
    }
    in_range(&p, low)
}

/// [`hermite_quats`] again for the blocks with a lane out of range, each
/// lane first divided by its largest component ([`renormalize_scaled`]).
/// At a segment's end (basis `[0, 1, 0, 0]`) such a block's value is its
/// key: the cubic there is `0 x inf` (NaN) where a tangent overflowed f32,
/// and the key is what the reference gives (the vector channels' copy of
/// `P1` in `crate::group`, free here on the cold path).
#[cold]
#[inline(never)]
fn rescale_quats(
    c: Segment,
    h: [f32; 4],
    dh: [f32; 4],
    rate: f32,
    out: &mut [f32x8],
    mut vel: Option<&mut [f32x8]>,
) {
    let at_end = h == [0.0, 1.0, 0.0, 0.0];
    let (h, dh, rate) = (&splat4(h), &splat4(dh), f32x8::splat(rate));
    for (b, k) in quat_keys(c).enumerate() {
        let (p, dp) = quat_curve(k, h, vel.is_some().then_some((dh, rate)));
        if in_range(&p, F32_RANGE[0]).to_bitmask() != 0xff {
            let p = if at_end { *k.0.0.1 } else { p };
            let planes = 4 * b..4 * b + 4;
            let v = vel.as_deref_mut().map(|v| &mut v[planes.clone()]);
            renormalize_scaled(&p, dp.as_ref(), &mut out[planes], v);
        }
    }
}

pub(crate) use tcb_core::quat::normalize;

/// The lanes where `|p|^2` is above `low` and below [`F32_RANGE`]'s top:
/// with `low` [`F32_RANGE`]'s bottom, well inside f32's range, so that
/// [`normalize`] may run as it is (all bits set there, none elsewhere; NaN
/// is out of range).
#[inline(always)]
pub(crate) fn in_range<L: Lane>(p: &[L; 4], low: f32) -> L::Mask {
    let n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
    n2.gt(L::splat(low)) & n2.lt(L::splat(F32_RANGE[1]))
}

/// Rewrite `out` (and `vel`) with [`normalize`] of a block where `|p|^2`
/// of some lane would overflow or underflow f32 (explicit tangents of
/// 1e36, say): each lane is first divided by its largest component, which
/// changes neither the rotation nor its velocity.
#[cold]
#[inline(never)]
pub(crate) fn renormalize_scaled(
    p: &[f32x8; 4],
    dp: Option<&[f32x8; 4]>,
    out: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
) {
    let m = p[0].abs().max(p[1].abs()).max(p[2].abs().max(p[3].abs()));
    let inv = f32x8::ONE / m;
    let (q, qv) = normalize(p.map(|x| x * inv), dp.map(|d| d.map(|x| x * inv)));
    out[..4].copy_from_slice(&q);
    if let (Some(vel), Some(qv)) = (vel, qv) {
        vel[..4].copy_from_slice(&qv);
    }
}

/// The lanes of `mask` (`e.mask`, or `e.value_mask` without velocities) in
/// one rotation block (4 planes), exactly: squad
/// in f64 ([`tcb_core::simd::squad`]) at `s`, normalized, velocity times `rate`.
///
/// This runs in f64 (four lanes per [`f64x4`], two halves per block): the
/// inner slerp between nearly opposite quaternions amplifies its inputs'
/// errors by about `1 / sin(angle)`, and in f32 such segments miss 1e-6.
///
/// `e.piece` (`[a, w]`) places the stored segment inside the squad segment
/// `controls`: it is evaluated at `a + w s`, its velocity scaled by `w` (for
/// a whole segment, `[0, 1]`, this changes no bit). Out of line: few
/// frames reach an exact entry.
#[inline(never)]
pub(crate) fn exact_quats(
    e: &Exact,
    controls: &[f64x4; 2 * SQ_STRIDE],
    mask: f32x8,
    s: f64,
    rate: f32,
    out: &mut [f32x8],
    vel: Option<&mut [f32x8]>,
) {
    use tcb_core::simd::squad::CONTROLS;
    let want_v = vel.is_some();
    let mut q = [[0.0f32; 8]; 4];
    let mut dq = [[0.0f32; 8]; 4];
    let [a, w] = e.piece;
    let (s, rate) = (a + w * s, w * f64::from(rate));
    let lanes = mask.to_bitmask();
    for h in 0..2 {
        let half = lanes >> (4 * h) & 0xf;
        let c: &[f64x4; CONTROLS] = controls[h * CONTROLS..(h + 1) * CONTROLS]
            .try_into()
            .expect("16 controls");
        match half.count_ones() {
            // The half without an exact lane is skipped.
            0 => {}
            // Most exact entries have one lane: it runs alone, in f64 (the
            // reference's own instance of the formula), at about a third of
            // the cost of four lanes in f64x4 on SSE2.
            1 => {
                let l = half.trailing_zeros() as usize;
                let c: [f64; CONTROLS] = std::array::from_fn(|k| c[k].to_array()[l]);
                let (v, d) = squad_at(&c, s, want_v.then_some(rate));
                for i in 0..4 {
                    q[i][4 * h + l] = v[i] as f32;
                    dq[i][4 * h + l] = d.map_or(0.0, |d| d[i] as f32);
                }
            }
            _ => {
                let rate = want_v.then_some(f64x4::splat(rate));
                let (v, d) = squad_at(c, f64x4::splat(s), rate);
                for i in 0..4 {
                    let a = v[i].to_array();
                    let b = d.map_or([0.0; 4], |d| d[i].to_array());
                    for l in 0..4 {
                        q[i][4 * h + l] = a[l] as f32;
                        dq[i][4 * h + l] = b[l] as f32;
                    }
                }
            }
        }
    }
    for i in 0..4 {
        out[i] = mask.select(f32x8::new(q[i]), out[i]);
    }
    if let Some(vel) = vel {
        for i in 0..4 {
            vel[i] = mask.select(f32x8::new(dq[i]), vel[i]);
        }
    }
}

/// The unit squad at `s` ([`tcb_core::simd::squad::unit`]), and with `rate` its
/// velocity times `rate`: for one lane and for four.
#[inline(always)]
fn squad_at<L: tcb_core::simd::lane::Lane>(
    c: &[L; tcb_core::simd::squad::CONTROLS],
    s: L,
    rate: Option<L>,
) -> ([L; 4], Option<[L; 4]>) {
    let (v, d) = tcb_core::simd::squad::unit(c, s, rate.is_some());
    (v, d.zip(rate).map(|(d, r)| d.map(|x| x * r)))
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

/// The AVX2 + FMA instance of [`vectors`] and of [`hermite_quats`]'s
/// values (see `crate::isa`): the same formulas on
/// [`tcb_core::simd::w8::W8`], whose element-wise operations become one
/// AVX instruction each here. Arrays are written out rather than built
/// with closures (see `tcb_core::simd::w8`).
#[cfg(target_arch = "x86_64")]
pub(crate) use v3::quats_inline;

#[cfg(target_arch = "x86_64")]
mod v3 {
    use crate::isa::Avx2Kernels;
    use crate::kernel::{in_range, normalize, quat_keys};
    use crate::segment::Segment;
    use std::arch::x86_64::__m256;
    use tcb_core::simd::basis::hermite;
    use tcb_core::simd::lane::Mask;
    use tcb_core::simd::w8::{M8, W8};
    use wide::f32x8;

    /// [`vectors`], where `crate::isa::avx2_kernels` said so (the token).
    #[inline(always)]
    pub(super) fn vectors_here(_: Avx2Kernels, c: Segment, h: [f32; 4], out: &mut [f32x8]) {
        // SAFETY: an `Avx2Kernels` exists only where `crate::isa` detected
        // AVX2 and FMA on this CPU.
        #[allow(unsafe_code)]
        unsafe {
            vectors(c, h, out)
        }
    }

    /// [`quats`], where `crate::isa::avx2_kernels` said so (the token).
    #[inline(always)]
    pub(super) fn quats_here<const LOW: u32>(
        _: Avx2Kernels,
        c: Segment,
        h: [f32; 4],
        out: &mut [f32x8],
    ) -> bool {
        // SAFETY: as in `vectors_here`.
        #[allow(unsafe_code)]
        unsafe {
            quats::<LOW>(c, h, out)
        }
    }

    /// Through AVX vectors, as `crate::quant`'s expansion: on arrays,
    /// LLVM's loop vectorizer vectorized the blocks' loop a second time,
    /// eight blocks at once with a transpose per operand (taken from 8
    /// rotation blocks on), and its setup cost every call.
    #[inline(always)]
    fn w(x: &f32x8) -> W8 {
        let v: __m256 = bytemuck::cast(*x);
        W8(bytemuck::cast(v))
    }

    /// [`w`]'s way back.
    #[inline(always)]
    fn back(x: W8) -> f32x8 {
        let v: __m256 = bytemuck::cast(x.0);
        bytemuck::cast(v)
    }

    #[inline(always)]
    fn rows(h: [f32; 4]) -> [W8; 4] {
        [W8([h[0]; 8]), W8([h[1]; 8]), W8([h[2]; 8]), W8([h[3]; 8])]
    }

    /// [`crate::kernel::vectors`].
    #[target_feature(enable = "avx2,fma")]
    fn vectors(c: Segment, h: [f32; 4], out: &mut [f32x8]) {
        let h = rows(h);
        let keys = c.p0.iter().zip(c.p1).zip(c.m0).zip(c.m1);
        // On arrays, unlike `quats`: LLVM then runs this loop four blocks
        // a turn (through `__m256`, one: `wide`'s instructions +30%).
        let a = |x: &f32x8| W8(x.to_array());
        for ((((p0, p1), m0), m1), o) in keys.zip(out) {
            *o = f32x8::new(hermite(&h, a(p0), a(p1), a(m0), a(m1)).0);
        }
    }

    /// [`crate::kernel::quats_above`] without velocities: the blocks'
    /// values, normalized; `false` where some lane's `|p|^2` is out of
    /// [`crate::kernel::in_range`]'s range from `f32::from_bits(LOW)`.
    #[target_feature(enable = "avx2,fma")]
    fn quats<const LOW: u32>(c: Segment, h: [f32; 4], out: &mut [f32x8]) -> bool {
        quats_inline::<LOW>(c, h, out)
    }

    /// [`quats`]' body, inlined into a caller that runs with AVX2 and FMA
    /// (a `#[target_feature]` function; elsewhere it runs, on arrays).
    #[inline(always)]
    pub(crate) fn quats_inline<const LOW: u32>(c: Segment, h: [f32; 4], out: &mut [f32x8]) -> bool {
        let low = f32::from_bits(LOW);
        let h = rows(h);
        let mut ok = M8([u32::MAX; 8]);
        for ((((p0, p1), m0), m1), o) in quat_keys(c).zip(out.as_chunks_mut::<4>().0) {
            let p = [
                hermite(&h, w(&p0[0]), w(&p1[0]), w(&m0[0]), w(&m1[0])),
                hermite(&h, w(&p0[1]), w(&p1[1]), w(&m0[1]), w(&m1[1])),
                hermite(&h, w(&p0[2]), w(&p1[2]), w(&m0[2]), w(&m1[2])),
                hermite(&h, w(&p0[3]), w(&p1[3]), w(&m0[3]), w(&m1[3])),
            ];
            ok = ok & in_range(&p, low);
            let (q, _) = normalize(p, None);
            *o = [back(q[0]), back(q[1]), back(q[2]), back(q[3])];
        }
        ok.all()
    }
}
