//! Greyscale PNG height maps, decoded with the `png` crate directly (not
//! through `image`): the declared size is checked against the
//! [`InputLimits`] before anything is allocated, and the zlib stream's
//! Adler-32 checksum is verified (the `png` crate skips it by default, so a
//! corrupt stream could otherwise decode to altered heights).

use std::io::Cursor;
use std::path::Path;

use png::{BitDepth, ColorType, DecodeOptions, Transformations};

use crate::error::{Error, Result};
use crate::io::limits::InputLimits;
use crate::io::one_line;

/// Bytes the `png` decoder may use besides the image (row buffers, the
/// zlib window, text chunks).
const PNG_WORKING_BYTES: usize = 64 << 20;

/// Decodes a greyscale PNG into `(width, height, raw values)`: the unsigned
/// integers of 16-bit or 1/2/4/8-bit greyscale, row 0 first.
///
/// Errors (one line, naming the file): a declared size beyond `limits`
/// (before decoding), alpha or colour images, bad CRCs, a bad Adler-32
/// checksum, truncated or corrupt data.
pub(crate) fn decode_png(path: &Path, bytes: &[u8], limits: &InputLimits) -> Result<(u32, u32, Vec<f32>)> {
    let corrupt = |e: png::DecodingError| {
        let why = match &e {
            png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
                "file is truncated".to_string()
            }
            _ => one_line(&e),
        };
        Error::input(path, format!("invalid PNG: {why}"))
    };
    let mut options = DecodeOptions::default();
    options.set_ignore_adler32(false);
    options.set_ignore_crc(false);
    let mut decoder = png::Decoder::new_with_options(Cursor::new(bytes), options);
    decoder.set_limits(png::Limits {
        bytes: PNG_WORKING_BYTES,
    });
    decoder.set_transformations(Transformations::EXPAND);
    let info = decoder.read_header_info().map_err(corrupt)?;
    let (w, h) = info.size();
    check_colour(path, info.color_type)?;
    let sample_bytes: u64 = if info.bit_depth == BitDepth::Sixteen { 2 } else { 1 };
    // The decoded bytes and the f32 values made from them.
    limits
        .check_image_fits(u64::from(w), u64::from(h), sample_bytes + 4)
        .map_err(|m| Error::input(path, m))?;
    let mut reader = decoder.read_info().map_err(corrupt)?;
    let (color, depth) = reader.output_color_type();
    check_colour(path, color)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| Error::input(path, format!("image of {w}×{h} pixels is too large")))?;
    let mut buf = vec![0u8; size];
    reader.next_frame(&mut buf).map_err(corrupt)?;
    // Reads the rest of the stream: the Adler-32 checksum and every chunk's CRC.
    reader.finish().map_err(corrupt)?;
    let raw = if depth == BitDepth::Sixteen {
        // PNG stores 16-bit samples big-endian.
        buf.chunks_exact(2)
            .map(|b| f32::from(u16::from_be_bytes([b[0], b[1]])))
            .collect()
    } else {
        buf.iter().map(|&b| f32::from(b)).collect()
    };
    Ok((w, h, raw))
}

/// Rejects all but plain greyscale, naming what the image is instead.
/// (A greyscale PNG with a tRNS chunk decodes as grey + alpha.)
fn check_colour(path: &Path, color: ColorType) -> Result<()> {
    match color {
        ColorType::Grayscale => Ok(()),
        ColorType::GrayscaleAlpha => Err(Error::input(
            path,
            "PNG has an alpha channel; save the height map as plain greyscale (16-bit)",
        )),
        other => Err(Error::input(
            path,
            format!("PNG is a colour image ({other:?}); height maps must be greyscale (16-bit)"),
        )),
    }
}
