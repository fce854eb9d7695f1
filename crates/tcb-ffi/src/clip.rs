//! Clips: loaded from a file or from memory and compiled for the runtime,
//! with the track queries that lay out a sampled row.

use crate::error::{Failure, Result, TcbStatus, guard, guard_value};
use crate::layout::{self, TcbTrackInfo};
use crate::ptr;
use std::ffi::c_char;
use std::path::Path;
use std::sync::Arc;
use tcb_core::skeleton::Skeleton;
use tcb_runtime::{Clip, CompileOptions};

/// `tcb_clip_load_*` flag: store the clip's controls in 16 bits where
/// that stays within the runtime's error bound (`CompileOptions::quantize`).
/// Ignored for `.tcbc` files, which are packed already.
pub const TCB_LOAD_QUANTIZE: u32 = 1;
/// `tcb_clip_load_*` flag: velocities of squad rotations from squad's own
/// derivative in f64 rather than the played cubic's (slower; for comparing
/// velocities with another implementation). Ignored for `.tcbc` files.
pub const TCB_LOAD_EXACT_VELOCITIES: u32 = 2;

/// `tcb_clip_load_*` flag: import BVH rotations as `hermite` tracks (one
/// cubic per segment, the fastest to sample) rather than the default
/// `squad` (`tcb import --rotation hermite`). Other formats keep theirs.
pub const TCB_LOAD_HERMITE_ROTATIONS: u32 = 4;

/// A compiled clip, ready to be played by instances, and the skeleton its
/// file carried (if any). Immutable once loaded: one clip may be used by
/// any number of instances on any threads at once. Instances, rigs and
/// skeletons made from it keep what they need, so it may be freed before them.
pub struct TcbClip {
    pub(crate) clip: Arc<Clip>,
    pub(crate) skeleton: Option<Skeleton>,
}

fn compile_options(flags: u32) -> Result<CompileOptions> {
    let known = TCB_LOAD_QUANTIZE | TCB_LOAD_EXACT_VELOCITIES | TCB_LOAD_HERMITE_ROTATIONS;
    if flags & !known != 0 {
        return Err(Failure::invalid(format!(
            "unknown load flags {:#x}",
            flags & !known
        )));
    }
    Ok(CompileOptions::default()
        .quantize(flags & TCB_LOAD_QUANTIZE != 0)
        .exact_velocities(flags & TCB_LOAD_EXACT_VELOCITIES != 0))
}

fn packed(bytes: &[u8], origin: &str) -> Result<TcbClip> {
    let clip = Clip::from_bytes(bytes)
        .map_err(|e| Failure::new(TcbStatus::InvalidData, format!("{origin}: {e}")))?;
    let skeleton = clip.packed().and_then(|p| p.skeleton.clone());
    Ok(TcbClip {
        clip: Arc::new(clip),
        skeleton,
    })
}

fn compiled(
    clip: &tcb_core::SourceClip,
    skeleton: Option<Skeleton>,
    flags: u32,
) -> Result<TcbClip> {
    let options = compile_options(flags)?;
    Ok(TcbClip {
        clip: Arc::new(Clip::compile_with(clip, &options)),
        skeleton,
    })
}

/// The BVH rotation mode `flags` ask for.
fn rotation(flags: u32) -> tcb_core::RotationMode {
    if flags & TCB_LOAD_HERMITE_ROTATIONS != 0 {
        tcb_core::RotationMode::Hermite
    } else {
        tcb_core::RotationMode::default()
    }
}

fn load_file(path: &str, animation: Option<&str>, flags: u32) -> Result<TcbClip> {
    let path = Path::new(path);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if ext.as_deref() == Some("tcbc") {
        compile_options(flags)?;
        let io =
            |e: std::io::Error| Failure::new(TcbStatus::Io, format!("{}: {e}", path.display()));
        let size = std::fs::metadata(path).map_err(io)?.len();
        if size > tcb_io::DEFAULT_MAX_FILE_BYTES {
            return Err(Failure::new(
                TcbStatus::InvalidData,
                format!(
                    "{}: {size} bytes; files above {} bytes are refused",
                    path.display(),
                    tcb_io::DEFAULT_MAX_FILE_BYTES
                ),
            ));
        }
        let bytes = std::fs::read(path).map_err(io)?;
        return packed(&bytes, &path.display().to_string());
    }
    let options = tcb_io::ImportOptions::default()
        .rotation(rotation(flags))
        .animation(animation.map(str::to_string));
    let loaded = tcb_io::load_with(path, &options)?;
    compiled(&loaded.clip, loaded.skeleton, flags)
}

