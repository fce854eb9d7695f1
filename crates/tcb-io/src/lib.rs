//! # tcb-io
//!
//! The clip file (`tcb-clip/1` JSON, the project's `docs/clip-format.md`):
//! parsing with errors that name the file, the track and the key, building
//! validated [`tcb_core::SourceClip`]s, and writing clips without leaving
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
pub mod clip_json;
pub mod error;
mod files;
pub mod gltf_export;
pub mod gltf_import;
mod json;
mod skeleton_json;

pub use clip_json::{
    ClipDoc, KeyDoc, SettingsDoc, TrackDoc, load_clip, read_clip_doc, write_clip_doc,
};
pub use error::{Error, ErrorKind, Location};
pub use files::{DEFAULT_MAX_FILE_BYTES, ImportOptions, write_atomically};

use files::read_limited;
use std::path::Path;
use tcb_core::skeleton::Skeleton;

/// A clip file, BVH or glTF file, read and validated.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The clip as a document (what `tcb import` writes).
    pub doc: ClipDoc,
    /// The source clip, built and validated (`tcb_runtime::Clip::compile`
    /// makes the compiled clip a game plays).
    pub clip: tcb_core::SourceClip,
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
    let Some(format) = Format::from_extension(&ext) else {
        let message = if ext.is_empty() {
            "no file extension to tell its type (expected .json, .bvh, .gltf or .glb)".to_string()
        } else {
            format!("unknown file type '.{ext}' (expected .json, .bvh, .gltf or .glb)")
        };
        return Err(Error::import(message).in_file(path));
    };
    let bytes = read_limited(path, options.max_file_bytes)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let (doc, warnings) =
        read_doc(&bytes, format, Some(base), &stem, options).map_err(|e| e.in_file(path))?;
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

/// What a file holds, for [`load_bytes`] ([`load`] tells it by extension).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Format {
    /// Clip JSON (`.json`, `docs/clip-format.md`).
    Json,
    /// BVH motion capture (`.bvh`).
    Bvh,
    /// glTF, as JSON (`.gltf`) or binary (`.glb`): the bytes tell which.
    Gltf,
}

impl Format {
    /// The format of a file extension (without the dot, any case): `json`,
    /// `bvh`, `gltf` or `glb`; `None` for any other.
    ///
    /// ```
    /// use tcb_io::Format;
    /// assert_eq!(Format::from_extension("GLB"), Some(Format::Gltf));
    /// assert_eq!(Format::from_extension("tcbc"), None); // tcb_runtime::Clip::from_bytes
    /// ```
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "json" => Some(Format::Json),
            "bvh" => Some(Format::Bvh),
            "gltf" | "glb" => Some(Format::Gltf),
            _ => None,
        }
    }
}

/// [`load_with`] from bytes in memory (an engine's asset reader, a
/// network buffer): `format` says what they are, `name` names a BVH
/// clip (and a glTF animation that has no name of its own; a clip JSON
/// names itself). A glTF file's buffers must be in the bytes (`.glb`) or
/// `data:` URIs: with no folder to resolve them in, external buffer files
/// are an error. Bytes above `options.max_file_bytes` are refused. Errors
/// and warnings name no file: add it with [`Error::in_file`].
///
/// ```
/// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
/// # /*
/// let path = "data/cmu-01_01.bvh"; // from the repository's root
/// # */
/// let bytes = std::fs::read(path).unwrap();
/// let options = tcb_io::ImportOptions::default();
/// let loaded = tcb_io::load_bytes(&bytes, tcb_io::Format::Bvh, "walk", &options)?;
/// assert_eq!(loaded.doc.name, "walk");
/// assert_eq!(loaded.skeleton.unwrap().joints().len(), 31 + 7);
/// # Ok::<(), tcb_io::Error>(())
/// ```
pub fn load_bytes(
    bytes: &[u8],
    format: Format,
    name: &str,
    options: &ImportOptions,
) -> Result<Loaded, Error> {
    let (len, limit) = (bytes.len() as u64, options.max_file_bytes);
    if len > limit {
        return Err(Error::import(format!(
            "{len} bytes; files above {limit} bytes are refused (ImportOptions::max_file_bytes)"
        )));
    }
    let (doc, warnings) = read_doc(bytes, format, None, name, options)?;
    let clip = doc.build()?;
    Ok(Loaded {
        skeleton: doc.skeleton.clone(),
        doc,
        clip,
        warnings,
    })
}

/// The document and warnings of `bytes` in `format`, errors naming no
/// file; `base` resolves a glTF file's external buffers.
fn read_doc(
    bytes: &[u8],
    format: Format,
    base: Option<&Path>,
    name: &str,
    options: &ImportOptions,
) -> Result<(ClipDoc, Vec<String>), Error> {
    let text = || {
        std::str::from_utf8(bytes).map_err(|_| Error {
            location: Location::default(),
            kind: ErrorKind::Io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                "stream did not contain valid UTF-8",
            )),
        })
    };
    Ok(match format {
        Format::Json => (ClipDoc::parse(text()?)?, Vec::new()),
        Format::Bvh => {
            let bvh = bvh::Bvh::parse(bvh::text(bytes)?)?;
            let doc = bvh.to_clip_doc(name, options.rotation)?;
            (doc, bvh.warnings().to_vec())
        }
        Format::Gltf => {
            let g = gltf_import::import_with(bytes, base, name, options)?;
            (g.doc, g.warnings)
        }
    })
}
