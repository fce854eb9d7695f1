//! Checked conversions of the caller's pointers: NULL, alignment and
//! length are checked here, once, before anything is read or written.

use crate::error::{Failure, Result, TcbStatus};
use std::ffi::{CStr, c_char};

fn null(what: &str) -> Failure {
    Failure::new(TcbStatus::NullPointer, format!("{what} is NULL"))
}

/// `p` as a shared reference.
///
/// # Safety
///
/// `p` is NULL or points to a live `T` that nothing writes for `'a`.
pub(crate) unsafe fn get<'a, T>(p: *const T, what: &str) -> Result<&'a T> {
    // SAFETY: the caller promises a NULL or a live, unaliased-by-writers `T`.
    unsafe { p.as_ref() }.ok_or_else(|| null(what))
}

/// `p` as an exclusive reference.
///
/// # Safety
///
/// `p` is NULL or points to a live `T` that nothing else uses for `'a`.
pub(crate) unsafe fn get_mut<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T> {
    // SAFETY: the caller promises a NULL or a live `T` used by no one else.
    unsafe { p.as_mut() }.ok_or_else(|| null(what))
}

/// A NUL-terminated UTF-8 string.
///
/// # Safety
///
/// `p` is NULL or points to a NUL-terminated string that lives for `'a`.
pub(crate) unsafe fn str<'a>(p: *const c_char, what: &str) -> Result<&'a str> {
    if p.is_null() {
        return Err(null(what));
    }
    // SAFETY: non-NULL and NUL-terminated, as the caller promises.
    let c = unsafe { CStr::from_ptr(p) };
    c.to_str()
        .map_err(|_| Failure::invalid(format!("{what} is not valid UTF-8")))
}

/// The caller's `len` elements at `p` (any pointer when `len` is 0).
///
/// # Safety
///
/// Unless `len` is 0, `p` is NULL or points to `len` initialized `T`s that
/// nothing writes for `'a`.
pub(crate) unsafe fn slice<'a, T>(p: *const T, len: usize, what: &str) -> Result<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    check(p, len, what)?;
    // SAFETY: non-NULL, aligned, at most isize::MAX bytes (checked above),
    // and `len` live elements, as the caller promises.
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// The caller's buffer of `len` elements at `p`, to write (any pointer
/// when `len` is 0).
///
/// # Safety
///
/// Unless `len` is 0, `p` is NULL or points to `len` writable `T`s that
/// nothing else uses for `'a`.
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, len: usize, what: &str) -> Result<&'a mut [T]> {
    if len == 0 {
        return Ok(&mut []);
    }
    check(p, len, what)?;
    // SAFETY: non-NULL, aligned, at most isize::MAX bytes (checked above),
    // and `len` elements the caller lends us alone, as it promises.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, len) })
}

fn check<T>(p: *const T, len: usize, what: &str) -> Result<()> {
    if p.is_null() {
        return Err(null(what));
    }
    if !p.is_aligned() {
        return Err(Failure::invalid(format!(
            "{what} is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    if len
        .checked_mul(std::mem::size_of::<T>().max(1))
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Failure::invalid(format!(
            "{what}: length {len} is too large"
        )));
    }
    Ok(())
}

/// Store `value` into the caller's `out`.
///
/// # Safety
///
/// `out` is NULL or valid for a write of a `T`.
pub(crate) unsafe fn put<T>(out: *mut T, value: T, what: &str) -> Result<()> {
    if out.is_null() {
        return Err(null(what));
    }
    if !out.is_aligned() {
        return Err(Failure::invalid(format!("{what} is not aligned")));
    }
    // SAFETY: non-NULL, aligned and writable, as the caller promises; `T`s
    // here are plain values (no destructor to run on the old contents).
    unsafe { out.write(value) };
    Ok(())
}

/// Clear a handle out-parameter before the work, so that it is NULL on
/// failure; error if it is NULL itself.
///
/// # Safety
///
/// `out` is NULL or valid for a write of a pointer.
pub(crate) unsafe fn clear_out<T>(out: *mut *mut T, what: &str) -> Result<()> {
    // SAFETY: as the caller promises.
    unsafe { put(out, std::ptr::null_mut(), what) }
}

/// Give a new handle to the caller.
///
/// # Safety
///
/// `out` was checked by [`clear_out`] and is still valid.
pub(crate) unsafe fn give<T>(out: *mut *mut T, value: T) {
    // SAFETY: checked non-NULL, aligned and writable by `clear_out`.
    unsafe { out.write(Box::into_raw(Box::new(value))) };
}

/// Free a handle given by [`give`] (NULL is ignored).
///
/// # Safety
///
/// `p` is NULL or a handle from [`give`] of this `T`, not freed before and
/// used by no one else.
pub(crate) unsafe fn free<T>(p: *mut T) {
    if !p.is_null() {
        // SAFETY: a box leaked by `give`, freed once, as the caller promises.
        drop(unsafe { Box::from_raw(p) });
    }
}

/// Copy `text` into the caller's buffer as a NUL-terminated string,
/// storing its length (bytes, without the NUL) in `len_out`. A buffer too
/// short for the text and its NUL is a `BufferLength` error that still
/// stores the length; `buf` may be NULL when `buf_len` is 0.
///
/// # Safety
///
/// `buf` is NULL or valid for `buf_len` bytes of writes; `len_out` is NULL
/// or valid for a write.
pub(crate) unsafe fn copy_str(
    text: &str,
    buf: *mut c_char,
    buf_len: usize,
    len_out: *mut usize,
) -> Result<()> {
    if !len_out.is_null() {
        // SAFETY: non-NULL and writable, as the caller promises.
        unsafe { put(len_out, text.len(), "name_len")? };
    }
    if buf_len <= text.len() {
        return Err(Failure::new(
            TcbStatus::BufferLength,
            format!(
                "a name of {} bytes needs a buffer of {} (its NUL included), given {buf_len}",
                text.len(),
                text.len() + 1
            ),
        ));
    }
    // SAFETY: as the caller promises (checked non-NULL and sized in `slice_mut`).
    let out = unsafe { slice_mut(buf.cast::<u8>(), buf_len, "buf")? };
    out[..text.len()].copy_from_slice(text.as_bytes());
    out[text.len()] = 0;
    Ok(())
}
