//! End-to-end tests of height pyramids (issue 31 item 1): `alpenglow dem
//! import` / `dem info`, `render --heightmap FILE.hpyr` against the same
//! field rendered from its PNG (FLIP), one-line errors for corrupt files,
//! and a 65536² procedural field (written into the tiled format here, not
//! checked in) rendered under validation with the process's peak memory
//! under 4 GiB, the same as for a 16384² field (memory does not grow with
//! the field).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use alpenglow::files::write_ridge_region;
use common::cli::*;

fn jacksboro() -> PathBuf {
    common::data("jacksboro-fault.png")
}

#[test]
fn a_pyramid_renders_as_its_source_does() {
    let dir = fresh_dir("dem-render");
    let pyramid = dir.join("jacksboro.hpyr");
    let out = run(&[
        "dem".as_ref(),
        "import".as_ref(),
        jacksboro().as_os_str(),
        "--spacing".as_ref(),
        "74.4,92.6".as_ref(),
        "--tile-side".as_ref(),
        "64".as_ref(),
        "--out".as_ref(),
        pyramid.as_os_str(),
    ]);
    assert_success("dem import", &out);
    assert!(
        text(&out.stdout).contains("403×344 samples, 4 levels"),
        "{}",
        text(&out.stdout)
    );
    let out = run(&[
        "dem".as_ref(),
        "info".as_ref(),
        pyramid.as_os_str(),
        "--verify".as_ref(),
    ]);
    assert_success("dem info", &out);
    assert!(text(&out.stdout).contains("every tile read and checked"));

    let render = |heightmap: &Path, extra: &[&str], name: &str| {
        let png = dir.join(name);
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "render".as_ref(),
            "--heightmap".as_ref(),
            heightmap.as_os_str(),
            "--width".as_ref(),
            "160".as_ref(),
            "--height".as_ref(),
            "100".as_ref(),
            "--validation".as_ref(),
            "--out".as_ref(),
            png.as_os_str(),
        ];
        args.extend(extra.iter().map(|a| std::ffi::OsStr::new(*a)));
        assert_success(name, &run(&args));
        read_rgba(&png)
    };
    let (from_png, w, h) = render(&jacksboro(), &["--spacing", "74.4,92.6"], "png.png");
    let (from_pyramid, ..) = render(&pyramid, &[], "pyramid.png");
    let coarse_only = ["--resident-side", "128", "--detail-window", "0"];
    let (coarse, ..) = render(&pyramid, &coarse_only, "coarse.png");
    // Level 2 resident and a finer level streamed in the detail window (by
    // default; level 1, the finest whose 1024 samples span 32 heights of
    // the overview camera).
    let (streamed, ..) = render(&pyramid, &["--resident-side", "128"], "streamed.png");
    // Level 0 differs from the PNG only by the 1/256 m quantum: the same image.
    let (same, _) = common::mean_flip(&from_png, &from_pyramid, w, h);
    assert!(same <= 0.005, "pyramid level 0 vs PNG: mean FLIP {same}");
    // Level 2 (102×87 samples) is a smoother terrain: the test can tell.
    let (different, _) = common::mean_flip(&from_png, &coarse, w, h);
    assert!(
        different > 4.0 * same.max(0.002),
        "level 2 vs PNG: mean FLIP {different}"
    );
    // The window brings level 1 back (measured 0.037 against 0.046; the
    // lighting's baked maps still come from level 2).
    let (window, _) = common::mean_flip(&from_png, &streamed, w, h);
    eprintln!("mean FLIP against the PNG: level 0 {same}, level 2 {different}, level 2 + window {window}");
    assert!(
        window < 0.9 * different,
        "level 2 + detail window vs PNG: mean FLIP {window}"
    );
}

