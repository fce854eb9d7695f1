#![allow(unsafe_code)] // calls of the C functions
//! The per-frame C calls allocate nothing on success: sampling (values and
//! velocities), blending, additive layers, reading poses and model-space
//! matrices, counted by a global allocator on the calling thread only.

use std::ffi::CString;
use std::ptr::null_mut;
use tcb_ffi::*;
use tcb_test_support::{CountingAllocator, count_allocations};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[track_caller]
fn ok(status: TcbStatus) {
    assert_eq!(status, TcbStatus::Ok);
}

#[test]
fn per_frame_calls_allocate_nothing() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    // SAFETY: `Player`'s handles stay live and its buffers keep their
    // lengths until `free`.
    unsafe {
        let mut player = Player::load(path);
        let ((), counted) = count_allocations(|| {
            for frame in 0..600 {
                player.frame(-1.0 + f64::from(frame) / 60.0);
            }
        });
        assert_eq!(counted.count, 0, "allocations in 600 frames");
        assert!(player.matrices.iter().all(|x| x.is_finite()));
        player.free();
    }
}

/// The handles and buffers of one frame's calls: a plain instance, two
/// through the CMU skeleton's rig (`b` looping at 1.5x), a rig pose to
/// blend them into, and skeletons for the plain and the rig layout.
struct Player {
    clip: *mut TcbClip,
    rig: *mut TcbRig,
    plain: *mut TcbInstance,
    a: *mut TcbInstance,
    b: *mut TcbInstance,
    pose: *mut TcbPose,
    skel: *mut TcbSkeleton,
    rig_skel: *mut TcbSkeleton,
    row: Vec<f32>,
    velocity: Vec<f32>,
    rig_row: Vec<f32>,
    matrices: Vec<f32>,
    locals: Vec<f32>,
    name: CString,
}

impl Player {
    /// Loads the clip at `path` and makes every handle and buffer.
    unsafe fn load(path: &str) -> Self {
        let path = CString::new(path).unwrap();
        // SAFETY: out pointers to locals; handles used as they are made.
        unsafe {
            let mut clip = null_mut();
            ok(tcb_clip_load_file(path.as_ptr(), 0, &mut clip));
            let mut rig = null_mut();
            ok(tcb_rig_from_skeleton(clip, &mut rig));
            let (mut plain, mut a, mut b) = (null_mut(), null_mut(), null_mut());
            ok(tcb_instance_new(clip, TCB_INSTANCE_VELOCITIES, &mut plain));
            for i in [&mut a, &mut b] {
                ok(tcb_instance_new_with_rig(
                    clip,
                    rig,
                    TCB_INSTANCE_VELOCITIES,
                    i,
                ));
            }
            ok(tcb_instance_set_playback(b, TcbPlayback::Loop as u32, 1.5));
            let mut pose = null_mut();
            ok(tcb_pose_new_for_rig(rig, TCB_POSE_VELOCITIES, &mut pose));
            let (mut skel, mut rig_skel) = (null_mut(), null_mut());
            ok(tcb_skeleton_new(clip, clip, &mut skel));
            ok(tcb_skeleton_new_for_rig(clip, rig, &mut rig_skel));
            let n = tcb_instance_channel_count(plain);
            let rn = tcb_rig_channel_count(rig);
            let joints = tcb_skeleton_joint_count(skel);
            Self {
                clip,
                rig,
                plain,
                a,
                b,
                pose,
                skel,
                rig_skel,
                row: vec![0.0; n],
                velocity: vec![0.0; n],
                rig_row: vec![0.0; rn],
                matrices: vec![0.0; 16 * joints],
                locals: vec![0.0; 10 * joints],
                name: CString::new("LeftHand.rotation").unwrap(),
            }
        }
    }

    /// One frame's calls at `t`: sampling (values and velocities), model
    /// and local transforms, blending (weighted, covered, additive),
    /// reading the pose, its model matrices, and a track lookup.
    unsafe fn frame(&mut self, t: f64) {
        let (n, rn) = (self.row.len(), self.rig_row.len());
        let layers = [self.a as *const TcbInstance, self.b as *const TcbInstance];
        let w = [0.3f32, 0.7];
        let mut info = TcbTrackInfo::default();
        // SAFETY: live handles (until `free`) and buffers of the lengths given.
        unsafe {
            ok(tcb_instance_sample(self.plain, t, self.row.as_mut_ptr(), n));
            ok(tcb_instance_sample_with_velocities(
                self.plain,
                t,
                self.row.as_mut_ptr(),
                n,
                self.velocity.as_mut_ptr(),
                n,
            ));
            ok(tcb_skeleton_model_matrices(
                self.skel,
                self.plain,
                self.matrices.as_mut_ptr(),
                self.matrices.len(),
            ));
            ok(tcb_skeleton_local_transforms(
                self.skel,
                self.plain,
                self.locals.as_mut_ptr(),
                self.locals.len(),
            ));
            ok(tcb_instance_update(self.a, t));
            let rig_row = self.rig_row.as_mut_ptr();
            ok(tcb_instance_sample(self.b, t + 3.0, rig_row, rn));
            ok(tcb_blend(self.pose, layers.as_ptr(), w.as_ptr(), 2));
            ok(tcb_blend_covered(self.pose, layers.as_ptr(), w.as_ptr(), 2));
            ok(tcb_blend_add(self.pose, self.b, self.a, 0.25));
            ok(tcb_pose_read(self.pose, rig_row, rn));
            ok(tcb_pose_read_velocities(self.pose, rig_row, rn));
            ok(tcb_skeleton_model_matrices_pose(
                self.rig_skel,
                self.pose,
                self.matrices.as_mut_ptr(),
                self.matrices.len(),
            ));
            ok(tcb_clip_find_track(
                self.clip,
                self.name.as_ptr(),
                &mut info,
            ));
        }
    }

    /// Frees every handle.
    unsafe fn free(self) {
        // SAFETY: each handle freed once, none used after.
        unsafe {
            tcb_skeleton_free(self.rig_skel);
            tcb_skeleton_free(self.skel);
            tcb_pose_free(self.pose);
            for i in [self.plain, self.a, self.b] {
                tcb_instance_free(i);
            }
            tcb_rig_free(self.rig);
            tcb_clip_free(self.clip);
        }
    }
}
