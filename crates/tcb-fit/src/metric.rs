//! What `docs/reduce.md` compares: the check times, clips as `tcb sample`
//! plays them (the runtime), and the `shell` and `value` errors.
//!
//! ```text
//! shell   e_j(t) = max over v in {0, R e_x, R e_y, R e_z} of |M_j(t) v - M'_j(t) v|
//!         M_j = M_parent(j) T_j R_j S_j          (model space, composed down the hierarchy)
//! value   vectors: max |x_c - x'_c| per component; rotations: 2 acos(|q . q'|)
//! ```

use crate::fit::{Norm, error};
use glam::DAffine3;
use std::sync::Arc;
use tcb_core::sample_times::inbetweens;
use tcb_core::skeleton::{Skeleton, Transform};
use tcb_core::{SourceClip, TrackKind};
use tcb_runtime::{Instance, SkeletonBinding};

/// The check times of a clip: every key time (the sorted union of its
/// tracks' key times) and 3 evenly spaced times inside each interval.
pub fn check_times(clip: &SourceClip) -> Vec<f64> {
    inbetweens(&clip.key_times(), 3)
}

/// A compiled clip played by the runtime (as `tcb sample` plays it) at
/// `times`: one row of [`SourceClip::channel_count`] values per time, concatenated.
pub fn play(clip: &Arc<tcb_runtime::Clip>, times: &[f64]) -> Vec<f32> {
    let channels = clip.channel_count();
    let mut instance = Instance::new(clip.clone());
    let mut rows = vec![0.0f32; times.len() * channels];
    for (row, &t) in rows.chunks_exact_mut(channels.max(1)).zip(times) {
        instance.sample(t).write_row(row, None);
    }
    rows
}

/// The largest error found, where.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    /// The error (model-space distance for `shell`; the track's units, or
    /// degrees for rotations, for `value`).
    pub error: f64,
    /// Error over the tolerance it is held to.
    pub ratio: f64,
    /// The joint (`shell`) or track (`value`).
    pub at: String,
    /// The check time.
    pub time: f64,
}

impl Worst {
    fn none() -> Self {
        Worst {
            error: 0.0,
            ratio: 0.0,
            at: String::new(),
            time: 0.0,
        }
    }

    fn take(&mut self, error: f64, ratio: f64, at: &str, time: f64) {
        // NaN counts as the worst there is; the first sample is taken even
        // at zero error, so an exact result still names a joint and time.
        let first = self.at.is_empty() && !at.is_empty();
        if first || ratio > self.ratio || (ratio.is_nan() && !self.ratio.is_nan()) {
            *self = Worst {
                error,
                ratio,
                at: at.to_owned(),
                time,
            };
        }
    }
}

/// An error measured over a whole clip.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The largest, and where.
    pub worst: Worst,
    /// Per joint (`shell`) or per track (`value`): the largest error over
    /// the tolerance.
    pub each: Vec<f64>,
    /// Per check time: the largest error over the tolerance.
    pub at_time: Vec<f64>,
}

/// The rest-pose height H of `docs/reduce.md`: the largest distance of any
/// joint from the (first) root in the rest pose.
pub fn rest_height(skeleton: &Skeleton) -> f64 {
    let local: Vec<Transform> = skeleton.joints().iter().map(|j| j.rest).collect();
    let mut model = vec![DAffine3::IDENTITY; local.len()];
    skeleton.model_transforms_f64(&local, &mut model);
    let Some(root) = model.first() else {
        return 0.0;
    };
    model
        .iter()
        .map(|m| (m.translation - root.translation).length())
        .fold(0.0, f64::max)
}

/// The `shell` error of `reduced` against `reference` (both compiled) at
/// `times`, with shell radius `radius`, over the joints of `skeleton`.
/// Joints are composed in f64 ([`Skeleton::model_transforms_f64`]).
pub fn shell_error(
    skeleton: &Skeleton,
    reference: &Arc<tcb_runtime::Clip>,
    reduced: &Arc<tcb_runtime::Clip>,
    times: &[f64],
    radius: f64,
    tolerance: f64,
) -> Measured {
    let bind_a = SkeletonBinding::new(skeleton.clone(), reference);
    let bind_b = SkeletonBinding::new(skeleton.clone(), reduced);
    let mut ia = Instance::new(reference.clone());
    let mut ib = Instance::new(reduced.clone());
    let n = skeleton.joints().len();
    let mut local = vec![Transform::IDENTITY; n];
    let (mut ma, mut mb) = (vec![DAffine3::IDENTITY; n], vec![DAffine3::IDENTITY; n]);
    let mut worst = Worst::none();
    let mut each = vec![0.0f64; n];
    let mut at_time = vec![0.0f64; times.len()];
    for (&t, at) in times.iter().zip(&mut at_time) {
        // Both bindings were made for their instance's clip, and `local`
        // has a transform per joint.
        bind_a
            .local_transforms(ia.sample(t), &mut local)
            .expect("bound to its clip");
        skeleton.model_transforms_f64(&local, &mut ma);
        bind_b
            .local_transforms(ib.sample(t), &mut local)
            .expect("bound to its clip");
        skeleton.model_transforms_f64(&local, &mut mb);
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let e = point_error(&ma[j], &mb[j], radius);
            worst.take(e, e / tolerance, &joint.name, t);
            each[j] = each[j].max(e / tolerance);
            *at = at.max(e / tolerance);
        }
    }
    Measured {
        worst,
        each,
        at_time,
    }
}

