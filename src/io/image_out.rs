//! Image output: 8-bit sRGB PNG (or JPEG) screenshots and 32-bit float
//! OpenEXR layers. The `encode_*` functions return the file's bytes, for
//! [`crate::io::atomic::OutputTransaction::stage_bytes`].
//!
//! Every writer goes through [`crate::io::atomic::write_bytes_atomically`], so a failed write leaves no
//! file behind. Pixel data is row-major with row 0 at the top of the image.

use std::collections::BTreeSet;
use std::io::Cursor;
use std::path::Path;

use crate::error::{Error, Result};
use crate::io::atomic::write_bytes_atomically;
use crate::io::limits::InputLimits;
use crate::io::one_line;

/// Named channels of an EXR image: `(name, samples)` per channel.
pub type ExrChannels = Vec<(String, Vec<f32>)>;

/// The samples of one extra EXR channel: 32-bit float, or 32-bit unsigned
/// integer (exact ids).
#[derive(Clone, Copy, Debug)]
pub enum ExrSamples<'a> {
    F32(&'a [f32]),
    U32(&'a [u32]),
}

impl ExrSamples<'_> {
    fn len(&self) -> usize {
        match self {
            ExrSamples::F32(v) => v.len(),
            ExrSamples::U32(v) => v.len(),
        }
    }
}

/// Number of pixels of a `width`×`height` image, rejecting empty images and
/// sizes that overflow `usize`.
fn pixel_count(what: &str, width: u32, height: u32) -> Result<usize> {
    if width == 0 || height == 0 {
        return Err(Error::invalid(what, format!("image size {width}×{height} is empty")));
    }
    (width as usize)
        .checked_mul(height as usize)
        .ok_or_else(|| Error::invalid(what, format!("image size {width}×{height} is too large")))
}

/// Checks that `rgba` holds 4 bytes per pixel of a `width`×`height` image.
fn check_rgba8(what: &str, rgba: &[u8], width: u32, height: u32) -> Result<()> {
    let pixels = pixel_count(&format!("{what} image size"), width, height)?;
    if Some(rgba.len()) != pixels.checked_mul(4) {
        return Err(Error::invalid(
            format!("{what} pixel data"),
            format!(
                "{} bytes for a {width}×{height} RGBA image (expected {})",
                rgba.len(),
                pixels.saturating_mul(4)
            ),
        ));
    }
    Ok(())
}

/// Encodes an 8-bit RGBA PNG in memory (see [`write_png_rgba8`]).
pub fn encode_png_rgba8(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    check_rgba8("PNG", rgba, width, height)?;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::{ExtendedColorType, ImageEncoder};
    let mut bytes = Vec::new();
    PngEncoder::new_with_quality(&mut bytes, CompressionType::Default, FilterType::Adaptive)
        .write_image(rgba, width, height, ExtendedColorType::Rgba8)
        .map_err(|e| Error::invalid("PNG encoding", one_line(e)))?;
    Ok(bytes)
}

/// Encodes a 16-bit greyscale PNG in memory (a height map the loaders
/// read back exactly): `values` row-major, row 0 at the top.
pub fn encode_png_gray16(values: &[u16], width: u32, height: u32) -> Result<Vec<u8>> {
    let pixels = pixel_count("PNG image size", width, height)?;
    if values.len() != pixels {
        return Err(Error::invalid(
            "PNG pixel data",
            format!("{} values for a {width}×{height} image", values.len()),
        ));
    }
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::{ExtendedColorType, ImageEncoder};
    // The encoder takes native-endian samples and writes them big-endian.
    let native: Vec<u8> = values.iter().flat_map(|v| v.to_ne_bytes()).collect();
    let mut bytes = Vec::new();
    PngEncoder::new_with_quality(&mut bytes, CompressionType::Default, FilterType::Adaptive)
        .write_image(&native, width, height, ExtendedColorType::L16)
        .map_err(|e| Error::invalid("PNG encoding", one_line(e)))?;
    Ok(bytes)
}

