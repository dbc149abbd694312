//! Height fields of any size on disk: the tiled, compressed, checksummed
//! height pyramid (`.hpyr`) that out-of-core terrain streams from
//! (dissertation §7.4.4: "a large sketch atlas in main memory and only the
//! visible part in video memory"; issue 31 item 1).
//!
//! # The file
//!
//! ```text
//! header   96 B   magic "ALPGHPYR", version, tile side, columns, rows,
//!                 spacing (m), height step (m), levels, height range,
//!                 index offset, entries, index CRC-32, header CRC-32
//! tiles    …      level by level, band by band (as written)
//! index    24 B a tile: offset, length, CRC-32, min, max height;
//!                 level 0 first, each level row-major (y, then x)
//! ```
//!
//! Level 0 is the field. Level `l + 1` holds every second sample of level
//! `l` after a `[1 2 1]/4` binomial low-pass each way
//! ([`writer`]), `⌈(n − 1)/2⌉ + 1` samples a side, down to the first level
//! that fits one tile; level `l` sample `c` therefore lies at
//! `c · extent / (n_l − 1)` over the field's extent. Tiles are
//! `tile_side²` samples (256² by default; edge tiles smaller), coded as
//! [`format`] says: heights quantised to the file's height step (1/256 m by
//! default: an error of at most 2 mm, and none for the integer metres of
//! SRTM), predicted, deflated. Every tile's CRC-32 is in the index and the
//! index's in the header, so corruption is an error naming the file and
//! the tile, never a wrong height.
//!
//! # Sizes
//!
//! The index of a 65536² field (87 381 tiles of 256²) is 2 MiB; of a
//! 100 000² field (10¹⁰ samples) 5 MiB. Writing holds about
//! `2 · tile_side · columns · 4 B` ([`writer`]); reading holds the index
//! and the tiles asked for ([`stream::TileCache`] bounds them).

pub(crate) mod format;
#[cfg(feature = "gdal")]
mod gdal_rows;
pub mod mosaic;
mod reader;
mod ridges;
pub mod stream;
#[cfg(test)]
mod tests;
mod writer;

use std::fmt;
use std::path::{Path, PathBuf};

use glam::DVec2;

#[cfg(feature = "gdal")]
pub use gdal_rows::GdalRows;
pub use mosaic::HgtMosaic;
pub use reader::HeightPyramid;
pub use ridges::write_ridge_region;
pub use writer::write_pyramid;

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;

/// Default [`HeightPyramid::level_within`] side of the level a renderer
/// keeps resident (4096²: 64 MiB of heights).
pub const DEFAULT_RESIDENT_SIDE: u32 = 4096;
/// Default samples per tile side.
pub const DEFAULT_TILE_SIDE: u32 = 256;
/// Smallest tile side.
pub const MIN_TILE_SIDE: u32 = 16;
/// Largest tile side.
pub const MAX_TILE_SIDE: u32 = 4096;
/// Default height quantum: 1/256 m.
pub const DEFAULT_HEIGHT_STEP: f64 = 1.0 / 256.0;
/// Finest height quantum (1/1024 m: ±10⁶ m still fits 31 bits).
pub const MIN_HEIGHT_STEP: f64 = 1.0 / 1024.0;
/// Coarsest height quantum (1 m).
pub const MAX_HEIGHT_STEP: f64 = 1.0;

/// How a pyramid is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PyramidOptions {
    /// Samples per tile side, [`MIN_TILE_SIDE`]..=[`MAX_TILE_SIDE`].
    pub tile_side: u32,
    /// Height quantum in metres, [`MIN_HEIGHT_STEP`]..=[`MAX_HEIGHT_STEP`].
    pub height_step: f64,
}

impl Default for PyramidOptions {
    fn default() -> Self {
        PyramidOptions {
            tile_side: DEFAULT_TILE_SIDE,
            height_step: DEFAULT_HEIGHT_STEP,
        }
    }
}

