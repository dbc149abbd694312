//! File input and output: height maps in, images and EXR layers out.
//!
//! Every writer goes through [`atomic::write_atomically`], so a failed or
//! interrupted write never leaves a partial file under the final name.
//! Every reader goes through [`read_input_limited`]: only regular files,
//! at most [`limits::InputLimits::max_file_bytes`] bytes.

pub mod atomic;
pub mod geotiff;
pub mod heightmap;
pub mod hgt;
pub mod image_out;
pub mod limits;
mod png_height;
pub mod pyramid;

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// Collapses an error message from a dependency onto one line.
pub(crate) fn one_line(message: impl std::fmt::Display) -> String {
    let text = message.to_string();
    let parts: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    parts.join("; ")
}

/// Reads a whole input file of at most the default
/// [`limits::InputLimits::max_file_bytes`]; see [`read_input_limited`].
pub(crate) fn read_input(path: &Path) -> Result<Vec<u8>> {
    read_input_limited(path, limits::InputLimits::DEFAULT_FILE_BYTES)
}

/// Why `meta` is not a regular file, if it is not ("is a FIFO, not a
/// regular file"…).
fn not_regular(meta: &std::fs::Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("is a directory, not a file");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("is a FIFO, not a regular file");
        }
        if t.is_char_device() {
            return Some("is a character device, not a regular file");
        }
        if t.is_block_device() {
            return Some("is a block device, not a regular file");
        }
        if t.is_socket() {
            return Some("is a socket, not a regular file");
        }
    }
    Some("is not a regular file")
}

/// Reads a whole input file of at most `max_bytes` bytes, mapping failures
/// to one-line errors that name the file.
///
/// The file's metadata is checked before it is opened (which never blocks,
/// not even on a FIFO): directories, FIFOs, devices and sockets are
/// rejected by name, and so is a file larger than `max_bytes`. The read
/// itself stops one byte past `max_bytes`, so a file that grows meanwhile
/// (or whose size the metadata misstates) cannot exceed the limit either.
pub fn read_input_limited(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    use std::io::ErrorKind;
    let io_error = |e: std::io::Error| match e.kind() {
        ErrorKind::NotFound => Error::input(path, "file not found"),
        ErrorKind::PermissionDenied => Error::input(path, "permission denied"),
        _ => Error::input(path, format!("cannot read: {}", one_line(e))),
    };
    let too_large = |size: u64| {
        Error::input(
            path,
            format!("file is {size} bytes, more than the limit of {max_bytes} (raise it with --max-input-mb)"),
        )
    };
    let meta = std::fs::metadata(path).map_err(io_error)?;
    if let Some(why) = not_regular(&meta) {
        return Err(Error::input(path, why));
    }
    if meta.len() > max_bytes {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(io_error)?;
    // The path may have been replaced between the two calls.
    if let Some(why) = file.metadata().ok().as_ref().and_then(not_regular) {
        return Err(Error::input(path, why));
    }
    let capacity = usize::try_from(meta.len()).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io_error)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests;
