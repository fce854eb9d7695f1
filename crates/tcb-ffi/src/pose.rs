//! Poses the caller owns: the output of a blend, read as a row.

use crate::clip::TcbClip;
use crate::error::{Failure, Result, TcbStatus, guard, guard_value};
use crate::instance::TcbInstance;
use crate::layout;
use crate::ptr;
use crate::rig::TcbRig;
use tcb_runtime::{Pose, blend};

/// `tcb_pose_new_*` flag: the pose carries velocities, so that a blend of
/// instances that sample velocities blends them too.
pub const TCB_POSE_VELOCITIES: u32 = 1;

/// Layers `tcb_blend` takes without allocating; more are blended too, with
/// one allocation per call.
pub const TCB_BLEND_STACK_LAYERS: usize = 16;

/// A pose owned by the caller, in a clip's or a rig's layout: where
/// `tcb_blend` writes. Not to be used from two threads at once.
pub struct TcbPose {
    pub(crate) pose: Pose,
}

fn flags_ok(flags: u32) -> Result<bool> {
    if flags & !TCB_POSE_VELOCITIES != 0 {
        return Err(Failure::invalid(format!(
            "unknown pose flags {:#x}",
            flags & !TCB_POSE_VELOCITIES
        )));
    }
    Ok(flags & TCB_POSE_VELOCITIES != 0)
}

fn give(out: *mut *mut TcbPose, pose: Pose, velocities: bool) {
    let pose = if velocities {
        pose.with_velocities()
    } else {
        pose
    };
    // SAFETY: every caller checked `out` with `clear_out` first.
    unsafe { ptr::give(out, TcbPose { pose }) };
}

/// A pose in `rig`'s layout holding the rig's rest values, to blend
/// instances made with `rig` into. `flags` is 0 or `TCB_POSE_VELOCITIES`.
/// On success `*out` is a new pose, to be freed with `tcb_pose_free`.
///
/// # Safety
///
/// `rig` is NULL or a live rig; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_new_for_rig(
    rig: *const TcbRig,
    flags: u32,
    out: *mut *mut TcbPose,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or a live rig, as the caller promises.
        let rig = unsafe { ptr::get(rig, "rig")? };
        let velocities = flags_ok(flags)?;
        give(out, rig.rig.rest_pose(), velocities);
        Ok(())
    })
}

/// A pose in `clip`'s own layout (zeros), to blend instances of that clip
/// made without a rig into. `flags` as `tcb_pose_new_for_rig`.
///
/// # Safety
///
/// `clip` is NULL or a live clip; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_new_for_clip(
    clip: *const TcbClip,
    flags: u32,
    out: *mut *mut TcbPose,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or a live clip, as the caller promises.
        let clip = unsafe { ptr::get(clip, "clip")? };
        let velocities = flags_ok(flags)?;
        give(out, Pose::new(&clip.clip), velocities);
        Ok(())
    })
}

/// Free a pose (NULL is ignored).
///
/// # Safety
///
/// `pose` is NULL or a pose from `tcb_pose_new_*` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_free(pose: *mut TcbPose) {
    guard(|| {
        // SAFETY: NULL or a live pose, freed once, as the caller promises.
        unsafe { ptr::free(pose) };
        Ok(())
    });
}

/// Floats in a row of this pose's layout (0 if `pose` is NULL).
///
/// # Safety
///
/// `pose` is NULL or a live pose.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_channel_count(pose: *const TcbPose) -> usize {
    guard_value(0, || {
        // SAFETY: NULL or a live pose, as the caller promises.
        let pose = unsafe { ptr::get(pose, "pose")? };
        Ok(layout::channel_count(pose.pose.layout()))
    })
}

/// Write the pose's values as a row into `out` (the layout of
/// `tcb_instance_sample`; `len` must be `tcb_pose_channel_count(pose)`).
/// Allocates nothing.
///
/// # Safety
///
/// `pose` is NULL or a live pose; `out` is NULL or valid for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_read(
    pose: *const TcbPose,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    read(pose, out, len, false)
}

/// Write the pose's velocities as a row into `out`, as `tcb_pose_read`
/// writes its values. `TCB_STATUS_INVALID_ARGUMENT` for a pose made
/// without `TCB_POSE_VELOCITIES`.
///
/// # Safety
///
/// `pose` is NULL or a live pose; `out` is NULL or valid for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_pose_read_velocities(
    pose: *const TcbPose,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    read(pose, out, len, true)
}

fn read(pose: *const TcbPose, out: *mut f32, len: usize, velocities: bool) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live pose, as the public callers' callers promise.
        let pose = unsafe { ptr::get(pose, "pose")? };
        // SAFETY: NULL or `len` writable floats, as they promise.
        let out = unsafe { ptr::slice_mut(out, len, "out")? };
        let want = layout::channel_count(pose.pose.layout());
        if out.len() != want {
            return Err(Failure::new(
                TcbStatus::BufferLength,
                format!("out has {} floats; this pose's rows have {want}", out.len()),
            ));
        }
        if velocities {
            if !pose.pose.has_velocities() {
                return Err(Failure::invalid(
                    "the pose has no velocities (make it with TCB_POSE_VELOCITIES)",
                ));
            }
            // The values go to a scratch of nothing: write_row fills
            // `values` first, so give it an empty one.
            pose.pose.write_row(&mut [], Some(out));
        } else {
            pose.pose.write_row(out, None);
        }
        Ok(())
    })
}

