//! Weighted blending of poses: vectors lerp, rotations nlerp with hemisphere
//! correction, optionally per track (masks), as engines use for cross-fades
//! and layers.
//!
//! ```text
//! weight of layer i in a lane   w_i = weight_i * mask_i[track]
//! vectors                       sum_i w_i x_i / sum_i w_i
//! rotations                     normalize(sum_i w_i sign(q_i . q_0) q_i)
//! ```
//!
//! Lanes whose weights sum to zero keep the first layer's value. Velocities,
//! when every pose has them, are blended with the same weights (and signs).

use crate::clip::{Clip, TrackId};
use crate::pose::Pose;
use wide::f32x8;

/// Per-track weights of one layer, expanded to the pose's lanes once so that
/// blending stays SIMD and allocation-free.
#[derive(Clone, Debug)]
pub struct BlendMask {
    lanes: Vec<f32x8>,
}

impl BlendMask {
    /// `weight(track)` for every track of `clip` (1.0 for full influence).
    pub fn new(clip: &Clip, weight: impl Fn(TrackId) -> f32) -> Self {
        let layout = clip.layout();
        let mut flat = vec![0.0f32; layout.blocks * 8];
        for (i, slot) in layout.slots.iter().enumerate() {
            let w = weight(TrackId(i));
            for &j in &slot.index[..slot.kind.dim()] {
                flat[j] = w;
            }
        }
        BlendMask {
            lanes: flat
                .chunks_exact(8)
                .map(|c| f32x8::new(c.try_into().expect("8 lanes")))
                .collect(),
        }
    }
}

/// Blend `layers` (pose, weight) into `out`, with an optional mask per layer.
///
/// Every pose must have `out`'s layout (poses of one clip, or of clips with
/// the same tracks and time grids); layers that do not are skipped.
pub fn blend(out: &mut Pose, layers: &[(&Pose, f32)], masks: Option<&[&BlendMask]>) {
    let layout = out.layout.clone();
    // Which layers share `out`'s layout, decided once per call: poses of one
    // clip share the Arc; poses of another clip need a deep comparison, which
    // must not run per block. Layers past the 128th compare each time.
    let same = |i: usize| {
        let l = &layers[i].0.layout;
        std::sync::Arc::ptr_eq(l, &layout) || **l == *layout
    };
    let mask: u128 = (0..layers.len().min(128))
        .filter(|&i| same(i))
        .fold(0, |m, i| m | 1 << i);
    let usable = |i: usize| if i < 128 { mask >> i & 1 == 1 } else { same(i) };
    let Some(first) = (0..layers.len()).find(|&i| usable(i)) else {
        return;
    };
    let weight = |i: usize, block: usize| {
        let w = f32x8::splat(layers[i].1);
        match masks.and_then(|m| m.get(i)) {
            Some(m) => w * m.lanes[block],
            None => w,
        }
    };
    let with_velocity = out.velocities.is_some() && layers.iter().all(|l| l.0.velocities.is_some());
    let base = layers[first].0;

    // Vectors (and every lane first; rotation blocks are redone below).
    for b in 0..layout.blocks {
        let mut sum = f32x8::ZERO;
        let mut acc = f32x8::ZERO;
        let mut vacc = f32x8::ZERO;
        for i in (0..layers.len()).filter(|&i| usable(i)) {
            let w = weight(i, b);
            sum += w;
            acc += w * layers[i].0.values[b];
            if with_velocity {
                vacc += w * layers[i].0.velocities.as_ref().expect("checked")[b];
            }
        }
        let none = sum.simd_eq(f32x8::ZERO);
        let inv = none.select(f32x8::ZERO, f32x8::ONE / sum);
        out.values[b] = none.select(base.values[b], acc * inv);
        if with_velocity {
            let v = base.velocities.as_ref().expect("checked")[b];
            out.velocities.as_mut().expect("checked")[b] = none.select(v, vacc * inv);
        }
    }
    // Rotations in planes of 8: nlerp with hemisphere correction against the first layer.
    for &q in &layout.quat_blocks {
        let q0: [f32x8; 4] = std::array::from_fn(|c| base.values[q + c]);
        let mut acc = [f32x8::ZERO; 4];
        let mut vacc = [f32x8::ZERO; 4];
        let mut sum = f32x8::ZERO;
        for i in (0..layers.len()).filter(|&i| usable(i)) {
            let p = layers[i].0;
            let qi: [f32x8; 4] = std::array::from_fn(|c| p.values[q + c]);
            let dot = q0[0] * qi[0] + q0[1] * qi[1] + q0[2] * qi[2] + q0[3] * qi[3];
            let sign = dot.simd_lt(f32x8::ZERO).select(-f32x8::ONE, f32x8::ONE);
            let w = weight(i, q) * sign;
            sum += weight(i, q);
            for c in 0..4 {
                acc[c] += w * qi[c];
                if with_velocity {
                    vacc[c] += w * p.velocities.as_ref().expect("checked")[q + c];
                }
            }
        }
        let len = (acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2] + acc[3] * acc[3]).sqrt();
        let keep = sum.simd_eq(f32x8::ZERO) | len.simd_eq(f32x8::ZERO);
        let inv = keep.select(f32x8::ZERO, f32x8::ONE / len);
        let inv_sum = keep.select(f32x8::ZERO, f32x8::ONE / sum);
        for c in 0..4 {
            out.values[q + c] = keep.select(q0[c], acc[c] * inv);
            if with_velocity {
                let v0 = base.velocities.as_ref().expect("checked")[q + c];
                out.velocities.as_mut().expect("checked")[q + c] =
                    keep.select(v0, vacc[c] * inv_sum);
            }
        }
    }
    // Rotations sampled by the reference: four consecutive floats.
    for &at in &layout.loose_quats {
        let read = |p: &Pose| -> [f32; 4] {
            let flat: &[f32] = bytemuck::cast_slice(&p.values);
            flat[at..at + 4].try_into().expect("4")
        };
        let q0 = read(base);
        let mut acc = [0.0f32; 4];
        for i in (0..layers.len()).filter(|&i| usable(i)) {
            let qi = read(layers[i].0);
            let flat_w = {
                let w = weight(i, at / 8).to_array()[at % 8];
                if q0.iter().zip(&qi).map(|(a, b)| a * b).sum::<f32>() < 0.0 {
                    -w
                } else {
                    w
                }
            };
            for c in 0..4 {
                acc[c] += flat_w * qi[c];
            }
        }
        let len = acc.iter().map(|x| x * x).sum::<f32>().sqrt();
        let flat: &mut [f32] = bytemuck::cast_slice_mut(&mut out.values);
        for c in 0..4 {
            flat[at + c] = if len > 0.0 { acc[c] / len } else { q0[c] };
        }
    }
}
