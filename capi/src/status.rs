//! Status codes, the thread-local last-error message and the guard every
//! exported function runs its body in: arguments checked (null pointers,
//! sizes) before anything is done, library errors mapped to a code and a
//! message, and panics caught at the boundary (unwinding into C is
//! undefined behaviour) and reported as [`ag_status::AG_ERROR_PANIC`].

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::adapter::Error;

/// What a function of the C API returns. `AG_OK` (0) is success; errors
/// are negative, and `ag_last_error()` then gives a one-line message that
/// names the parameter, file or feature at fault.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ag_status {
    /// Success.
    AG_OK = 0,
    /// `ag_renderer_poll`: the frame is not finished yet (not an error).
    AG_NOT_READY = 1,
    /// A required pointer argument was NULL.
    AG_ERROR_NULL_POINTER = -1,
    /// An argument or setting is out of range (NaN heights, a bad camera,
    /// an unknown model name, an unknown or overwritten ticket, ...).
    AG_ERROR_INVALID_ARGUMENT = -2,
    /// A caller-owned output buffer is smaller than the output it should
    /// receive (see `ag_renderer_output_bytes`). Nothing was written.
    AG_ERROR_BUFFER_TOO_SMALL = -3,
    /// An input file is missing, unreadable or malformed.
    AG_ERROR_INPUT = -4,
    /// An output could not be written.
    AG_ERROR_OUTPUT = -5,
    /// The Vulkan loader, device, a Vulkan call or GPU memory failed.
    AG_ERROR_DEVICE = -6,
    /// The Khronos validation layers reported messages (`ag_context_destroy`).
    AG_ERROR_VALIDATION = -7,
    /// A bug in alpenglow: a panic caught at the C boundary, or an
    /// inconsistent internal state. The handle involved should be destroyed.
    AG_ERROR_INTERNAL = -8,
}

thread_local! {
    /// The message of the last failed call on this thread.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Records `message` (control characters escaped by the library's error
/// type; interior NULs replaced) as this thread's last error.
pub(crate) fn set_last_error(message: &str) {
    let message = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    LAST_ERROR.with(|last| *last.borrow_mut() = message);
}

/// The one-line message of the last call on this thread that did not
/// return `AG_OK` or `AG_NOT_READY`; an empty string if there was none.
/// The pointer stays valid until the next failing call on this thread;
/// never NULL; do not free it.
#[no_mangle]
pub extern "C" fn ag_last_error() -> *const c_char {
    LAST_ERROR.with(|last| last.borrow().as_ptr())
}

/// An error of the C layer: a status and its message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: ag_status,
    pub message: String,
}

