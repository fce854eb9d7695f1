#![allow(unsafe_code)] // calling the C functions is what this tests
//! The C functions called from Rust as C calls them: results against the
//! Rust API on the same clip, and every error path (NULL pointers, short
//! buffers, bad files, mismatched layouts) giving its status and a message
//! without a panic or a write.

use std::ffi::{CStr, CString, c_char};
use std::path::PathBuf;
use std::ptr::{null, null_mut};
use std::sync::Arc;
use tcb_ffi::*;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(name)
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

fn message() -> String {
    // SAFETY: never NULL; valid until the next failure on this thread.
    unsafe { CStr::from_ptr(tcb_last_error_message()) }
        .to_str()
        .unwrap()
        .to_string()
}

/// `status` is `want`, with a message containing `part`.
#[track_caller]
fn fails(status: TcbStatus, want: TcbStatus, part: &str) {
    assert_eq!(status, want, "{}", message());
    let m = message();
    assert!(m.contains(part), "{m:?} lacks {part:?}");
}

const BVH: &str = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
    JOINT Spine\n {\n  OFFSET 0 5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 5 0\n  }\n }\n}\n\
    MOTION\nFrames: 3\nFrame Time: 0.5\n0 0 0 0 0 0 0 0 0\n1 0 0 0 30 0 0 20 0\n2 0 0 0 60 0 0 40 0\n";

fn load(path: &std::path::Path) -> *mut TcbClip {
    let mut clip = null_mut();
    let p = c(path.to_str().unwrap());
    // SAFETY: a NUL-terminated path and a writable out pointer.
    let status = unsafe { tcb_clip_load_file(p.as_ptr(), 0, &mut clip) };
    assert_eq!(status, TcbStatus::Ok, "{}", message());
    assert!(!clip.is_null());
    clip
}

fn load_memory(bytes: &[u8], format: &str) -> (TcbStatus, *mut TcbClip) {
    let mut clip = null_mut();
    let f = c(format);
    // SAFETY: `bytes` is readable for its length; the rest as above.
    let status =
        unsafe { tcb_clip_load_memory(bytes.as_ptr(), bytes.len(), f.as_ptr(), 0, &mut clip) };
    (status, clip)
}

fn instance(clip: *const TcbClip, flags: u32) -> *mut TcbInstance {
    let mut inst = null_mut();
    // SAFETY: a live clip and a writable out pointer.
    assert_eq!(
        unsafe { tcb_instance_new(clip, flags, &mut inst) },
        TcbStatus::Ok
    );
    inst
}

