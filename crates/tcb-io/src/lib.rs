//! # tcb-io
//!
//! The clip file (`tcb-clip/1` JSON, the project's `docs/clip-format.md`):
//! parsing with errors that name the file, the track and the key, building
//! validated [`tcb_core::Clip`]s, and writing clips without leaving
//! half-written files; BVH and glTF import, glTF export.
//!
//! Most programs start with [`load`]: a clip file, BVH or glTF by its
//! extension, with its skeleton when the file has one.
//!
//! ```
//! # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
//! # /*
//! let path = "data/cmu-01_01.bvh"; // from the repository's root
//! # */
//! let loaded = tcb_io::load(path)?;
//! println!("{} tracks, {} joints", loaded.clip.tracks().len(), loaded.skeleton.map_or(0, |s| s.joints().len()));
//! # Ok::<(), tcb_io::Error>(())
//! ```
//!
//! A clip from text, and the one-line errors of a bad one:
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
mod files;
pub mod gltf_export;
pub mod gltf_import;
mod json;
mod skeleton_json;

pub use clip::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc, load_clip, read_clip_doc, write_clip_doc};
pub use error::{Error, ErrorKind, Location};
pub use files::{DEFAULT_MAX_FILE_BYTES, ImportOptions, write_atomically};

use files::{read_limited, read_text_limited};
use std::path::Path;
use tcb_core::skeleton::Skeleton;

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
/// assert_eq!(loaded.skeleton.unwrap().joints().len(), 31 + 7); // joints and End Sites
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
