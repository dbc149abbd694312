//! Height pyramids: round trips against the source, every coarser level
//! against an independent whole-array twin of the filter, corruption and
//! truncation found, mosaics stitched.

use std::path::{Path, PathBuf};

use glam::DVec2;

use super::*;
use crate::io::heightmap::HeightField;

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-pyramid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Rough relief: a hash of the sample plus a slope (residuals of several
/// bytes, so the codec's long varints are exercised).
fn rough(columns: u32, rows: u32) -> HeightField {
    HeightField::from_fn(columns, rows, DVec2::new(2.0, 3.0), |c, r| {
        let hash = (c.wrapping_mul(2_654_435_761) ^ r.wrapping_mul(40_503)) % 10_007;
        hash as f32 * 0.37 - 1500.0 + c as f32 * 0.5
    })
}

/// Level `l + 1` from level `l` as a whole 2-D array: the 3×3 binomial
/// kernel centred on every second sample, edges clamped.
fn twin_downsample(columns: usize, rows: usize, h: &[f32]) -> (usize, usize, Vec<f32>) {
    let (nc, nr) = ((columns - 1).div_ceil(2) + 1, (rows - 1).div_ceil(2) + 1);
    let kernel = [[1.0, 2.0, 1.0], [2.0, 4.0, 2.0], [1.0, 2.0, 1.0]];
    let mut out = vec![0f32; nc * nr];
    for r in 0..nr {
        for c in 0..nc {
            let mut sum = 0.0f64;
            for (dy, krow) in kernel.iter().enumerate() {
                for (dx, k) in krow.iter().enumerate() {
                    let y = (2 * r + dy).saturating_sub(1).min(rows - 1);
                    let x = (2 * c + dx).saturating_sub(1).min(columns - 1);
                    sum += k * f64::from(h[y * columns + x]);
                }
            }
            out[r * nc + c] = (sum / 16.0) as f32;
        }
    }
    (nc, nr, out)
}

fn write(field: &HeightField, name: &str, tile_side: u32) -> (PathBuf, PyramidSummary) {
    let path = temp(name);
    let options = PyramidOptions {
        tile_side,
        ..PyramidOptions::default()
    };
    let summary = write_pyramid(&path, &mut FieldRows::new(field, Path::new("test field")), &options).unwrap();
    (path, summary)
}

#[test]
fn every_level_matches_the_source_and_its_filter_twin() {
    // Sizes that are not multiples of the tile side nor of 2^l + 1.
    let field = rough(75, 53);
    let (path, summary) = write(&field, "rough.hpyr", 16);
    let pyramid = HeightPyramid::open(&path).unwrap();
    assert_eq!(pyramid.size(), (75, 53));
    assert_eq!(summary.levels, pyramid.levels());
    assert_eq!(
        (0..pyramid.levels()).map(|l| pyramid.level_size(l)).collect::<Vec<_>>(),
        vec![(75, 53), (38, 27), (20, 14), (11, 8)]
    );
    let step = pyramid.height_step() as f32;
    let (mut columns, mut rows, mut expected) = (75usize, 53usize, field.heights.clone());
    for level in 0..pyramid.levels() {
        let got = pyramid.level_field(level).unwrap();
        assert_eq!((got.columns as usize, got.rows as usize), (columns, rows));
        // Quantisation error accumulates by at most half a step per level.
        let tolerance = step * (0.5 + level as f32);
        for (i, (&g, &e)) in got.heights.iter().zip(&expected).enumerate() {
            assert!((g - e).abs() <= tolerance, "level {level} sample {i}: {g} vs {e}");
        }
        assert!((got.extent() - field.extent()).length() < 1e-9);
        (columns, rows, expected) = twin_downsample(columns, rows, &got.heights);
    }
    let (lo, hi) = field.min_max();
    let (plo, phi) = pyramid.height_range();
    assert!((plo - lo).abs() <= step && (phi - hi).abs() <= step);
    pyramid.verify().unwrap();
}

#[test]
fn regions_clamp_at_the_edges_and_span_tiles() {
    let field = rough(40, 40);
    let (path, _) = write(&field, "region.hpyr", 16);
    let pyramid = HeightPyramid::open(&path).unwrap();
    let region = pyramid.read_region(0, 30, 12, 14, 9).unwrap();
    for j in 0..9u32 {
        for i in 0..14u32 {
            let want = field.height((30 + i).min(39), 12 + j);
            let got = region[(j * 14 + i) as usize];
            assert!((got - want).abs() <= 0.5 / 256.0, "({i}, {j}): {got} vs {want}");
        }
    }
    let tile = pyramid.read_tile(TileKey { level: 0, x: 2, y: 2 }).unwrap();
    assert_eq!((tile.width, tile.height), (8, 8));
    let err = pyramid
        .read_tile(TileKey { level: 0, x: 3, y: 0 })
        .unwrap_err()
        .to_string();
    assert!(err.contains("no such tile") && err.contains("region.hpyr"), "{err}");
}

#[test]
fn smooth_relief_compresses_and_integers_survive_exactly() {
    // SRTM-like integer metres on a smooth slope: exact, and small.
    let field = HeightField::from_fn(257, 257, DVec2::splat(30.0), |c, r| {
        (1000.0 + 200.0 * ((c as f32) * 0.02).sin() * ((r as f32) * 0.03).cos()).round()
    });
    let (path, summary) = write(&field, "smooth.hpyr", 64);
    let pyramid = HeightPyramid::open(&path).unwrap();
    assert_eq!(pyramid.level_field(0).unwrap().heights, field.heights);
    let raw = 4 * 257 * 257;
    assert!(summary.bytes * 4 < raw, "{} bytes for {raw} raw", summary.bytes);
}

#[test]
fn corruption_and_truncation_are_errors_naming_the_file() {
    let field = rough(40, 40);
    let (path, _) = write(&field, "corrupt.hpyr", 16);
    let good = std::fs::read(&path).unwrap();
    type Damage = Box<dyn Fn(&mut Vec<u8>)>;
    let cases: [(&str, Damage, &str); 5] = [
        ("magic", Box::new(|b: &mut Vec<u8>| b[0] = b'X'), "bad magic"),
        ("header", Box::new(|b: &mut Vec<u8>| b[17] ^= 1), "header's checksum"),
        (
            "tile",
            Box::new(|b: &mut Vec<u8>| b[100] ^= 0x40),
            "checksum does not match",
        ),
        (
            "index",
            Box::new(|b: &mut Vec<u8>| {
                let n = b.len();
                b[n - 3] ^= 1
            }),
            "index's checksum",
        ),
        (
            "truncated",
            Box::new(|b: &mut Vec<u8>| {
                let n = b.len();
                b.truncate(n - 10)
            }),
            "truncated",
        ),
    ];
    for (name, damage, expect) in cases {
        let mut bytes = good.clone();
        damage(&mut bytes);
        let bad = temp(&format!("bad-{name}.hpyr"));
        std::fs::write(&bad, &bytes).unwrap();
        let err = HeightPyramid::open(&bad)
            .and_then(|p| p.verify())
            .unwrap_err()
            .to_string();
        assert!(err.contains(expect) && err.contains("bad-"), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn bad_sources_and_options_write_nothing() {
    let mut field = rough(20, 20);
    field.heights[45] = f32::NAN;
    let path = temp("nan.hpyr");
    let err = write_pyramid(
        &path,
        &mut FieldRows::new(&field, Path::new("dem.tif")),
        &PyramidOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("dem.tif") && err.contains("column 5, row 2"), "{err}");
    assert!(!path.exists());
    let options = PyramidOptions {
        tile_side: 8,
        ..PyramidOptions::default()
    };
    let err = write_pyramid(&path, &mut FieldRows::new(&rough(20, 20), Path::new("x")), &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("tile side"), "{err}");
}

#[test]
fn procedural_rows_are_made_in_bands() {
    let mut source = FnRows {
        shape: FieldShape {
            columns: 300,
            rows: 70,
            spacing: DVec2::ONE,
            origin: PathBuf::from("procedural"),
        },
        fill: |r, row: &mut [f32]| {
            for (c, h) in row.iter_mut().enumerate() {
                *h = (c as u32 * 3 + r * 7) as f32;
            }
        },
    };
    let path = temp("fn.hpyr");
    write_pyramid(
        &path,
        &mut source,
        &PyramidOptions {
            tile_side: 32,
            ..PyramidOptions::default()
        },
    )
    .unwrap();
    let field = HeightPyramid::open(&path).unwrap().level_field(0).unwrap();
    assert_eq!(field.height(299, 69), (299 * 3 + 69 * 7) as f32);
    assert_eq!(field.height(17, 33), (17 * 3 + 33 * 7) as f32);
}

/// Writes an SRTM3 cell whose heights are a function of the mosaic's
/// global sample position (so shared edges agree).
fn write_cell(dir: &Path, lat: i32, lon: i32, f: impl Fn(i64, i64) -> i16) -> PathBuf {
    let name = mosaic::cell_name_for_tests((lat, lon));
    let mut bytes = Vec::with_capacity(1201 * 1201 * 2);
    for row in 0..1201i64 {
        for col in 0..1201i64 {
            // Global: x east from the west edge of cell lon 7, y north.
            let x = (i64::from(lon) - 7) * 1200 + col;
            let y = (i64::from(lat) - 46) * 1200 + (1200 - row);
            bytes.extend_from_slice(&f(x, y).to_be_bytes());
        }
    }
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn hgt_cells_stitch_into_one_field() {
    let dir = temp("mosaic");
    std::fs::create_dir_all(&dir).unwrap();
    let f = |x: i64, y: i64| ((x * 3 + y * 5) % 4000) as i16;
    let paths: Vec<PathBuf> = [(46, 7), (46, 8), (47, 7), (47, 8)]
        .iter()
        .map(|&(lat, lon)| write_cell(&dir, lat, lon, f))
        .collect();
    let mut mosaic = HgtMosaic::open(&paths).unwrap();
    assert_eq!((mosaic.shape().columns, mosaic.shape().rows), (2401, 2401));
    // 3″ at 47° N: ≈ 63 m east, 93 m north.
    let s = mosaic.shape().spacing;
    assert!((s.x - 63.3).abs() < 0.5 && (s.y - 92.6).abs() < 0.5, "{s}");
    let mut rows = vec![0f32; 2401 * 3];
    mosaic.read_rows(1199, &mut rows).unwrap();
    for (k, row) in rows.chunks_exact(2401).enumerate() {
        for x in [0usize, 1199, 1200, 1201, 2400] {
            assert_eq!(
                row[x],
                f32::from(f(x as i64, 1199 + k as i64)),
                "x {x} row {}",
                1199 + k
            );
        }
    }
    let err = HgtMosaic::open(&paths[..3]).unwrap_err().to_string();
    assert!(err.contains("N47E008.hgt is missing"), "{err}");
}