/// The CMU clip sampled through the C API is the Rust runtime's, bit for
/// bit, and its model matrices are `SkeletonBinding`'s.
#[test]
fn cmu_rows_and_matrices_match_the_runtime() {
    // Kept whole: one clip, instance and skeleton handle run through every check, as a C caller's would.
    let path = data("cmu-01_01.bvh");
    let clip = load(&path);
    let loaded = tcb_io::load(&path).unwrap();
    let rust_clip = Arc::new(tcb_runtime::Clip::compile(&loaded.clip));
    let mut rust = tcb_runtime::Instance::new(rust_clip.clone());
    // SAFETY: live handles and buffers of the lengths given, throughout.
    unsafe {
        assert_eq!(tcb_clip_track_count(clip), rust_clip.tracks().len());
        let n = tcb_clip_channel_count(clip);
        assert_eq!(n, rust_clip.channel_count());
        assert!(tcb_clip_has_skeleton(clip));
        let (mut t0, mut t1) = (f64::NAN, f64::NAN);
        assert_eq!(tcb_clip_time_range(clip, &mut t0, &mut t1), TcbStatus::Ok);
        assert_eq!(Some((t0, t1)), rust_clip.time_range());

        let inst = instance(clip, 0);
        assert_eq!(tcb_instance_channel_count(inst), n);
        let (mut row, mut want) = (vec![0.0f32; n], vec![0.0f32; n]);
        for t in [0.0, 1.5, 7.25, -3.0, 100.0, f64::NAN] {
            let status = tcb_instance_sample(inst, t, row.as_mut_ptr(), n);
            assert_eq!(status, TcbStatus::Ok);
            rust.sample_to(t, &mut want).unwrap();
            assert_eq!(
                row.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                "t = {t}"
            );
        }

        // The track Hips.translation: first, 3 floats at offset 0.
        let mut info = TcbTrackInfo::default();
        let name = c("Hips.translation");
        assert_eq!(
            tcb_clip_find_track(clip, name.as_ptr(), &mut info),
            TcbStatus::Ok
        );
        assert_eq!((info.index, info.offset, info.components), (0, 0, 3));
        assert_eq!(info.kind, TcbTrackKind::Vec3);
        let mut second = TcbTrackInfo::default();
        assert_eq!(tcb_clip_track_info(clip, 1, &mut second), TcbStatus::Ok);
        assert_eq!((second.kind, second.offset), (TcbTrackKind::Quat, 3));

        // Model matrices at 1.5 s against SkeletonBinding.
        let mut skel = null_mut();
        assert_eq!(tcb_skeleton_new(clip, clip, &mut skel), TcbStatus::Ok);
        let joints = tcb_skeleton_joint_count(skel);
        assert_eq!(joints, 31 + 7);
        let binding =
            tcb_runtime::SkeletonBinding::new(loaded.skeleton.clone().unwrap(), &rust_clip);
        let mut local = vec![tcb_core::skeleton::Transform::IDENTITY; joints];
        let mut model = vec![glam::Affine3A::IDENTITY; joints];
        tcb_instance_update(inst, 1.5);
        binding
            .model_transforms(rust.sample(1.5), &mut local, &mut model)
            .unwrap();
        let mut m = vec![0.0f32; joints * 16];
        let status = tcb_skeleton_model_matrices(skel, inst, m.as_mut_ptr(), m.len());
        assert_eq!(status, TcbStatus::Ok);
        for (j, a) in model.iter().enumerate() {
            assert_eq!(
                &m[16 * j..16 * j + 16],
                &glam::Mat4::from(*a).to_cols_array()
            );
        }
        // Local transforms: translation, rotation, scale per joint.
        binding.local_transforms(rust.pose(), &mut local).unwrap();
        let mut l = vec![0.0f32; joints * 10];
        let status = tcb_skeleton_local_transforms(skel, inst, l.as_mut_ptr(), l.len());
        assert_eq!(status, TcbStatus::Ok);
        for (j, t) in local.iter().enumerate() {
            let want: Vec<f32> = (t.translation.to_array().into_iter())
                .chain(t.rotation.to_array())
                .chain(t.scale.to_array())
                .collect();
            assert_eq!(&l[10 * j..10 * j + 10], &want[..], "joint {j}");
        }
        let status = tcb_skeleton_local_transforms(skel, inst, l.as_mut_ptr(), 16 * joints);
        fails(status, TcbStatus::BufferLength, "(10 each)");
        // Joint queries.
        let mut head = 0usize;
        let name = c("Head");
        assert_eq!(
            tcb_skeleton_find_joint(skel, name.as_ptr(), &mut head),
            TcbStatus::Ok
        );
        let mut parent = 0i64;
        assert_eq!(
            tcb_skeleton_joint_parent(skel, 0, &mut parent),
            TcbStatus::Ok
        );
        assert_eq!(parent, -1);
        assert_eq!(
            tcb_skeleton_joint_parent(skel, head, &mut parent),
            TcbStatus::Ok
        );
        assert_eq!(
            Some(parent as usize),
            loaded.skeleton.as_ref().unwrap().joints()[head].parent
        );
        let mut buf = [0 as c_char; 16];
        let mut len = 0usize;
        let status = tcb_skeleton_joint_name(skel, head, buf.as_mut_ptr(), buf.len(), &mut len);
        assert_eq!(status, TcbStatus::Ok);
        assert_eq!(CStr::from_ptr(buf.as_ptr()).to_str().unwrap(), "Head");
        assert_eq!(len, 4);

        tcb_skeleton_free(skel);
        tcb_instance_free(inst);
        tcb_clip_free(clip);
    }
}