/// Writes an 8-bit RGBA PNG.
///
/// `rgba` holds 4 bytes per pixel, row-major, row 0 at the top, already
/// encoded for display (sRGB transfer function, e.g. tone-mapped by the
/// GPU). The encoder settings are fixed and the file carries no timestamp,
/// so identical input gives a byte-identical file.
///
/// Errors: empty size, `rgba.len() != 4·width·height`, encoder or I/O
/// failure (the message names `path`).
pub fn write_png_rgba8(path: &Path, rgba: &[u8], width: u32, height: u32) -> Result<()> {
    let bytes = encode_png_rgba8(rgba, width, height)?;
    write_bytes_atomically(path, &bytes)
}

/// The JPEG quality of [`encode_jpeg_rgba8`] (1–100; 90 keeps terrain
/// texture detail with files about a fifth of the PNG's size).
pub const JPEG_QUALITY: u8 = 90;

/// Encodes 8-bit RGBA pixels (as for [`write_png_rgba8`]) as a baseline
/// JPEG of quality [`JPEG_QUALITY`]; JPEG has no alpha, so alpha is dropped.
pub fn encode_jpeg_rgba8(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    check_rgba8("JPEG", rgba, width, height)?;
    if width > u32::from(u16::MAX) || height > u32::from(u16::MAX) {
        return Err(Error::invalid(
            "JPEG image size",
            format!("{width}×{height} exceeds the format's 65535 pixels per side; use .png"),
        ));
    }
    let rgb: Vec<u8> = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    use image::codecs::jpeg::JpegEncoder;
    use image::{ExtendedColorType, ImageEncoder};
    let mut bytes = Vec::new();
    JpegEncoder::new_with_quality(&mut bytes, JPEG_QUALITY)
        .write_image(&rgb, width, height, ExtendedColorType::Rgb8)
        .map_err(|e| Error::invalid("JPEG encoding", one_line(e)))?;
    Ok(bytes)
}

/// Image formats of 8-bit outputs, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`: lossless, with alpha.
    Png,
    /// `.jpg` or `.jpeg`: quality `JPEG_QUALITY`, no alpha.
    Jpeg,
}

impl ImageFormat {
    /// The format of `path`'s extension (case-insensitive): `.png`, `.jpg`
    /// or `.jpeg`. Errors name the extension: "unsupported extension .bmp;
    /// use .png or .jpg".
    pub fn from_path(path: &Path) -> std::result::Result<ImageFormat, String> {
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("jpg" | "jpeg") => Ok(ImageFormat::Jpeg),
            Some(other) => Err(format!("unsupported extension .{other}; use .png or .jpg")),
            None => Err("no file extension; use .png or .jpg".into()),
        }
    }

    /// Encodes 8-bit RGBA pixels (as for [`write_png_rgba8`]) in this format.
    pub fn encode_rgba8(self, rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
        match self {
            ImageFormat::Png => encode_png_rgba8(rgba, width, height),
            ImageFormat::Jpeg => encode_jpeg_rgba8(rgba, width, height),
        }
    }
}

/// Writes 8-bit RGBA pixels as PNG or JPEG by `path`'s extension (see
/// [`ImageFormat::from_path`]), atomically.
pub fn write_image_by_extension(path: &Path, rgba: &[u8], width: u32, height: u32) -> Result<()> {
    let format = ImageFormat::from_path(path).map_err(|m| Error::output(path, m))?;
    write_bytes_atomically(path, &format.encode_rgba8(rgba, width, height)?)
}

/// Writes a 32-bit float OpenEXR file with channels R, G, B, A, Z and any
/// `extra` channels.
///
/// * `rgba`: 4 linear values per pixel (R, G, B, A), row-major, row 0 at the
///   top (the EXR data window starts at (0, 0) and lines are stored in
///   increasing y, i.e. top to bottom).
/// * `depth`: one view-space depth per pixel, `+inf` where nothing was hit;
///   stored unchanged in channel `Z`.
/// * `extra`: further named channels, one value per pixel each.
///
/// Channels are stored in alphabetical order as the format requires; ZIP
/// compression (lossless) in 16-line blocks.
///
/// Errors: empty size, wrong slice lengths, empty, duplicate or reserved
/// extra channel names, encoder or I/O failure.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[f32],
    depth: &[f32],
    extra: &[(&str, &[f32])],
) -> Result<()> {
    let extra: Vec<(&str, ExrSamples)> = extra.iter().map(|&(n, v)| (n, ExrSamples::F32(v))).collect();
    write_exr_samples(path, (width, height), (rgba, depth), &extra)
}

