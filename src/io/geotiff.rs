//! GeoTIFF height maps (the usual DEM format): one sample per pixel, 8, 16,
//! 32 or 64-bit integer or float, uncompressed, LZW or Deflate.
//!
//! Spacing and orientation come from the georeferencing:
//! `ModelPixelScale` (row 0 the northern edge, as GeoTIFF defines it) or a
//! `ModelTransformation` without rotation (row 0 north where its y scale is
//! negative). In a geographic CRS (`GTModelTypeGeoKey` 2: degrees) the
//! spacing is converted to metres at the field's centre latitude
//! ([`crate::io::hgt::metres_per_degree`]); a projected CRS's linear unit is
//! used as metres (metre, foot and US survey foot are known; a file without
//! geo keys is taken to be in metres). A file without georeferencing is a
//! plain greyscale TIFF: spacing and row order come from the options, as
//! for PNG. Samples equal to the `GDAL_NODATA` value are an error naming
//! the first one.

use std::io::Cursor;
use std::path::Path;

use glam::DVec2;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::ColorType;

use crate::error::{Error, Result};
use crate::io::heightmap::RawGrid;
use crate::io::hgt::metres_per_degree;
use crate::io::limits::InputLimits;
use crate::io::one_line;

/// `GTModelTypeGeoKey`, `ProjLinearUnitsGeoKey`.
const MODEL_TYPE_KEY: u16 = 1024;
const LINEAR_UNITS_KEY: u16 = 3076;
/// Values of `GTModelTypeGeoKey`.
const MODEL_GEOGRAPHIC: u16 = 2;
const MODEL_GEOCENTRIC: u16 = 3;

/// Whether `bytes` start like a TIFF or BigTIFF file.
pub fn is_tiff(bytes: &[u8]) -> bool {
    [b"II*\0", b"MM\0*", b"II+\0", b"MM\0+"]
        .iter()
        .any(|m| bytes.starts_with(*m))
}

/// The most bytes one decoded TIFF tag may take (GeoTIFF's largest,
/// ModelTransformation, is 16 doubles).
const TAG_BYTES: usize = 1 << 20;

/// Decodes a greyscale (Geo)TIFF into raw values with the spacing and row
/// order of its georeferencing. No-data samples are an error, or NaN with
/// `voids` (the unknown samples of [`crate::io::heightmap::load_heightmap_with_voids`]).
pub(crate) fn decode_geotiff(path: &Path, bytes: &[u8], limits: &InputLimits, voids: bool) -> Result<RawGrid> {
    let bad = |e: tiff::TiffError| Error::input(path, format!("invalid TIFF: {}", one_line(e)));
    let mut decoder = Decoder::new(Cursor::new(bytes)).map_err(bad)?;
    let (w, h) = decoder.dimensions().map_err(bad)?;
    let bits = match decoder.colortype().map_err(bad)? {
        ColorType::Gray(bits) => u64::from(bits),
        other => {
            return Err(Error::input(
                path,
                format!("TIFF is {other:?}; height maps must have one sample per pixel (greyscale)"),
            ))
        }
    };
    let decoded_bytes = bits.div_ceil(8).max(1);
    limits
        .check_image_fits(u64::from(w), u64::from(h), decoded_bytes + 4)
        .map_err(|m| Error::input(path, m))?;
    // Tags first, each at most 1 MiB decoded: the crate bounds a tag's
    // value array by `decoding_buffer_size`, so the image's allowance must
    // not apply to them (a tag claiming 10⁸ values would allocate it).
    let mut tag_limits = Limits::default();
    tag_limits.decoding_buffer_size = TAG_BYTES;
    tag_limits.ifd_value_size = TAG_BYTES;
    let mut decoder = decoder.with_limits(tag_limits);
    let georef = georeference(path, &mut decoder, h)?;
    let nodata = (decoder.get_tag_ascii_string(Tag::GdalNodata).ok())
        .and_then(|s| s.trim_matches(char::from(0)).trim().parse::<f64>().ok());
    // Then the image, within its declared (and checked) size.
    let image_bytes = u64::from(w) * u64::from(h) * decoded_bytes;
    let mut image_limits = Limits::default();
    image_limits.decoding_buffer_size = usize::try_from(image_bytes.min(limits.max_decode_bytes))
        .unwrap_or(usize::MAX)
        .max(TAG_BYTES);
    let mut decoder = decoder.with_limits(image_limits);
    let mut values = samples(decoder.read_image().map_err(bad)?);
    if values.len() as u64 != u64::from(w) * u64::from(h) {
        return Err(Error::input(
            path,
            format!("{} samples for a {w}×{h} image", values.len()),
        ));
    }
    let is_nodata = |v: f32| nodata.is_some_and(|n| f64::from(v) == n as f32 as f64);
    if voids {
        values.iter_mut().filter(|v| is_nodata(**v)).for_each(|v| *v = f32::NAN);
    }
    if let Some(nodata) = nodata {
        if let Some(i) = values.iter().position(|&v| f64::from(v) == nodata as f32 as f64) {
            let (c, r) = (i % w as usize, i / w as usize);
            return Err(Error::input(
                path,
                format!(
                    "no-data sample ({nodata}) at column {c}, row {r}; fill the voids first (e.g. gdal_fillnodata.py)"
                ),
            ));
        }
    }
    Ok(RawGrid {
        columns: w,
        rows: h,
        values,
        spacing: georef.map(|g| g.0),
        north_up: georef.map(|g| g.1),
    })
}

