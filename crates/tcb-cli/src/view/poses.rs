//! What `tcb view` plays: the frame times, and each joint's model-space
//! position at every frame, from the runtime (`SkeletonBinding`), so that
//! the page draws them and computes nothing.

use serde::Serialize;
use std::sync::Arc;
use tcb_core::SourceClip;
use tcb_core::sample_times::{frame_count, frame_times};
use tcb_core::skeleton::Skeleton;

/// Most frames one page holds.
pub(crate) const MAX_FRAMES: u64 = 200_000;

/// Most joint positions (frames x joints) one page holds: about 10 bytes
/// of JSON each.
pub(crate) const MAX_POSITIONS: u64 = 30_000_000;

/// Frame rate of a clip whose keys are not on one even grid.
pub(crate) const DEFAULT_FPS: f64 = 60.0;

/// The times a page plays.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Frames {
    /// Frame times, seconds, increasing.
    pub times: Vec<f64>,
    /// Frames per second.
    pub fps: f64,
    /// Where the rate came from, for the page and stderr.
    pub source: &'static str,
}

/// The frames of `clip` at `fps`, or by default at the clip's own rate:
/// its key times when they are one even grid (motion capture, baked
/// animation), else [`DEFAULT_FPS`] over its keys' range.
pub(crate) fn frames(clip: &SourceClip, fps: Option<f64>) -> Result<Frames, String> {
    let (first, last) = clip.time_range().ok_or("the clip has no tracks to view")?;
    if let Some(fps) = fps
        && !(fps > 0.0 && fps.is_finite())
    {
        return Err(format!("--fps must be a positive number, got {fps}"));
    }
    let keys = clip.key_times();
    if fps.is_none()
        && let Some(rate) = even_rate(&keys)
    {
        return Ok(Frames {
            times: keys,
            fps: rate,
            source: "the clip's key times",
        });
    }
    let (fps, source) = match fps {
        Some(fps) => (fps, "--fps"),
        None => (DEFAULT_FPS, "the default: keys not evenly spaced"),
    };
    match frame_count(first, last, fps) {
        Some(n) if n <= MAX_FRAMES => Ok(Frames {
            times: frame_times(first, last, fps).collect(),
            fps,
            source,
        }),
        _ => Err(format!(
            "--fps {fps} over {first} to {last} s asks for more than {MAX_FRAMES} frames"
        )),
    }
}

/// `1 / step` when `keys` (at least two) are evenly spaced, within a
/// thousandth of the step.
fn even_rate(keys: &[f64]) -> Option<f64> {
    let (&first, &last) = (keys.first()?, keys.last()?);
    let n = keys.len();
    if n < 2 || n as u64 > MAX_FRAMES {
        return None;
    }
    let step = (last - first) / (n - 1) as f64;
    let even = step > 0.0
        && keys
            .iter()
            .enumerate()
            .all(|(i, &t)| (t - (first + i as f64 * step)).abs() <= 1e-3 * step);
    even.then(|| 1.0 / step)
}

/// A skeleton's joints and their positions at every frame, as the page
/// reads them.
#[derive(Serialize)]
pub(crate) struct Figure {
    /// Joint names, in the skeleton's order.
    pub names: Vec<String>,
    /// Each joint's parent (an index into `names`), or `null` for a root.
    pub parents: Vec<Option<usize>>,
    /// The up axis: 1 (Y) or 2 (Z), the one the rest pose spreads along
    /// more (`tcb_plot::ground_plane`).
    pub up: usize,
    /// Model-space positions: frame after frame, joint after joint, x y z.
    pub positions: Vec<f32>,
    /// The joints with a rotation track and no child, whose rotation their
    /// position cannot show: the page draws them a tip along their +Y
    /// (glTF's bone axis).
    pub tips: Vec<usize>,
    /// The tips' model-space rotations: frame after frame, tip after tip,
    /// x y z w.
    pub tip_rotations: Vec<f32>,
}

