//! Height fields and loading them from 16-bit PNG or OpenEXR height maps.
//!
//! # Convention
//!
//! Sample (column `c`, row `r`) sits at world position `(c·dx, r·dy, h)`
//! (right-handed, +Z up). Row `r` of the image is row `r` of the field: the
//! image is **not** flipped. Image row 0 (the top row) therefore lies at
//! `y = 0` and later rows at larger `y`. For a north-up map (such as the
//! SRTM test DEM, whose row 0 is its northern edge) +Y points south, and a
//! right-handed +Z-up world then shows the map mirrored north–south unless
//! the caller flips the rows; this loader leaves that choice to the caller.

use std::io::Cursor;
use std::path::Path;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::io::{one_line, MAX_DECODE_BYTES};

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
    /// columns·rows`, finite positive spacing, all heights finite. Errors
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
        if let Some(i) = self.heights.iter().position(|v| !v.is_finite()) {
            let (c, r) = (i % w as usize, i / w as usize);
            return Err(Error::input(
                origin,
                format!("height at column {c}, row {r} is {}", self.heights[i]),
            ));
        }
        Ok(())
    }
}

/// Why a spacing is unusable, if it is.
fn check_spacing(spacing: DVec2) -> std::result::Result<(), String> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if ok(spacing.x) && ok(spacing.y) {
        Ok(())
    } else {
        Err(format!(
            "sample spacing ({}, {}) must be finite and positive",
            spacing.x, spacing.y
        ))
    }
}

/// How raw height-map values become metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightmapOptions {
    /// Multiplies each raw value (PNG: the integer 0‥65535 or 0‥255; EXR:
    /// the stored float). Must be finite and positive.
    pub scale: f32,
    /// Added after scaling, in metres. Must be finite.
    pub offset: f32,
    /// Metres between samples in x (columns) and y (rows). Must be finite
    /// and positive.
    pub spacing: DVec2,
}

impl Default for HeightmapOptions {
    /// Scale 1, offset 0, spacing 1 m × 1 m.
    fn default() -> Self {
        Self {
            scale: 1.0,
            offset: 0.0,
            spacing: DVec2::ONE,
        }
    }
}

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Loads a height map: `height = raw · scale + offset` in metres.
///
/// The format is recognised by content (file signature):
///
/// * **PNG**, 16-bit greyscale (the usual DEM encoding) or 8-bit
///   greyscale; raw values are the unsigned integers. Colour, palette and
///   grey+alpha PNGs are rejected.
/// * **OpenEXR**: the first valid layer at full resolution; the channel
///   named `Y`, else `R`, else `Z` (also as the last component of a layer
///   name like `height.Y`), else the alphabetically first channel; raw
///   values are the stored floats (half, float or uint).
///
/// Rows are not flipped; see the module documentation for the convention.
///
/// Errors (one line, naming the file): options out of range (non-finite or
/// non-positive scale or spacing, non-finite offset), missing or unreadable
/// file, empty file, unsupported format, corrupt or truncated data, colour
/// PNG, an image smaller than 2×2 samples, and NaN or infinite heights (the
/// first bad sample's column and row are named).
pub fn load_heightmap(path: &Path, opts: &HeightmapOptions) -> Result<HeightField> {
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
    check_spacing(opts.spacing).map_err(|m| Error::invalid("height-map spacing", format!("{m} (for {name})")))?;

    let bytes = crate::io::read_input(path)?;
    if bytes.is_empty() {
        return Err(Error::input(path, "file is empty"));
    }
    let (columns, rows, raw) = if bytes.starts_with(PNG_MAGIC) {
        decode_png(path, &bytes)?
    } else if bytes.starts_with(EXR_MAGIC) {
        decode_exr(path, &bytes)?
    } else {
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        let msg = match ext.as_deref() {
            Some("png") => "not a PNG file (bad signature)",
            Some("exr") => "not an OpenEXR file (bad signature)",
            _ => "unsupported height-map format (expected a greyscale PNG or an OpenEXR file)",
        };
        return Err(Error::input(path, msg));
    };
    if columns == 0 || rows == 0 {
        return Err(Error::input(path, format!("image is empty ({columns}×{rows})")));
    }
    if columns < 2 || rows < 2 {
        return Err(Error::input(
            path,
            format!("image is {columns}×{rows}; a height field needs at least 2×2 samples"),
        ));
    }
    if let Some(i) = raw.iter().position(|v| !v.is_finite()) {
        let (c, r) = (i % columns as usize, i / columns as usize);
        return Err(Error::input(
            path,
            format!("sample at column {c}, row {r} is {}", raw[i]),
        ));
    }
    let heights: Vec<f32> = raw.iter().map(|&v| v * opts.scale + opts.offset).collect();
    let field = HeightField {
        columns,
        rows,
        spacing: opts.spacing,
        heights,
    };
    // Catches overflow of value·scale + offset to infinity, among others.
    field.validate(path)?;
    Ok(field)
}

/// Decodes a greyscale PNG into raw values.
fn decode_png(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<f32>)> {
    use image::codecs::png::PngDecoder;
    use image::{ColorType, ImageDecoder, Limits};
    let corrupt = |e: image::ImageError| Error::input(path, format!("invalid PNG: {}", one_line(e)));
    let mut limits = Limits::default();
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    let decoder = PngDecoder::with_limits(Cursor::new(bytes), limits).map_err(corrupt)?;
    let (w, h) = decoder.dimensions();
    let color = decoder.color_type();
    let bytes_per_sample = match color {
        ColorType::L16 => 2,
        ColorType::L8 => 1,
        ColorType::La8 | ColorType::La16 => {
            return Err(Error::input(
                path,
                "PNG has an alpha channel; save the height map as plain greyscale (16-bit)",
            ))
        }
        other => {
            return Err(Error::input(
                path,
                format!("PNG is a colour image ({other:?}); height maps must be greyscale (16-bit)"),
            ))
        }
    };
    let total = usize::try_from(decoder.total_bytes()).map_err(|_| Error::input(path, "image too large"))?;
    let mut buf = vec![0u8; total];
    decoder.read_image(&mut buf).map_err(corrupt)?;
    let raw = if bytes_per_sample == 2 {
        // `image` returns 16-bit samples in native byte order.
        buf.chunks_exact(2)
            .map(|b| f32::from(u16::from_ne_bytes([b[0], b[1]])))
            .collect()
    } else {
        buf.iter().map(|&b| f32::from(b)).collect()
    };
    Ok((w, h, raw))
}

/// Decodes the height channel of an OpenEXR file into raw values.
fn decode_exr(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<f32>)> {
    let (w, h, channels) = crate::io::image_out::decode_exr_channels(path, bytes)?;
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
    Ok((w, h, raw))
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
                spacing: DVec2::new(1.0, -1.0),
                ..Default::default()
            },
        ] {
            let e = load_heightmap(p, &opts).unwrap_err().to_string();
            assert!(e.contains("does-not-matter.png"), "{e}");
        }
    }
}
