//! Files read and written: [`ImportOptions`], the size limit on files
//! read, and writes that leave either the old file or the new one.

use crate::error::Error;
use std::io::Write;
use std::path::Path;
use tcb_core::RotationMode;

/// Files larger than this are refused unread (1 GiB; the bundled CMU
/// capture, 2752 frames of 31 joints, is 2 MB). [`ImportOptions::max_file_bytes`]
/// raises it for [`load_with`](crate::load_with).
pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 30;

/// Choices for importing other formats (see [`load_with`](crate::load_with)).
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
