//! Status codes, the thread's last error message, and the guard every
//! entry point runs its body in: no panic crosses into C, no pointer is
//! used before it is checked.

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What a call did. Every function that can fail returns one; on anything
/// but `TCB_STATUS_OK`, `tcb_last_error_message()` says why.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TcbStatus {
    /// Success.
    Ok = 0,
    /// A pointer that must not be NULL was NULL.
    NullPointer = 1,
    /// An argument is out of range: unknown flags or playback mode, a
    /// non-finite speed, an index past the end, a path or name that is
    /// not UTF-8, an unknown file format.
    InvalidArgument = 2,
    /// A caller's buffer has another length than the call needs (the
    /// message says how many elements it needs).
    BufferLength = 3,
    /// A file could not be read.
    Io = 4,
    /// A file or buffer was read but is not a valid clip (syntax, a track
    /// that cannot be built, a damaged `.tcbc`).
    InvalidData = 5,
    /// Things that do not fit together: poses of different layouts, a
    /// clip a rig refuses, a skeleton bound to another layout.
    Mismatch = 6,
    /// A track or joint of that name does not exist, or a clip has no
    /// skeleton.
    NotFound = 7,
    /// An internal error (a panic in the library, caught at the boundary).
    /// The handles passed to that call should be freed and not used again.
    Internal = 8,
}

/// A failed call: its status and message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub(crate) status: TcbStatus,
    pub(crate) message: String,
}

impl Failure {
    pub(crate) fn new(status: TcbStatus, message: impl Into<String>) -> Self {
        Failure {
            status,
            message: message.into(),
        }
    }

    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Failure::new(TcbStatus::InvalidArgument, message)
    }
}

impl From<tcb_io::Error> for Failure {
    fn from(e: tcb_io::Error) -> Self {
        let status = match e.kind {
            tcb_io::ErrorKind::Io(_) => TcbStatus::Io,
            _ => TcbStatus::InvalidData,
        };
        Failure::new(status, e.to_string())
    }
}

pub(crate) type Result<T> = std::result::Result<T, Failure>;

thread_local! {
    /// The message of the last failed call on this thread.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Record `message` as this thread's last error (NUL bytes become spaces).
pub(crate) fn set_last_error(message: &str) {
    let c = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Run `body`, turning an error or a panic into a status and this thread's
/// last error message.
pub(crate) fn guard(body: impl FnOnce() -> Result<()>) -> TcbStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => TcbStatus::Ok,
        Ok(Err(f)) => {
            set_last_error(&f.message);
            f.status
        }
        Err(payload) => {
            set_last_error(&panic_message(payload.as_ref()));
            TcbStatus::Internal
        }
    }
}

/// Run `body` for a value, giving `fallback` (and recording the message)
/// if it fails or panics.
pub(crate) fn guard_value<T>(fallback: T, body: impl FnOnce() -> Result<T>) -> T {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(v)) => v,
        Ok(Err(f)) => {
            set_last_error(&f.message);
            fallback
        }
        Err(payload) => {
            set_last_error(&panic_message(payload.as_ref()));
            fallback
        }
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string());
    format!("internal error (a panic in tcb, caught): {what}")
}

/// The message of the last call on this thread that failed: a NUL-terminated
/// UTF-8 string, empty if no call has failed on this thread. Successful
/// calls leave it as it is.
///
/// The pointer stays valid until the next call that fails on this thread
/// (or the thread ends); copy the text to keep it. Never NULL; do not free it.
#[unsafe(no_mangle)]
pub extern "C" fn tcb_last_error_message() -> *const c_char {
    catch_unwind(|| LAST_ERROR.with(|e| e.borrow().as_ptr())).unwrap_or(c"".as_ptr())
}

/// The version of this library, as `"0.1.0"`: a static NUL-terminated
/// string (never NULL, not to be freed).
#[unsafe(no_mangle)]
pub extern "C" fn tcb_version() -> *const c_char {
    const VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"",
        };
    VERSION.as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic in a body becomes `Internal` with its message, and the
    /// thread's message is kept until the next failure.
    #[test]
    fn panics_are_caught() {
        let status = guard(|| panic!("boom"));
        assert_eq!(status, TcbStatus::Internal);
        // SAFETY: the pointer is this thread's message, valid until the next failure.
        let msg = unsafe { CStr::from_ptr(tcb_last_error_message()) };
        assert!(msg.to_str().unwrap().contains("boom"), "{msg:?}");
        assert_eq!(guard(|| Ok(())), TcbStatus::Ok);
        // SAFETY: as above.
        let msg = unsafe { CStr::from_ptr(tcb_last_error_message()) };
        assert!(msg.to_str().unwrap().contains("boom"));
        assert_eq!(guard_value(7usize, || panic!("again")), 7);
        let failed = guard(|| Err(Failure::new(TcbStatus::NotFound, "no\0such")));
        assert_eq!(failed, TcbStatus::NotFound);
        // SAFETY: as above.
        let msg = unsafe { CStr::from_ptr(tcb_last_error_message()) };
        assert_eq!(msg.to_str().unwrap(), "no such");
    }
}
