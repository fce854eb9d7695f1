//! Optional 16-bit storage of a group's per-key controls, chosen when a
//! clip is compiled ([`crate::CompileOptions::quantize`]).
//!
//! Per lane (channel) and plane (for rotations per component too), over all
//! of the group's keys, one range for `P` and one shared by `TO` and `TI`
//! (so that a `TI` stored as its key's `TO`, see `crate::store`, stays
//! equal to it):
//!
//! ```text
//! scale = (max - min) / 65535      q = round((x - min) / scale)      x' = min + q scale
//! ```
//!
//! so each stored control is off by at most `scale / 2` (plus f32
//! rounding); the error actually made is measured when the clip is compiled.
//! A sample inside the keys is `h1 P0 + h2 P1 + h3 M0 + h4 M1` with
//! `h1 + h2 = 1`, `h1, h2 >= 0` and `|h3|, |h4| <= 4/27`, so it moves by at
//! most `e_P + 4/27 (e_TO + e_TI)` (the bound [`crate::Clip::quantization_error`]
//! reports; rotations are normalized after, which multiplies it by at most
//! `2 / min(1, |p|)` with |p| the curve's smallest length: about 2 near unit
//! length, more for curves between keys on opposite hemispheres that a
//! track keeps as written). Linear extrapolation adds `|dt| e_TO`.
//! The kernels themselves are unchanged: an instance expands the two keys a
//! group reads into a two-slot cache (forward playback expands one key per
//! crossing), and a track on its own key times expands its segment into its
//! lane's cached controls when it crosses a key (`loose.rs`).

use tcb_core::simd::basis::Real;
use wide::{f32x8, i32x8, u16x8};

/// The 16-bit step of a range `lo ..= hi` (halved first: `hi - lo`
/// overflows f32 for a range spanning it). One formula for groups and
/// loose lanes.
pub(crate) fn step_of(lo: f32, hi: f32) -> f32 {
    (hi / 2.0 - lo / 2.0) / 32767.5
}

/// A 16-bit number `q` (as a float: exact) back from its range's minimum
/// `lo` and `step`: `lo + q step` (module docs). One formula for groups,
/// their AVX2 instance and loose lanes.
#[inline(always)]
pub(crate) fn dequantize16<L: Real>(lo: L, q: L, step: L) -> L {
    lo + q * step
}

/// The larger of `e` and `x`, NaN kept (`f32::max` would drop it, and a
/// lane whose error is NaN would claim none).
pub(crate) fn worse(e: f32, x: f32) -> f32 {
    if x.is_nan() || x > e { x } else { e }
}

/// What errors `[e_P, e_TO, e_TI]` in a segment's stored controls can move
/// a sample inside it: `e_P + 4/27 (e_TO + e_TI)` (module docs).
pub(crate) fn sample_bound(e: [f32; 3]) -> f32 {
    e[0] + 4.0 / 27.0 * (e[1] + e[2])
}

/// One group's controls in 16 bits, laid out as the f32 ones
/// ([`crate::store`]): `[P TO]` per key and `TI` where it differs.
#[derive(Clone, Debug)]
pub(crate) struct Quantized {
    /// At the same offsets as the f32 layout.
    data: Vec<u16x8>,
    /// `[P planes][T planes]`: each lane's minimum and step, `T` shared by
    /// `TO` and `TI` (so that a `TI` equal to its `TO` stays equal).
    min: Vec<f32x8>,
    scale: Vec<f32x8>,
    planes: usize,
}

