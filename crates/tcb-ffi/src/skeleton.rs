//! Skeletons bound to a layout: model-space joint matrices from a sampled
//! or blended pose, into the caller's floats.

use crate::clip::TcbClip;
use crate::error::{Failure, Result, TcbStatus, guard, guard_value};
use crate::instance::TcbInstance;
use crate::pose::TcbPose;
use crate::ptr;
use crate::rig::TcbRig;
use glam::{Affine3A, Mat4};
use std::ffi::c_char;
use std::sync::Arc;
use tcb_core::skeleton::{Skeleton, Transform};
use tcb_runtime::{Pose, PoseLayout, SkeletonBinding};

/// Floats per joint in `tcb_skeleton_model_matrices`'s output: a 4x4
/// matrix, column-major.
pub const TCB_MATRIX_FLOATS: usize = 16;
/// Floats per joint in `tcb_skeleton_local_transforms`'s output:
/// translation `x y z`, rotation `x y z w`, scale `x y z`.
pub const TCB_TRANSFORM_FLOATS: usize = 10;

/// A joint hierarchy bound to the poses of one layout (a clip's or a
/// rig's): each joint's `<joint>.translation`, `.rotation` and `.scale`
/// tracks found by name; parts no track animates keep the joint's rest
/// transform. Holds its own scratch space, so computing matrices allocates
/// nothing: not to be used from two threads at once (make one per thread).
pub struct TcbSkeleton {
    binding: SkeletonBinding,
    layout: Arc<PoseLayout>,
    local: Vec<Transform>,
    model: Vec<Affine3A>,
}

fn skeleton_of(clip: &TcbClip) -> Result<Skeleton> {
    clip.skeleton.clone().ok_or_else(|| {
        Failure::new(
            TcbStatus::NotFound,
            "the clip has no skeleton (a .tcbc file keeps none: take it from the file it was made from)",
        )
    })
}

fn bound(skeleton: Skeleton, layout: &Arc<PoseLayout>) -> TcbSkeleton {
    let joints = skeleton.joints().len();
    TcbSkeleton {
        binding: SkeletonBinding::for_layout(skeleton, layout),
        layout: layout.clone(),
        local: vec![Transform::IDENTITY; joints],
        model: vec![Affine3A::IDENTITY; joints],
    }
}

/// The skeleton of `skeleton_from`'s file, bound to the poses of `clip`
/// (instances of `clip` made without a rig, poses from
/// `tcb_pose_new_for_clip`). Usually both are the same clip; a `.tcbc`
/// clip, which keeps no skeleton, takes it from the BVH, glTF or clip file
/// it was made from. `TCB_STATUS_NOT_FOUND` if `skeleton_from` has no
/// skeleton. On success `*out` is a new skeleton, to be freed with
/// `tcb_skeleton_free`.
///
/// # Safety
///
/// `skeleton_from` and `clip` are NULL or live clips; `out` is NULL or
/// valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_new(
    skeleton_from: *const TcbClip,
    clip: *const TcbClip,
    out: *mut *mut TcbSkeleton,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or live clips, as the caller promises.
        let (from, clip) = unsafe {
            (
                ptr::get(skeleton_from, "skeleton_from")?,
                ptr::get(clip, "clip")?,
            )
        };
        let skeleton = bound(skeleton_of(from)?, clip.clip.layout());
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, skeleton) };
        Ok(())
    })
}

/// The skeleton of `skeleton_from`'s file, bound to the poses of `rig`
/// (instances made with `rig`, poses from `tcb_pose_new_for_rig`).
/// Otherwise as `tcb_skeleton_new`.
///
/// # Safety
///
/// `skeleton_from` is NULL or a live clip, `rig` NULL or a live rig; `out`
/// is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_new_for_rig(
    skeleton_from: *const TcbClip,
    rig: *const TcbRig,
    out: *mut *mut TcbSkeleton,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: NULL or live handles, as the caller promises.
        let (from, rig) = unsafe {
            (
                ptr::get(skeleton_from, "skeleton_from")?,
                ptr::get(rig, "rig")?,
            )
        };
        let skeleton = bound(skeleton_of(from)?, rig.rig.layout());
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, skeleton) };
        Ok(())
    })
}

/// Free a skeleton (NULL is ignored).
///
/// # Safety
///
/// `skeleton` is NULL or a skeleton from `tcb_skeleton_new*` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_free(skeleton: *mut TcbSkeleton) {
    guard(|| {
        // SAFETY: NULL or a live skeleton, freed once, as the caller promises.
        unsafe { ptr::free(skeleton) };
        Ok(())
    });
}