impl Failure {
    pub(crate) fn new(status: ag_status, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    /// A NULL pointer passed as `parameter`.
    pub(crate) fn null(parameter: &str) -> Failure {
        Failure::new(ag_status::AG_ERROR_NULL_POINTER, format!("{parameter} is NULL"))
    }

    /// `parameter` out of range.
    pub(crate) fn invalid(parameter: &str, message: impl std::fmt::Display) -> Failure {
        Failure::new(
            ag_status::AG_ERROR_INVALID_ARGUMENT,
            format!("invalid {parameter}: {message}"),
        )
    }
}

impl From<Error> for Failure {
    fn from(error: Error) -> Failure {
        let status = match &error {
            Error::InvalidArgument { .. } => ag_status::AG_ERROR_INVALID_ARGUMENT,
            Error::Input { .. } => ag_status::AG_ERROR_INPUT,
            Error::Output { .. } => ag_status::AG_ERROR_OUTPUT,
            Error::Loader(_)
            | Error::Device(_)
            | Error::Vulkan { .. }
            | Error::Allocation { .. }
            | Error::Shader { .. } => ag_status::AG_ERROR_DEVICE,
            _ => ag_status::AG_ERROR_INTERNAL,
        };
        Failure::new(status, error.to_string())
    }
}

pub(crate) type Outcome<T = ()> = std::result::Result<T, Failure>;

/// Runs `body`, the whole of an exported function: its failure becomes
/// the returned status and this thread's last error; a panic is caught
/// here, never unwinds into C.
pub(crate) fn guard(body: impl FnOnce() -> Outcome<ag_status>) -> ag_status {
    let outcome = catch_unwind(AssertUnwindSafe(body)).unwrap_or_else(|payload| {
        let what = (payload.downcast_ref::<&str>().copied())
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
            .unwrap_or("unknown panic");
        Err(Failure::new(
            ag_status::AG_ERROR_INTERNAL,
            format!("internal error (a bug in alpenglow, please report it): {what}"),
        ))
    });
    match outcome {
        Ok(status) => status,
        Err(failure) => {
            set_last_error(&failure.message);
            failure.status
        }
    }
}

/// `pointer` as a shared reference, or a NULL-pointer failure naming `parameter`.
///
/// # Safety
/// A non-NULL `pointer` must point to a valid, initialised `T` that nobody
/// mutates for `'a`.
pub(crate) unsafe fn arg<'a, T>(pointer: *const T, parameter: &str) -> Outcome<&'a T> {
    // SAFETY: the caller guarantees that a non-NULL pointer is valid for 'a.
    unsafe { pointer.as_ref() }.ok_or_else(|| Failure::null(parameter))
}

/// `pointer` as an exclusive reference, or a NULL-pointer failure naming `parameter`.
///
/// # Safety
/// A non-NULL `pointer` must point to a valid `T` that nothing else
/// accesses for `'a`.
pub(crate) unsafe fn arg_mut<'a, T>(pointer: *mut T, parameter: &str) -> Outcome<&'a mut T> {
    // SAFETY: the caller guarantees that a non-NULL pointer is valid and unaliased for 'a.
    unsafe { pointer.as_mut() }.ok_or_else(|| Failure::null(parameter))
}

/// Writes `value` through the out-pointer `pointer` (named `parameter`).
///
/// # Safety
/// A non-NULL `pointer` must be valid for writing a `T` (it may be
/// uninitialised: the old value is not dropped).
pub(crate) unsafe fn put<T>(pointer: *mut T, parameter: &str, value: T) -> Outcome {
    if pointer.is_null() {
        return Err(Failure::null(parameter));
    }
    // SAFETY: not NULL (checked above); the caller guarantees it is valid for writes.
    unsafe { pointer.write(value) };
    Ok(())
}

/// A NUL-terminated UTF-8 string argument.
///
/// # Safety
/// A non-NULL `pointer` must point to a NUL-terminated string that stays
/// valid and unchanged during the call.
pub(crate) unsafe fn str_arg<'a>(pointer: *const c_char, parameter: &str) -> Outcome<&'a str> {
    if pointer.is_null() {
        return Err(Failure::null(parameter));
    }
    // SAFETY: not NULL (checked above); the caller guarantees NUL termination and validity.
    let text = unsafe { CStr::from_ptr(pointer) };
    text.to_str().map_err(|_| Failure::invalid(parameter, "not UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_internal_errors_with_a_message() {
        let status = guard(|| panic!("boom"));
        assert_eq!(status, ag_status::AG_ERROR_INTERNAL);
        // SAFETY: ag_last_error never returns NULL and the string lives until the next failure.
        let message = unsafe { CStr::from_ptr(ag_last_error()) }.to_str().unwrap().to_owned();
        assert!(message.contains("boom"), "{message}");
    }

    #[test]
    fn the_last_error_is_per_thread() {
        set_last_error("on the test thread");
        let other = std::thread::spawn(|| {
            // SAFETY: as above.
            let message = unsafe { CStr::from_ptr(ag_last_error()) };
            message.to_str().unwrap().to_owned()
        });
        assert_eq!(other.join().unwrap(), "");
        // SAFETY: as above.
        let message = unsafe { CStr::from_ptr(ag_last_error()) };
        assert_eq!(message.to_str().unwrap(), "on the test thread");
    }

    #[test]
    fn messages_with_nul_bytes_are_kept() {
        set_last_error("a\0b");
        // SAFETY: as above.
        let message = unsafe { CStr::from_ptr(ag_last_error()) };
        assert_eq!(message.to_str().unwrap(), "a\\0b");
    }
}
