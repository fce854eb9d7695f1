//! Rigs: one fixed track list, so that instances of different clips of a
//! character sample into rows (and poses) of one layout and can be blended.

use crate::clip::TcbClip;
use crate::error::{Failure, Result, TcbStatus, guard, guard_value};
use crate::layout::{self, TcbTrackInfo};
use crate::ptr;
use std::ffi::c_char;
use std::sync::Arc;
use tcb_core::TrackKind;
use tcb_runtime::{Rig, RigTrack};

/// A rig: a fixed list of tracks with rest values. Instances made with it
/// (`tcb_instance_new_with_rig`) write rows in the rig's track order, tracks
/// their clip lacks keeping the rest values. Immutable; may be used from
/// any thread, and freed before the instances, poses and skeletons made with it.
pub struct TcbRig {
    pub(crate) rig: Arc<Rig>,
}

fn rig_error(e: tcb_runtime::RigError) -> Failure {
    Failure::new(TcbStatus::Mismatch, e.to_string())
}

/// A rig of the joints of `clip`'s skeleton: per joint a translation
/// (vec3), a rotation (quat) and a scale (vec3) track, named
/// `<joint>.translation`, `<joint>.rotation`, `<joint>.scale`, with the
/// joint's rest transform as rest values. `TCB_STATUS_NOT_FOUND` if the
/// clip has no skeleton. On success `*out` is a new rig, to be freed with
/// `tcb_rig_free`.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_from_skeleton(
    clip: *const TcbClip,
    out: *mut *mut TcbRig,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let clip = unsafe { ptr::get(clip, "clip")? };
        let skeleton = clip
            .skeleton
            .as_ref()
            .ok_or_else(|| Failure::new(TcbStatus::NotFound, "the clip has no skeleton"))?;
        let rig = Rig::from_skeleton(skeleton).map_err(rig_error)?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, TcbRig { rig: Arc::new(rig) }) };
        Ok(())
    })
}

/// A rig of `clip`'s tracks, in the clip's order, resting at zero
/// (rotations at the identity), as `Rig::from_clip` makes one. On success `*out` is a new rig, to be freed
/// with `tcb_rig_free`.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_from_clip(
    clip: *const TcbClip,
    out: *mut *mut TcbRig,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let clip = unsafe { ptr::get(clip, "clip")? };
        // `Rig::from_clip` wants the source clip, which is not kept (a
        // `.tcbc` has none): the same tracks from the compiled clip's layout.
        let tracks = (clip.clip.tracks().iter())
            .map(|t| RigTrack {
                name: t.name().to_string(),
                kind: t.kind(),
                rest: if t.kind() == TrackKind::Quat {
                    [0.0, 0.0, 0.0, 1.0]
                } else {
                    [0.0; 4]
                },
            })
            .collect();
        let rig = Rig::new(tracks).map_err(rig_error)?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, TcbRig { rig: Arc::new(rig) }) };
        Ok(())
    })
}

/// Free a rig (NULL is ignored). Instances, poses and skeletons made with
/// it stay valid.
///
/// # Safety
///
/// `rig` is NULL or a rig from `tcb_rig_from_*` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_free(rig: *mut TcbRig) {
    guard(|| {
        // SAFETY: NULL or a live rig handle, freed once, as the caller promises.
        unsafe { ptr::free(rig) };
        Ok(())
    });
}

/// The rig, or a failure if `rig` is NULL.
///
/// # Safety
///
/// `rig` is NULL or a live rig handle.
unsafe fn get<'a>(rig: *const TcbRig) -> Result<&'a TcbRig> {
    // SAFETY: as the caller promises.
    unsafe { ptr::get(rig, "rig") }
}

/// Number of tracks of the rig (0 if `rig` is NULL).
///
/// # Safety
///
/// `rig` is NULL or a live rig handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_track_count(rig: *const TcbRig) -> usize {
    // SAFETY: NULL or a live rig handle, as the caller promises.
    guard_value(0, || Ok(unsafe { get(rig)? }.rig.tracks().len()))
}

/// Floats in one sampled row of the rig's layout (the length
/// `tcb_instance_sample` wants from an instance with this rig); 0 if `rig`
/// is NULL.
///
/// # Safety
///
/// `rig` is NULL or a live rig handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_channel_count(rig: *const TcbRig) -> usize {
    // SAFETY: NULL or a live rig handle, as the caller promises.
    guard_value(0, || {
        Ok(layout::channel_count(unsafe { get(rig)? }.rig.layout()))
    })
}

/// Where track `index` (in rig order) lives in a row of the rig's layout.
///
/// # Safety
///
/// `rig` is NULL or a live rig handle; `info` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_track_info(
    rig: *const TcbRig,
    index: usize,
    info: *mut TcbTrackInfo,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live rig handle, as the caller promises.
        let found = layout::info(unsafe { get(rig)? }.rig.layout(), index)?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(info, found, "info") }
    })
}

/// The rig's track called `name`: its index, kind and place in a row.
/// `TCB_STATUS_NOT_FOUND` if the rig has no such track.
///
/// # Safety
///
/// `rig` is NULL or a live rig handle; `name` is NULL or NUL-terminated;
/// `info` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_find_track(
    rig: *const TcbRig,
    name: *const c_char,
    info: *mut TcbTrackInfo,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live rig handle, as the caller promises.
        let rig = unsafe { get(rig)? };
        // SAFETY: NULL or NUL-terminated, as the caller promises.
        let name = unsafe { ptr::str(name, "name")? };
        let found = layout::find(rig.rig.layout(), name)?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(info, found, "info") }
    })
}

/// Copy the name of the rig's track `index` into `buf`, as
/// `tcb_clip_track_name` does for a clip.
///
/// # Safety
///
/// `rig` is NULL or a live rig handle; `buf` is NULL or valid for
/// `buf_len` bytes of writes; `name_len` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_rig_track_name(
    rig: *const TcbRig,
    index: usize,
    buf: *mut c_char,
    buf_len: usize,
    name_len: *mut usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live rig handle, as the caller promises.
        let name = layout::name(unsafe { get(rig)? }.rig.layout(), index)?;
        // SAFETY: as the caller promises.
        unsafe { ptr::copy_str(name, buf, buf_len, name_len) }
    })
}