/// Every entry point refuses NULL with `TCB_STATUS_NULL_POINTER` and a
/// message naming the argument; counts give 0; frees ignore NULL.
#[test]
fn null_pointers_are_refused() {
    // Kept whole: a table of calls, each entry point with NULL in one argument at a time.
    let clip = load_memory(BVH.as_bytes(), "bvh").1;
    let inst = instance(clip, 0);
    let name = c("Hips.rotation");
    let null_status = TcbStatus::NullPointer;
    // SAFETY: every pointer given is NULL or live.
    unsafe {
        let mut out_clip = null_mut();
        fails(
            tcb_clip_load_file(null(), 0, &mut out_clip),
            null_status,
            "path",
        );
        let p = c("x.bvh");
        fails(
            tcb_clip_load_file(p.as_ptr(), 0, null_mut()),
            null_status,
            "out",
        );
        fails(
            tcb_clip_load_memory(null(), 3, c"bvh".as_ptr(), 0, &mut out_clip),
            null_status,
            "bytes",
        );
        fails(
            tcb_clip_load_memory(BVH.as_ptr(), BVH.len(), null(), 0, &mut out_clip),
            null_status,
            "format",
        );
        assert_eq!(tcb_clip_track_count(null()), 0);
        assert_eq!(tcb_clip_channel_count(null()), 0);
        assert!(!tcb_clip_has_skeleton(null()));
        let mut info = TcbTrackInfo::default();
        fails(
            tcb_clip_track_info(null(), 0, &mut info),
            null_status,
            "clip",
        );
        fails(
            tcb_clip_track_info(clip, 0, null_mut()),
            null_status,
            "info",
        );
        fails(
            tcb_clip_find_track(clip, null(), &mut info),
            null_status,
            "name",
        );
        fails(
            tcb_clip_find_track(clip, name.as_ptr(), null_mut()),
            null_status,
            "info",
        );
        let mut t = 0.0;
        fails(
            tcb_clip_time_range(clip, &mut t, null_mut()),
            null_status,
            "end",
        );
        fails(
            tcb_clip_track_name(clip, 0, null_mut(), 64, null_mut()),
            null_status,
            "buf",
        );

        let mut out_inst = null_mut();
        fails(
            tcb_instance_new(null(), 0, &mut out_inst),
            null_status,
            "clip",
        );
        fails(
            tcb_instance_new_with_rig(clip, null(), 0, &mut out_inst),
            null_status,
            "rig",
        );
        fails(
            tcb_instance_set_playback(null_mut(), 0, 1.0),
            null_status,
            "instance",
        );
        fails(
            tcb_instance_sample(null_mut(), 0.0, null_mut(), 0),
            null_status,
            "instance",
        );
        let n = tcb_instance_channel_count(inst);
        fails(
            tcb_instance_sample(inst, 0.0, null_mut(), n),
            null_status,
            "out",
        );
        fails(
            tcb_instance_update(null_mut(), 0.0),
            null_status,
            "instance",
        );
        assert_eq!(tcb_instance_channel_count(null()), 0);

        let mut rig = null_mut();
        fails(tcb_rig_from_skeleton(null(), &mut rig), null_status, "clip");
        fails(tcb_rig_from_clip(null(), &mut rig), null_status, "clip");
        assert_eq!(tcb_rig_track_count(null()), 0);
        assert_eq!(tcb_rig_channel_count(null()), 0);
        fails(
            tcb_rig_find_track(null(), name.as_ptr(), &mut info),
            null_status,
            "rig",
        );

        let mut pose = null_mut();
        fails(
            tcb_pose_new_for_rig(null(), 0, &mut pose),
            null_status,
            "rig",
        );
        fails(
            tcb_pose_new_for_clip(clip, 0, null_mut()),
            null_status,
            "out",
        );
        fails(tcb_pose_read(null(), null_mut(), 0), null_status, "pose");
        assert_eq!(tcb_pose_channel_count(null()), 0);
        fails(tcb_blend(null_mut(), null(), null(), 0), null_status, "out");
        assert_eq!(tcb_pose_new_for_clip(clip, 0, &mut pose), TcbStatus::Ok);
        fails(tcb_blend(pose, null(), null(), 2), null_status, "layers");
        let layers = [inst as *const TcbInstance, null()];
        fails(
            tcb_blend(pose, layers.as_ptr(), null(), 2),
            null_status,
            "weights",
        );
        let weights = [0.5f32, 0.5];
        fails(
            tcb_blend(pose, layers.as_ptr(), weights.as_ptr(), 2),
            null_status,
            "layers[1]",
        );
        fails(
            tcb_blend_add(pose, inst, null(), 1.0),
            null_status,
            "reference",
        );

        let mut skel = null_mut();
        fails(
            tcb_skeleton_new(null(), clip, &mut skel),
            null_status,
            "skeleton_from",
        );
        fails(
            tcb_skeleton_new(clip, null(), &mut skel),
            null_status,
            "clip",
        );
        fails(
            tcb_skeleton_new_for_rig(clip, null(), &mut skel),
            null_status,
            "rig",
        );
        assert_eq!(tcb_skeleton_joint_count(null()), 0);
        assert_eq!(tcb_skeleton_new(clip, clip, &mut skel), TcbStatus::Ok);
        let joints = tcb_skeleton_joint_count(skel);
        fails(
            tcb_skeleton_model_matrices(skel, null(), null_mut(), 0),
            null_status,
            "instance",
        );
        fails(
            tcb_skeleton_model_matrices(skel, inst, null_mut(), 16 * joints),
            null_status,
            "out",
        );
        fails(
            tcb_skeleton_model_matrices_pose(null_mut(), pose, null_mut(), 0),
            null_status,
            "skeleton",
        );
        let mut index = 0usize;
        fails(
            tcb_skeleton_find_joint(skel, null(), &mut index),
            null_status,
            "name",
        );
        fails(
            tcb_skeleton_joint_parent(skel, 0, null_mut()),
            null_status,
            "parent",
        );

        tcb_clip_free(null_mut());
        tcb_instance_free(null_mut());
        tcb_rig_free(null_mut());
        tcb_pose_free(null_mut());
        tcb_skeleton_free(null_mut());
        tcb_skeleton_free(skel);
        tcb_pose_free(pose);
        tcb_instance_free(inst);
        tcb_clip_free(clip);
    }
}

