//! Instances: one playing copy of a clip each, sampled into the caller's
//! float row without allocating.

use crate::clip::TcbClip;
use crate::error::{Failure, Result, TcbStatus, guard, guard_value};
use crate::layout;
use crate::ptr;
use crate::rig::TcbRig;
use tcb_runtime::{BlendMask, Instance, Playback};

/// `tcb_instance_new*` flag: sample velocities (d/dt of every channel) as
/// well as values, for `tcb_instance_sample_with_velocities` (about twice
/// the work per sample).
pub const TCB_INSTANCE_VELOCITIES: u32 = 1;

/// How an instance maps the time it is given onto the clip's keys
/// (`tcb_instance_set_playback`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TcbPlayback {
    /// The clip's own time: outside its keys its `pre`/`post` modes apply.
    Clip = 0,
    /// Over and over from the first key to the last.
    Loop = 1,
    /// Held at the first key before it and at the last after it.
    Clamp = 2,
    /// Forwards to the last key, backwards to the first, and so on.
    PingPong = 3,
}

/// One playing copy of a clip: its cursors and its last sampled pose. Per
/// character; not to be used from two threads at once (distinct instances
/// may be sampled on distinct threads). Keeps its clip (and rig) alive.
pub struct TcbInstance {
    pub(crate) inst: Instance,
    /// Per track of its pose: 1 where its clip animates it, 0 where it
    /// keeps the rig's rest value (`tcb_blend_covered`); made once here.
    pub(crate) coverage: BlendMask,
}

fn flags_ok(flags: u32) -> Result<bool> {
    if flags & !TCB_INSTANCE_VELOCITIES != 0 {
        return Err(Failure::invalid(format!(
            "unknown instance flags {:#x}",
            flags & !TCB_INSTANCE_VELOCITIES
        )));
    }
    Ok(flags & TCB_INSTANCE_VELOCITIES != 0)
}

fn with_velocities(inst: Instance, on: bool) -> TcbInstance {
    let inst = if on { inst.with_velocities() } else { inst };
    let coverage = inst.coverage_mask();
    TcbInstance { inst, coverage }
}

/// A new instance of `clip`, playing in `TCB_PLAYBACK_CLIP` mode at
/// speed 1. Its rows are the clip's (`tcb_clip_channel_count` floats, tracks in
/// file order). `flags` is 0 or `TCB_INSTANCE_VELOCITIES`. On success
/// `*out` is a new instance, to be freed with `tcb_instance_free`.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_new(
    clip: *const TcbClip,
    flags: u32,
    out: *mut *mut TcbInstance,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let clip = unsafe { ptr::get(clip, "clip")? };
        let velocities = flags_ok(flags)?;
        let inst = with_velocities(Instance::new(clip.clip.clone()), velocities);
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, inst) };
        Ok(())
    })
}

/// A new instance of `clip` whose rows and pose are in `rig`'s layout
/// (`tcb_rig_channel_count` floats, tracks in rig order; tracks the clip
/// lacks keep the rig's rest values), so that instances of different clips
/// of one rig blend. `TCB_STATUS_MISMATCH` if the clip has a track the rig
/// lacks or of another kind. `flags` as `tcb_instance_new`.
///
/// # Safety
///
/// `clip` and `rig` are NULL or live handles; `out` is NULL or valid for
/// writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_new_with_rig(
    clip: *const TcbClip,
    rig: *const TcbRig,
    flags: u32,
    out: *mut *mut TcbInstance,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or live handles, as the caller promises.
        let (clip, rig) = unsafe { (ptr::get(clip, "clip")?, ptr::get(rig, "rig")?) };
        let velocities = flags_ok(flags)?;
        let inst = Instance::with_rig(clip.clip.clone(), &rig.rig)
            .map_err(|e| Failure::new(TcbStatus::Mismatch, e.to_string()))?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, with_velocities(inst, velocities)) };
        Ok(())
    })
}

/// Free an instance (NULL is ignored).
///
/// # Safety
///
/// `instance` is NULL or an instance from `tcb_instance_new*` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_free(instance: *mut TcbInstance) {
    guard(|| {
        // SAFETY: NULL or a live instance, freed once, as the caller promises.
        unsafe { ptr::free(instance) };
        Ok(())
    });
}

/// Play in `mode` (a `TcbPlayback` value) at `speed` (1 the clip's own
/// speed, 2 twice as fast, negative backwards): `tcb_instance_sample(t)`
/// then samples the clip where `mode` maps `speed * t` over its keys, and
/// velocities are scaled to match. An unknown mode or a NaN or infinite
/// speed is `TCB_STATUS_INVALID_ARGUMENT`, and nothing changes.
///
/// # Safety
///
/// `instance` is NULL or a live instance used by no other thread during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_set_playback(
    instance: *mut TcbInstance,
    mode: u32,
    speed: f64,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live instance used by no one else, as the caller promises.
        let inst = unsafe { ptr::get_mut(instance, "instance")? };
        let mode = match mode {
            0 => Playback::Clip,
            1 => Playback::Loop,
            2 => Playback::Clamp,
            3 => Playback::PingPong,
            m => return Err(Failure::invalid(format!("unknown playback mode {m}"))),
        };
        (inst.inst.set_playback(mode, speed)).map_err(|e| Failure::invalid(e.to_string()))
    })
}

