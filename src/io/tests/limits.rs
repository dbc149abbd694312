//! Hostile and real-world height-map inputs, generated here: absurd PNG
//! headers, zlib bombs, corrupt checksums, special files, out-of-range
//! heights and spacings, GeoTIFF and SRTM `.hgt` DEMs, and the library's
//! upload-size checks (issue 15).

use std::path::{Path, PathBuf};

use crate::io::heightmap::{check_spacing, load_heightmap, HeightField, HeightmapOptions, RowOrder};
use crate::io::limits::InputLimits;
use crate::test_support::{absurd_png, crc32};
use glam::DVec2;

/// A fresh scratch directory under the system temp dir, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("alpenglow-io_limits-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Expects a one-line error that names the file and contains `needle`.
fn expect_error(path: &Path, opts: &HeightmapOptions, needle: &str) -> String {
    let msg = load_heightmap(path, opts).expect_err("bad input must fail").to_string();
    let file = path.file_name().unwrap().to_string_lossy();
    assert!(msg.contains(file.as_ref()), "message does not name {file}: {msg}");
    assert!(!msg.contains('\n'), "message is not one line: {msg:?}");
    assert!(msg.contains(needle), "expected {needle:?} in: {msg}");
    msg
}

/// A valid 16-bit greyscale PNG of `values`.
fn grey16_png(width: u32, height: u32, values: &[u16]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Sixteen);
    let mut w = enc.write_header().unwrap();
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    w.write_image_data(&data).unwrap();
    w.finish().unwrap();
    out
}

/// Byte ranges `(start of data, end of data)` of every IDAT chunk.
fn idat_chunks(png: &[u8]) -> Vec<(usize, usize)> {
    let mut at = 8;
    let mut found = Vec::new();
    while at + 8 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        if &png[at + 4..at + 8] == b"IDAT" {
            found.push((at + 8, at + 8 + len));
        }
        at += 12 + len;
    }
    found
}

#[test]
fn absurd_png_headers_are_one_line_errors_before_allocating() {
    let dir = Scratch::new("absurd");
    let opts = HeightmapOptions::default();
    for (w, h) in [
        (150_000, 100_000),
        (200_000, 200_000),
        (1_000_000, 1_000_000),
        (i32::MAX as u32, i32::MAX as u32),
    ] {
        let path = dir.file(&format!("claims-{w}x{h}.png"), &absurd_png(w, h));
        assert!(std::fs::metadata(&path).unwrap().len() < 100);
        expect_error(&path, &opts, "largest supported side is 32768");
    }
    // Within the side limit, beyond the pixel limit.
    let path = dir.file("claims-30000x30000.png", &absurd_png(30_000, 30_000));
    expect_error(&path, &opts, "more than the limit of 268435456");
    // Within every limit: the missing data is the error.
    let path = dir.file("claims-64x64.png", &absurd_png(64, 64));
    expect_error(&path, &opts, "invalid PNG");
}

#[test]
fn zlib_bombs_are_bounded_by_the_declared_size_limit() {
    let dir = Scratch::new("bomb");
    let side = 2048u32;
    let bomb = grey16_png(side, side, &vec![0u16; (side * side) as usize]);
    assert!(bomb.len() < 64 << 10, "{} bytes", bomb.len());
    let path = dir.file("bomb.png", &bomb);
    let lowered = HeightmapOptions {
        spacing: Some(DVec2::ONE),
        limits: InputLimits {
            max_image_pixels: 1 << 20,
            ..InputLimits::default()
        },
        ..HeightmapOptions::default()
    };
    expect_error(&path, &lowered, "more than the limit of 1048576");
    let decode = HeightmapOptions {
        limits: InputLimits {
            max_decode_bytes: 1 << 20,
            ..InputLimits::default()
        },
        ..lowered
    };
    expect_error(&path, &decode, "bytes decoded");
    // The default limits take it: it is a legal (flat) height map.
    let field = load_heightmap(&path, &HeightmapOptions::default()).unwrap();
    assert_eq!((field.columns, field.rows, field.min_max()), (side, side, (0.0, 0.0)));
}