#[test]
fn corrupt_pyramids_and_bad_options_are_one_line_errors() {
    let dir = fresh_dir("dem-errors");
    let pyramid = dir.join("j.hpyr");
    let out = run(&[
        "dem".as_ref(),
        "import".as_ref(),
        jacksboro().as_os_str(),
        "--tile-side".as_ref(),
        "8".as_ref(),
        "--out".as_ref(),
        pyramid.as_os_str(),
    ]);
    assert_one_line_error("tile side 8", &out, &["tile side", "8"]);
    assert!(!pyramid.exists());
    let out = run(&[
        "dem".as_ref(),
        "import".as_ref(),
        jacksboro().as_os_str(),
        "--out".as_ref(),
        pyramid.as_os_str(),
    ]);
    assert_success("dem import", &out);
    let mut bytes = std::fs::read(&pyramid).unwrap();
    bytes[4000] ^= 0x10;
    let broken = dir.join("broken.hpyr");
    std::fs::write(&broken, &bytes).unwrap();
    let out = run(&["dem".as_ref(), "info".as_ref(), broken.as_os_str(), "--verify".as_ref()]);
    assert_one_line_error("corrupt tile", &out, &["broken.hpyr", "checksum"]);
    let truncated = dir.join("truncated.hpyr");
    std::fs::write(&truncated, &bytes[..bytes.len() - 100]).unwrap();
    let png = dir.join("t.png");
    let out = run(&[
        "render".as_ref(),
        "--heightmap".as_ref(),
        truncated.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
    ]);
    assert_one_line_error("truncated", &out, &["truncated.hpyr", "truncated"]);
    assert!(!png.exists());
    let out = run(&[
        "render".as_ref(),
        "--heightmap".as_ref(),
        pyramid.as_os_str(),
        "--resident-side".as_ref(),
        "1".as_ref(),
    ]);
    assert_one_line_error("resident side 1", &out, &["--resident-side"]);
}

/// `VmHWM` (peak resident set) of process `pid` in bytes.
fn peak_rss(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
}

/// A procedural `side²` field at 1 m written as a pyramid
/// ([`write_ridge_region`]).
fn procedural_pyramid(dir: &Path, side: u32) -> PathBuf {
    let path = dir.join(format!("procedural-{side}.hpyr"));
    write_ridge_region(&path, side).unwrap();
    path
}

/// Renders `pyramid` under validation; returns the peak resident memory.
fn render_peak_memory(pyramid: &Path, png: &Path) -> u64 {
    let mut child = Command::new(bin())
        .args([
            "render",
            "--vegetation",
            "off",
            "--validation",
            "--width",
            "160",
            "--height",
            "100",
        ])
        // Over the field's south-west, looking north-east along it from 2 km up.
        .args(["--eye", "8000,3000,2600", "--target", "9000,9000,600"])
        .arg("--heightmap")
        .arg(pyramid)
        .arg("--out")
        .arg(png)
        .env(
            "XDG_CACHE_HOME",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut peak = 0;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        peak = peak.max(peak_rss(child.id()).unwrap_or(0));
        std::thread::sleep(Duration::from_millis(10));
    };
    let stderr = child.wait_with_output().map(|o| text(&o.stderr)).unwrap_or_default();
    assert!(status.success(), "render of {} failed: {stderr}", pyramid.display());
    assert!(peak > 0, "the peak memory was not read");
    peak
}

#[test]
fn a_65536_field_renders_in_bounded_memory() {
    let dir = fresh_dir("dem-65536");
    let small = procedural_pyramid(&dir, 16384);
    let small_peak = render_peak_memory(&small, &dir.join("16384.png"));
    let big = procedural_pyramid(&dir, 65536);
    let big_peak = render_peak_memory(&big, &dir.join("65536.png"));
    let gib = |b: u64| b as f64 / f64::from(1 << 30);
    eprintln!(
        "peak resident memory: 16384² {:.2} GiB, 65536² {:.2} GiB",
        gib(small_peak),
        gib(big_peak)
    );
    assert!(big_peak < 4 << 30, "65536²: {:.2} GiB", gib(big_peak));
    // The resident level is 4097² for both (levels 2 and 4): memory does not
    // grow with the field.
    assert!(
        (big_peak as f64) < 1.15 * small_peak as f64,
        "65536² {:.2} GiB vs 16384² {:.2} GiB",
        gib(big_peak),
        gib(small_peak)
    );
    let (image, w, h) = read_rgba(&dir.join("65536.png"));
    // Ground, not only sky: the lower half differs from the top row's colour.
    let top = &image[..4];
    let differing = image[(w * h / 2 * 4) as usize..]
        .chunks_exact(4)
        .filter(|p| p.iter().zip(top).any(|(a, b)| a.abs_diff(*b) > 24))
        .count();
    assert!(differing > (w * h / 4) as usize, "{differing} ground pixels");
    // The pyramids go; the two PNGs stay to be looked at.
    std::fs::remove_file(&small).ok();
    std::fs::remove_file(&big).ok();
}

