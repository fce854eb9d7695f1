//! Weighted blending of poses: vectors lerp, rotations nlerp with hemisphere
//! correction, optionally per track (masks), as engines use for cross-fades
//! and layers; and additive layers.
//!
//! ```text
//! weight of layer i in a lane   w_i = weight_i * mask_i[track]
//! vectors                       sum_i w_i x_i / sum_i w_i
//! rotations                     normalize(sum_i w_i sign(q_i . q_0) q_i)
//! ```
//!
//! Lanes whose weights sum to zero keep the first layer's value. Velocities,
//! when every pose has them, are blended with the same weights (and signs).
//!
//! Every pose and mask must have the output's layout: poses of one clip, of
//! clips compiled alike, or, for any clips of one character, poses of one
//! [`Rig`](crate::Rig). Anything else is a [`BlendError`] and nothing is
//! written.
//!
//! Additive layers ([`add`]) apply the difference between a pose and a
//! reference pose, as ozz-animation's additive layers do:
//!
//! ```text
//! vectors     x += w (x_layer - x_reference)
//! rotations   q = nlerp(1, d, w) q,   d = q_layer conj(q_reference)  (d.w >= 0)
//! ```
//!
//! Scale tracks are vectors here, so their difference is added too (ozz
//! multiplies scales); the two agree at weights 0 and 1 on a unit reference.

use crate::clip::{Clip, TrackId};
use crate::kernel::normalize;
use crate::pose::{Pose, PoseLayout};
use std::fmt;
use std::sync::Arc;
use tcb_core::quat::mul as quat_mul;
use wide::f32x8;

/// Per-track weights of one layer, expanded to the pose's lanes once so that
/// blending stays SIMD and allocation-free.
#[derive(Clone, Debug)]
pub struct BlendMask {
    layout: Arc<PoseLayout>,
    lanes: Vec<f32x8>,
}

impl BlendMask {
    /// `weight(track)` for every track of `clip` (1.0 for full influence).
    pub fn new(clip: &Clip, weight: impl Fn(TrackId) -> f32) -> Self {
        BlendMask::for_layout(clip.layout(), weight)
    }

    /// `weight(track)` for every track of poses with `layout` (a clip's, or
    /// a [`Rig`](crate::Rig)'s, whose track ids [`Rig::track`](crate::Rig::track) gives).
    pub fn for_layout(layout: &Arc<PoseLayout>, weight: impl Fn(TrackId) -> f32) -> Self {
        let mut flat = vec![0.0f32; layout.blocks * 8];
        for (i, slot) in layout.slots.iter().enumerate() {
            let w = weight(TrackId(i));
            for &j in &slot.index[..slot.kind.dim()] {
                flat[j] = w;
            }
        }
        BlendMask {
            layout: layout.clone(),
            lanes: flat
                .chunks_exact(8)
                .map(|c| f32x8::new(c.try_into().expect("8 lanes")))
                .collect(),
        }
    }

    /// This mask times `other`, track by track (same layout).
    pub fn times(&self, other: &BlendMask) -> Result<BlendMask, BlendError> {
        if !same_layout(&other.layout, &self.layout) {
            return Err(BlendError::Mask { layer: 1 });
        }
        Ok(BlendMask {
            layout: self.layout.clone(),
            lanes: self
                .lanes
                .iter()
                .zip(&other.lanes)
                .map(|(a, b)| *a * *b)
                .collect(),
        })
    }
}

/// A blend that was refused; the output was not written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BlendError {
    /// Layer `layer` (for [`add`]: 0 the layer, 1 the reference) has
    /// another layout than the output (another rig, or a clip not sampled
    /// through the output's rig).
    Layout {
        /// Index of the layer.
        layer: usize,
    },
    /// The mask of layer `layer` was made for another layout.
    Mask {
        /// Index of the layer.
        layer: usize,
    },
    /// `masks` has another length than `layers`.
    MaskCount {
        /// Layers.
        layers: usize,
        /// Masks.
        masks: usize,
    },
}

impl fmt::Display for BlendError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BlendError::Layout { layer } => write!(
                f,
                "layer {layer} has another pose layout than the output (sample every layer through one Rig)"
            ),
            BlendError::Mask { layer } => {
                write!(
                    f,
                    "the mask of layer {layer} was made for another pose layout"
                )
            }
            BlendError::MaskCount { layers, masks } => {
                write!(f, "{masks} masks for {layers} layers")
            }
        }
    }
}

