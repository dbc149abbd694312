//! `ag_context`: the Vulkan instance and device.

use std::ffi::c_char;

use crate::adapter::{self, Context};
use crate::status::{ag_status, arg, guard, put, str_arg, Failure};
use crate::types::ag_context_options;

/// A Vulkan instance and device (opaque). Renderers keep their device
/// alive: a context may be destroyed before them, but destroy them first
/// to have their validation messages counted by `ag_context_destroy`.
#[allow(non_camel_case_types)]
pub struct ag_context {
    pub(crate) ctx: Context,
}

/// Creates a context; `*out` receives it (NULL on failure).
///
/// # Safety
/// `options` is NULL or points to a valid `ag_context_options` whose
/// `device` is NULL or a NUL-terminated string; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_context_create(options: *const ag_context_options, out: *mut *mut ag_context) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(out, "out", std::ptr::null_mut()) }?;
        // SAFETY: the caller passes NULL or a valid options struct.
        let options = unsafe { arg(options, "options") }?;
        let device = match options.device.is_null() {
            true => None,
            // SAFETY: not NULL; the caller guarantees a NUL-terminated string.
            false => Some(unsafe { str_arg(options.device, "options.device") }?),
        };
        let ctx = adapter::context(options.validation, device)?;
        let handle = Box::into_raw(Box::new(ag_context { ctx }));
        // SAFETY: checked writable above.
        unsafe { put(out, "out", handle) }?;
        Ok(ag_status::AG_OK)
    })
}

/// Destroys `ctx` (NULL: nothing to do). `validation_messages` (may be
/// NULL) receives how many messages the validation layers reported over
/// the context's life, its device's destruction included when no renderer
/// holds it any more; with any, returns `AG_ERROR_VALIDATION` and
/// `ag_last_error()` lists them. 0 and `AG_OK` without validation.
///
/// # Safety
/// `ctx` is NULL or a context from `ag_context_create` not yet destroyed;
/// `validation_messages` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_context_destroy(ctx: *mut ag_context, validation_messages: *mut u64) -> ag_status {
    guard(|| {
        let report = match ctx.is_null() {
            true => None,
            // SAFETY: a live handle from ag_context_create, owned by the caller until now.
            false => adapter::destroy_context(unsafe { Box::from_raw(ctx) }.ctx),
        };
        let (count, messages) = report.unwrap_or_default();
        if !validation_messages.is_null() {
            // SAFETY: not NULL; the caller guarantees it is writable.
            unsafe { put(validation_messages, "validation_messages", count) }?;
        }
        match count {
            0 => Ok(ag_status::AG_OK),
            _ => Err(validation_failure(count, &messages)),
        }
    })
}

/// How many messages the validation layers reported so far (without the
/// ones of destruction: see `ag_context_destroy`).
///
/// # Safety
/// `ctx` is NULL or a live context; `count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_context_validation_messages(ctx: *const ag_context, count: *mut u64) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live handle.
        let ctx = unsafe { arg(ctx, "ctx") }?;
        let (total, _) = adapter::validation_messages(&ctx.ctx)
            .ok_or_else(|| Failure::invalid("ctx", "the context was created without validation"))?;
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(count, "count", total) }?;
        Ok(ag_status::AG_OK)
    })
}

/// Writes the name of the context's device, NUL-terminated and truncated to
/// `bytes` (the full name's length + 1 into `*needed` when `needed` is not NULL).
///
/// # Safety
/// `ctx` is NULL or a live context; `name` is NULL or writable for `bytes`
/// bytes; `needed` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_context_device_name(
    ctx: *const ag_context,
    name: *mut c_char,
    bytes: usize,
    needed: *mut usize,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live handle.
        let ctx = unsafe { arg(ctx, "ctx") }?;
        let text = adapter::device_name(&ctx.ctx);
        if !needed.is_null() {
            // SAFETY: not NULL; the caller guarantees it is writable.
            unsafe { put(needed, "needed", text.len() + 1) }?;
        }
        if name.is_null() || bytes == 0 {
            return Ok(ag_status::AG_OK);
        }
        let n = text.len().min(bytes - 1);
        // SAFETY: `name` is writable for `bytes` ≥ n + 1 bytes (caller's promise) and
        // does not overlap the Rust string.
        unsafe {
            std::ptr::copy_nonoverlapping(text.as_ptr(), name.cast::<u8>(), n);
            name.add(n).write(0);
        }
        Ok(ag_status::AG_OK)
    })
}

/// The failure of a context whose validation layers reported `count` messages.
fn validation_failure(count: u64, messages: &[String]) -> Failure {
    const SHOWN: usize = 5;
    let mut text = format!("validation layers reported {count} message(s): ");
    text.push_str(&messages.iter().take(SHOWN).cloned().collect::<Vec<_>>().join(" | "));
    if messages.len() > SHOWN {
        text.push_str(&format!(" | … and {} more", messages.len() - SHOWN));
    }
    Failure::new(ag_status::AG_ERROR_VALIDATION, text.replace(['\n', '\r'], " "))
}