fn load_memory(bytes: &[u8], format: &str, flags: u32) -> Result<TcbClip> {
    let text = || {
        std::str::from_utf8(bytes)
            .map_err(|e| Failure::new(TcbStatus::InvalidData, format!("{format} text: {e}")))
    };
    let (clip, skeleton) = match format.to_ascii_lowercase().as_str() {
        "tcbc" => {
            compile_options(flags)?;
            return packed(bytes, "tcbc bytes");
        }
        "json" => {
            let doc = tcb_io::ClipDoc::parse(text()?)?;
            (doc.build()?, doc.skeleton)
        }
        "bvh" => {
            // As `tcb_clip_load_file` reads a BVH file (bytes that are not
            // text are "not a BVH file").
            let options = tcb_io::ImportOptions::default().rotation(rotation(flags));
            let loaded = tcb_io::load_bytes(bytes, tcb_io::Format::Bvh, "clip", &options)?;
            (loaded.clip, loaded.skeleton)
        }
        "gltf" | "glb" => {
            let options = tcb_io::ImportOptions::default();
            let doc = tcb_io::gltf_import::import_with(bytes, None, "clip", &options)?.doc;
            (doc.build()?, doc.skeleton)
        }
        other => {
            return Err(Failure::invalid(format!(
                "unknown format {other:?} (expected \"json\", \"bvh\", \"gltf\", \"glb\" or \"tcbc\")"
            )));
        }
    };
    compiled(&clip, skeleton, flags)
}

/// Load a clip file and compile it: by extension, a clip (`.json`), BVH
/// (`.bvh`) or glTF (`.gltf`, `.glb`; the first animation) file, imported
/// as `tcb import` does, or a packed `.tcbc` file (played from its packed
/// stream). BVH and glTF files, clip files with a `skeleton` and `.tcbc`
/// files written from those give the clip a skeleton
/// (`tcb_clip_has_skeleton`).
///
/// `path` is a NUL-terminated UTF-8 path; `flags` is 0 or an OR of
/// `TCB_LOAD_*`. On success `*out` is a new clip, to be freed with
/// `tcb_clip_free`; on failure `*out` is NULL and the status says why
/// (`TCB_STATUS_IO`: unreadable; `TCB_STATUS_INVALID_DATA`: not a valid clip).
///
/// # Safety
///
/// `path` is NULL or a NUL-terminated string; `out` is NULL or valid for
/// writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_load_file(
    path: *const c_char,
    flags: u32,
    out: *mut *mut TcbClip,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: `path` is NULL or NUL-terminated, as the caller promises.
        let path = unsafe { ptr::str(path, "path")? };
        let clip = load_file(path, None, flags)?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, clip) };
        Ok(())
    })
}

/// `tcb_clip_load_file` of one animation of a glTF file: `animation` is its
/// name or its index as text (`"walk"`, `"2"`); NULL takes the first, as
/// `tcb_clip_load_file` does. A name the file lacks is
/// `TCB_STATUS_INVALID_DATA`, with the file's animations in the message.
/// Other formats ignore `animation`.
///
/// # Safety
///
/// `path` is NULL or a NUL-terminated string; `animation` is NULL or a
/// NUL-terminated string; `out` is NULL or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_load_file_animation(
    path: *const c_char,
    animation: *const c_char,
    flags: u32,
    out: *mut *mut TcbClip,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: `path` is NULL or NUL-terminated, as the caller promises.
        let path = unsafe { ptr::str(path, "path")? };
        let animation = match animation.is_null() {
            true => None,
            // SAFETY: non-NULL and NUL-terminated, as the caller promises.
            false => Some(unsafe { ptr::str(animation, "animation")? }),
        };
        let clip = load_file(path, animation, flags)?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, clip) };
        Ok(())
    })
}

/// Load a clip from `len` bytes in memory and compile it. `format` names
/// what the bytes are: `"json"` (a clip file), `"bvh"`, `"gltf"` or `"glb"`
/// (external buffers are refused: only data URIs and the GLB blob are
/// read) or `"tcbc"` (a packed clip). `flags` as `tcb_clip_load_file`. The
/// bytes are not kept: they may be freed when this returns.
///
/// # Safety
///
/// `bytes` is NULL or points to `len` readable bytes (any pointer when
/// `len` is 0); `format` is NULL or a NUL-terminated string; `out` is NULL
/// or valid for writing a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_load_memory(
    bytes: *const u8,
    len: usize,
    format: *const c_char,
    flags: u32,
    out: *mut *mut TcbClip,
) -> TcbStatus {
    guard(|| {
        // SAFETY: `out` is NULL or writable, as the caller promises.
        unsafe { ptr::clear_out(out, "out")? };
        // SAFETY: `format` is NULL or NUL-terminated, as the caller promises.
        let format = unsafe { ptr::str(format, "format")? };
        // SAFETY: `bytes` is NULL or `len` readable bytes, as the caller promises.
        let bytes = unsafe { ptr::slice(bytes, len, "bytes")? };
        let clip = load_memory(bytes, format, flags)?;
        // SAFETY: checked by `clear_out` above.
        unsafe { ptr::give(out, clip) };
        Ok(())
    })
}