impl Quantized {
    /// Quantize `packed` (the f32 layout of [`crate::store`]: key `k`'s
    /// `P` and `TO` from `at[k][0]`, its `TI` at `at[k][1]`, `planes`
    /// vectors each). Also returns, per control (`P`, `TO`, `TI`), plane
    /// and lane, the largest error on any key; `None` where some lane's
    /// range or error is not finite (values or tangents beyond f32), so
    /// that its group stays in f32 rather than state a bound it does not
    /// keep.
    pub fn new(
        packed: &[f32x8],
        at: &[[u32; 2]],
        planes: usize,
    ) -> Option<(Self, [Vec<[f32; 8]>; 3])> {
        // Section start of control j at key k.
        let start = |k: usize, j: usize| match j {
            0 => at[k][0] as usize,
            1 => at[k][0] as usize + planes,
            _ => at[k][1] as usize,
        };
        let mut min = Vec::with_capacity(2 * planes);
        let mut scale = Vec::with_capacity(2 * planes);
        for range in [&[0usize][..], &[1, 2][..]] {
            for p in 0..planes {
                let (mut lo, mut hi) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
                for k in 0..at.len() {
                    for &j in range {
                        let x = packed[start(k, j) + p].to_array();
                        for l in 0..8 {
                            lo[l] = lo[l].min(x[l]);
                            hi[l] = hi[l].max(x[l]);
                        }
                    }
                }
                min.push(f32x8::new(lo));
                scale.push(f32x8::new(std::array::from_fn(|l| step_of(lo[l], hi[l]))));
            }
        }
        let mut q = Quantized {
            data: vec![u16x8::ZERO; packed.len()],
            min,
            scale,
            planes,
        };
        let mut error: [Vec<[f32; 8]>; 3] = std::array::from_fn(|_| vec![[0.0f32; 8]; planes]);
        for k in 0..at.len() {
            for (j, error) in error.iter_mut().enumerate() {
                let r = usize::from(j > 0) * planes;
                for (p, error) in error.iter_mut().enumerate() {
                    let i = start(k, j) + p;
                    let (x, lo, s) = (
                        packed[i].to_array(),
                        q.min[r + p].to_array(),
                        q.scale[r + p].to_array(),
                    );
                    let v: [u16; 8] = std::array::from_fn(|l| {
                        if s[l] > 0.0 {
                            ((x[l] - lo[l]) / s[l]).round().clamp(0.0, 65535.0) as u16
                        } else {
                            0
                        }
                    });
                    for (l, e) in error.iter_mut().enumerate() {
                        let back = dequantize16(lo[l], f32::from(v[l]), s[l]);
                        *e = worse(*e, (back - x[l]).abs());
                    }
                    q.data[i] = u16x8::new(v);
                }
            }
        }
        let finite = |v: &[f32x8]| v.iter().all(|x| x.to_array().iter().all(|y| y.is_finite()));
        let errors_finite = error.iter().flatten().flatten().all(|e| e.is_finite());
        (finite(&q.min) && finite(&q.scale) && errors_finite).then_some((q, error))
    }

    /// Expand the section (`planes` vectors) starting at `at` into `out`:
    /// a `P` section, or with `tangent` a `TO` or `TI` one.
    /// `avx2`: run the AVX2 instance (asked once per segment by the
    /// caller).
    #[inline(always)]
    pub fn expand(
        &self,
        at: usize,
        tangent: bool,
        out: &mut [f32x8],
        avx2: Option<crate::isa::Avx2Kernels>,
    ) {
        let n = self.planes;
        let r = usize::from(tangent) * n;
        let src = &self.data[at..at + n];
        let (min, scale) = (&self.min[r..r + n], &self.scale[r..r + n]);
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = avx2 {
            return v3::expand_here(avx2, src, min, scale, out);
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = avx2;
        for (((o, q), lo), s) in out.iter_mut().zip(src).zip(min).zip(scale) {
            *o = dequantize16(*lo, f32x8::from_i32x8(i32x8::from_u16x8(*q)), *s);
        }
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.data.as_slice())
            + std::mem::size_of_val(self.min.as_slice())
            + std::mem::size_of_val(self.scale.as_slice())
    }
}

/// The AVX2 + FMA instance of [`Quantized::expand`] (see `crate::isa`):
/// [`dequantize16`] on `tcb_core::simd::w8::W8`, each `u16` widened and
/// converted in one instruction per plane.
#[cfg(target_arch = "x86_64")]
mod v3 {
    use crate::isa::Avx2Kernels;
    use crate::quant::dequantize16;
    use std::arch::x86_64::{__m256, _mm256_cvtepi32_ps, _mm256_cvtepu16_epi32};
    use tcb_core::simd::w8::W8;
    use wide::{f32x8, u16x8};

    /// [`crate::quant::Quantized::expand`]'s planes, where
    /// `crate::isa::avx2_kernels` said so (the token).
    #[inline(always)]
    pub(super) fn expand_here(
        _: Avx2Kernels,
        src: &[u16x8],
        min: &[f32x8],
        scale: &[f32x8],
        out: &mut [f32x8],
    ) {
        // SAFETY: an `Avx2Kernels` exists only where `crate::isa` detected
        // AVX2 and FMA on this CPU.
        #[allow(unsafe_code)]
        unsafe {
            expand(src, min, scale, out)
        }
    }

    /// Through AVX vectors, as the decoder's `Plane` loads: on arrays,
    /// LLVM's loop vectorizer vectorizes this loop again across its
    /// iterations (a transpose per operand, 2.1x the instructions).
    #[inline(always)]
    fn w(x: &f32x8) -> W8 {
        let v: __m256 = bytemuck::cast(*x);
        W8(bytemuck::cast(v))
    }

    #[target_feature(enable = "avx2,fma")]
    fn expand(src: &[u16x8], min: &[f32x8], scale: &[f32x8], out: &mut [f32x8]) {
        for (((o, q), lo), s) in out.iter_mut().zip(src).zip(min).zip(scale) {
            // Each `u16` widened and converted: exact.
            let q: __m256 = _mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(bytemuck::cast(*q)));
            let v = dequantize16(w(lo), W8(bytemuck::cast(q)), w(s));
            let v: __m256 = bytemuck::cast(v.0);
            *o = bytemuck::cast(v);
        }
    }
}
