//! Any GDAL raster as [`HeightRows`] (feature `gdal`): GeoTIFF,
//! Cloud-Optimized GeoTIFF, VRT mosaics and every other format the
//! system's GDAL reads, the first band read a band of rows at a time, so a
//! 10⁹–10¹⁰-sample dataset streams into a pyramid without being in memory.
//!
//! Orientation and spacing come from the geotransform: a negative pixel
//! height (north-up, nearly every raster) has its rows flipped so that
//! field row 0 is the southern edge ([`crate::io::heightmap`]'s
//! convention); rotated rasters are refused. Projected rasters give their
//! pixel size in metres (their linear unit converted); geographic ones
//! (degrees) the arc step in metres at the raster's centre latitude, as
//! SRTM cells do ([`metres_per_degree`]). The band's scale and offset, then
//! the caller's, make the values metres. No-data samples are an error
//! naming the first one (fill them first, e.g. `gdal_fillnodata.py`).

use std::path::Path;

use gdal::Dataset;
use glam::DVec2;

use super::{FieldShape, HeightRows};
use crate::error::{Error, Result};
use crate::io::heightmap::check_spacing;
use crate::io::hgt::metres_per_degree;

/// A GDAL raster's first band, read by rows.
pub struct GdalRows {
    dataset: Dataset,
    shape: FieldShape,
    /// The raster's row 0 is the northern edge.
    north_up: bool,
    no_data: Option<f64>,
    scale: f64,
    offset: f64,
}

impl GdalRows {
    /// Opens `path` with GDAL; `spacing` overrides the geotransform's, and
    /// `scale`, `offset` apply after the band's own.
    pub fn open(path: &Path, spacing: Option<DVec2>, scale: f64, offset: f64) -> Result<GdalRows> {
        let bad = |m: String| Error::input(path, m);
        let gdal_error = |e: gdal::errors::GdalError| bad(crate::io::one_line(e));
        let dataset = Dataset::open(path).map_err(gdal_error)?;
        let band = dataset.rasterband(1).map_err(gdal_error)?;
        let (w, h) = band.size();
        let (columns, rows) = (
            u32::try_from(w).map_err(|_| bad(format!("{w} columns is too many")))?,
            u32::try_from(h).map_err(|_| bad(format!("{h} rows is too many")))?,
        );
        let (no_data, band_scale, band_offset) = (
            band.no_data_value(),
            band.scale().unwrap_or(1.0),
            band.offset().unwrap_or(0.0),
        );
        let (geo_spacing, north_up) = match dataset.geo_transform() {
            Ok(t) => {
                if t[2] != 0.0 || t[4] != 0.0 {
                    return Err(bad(
                        "the raster is rotated (its geotransform has shear terms); warp it north-up first (gdalwarp)"
                            .into(),
                    ));
                }
                let step = DVec2::new(t[1].abs(), t[5].abs());
                let metres = match dataset.spatial_ref() {
                    Ok(srs) if srs.is_geographic() => {
                        let centre_lat = t[3] + t[5] * f64::from(rows) * 0.5;
                        step * metres_per_degree(centre_lat)
                    }
                    Ok(srs) => step * srs.linear_units(),
                    Err(_) => step,
                };
                (Some(metres), t[5] < 0.0)
            }
            Err(_) => (None, true),
        };
        let spacing = match spacing.or(geo_spacing) {
            Some(s) => s,
            None => {
                log::warn!(
                    "{}: no georeferencing and no --spacing: 1 m between samples",
                    path.display()
                );
                DVec2::ONE
            }
        };
        check_spacing(spacing).map_err(bad)?;
        Ok(GdalRows {
            dataset,
            shape: FieldShape {
                columns,
                rows,
                spacing,
                origin: path.to_path_buf(),
            },
            north_up,
            no_data,
            scale: band_scale * scale,
            offset: band_offset * scale + offset,
        })
    }
}

impl HeightRows for GdalRows {
    fn shape(&self) -> &FieldShape {
        &self.shape
    }
    fn read_rows(&mut self, first: u32, out: &mut [f32]) -> Result<()> {
        let (columns, rows, origin) = (
            self.shape.columns as usize,
            self.shape.rows as usize,
            &self.shape.origin,
        );
        let count = out.len() / columns.max(1);
        // Field rows first..first+count are raster rows counted from the
        // north when the raster is north-up.
        let raster_first = if self.north_up {
            rows - first as usize - count
        } else {
            first as usize
        };
        let band = self
            .dataset
            .rasterband(1)
            .map_err(|e| Error::input(origin, crate::io::one_line(e)))?;
        let buffer = band
            .read_as::<f64>((0, raster_first as isize), (columns, count), (columns, count), None)
            .map_err(|e| Error::input(origin, crate::io::one_line(e)))?;
        let data = buffer.data();
        for k in 0..count {
            let raster_row = if self.north_up { count - 1 - k } else { k };
            let source = &data[raster_row * columns..(raster_row + 1) * columns];
            for (c, (h, &v)) in out[k * columns..(k + 1) * columns].iter_mut().zip(source).enumerate() {
                if self.no_data.is_some_and(|nd| v == nd || (nd.is_nan() && v.is_nan())) {
                    return Err(Error::input(
                        origin,
                        format!(
                            "no-data sample at column {c}, row {} (from the north); fill the voids first (e.g. gdal_fillnodata.py)",
                            raster_first + raster_row
                        ),
                    ));
                }
                *h = (v * self.scale + self.offset) as f32;
            }
        }
        Ok(())
    }
}