/// A buffer of the wrong length is refused with the length wanted, and
/// nothing is written into it.
#[test]
fn wrong_lengths_write_nothing() {
    // Kept whole: a table of calls, each buffer argument one length off at a time.
    let clip = load_memory(BVH.as_bytes(), "bvh").1;
    let inst = instance(clip, TCB_INSTANCE_VELOCITIES);
    // SAFETY: live handles; buffers at least as long as the lengths given.
    unsafe {
        let n = tcb_instance_channel_count(inst);
        assert_eq!(n, 3 + 4 + 4);
        let mut row = vec![-7.0f32; n + 1];
        for len in [n - 1, n + 1, 1] {
            let status = tcb_instance_sample(inst, 0.5, row.as_mut_ptr(), len);
            fails(status, TcbStatus::BufferLength, &format!("have {n}"));
            assert!(row.iter().all(|&x| x == -7.0));
        }
        let mut v = vec![-7.0f32; n];
        let status =
            tcb_instance_sample_with_velocities(inst, 0.5, row.as_mut_ptr(), n, v.as_mut_ptr(), 2);
        fails(status, TcbStatus::BufferLength, "velocities");
        assert!(row.iter().chain(&v).all(|&x| x == -7.0));
        let status = tcb_instance_sample_with_velocities(
            inst,
            0.5,
            row.as_mut_ptr(),
            n,
            row.as_mut_ptr().add(1),
            n,
        );
        fails(status, TcbStatus::InvalidArgument, "overlap");
        let status =
            tcb_instance_sample_with_velocities(inst, 0.5, row.as_mut_ptr(), n, v.as_mut_ptr(), n);
        assert_eq!(status, TcbStatus::Ok);
        // The same as the Rust instance's, and as a blend of it alone.
        let loaded = tcb_io::ClipDoc::parse(
            &tcb_io::bvh::Bvh::parse(BVH)
                .unwrap()
                .to_clip_doc("clip", Default::default())
                .unwrap()
                .to_json(),
        )
        .unwrap()
        .build()
        .unwrap();
        let mut rust = tcb_runtime::Instance::new(Arc::new(tcb_runtime::Clip::compile(&loaded)))
            .with_velocities();
        let (mut want, mut want_v) = (vec![0.0f32; n], vec![0.0f32; n]);
        rust.sample(0.5).write_row(&mut want, Some(&mut want_v));
        assert_eq!((&row[..n], &v[..]), (&want[..], &want_v[..]));
        let mut pose = null_mut();
        assert_eq!(
            tcb_pose_new_for_clip(clip, TCB_POSE_VELOCITIES, &mut pose),
            TcbStatus::Ok
        );
        let layers = [inst as *const TcbInstance];
        assert_eq!(
            tcb_blend(pose, layers.as_ptr(), [1.0f32].as_ptr(), 1),
            TcbStatus::Ok
        );
        let mut pv = vec![0.0f32; n];
        assert_eq!(
            tcb_pose_read_velocities(pose, pv.as_mut_ptr(), n),
            TcbStatus::Ok
        );
        assert_eq!(pv, want_v);
        tcb_pose_free(pose);
        assert!(v.iter().any(|&x| x != 0.0 && x != -7.0));

        let mut skel = null_mut();
        assert_eq!(tcb_skeleton_new(clip, clip, &mut skel), TcbStatus::Ok);
        let joints = tcb_skeleton_joint_count(skel);
        assert_eq!(joints, 3); // Hips, Spine, Spine_end
        let mut m = vec![-7.0f32; 16 * joints];
        let status = tcb_skeleton_model_matrices(skel, inst, m.as_mut_ptr(), 16 * joints - 1);
        fails(status, TcbStatus::BufferLength, "48");
        assert!(m.iter().all(|&x| x == -7.0));

        // Names: too short a buffer says how long the name is.
        let mut len = 0usize;
        let status = tcb_clip_track_name(clip, 1, null_mut(), 0, &mut len);
        fails(status, TcbStatus::BufferLength, "needs a buffer of 14");
        assert_eq!(len, "Hips.rotation".len());
        let mut buf = [1 as c_char; 14];
        let status = tcb_clip_track_name(clip, 1, buf.as_mut_ptr(), 13, &mut len);
        assert_eq!(status, TcbStatus::BufferLength);
        assert!(buf.iter().all(|&b| b == 1));
        let status = tcb_clip_track_name(clip, 1, buf.as_mut_ptr(), 14, null_mut());
        assert_eq!(status, TcbStatus::Ok);
        assert_eq!(CStr::from_ptr(buf.as_ptr()).to_str(), Ok("Hips.rotation"));
        // Indices past the end.
        let mut info = TcbTrackInfo::default();
        fails(
            tcb_clip_track_info(clip, 3, &mut info),
            TcbStatus::InvalidArgument,
            "3 tracks",
        );
        let mut parent = 0i64;
        let status = tcb_skeleton_joint_parent(skel, 3, &mut parent);
        fails(status, TcbStatus::InvalidArgument, "3 joints");

        tcb_skeleton_free(skel);
        tcb_instance_free(inst);
        tcb_clip_free(clip);
    }
}