/// [`write_exr`] with extra channels of float or unsigned integer samples
/// (`UINT` channels: ids stay exact).
pub fn write_exr_samples(
    path: &Path,
    size: (u32, u32),
    rgba_depth: (&[f32], &[f32]),
    extra: &[(&str, ExrSamples)],
) -> Result<()> {
    let bytes = encode_exr_samples(size, rgba_depth, extra)?;
    write_bytes_atomically(path, &bytes)
}

/// Encodes the OpenEXR file of [`write_exr_samples`] in memory.
pub fn encode_exr_samples(
    (width, height): (u32, u32),
    (rgba, depth): (&[f32], &[f32]),
    extra: &[(&str, ExrSamples)],
) -> Result<Vec<u8>> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer, LayerAttributes, LineOrder,
        SmallVec, WritableImage,
    };

    let pixels = pixel_count("EXR image size", width, height)?;
    let check_len = |what: &str, len: usize, per_pixel: usize| -> Result<()> {
        if Some(len) == pixels.checked_mul(per_pixel) {
            Ok(())
        } else {
            Err(Error::invalid(
                format!("EXR {what}"),
                format!(
                    "{len} values for a {width}×{height} image (expected {})",
                    pixels.saturating_mul(per_pixel)
                ),
            ))
        }
    };
    check_len("RGBA data", rgba.len(), 4)?;
    check_len("depth data", depth.len(), 1)?;
    let mut names: BTreeSet<&str> = ["R", "G", "B", "A", "Z"].into_iter().collect();
    for (name, data) in extra {
        if name.is_empty() || !name.is_ascii() || name.chars().any(|c| c.is_ascii_control()) {
            return Err(Error::invalid(
                "EXR channel name",
                format!("{name:?} must be non-empty printable ASCII"),
            ));
        }
        if !names.insert(name) {
            return Err(Error::invalid("EXR channel name", format!("{name:?} is used twice")));
        }
        check_len(&format!("channel {name}"), data.len(), 1)?;
    }

    let component = |k: usize| -> Vec<f32> { rgba.iter().skip(k).step_by(4).copied().collect() };
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (k, name) in ["R", "G", "B", "A"].iter().enumerate() {
        list.push(AnyChannel::new(*name, FlatSamples::F32(component(k))));
    }
    list.push(AnyChannel::new("Z", FlatSamples::F32(depth.to_vec())));
    for (name, data) in extra {
        let samples = match data {
            ExrSamples::F32(v) => FlatSamples::F32(v.to_vec()),
            ExrSamples::U32(v) => FlatSamples::U32(v.to_vec()),
        };
        list.push(AnyChannel::new(*name, samples));
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);

    let mut bytes = Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::invalid("EXR encoding", one_line(e)))?;
    Ok(bytes.into_inner())
}

/// Encodes a one-channel OpenEXR height map in memory: 32-bit float
/// channel `Y` (the channel the height-map loader reads first), `values`
/// row-major, row 0 at the top, ZIP compression (lossless).
pub fn encode_exr_height(values: &[f32], width: u32, height: u32) -> Result<Vec<u8>> {
    use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels, WritableImage};
    let pixels = pixel_count("EXR image size", width, height)?;
    if values.len() != pixels {
        return Err(Error::invalid(
            "EXR height data",
            format!("{} values for a {width}×{height} image", values.len()),
        ));
    }
    let w = width as usize;
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: exr::math::Vec2<usize>| (values[p.y() * w + p.x()],));
    let layer = Layer::new(
        (w, height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let mut bytes = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::invalid("EXR encoding", one_line(e)))?;
    Ok(bytes.into_inner())
}

/// Channels of an EXR image as `(width, height, [(name, samples)])`, samples
/// row-major from the top, converted to `f32`, channels in file
/// (alphabetical) order. Reads the first valid layer at full resolution,
/// within the default [`InputLimits`].
pub(crate) fn decode_exr_channels(path: &Path, bytes: &[u8]) -> Result<(u32, u32, ExrChannels)> {
    decode_exr_channels_limited(path, bytes, &InputLimits::default())
}