#[test]
fn corrupt_checksums_and_truncation_are_rejected() {
    let dir = Scratch::new("corrupt");
    let (w, h) = (37u32, 23u32);
    let values: Vec<u16> = (0..w * h).map(|i| (i * 97 % 65536) as u16).collect();
    let good = grey16_png(w, h, &values);
    let field = load_heightmap(&dir.file("good.png", &good), &HeightmapOptions::default()).unwrap();
    assert_eq!(field.height(5, 3), f32::from(values[(3 * w + 5) as usize]));

    // Flip the zlib stream's Adler-32 (the last 4 bytes of the last IDAT)
    // and fix the chunk's CRC, so only the Adler-32 is wrong.
    let (start, end) = *idat_chunks(&good).last().unwrap();
    let mut adler = good.clone();
    for b in &mut adler[end - 4..end] {
        *b ^= 0xFF;
    }
    let crc = crc32(&adler[start - 4..end]);
    adler[end..end + 4].copy_from_slice(&crc.to_be_bytes());
    expect_error(
        &dir.file("adler.png", &adler),
        &HeightmapOptions::default(),
        "invalid PNG",
    );

    // A data byte changed, CRC left alone.
    let mut crc_bad = good.clone();
    crc_bad[start + 5] ^= 0x55;
    expect_error(
        &dir.file("crc.png", &crc_bad),
        &HeightmapOptions::default(),
        "invalid PNG",
    );

    // Cut inside the IDAT.
    let cut = &good[..(start + end) / 2];
    expect_error(&dir.file("cut.png", cut), &HeightmapOptions::default(), "invalid PNG");
}

#[test]
fn special_and_oversized_files_are_rejected_by_name() {
    let dir = Scratch::new("special");
    let opts = HeightmapOptions::default();
    let fifo = dir.0.join("fifo.png");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    // No writer: opening it would block forever.
    expect_error(&fifo, &opts, "is a FIFO, not a regular file");
    let msg = load_heightmap(Path::new("/dev/zero"), &opts).unwrap_err().to_string();
    assert!(
        msg.contains("/dev/zero: is a character device, not a regular file"),
        "{msg}"
    );
    expect_error(&dir.0, &opts, "is a directory");

    let path = dir.file("big.png", &grey16_png(4, 4, &[7; 16]));
    let tiny = HeightmapOptions {
        limits: InputLimits {
            max_file_bytes: 20,
            ..InputLimits::default()
        },
        ..opts
    };
    expect_error(&path, &tiny, "more than the limit of 20");
    assert_eq!(InputLimits::with_max_file_mib(3).max_file_bytes, 3 << 20);
}

#[test]
fn heights_and_spacings_out_of_range_name_the_problem() {
    let dir = Scratch::new("range");
    let (w, h) = (3u32, 2u32);
    let mut rgba = vec![0.0f32; (4 * w * h) as usize];
    rgba[4 * 4] = 3e38; // R of column 1, row 1
    let depth = vec![0.0f32; (w * h) as usize];
    let path = dir.0.join("huge.exr");
    crate::io::image_out::write_exr(&path, w, h, &rgba, &depth, &[]).unwrap();
    let msg = expect_error(
        &path,
        &HeightmapOptions::default(),
        "column 1, row 1 is 300000000000000000000000000000000000000 m",
    );
    assert!(msg.contains("within ±1000 km"), "{msg}");

    let png = dir.file("ramp.png", &grey16_png(2, 2, &[1, 2, 3, 4]));
    for bad in [1e30, 1e-30, 0.0, -1.0, f64::NAN, 1e5 * 1.001] {
        let opts = HeightmapOptions {
            spacing: Some(DVec2::new(bad, 1.0)),
            ..HeightmapOptions::default()
        };
        let msg = load_heightmap(&png, &opts).unwrap_err().to_string();
        assert!(msg.contains("0.001..=100000 m") && msg.contains("ramp.png"), "{msg}");
    }
    assert!(check_spacing(DVec2::new(1e-3, 1e5)).is_ok());
    assert!(check_spacing(DVec2::splat(1e30))
        .unwrap_err()
        .contains("1000000000000000000000000000000 m"));

    let field = HeightField::from_fn(3, 3, DVec2::ONE, |c, r| if (c, r) == (2, 1) { -2e6 } else { 0.0 });
    let msg = field.validate(Path::new("made")).unwrap_err().to_string();
    assert!(msg.contains("column 2, row 1 is -2000000 m"), "{msg}");
}

#[test]
fn png_rows_are_kept_south_up_or_flipped_north_up() {
    let dir = Scratch::new("rows");
    // 2 columns, 3 rows: row r holds 10·r + c.
    let path = dir.file("rows.png", &grey16_png(2, 3, &[0, 1, 10, 11, 20, 21]));
    let kept = load_heightmap(&path, &HeightmapOptions::default()).unwrap();
    assert_eq!(kept.heights, vec![0.0, 1.0, 10.0, 11.0, 20.0, 21.0]);
    let opts = HeightmapOptions {
        rows: RowOrder::NorthUp,
        ..HeightmapOptions::default()
    };
    let flipped = load_heightmap(&path, &opts).unwrap();
    assert_eq!(flipped.heights, vec![20.0, 21.0, 10.0, 11.0, 0.0, 1.0]);
}

