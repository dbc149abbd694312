//! Height fields and loading them from PNG, OpenEXR, GeoTIFF or SRTM
//! `.hgt` height maps.
//!
//! # Convention
//!
//! Sample (column `c`, row `r`) sits at world position `(c·dx, r·dy, h)`
//! (right-handed, +Z up, +Y north). Field row 0 is therefore the southern
//! edge.
//!
//! How image rows map to field rows is [`HeightmapOptions::rows`] for PNG,
//! EXR and plain TIFF: the default [`RowOrder::SouthUp`] keeps them
//! (image row 0, its top row, becomes field row 0, the southern edge: the
//! image appears mirrored north–south); [`RowOrder::NorthUp`] (`--rows
//! north-up`, the convention of nearly every GIS raster) flips them so
//! that the image's top row is the northern edge. GeoTIFF and `.hgt` files
//! say where north is and are oriented by that, whatever the option.
//!
//! # Limits
//!
//! Heights must lie within ±[`MAX_ABS_HEIGHT`] m and spacings within
//! [`MIN_SPACING`]..=[`MAX_SPACING`] m; files are read and decoded within
//! [`HeightmapOptions::limits`] (declared image size checked before any
//! allocation).

use std::path::Path;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::io::limits::InputLimits;

/// Largest |height| of a field in metres (1000 km): far beyond any
/// terrain, small enough that positions and normals stay finite in `f32`.
pub const MAX_ABS_HEIGHT: f32 = 1.0e6;
/// Smallest sample spacing in metres (1 mm).
pub const MIN_SPACING: f64 = 1.0e-3;
/// Largest sample spacing in metres (100 km).
pub const MAX_SPACING: f64 = 1.0e5;

/// Height-field bytes per sample for the memory model ([`crate::budget`]):
/// on the host the field and the renderer's copy (f32 each); on the device
/// the R32F sketch atlas and its staging upload, the atlas being one
/// allocation of 4 B a sample.
pub const HEIGHT_HOST_BYTES: u64 = 8;
/// See [`HEIGHT_HOST_BYTES`].
pub const HEIGHT_DEVICE_BYTES: u64 = 8;

/// A regular grid of heights in metres.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightField {
    /// Samples per row (x direction).
    pub columns: u32,
    /// Number of rows (y direction).
    pub rows: u32,
    /// Metres between neighbouring samples in x and in y.
    pub spacing: DVec2,
    /// Heights in metres, row-major: row `r`, column `c` at `r·columns + c`.
    pub heights: Vec<f32>,
}

impl HeightField {
    /// A `columns×rows` field with `spacing` and height `f(c, r)` at
    /// column `c`, row `r`.
    pub fn from_fn(columns: u32, rows: u32, spacing: DVec2, f: impl Fn(u32, u32) -> f32) -> HeightField {
        let heights = (0..rows)
            .flat_map(|r| (0..columns).map(move |c| (c, r)))
            .map(|(c, r)| f(c, r))
            .collect();
        HeightField {
            columns,
            rows,
            spacing,
            heights,
        }
    }

    /// Height at column `c`, row `r`. Coordinates outside the grid are
    /// clamped to the nearest edge sample, so neighbour look-ups at the
    /// border need no special case. Never panics: a field whose `heights`
    /// is shorter than `columns·rows` (see [`HeightField::validate`])
    /// yields NaN for the missing samples.
    pub fn height(&self, c: u32, r: u32) -> f32 {
        let c = c.min(self.columns.saturating_sub(1)) as usize;
        let r = r.min(self.rows.saturating_sub(1)) as usize;
        r.checked_mul(self.columns as usize)
            .and_then(|i| i.checked_add(c))
            .and_then(|i| self.heights.get(i))
            .copied()
            .unwrap_or(f32::NAN)
    }

    /// Size of the covered area in metres: `((columns−1)·dx, (rows−1)·dy)`.
    pub fn extent(&self) -> DVec2 {
        DVec2::new(
            f64::from(self.columns.saturating_sub(1)) * self.spacing.x,
            f64::from(self.rows.saturating_sub(1)) * self.spacing.y,
        )
    }

    /// Smallest and largest height, ignoring NaN samples;
    /// `(+inf, −inf)` for a field without (non-NaN) samples.
    pub fn min_max(&self) -> (f32, f32) {
        self.heights
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }

