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
//! Lanes whose weights sum to less than [`MIN_WEIGHT_SUM`] (1e-12) in
//! magnitude keep the first layer's value. Velocities,
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

/// Lanes whose layer weights sum to less than this in magnitude keep the
/// first layer's value, as at a sum of zero: dividing by a smaller sum
/// (a denormal) would give infinities, and weights that small blend
/// nothing a frame can show.
pub const MIN_WEIGHT_SUM: f32 = 1e-12;

use crate::clip::Clip;
use crate::kernel::normalize;
use crate::layout::PoseLayout;
use crate::layout::TrackId;
use crate::pose::Pose;
use std::fmt;
use std::ops::Range;
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
            let w = weight(layout.id(i));
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

/// The runs of pose blocks that are not x/y/z/w planes of rotations: the
/// gaps between `quat_blocks` (sorted), so that vector blocks are walked as
/// slices, without a test per block.
#[inline]
fn vector_runs(layout: &PoseLayout) -> impl Iterator<Item = Range<usize>> + '_ {
    let starts = std::iter::once(0).chain(layout.quat_blocks.iter().map(|&q| q + 4));
    let ends = layout
        .quat_blocks
        .iter()
        .copied()
        .chain(std::iter::once(layout.blocks));
    starts.zip(ends).filter(|(a, b)| a < b).map(|(a, b)| a..b)
}

/// `acc += w(b) * x` over blocks `r` (`acc` and `x` are those blocks).
#[inline(always)]
fn accumulate(acc: &mut [f32x8], x: &[f32x8], r: Range<usize>, w: impl Fn(usize) -> f32x8) {
    for ((a, &x), b) in acc.iter_mut().zip(x).zip(r) {
        *a += w(b) * x;
    }
}

/// Blend `layers` (pose, weight) into `out`, with an optional mask per layer.
///
/// Every pose and mask must have `out`'s layout; otherwise nothing is
/// written and the first mismatch is returned.
///
/// Layers are summed one after another into `out` (in layer order, as the
/// formulas in the module docs read), so each pass streams through slices.
pub fn blend(
    out: &mut Pose,
    layers: &[(&Pose, f32)],
    masks: Option<&[&BlendMask]>,
) -> Result<(), BlendError> {
    // Hot (every frame of a blended character) and kept whole: its loops
    // share the layers' weights and sums, which steps would pass around.
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
    let with_velocity = out.velocities.is_some() && layers.iter().all(|l| l.0.velocities.is_some());
    let Pose {
        values: out_v,
        velocities: out_dv,
        ..
    } = out;
    let mut out_dv = out_dv.as_mut().filter(|_| with_velocity);
    let (zero, one) = (f32x8::ZERO, f32x8::ONE);
    let min_sum = f32x8::splat(MIN_WEIGHT_SUM);
    // Lanes whose weights sum to almost nothing keep the first layer.
    let none_at = |sum: f32x8| sum.abs().simd_lt(min_sum);
    // The weight of layer i in block b, and the sum over layers.
    let w_at = |i: usize, b: usize| {
        let w = f32x8::splat(layers[i].1);
        match masks {
            Some(m) => w * m[i].lanes[b],
            None => w,
        }
    };
    let flat_sum = f32x8::splat(layers.iter().map(|l| l.1).sum());
    let sum_at = |b: usize| match masks {
        Some(_) => (0..layers.len()).fold(zero, |s, i| s + w_at(i, b)),
        None => flat_sum,
    };

    // Vectors: sum w_i x_i, then divide by sum w_i.
    for r in vector_runs(&layout) {
        out_v[r.clone()].fill(zero);
        for (i, (pose, _)) in layers.iter().enumerate() {
            let x = &pose.values[r.clone()];
            accumulate(&mut out_v[r.clone()], x, r.clone(), |b| w_at(i, b));
        }
        let mut dv = out_dv.as_deref_mut().map(|v| &mut v[r.clone()]);
        if let Some(dv) = dv.as_deref_mut() {
            dv.fill(zero);
            for (i, (pose, _)) in layers.iter().enumerate() {
                let x = &pose.velocities.as_ref().expect("checked")[r.clone()];
                accumulate(dv, x, r.clone(), |b| w_at(i, b));
            }
        }
        let base_v = &base.values[r.clone()];
        for ((b, o), &x0) in r.clone().zip(&mut out_v[r.clone()]).zip(base_v) {
            let sum = sum_at(b);
            let none = none_at(sum);
            let inv = none.select(zero, one / sum);
            *o = none.select(x0, *o * inv);
        }
        if let Some(dv) = dv {
            let base_dv = &base.velocities.as_ref().expect("checked")[r.clone()];
            for ((b, o), &v0) in r.clone().zip(dv).zip(base_dv) {
                let sum = sum_at(b);
                let none = none_at(sum);
                *o = none.select(v0, *o * none.select(zero, one / sum));
            }
        }
    }
    // Rotations in planes of 8: nlerp with hemisphere correction against
    // the first layer.
    for &block in &layout.quat_blocks {
        let planes = |d: &[f32x8]| -> [f32x8; 4] {
            let p = &d[block..block + 4];
            [p[0], p[1], p[2], p[3]]
        };
        let q0 = planes(&base.values);
        let mut acc = [zero; 4];
        let mut vacc = [zero; 4];
        let mut sum = zero;
        for (i, (p, _)) in layers.iter().enumerate() {
            let qi = planes(&p.values);
            let dot = q0[0] * qi[0] + q0[1] * qi[1] + q0[2] * qi[2] + q0[3] * qi[3];
            let sign = dot.simd_lt(zero).select(-one, one);
            let wi = w_at(i, block);
            let ws = wi * sign;
            sum += wi;
            for c in 0..4 {
                acc[c] += ws * qi[c];
            }
            if with_velocity {
                let dq = planes(p.velocities.as_ref().expect("checked"));
                for c in 0..4 {
                    vacc[c] += ws * dq[c];
                }
            }
        }
        let len = (acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2] + acc[3] * acc[3]).sqrt();
        // A length below f32's smallest normal would make its inverse inf.
        let keep = none_at(sum) | len.simd_lt(f32x8::splat(f32::MIN_POSITIVE));
        let inv = keep.select(zero, one / len);
        let inv_sum = keep.select(zero, one / sum);
        for (c, o) in out_v[block..block + 4].iter_mut().enumerate() {
            *o = keep.select(q0[c], acc[c] * inv);
        }
        if let Some(dv) = out_dv.as_deref_mut() {
            let v0 = planes(base.velocities.as_ref().expect("checked"));
            for (c, o) in dv[block..block + 4].iter_mut().enumerate() {
                *o = keep.select(v0[c], vacc[c] * inv_sum);
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
/// let mut base = tcb_runtime::Instance::new(clip.clone());
/// let mut breathe = tcb_runtime::Instance::new(clip.clone());
/// let mut reference = tcb_runtime::Instance::new(clip.clone());
/// let mut out = base.sample(0.5).clone();
/// breathe.sample(0.75);
/// reference.sample(0.25);
/// tcb_runtime::blend::add(&mut out, breathe.pose(), reference.pose(), 0.5, None).unwrap();
/// assert!((out.scalar(x).unwrap() - (0.5 + 0.5 * (0.75 - 0.25))).abs() < 1e-6);
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
    for b in vector_runs(&layout).flatten() {
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