/// A GeoTIFF of `values` (`width` columns) with `tags` written by `tag`.
fn geotiff<C, F>(path: &Path, width: u32, values: &[C::Inner], tag: F)
where
    C: tiff::encoder::colortype::ColorType,
    [C::Inner]: tiff::encoder::TiffValue,
    F: FnOnce(&mut tiff::encoder::DirectoryEncoder<'_, std::fs::File, tiff::encoder::TiffKindStandard>),
{
    let file = std::fs::File::create(path).unwrap();
    let mut tiff = tiff::encoder::TiffEncoder::new(file).unwrap();
    let height = values.len() as u32 / width;
    let mut image = tiff.new_image::<C>(width, height).unwrap();
    tag(image.encoder());
    image.write_data(values).unwrap();
}

#[test]
fn geotiffs_take_spacing_and_orientation_from_their_georeferencing() {
    use tiff::encoder::colortype::{Gray16, Gray32Float, GrayI16};
    use tiff::tags::Tag;
    let dir = Scratch::new("geotiff");
    // 3 columns, 2 rows; row 0 (north) holds 100.., row 1 holds 200...
    let values = [100u16, 101, 102, 200, 201, 202];

    // Geographic: 1/1200° (3″) pixels, top edge at 45.5°N, 2 rows.
    let geo = dir.0.join("geographic.tif");
    geotiff::<Gray16, _>(&geo, 3, &values, |e| {
        e.write_tag(Tag::ModelPixelScaleTag, &[1.0 / 1200.0, 1.0 / 1200.0, 0.0][..])
            .unwrap();
        e.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 7.0, 45.5, 0.0][..])
            .unwrap();
        e.write_tag(Tag::GeoKeyDirectoryTag, &[1u16, 1, 0, 1, 1024, 0, 1, 2][..])
            .unwrap();
    });
    let f = load_heightmap(&geo, &HeightmapOptions::default()).unwrap();
    // Flipped: field row 0 is the southern row.
    assert_eq!(f.heights, vec![200.0, 201.0, 202.0, 100.0, 101.0, 102.0]);
    // At 45.5°N: about 78 159 m per degree of longitude, 111 141 m of latitude.
    let per_deg = crate::io::hgt::metres_per_degree(45.5 - 1.0 / 1200.0);
    assert!(
        (f.spacing - per_deg / 1200.0).abs().max_element() < 1e-9,
        "{}",
        f.spacing
    );
    assert!(
        (f.spacing.x - 65.13).abs() < 0.01 && (f.spacing.y - 92.62).abs() < 0.01,
        "{}",
        f.spacing
    );
    // An explicit spacing wins.
    let given = HeightmapOptions {
        spacing: Some(DVec2::splat(5.0)),
        ..HeightmapOptions::default()
    };
    assert_eq!(load_heightmap(&geo, &given).unwrap().spacing, DVec2::splat(5.0));

    // Projected, in feet, by a transformation whose y scale is positive
    // (row 0 south: kept). Signed 16-bit heights.
    let feet = dir.0.join("projected.tif");
    let signed = [-5i16, 0, 5, 10, 15, 20];
    geotiff::<GrayI16, _>(&feet, 3, &signed, |e| {
        let m = [
            10.0, 0.0, 0.0, 500.0, 0.0, 20.0, 0.0, 4000.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ];
        e.write_tag(Tag::ModelTransformationTag, &m[..]).unwrap();
        e.write_tag(
            Tag::GeoKeyDirectoryTag,
            &[1u16, 1, 0, 2, 1024, 0, 1, 1, 3076, 0, 1, 9002][..],
        )
        .unwrap();
    });
    let f = load_heightmap(&feet, &HeightmapOptions::default()).unwrap();
    assert_eq!(f.heights, vec![-5.0, 0.0, 5.0, 10.0, 15.0, 20.0]);
    assert!(
        (f.spacing - DVec2::new(3.048, 6.096)).abs().max_element() < 1e-12,
        "{}",
        f.spacing
    );

    // Float samples with a GDAL no-data marker: the void is named.
    let voids = dir.0.join("voids.tif");
    geotiff::<Gray32Float, _>(&voids, 2, &[1.0f32, 2.0, -9999.0, 4.0], |e| {
        e.write_tag(Tag::ModelPixelScaleTag, &[30.0, 30.0, 0.0][..]).unwrap();
        e.write_tag(Tag::GdalNodata, "-9999").unwrap();
    });
    expect_error(
        &voids,
        &HeightmapOptions::default(),
        "no-data sample (-9999) at column 0, row 1",
    );

    // Plain TIFF (no georeferencing): like a PNG, rows kept, spacing given.
    let plain = dir.0.join("plain.tif");
    geotiff::<Gray32Float, _>(&plain, 2, &[1.0f32, 2.0, 3.0, 4.0], |_| {});
    let f = load_heightmap(&plain, &HeightmapOptions::default()).unwrap();
    assert_eq!((f.heights.clone(), f.spacing), (vec![1.0, 2.0, 3.0, 4.0], DVec2::ONE));

    // A header claiming a huge image is rejected before decoding.
    let big = dir.0.join("big.tif");
    geotiff::<Gray16, _>(&big, 3, &values, |_| {});
    let small = HeightmapOptions {
        limits: InputLimits {
            max_image_pixels: 5,
            ..InputLimits::default()
        },
        ..HeightmapOptions::default()
    };
    expect_error(&big, &small, "more than the limit of 5");
}