/// `max over v in {0, R e_x, R e_y, R e_z} of |a v - b v|`.
pub fn point_error(a: &DAffine3, b: &DAffine3, radius: f64) -> f64 {
    let dt = a.translation - b.translation;
    let cols = [
        a.matrix3.x_axis - b.matrix3.x_axis,
        a.matrix3.y_axis - b.matrix3.y_axis,
        a.matrix3.z_axis - b.matrix3.z_axis,
    ];
    cols.iter()
        .map(|c| (dt + *c * radius).length())
        .fold(dt.length(), f64::max)
}

/// The `value` error of `reduced` (compiled) against `reference` played at
/// `times` (`reference_rows`, from [`play`]): vectors against `tolerance`
/// (per component), rotations against `rotation_degrees`. The worst is the
/// largest ratio.
pub fn value_error(
    reference: &SourceClip,
    reference_rows: &[f32],
    reduced: &Arc<tcb_runtime::Clip>,
    times: &[f64],
    tolerance: f64,
    rotation_degrees: f64,
) -> Measured {
    let channels = reference.channel_count();
    let (ra, rb) = (reference_rows, play(reduced, times));
    let mut worst = Worst::none();
    let mut each = vec![0.0f64; reference.tracks().len()];
    let mut at_time = vec![0.0f64; times.len()];
    for (i, &t) in times.iter().enumerate() {
        let (ya, yb) = (
            &ra[i * channels..(i + 1) * channels],
            &rb[i * channels..(i + 1) * channels],
        );
        let mut at = 0;
        for (k, track) in reference.tracks().iter().enumerate() {
            let kind = track.data.kind();
            let dim = kind.dim();
            let (a, b) = (&ya[at..at + dim], &yb[at..at + dim]);
            let (e, limit) = if kind == TrackKind::Quat {
                (rotation_angle_degrees(a, b), rotation_degrees)
            } else {
                (error(Norm::MaxAbs, &lanes(a), &lanes(b), dim), tolerance)
            };
            worst.take(e, e / limit, &track.name, t);
            each[k] = each[k].max(e / limit);
            at_time[i] = at_time[i].max(e / limit);
            at += dim;
        }
    }
    Measured {
        worst,
        each,
        at_time,
    }
}

/// `2 acos(|q . q'|)` in degrees, for quaternions as `[x, y, z, w]`
/// (normalized here).
pub fn rotation_angle_degrees(a: &[f32], b: &[f32]) -> f64 {
    // acos is ill-conditioned near 1: the fitter's half-angle sine instead.
    let sin_half = error(Norm::Rotation, &lanes(a), &lanes(b), 4);
    2.0 * sin_half.min(1.0).asin().to_degrees()
}

/// Up to 4 components in f64, zero-padded.
fn lanes(v: &[f32]) -> [f64; 4] {
    std::array::from_fn(|c| v.get(c).map_or(0.0, |x| f64::from(*x)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_turn_is_90_degrees() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let d = rotation_angle_degrees(&[0.0, 0.0, 0.0, 1.0], &[0.0, 0.0, h, h]);
        assert!((d - 90.0).abs() < 1e-5, "{d}");
        assert!(rotation_angle_degrees(&[0.0, 0.0, 0.0, 1.0], &[0.0, 0.0, 0.0, -1.0]) < 1e-6);
    }

    #[test]
    fn shell_points_see_rotation_at_the_radius() {
        let a = DAffine3::IDENTITY;
        let b = DAffine3::from_rotation_z(0.001);
        let e = point_error(&a, &b, 2.0);
        // chord of 0.001 rad at radius 2
        assert!((e - 2.0 * 2.0 * (0.0005f64).sin()).abs() < 1e-6, "{e}");
    }
}
