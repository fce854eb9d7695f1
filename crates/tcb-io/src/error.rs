//! Errors that name the file, the track and the key.

use std::fmt;
use std::path::{Path, PathBuf};
use tcb_core::TrackError;

/// Where in a clip file a problem is.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Location {
    /// The file (`None` for text parsed from memory).
    pub file: Option<PathBuf>,
    /// The track's name, or `#i` when it has none yet.
    pub track: Option<String>,
    /// The key index.
    pub key: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(file) = &self.file {
            parts.push(file.display().to_string());
        }
        if let Some(track) = &self.track {
            parts.push(format!("track {track}"));
        }
        if let Some(key) = self.key {
            parts.push(format!("key {key}"));
        }
        f.write_str(&parts.join(": "))
    }
}

/// What went wrong.
#[derive(Debug)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read or written.
    Io(std::io::Error),
    /// Not JSON.
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// serde_json's message.
        message: String,
    },
    /// A field that is missing, of the wrong type or shape, or unknown.
    Invalid(String),
    /// Data a track cannot be built from.
    Track(TrackError),
    /// A text format (BVH) that cannot be read at a line.
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong there.
        message: String,
    },
    /// A file that cannot be imported as a whole (glTF structure, sizes).
    Import(String),
}

/// A clip file problem, with its location.
#[derive(Debug)]
pub struct Error {
    /// Where.
    pub location: Location,
    /// What.
    pub kind: ErrorKind,
}

impl Error {
    pub(crate) fn invalid(location: Location, message: impl Into<String>) -> Self {
        Error {
            location,
            kind: ErrorKind::Invalid(message.into()),
        }
    }

    pub(crate) fn syntax(line: usize, message: impl Into<String>) -> Self {
        Error {
            location: Location::default(),
            kind: ErrorKind::Syntax {
                line,
                message: message.into(),
            },
        }
    }

    /// A file that cannot be imported or used as a whole, with a message.
    pub fn import(message: impl Into<String>) -> Self {
        Error {
            location: Location::default(),
            kind: ErrorKind::Import(message.into()),
        }
    }

    pub(crate) fn io(file: &Path, e: std::io::Error) -> Self {
        Error {
            location: Location {
                file: Some(file.to_path_buf()),
                ..Location::default()
            },
            kind: ErrorKind::Io(e),
        }
    }

    /// Attach the file name (for errors from text parsed in memory).
    pub fn in_file(mut self, file: impl AsRef<Path>) -> Self {
        self.location.file = Some(file.as_ref().to_path_buf());
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // A track error carries its own key; show it once.
        let mut loc = self.location.clone();
        if let ErrorKind::Track(e) = &self.kind
            && e.key().is_some()
        {
            loc.key = None;
        }
        let loc = loc.to_string();
        if !loc.is_empty() {
            write!(f, "{loc}: ")?;
        }
        match &self.kind {
            ErrorKind::Io(e) => write!(f, "{e}"),
            ErrorKind::Json {
                line,
                column,
                message,
            } => write!(f, "line {line}, column {column}: {message}"),
            ErrorKind::Invalid(m) => f.write_str(m),
            ErrorKind::Track(e) => write!(f, "{e}"),
            ErrorKind::Syntax { line, message } => write!(f, "line {line}: {message}"),
            ErrorKind::Import(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            ErrorKind::Io(e) => Some(e),
            ErrorKind::Track(e) => Some(e),
            _ => None,
        }
    }
}