/// The skeleton, or a failure if `skeleton` is NULL.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton.
unsafe fn get<'a>(skeleton: *const TcbSkeleton) -> Result<&'a TcbSkeleton> {
    // SAFETY: as the caller promises.
    unsafe { ptr::get(skeleton, "skeleton") }
}

/// Number of joints (0 if `skeleton` is NULL). Joints are ordered parents
/// first; a BVH file's End Sites are leaf joints `<parent>_end` after its joints.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_joint_count(skeleton: *const TcbSkeleton) -> usize {
    // SAFETY: NULL or a live skeleton, as the caller promises.
    guard_value(0, || {
        Ok(unsafe { get(skeleton)? }.binding.skeleton().joints().len())
    })
}

fn joint(s: &TcbSkeleton, index: usize) -> Result<&tcb_core::skeleton::Joint> {
    let joints = s.binding.skeleton().joints();
    joints.get(index).ok_or_else(|| {
        Failure::invalid(format!(
            "joint index {index} is past the last joint ({} joints)",
            joints.len()
        ))
    })
}

/// Copy the name of joint `index` into `buf`, as `tcb_clip_track_name`
/// does for a track.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton; `buf` is NULL or valid for
/// `buf_len` bytes of writes; `name_len` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_joint_name(
    skeleton: *const TcbSkeleton,
    index: usize,
    buf: *mut c_char,
    buf_len: usize,
    name_len: *mut usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live skeleton, as the caller promises.
        let j = joint(unsafe { get(skeleton)? }, index)?;
        // SAFETY: as the caller promises.
        unsafe { ptr::copy_str(&j.name, buf, buf_len, name_len) }
    })
}

/// The parent of joint `index` into `*parent`: a smaller index, or -1 for a root.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton; `parent` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_joint_parent(
    skeleton: *const TcbSkeleton,
    index: usize,
    parent: *mut i64,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live skeleton, as the caller promises.
        let j = joint(unsafe { get(skeleton)? }, index)?;
        let p = j
            .parent
            .map_or(-1, |p| i64::try_from(p).unwrap_or(i64::MAX));
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(parent, p, "parent") }
    })
}

/// The index of the joint called `name` into `*index`
/// (`TCB_STATUS_NOT_FOUND` if there is none).
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton; `name` is NULL or NUL-terminated;
/// `index` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_find_joint(
    skeleton: *const TcbSkeleton,
    name: *const c_char,
    index: *mut usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live skeleton, NULL or NUL-terminated, as the caller promises.
        let (s, name) = unsafe { (get(skeleton)?, ptr::str(name, "name")?) };
        let i = (s.binding.skeleton().joint(name))
            .ok_or_else(|| Failure::new(TcbStatus::NotFound, format!("no joint {name:?}")))?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(index, i, "index") }
    })
}

/// What a skeleton writes per joint.
#[derive(Clone, Copy)]
enum Output {
    /// `TCB_MATRIX_FLOATS`: model-space matrices.
    Model,
    /// `TCB_TRANSFORM_FLOATS`: local translation, rotation, scale.
    Local,
}

/// Joint transforms of `pose` into the caller's floats.
fn write(s: &mut TcbSkeleton, pose: &Pose, out: &mut [f32], what: Output) -> Result<()> {
    let per = match what {
        Output::Model => TCB_MATRIX_FLOATS,
        Output::Local => TCB_TRANSFORM_FLOATS,
    };
    let want = per * s.model.len();
    if out.len() != want {
        return Err(Failure::new(
            TcbStatus::BufferLength,
            format!(
                "out has {} floats; {} joints take {want} ({per} each)",
                out.len(),
                s.model.len()
            ),
        ));
    }
    if !Arc::ptr_eq(pose.layout(), &s.layout) && **pose.layout() != *s.layout {
        return Err(Failure::new(
            TcbStatus::Mismatch,
            "the pose is of another layout than the skeleton was bound to \
             (a rig's instances need tcb_skeleton_new_for_rig)",
        ));
    }
    let TcbSkeleton {
        binding,
        local,
        model,
        ..
    } = s;
    // The layout and lengths were checked above; the binding checks them
    // again.
    let bound = |e: tcb_runtime::BindingError| Failure::new(TcbStatus::Mismatch, e.to_string());
    match what {
        Output::Model => {
            binding
                .model_transforms(pose, local, model)
                .map_err(bound)?;
            for (m, o) in model.iter().zip(out.chunks_exact_mut(per)) {
                o.copy_from_slice(&Mat4::from(*m).to_cols_array());
            }
        }
        Output::Local => {
            binding.local_transforms(pose, local).map_err(bound)?;
            for (t, o) in local.iter().zip(out.chunks_exact_mut(per)) {
                o[0..3].copy_from_slice(&t.translation.to_array());
                o[3..7].copy_from_slice(&t.rotation.to_array());
                o[7..10].copy_from_slice(&t.scale.to_array());
            }
        }
    }
    Ok(())
}