/// Samples as `f32` (64-bit values rounded).
fn samples(result: DecodingResult) -> Vec<f32> {
    match result {
        DecodingResult::U8(v) => v.into_iter().map(f32::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f32::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I8(v) => v.into_iter().map(f32::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f32::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::F16(v) => v.into_iter().map(|x| x.to_f32()).collect(),
        DecodingResult::F32(v) => v,
        DecodingResult::F64(v) => v.into_iter().map(|x| x as f32).collect(),
    }
}

/// Spacing in metres and whether row 0 is north, from the georeferencing
/// tags; `None` without them.
fn georeference<R: std::io::Read + std::io::Seek>(
    path: &Path,
    decoder: &mut Decoder<R>,
    rows: u32,
) -> Result<Option<(DVec2, bool)>> {
    let bad = |m: String| Error::input(path, format!("GeoTIFF georeferencing: {m}"));
    let tag = |d: &mut Decoder<R>, t: Tag| d.get_tag_f64_vec(t).ok();
    // (x scale, y scale, y of row 0's top edge, row 0 is north)
    let (sx, sy, y0, north_up) = if let Some(s) = tag(decoder, Tag::ModelPixelScaleTag) {
        if s.len() < 2 {
            return Err(bad(format!("ModelPixelScale has {} values, not 3", s.len())));
        }
        let tie = tag(decoder, Tag::ModelTiepointTag).unwrap_or_default();
        // Raster (i, j) = tie[0], tie[1] sits at model (x, y) = tie[3], tie[4].
        let y0 = match tie.as_slice() {
            [_, j, _, _, y, ..] => y + j * s[1],
            _ => 0.0,
        };
        (s[0], s[1], y0, true)
    } else if let Some(m) = tag(decoder, Tag::ModelTransformationTag) {
        if m.len() < 16 {
            return Err(bad(format!("ModelTransformation has {} values, not 16", m.len())));
        }
        if m[1] != 0.0 || m[4] != 0.0 {
            return Err(bad("rotated or sheared rasters are not supported".into()));
        }
        if m[0] < 0.0 {
            return Err(bad("a raster mirrored east–west is not supported".into()));
        }
        (m[0], m[5].abs(), m[7], m[5] < 0.0)
    } else {
        return Ok(None);
    };
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !(ok(sx) && ok(sy)) {
        return Err(bad(format!("pixel size ({sx}, {sy}) must be finite and positive")));
    }
    let keys = decoder.get_tag_u16_vec(Tag::GeoKeyDirectoryTag).unwrap_or_default();
    let key = |k: u16| {
        // Header of 4 values, then (key, location, count, value) entries;
        // location 0 means the value is inline.
        keys.get(4..)?
            .chunks_exact(4)
            .find(|e| e[0] == k && e[1] == 0)
            .map(|e| e[3])
    };
    let metres = match key(MODEL_TYPE_KEY) {
        Some(MODEL_GEOGRAPHIC) => {
            let half_height = f64::from(rows) * sy / 2.0;
            let centre = if north_up { y0 - half_height } else { y0 + half_height };
            if !(-90.0..=90.0).contains(&centre) {
                return Err(bad(format!(
                    "centre latitude {centre}° of a geographic (degrees) CRS is outside ±90°"
                )));
            }
            metres_per_degree(centre) * DVec2::new(sx, sy)
        }
        Some(MODEL_GEOCENTRIC) => return Err(bad("geocentric CRSs are not supported".into())),
        _ => {
            let unit = match key(LINEAR_UNITS_KEY) {
                None | Some(9001) => 1.0,
                Some(9002) => 0.3048,
                Some(9003) => 1200.0 / 3937.0,
                Some(code) => {
                    return Err(bad(format!(
                        "linear unit code {code} is not supported (metre 9001, foot 9002, US survey foot 9003)"
                    )))
                }
            };
            DVec2::new(sx, sy) * unit
        }
    };
    Ok(Some((metres, north_up)))
}
