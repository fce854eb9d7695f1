//! # tcb-io
//!
//! The clip file (`tcb-clip/1` JSON, the project's `docs/clip-format.md`):
//! parsing with errors that name the file, the track and the key, building
//! validated [`tcb_core::Clip`]s, and writing clips without leaving
//! half-written files.
//!
//! ```
//! let text = r#"{
//!   "format": "tcb-clip/1",
//!   "tracks": [{"name": "x", "kind": "scalar", "times": [0, 1], "values": [0, 2]}]
//! }"#;
//! let clip = tcb_io::ClipDoc::parse(text)?.build()?;
//! let mut row = [0.0f32];
//! clip.sample_into(0.5, &mut row, None);
//! assert_eq!(row, [1.0]);
//!
//! let bad = r#"{"format": "tcb-clip/1",
//!   "tracks": [{"name": "x", "kind": "scalar", "times": [0, 0], "values": [0, 2]}]}"#;
//! let err = tcb_io::ClipDoc::parse(bad)?.build().unwrap_err();
//! assert_eq!(err.to_string(), "track 'x': key 1: time 0 is not after the previous key's time 0 (times must strictly increase)");
//! # Ok::<(), tcb_io::Error>(())
//! ```

#![forbid(unsafe_code)]

pub mod bvh;
pub mod clip;
pub mod error;
pub mod gltf_export;
pub mod gltf_import;
mod skeleton_json;

pub use clip::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc, load_clip, read_clip_doc, write_clip_doc};
pub use error::{Error, ErrorKind, Location};

use std::io::Write;
use std::path::Path;
use tcb_core::RotationMode;
use tcb_core::skeleton::Skeleton;

/// Files larger than this are refused unread (1 GiB; the bundled CMU
/// capture, 2752 frames of 31 joints, is 2 MB). [`ImportOptions::max_file_bytes`]
/// raises it for [`load_with`].
pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 30;

/// Choices for importing other formats (see [`load_with`]).
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Rotation mode of BVH rotation tracks (default `squad`).
    pub rotation: RotationMode,
    /// glTF animation to import, by name or index (default: the first).
    pub animation: Option<String>,
    /// Largest file read, in bytes (default [`DEFAULT_MAX_FILE_BYTES`]).
    pub max_file_bytes: u64,
    /// glTF: let buffer URIs name files outside the `.gltf`'s folder
    /// (absolute paths, `..`, symbolic links out of it); default `false`,
    /// for a trusted asset tree only (`--allow-outside-paths`).
    pub allow_outside_paths: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            rotation: RotationMode::default(),
            animation: None,
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            allow_outside_paths: false,
        }
    }
}

/// The bytes of `path`, refusing (unread) a file larger than `limit`.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, Error> {
    use std::io::Read;
    let too_big = |len: u64| {
        Error::import(format!(
            "{len} bytes; files above {limit} bytes are refused (ImportOptions::max_file_bytes)"
        ))
        .in_file(path)
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    if len > limit {
        return Err(too_big(len));
    }
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_limited`] as UTF-8 text.
pub(crate) fn read_text_limited(path: &Path, limit: u64) -> Result<String, Error> {
    String::from_utf8(read_limited(path, limit)?).map_err(|_| {
        let e = std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        );
        Error::io(path, e)
    })
}

/// A clip file, BVH or glTF file, read and validated.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The clip as a document (what `tcb import` writes).
    pub doc: ClipDoc,
    /// The clip, built and validated.
    pub clip: tcb_core::Clip,
    /// The joint hierarchy: the clip's `skeleton` (BVH and glTF imports
    /// fill it; BVH End Sites are leaf joints `<parent>_end` after the
    /// joints, [`bvh::Bvh::skeleton_with_end_sites`]).
    pub skeleton: Option<Skeleton>,
    /// Things that were read but look wrong, for the user to see.
    pub warnings: Vec<String>,
}

/// Load a clip (`.json`), a BVH file (`.bvh`) or a glTF file (`.gltf`,
/// `.glb`), by extension, with default [`ImportOptions`].
///
/// ```
/// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
/// # /*
/// let path = "data/cmu-01_01.bvh"; // from the repository's root
/// # */
/// let loaded = tcb_io::load(path)?; // a &str, String, &Path or PathBuf
/// assert_eq!(loaded.skeleton.unwrap().joints.len(), 31 + 7); // joints and End Sites
/// assert_eq!(loaded.clip.tracks()[0].name, "Hips.translation");
/// # Ok::<(), tcb_io::Error>(())
/// ```
///
/// A BVH file's skeleton is [`bvh::Bvh::skeleton_with_end_sites`]: the
/// joints of [`bvh::Bvh::skeleton`] at the same indices, then one leaf
/// joint `<parent>_end` per End Site.
pub fn load(path: impl AsRef<Path>) -> Result<Loaded, Error> {
    load_with(path, &ImportOptions::default())
}

/// [`load`] with options.
pub fn load_with(path: impl AsRef<Path>, options: &ImportOptions) -> Result<Loaded, Error> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (doc, warnings) = match ext.as_str() {
        "json" => (
            clip::read_clip_doc_limited(path, options.max_file_bytes)?,
            Vec::new(),
        ),
        "bvh" => {
            let text = read_text_limited(path, options.max_file_bytes)?;
            let bvh = bvh::Bvh::parse(&text).map_err(|e| e.in_file(path))?;
            let doc = bvh
                .to_clip_doc(&stem, options.rotation)
                .map_err(|e| e.in_file(path))?;
            (doc, bvh.warnings().to_vec())
        }
        "gltf" | "glb" => {
            let bytes = read_limited(path, options.max_file_bytes)?;
            let base = path.parent().unwrap_or(Path::new("."));
            let g = gltf_import::import_with(&bytes, Some(base), &stem, options)
                .map_err(|e| e.in_file(path))?;
            (g.doc, g.warnings)
        }
        "" => {
            return Err(Error::import(
                "no file extension to tell its type (expected .json, .bvh, .gltf or .glb)",
            )
            .in_file(path));
        }
        _ => {
            return Err(Error::import(format!(
                "unknown file type '.{ext}' (expected .json, .bvh, .gltf or .glb)"
            ))
            .in_file(path));
        }
    };
    let clip = doc.build().map_err(|e| e.in_file(path))?;
    // Warnings name the file, like errors.
    let warnings = warnings
        .into_iter()
        .map(|w| format!("{}: {w}", path.display()))
        .collect();
    Ok(Loaded {
        skeleton: doc.skeleton.clone(),
        doc,
        clip,
        warnings,
    })
}

/// Write `bytes` to `path` through a temporary file in the same directory,
/// renamed over `path` only once everything is written and synced.
pub fn write_atomically(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(), Error> {
    let path = path.as_ref();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}
