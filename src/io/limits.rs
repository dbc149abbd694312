//! Explicit limits on what an input file may make the library read and
//! allocate, checked before the allocation (a corrupt or hostile header
//! gives a one-line error, never an aborting allocation).
//!
//! The defaults are generous for real data and documented on each field;
//! raise them through [`InputLimits`] (library) or `--max-input-mb` (CLI).

/// Limits on one input file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputLimits {
    /// Largest file read, in bytes (default [`InputLimits::DEFAULT_FILE_BYTES`],
    /// 2 GiB: a 16384² float GeoTIFF or EXR is 1 GiB uncompressed). Reads
    /// stop one byte past it, so a file that grows while read (or a special
    /// file whose metadata lies) cannot exceed it either.
    pub max_file_bytes: u64,
    /// Most samples (width·height) of one input image, as its header
    /// declares them (default [`InputLimits::DEFAULT_IMAGE_PIXELS`], 2²⁸ =
    /// 16384²). Checked before decoding, so a small file claiming a huge
    /// image (a "zlib bomb") is rejected without decoding it.
    pub max_image_pixels: u64,
    /// Most bytes a decoder may allocate for one decoded image (default
    /// [`InputLimits::DEFAULT_DECODE_BYTES`], 4 GiB).
    pub max_decode_bytes: u64,
    /// Most elements (vertices, faces, points, keyframes…) a loader accepts
    /// from one file (default [`InputLimits::DEFAULT_ELEMENTS`], 2²⁸).
    pub max_elements: u64,
}

impl InputLimits {
    /// Default [`InputLimits::max_file_bytes`]: 2 GiB.
    pub const DEFAULT_FILE_BYTES: u64 = 2 << 30;
    /// Default [`InputLimits::max_image_pixels`]: 2²⁸ (16384²).
    pub const DEFAULT_IMAGE_PIXELS: u64 = 1 << 28;
    /// Default [`InputLimits::max_decode_bytes`]: 4 GiB.
    pub const DEFAULT_DECODE_BYTES: u64 = 4 << 30;
    /// Default [`InputLimits::max_elements`]: 2²⁸.
    pub const DEFAULT_ELEMENTS: u64 = 1 << 28;
    /// Largest side of an input image (32768) whatever the limits: no
    /// Vulkan device samples a larger 2-D image, so a header claiming more
    /// is rejected as corrupt.
    pub const MAX_IMAGE_SIDE: u32 = 32768;

    /// The defaults with [`InputLimits::max_file_bytes`] set to `mib` MiB
    /// (`--max-input-mb`); the pixel and decode limits grow with it when it
    /// exceeds the default file size, so a larger file can also be decoded.
    pub fn with_max_file_mib(mib: u64) -> InputLimits {
        let bytes = mib.saturating_mul(1 << 20);
        let d = InputLimits::default();
        let factor = bytes.div_ceil(d.max_file_bytes).max(1);
        InputLimits {
            max_file_bytes: bytes,
            max_image_pixels: d.max_image_pixels.saturating_mul(factor),
            max_decode_bytes: d.max_decode_bytes.saturating_mul(factor),
            max_elements: d.max_elements.saturating_mul(factor),
        }
    }

    /// Checks a declared `width`×`height` image against
    /// [`InputLimits::MAX_IMAGE_SIDE`], [`InputLimits::max_image_pixels`] and,
    /// at `bytes_per_pixel` decoded bytes, [`InputLimits::max_decode_bytes`].
    /// The error is one line without the file name (the caller adds it).
    pub fn check_image(&self, width: u64, height: u64, bytes_per_pixel: u64) -> Result<(), String> {
        let side = u64::from(InputLimits::MAX_IMAGE_SIDE);
        if width > side || height > side {
            return Err(format!(
                "image claims {width}×{height} pixels; the largest supported side is {side} (corrupt header?)"
            ));
        }
        let pixels = width.saturating_mul(height);
        if pixels > self.max_image_pixels {
            return Err(format!(
                "image claims {width}×{height} = {pixels} pixels, more than the limit of {} \
                 (raise it with --max-input-mb or InputLimits::max_image_pixels)",
                self.max_image_pixels
            ));
        }
        let bytes = pixels.saturating_mul(bytes_per_pixel);
        if bytes > self.max_decode_bytes {
            return Err(format!(
                "image of {width}×{height} pixels needs {bytes} bytes decoded, more than the limit of {} \
                 (raise it with --max-input-mb or InputLimits::max_decode_bytes)",
                self.max_decode_bytes
            ));
        }
        Ok(())
    }

    /// [`InputLimits::check_image`], then the memory model
    /// (`crate::budget`): the image decoded at `bytes_per_pixel` plus 4 B
    /// a sample as kept, against the host's available memory.
    pub fn check_image_fits(&self, width: u64, height: u64, bytes_per_pixel: u64) -> Result<(), String> {
        self.check_image(width, height, bytes_per_pixel)?;
        check_image_memory(width, height, bytes_per_pixel, crate::budget::host_available_bytes())
    }
}

/// Whether a `width`×`height` image decoded at `bytes_per_pixel` and kept
/// at 4 B a sample fits `host` bytes; the error says the estimate and the
/// limit (one line, without the file name).
pub fn check_image_memory(width: u64, height: u64, bytes_per_pixel: u64, host: u64) -> Result<(), String> {
    let need = width
        .saturating_mul(height)
        .saturating_mul(bytes_per_pixel.saturating_add(4));
    if need > host {
        return Err(format!(
            "image of {width}×{height} pixels needs about {} of host memory decoded; {} is available",
            crate::budget::format_bytes(need),
            crate::budget::format_bytes(host)
        ));
    }
    Ok(())
}

impl Default for InputLimits {
    /// The documented defaults of each field.
    fn default() -> Self {
        InputLimits {
            max_file_bytes: InputLimits::DEFAULT_FILE_BYTES,
            max_image_pixels: InputLimits::DEFAULT_IMAGE_PIXELS,
            max_decode_bytes: InputLimits::DEFAULT_DECODE_BYTES,
            max_elements: InputLimits::DEFAULT_ELEMENTS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoded_images_are_checked_against_host_memory() {
        assert!(check_image_memory(403, 344, 6, 2 << 20).is_ok());
        let e = check_image_memory(403, 344, 6, 1 << 20).unwrap_err();
        assert_eq!(
            e,
            "image of 403×344 pixels needs about 1.3 MiB of host memory decoded; 1.0 MiB is available"
        );
        assert!(check_image_memory(u64::MAX, 2, 8, u64::MAX - 1).is_err());
    }

    #[test]
    fn image_checks_name_the_limit() {
        let l = InputLimits::default();
        assert!(l.check_image(16384, 16384, 2).is_ok());
        assert!(l
            .check_image(200_000, 200_000, 2)
            .unwrap_err()
            .contains("largest supported side"));
        assert!(l
            .check_image(32768, 32768, 2)
            .unwrap_err()
            .contains("more than the limit"));
        assert!(l.check_image(u64::MAX, u64::MAX, 8).is_err());
        let small = InputLimits {
            max_decode_bytes: 100,
            ..l
        };
        assert!(small.check_image(10, 10, 2).unwrap_err().contains("bytes decoded"));
        let raised = InputLimits::with_max_file_mib(8192);
        assert_eq!(raised.max_file_bytes, 8 << 30);
        assert!(raised.check_image(32768, 32768, 4).is_ok());
        assert_eq!(InputLimits::with_max_file_mib(1).max_image_pixels, l.max_image_pixels);
    }
}