/// Bad files and arguments: a status, a message naming the problem, and a
/// NULL handle.
#[test]
fn bad_files_give_a_status_and_a_message() {
    let dir = std::env::temp_dir().join(format!("tcb-ffi-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        c(p.to_str().unwrap())
    };
    let try_file = |path: &CString| {
        let mut clip = std::ptr::dangling_mut::<TcbClip>(); // not NULL: the call clears it
        // SAFETY: a NUL-terminated path and a writable out pointer.
        let status = unsafe { tcb_clip_load_file(path.as_ptr(), 0, &mut clip) };
        assert!(clip.is_null());
        status
    };
    fails(
        try_file(&c("/no/such/file.bvh")),
        TcbStatus::Io,
        "/no/such/file.bvh",
    );
    fails(
        try_file(&c("/no/such/file.tcbc")),
        TcbStatus::Io,
        "/no/such/file.tcbc",
    );
    let bad_bvh = write("bad.bvh", b"HIERARCHY\nROOT Hips\n{\n OFFSET 0 0\n");
    fails(try_file(&bad_bvh), TcbStatus::InvalidData, "bad.bvh");
    let bad_json = write(
        "bad.json",
        br#"{"format": "tcb-clip/1", "tracks": [{"name": "x"}]}"#,
    );
    fails(try_file(&bad_json), TcbStatus::InvalidData, "bad.json");
    let bad_tcbc = write("bad.tcbc", b"not a packed clip at all");
    fails(try_file(&bad_tcbc), TcbStatus::InvalidData, "bad.tcbc");
    let unknown = write("clip.txt", b"");
    fails(
        try_file(&unknown),
        TcbStatus::InvalidData,
        "unknown file type",
    );
    // A path that is not UTF-8.
    let mut clip = null_mut();
    let latin1 = CString::new(vec![b'/', 0xE9, b'.', b'b', b'v', b'h']).unwrap();
    // SAFETY: a NUL-terminated path and a writable out pointer.
    let status = unsafe { tcb_clip_load_file(latin1.as_ptr(), 0, &mut clip) };
    fails(status, TcbStatus::InvalidArgument, "UTF-8");
    // Unknown flags.
    let good = write("good.bvh", BVH.as_bytes());
    // SAFETY: as above.
    let status = unsafe { tcb_clip_load_file(good.as_ptr(), 1 << 7, &mut clip) };
    fails(status, TcbStatus::InvalidArgument, "flags");
    // In memory.
    let (status, clip) = load_memory(b"HIERARCHY\n", "bvh");
    fails(status, TcbStatus::InvalidData, "");
    assert!(clip.is_null());
    let (status, _) = load_memory(&[0xff, 0xfe], "json");
    fails(status, TcbStatus::InvalidData, "json text");
    // Bytes that are not text are not a BVH file, as the file loader says.
    let (status, _) = load_memory(&[0x85, 0x00, 0x13], "bvh");
    fails(status, TcbStatus::InvalidData, "not a BVH file: not text");
    let (status, _) = load_memory(b"{}", "fbx");
    fails(status, TcbStatus::InvalidArgument, "unknown format \"fbx\"");
    let (status, _) = load_memory(b"glTF junk", "glb");
    fails(status, TcbStatus::InvalidData, "");
    let (status, _) = load_memory(&[], "tcbc");
    fails(status, TcbStatus::InvalidData, "tcbc");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Loading from memory gives what loading the file gives; a packed clip
/// loads from bytes and from a `.tcbc` file and plays as `Clip::from_bytes`.
#[test]
fn memory_files_and_packed_clips() {
    // Kept whole: every load reads the same files from one temporary folder, removed at the end.
    let dir = std::env::temp_dir().join(format!("tcb-ffi-pack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bvh_path = dir.join("two.bvh");
    std::fs::write(&bvh_path, BVH).unwrap();
    let from_file = load(&bvh_path);
    let (status, from_memory) = load_memory(BVH.as_bytes(), "BVH");
    assert_eq!(status, TcbStatus::Ok);
    let sample = |clip: *const TcbClip, t: f64| {
        let inst = instance(clip, 0);
        // SAFETY: live handles and a row of the length given.
        unsafe {
            let mut row = vec![0.0f32; tcb_instance_channel_count(inst)];
            let status = tcb_instance_sample(inst, t, row.as_mut_ptr(), row.len());
            assert_eq!(status, TcbStatus::Ok);
            tcb_instance_free(inst);
            row
        }
    };
    assert_eq!(sample(from_file, 0.6), sample(from_memory, 0.6));

    // A clip file with a skeleton, from memory.
    let loaded = tcb_io::load(&bvh_path).unwrap();
    let json = loaded.doc.to_json();
    let (status, from_json) = load_memory(json.as_bytes(), "json");
    assert_eq!(status, TcbStatus::Ok, "{}", message());
    // SAFETY: a live clip.
    assert!(unsafe { tcb_clip_has_skeleton(from_json) });
    assert_eq!(sample(from_json, 0.6), sample(from_file, 0.6));

    // Packed: quantized in steps of 1e-4 and encoded.
    let keys = tcb_runtime::KeyValues::sample(&loaded.clip).unwrap();
    let source = keys
        .quantize(&vec![1e-4; loaded.clip.tracks().len()])
        .unwrap();
    let bytes = tcb_runtime::Packed::encode(&source).unwrap().to_bytes();
    let rust = Arc::new(tcb_runtime::Clip::from_bytes(&bytes).unwrap());
    let mut want = vec![0.0f32; rust.channel_count()];
    tcb_runtime::Instance::new(rust)
        .sample_to(0.6, &mut want)
        .unwrap();
    let (status, packed) = load_memory(&bytes, "tcbc");
    assert_eq!(status, TcbStatus::Ok, "{}", message());
    assert_eq!(sample(packed, 0.6), want);
    let tcbc_path = dir.join("two.tcbc");
    std::fs::write(&tcbc_path, &bytes).unwrap();
    let packed_file = load(&tcbc_path);
    assert_eq!(sample(packed_file, 0.6), want);
    // SAFETY: live handles.
    unsafe {
        assert!(!tcb_clip_has_skeleton(packed_file));
        // No skeleton of its own: take the BVH's.
        let mut skel = null_mut();
        let status = tcb_skeleton_new(packed_file, packed_file, &mut skel);
        fails(status, TcbStatus::NotFound, "no skeleton");
        assert!(skel.is_null());
        let status = tcb_skeleton_new(from_file, packed_file, &mut skel);
        assert_eq!(status, TcbStatus::Ok);
        let inst = instance(packed_file, 0);
        tcb_instance_update(inst, 0.6);
        let mut m = [0.0f32; 48];
        assert_eq!(
            tcb_skeleton_model_matrices(skel, inst, m.as_mut_ptr(), 48),
            TcbStatus::Ok
        );
        // The chain keeps its bone lengths (5 and 5), and the packed pose
        // is the BVH clip's within its quantization.
        let at = |m: &[f32], j: usize| glam::Vec3::from_slice(&m[16 * j + 12..16 * j + 15]);
        assert!(((at(&m, 1) - at(&m, 0)).length() - 5.0).abs() < 1e-5);
        assert!(((at(&m, 2) - at(&m, 1)).length() - 5.0).abs() < 1e-5);
        let mut bvh_skel = null_mut();
        assert_eq!(
            tcb_skeleton_new(from_file, from_file, &mut bvh_skel),
            TcbStatus::Ok
        );
        let bvh_inst = instance(from_file, 0);
        tcb_instance_update(bvh_inst, 0.6);
        let mut bvh_m = [0.0f32; 48];
        let status = tcb_skeleton_model_matrices(bvh_skel, bvh_inst, bvh_m.as_mut_ptr(), 48);
        assert_eq!(status, TcbStatus::Ok);
        for j in 0..3 {
            assert!((at(&m, j) - at(&bvh_m, j)).length() < 0.02, "joint {j}");
        }
        tcb_instance_free(bvh_inst);
        tcb_skeleton_free(bvh_skel);
        // An instance of the BVH clip has another layout than the packed one.
        let other = instance(from_file, 0);
        let status = tcb_skeleton_model_matrices(skel, other, m.as_mut_ptr(), 48);
        if status != TcbStatus::Ok {
            fails(status, TcbStatus::Mismatch, "layout");
        }
        tcb_instance_free(other);
        tcb_instance_free(inst);
        tcb_skeleton_free(skel);
        for clip in [from_file, from_memory, from_json, packed, packed_file] {
            tcb_clip_free(clip);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Rigs, blends, additive layers and playback: as the Rust API does them,
/// and mismatched layouts refused without a write.
#[test]
fn rigs_blends_and_playback() {
    // Kept whole: one set of rig, instance and pose handles runs through every step, then is freed in any order (itself checked).
    let (_, clip) = load_memory(BVH.as_bytes(), "bvh");
    let path = std::env::temp_dir().join(format!("tcb-ffi-rig-{}.bvh", std::process::id()));
    std::fs::write(&path, BVH).unwrap();
    let loaded = tcb_io::load(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let rust_rig =
        Arc::new(tcb_runtime::Rig::from_skeleton(loaded.skeleton.as_ref().unwrap()).unwrap());
    let rust_clip = Arc::new(tcb_runtime::Clip::compile(&loaded.clip));
    // SAFETY: live handles and buffers of the lengths given, throughout.
    unsafe {
        let mut rig = null_mut();
        assert_eq!(tcb_rig_from_skeleton(clip, &mut rig), TcbStatus::Ok);
        assert_eq!(tcb_rig_track_count(rig), 3 * 3);
        let rn = tcb_rig_channel_count(rig);
        assert_eq!(rn, 3 * (3 + 4 + 3));
        let mut info = TcbTrackInfo::default();
        let name = c("Spine.rotation");
        assert_eq!(
            tcb_rig_find_track(rig, name.as_ptr(), &mut info),
            TcbStatus::Ok
        );
        assert_eq!(
            (info.index, info.offset, info.kind),
            (4, 13, TcbTrackKind::Quat)
        );
        let mut buf = [0 as c_char; 32];
        assert_eq!(
            tcb_rig_track_name(rig, 4, buf.as_mut_ptr(), 32, null_mut()),
            TcbStatus::Ok
        );
        assert_eq!(CStr::from_ptr(buf.as_ptr()).to_str(), Ok("Spine.rotation"));

        let (mut a, mut b) = (null_mut(), null_mut());
        assert_eq!(
            tcb_instance_new_with_rig(clip, rig, 0, &mut a),
            TcbStatus::Ok
        );
        assert_eq!(
            tcb_instance_new_with_rig(clip, rig, 0, &mut b),
            TcbStatus::Ok
        );
        assert_eq!(tcb_instance_channel_count(a), rn);
        let mut pose = null_mut();
        assert_eq!(tcb_pose_new_for_rig(rig, 0, &mut pose), TcbStatus::Ok);
        assert_eq!(tcb_pose_channel_count(pose), rn);
        tcb_instance_update(a, 0.25);
        tcb_instance_update(b, 0.8);
        let layers = [a as *const _, b as *const _];
        let weights = [0.25f32, 0.75];
        assert_eq!(
            tcb_blend(pose, layers.as_ptr(), weights.as_ptr(), 2),
            TcbStatus::Ok
        );
        let mut row = vec![0.0f32; rn];
        assert_eq!(tcb_pose_read(pose, row.as_mut_ptr(), rn), TcbStatus::Ok);

        let mut ra = tcb_runtime::Instance::with_rig(rust_clip.clone(), &rust_rig).unwrap();
        let mut rb = tcb_runtime::Instance::with_rig(rust_clip.clone(), &rust_rig).unwrap();
        ra.sample(0.25);
        rb.sample(0.8);
        let mut out = rust_rig.rest_pose();
        tcb_runtime::blend(&mut out, &[(ra.pose(), 0.25), (rb.pose(), 0.75)], None).unwrap();
        let mut want = vec![0.0f32; rn];
        out.write_row(&mut want, None);
        assert_eq!(row, want);

        // Additive: b minus a at full weight onto the blend.
        assert_eq!(tcb_blend_add(pose, b, a, 1.0), TcbStatus::Ok);
        tcb_runtime::blend::add(&mut out, rb.pose(), ra.pose(), 1.0, None).unwrap();
        assert_eq!(tcb_pose_read(pose, row.as_mut_ptr(), rn), TcbStatus::Ok);
        out.write_row(&mut want, None);
        assert_eq!(row, want);

        // Covered: a clip of the Spine rotation alone weighs only there.
        let spine_json = r#"{"format": "tcb-clip/1", "tracks": [{"name": "Spine.rotation",
            "kind": "quat", "times": [0, 1], "values": [[0, 0, 0, 1], [0, 0, 0.6, 0.8]]}]}"#;
        let (_, spine_clip) = load_memory(spine_json.as_bytes(), "json");
        let mut spine = null_mut();
        let status = tcb_instance_new_with_rig(spine_clip, rig, 0, &mut spine);
        assert_eq!(status, TcbStatus::Ok);
        tcb_instance_update(spine, 0.5);
        let covered = [a as *const _, spine as *const _];
        let half = [0.5f32, 0.5];
        let status = tcb_blend_covered(pose, covered.as_ptr(), half.as_ptr(), 2);
        assert_eq!(status, TcbStatus::Ok);
        assert_eq!(tcb_pose_read(pose, row.as_mut_ptr(), rn), TcbStatus::Ok);
        let spine_rust = tcb_io::ClipDoc::parse(spine_json).unwrap().build().unwrap();
        let mut rs = tcb_runtime::Instance::with_rig(
            Arc::new(tcb_runtime::Clip::compile(&spine_rust)),
            &rust_rig,
        )
        .unwrap();
        rs.sample(0.5);
        let masks = [&ra.coverage_mask(), &rs.coverage_mask()];
        tcb_runtime::blend(
            &mut out,
            &[(ra.pose(), 0.5), (rs.pose(), 0.5)],
            Some(&masks),
        )
        .unwrap();
        out.write_row(&mut want, None);
        assert_eq!(row, want);
        // Hips.translation is a's alone; uncovered it would be pulled to rest.
        let mut a_row = vec![0.0f32; rn];
        tcb_instance_sample(a, 0.25, a_row.as_mut_ptr(), rn);
        assert_eq!(&row[..3], &a_row[..3]);
        assert_eq!(
            tcb_blend(pose, covered.as_ptr(), half.as_ptr(), 2),
            TcbStatus::Ok
        );
        assert_eq!(tcb_pose_read(pose, row.as_mut_ptr(), rn), TcbStatus::Ok);
        assert_ne!(&row[..3], &a_row[..3]);
        tcb_instance_free(spine);
        tcb_clip_free(spine_clip);

        // More layers than the stack holds.
        let many: Vec<*const TcbInstance> = (0..20).map(|i| layers[i % 2]).collect();
        let w = [1.0f32; 20];
        assert_eq!(
            tcb_blend(pose, many.as_ptr(), w.as_ptr(), 20),
            TcbStatus::Ok
        );

        // An instance without the rig has another layout: refused, pose unchanged.
        let plain = instance(clip, 0);
        tcb_pose_read(pose, want.as_mut_ptr(), rn);
        let mixed = [a as *const _, plain as *const _];
        let status = tcb_blend(pose, mixed.as_ptr(), weights.as_ptr(), 2);
        fails(status, TcbStatus::Mismatch, "layer 1");
        assert_eq!(tcb_pose_read(pose, row.as_mut_ptr(), rn), TcbStatus::Ok);
        assert_eq!(row, want);
        let status = tcb_blend_add(pose, plain, a, 1.0);
        fails(status, TcbStatus::Mismatch, "");
        // The clip's skeleton bound to the clip refuses a rig pose.
        let mut skel = null_mut();
        assert_eq!(tcb_skeleton_new(clip, clip, &mut skel), TcbStatus::Ok);
        let mut m = [0.0f32; 48];
        let status = tcb_skeleton_model_matrices_pose(skel, pose, m.as_mut_ptr(), 48);
        fails(status, TcbStatus::Mismatch, "tcb_skeleton_new_for_rig");
        let mut rig_skel = null_mut();
        assert_eq!(
            tcb_skeleton_new_for_rig(clip, rig, &mut rig_skel),
            TcbStatus::Ok
        );
        let status = tcb_skeleton_model_matrices_pose(rig_skel, pose, m.as_mut_ptr(), 48);
        assert_eq!(status, TcbStatus::Ok);
        assert!(m.iter().all(|x| x.is_finite()));
        // Velocities asked of a pose without them.
        let status = tcb_pose_read_velocities(pose, row.as_mut_ptr(), rn);
        fails(status, TcbStatus::InvalidArgument, "TCB_POSE_VELOCITIES");

        // A rig of the clip's own tracks; the rig refusing another clip.
        let mut clip_rig = null_mut();
        assert_eq!(tcb_rig_from_clip(clip, &mut clip_rig), TcbStatus::Ok);
        assert_eq!(tcb_rig_track_count(clip_rig), 3);
        let other_json = r#"{"format": "tcb-clip/1", "tracks": [
            {"name": "elsewhere", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#;
        let (_, other) = load_memory(other_json.as_bytes(), "json");
        let mut refused = null_mut();
        let status = tcb_instance_new_with_rig(other, clip_rig, 0, &mut refused);
        fails(status, TcbStatus::Mismatch, "elsewhere");
        let mut no_rig = null_mut();
        let status = tcb_rig_from_skeleton(other, &mut no_rig);
        fails(status, TcbStatus::NotFound, "skeleton");

        // Playback: ping-pong at 2x plays clip time 0.5 at t = 0.75 (keys 0..1).
        assert_eq!(
            tcb_instance_set_playback(plain, TcbPlayback::PingPong as u32, 2.0),
            TcbStatus::Ok
        );
        let pn = tcb_instance_channel_count(plain);
        let mut got = vec![0.0f32; pn];
        tcb_instance_sample(plain, 0.75, got.as_mut_ptr(), pn);
        let mut at = tcb_runtime::Instance::new(rust_clip.clone());
        let mut expect = vec![0.0f32; pn];
        at.sample_to(0.5, &mut expect).unwrap();
        assert_eq!(got, expect);
        fails(
            tcb_instance_set_playback(plain, 4, 1.0),
            TcbStatus::InvalidArgument,
            "mode 4",
        );
        fails(
            tcb_instance_set_playback(plain, 0, f64::NAN),
            TcbStatus::InvalidArgument,
            "NaN",
        );
        let status = tcb_instance_sample_with_velocities(
            plain,
            0.0,
            got.as_mut_ptr(),
            pn,
            expect.as_mut_ptr(),
            pn,
        );
        fails(
            status,
            TcbStatus::InvalidArgument,
            "TCB_INSTANCE_VELOCITIES",
        );

        // Handles freed in any order: the instances keep the clip and rig alive.
        tcb_clip_free(clip);
        tcb_rig_free(rig);
        assert_eq!(
            tcb_instance_sample(a, 0.5, row.as_mut_ptr(), rn),
            TcbStatus::Ok
        );
        for h in [a, b, plain] {
            tcb_instance_free(h);
        }
        tcb_skeleton_free(skel);
        tcb_skeleton_free(rig_skel);
        tcb_pose_free(pose);
        tcb_rig_free(clip_rig);
        tcb_clip_free(other);
    }
}

/// glTF animations chosen by name or index; BVH rotations as hermite.
#[test]
fn import_options() {
    let gltf = c(data("simple_skin.gltf").to_str().unwrap());
    let load_animation = |animation: Option<&str>| {
        let name = animation.map(c);
        let mut clip = null_mut();
        let a = name.as_ref().map_or(null(), |n| n.as_ptr());
        // SAFETY: NUL-terminated strings or NULL, and a writable out pointer.
        let status = unsafe { tcb_clip_load_file_animation(gltf.as_ptr(), a, 0, &mut clip) };
        (status, clip)
    };
    for animation in [None, Some("0")] {
        let (status, clip) = load_animation(animation);
        assert_eq!(status, TcbStatus::Ok, "{}", message());
        // SAFETY: a live clip.
        unsafe {
            assert!(tcb_clip_has_skeleton(clip));
            assert!(tcb_clip_track_count(clip) > 0);
            tcb_clip_free(clip);
        }
    }
    let (status, clip) = load_animation(Some("nope"));
    fails(status, TcbStatus::InvalidData, "nope");
    assert!(clip.is_null());

    let path = data("cmu-01_01.bvh");
    let p = c(path.to_str().unwrap());
    let mut clip = null_mut();
    // SAFETY: a NUL-terminated path and a writable out pointer.
    let status = unsafe { tcb_clip_load_file(p.as_ptr(), TCB_LOAD_HERMITE_ROTATIONS, &mut clip) };
    assert_eq!(status, TcbStatus::Ok);
    let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
    let loaded = tcb_io::load_with(&path, &options).unwrap();
    let mut rust = tcb_runtime::Instance::new(Arc::new(tcb_runtime::Clip::compile(&loaded.clip)));
    let inst = instance(clip, 0);
    // SAFETY: live handles and rows of the lengths given.
    unsafe {
        let n = tcb_instance_channel_count(inst);
        let (mut row, mut want) = (vec![0.0f32; n], vec![0.0f32; n]);
        assert_eq!(
            tcb_instance_sample(inst, 2.2, row.as_mut_ptr(), n),
            TcbStatus::Ok
        );
        rust.sample_to(2.2, &mut want).unwrap();
        assert_eq!(row, want);
        tcb_instance_free(inst);
        tcb_clip_free(clip);
    }
}
