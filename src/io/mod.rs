//! File input and output: height maps in, images and EXR layers out.
//!
//! Every writer goes through [`atomic::write_atomically`], so a failed or
//! interrupted write never leaves a partial file under the final name.

pub mod atomic;
pub mod heightmap;
pub mod image_out;

/// Most memory a decoder may claim for one input image (4 GiB; a 32768²
/// 16-bit height map needs 2 GiB). Corrupt headers that claim more are
/// rejected instead of aborting the process on a failed allocation.
pub(crate) const MAX_DECODE_BYTES: u64 = 4 << 30;

/// Collapses an error message from a dependency onto one line.
pub(crate) fn one_line(message: impl std::fmt::Display) -> String {
    let text = message.to_string();
    let parts: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    parts.join("; ")
}

/// Reads a whole input file, mapping I/O failures to one-line errors that
/// name the file.
pub(crate) fn read_input(path: &std::path::Path) -> crate::error::Result<Vec<u8>> {
    use crate::error::Error;
    use std::io::ErrorKind;
    if path.is_dir() {
        return Err(Error::input(path, "is a directory, not a file"));
    }
    std::fs::read(path).map_err(|e| match e.kind() {
        ErrorKind::NotFound => Error::input(path, "file not found"),
        ErrorKind::PermissionDenied => Error::input(path, "permission denied"),
        _ => Error::input(path, format!("cannot read: {}", one_line(e))),
    })
}
