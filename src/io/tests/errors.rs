//! Height-map loading against the real DEM and bad fixtures in tests/data,
//! EXR and PNG output round trips, and atomic-write guarantees.

use crate::test_support::data;
use std::path::{Path, PathBuf};

use crate::io::heightmap::{load_heightmap, HeightmapOptions};
use crate::io::image_out::{read_exr_channels, write_exr, write_png_rgba8};
use glam::DVec2;

/// A fresh, empty scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = crate::test_support::target_tmp().join(format!("io_errors-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Loads `path`, expects an error, and checks the message is one line that
/// names the file and contains `needle`.
fn expect_error(path: &Path, opts: &HeightmapOptions, needle: &str) {
    let err = load_heightmap(path, opts).expect_err("bad input must fail");
    let msg = err.to_string();
    let file = path.file_name().unwrap().to_string_lossy();
    assert!(msg.contains(file.as_ref()), "message does not name {file}: {msg}");
    assert!(!msg.contains('\n'), "message is not one line: {msg:?}");
    assert!(msg.contains(needle), "expected {needle:?} in: {msg}");
}

fn write_grey16(path: &Path, width: u32, height: u32, values: &[u16]) {
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, values.to_vec())
        .unwrap()
        .save(path)
        .unwrap();
}

#[test]
fn real_dem_loads_with_expected_size_range_and_spacing() {
    let path = data("jacksboro-fault.png");
    let field = load_heightmap(&path, &HeightmapOptions::default()).unwrap();
    assert_eq!((field.columns, field.rows), (403, 344));
    assert_eq!(field.heights.len(), 403 * 344);
    assert_eq!(field.min_max(), (236.0, 1076.0));
    assert_eq!(field.spacing, DVec2::ONE);

    // Row r of the image is row r of the field: no flipping.
    let img = image::open(&path).unwrap().into_luma16();
    for (c, r) in [(0, 0), (402, 0), (0, 343), (201, 172), (402, 343)] {
        assert_eq!(field.height(c, r), f32::from(img.get_pixel(c, r).0[0]));
    }

    let opts = HeightmapOptions {
        scale: 2.0,
        offset: -100.0,
        spacing: Some(DVec2::new(74.4, 92.6)),
        ..Default::default()
    };
    let scaled = load_heightmap(&path, &opts).unwrap();
    assert_eq!(scaled.min_max(), (372.0, 2052.0));
    assert_eq!(scaled.spacing, DVec2::new(74.4, 92.6));
    let extent = scaled.extent();
    assert!((extent.x - 402.0 * 74.4).abs() < 1e-9 && (extent.y - 343.0 * 92.6).abs() < 1e-9);
    assert_eq!(scaled.height(10, 20), 2.0 * field.height(10, 20) - 100.0);
}

#[test]
fn tiny_ramp_values_and_orientation() {
    let field = load_heightmap(&data("tiny-ramp.png"), &HeightmapOptions::default()).unwrap();
    assert_eq!((field.columns, field.rows), (8, 6));
    for r in 0..6 {
        for c in 0..8 {
            assert_eq!(field.height(c, r), (1000 * r + 10 * c) as f32);
        }
    }
}

#[test]
fn bad_fixtures_fail_with_one_line_messages() {
    let o = HeightmapOptions::default();
    expect_error(&data("truncated.png"), &o, "invalid PNG");
    expect_error(&data("empty.png"), &o, "empty");
    expect_error(&data("not-an-image.png"), &o, "not a PNG");
    expect_error(&data("colour.png"), &o, "colour");
    expect_error(&data("nan.exr"), &o, "column 2, row 1");
    expect_error(&data("does-not-exist.png"), &o, "not found");
    expect_error(&data("README.md"), &o, "unsupported");
}