impl PyramidOptions {
    /// Checks both ranges.
    pub fn validate(&self) -> Result<()> {
        if !(MIN_TILE_SIDE..=MAX_TILE_SIDE).contains(&self.tile_side) {
            return Err(Error::invalid(
                "tile side",
                format!("{} (must be within {MIN_TILE_SIDE}..={MAX_TILE_SIDE})", self.tile_side),
            ));
        }
        if !(MIN_HEIGHT_STEP..=MAX_HEIGHT_STEP).contains(&self.height_step) {
            return Err(Error::invalid(
                "height step",
                format!(
                    "{} m (must be within {MIN_HEIGHT_STEP}..={MAX_HEIGHT_STEP} m)",
                    self.height_step
                ),
            ));
        }
        Ok(())
    }
}

/// What [`write_pyramid`] wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PyramidSummary {
    pub columns: u32,
    pub rows: u32,
    pub levels: u32,
    pub tiles: u64,
    /// Bytes of the file.
    pub bytes: u64,
    pub min_height: f32,
    pub max_height: f32,
}

/// One tile of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileKey {
    pub level: u32,
    /// Tile column.
    pub x: u32,
    /// Tile row.
    pub y: u32,
}

impl fmt::Display for TileKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {}) of level {}", self.x, self.y, self.level)
    }
}

/// A decoded tile: `width × height` heights, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct PyramidTile {
    pub key: TileKey,
    pub width: u32,
    pub height: u32,
    pub heights: Vec<f32>,
}

/// The size, spacing and name of a [`HeightRows`] source.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldShape {
    /// Samples per row.
    pub columns: u32,
    /// Rows.
    pub rows: u32,
    /// Metres between samples in x and y.
    pub spacing: DVec2,
    /// What errors name (a file, or a description).
    pub origin: PathBuf,
}

/// A height field read top to bottom (field row 0 first) in bands: what
/// [`write_pyramid`] consumes, so that no source need be in memory whole.
pub trait HeightRows {
    /// Its size, spacing and name.
    fn shape(&self) -> &FieldShape;
    /// Fills `out` (`out.len() / columns` rows) with rows `first..`.
    fn read_rows(&mut self, first: u32, out: &mut [f32]) -> Result<()>;
}

/// A height field in memory as [`HeightRows`].
pub struct FieldRows<'a> {
    field: &'a HeightField,
    shape: FieldShape,
}

impl<'a> FieldRows<'a> {
    pub fn new(field: &'a HeightField, origin: &Path) -> Self {
        let shape = FieldShape {
            columns: field.columns,
            rows: field.rows,
            spacing: field.spacing,
            origin: origin.to_path_buf(),
        };
        FieldRows { field, shape }
    }
}

impl HeightRows for FieldRows<'_> {
    fn shape(&self) -> &FieldShape {
        &self.shape
    }
    fn read_rows(&mut self, first: u32, out: &mut [f32]) -> Result<()> {
        let start = first as usize * self.field.columns as usize;
        let source = self
            .field
            .heights
            .get(start..start + out.len())
            .ok_or_else(|| Error::input(&self.shape.origin, "the field has fewer samples than its size"))?;
        out.copy_from_slice(source);
        Ok(())
    }
}

/// A procedural field as [`HeightRows`]: `fill(row, heights)` writes one
/// row's heights; rows are made on every core as they are read.
pub struct FnRows<F: Fn(u32, &mut [f32]) + Sync> {
    pub shape: FieldShape,
    pub fill: F,
}

impl<F: Fn(u32, &mut [f32]) + Sync> HeightRows for FnRows<F> {
    fn shape(&self) -> &FieldShape {
        &self.shape
    }
    fn read_rows(&mut self, first: u32, out: &mut [f32]) -> Result<()> {
        let columns = self.shape.columns as usize;
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let rows_per_thread = (out.len() / columns.max(1)).div_ceil(threads).max(1);
        let fill = &self.fill;
        std::thread::scope(|scope| {
            for (k, part) in out.chunks_mut(rows_per_thread * columns).enumerate() {
                let start = first + (k * rows_per_thread) as u32;
                scope.spawn(move || {
                    for (r, row) in (start..).zip(part.chunks_exact_mut(columns)) {
                        fill(r, row);
                    }
                });
            }
        });
        Ok(())
    }
}
