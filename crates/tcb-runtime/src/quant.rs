//! Optional 16-bit storage of a group's per-key controls, chosen when a
//! clip is compiled ([`crate::CompileOptions::quantize`]).
//!
//! Per lane (channel) and per control (`P`, `TO`, `TI`; for rotations per
//! component too), over all of the group's keys:
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

use wide::{f32x8, i32x8, u16x8};

/// One group's controls (vectors or rotations) in 16 bits.
#[derive(Clone, Debug)]
pub(crate) struct Quantized {
    /// `[key][block][j]`, like the f32 layout.
    data: Vec<u16x8>,
    /// `[block][j]`: each lane's minimum and step.
    min: Vec<f32x8>,
    scale: Vec<f32x8>,
    /// Vectors per key and block (`KEY_STRIDE` or `HQ_STRIDE`).
    stride: usize,
    blocks: usize,
}

impl Quantized {
    /// Quantize `packed` (`[key][block][j]`, `keys` keys of `blocks` blocks
    /// of `stride` vectors). Also returns, per block and j, each lane's
    /// largest error on any key.
    pub fn new(
        packed: &[f32x8],
        keys: usize,
        blocks: usize,
        stride: usize,
    ) -> (Self, Vec<[f32; 8]>) {
        let at = |k: usize, b: usize, j: usize| packed[(k * blocks + b) * stride + j].to_array();
        let mut min = Vec::with_capacity(blocks * stride);
        let mut scale = Vec::with_capacity(blocks * stride);
        for b in 0..blocks {
            for j in 0..stride {
                let (mut lo, mut hi) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
                for k in 0..keys {
                    let x = at(k, b, j);
                    for l in 0..8 {
                        lo[l] = lo[l].min(x[l]);
                        hi[l] = hi[l].max(x[l]);
                    }
                }
                min.push(f32x8::new(lo));
                scale.push(f32x8::new(std::array::from_fn(|l| {
                    (hi[l] - lo[l]) / 65535.0
                })));
            }
        }
        let mut data = Vec::with_capacity(packed.len());
        let mut error = vec![[0.0f32; 8]; blocks * stride];
        for k in 0..keys {
            for b in 0..blocks {
                for j in 0..stride {
                    let (x, lo, s) = (
                        at(k, b, j),
                        min[b * stride + j].to_array(),
                        scale[b * stride + j].to_array(),
                    );
                    let q: [u16; 8] = std::array::from_fn(|l| {
                        if s[l] > 0.0 {
                            ((x[l] - lo[l]) / s[l]).round().clamp(0.0, 65535.0) as u16
                        } else {
                            0
                        }
                    });
                    for l in 0..8 {
                        let back = lo[l] + f32::from(q[l]) * s[l];
                        let e = &mut error[b * stride + j][l];
                        *e = e.max((back - x[l]).abs());
                    }
                    data.push(u16x8::new(q));
                }
            }
        }
        let q = Quantized {
            data,
            min,
            scale,
            stride,
            blocks,
        };
        (q, error)
    }

    /// Expand key `k` (all blocks) into `out` (`blocks * stride` vectors).
    #[inline]
    pub fn expand(&self, k: usize, out: &mut [f32x8]) {
        let n = self.blocks * self.stride;
        let src = &self.data[k * n..(k + 1) * n];
        for (((o, q), lo), s) in out.iter_mut().zip(src).zip(&self.min).zip(&self.scale) {
            *o = *lo + f32x8::from_i32x8(i32x8::from_u16x8(*q)) * *s;
        }
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.data.as_slice())
            + std::mem::size_of_val(self.min.as_slice())
            + std::mem::size_of_val(self.scale.as_slice())
    }
}
