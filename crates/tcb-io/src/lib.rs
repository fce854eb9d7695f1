//! # tcb-io
//!
//! The clip file (`tcb-clip/1` JSON, the project's `spec/clip-format.md`):
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

pub mod clip;
pub mod error;

pub use clip::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc, load_clip, read_clip_doc, write_clip_doc};
pub use error::{Error, ErrorKind, Location};

use std::io::Write;
use std::path::Path;

/// Write `bytes` to `path` through a temporary file in the same directory,
/// renamed over `path` only once everything is written and synced.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), Error> {
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

/// The README's example, compiled as a doctest so that it stays true.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