    /// Checks the invariants: at least 2×2 samples, `heights.len() ==
    /// columns·rows`, spacing within [`MIN_SPACING`]..=[`MAX_SPACING`] m,
    /// every height finite and within ±[`MAX_ABS_HEIGHT`] m. Errors
    /// name `origin` (the file or source the field came from) and, for bad
    /// heights, the first bad sample's column and row.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        let (w, h) = (self.columns, self.rows);
        if w == 0 || h == 0 {
            return Err(Error::input(origin, format!("height field is empty ({w}×{h})")));
        }
        if w < 2 || h < 2 {
            return Err(Error::input(
                origin,
                format!("height field is {w}×{h}; at least 2×2 samples are needed"),
            ));
        }
        let expected = (w as usize).checked_mul(h as usize);
        if expected != Some(self.heights.len()) {
            return Err(Error::input(
                origin,
                format!(
                    "{} height samples for a {w}×{h} grid (expected {})",
                    self.heights.len(),
                    (w as u64) * (h as u64)
                ),
            ));
        }
        check_spacing(self.spacing).map_err(|m| Error::input(origin, m))?;
        let in_range = |v: f32| v.is_finite() && v.abs() <= MAX_ABS_HEIGHT;
        if let Some(i) = self.heights.iter().position(|&v| !in_range(v)) {
            let (c, r) = (i % w as usize, i / w as usize);
            return Err(Error::input(
                origin,
                format!(
                    "height at column {c}, row {r} is {} m; heights must be finite and within ±{} km",
                    self.heights[i],
                    MAX_ABS_HEIGHT / 1000.0
                ),
            ));
        }
        Ok(())
    }
}

/// Why a spacing is unusable, if it is: each of x and y must lie within
/// [`MIN_SPACING`]..=[`MAX_SPACING`] metres. The message (one line) gives
/// the value and the range; callers prefix the option or key it came from.
pub fn check_spacing(spacing: DVec2) -> std::result::Result<(), String> {
    let ok = |v: f64| (MIN_SPACING..=MAX_SPACING).contains(&v);
    if ok(spacing.x) && ok(spacing.y) {
        Ok(())
    } else {
        let value = if spacing.x == spacing.y {
            format!("{} m", spacing.x)
        } else {
            format!("({}, {}) m", spacing.x, spacing.y)
        };
        Err(format!(
            "sample spacing {value} is out of range; it must be within {MIN_SPACING}..={MAX_SPACING} m"
        ))
    }
}

/// How the rows of an image map to the field's rows (north is +Y).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RowOrder {
    /// Image row 0 (the top) is the southern edge: rows are kept as they
    /// are (field row `r` = image row `r`). The default, for compatibility.
    #[default]
    SouthUp,
    /// Image row 0 is the northern edge (nearly every GIS raster): rows are
    /// flipped on loading.
    NorthUp,
}

/// How raw height-map values become metres, and the limits of reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightmapOptions {
    /// Multiplies each raw value (PNG: the integer 0‥65535 or 0‥255; EXR:
    /// the stored float). Must be finite and positive.
    pub scale: f32,
    /// Added after scaling, in metres. Must be finite.
    pub offset: f32,
    /// Metres between samples in x (columns) and y (rows), within
    /// [`MIN_SPACING`]..=[`MAX_SPACING`]. `None`: from the file's
    /// georeferencing (GeoTIFF, `.hgt`), else 1 m with a warning.
    pub spacing: Option<DVec2>,
    /// Row order of PNG, EXR and plain TIFF files (GeoTIFF and `.hgt`
    /// files carry their own).
    pub rows: RowOrder,
    /// Limits on the file's size and the declared image size.
    pub limits: InputLimits,
}

impl Default for HeightmapOptions {
    /// Scale 1, offset 0, spacing from the file (else 1 m), rows south-up
    /// (kept), default [`InputLimits`].
    fn default() -> Self {
        Self {
            scale: 1.0,
            offset: 0.0,
            spacing: None,
            rows: RowOrder::SouthUp,
            limits: InputLimits::default(),
        }
    }
}

/// A decoded grid of raw values, before scaling.
#[derive(Debug)]
pub(crate) struct RawGrid {
    pub columns: u32,
    pub rows: u32,
    /// Raw values, image row 0 first.
    pub values: Vec<f32>,
    /// Metres between samples, where the file says.
    pub spacing: Option<DVec2>,
    /// Whether image row 0 is north, where the file says.
    pub north_up: Option<bool>,
}

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Loads a height map: `height = raw · scale + offset` in metres.
///
/// The format is recognised by content (file signature), `.hgt` by name:
///
/// * **PNG**, 16-bit greyscale (the usual DEM encoding) or 1–8-bit
///   greyscale; raw values are the unsigned integers. Colour, palette and
///   grey+alpha PNGs are rejected, and so are bad CRCs and a bad zlib
///   Adler-32 checksum.
/// * **OpenEXR**: the first valid layer at full resolution; the channel
///   named `Y`, else `R`, else `Z` (also as the last component of a layer
///   name like `height.Y`), else the alphabetically first channel; raw
///   values are the stored floats (half, float or uint). Deep data is
///   rejected.
/// * **GeoTIFF** or plain TIFF, one sample per pixel (see
///   `crate::io::geotiff`): spacing and orientation from the
///   georeferencing.
/// * **SRTM `.hgt`** (see `crate::io::hgt`): spacing from the file's size
///   and the latitude in its name; voids are an error.
///
/// Rows: see the module documentation. Spacing: `opts.spacing`, else the
/// file's georeferencing, else 1 m (a warning is logged).
///
/// Errors (one line, naming the file): options out of range, missing,
/// special (FIFO, device, directory) or too large file, declared image
/// size beyond `opts.limits` (checked before decoding), empty file,
/// unsupported format, corrupt or truncated data, colour images, an image
/// smaller than 2×2 samples, and NaN, infinite or out-of-range heights (the
/// first bad sample's column and row are named).
pub fn load_heightmap(path: &Path, opts: &HeightmapOptions) -> Result<HeightField> {
    load(path, opts, false).map(|(field, _)| field)
}

