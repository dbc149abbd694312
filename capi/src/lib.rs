//! The C ABI of alpenglow (`include/alpenglow.h`, generated from this crate
//! by cbindgen; built as `libalpenglow_c.so` and `libalpenglow_c.a`).
//!
//! * Opaque handles with create/destroy pairs: `ag_context` (Vulkan
//!   instance and device), `ag_scene` (from heights, a file or a procedural
//!   model), `ag_renderer` (a scene rendered with `ag_settings`).
//! * Plain structs: `ag_camera`, `ag_settings` (`ag_settings_default()`),
//!   `ag_frame_buffers` (caller-owned output buffers, one `ag_buffer` per
//!   output; `ag_renderer_output_bytes` sizes them).
//! * Frames: `ag_renderer_render` (blocking), or `ag_renderer_submit` → a
//!   ticket, then `ag_renderer_poll` / `ag_renderer_wait`.
//! * Every function returns an `ag_status` (`AG_OK` = 0, errors negative)
//!   and leaves a one-line message for `ag_last_error()` (thread-local).
//!   NULL pointers, bad sizes and bad values are errors, never crashes;
//!   panics are caught at the boundary (`AG_ERROR_INTERNAL`).
//!
//! Only [`adapter`] names alpenglow's Rust API, so following its changes
//! is one file's work.
//!
//! Why cbindgen: the header is derived from the Rust declarations, so the
//! C and Rust signatures and struct layouts cannot drift apart (a test
//! regenerates it and compares); it is the standard tool for exporting a
//! Rust C ABI, needs nothing at build time of the library (a dev-dependency
//! of the freshness test only), and keeps the doc comments in the header.

mod adapter;
mod context;
mod renderer;
mod scene;
mod status;
mod types;

pub use context::*;
pub use renderer::*;
pub use scene::*;
pub use status::{ag_last_error, ag_status};
pub use types::*;

use std::ffi::c_char;

/// alpenglow's version, e.g. "0.1.0" (NUL-terminated, static; do not free).
#[no_mangle]
pub extern "C" fn ag_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The ABI version of the library (`AG_ABI_VERSION` of the header it was
/// built with): compare it with the header's at start-up.
#[no_mangle]
pub extern "C" fn ag_abi_version() -> u32 {
    AG_ABI_VERSION
}