#[test]
fn small_and_8_bit_images() {
    let dir = scratch("small");
    let thin = dir.join("thin.png");
    write_grey16(&thin, 1, 5, &[1, 2, 3, 4, 5]);
    expect_error(&thin, &HeightmapOptions::default(), "at least 2×2");

    let grey8 = dir.join("grey8.png");
    image::GrayImage::from_raw(3, 2, vec![0, 1, 2, 250, 251, 255])
        .unwrap()
        .save(&grey8)
        .unwrap();
    let opts = HeightmapOptions {
        scale: 0.5,
        offset: 10.0,
        ..Default::default()
    };
    let field = load_heightmap(&grey8, &opts).unwrap();
    assert_eq!(field.heights, vec![10.0, 10.5, 11.0, 135.0, 135.5, 137.5]);
}

#[test]
fn exr_roundtrip_keeps_channels_and_infinite_depth() {
    let dir = scratch("exr");
    let path = dir.join("frame.exr");
    let (w, h) = (5u32, 3u32);
    let n = (w * h) as usize;
    let rgba: Vec<f32> = (0..4 * n).map(|i| i as f32 * 0.25 - 1.0).collect();
    let mut depth: Vec<f32> = (0..n).map(|i| 10.0 + i as f32).collect();
    depth[0] = f32::INFINITY;
    depth[n - 1] = f32::INFINITY;
    let extra: Vec<f32> = (0..n).map(|i| (i * i) as f32).collect();
    write_exr(&path, w, h, &rgba, &depth, &[("W", &extra)]).unwrap();
    assert_eq!(listing(&dir), ["frame.exr"]);

    let (rw, rh, channels) = read_exr_channels(&path).unwrap();
    assert_eq!((rw, rh), (w, h));
    let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["A", "B", "G", "R", "W", "Z"]);
    let get = |name: &str| &channels.iter().find(|(n, _)| n == name).unwrap().1;
    for (k, name) in ["R", "G", "B", "A"].iter().enumerate() {
        let expect: Vec<f32> = rgba.iter().skip(k).step_by(4).copied().collect();
        assert_eq!(get(name), &expect, "channel {name}");
    }
    assert_eq!(get("Z"), &depth);
    assert_eq!(get("W"), &extra);

    // Same input, same bytes.
    let again = dir.join("again.exr");
    write_exr(&again, w, h, &rgba, &depth, &[("W", &extra)]).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(&again).unwrap());

    // As a height map, an EXR without "Y" uses "R"; the infinite Z is ignored.
    let field = load_heightmap(&path, &HeightmapOptions::default()).unwrap();
    assert_eq!(&field.heights, get("R"));
}

#[test]
fn png_output_is_deterministic_and_decodes_back() {
    let dir = scratch("png");
    let (w, h) = (7u32, 4u32);
    let rgba: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 256) as u8).collect();
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    write_png_rgba8(&a, &rgba, w, h).unwrap();
    write_png_rgba8(&b, &rgba, w, h).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let back = image::open(&a).unwrap().into_rgba8();
    assert_eq!(back.dimensions(), (w, h));
    assert_eq!(back.into_raw(), rgba);
    assert_eq!(listing(&dir), ["a.png", "b.png"]);
}

#[test]
fn writes_into_a_missing_directory_fail_and_create_nothing() {
    let dir = scratch("atomic");
    let missing = dir.join("missing");
    let png = missing.join("shot.png");
    let err = write_png_rgba8(&png, &[0; 16], 2, 2).unwrap_err().to_string();
    assert!(err.contains("shot.png") && err.contains("does not exist"), "{err}");
    let exr = missing.join("frame.exr");
    let err = write_exr(&exr, 1, 1, &[0.0; 4], &[f32::INFINITY], &[])
        .unwrap_err()
        .to_string();
    assert!(err.contains("frame.exr") && !err.contains('\n'), "{err}");
    assert!(!missing.exists());
    assert!(listing(&dir).is_empty());

    // Bad input fails before anything touches the disk.
    let target = dir.join("bad.exr");
    assert!(write_exr(&target, 2, 2, &[0.0; 4], &[0.0; 4], &[]).is_err());
    assert!(listing(&dir).is_empty());
}
