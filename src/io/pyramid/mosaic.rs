//! A mosaic of SRTM `.hgt` cells as one field ([`HgtMosaic`]): the cells
//! must fill a rectangle of whole degrees, share one resolution (1″ or
//! 3″), and neighbours share their edge samples (as SRTM's do), so the
//! mosaic of `a × b` cells of `n²` samples is `(b(n−1)+1) × (a(n−1)+1)`.
//! The spacing is the arc step in metres at the mosaic's centre latitude
//! ([`metres_per_degree`]). Rows are read band by band, holding the cells
//! of at most two rows of degrees.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::DVec2;

use super::{FieldShape, HeightRows};
use crate::error::{Error, Result};
use crate::io::hgt::{decode_hgt, metres_per_degree};

/// SRTM cells as one height field, streamed by rows.
#[derive(Debug)]
pub struct HgtMosaic {
    /// Cell files by (latitude, longitude) of their south-west corner.
    cells: BTreeMap<(i32, i32), PathBuf>,
    south: i32,
    west: i32,
    lat_cells: u32,
    lon_cells: u32,
    /// Samples per cell side (1201 or 3601).
    side: u32,
    shape: FieldShape,
    /// Decoded cells (north-up rows) of the rows of degrees read last.
    loaded: Vec<(i32, Vec<Vec<f32>>)>,
}

/// (latitude, longitude) of the south-west corner named by an SRTM file
/// name, like `N46E007.hgt` → (46, 7), `S12W044.hgt` → (−12, −44).
pub fn cell_from_name(path: &Path) -> Option<(i32, i32)> {
    let stem = path.file_stem()?.to_str()?.to_ascii_uppercase();
    let b = stem.as_bytes();
    let lat_sign = match b.first()? {
        b'N' => 1,
        b'S' => -1,
        _ => return None,
    };
    let lat_digits: String = stem[1..].chars().take_while(char::is_ascii_digit).collect();
    let rest = &stem[1 + lat_digits.len()..];
    let lon_sign = match rest.as_bytes().first()? {
        b'E' => 1,
        b'W' => -1,
        _ => return None,
    };
    let lon_digits: String = rest[1..].chars().take_while(char::is_ascii_digit).collect();
    if lat_digits.is_empty() || lon_digits.is_empty() || 1 + lon_digits.len() != rest.len() {
        return None;
    }
    let (lat, lon): (i32, i32) = (lat_digits.parse().ok()?, lon_digits.parse().ok()?);
    (lat < 90 && lon <= 180).then_some((lat_sign * lat, lon_sign * lon))
}

#[cfg(test)]
pub(crate) fn cell_name_for_tests(cell: (i32, i32)) -> String {
    cell_name(cell)
}

fn cell_name((lat, lon): (i32, i32)) -> String {
    format!(
        "{}{:02}{}{:03}.hgt",
        if lat < 0 { 'S' } else { 'N' },
        lat.abs(),
        if lon < 0 { 'W' } else { 'E' },
        lon.abs()
    )
}