/// Each joint's model-space position at each of `times`: `runtime` (`clip`
/// compiled, or the packed stream whose reference it is) sampled by an
/// instance and bound to `skeleton` ([`tcb_runtime::SkeletonBinding`]).
pub(crate) fn figure(
    clip: &SourceClip,
    runtime: Arc<tcb_runtime::Clip>,
    skeleton: &Skeleton,
    times: &[f64],
) -> Result<Figure, String> {
    let joints = skeleton.joints().len();
    let count = times.len() as u64 * joints as u64;
    if count > MAX_POSITIONS {
        return Err(format!(
            "{} frames of {joints} joints are more than the {MAX_POSITIONS} positions a page holds; lower --fps",
            times.len()
        ));
    }
    let binding = tcb_runtime::SkeletonBinding::new(skeleton.clone(), &runtime);
    let mut instance = tcb_runtime::Instance::new(runtime);
    let mut local = vec![tcb_core::skeleton::Transform::IDENTITY; joints];
    let mut model = vec![glam::Affine3A::IDENTITY; joints];
    let rotated = |name: &str| {
        let track = format!("{name}.rotation");
        clip.tracks()
            .iter()
            .any(|t| t.name == track && t.data.kind() == tcb_core::TrackKind::Quat)
    };
    let tips: Vec<usize> = skeleton
        .joints()
        .iter()
        .enumerate()
        .filter(|(i, j)| {
            !skeleton.joints().iter().any(|c| c.parent == Some(*i)) && rotated(&j.name)
        })
        .map(|(i, _)| i)
        .collect();
    let mut positions = Vec::with_capacity(count as usize * 3);
    let mut tip_rotations = Vec::with_capacity(times.len() * tips.len() * 4);
    for &t in times {
        binding
            .model_transforms(instance.sample(t), &mut local, &mut model)
            .map_err(|e| e.to_string())?;
        for m in &model {
            positions.extend_from_slice(&m.translation.to_array());
        }
        for &j in &tips {
            let (_, rotation, _) = model[j].to_scale_rotation_translation();
            tip_rotations.extend_from_slice(&rotation.to_array());
        }
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        let (frame, joint) = (i / 3 / joints, i / 3 % joints);
        return Err(format!(
            "joint '{}' is not at a finite position at {} s",
            skeleton.joints()[joint].name,
            times[frame]
        ));
    }
    let up = if tcb_plot::ground_plane(skeleton) == [0, 1] {
        2
    } else {
        1
    };
    Ok(Figure {
        names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
        parents: skeleton.joints().iter().map(|j| j.parent).collect(),
        up,
        positions,
        tips,
        tip_rotations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(tracks: &str) -> SourceClip {
        let text = format!(r#"{{"format": "tcb-clip/1", "tracks": [{tracks}]}}"#);
        tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap()
    }

    #[test]
    fn even_keys_are_the_frames() {
        let c = clip(
            r#"{"name": "x", "kind": "scalar", "times": [0, 0.25, 0.5, 0.75], "values": [0, 1, 0, 1]}"#,
        );
        let f = frames(&c, None).unwrap();
        assert_eq!(f.times, [0.0, 0.25, 0.5, 0.75]);
        assert_eq!(f.fps, 4.0);
        assert_eq!(f.source, "the clip's key times");
    }

    #[test]
    fn uneven_keys_play_at_the_default_rate_and_fps_overrides() {
        let c =
            clip(r#"{"name": "x", "kind": "scalar", "times": [0, 0.1, 1], "values": [0, 1, 0]}"#);
        let f = frames(&c, None).unwrap();
        assert_eq!((f.fps, f.times.len()), (DEFAULT_FPS, 61));
        let f = frames(&c, Some(4.0)).unwrap();
        assert_eq!(f.times, [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert!(frames(&c, Some(0.0)).unwrap_err().contains("--fps"));
        assert!(frames(&c, Some(1e300)).unwrap_err().contains("more than"));
    }
}