/// [`decode_exr_channels`] within `limits`: every header's data window is
/// checked against them before any pixel is read, and deep data is
/// rejected.
pub(crate) fn decode_exr_channels_limited(
    path: &Path,
    bytes: &[u8],
    limits: &InputLimits,
) -> Result<(u32, u32, ExrChannels)> {
    use exr::prelude::{read, ReadChannels, ReadLayers};
    let invalid = |e: exr::error::Error| Error::input(path, format!("invalid OpenEXR file: {}", one_line(e)));
    // Check the claimed size before decoding: a corrupt header must not make
    // the decoder attempt a huge allocation (which aborts the process).
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(invalid)?;
    for header in &meta.headers {
        if header.deep || meta.requirements.has_deep_data {
            return Err(Error::input(path, "OpenEXR deep data is not supported"));
        }
        let size = header.layer_size;
        let channels = header.channels.list.len() as u64;
        // Each channel's samples, as stored (≤ 4 bytes) and as f32.
        limits
            .check_image_fits(size.width() as u64, size.height() as u64, channels.max(1) * 8)
            .map_err(|m| Error::input(path, m))?;
        if header.chunk_count > bytes.len() / 8 {
            return Err(Error::input(
                path,
                "file is truncated or corrupt (too few bytes for its blocks)",
            ));
        }
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(invalid)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let width = u32::try_from(w).map_err(|_| Error::input(path, "image too wide"))?;
    let height = u32::try_from(h).map_err(|_| Error::input(path, "image too tall"))?;
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect::<Vec<f32>>()))
        .collect::<Vec<_>>();
    if let Some((name, _)) = channels.iter().find(|(_, s)| s.len() != w * h) {
        return Err(Error::input(
            path,
            format!("channel {name} is subsampled, which is not supported"),
        ));
    }
    Ok((width, height, channels))
}

/// Reads every channel of an OpenEXR file (first layer, full resolution) as
/// `(width, height, [(name, samples)])`; samples are row-major with row 0 at
/// the top, converted to `f32`; channels in alphabetical order. Meant for
/// tests and tools that check what [`write_exr`] produced.
pub fn read_exr_channels(path: &Path) -> Result<(u32, u32, ExrChannels)> {
    let bytes = crate::io::read_input(path)?;
    decode_exr_channels(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_wrong_lengths_and_names() {
        let p = std::env::temp_dir().join("alpenglow-never-written.exr");
        let rgba = vec![0.0; 4 * 6];
        let z = vec![0.0; 6];
        assert!(write_exr(&p, 3, 2, &rgba[1..], &z, &[]).is_err());
        assert!(write_exr(&p, 3, 2, &rgba, &z[1..], &[]).is_err());
        assert!(write_exr(&p, 3, 2, &rgba, &z, &[("Z", &z)]).is_err());
        assert!(write_exr(&p, 3, 2, &rgba, &z, &[("", &z)]).is_err());
        assert!(write_exr(&p, 3, 2, &rgba, &z, &[("W", &z[1..])]).is_err());
        assert!(write_exr(&p, 0, 2, &[], &[], &[]).is_err());
        assert!(write_png_rgba8(&p, &[0; 7], 1, 2).is_err());
        assert!(!p.exists());
    }

    #[test]
    fn formats_by_extension() {
        let f = |s: &str| ImageFormat::from_path(Path::new(s));
        assert_eq!(f("a.png"), Ok(ImageFormat::Png));
        assert_eq!(f("a.JPG"), Ok(ImageFormat::Jpeg));
        assert_eq!(f("a.jpeg"), Ok(ImageFormat::Jpeg));
        assert_eq!(f("a.bmp"), Err("unsupported extension .bmp; use .png or .jpg".into()));
        assert!(f("a").unwrap_err().contains("no file extension"));
        let rgba: Vec<u8> = (0..4 * 16 * 8).map(|i| (i % 251) as u8).collect();
        let jpeg = ImageFormat::Jpeg.encode_rgba8(&rgba, 16, 8).unwrap();
        assert_eq!(&jpeg[..3], &[0xFF, 0xD8, 0xFF], "JPEG start-of-image marker");
        let png = ImageFormat::Png.encode_rgba8(&rgba, 16, 8).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert!(encode_jpeg_rgba8(&rgba[1..], 16, 8).is_err());
    }
}