/// Blend the last sampled poses of `count` instances into `out`: vectors
/// the weighted mean, rotations normalized weighted sums with each
/// quaternion turned to the first layer's hemisphere (nlerp). Weights need
/// not sum to 1 (they are normalized); where they sum to almost 0 the first
/// layer is kept. Velocities are blended when `out` and every layer carry
/// them. Every instance must have `out`'s layout (instances of one rig and
/// a pose of that rig, or instances of one clip without a rig and a pose
/// of that clip): otherwise `TCB_STATUS_MISMATCH` and nothing is written.
/// `count` 0 leaves `out` as it is. Allocates nothing for up to
/// `TCB_BLEND_STACK_LAYERS` layers.
///
/// # Safety
///
/// `out` is NULL or a live pose used by no other thread; `layers` is NULL
/// or points to `count` pointers, each NULL or a live instance not sampled
/// during the call; `weights` is NULL or points to `count` floats (any
/// pointers when `count` is 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_blend(
    out: *mut TcbPose,
    layers: *const *const TcbInstance,
    weights: *const f32,
    count: usize,
) -> TcbStatus {
    // SAFETY: as the caller promises.
    unsafe { blend_layers(out, layers, weights, count, false) }
}

/// `tcb_blend`, with each layer weighing only on the tracks its clip
/// animates: for instances made with a rig, the tracks their clip lacks
/// (which hold the rig's rest values) do not pull the blend towards the
/// rest pose. A track no layer animates keeps the first layer's value.
/// (Without a rig every track is animated, and this is `tcb_blend`.)
/// Allocates nothing for up to `TCB_BLEND_STACK_LAYERS` layers.
///
/// # Safety
///
/// As `tcb_blend`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_blend_covered(
    out: *mut TcbPose,
    layers: *const *const TcbInstance,
    weights: *const f32,
    count: usize,
) -> TcbStatus {
    // SAFETY: as the caller promises.
    unsafe { blend_layers(out, layers, weights, count, true) }
}

/// `tcb_blend` and `tcb_blend_covered`.
///
/// # Safety
///
/// As `tcb_blend`.
unsafe fn blend_layers(
    out: *mut TcbPose,
    layers: *const *const TcbInstance,
    weights: *const f32,
    count: usize,
    covered: bool,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live pose used by no one else, as the caller promises.
        let out = unsafe { ptr::get_mut(out, "out")? };
        // SAFETY: NULL or `count` readable pointers and floats, as the caller promises.
        let (layers, weights) = unsafe {
            (
                ptr::slice(layers, count, "layers")?,
                ptr::slice(weights, count, "weights")?,
            )
        };
        if let Some(i) = layers.iter().position(|l| l.is_null()) {
            return Err(Failure::new(
                TcbStatus::NullPointer,
                format!("layers[{i}] is NULL"),
            ));
        }
        let Some(&first) = layers.first() else {
            return Ok(());
        };
        // SAFETY: checked non-NULL above; live, as the caller promises.
        let first = unsafe { &*first };
        // SAFETY: checked non-NULL above; live, as the caller promises.
        let inst = |i: usize| unsafe { &*layers[i] };
        let layer = |i: usize| (inst(i).inst.pose(), weights[i]);
        let mismatch = |e: blend::BlendError| Failure::new(TcbStatus::Mismatch, e.to_string());
        if count <= TCB_BLEND_STACK_LAYERS {
            let mut stack = [(first.inst.pose(), 0.0); TCB_BLEND_STACK_LAYERS];
            let mut masks = [&first.coverage; TCB_BLEND_STACK_LAYERS];
            for i in 0..count {
                stack[i] = layer(i);
                masks[i] = &inst(i).coverage;
            }
            let masks = covered.then_some(&masks[..count]);
            blend(&mut out.pose, &stack[..count], masks).map_err(mismatch)
        } else {
            let all: Vec<_> = (0..count).map(layer).collect();
            let masks: Vec<_> = (0..count).map(|i| &inst(i).coverage).collect();
            let masks = covered.then_some(&masks[..]);
            blend(&mut out.pose, &all, masks).map_err(mismatch)
        }
    })
}

/// Add an additive layer to `pose` in place: `pose` plus `weight` times
/// (`layer`'s last sample minus `reference`'s), per track (rotations: the
/// rotation from the reference to the layer, scaled by `weight`, composed
/// onto the pose's; the formulas are `tcb_runtime::blend`'s module docs). All three must have one layout, else
/// `TCB_STATUS_MISMATCH` and nothing is written. Allocates nothing.
///
/// # Safety
///
/// `pose` is NULL or a live pose used by no other thread; `layer` and
/// `reference` are NULL or live instances not sampled during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_blend_add(
    pose: *mut TcbPose,
    layer: *const TcbInstance,
    reference: *const TcbInstance,
    weight: f32,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or live handles, the pose used by no one else, as the caller promises.
        let (pose, layer, reference) = unsafe {
            (
                ptr::get_mut(pose, "pose")?,
                ptr::get(layer, "layer")?,
                ptr::get(reference, "reference")?,
            )
        };
        blend::add(
            &mut pose.pose,
            layer.inst.pose(),
            reference.inst.pose(),
            weight,
            None,
        )
        .map_err(|e| Failure::new(TcbStatus::Mismatch, e.to_string()))
    })
}