/// GDAL (feature `gdal`): a GeoTIFF written by GDAL itself, and a VRT
/// mosaic of its two halves, import to the same heights as alpenglow's own
/// GeoTIFF reader gives (two independent readers), north-up rows flipped to
/// the field's south-up order, spacing from the geotransform.
#[cfg(feature = "gdal")]
#[test]
fn gdal_rasters_and_vrt_mosaics_import_like_the_builtin_reader() {
    use alpenglow::files::{load_heightmap, HeightPyramid};
    use gdal::raster::Buffer;
    use gdal::{spatial_ref::SpatialRef, DriverManager};

    let dir = fresh_dir("dem-gdal");
    let field = common::jacksboro_field();
    let (w, h) = (field.columns as usize, field.rows as usize);
    let driver = DriverManager::get_driver_by_name("GTiff").unwrap();
    // Columns c0..c1 of the field as a north-up GeoTIFF in UTM 16N.
    let write_tif = |name: &str, c0: usize, c1: usize| {
        let path = dir.join(name);
        let mut ds = driver.create_with_band_type::<f32, _>(&path, c1 - c0, h, 1).unwrap();
        ds.set_geo_transform(&[500_000.0 + c0 as f64 * 74.4, 74.4, 0.0, 4_000_000.0, 0.0, -92.6])
            .unwrap();
        ds.set_spatial_ref(&SpatialRef::from_epsg(32616).unwrap()).unwrap();
        let data: Vec<f32> = (0..h)
            .flat_map(|r| (c0..c1).map(move |c| (c, h - 1 - r)))
            .map(|(c, r)| field.height(c as u32, r as u32))
            .collect();
        let mut buffer = Buffer::new((c1 - c0, h), data);
        ds.rasterband(1)
            .unwrap()
            .write((0, 0), (c1 - c0, h), &mut buffer)
            .unwrap();
        path
    };
    let whole = write_tif("whole.tif", 0, w);
    let west = write_tif("west.tif", 0, 200);
    let east = write_tif("east.tif", 200, w);
    let vrt = dir.join("mosaic.vrt");
    let source = |file: &Path, x0: usize, width: usize| {
        format!(
            "<SimpleSource><SourceFilename relativeToVRT=\"0\">{}</SourceFilename><SourceBand>1</SourceBand>\
             <SrcRect xOff=\"0\" yOff=\"0\" xSize=\"{width}\" ySize=\"{h}\"/>\
             <DstRect xOff=\"{x0}\" yOff=\"0\" xSize=\"{width}\" ySize=\"{h}\"/></SimpleSource>",
            file.display()
        )
    };
    std::fs::write(
        &vrt,
        format!(
            "<VRTDataset rasterXSize=\"{w}\" rasterYSize=\"{h}\">\
             <GeoTransform>500000, 74.4, 0, 4000000, 0, -92.6</GeoTransform>\
             <VRTRasterBand dataType=\"Float32\" band=\"1\">{}{}</VRTRasterBand></VRTDataset>",
            source(&west, 0, 200),
            source(&east, 200, w - 200)
        ),
    )
    .unwrap();
    let builtin = load_heightmap(&whole, &alpenglow::HeightmapOptions::default()).unwrap();
    assert_eq!(
        builtin.heights, field.heights,
        "the GeoTIFF's rows are the field's, flipped"
    );
    for (name, input) in [("tif", &whole), ("vrt", &vrt)] {
        let out = dir.join(format!("{name}.hpyr"));
        let import = run(&[
            "dem".as_ref(),
            "import".as_ref(),
            input.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        assert_success(name, &import);
        let pyramid = HeightPyramid::open(&out).unwrap();
        let spacing = pyramid.spacing();
        assert!(
            (spacing.x - 74.4).abs() < 1e-9 && (spacing.y - 92.6).abs() < 1e-9,
            "{name}: {spacing}"
        );
        let level0 = pyramid.level_field(0).unwrap();
        for (i, (a, b)) in level0.heights.iter().zip(&builtin.heights).enumerate() {
            assert!(
                (a - b).abs() <= 0.5 / 256.0,
                "{name}: sample {i}: GDAL {a} vs built-in {b}"
            );
        }
    }
}