/// Floats in one row of this instance: its rig's channel count if it has
/// one, else its clip's (0 if `instance` is NULL).
///
/// # Safety
///
/// `instance` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_channel_count(instance: *const TcbInstance) -> usize {
    guard_value(0, || {
        // SAFETY: NULL or a live instance, as the caller promises.
        let inst = unsafe { ptr::get(instance, "instance")? };
        Ok(layout::channel_count(inst.inst.pose().layout()))
    })
}

fn length_error(what: &str, given: usize, want: usize) -> Failure {
    Failure::new(
        TcbStatus::BufferLength,
        format!("{what} has {given} floats; this instance's rows have {want}"),
    )
}

/// Sample every track at `time` (seconds, any value: outside the keys the
/// playback mode and the clip's `pre`/`post` apply; NaN gives the first
/// key's values) and write the row into `out`: every track's components in
/// track order (the clip's file order, or the rig's order with a rig),
/// components consecutive (`x y z` for a vec3, `x y z w` for a rotation,
/// one float for a scalar); `tcb_*_track_info` gives each track's offset.
/// `len` must be exactly `tcb_instance_channel_count(instance)`, else
/// `TCB_STATUS_BUFFER_LENGTH` and nothing is sampled or written. Allocates
/// nothing. The sample is also kept as the instance's pose (for
/// `tcb_blend` and `tcb_skeleton_model_matrices`).
///
/// # Safety
///
/// `instance` is NULL or a live instance used by no other thread during the
/// call; `out` is NULL or valid for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_sample(
    instance: *mut TcbInstance,
    time: f64,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live instance used by no one else, as the caller promises.
        let inst = unsafe { ptr::get_mut(instance, "instance")? };
        // SAFETY: NULL or `len` writable floats, as the caller promises.
        let out = unsafe { ptr::slice_mut(out, len, "out")? };
        (inst.inst.sample_to(time, out)).map_err(|e| length_error("out", e.given, e.want))
    })
}

/// Sample at `time` (as `tcb_instance_sample`) without writing a row: the
/// pose is kept in the instance, for `tcb_blend` and
/// `tcb_skeleton_model_matrices`. Allocates nothing.
///
/// # Safety
///
/// `instance` is NULL or a live instance used by no other thread during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_update(instance: *mut TcbInstance, time: f64) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live instance used by no one else, as the caller promises.
        let inst = unsafe { ptr::get_mut(instance, "instance")? };
        inst.inst.sample(time);
        Ok(())
    })
}

/// Sample at `time` (as `tcb_instance_sample`) and write the values into
/// `values` and their d/dt (per second of the time given) into
/// `velocities`, both rows of `tcb_instance_channel_count` floats in the
/// same layout. The instance must have been made with
/// `TCB_INSTANCE_VELOCITIES` (else `TCB_STATUS_INVALID_ARGUMENT`). Allocates nothing.
///
/// # Safety
///
/// `instance` is NULL or a live instance used by no other thread during the
/// call; `values` and `velocities` are NULL or valid for `values_len` and
/// `velocities_len` floats of writes, and do not overlap.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_instance_sample_with_velocities(
    instance: *mut TcbInstance,
    time: f64,
    values: *mut f32,
    values_len: usize,
    velocities: *mut f32,
    velocities_len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live instance used by no one else, as the caller promises.
        let inst = unsafe { ptr::get_mut(instance, "instance")? };
        for (p, len, what) in [
            (values, values_len, "values"),
            (velocities, velocities_len, "velocities"),
        ] {
            if p.is_null() && len > 0 {
                return Err(Failure::new(
                    TcbStatus::NullPointer,
                    format!("{what} is NULL"),
                ));
            }
        }
        let (a, b) = (values as usize, velocities as usize);
        let bytes = |len: usize| len.saturating_mul(size_of::<f32>());
        if values_len > 0
            && velocities_len > 0
            && a < b.saturating_add(bytes(velocities_len))
            && b < a.saturating_add(bytes(values_len))
        {
            return Err(Failure::invalid("values and velocities overlap"));
        }
        // SAFETY: NULL or writable floats, checked not to overlap above.
        let (values, velocities) = unsafe {
            (
                ptr::slice_mut(values, values_len, "values")?,
                ptr::slice_mut(velocities, velocities_len, "velocities")?,
            )
        };
        if !inst.inst.pose().has_velocities() {
            return Err(Failure::invalid(
                "the instance samples no velocities (make it with TCB_INSTANCE_VELOCITIES)",
            ));
        }
        let want = layout::channel_count(inst.inst.pose().layout());
        if values.len() != want {
            return Err(length_error("values", values.len(), want));
        }
        if velocities.len() != want {
            return Err(length_error("velocities", velocities.len(), want));
        }
        inst.inst.sample(time).write_row(values, Some(velocities));
        Ok(())
    })
}
