//! A procedural region of any size, written straight into the tiled
//! format (issue 31 item 1): what the out-of-core tests and the `drive`
//! example stream when no real DEM of 10⁹ samples is at hand. Nothing of
//! it is held in memory but two profiles of `side` samples and the
//! writer's rows.

use std::path::Path;

use glam::DVec2;

use super::{write_pyramid, FieldShape, FnRows, PyramidOptions, PyramidSummary, DEFAULT_HEIGHT_STEP};
use crate::error::Result;

/// Writes a `side × side` field of 1 m samples to `path` as a pyramid
/// (default options): ridges across x and across y, each a sum of sines
/// of 2.9 km, 1.1 km, 330 m and 77 m (500, 220, 60 and 12 m high), 600 m
/// above zero, heights on the file's quantum so the planar predictor
/// leaves little to code. Errors name the file.
pub fn write_ridge_region(path: &Path, side: u32) -> Result<PyramidSummary> {
    let profile = |phase: f32| -> Vec<f32> {
        (0..side)
            .map(|i| {
                let x = i as f32;
                let h = 500.0 * (x / 2900.0 + phase).sin()
                    + 220.0 * (x / 1100.0 + 2.0 * phase).sin()
                    + 60.0 * (x / 330.0 - phase).sin()
                    + 12.0 * (x / 77.0).sin();
                let quantum = DEFAULT_HEIGHT_STEP as f32;
                (h / quantum).round() * quantum
            })
            .collect()
    };
    let (across, along) = (profile(0.3), profile(1.7));
    let mut source = FnRows {
        shape: FieldShape {
            columns: side,
            rows: side,
            spacing: DVec2::ONE,
            origin: path.to_path_buf(),
        },
        fill: |r: u32, row: &mut [f32]| {
            let offset = along[r as usize] + 600.0;
            for (h, a) in row.iter_mut().zip(&across) {
                *h = a + offset;
            }
        },
    };
    write_pyramid(path, &mut source, &PyramidOptions::default())
}