/// Free a clip (NULL is ignored). Instances, rigs and skeletons made from
/// it stay valid.
///
/// # Safety
///
/// `clip` is NULL or a clip from `tcb_clip_load_*` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_free(clip: *mut TcbClip) {
    guard(|| {
        // SAFETY: NULL or a live clip handle, freed once, as the caller promises.
        unsafe { ptr::free(clip) };
        Ok(())
    });
}

/// The clip, or a failure if `clip` is NULL.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle.
unsafe fn get<'a>(clip: *const TcbClip) -> Result<&'a TcbClip> {
    // SAFETY: as the caller promises.
    unsafe { ptr::get(clip, "clip") }
}

/// Number of tracks of the clip (0 if `clip` is NULL).
///
/// # Safety
///
/// `clip` is NULL or a live clip handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_track_count(clip: *const TcbClip) -> usize {
    // SAFETY: NULL or a live clip handle, as the caller promises.
    guard_value(0, || Ok(unsafe { get(clip)? }.clip.tracks().len()))
}

/// Floats in one sampled row of the clip (the length `tcb_instance_sample`
/// wants from an instance without a rig): every track's components, a
/// rotation counting 4 (0 if `clip` is NULL).
///
/// # Safety
///
/// `clip` is NULL or a live clip handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_channel_count(clip: *const TcbClip) -> usize {
    // SAFETY: NULL or a live clip handle, as the caller promises.
    guard_value(0, || {
        Ok(layout::channel_count(unsafe { get(clip)? }.clip.layout()))
    })
}

/// Where track `index` (in file order) lives in a sampled row of the clip.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `info` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_track_info(
    clip: *const TcbClip,
    index: usize,
    info: *mut TcbTrackInfo,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let found = layout::info(unsafe { get(clip)? }.clip.layout(), index)?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(info, found, "info") }
    })
}

/// The track called `name` (a NUL-terminated string such as
/// `"Hips.translation"`): its index, kind and place in a sampled row.
/// `TCB_STATUS_NOT_FOUND` if the clip has no such track.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `name` is NULL or NUL-terminated;
/// `info` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_find_track(
    clip: *const TcbClip,
    name: *const c_char,
    info: *mut TcbTrackInfo,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let clip = unsafe { get(clip)? };
        // SAFETY: NULL or NUL-terminated, as the caller promises.
        let name = unsafe { ptr::str(name, "name")? };
        let found = layout::find(clip.clip.layout(), name)?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe { ptr::put(info, found, "info") }
    })
}

/// Copy the name of track `index` into `buf` (`buf_len` bytes) as a
/// NUL-terminated string, and its length in bytes (without the NUL) into
/// `*name_len` if `name_len` is not NULL. A buffer shorter than the name
/// and its NUL gives `TCB_STATUS_BUFFER_LENGTH`, with `*name_len` set and
/// nothing written: call with `buf_len` 0 to learn the length.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `buf` is NULL or valid for
/// `buf_len` bytes of writes; `name_len` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_track_name(
    clip: *const TcbClip,
    index: usize,
    buf: *mut c_char,
    buf_len: usize,
    name_len: *mut usize,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let name = layout::name(unsafe { get(clip)? }.clip.layout(), index)?;
        // SAFETY: as the caller promises.
        unsafe { ptr::copy_str(name, buf, buf_len, name_len) }
    })
}

/// The clip's first and last key times, in seconds, into `*start` and
/// `*end` (`TCB_STATUS_NOT_FOUND` for a clip without keys).
///
/// # Safety
///
/// `clip` is NULL or a live clip handle; `start` and `end` are NULL or
/// valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_time_range(
    clip: *const TcbClip,
    start: *mut f64,
    end: *mut f64,
) -> TcbStatus {
    guard(|| {
        // SAFETY: NULL or a live clip handle, as the caller promises.
        let clip = unsafe { get(clip)? };
        let (t0, t1) = clip
            .clip
            .time_range()
            .ok_or_else(|| Failure::new(TcbStatus::NotFound, "the clip has no keys"))?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe {
            ptr::put(start, t0, "start")?;
            ptr::put(end, t1, "end")
        }
    })
}

/// Whether the clip's file carried a skeleton (BVH and glTF files do, clip
/// files may, `.tcbc` files do not); false if `clip` is NULL.
///
/// # Safety
///
/// `clip` is NULL or a live clip handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn tcb_clip_has_skeleton(clip: *const TcbClip) -> bool {
    // SAFETY: NULL or a live clip handle, as the caller promises.
    guard_value(false, || Ok(unsafe { get(clip)? }.skeleton.is_some()))
}