/// [`load_heightmap`] that accepts voids: NaN or infinite samples of PNG,
/// EXR and TIFF files, a GeoTIFF's `GDAL_NODATA` samples and an SRTM
/// `.hgt` file's voids (−32768). Returns the field, with height 0 m
/// (`0·scale + offset`) at each void, and the void mask (row-major like the
/// heights; `true`: unknown). The unknown samples of hole filling
/// (`crate::synthesis::fill`, §7.3).
pub fn load_heightmap_with_voids(path: &Path, opts: &HeightmapOptions) -> Result<(HeightField, Vec<bool>)> {
    load(path, opts, true)
}

/// [`load_heightmap`], with `voids`: [`load_heightmap_with_voids`].
fn load(path: &Path, opts: &HeightmapOptions, voids: bool) -> Result<(HeightField, Vec<bool>)> {
    check_options(path, opts)?;
    let bytes = crate::io::read_input_limited(path, opts.limits.max_file_bytes)?;
    if bytes.is_empty() {
        return Err(Error::input(path, "file is empty"));
    }
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let grid = if bytes.starts_with(PNG_MAGIC) {
        let (columns, rows, values) = crate::io::png_height::decode_png(path, &bytes, &opts.limits)?;
        RawGrid::plain(columns, rows, values)
    } else if bytes.starts_with(EXR_MAGIC) {
        decode_exr(path, &bytes, &opts.limits)?
    } else if crate::io::geotiff::is_tiff(&bytes) {
        crate::io::geotiff::decode_geotiff(path, &bytes, &opts.limits, voids)?
    } else if ext.as_deref() == Some("hgt") {
        crate::io::hgt::decode_hgt(path, &bytes, voids)?
    } else {
        let msg = match ext.as_deref() {
            Some("png") => "not a PNG file (bad signature)",
            Some("exr") => "not an OpenEXR file (bad signature)",
            Some("tif" | "tiff") => "not a TIFF file (bad signature)",
            _ => "unsupported height-map format (expected a greyscale PNG, OpenEXR, GeoTIFF or SRTM .hgt file)",
        };
        return Err(Error::input(path, msg));
    };
    drop(bytes);
    field_from_grid(path, grid, opts, voids)
}

/// Checks scale, offset and spacing before the file is read.
fn check_options(path: &Path, opts: &HeightmapOptions) -> Result<()> {
    let name = path.display();
    if !(opts.scale.is_finite() && opts.scale > 0.0) {
        return Err(Error::invalid(
            "height-map scale",
            format!("{} for {name}: must be finite and positive", opts.scale),
        ));
    }
    if !opts.offset.is_finite() {
        return Err(Error::invalid(
            "height-map offset",
            format!("{} for {name}: must be finite", opts.offset),
        ));
    }
    if let Some(spacing) = opts.spacing {
        check_spacing(spacing).map_err(|m| Error::invalid("height-map spacing", format!("{m} (for {name})")))?;
    }
    Ok(())
}

impl RawGrid {
    /// A grid without georeferencing.
    pub(crate) fn plain(columns: u32, rows: u32, values: Vec<f32>) -> RawGrid {
        RawGrid {
            columns,
            rows,
            values,
            spacing: None,
            north_up: None,
        }
    }
}