/// Write every joint's model-space matrix, from `instance`'s last sample
/// (`tcb_instance_sample` or `tcb_instance_update`), into `out`: per joint
/// in joint order 16 floats, a 4x4 matrix in column-major order (OpenGL's
/// and glam's: floats 12, 13, 14 are the joint's position, the last row
/// is 0 0 0 1), the parent's model matrix times the joint's local
/// translation * rotation * scale. `len` must be 16 times
/// `tcb_skeleton_joint_count`, else `TCB_STATUS_BUFFER_LENGTH`; an
/// instance of another layout than the skeleton's is `TCB_STATUS_MISMATCH`.
/// Nothing is written on failure. Allocates nothing.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton used by no other thread;
/// `instance` is NULL or a live instance not sampled during the call; `out`
/// is NULL or valid for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_model_matrices(
    skeleton: *mut TcbSkeleton,
    instance: *const TcbInstance,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or live handles (the skeleton used by no one else)
        // and `len` writable floats, as the caller promises.
        let (s, inst, out) = unsafe {
            (
                ptr::get_mut(skeleton, "skeleton")?,
                ptr::get(instance, "instance")?,
                ptr::slice_mut(out, len, "out")?,
            )
        };
        write(s, inst.inst.pose(), out, Output::Model)
    })
}

/// `tcb_skeleton_model_matrices` of a pose (a blend's output).
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton used by no other thread; `pose` is
/// NULL or a live pose not written during the call; `out` is NULL or valid
/// for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_model_matrices_pose(
    skeleton: *mut TcbSkeleton,
    pose: *const TcbPose,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or live handles (the skeleton used by no one else)
        // and `len` writable floats, as the caller promises.
        let (s, pose, out) = unsafe {
            (
                ptr::get_mut(skeleton, "skeleton")?,
                ptr::get(pose, "pose")?,
                ptr::slice_mut(out, len, "out")?,
            )
        };
        write(s, &pose.pose, out, Output::Model)
    })
}

/// Write every joint's transform relative to its parent, from `instance`'s
/// last sample, into `out`: per joint in joint order 10 floats,
/// translation `x y z`, rotation quaternion `x y z w`, scale `x y z` (parts
/// no track animates: the joint's rest values), for an engine that composes
/// its own hierarchy. `len` must be 10 times `tcb_skeleton_joint_count`.
/// Errors as `tcb_skeleton_model_matrices`; allocates nothing.
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton used by no other thread;
/// `instance` is NULL or a live instance not sampled during the call; `out`
/// is NULL or valid for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_local_transforms(
    skeleton: *mut TcbSkeleton,
    instance: *const TcbInstance,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or live handles (the skeleton used by no one else)
        // and `len` writable floats, as the caller promises.
        let (s, inst, out) = unsafe {
            (
                ptr::get_mut(skeleton, "skeleton")?,
                ptr::get(instance, "instance")?,
                ptr::slice_mut(out, len, "out")?,
            )
        };
        write(s, inst.inst.pose(), out, Output::Local)
    })
}

/// `tcb_skeleton_local_transforms` of a pose (a blend's output).
///
/// # Safety
///
/// `skeleton` is NULL or a live skeleton used by no other thread; `pose` is
/// NULL or a live pose not written during the call; `out` is NULL or valid
/// for `len` floats of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_skeleton_local_transforms_pose(
    skeleton: *mut TcbSkeleton,
    pose: *const TcbPose,
    out: *mut f32,
    len: usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or live handles (the skeleton used by no one else)
        // and `len` writable floats, as the caller promises.
        let (s, pose, out) = unsafe {
            (
                ptr::get_mut(skeleton, "skeleton")?,
                ptr::get(pose, "pose")?,
                ptr::slice_mut(out, len, "out")?,
            )
        };
        write(s, &pose.pose, out, Output::Local)
    })
}