#[test]
fn srtm_hgt_files_are_north_up_with_spacing_from_their_latitude() {
    let dir = Scratch::new("hgt");
    let side = 1201usize;
    let mut bytes = Vec::with_capacity(side * side * 2);
    for r in 0..side {
        for c in 0..side {
            bytes.extend_from_slice(&((r as i16) - (c as i16 % 7)).to_be_bytes());
        }
    }
    let path = dir.file("N45E007.hgt", &bytes);
    let f = load_heightmap(&path, &HeightmapOptions::default()).unwrap();
    assert_eq!((f.columns, f.rows), (1201, 1201));
    // File row 0 (north, height 0 − c%7) is field row 1200.
    assert_eq!(f.height(3, 1200), -3.0);
    assert_eq!(f.height(0, 0), 1200.0);
    let per_deg = crate::io::hgt::metres_per_degree(45.5);
    assert!(
        (f.spacing - per_deg / 1200.0).abs().max_element() < 1e-9,
        "{}",
        f.spacing
    );

    bytes[2 * (side * 3 + 4)..2 * (side * 3 + 4) + 2].copy_from_slice(&(-32768i16).to_be_bytes());
    let voids = dir.file("N45E008.hgt", &bytes);
    expect_error(
        &voids,
        &HeightmapOptions::default(),
        "void sample (−32768) at column 4, row 3",
    );
    let unnamed = dir.file("dem.hgt", &bytes);
    expect_error(&unnamed, &HeightmapOptions::default(), "like N37W122.hgt");
}

#[test]
fn exr_deep_flags_and_absurd_data_windows_are_rejected() {
    let dir = Scratch::new("exr");
    let (w, h) = (4u32, 4u32);
    let n = (w * h) as usize;
    let path = dir.0.join("ok.exr");
    crate::io::image_out::write_exr(&path, w, h, &vec![1.0; 4 * n], &vec![0.0; n], &[]).unwrap();
    let good = std::fs::read(&path).unwrap();
    assert!(load_heightmap(&path, &HeightmapOptions::default()).is_ok());

    let mut deep = good.clone();
    deep[5] |= 0x08; // version flags bit 11: "has deep data"
    expect_error(
        &dir.file("deep.exr", &deep),
        &HeightmapOptions::default(),
        "deep data is not supported",
    );

    // dataWindow box2i: xMin, yMin, xMax, yMax after "dataWindow\0box2i\0" and a size.
    let key = b"dataWindow\0box2i\0";
    let at = good.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    let mut huge = good.clone();
    huge[at + 8..at + 12].copy_from_slice(&999_999i32.to_le_bytes());
    huge[at + 12..at + 16].copy_from_slice(&999_999i32.to_le_bytes());
    let msg = load_heightmap(&dir.file("huge.exr", &huge), &HeightmapOptions::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("huge.exr") && !msg.contains('\n'), "{msg}");
}

#[test]
fn image_with_data_checks_the_length_and_renderer_validates_the_field() {
    use crate::vulkan::{Image, ImageDesc};
    use ash::vk;
    let (ctx, report) = crate::test_support::validated_context();
    let desc = ImageDesc {
        name: "short".into(),
        width: 1024,
        height: 1024,
        format: vk::Format::R32_SFLOAT,
        usage: vk::ImageUsageFlags::SAMPLED,
    };
    let msg = Image::with_data(&ctx, desc.clone(), &[0u8; 4]).unwrap_err().to_string();
    assert!(msg.contains("4194304 bytes") && msg.contains("but 4 bytes"), "{msg}");
    let small = ImageDesc {
        width: 2,
        height: 2,
        ..desc
    };
    assert!(Image::with_data(&ctx, small, &[0u8; 16]).is_ok());

    let mut scene = crate::renderer::Scene::new(HeightField::from_fn(8, 8, DVec2::splat(10.0), |_, _| 1.0));
    scene.heights.heights.truncate(10);
    let settings = crate::renderer::RenderSettings::new(64, 48);
    let msg = crate::renderer::Renderer::new(&ctx, &scene, settings)
        .err()
        .expect("a short field must fail")
        .to_string();
    assert!(msg.contains("10 height samples for a 8×8 grid"), "{msg}");
    ctx.wait_idle().ok();
    drop(ctx);
    crate::test_support::assert_validation_clean(&report);
}