/// Checks, orients and scales a decoded grid (in place: no second copy of
/// the samples); with `voids`, non-finite samples become 0 and `true` in
/// the returned mask (else they are an error and the mask is empty).
fn field_from_grid(
    path: &Path,
    grid: RawGrid,
    opts: &HeightmapOptions,
    voids: bool,
) -> Result<(HeightField, Vec<bool>)> {
    let RawGrid {
        columns,
        rows,
        values: mut raw,
        spacing,
        north_up,
    } = grid;
    if columns == 0 || rows == 0 {
        return Err(Error::input(path, format!("image is empty ({columns}×{rows})")));
    }
    if columns < 2 || rows < 2 {
        return Err(Error::input(
            path,
            format!("image is {columns}×{rows}; a height field needs at least 2×2 samples"),
        ));
    }
    let mut unknown = Vec::new();
    if voids {
        unknown = raw.iter().map(|v| !v.is_finite()).collect();
        raw.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = 0.0);
    }
    if let Some(i) = raw.iter().position(|v| !v.is_finite()) {
        let (c, r) = (i % columns as usize, i / columns as usize);
        return Err(Error::input(
            path,
            format!("sample at column {c}, row {r} is {}", raw[i]),
        ));
    }
    if north_up.unwrap_or(opts.rows == RowOrder::NorthUp) {
        flip_rows(&mut raw, columns as usize);
        flip_rows(&mut unknown, columns as usize);
    }
    for v in &mut raw {
        *v = *v * opts.scale + opts.offset;
    }
    let spacing = match (opts.spacing, spacing) {
        (Some(given), _) => given,
        (None, Some(from_file)) => {
            check_spacing(from_file).map_err(|m| Error::input(path, format!("georeferencing: {m}")))?;
            from_file
        }
        (None, None) => {
            log::warn!(
                "{}: uses the default spacing of 1 m; pass --spacing (metres between samples)",
                path.display()
            );
            DVec2::ONE
        }
    };
    let field = HeightField {
        columns,
        rows,
        spacing,
        heights: raw,
    };
    // Catches overflow of value·scale + offset, among others.
    field.validate(path)?;
    Ok((field, unknown))
}

/// Reverses the order of the rows of `values` (`columns` per row) in place.
fn flip_rows<T>(values: &mut [T], columns: usize) {
    let rows = values.len() / columns.max(1);
    for r in 0..rows / 2 {
        let (top, bottom) = values.split_at_mut((rows - 1 - r) * columns);
        top[r * columns..(r + 1) * columns].swap_with_slice(&mut bottom[..columns]);
    }
}

/// Decodes the height channel of an OpenEXR file into raw values.
fn decode_exr(path: &Path, bytes: &[u8], limits: &InputLimits) -> Result<RawGrid> {
    let (w, h, channels) = crate::io::image_out::decode_exr_channels_limited(path, bytes, limits)?;
    let short = |n: &str| n.rsplit('.').next().unwrap_or(n).to_string();
    let pick = ["Y", "R", "Z"]
        .iter()
        .find_map(|want| channels.iter().position(|(n, _)| short(n) == *want))
        .unwrap_or(0);
    let raw = channels
        .into_iter()
        .nth(pick)
        .map(|(_, samples)| samples)
        .ok_or_else(|| Error::input(path, "OpenEXR file has no channels"))?;
    Ok(RawGrid::plain(w, h, raw))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field() -> HeightField {
        HeightField {
            columns: 3,
            rows: 2,
            spacing: DVec2::new(2.0, 0.5),
            heights: vec![1.0, 2.0, 3.0, 4.0, 5.0, -6.0],
        }
    }

    #[test]
    fn accessors() {
        let f = field();
        assert_eq!(f.height(1, 1), 5.0);
        assert_eq!(f.height(9, 9), -6.0);
        assert_eq!(f.extent(), DVec2::new(4.0, 0.5));
        assert_eq!(f.min_max(), (-6.0, 5.0));
        assert!(f.validate(Path::new("x")).is_ok());
    }

    #[test]
    fn validate_rejects_bad_fields() {
        let p = Path::new("field.bin");
        let mut f = field();
        f.heights[4] = f32::NAN;
        let e = f.validate(p).unwrap_err().to_string();
        assert!(e.contains("column 1, row 1") && e.contains("field.bin"), "{e}");
        let mut f = field();
        f.spacing.y = 0.0;
        assert!(f.validate(p).is_err());
        let mut f = field();
        f.heights.pop();
        assert!(f.validate(p).is_err());
        assert!(f.height(2, 1).is_nan());
        let f = HeightField {
            columns: 1,
            rows: 5,
            spacing: DVec2::ONE,
            heights: vec![0.0; 5],
        };
        assert!(f.validate(p).is_err());
    }

    #[test]
    fn bad_options_are_rejected_before_reading() {
        let p = Path::new("does-not-matter.png");
        for opts in [
            HeightmapOptions {
                scale: 0.0,
                ..Default::default()
            },
            HeightmapOptions {
                scale: f32::NAN,
                ..Default::default()
            },
            HeightmapOptions {
                offset: f32::INFINITY,
                ..Default::default()
            },
            HeightmapOptions {
                spacing: Some(DVec2::new(1.0, -1.0)),
                ..Default::default()
            },
            HeightmapOptions {
                spacing: Some(DVec2::splat(1e30)),
                ..Default::default()
            },
        ] {
            let e = load_heightmap(p, &opts).unwrap_err().to_string();
            assert!(e.contains("does-not-matter.png"), "{e}");
        }
    }
}
