#![allow(unsafe_code)] // a counting global allocator, and calls of the C functions
//! The per-frame C calls allocate nothing on success: sampling (values and
//! velocities), blending, additive layers, reading poses and model-space
//! matrices, counted by a global allocator on the calling thread only.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::CString;
use std::ptr::null_mut;
use tcb_ffi::*;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[track_caller]
fn ok(status: TcbStatus) {
    assert_eq!(status, TcbStatus::Ok);
}

#[test]
fn per_frame_calls_allocate_nothing() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let path = CString::new(path).unwrap();
    // SAFETY: live handles and buffers of the lengths given, throughout.
    unsafe {
        let mut clip = null_mut();
        ok(tcb_clip_load_file(path.as_ptr(), 0, &mut clip));
        let mut rig = null_mut();
        ok(tcb_rig_from_skeleton(clip, &mut rig));
        let (mut plain, mut a, mut b) = (null_mut(), null_mut(), null_mut());
        ok(tcb_instance_new(clip, TCB_INSTANCE_VELOCITIES, &mut plain));
        ok(tcb_instance_new_with_rig(
            clip,
            rig,
            TCB_INSTANCE_VELOCITIES,
            &mut a,
        ));
        ok(tcb_instance_new_with_rig(
            clip,
            rig,
            TCB_INSTANCE_VELOCITIES,
            &mut b,
        ));
        ok(tcb_instance_set_playback(b, TcbPlayback::Loop as u32, 1.5));
        let mut pose = null_mut();
        ok(tcb_pose_new_for_rig(rig, TCB_POSE_VELOCITIES, &mut pose));
        let (mut skel, mut rig_skel) = (null_mut(), null_mut());
        ok(tcb_skeleton_new(clip, clip, &mut skel));
        ok(tcb_skeleton_new_for_rig(clip, rig, &mut rig_skel));
        let n = tcb_instance_channel_count(plain);
        let rn = tcb_rig_channel_count(rig);
        let (mut row, mut velocity, mut rig_row) = (vec![0.0; n], vec![0.0; n], vec![0.0; rn]);
        let mut matrices = vec![0.0; 16 * tcb_skeleton_joint_count(skel)];
        let mut locals = vec![0.0; 10 * tcb_skeleton_joint_count(skel)];
        let layers = [a as *const TcbInstance, b as *const TcbInstance];
        let name = CString::new("LeftHand.rotation").unwrap();
        let mut info = TcbTrackInfo::default();

        let before = ALLOCATIONS.with(Cell::get);
        COUNTING.with(|c| c.set(true));
        for frame in 0..600 {
            let t = -1.0 + frame as f64 / 60.0;
            ok(tcb_instance_sample(plain, t, row.as_mut_ptr(), n));
            ok(tcb_instance_sample_with_velocities(
                plain,
                t,
                row.as_mut_ptr(),
                n,
                velocity.as_mut_ptr(),
                n,
            ));
            ok(tcb_skeleton_model_matrices(
                skel,
                plain,
                matrices.as_mut_ptr(),
                matrices.len(),
            ));
            ok(tcb_skeleton_local_transforms(
                skel,
                plain,
                locals.as_mut_ptr(),
                locals.len(),
            ));
            ok(tcb_instance_update(a, t));
            ok(tcb_instance_sample(b, t + 3.0, rig_row.as_mut_ptr(), rn));
            let w = [0.3f32, 0.7];
            ok(tcb_blend(pose, layers.as_ptr(), w.as_ptr(), 2));
            ok(tcb_blend_covered(pose, layers.as_ptr(), w.as_ptr(), 2));
            ok(tcb_blend_add(pose, b, a, 0.25));
            ok(tcb_pose_read(pose, rig_row.as_mut_ptr(), rn));
            ok(tcb_pose_read_velocities(pose, rig_row.as_mut_ptr(), rn));
            ok(tcb_skeleton_model_matrices_pose(
                rig_skel,
                pose,
                matrices.as_mut_ptr(),
                matrices.len(),
            ));
            ok(tcb_clip_find_track(clip, name.as_ptr(), &mut info));
        }
        COUNTING.with(|c| c.set(false));
        let allocations = ALLOCATIONS.with(Cell::get) - before;
        assert_eq!(allocations, 0, "allocations in 600 frames");
        assert!(matrices.iter().all(|x| x.is_finite()));

        tcb_skeleton_free(rig_skel);
        tcb_skeleton_free(skel);
        tcb_pose_free(pose);
        for i in [plain, a, b] {
            tcb_instance_free(i);
        }
        tcb_rig_free(rig);
        tcb_clip_free(clip);
    }
}