impl HgtMosaic {
    /// The mosaic of `paths` (at least one `.hgt` file); errors name the
    /// file or the missing cell.
    pub fn open(paths: &[PathBuf]) -> Result<HgtMosaic> {
        let first = paths
            .first()
            .ok_or_else(|| Error::invalid("mosaic", "no .hgt files given"))?;
        let mut cells = BTreeMap::new();
        let mut side = None;
        for path in paths {
            let cell = cell_from_name(path).ok_or_else(|| {
                Error::input(
                    path,
                    "an SRTM .hgt file's name must give its latitude and longitude, like N37W122.hgt",
                )
            })?;
            let bytes = std::fs::metadata(path)
                .map_err(|e| Error::input(path, format!("cannot read: {}", crate::io::one_line(e))))?
                .len();
            let n = match bytes {
                2_884_802 => 1201,
                25_934_402 => 3601,
                _ => {
                    return Err(Error::input(
                        path,
                        format!("SRTM .hgt file of {bytes} bytes; expected 1201² or 3601² 16-bit samples"),
                    ))
                }
            };
            if *side.get_or_insert(n) != n {
                return Err(Error::input(
                    path,
                    "its resolution differs from the mosaic's other cells",
                ));
            }
            if cells.insert(cell, path.clone()).is_some() {
                return Err(Error::input(path, format!("cell {} is given twice", cell_name(cell))));
            }
        }
        let south = cells.keys().map(|k| k.0).min().unwrap_or(0);
        let north = cells.keys().map(|k| k.0).max().unwrap_or(0);
        let west = cells.keys().map(|k| k.1).min().unwrap_or(0);
        let east = cells.keys().map(|k| k.1).max().unwrap_or(0);
        for lat in south..=north {
            for lon in west..=east {
                if !cells.contains_key(&(lat, lon)) {
                    return Err(Error::invalid(
                        "mosaic",
                        format!(
                            "the cells must fill a rectangle; {} is missing (between {} and {})",
                            cell_name((lat, lon)),
                            cell_name((south, west)),
                            cell_name((north, east))
                        ),
                    ));
                }
            }
        }
        let side = side.unwrap_or(1201);
        let (lat_cells, lon_cells) = ((north - south + 1) as u32, (east - west + 1) as u32);
        let arc = if side == 3601 { 1.0 } else { 3.0 } / 3600.0;
        let centre = f64::from(south) + 0.5 * f64::from(lat_cells);
        Ok(HgtMosaic {
            cells,
            south,
            west,
            lat_cells,
            lon_cells,
            side,
            shape: FieldShape {
                columns: lon_cells * (side - 1) + 1,
                rows: lat_cells * (side - 1) + 1,
                spacing: metres_per_degree(centre) * arc,
                origin: first.clone(),
            },
            loaded: Vec::new(),
        })
    }

    /// The mosaic with `spacing` (metres) instead of the arc step at its
    /// centre latitude.
    pub fn with_spacing(mut self, spacing: DVec2) -> Result<HgtMosaic> {
        crate::io::heightmap::check_spacing(spacing).map_err(|m| Error::invalid("spacing", m))?;
        self.shape.spacing = spacing;
        Ok(self)
    }

    /// The cells of the row of degrees `lat` (decoded, north-up), loaded
    /// on first use; at most two rows are kept.
    fn cell_row(&mut self, lat: i32) -> Result<usize> {
        if let Some(i) = self.loaded.iter().position(|(l, _)| *l == lat) {
            return Ok(i);
        }
        let mut row = Vec::with_capacity(self.lon_cells as usize);
        for lon in self.west..self.west + self.lon_cells as i32 {
            let path = &self.cells[&(lat, lon)];
            let bytes = crate::io::read_input(path)?;
            row.push(decode_hgt(path, &bytes, false)?.values);
        }
        if self.loaded.len() == 2 {
            self.loaded.remove(0);
        }
        self.loaded.push((lat, row));
        Ok(self.loaded.len() - 1)
    }
}

impl HeightRows for HgtMosaic {
    fn shape(&self) -> &FieldShape {
        &self.shape
    }
    fn read_rows(&mut self, first: u32, out: &mut [f32]) -> Result<()> {
        let columns = self.shape.columns as usize;
        let step = self.side - 1;
        for (k, row) in out.chunks_exact_mut(columns).enumerate() {
            let r = first + k as u32;
            let cell_y = (r / step).min(self.lat_cells - 1);
            let hgt_row = (step - (r - cell_y * step)) as usize;
            let slot = self.cell_row(self.south + cell_y as i32)?;
            let cells = &self.loaded[slot].1;
            for (c, h) in row.iter_mut().enumerate() {
                let cell_x = (c as u32 / step).min(self.lon_cells - 1);
                let col = c - (cell_x * step) as usize;
                *h = cells[cell_x as usize][hgt_row * self.side as usize + col];
            }
        }
        Ok(())
    }
}
