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
///
/// Start from [`Default`] and set fields with the builder methods, so that
/// a field added later does not break the code that builds these:
///
/// ```
/// let options = tcb_io::ImportOptions::default()
///     .animation(Some("walk".to_string()))
///     .allow_outside_paths(true);
/// assert_eq!(options.animation.as_deref(), Some("walk"));
/// assert!(options.allow_outside_paths);
/// ```
///
/// The struct is `#[non_exhaustive]`: a struct literal does not compile
/// outside this crate.
///
/// ```compile_fail
/// let options = tcb_io::ImportOptions {
///     allow_outside_paths: true,
///     ..Default::default()
/// };
/// ```
#[derive(Clone, Debug)]
#[non_exhaustive]
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

impl ImportOptions {
    /// These options with [`rotation`](Self::rotation) set to `mode`.
    #[must_use]
    pub fn rotation(mut self, mode: RotationMode) -> Self {
        self.rotation = mode;
        self
    }

    /// These options with [`animation`](Self::animation) set to `name` (`None`: the first).
    #[must_use]
    pub fn animation(mut self, name: Option<String>) -> Self {
        self.animation = name;
        self
    }

    /// These options with [`max_file_bytes`](Self::max_file_bytes) set to `bytes`.
    #[must_use]
    pub fn max_file_bytes(mut self, bytes: u64) -> Self {
        self.max_file_bytes = bytes;
        self
    }

    /// These options with [`allow_outside_paths`](Self::allow_outside_paths) set to `on`.
    #[must_use]
    pub fn allow_outside_paths(mut self, on: bool) -> Self {
        self.allow_outside_paths = on;
        self
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