impl std::error::Error for BlendError {}

/// Layouts are the same when shared, or equal (clips compiled alike).
fn same_layout(a: &Arc<PoseLayout>, b: &Arc<PoseLayout>) -> bool {
    Arc::ptr_eq(a, b) || **a == **b
}

/// The pose blocks that are not x/y/z/w planes of rotations, walking
/// `quat_blocks` (sorted) alongside: no search per block.
#[inline]
fn vector_blocks(layout: &PoseLayout) -> impl Iterator<Item = usize> + '_ {
    let mut q = layout.quat_blocks.iter().peekable();
    (0..layout.blocks).filter(move |&b| {
        while q.next_if(|&&s| b >= s + 4).is_some() {}
        q.peek().is_none_or(|&&s| b < s)
    })
}

/// Blend `layers` (pose, weight) into `out`, with an optional mask per layer.
///
/// Every pose and mask must have `out`'s layout; otherwise nothing is
/// written and the first mismatch is returned.
pub fn blend(
    out: &mut Pose,
    layers: &[(&Pose, f32)],
    masks: Option<&[&BlendMask]>,
) -> Result<(), BlendError> {
    let layout = out.layout.clone();
    if let Some(i) = (0..layers.len()).find(|&i| !same_layout(&layers[i].0.layout, &layout)) {
        return Err(BlendError::Layout { layer: i });
    }
    if let Some(m) = masks {
        if m.len() != layers.len() {
            return Err(BlendError::MaskCount {
                layers: layers.len(),
                masks: m.len(),
            });
        }
        if let Some(i) = (0..m.len()).find(|&i| !same_layout(&m[i].layout, &layout)) {
            return Err(BlendError::Mask { layer: i });
        }
    }
    let Some(&(base, _)) = layers.first() else {
        return Ok(());
    };
    let weight = |i: usize, block: usize| {
        let w = f32x8::splat(layers[i].1);
        match masks {
            Some(m) => w * m[i].lanes[block],
            None => w,
        }
    };
    let with_velocity = out.velocities.is_some() && layers.iter().all(|l| l.0.velocities.is_some());

    // Vectors.
    for b in vector_blocks(&layout) {
        let mut sum = f32x8::ZERO;
        let mut acc = f32x8::ZERO;
        let mut vacc = f32x8::ZERO;
        for (i, (pose, _)) in layers.iter().enumerate() {
            let w = weight(i, b);
            sum += w;
            acc += w * pose.values[b];
            if with_velocity {
                vacc += w * pose.velocities.as_ref().expect("checked")[b];
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
    // Rotations in planes of 8: nlerp with hemisphere correction against
    // the first layer.
    for &block in &layout.quat_blocks {
        let get = |d: &[f32x8], c: usize| d[block + c];
        let q0: [f32x8; 4] = std::array::from_fn(|c| get(&base.values, c));
        let mut acc = [f32x8::ZERO; 4];
        let mut vacc = [f32x8::ZERO; 4];
        let mut sum = f32x8::ZERO;
        for (i, (p, _)) in layers.iter().enumerate() {
            let qi: [f32x8; 4] = std::array::from_fn(|c| get(&p.values, c));
            let dot = q0[0] * qi[0] + q0[1] * qi[1] + q0[2] * qi[2] + q0[3] * qi[3];
            let sign = dot.simd_lt(f32x8::ZERO).select(-f32x8::ONE, f32x8::ONE);
            let w = weight(i, block) * sign;
            sum += weight(i, block);
            for c in 0..4 {
                acc[c] += w * qi[c];
                if with_velocity {
                    vacc[c] += w * get(p.velocities.as_ref().expect("checked"), c);
                }
            }
        }
        let len = (acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2] + acc[3] * acc[3]).sqrt();
        let keep = sum.simd_eq(f32x8::ZERO) | len.simd_eq(f32x8::ZERO);
        let inv = keep.select(f32x8::ZERO, f32x8::ONE / len);
        let inv_sum = keep.select(f32x8::ZERO, f32x8::ONE / sum);
        for c in 0..4 {
            out.values[block + c] = keep.select(q0[c], acc[c] * inv);
            if with_velocity {
                let v0 = get(base.velocities.as_ref().expect("checked"), c);
                out.velocities.as_mut().expect("checked")[block + c] =
                    keep.select(v0, vacc[c] * inv_sum);
            }
        }
    }
    Ok(())
}

/// Add an additive layer in place: `pose` ⊕ `weight` (`layer` ⊖ `reference`),
/// per track times `mask` (see the module docs for the formulas).
/// Velocities are carried exactly when `pose` and `layer` have them; a
/// `reference` without velocities is a constant (the usual fixed reference
/// pose), one with them moves.
///
/// ```
/// # use std::sync::Arc;
/// # let text = r#"{"format": "tcb-clip/1", "tracks": [{"name": "x", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#;
/// # let clip = Arc::new(tcb_runtime::Clip::compile(&tcb_io::ClipDoc::parse(text).unwrap().build().unwrap()));
/// let x = clip.track("x").unwrap();
/// let mut base = tcb_runtime::Instance::new(clip.clone(), false);
/// let mut breathe = tcb_runtime::Instance::new(clip.clone(), false);
/// let mut reference = tcb_runtime::Instance::new(clip.clone(), false);
/// let mut out = base.sample(0.5).clone();
/// breathe.sample(0.75);
/// reference.sample(0.25);
/// tcb_runtime::blend::add(&mut out, breathe.pose(), reference.pose(), 0.5, None).unwrap();
/// assert!((out.scalar(x) - (0.5 + 0.5 * (0.75 - 0.25))).abs() < 1e-6);
/// ```
pub fn add(
    pose: &mut Pose,
    layer: &Pose,
    reference: &Pose,
    weight: f32,
    mask: Option<&BlendMask>,
) -> Result<(), BlendError> {
    let layout = pose.layout.clone();
    for (i, p) in [layer, reference].iter().enumerate() {
        if !same_layout(&p.layout, &layout) {
            return Err(BlendError::Layout { layer: i });
        }
    }
    if let Some(m) = mask
        && !same_layout(&m.layout, &layout)
    {
        return Err(BlendError::Mask { layer: 0 });
    }
    let w_at = |b: usize| {
        let w = f32x8::splat(weight);
        mask.map_or(w, |m| w * m.lanes[b])
    };
    // The reference moves only if it has velocities (a pose sampled once,
    // without them, is a constant).
    let vel = match &layer.velocities {
        Some(l) if pose.velocities.is_some() => Some((l, reference.velocities.as_ref())),
        _ => None,
    };
    for b in vector_blocks(&layout) {
        let w = w_at(b);
        pose.values[b] += w * (layer.values[b] - reference.values[b]);
        if let (Some((l, r)), Some(v)) = (vel, pose.velocities.as_mut()) {
            v[b] += w * (l[b] - r.map_or(f32x8::ZERO, |r| r[b]));
        }
    }
    let conj = |q: [f32x8; 4]| [-q[0], -q[1], -q[2], q[3]];
    for &block in &layout.quat_blocks {
        let planes = |d: &[f32x8]| -> [f32x8; 4] { std::array::from_fn(|c| d[block + c]) };
        let w = w_at(block);
        let (l, r, base) = (
            planes(&layer.values),
            planes(&reference.values),
            planes(&pose.values),
        );
        let d = quat_mul(&l, &conj(r));
        let sign = d[3].simd_lt(f32x8::ZERO).select(-f32x8::ONE, f32x8::ONE);
        let ws = w * sign;
        let p = [
            ws * d[0],
            ws * d[1],
            ws * d[2],
            (f32x8::ONE - w) + ws * d[3],
        ];
        let dp = vel.map(|(lv, rv)| {
            let dl = quat_mul(&planes(lv), &conj(r));
            let dr = rv.map_or([f32x8::ZERO; 4], |rv| quat_mul(&l, &conj(planes(rv))));
            std::array::from_fn(|c| ws * (dl[c] + dr[c]))
        });
        let (n, dn) = normalize(p, dp);
        let out = quat_mul(&n, &base);
        pose.values[block..block + 4].copy_from_slice(&out);
        if let (Some(dn), Some(v)) = (dn, pose.velocities.as_mut()) {
            let a = quat_mul(&dn, &base);
            let b = quat_mul(&n, &planes(v));
            for c in 0..4 {
                v[block + c] = a[c] + b[c];
            }
        }
    }
    Ok(())
}
