//! Shared helpers of the in-crate white-box tests (a copy of what they need
//! from `tests/common`): every test device runs
//! with the Khronos validation layers and synchronization validation, and
//! every test ends by asserting that nothing was reported.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::io::heightmap::{load_heightmap, HeightField, HeightmapOptions};
use crate::vulkan::{Context, ContextOptions, DeviceSelector, ValidationReport};

/// Both terrain rasterizer paths (issue 28): the terrain, lighting and AOV
/// tests that check a rendered frame against a reference run in each.
pub const RASTER_PATHS: [crate::RasterPath; 2] = [crate::RasterPath::Hardware, crate::RasterPath::Compute];

/// A buffer copies read from and write to, shared (to import into a graph).
pub fn transfer_buffer(
    ctx: &Context,
    name: &str,
    size: u64,
    location: crate::vulkan::MemoryLocation,
) -> Arc<crate::vulkan::Buffer> {
    let usage = crate::vulkan::BufferUsageFlags::TRANSFER_DST | crate::vulkan::BufferUsageFlags::TRANSFER_SRC;
    let desc = crate::vulkan::BufferDesc {
        name: name.into(),
        size,
        usage,
        location,
    };
    Arc::new(crate::vulkan::Buffer::new(ctx, desc).expect("a transfer buffer"))
}

/// A context with validation and synchronization validation on.
pub fn validated_context() -> (Context, Arc<ValidationReport>) {
    let ctx = Context::new(&ContextOptions {
        validation: true,
        device: std::env::var("ALPENGLOW_DEVICE")
            .ok()
            .and_then(|d| d.parse().ok())
            .unwrap_or(DeviceSelector::Best),
    })
    .unwrap_or_else(|e| panic!("cannot create a validated Vulkan context: {e}"));
    let report = ctx.validation_report().expect("validation was requested");
    (ctx, report)
}

/// Fails the test if validation reported any error or warning. Call after
/// every Vulkan object (and the context) was dropped, so leak reports count.
pub fn assert_validation_clean(report: &ValidationReport) {
    let messages = report.messages();
    assert!(
        report.total() == 0,
        "validation reported {} error(s) and {} warning(s):\n{}",
        report.errors(),
        report.warnings(),
        messages.join("\n")
    );
}

/// A file in `tests/data`.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// The real Jacksboro DEM (`tests/data/README.md`): metres, 74.4 m × 92.6 m
/// spacing.
pub fn jacksboro_field() -> HeightField {
    let options = HeightmapOptions {
        scale: 1.0,
        offset: 0.0,
        spacing: Some(glam::DVec2::new(74.4, 92.6)),
        ..Default::default()
    };
    load_heightmap(&data("jacksboro-fault.png"), &options).expect("real DEM")
}

/// Along the valley of the Jacksboro fault, from its south-western part
/// towards the north-east, a few hundred metres above the valley floor.
pub fn jacksboro_valley_camera() -> crate::renderer::Camera {
    crate::renderer::Camera {
        eye: glam::DVec3::new(13600.0, 9600.0, 750.0),
        target: glam::DVec3::new(18500.0, 21500.0, 350.0),
        up: glam::DVec3::Z,
        fov_y_deg: 50.0,
        near: 5.0,
        far: 100000.0,
    }
}

/// The directory holding golden images.
pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// Where failing image tests leave their output for inspection.
pub fn failure_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/golden-failures");
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// Scratch space of the in-crate tests (what `CARGO_TARGET_TMPDIR` is to
/// integration tests, which unit tests do not get): `target/tmp`.
pub fn target_tmp() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/tmp");
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// Mean FLIP error between two sRGB RGBA8 images of the same size (alpha ignored).
pub fn mean_flip(reference_rgba: &[u8], test_rgba: &[u8], width: u32, height: u32) -> (f32, Vec<u8>) {
    let rgb = |rgba: &[u8]| -> Vec<u8> { rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference_rgba));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test_rgba));
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let heatmap = error.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let mean = nv_flip::FlipPool::from_image(&error).mean();
    (mean, heatmap)
}
pub mod atlas;
pub mod plane;
pub mod points;

/// With `ALPENGLOW_DUMP=DIR` (an existing folder), writes each named RGBA8
/// image as `DIR/<n>-<name>.png`, n the number of entries already there,
/// for looking at what an image test compared.
pub fn dump_pngs(images: &[(&str, &[u8])], width: u32, height: u32) {
    let Ok(dir) = std::env::var("ALPENGLOW_DUMP") else {
        return;
    };
    let dir = Path::new(&dir);
    let n = std::fs::read_dir(dir).map(|d| d.count()).unwrap_or(0);
    for (name, rgba) in images {
        let _ = crate::io::image_out::write_png_rgba8(&dir.join(format!("{n}-{name}.png")), rgba, width, height);
    }
}

/// RGBA8 images of `width` columns and the same height, side by side.
pub fn side_by_side(images: &[Vec<u8>], width: u32) -> Vec<u8> {
    let row = width as usize * 4;
    let rows = images[0].len() / row;
    (0..rows)
        .flat_map(|r| {
            images
                .iter()
                .flat_map(move |i| i[r * row..(r + 1) * row].iter().copied())
        })
        .collect()
}

/// Per-pixel FLIP error between two sRGB RGBA8 images of the same size (alpha ignored).
pub fn flip_errors(reference_rgba: &[u8], test_rgba: &[u8], width: u32, height: u32) -> Vec<f32> {
    let rgb = |rgba: &[u8]| -> Vec<u8> { rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference_rgba));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test_rgba));
    nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec()
}

/// sRGB8 code value → linear.
pub fn srgb8_to_linear(c: u8) -> f32 {
    let s = f32::from(c) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear RGB → sRGB8 code value (the transfer function of the tone mapper's output stage, no tone curve).
pub fn linear_to_srgb8(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// CRC-32 (ISO-HDLC), as PNG chunks use it.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG chunk with its length and CRC.
pub fn png_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    let mut body = kind.to_vec();
    body.extend_from_slice(data);
    out.extend_from_slice(&body);
    out.extend_from_slice(&crc32(&body).to_be_bytes());
    out
}

/// A tiny PNG whose header claims a `width`×`height` 16-bit greyscale
/// image, with an empty zlib stream as its data.
pub fn absurd_png(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[16, 0, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(png_chunk(b"IHDR", &ihdr));
    png.extend(png_chunk(b"IDAT", &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01]));
    png.extend(png_chunk(b"IEND", &[]));
    png
}

/// The `.rs` files under `folder`, recursively.
pub fn rust_files(folder: &Path, files: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        match path.is_dir() {
            true => rust_files(&path, files),
            false if path.extension().is_some_and(|e| e == "rs") => files.push(path),
            false => {}
        }
    }
}
