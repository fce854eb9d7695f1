//! # tcb-ffi
//!
//! A C ABI for the tcb runtime, for C and C++ engines: load a clip (clip
//! JSON, BVH, glTF, or a packed `.tcbc`) and compile it, make instances
//! (through a rig if clips are to be blended), sample them every frame
//! into the caller's floats, blend them, and turn a pose into model-space
//! joint matrices through a skeleton. The header is `include/tcb.h`,
//! generated from this crate by cbindgen (`crates/tcb-ffi/cbindgen.toml`;
//! CI fails if it drifts); link `libtcb_ffi.a` or `libtcb_ffi.so`.
//!
//! ```c
//! TcbClip *clip = NULL;
//! if (tcb_clip_load_file("data/cmu-01_01.bvh", 0, &clip) != TCB_STATUS_OK) {
//!     fprintf(stderr, "%s\n", tcb_last_error_message());
//!     return 1;
//! }
//! TcbInstance *inst = NULL;
//! tcb_instance_new(clip, 0, &inst);
//! size_t n = tcb_instance_channel_count(inst);
//! float *row = malloc(n * sizeof(float));
//! TcbTrackInfo hips;
//! tcb_clip_find_track(clip, "Hips.translation", &hips);
//! tcb_instance_sample(inst, 1.5, row, n);   /* every frame; allocates nothing */
//! printf("%f %f %f\n", row[hips.offset], row[hips.offset + 1], row[hips.offset + 2]);
//! free(row);
//! tcb_instance_free(inst);
//! tcb_clip_free(clip);
//! ```
//!
//! ## The row layout
//!
//! `tcb_instance_sample` writes one float per channel: every track in
//! track order (the clip's file order, or the rig's order for an instance
//! made with a rig), each track's components consecutive (`x y z` for a
//! vec3, `x y z w` for a rotation quaternion, one float for a scalar). A
//! track's first float is its `TcbTrackInfo::offset` (`tcb_clip_find_track`,
//! `tcb_rig_find_track`). Model matrices (`tcb_skeleton_model_matrices`)
//! are 16 floats a joint, column-major; local transforms
//! (`tcb_skeleton_local_transforms`) 10: translation, rotation, scale.
//!
//! ## The contract
//!
//! - Every function that can fail returns a `TcbStatus`; on failure
//!   `tcb_last_error_message()` (per thread) says why, and output handles
//!   are set to NULL. Counts return 0 for a NULL handle.
//! - Every pointer is checked for NULL (and buffers for their length and
//!   alignment) before it is used; a wrong length is an error, never a
//!   partial write.
//! - No panic crosses the boundary: each entry point runs under
//!   `catch_unwind`, a panic becoming `TCB_STATUS_INTERNAL`.
//! - Sampling, blending and matrices allocate nothing on success.
//! - Handles are freed with their `tcb_*_free`, in any order: an instance
//!   keeps its clip alive, so does a skeleton its binding.
//! - Clips and rigs are immutable and may be shared across threads;
//!   instances, poses and skeletons are used by one thread at a time.

#![deny(unsafe_op_in_unsafe_fn)]
// The boundary itself: `#[unsafe(no_mangle)]` and raw pointers from C.
#![allow(unsafe_code)]

mod clip;
mod error;
mod instance;
mod layout;
mod pose;
mod ptr;
mod rig;
mod skeleton;

pub use clip::{
    TCB_LOAD_EXACT_VELOCITIES, TCB_LOAD_HERMITE_ROTATIONS, TCB_LOAD_QUANTIZE, TcbClip,
    tcb_clip_channel_count, tcb_clip_find_track, tcb_clip_free, tcb_clip_has_skeleton,
    tcb_clip_load_file, tcb_clip_load_file_animation, tcb_clip_load_memory, tcb_clip_time_range,
    tcb_clip_track_count, tcb_clip_track_info, tcb_clip_track_name,
};
pub use error::{TcbStatus, tcb_last_error_message, tcb_version};
pub use instance::{
    TCB_INSTANCE_VELOCITIES, TcbInstance, TcbPlayback, tcb_instance_channel_count,
    tcb_instance_free, tcb_instance_new, tcb_instance_new_with_rig, tcb_instance_sample,
    tcb_instance_sample_with_velocities, tcb_instance_set_playback, tcb_instance_update,
};
pub use layout::{TcbTrackInfo, TcbTrackKind};
pub use pose::{
    TCB_BLEND_STACK_LAYERS, TCB_POSE_VELOCITIES, TcbPose, tcb_blend, tcb_blend_add,
    tcb_blend_covered, tcb_pose_channel_count, tcb_pose_free, tcb_pose_new_for_clip,
    tcb_pose_new_for_rig, tcb_pose_read, tcb_pose_read_velocities,
};
pub use rig::{
    TcbRig, tcb_rig_channel_count, tcb_rig_find_track, tcb_rig_free, tcb_rig_from_clip,
    tcb_rig_from_skeleton, tcb_rig_track_count, tcb_rig_track_info, tcb_rig_track_name,
};
pub use skeleton::{
    TCB_MATRIX_FLOATS, TCB_TRANSFORM_FLOATS, TcbSkeleton, tcb_skeleton_find_joint,
    tcb_skeleton_free, tcb_skeleton_joint_count, tcb_skeleton_joint_name,
    tcb_skeleton_joint_parent, tcb_skeleton_local_transforms, tcb_skeleton_local_transforms_pose,
    tcb_skeleton_model_matrices, tcb_skeleton_model_matrices_pose, tcb_skeleton_new,
    tcb_skeleton_new_for_rig,
};
