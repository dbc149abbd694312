//! SRTM `.hgt` height maps: a square grid of big-endian signed 16-bit
//! heights in metres, row 0 the northern edge, 1201² samples (3″, SRTM3)
//! or 3601² (1″, SRTM1), covering the 1°×1° cell named by the file
//! (`N37W122.hgt`: latitudes 37..38 °N, longitudes 122..121 °W).
//!
//! Spacing: 3″ or 1″ converted to metres at the cell's centre latitude
//! with [`metres_per_degree`]. Voids (−32768) are an error naming the
//! first one: fill them first (e.g. `gdal_fillnodata.py`), since any
//! filled value would be a guess.

use std::path::Path;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::io::heightmap::RawGrid;

/// The void marker of SRTM files.
pub const VOID: i16 = -32768;

/// Metres per degree of longitude (x) and of latitude (y) at latitude
/// `lat_deg` on the WGS84 ellipsoid (the usual series expansion, accurate
/// to about a centimetre per degree).
pub fn metres_per_degree(lat_deg: f64) -> DVec2 {
    let phi = lat_deg.to_radians();
    let lon = 111_412.84 * phi.cos() - 93.5 * (3.0 * phi).cos() + 0.118 * (5.0 * phi).cos();
    let lat = 111_132.92 - 559.82 * (2.0 * phi).cos() + 1.175 * (4.0 * phi).cos() - 0.0023 * (6.0 * phi).cos();
    DVec2::new(lon.max(0.0), lat)
}

/// The latitude of the south-west corner named by an SRTM file name
/// (`N37W122.hgt` → 37, `S12E044.hgt` → −12), if it has one.
pub fn latitude_from_name(path: &Path) -> Option<f64> {
    let stem = path.file_stem()?.to_str()?.to_ascii_uppercase();
    let sign = match stem.as_bytes().first()? {
        b'N' => 1.0,
        b'S' => -1.0,
        _ => return None,
    };
    let digits: String = stem[1..].chars().take_while(char::is_ascii_digit).collect();
    let lat: f64 = digits.parse().ok()?;
    let rest = &stem[1 + digits.len()..];
    (lat <= 90.0 && (rest.starts_with('E') || rest.starts_with('W'))).then_some(sign * lat)
}

/// Decodes an SRTM `.hgt` file: its size gives the resolution, its name the
/// latitude (for the spacing). Voids are an error, or NaN samples with
/// `voids` (the unknown samples of [`crate::io::heightmap::load_heightmap_with_voids`]).
pub(crate) fn decode_hgt(path: &Path, bytes: &[u8], voids: bool) -> Result<RawGrid> {
    let (side, arc_seconds) = match bytes.len() {
        n if n == 1201 * 1201 * 2 => (1201u32, 3.0),
        n if n == 3601 * 3601 * 2 => (3601u32, 1.0),
        n => {
            return Err(Error::input(
                path,
                format!(
                    "SRTM .hgt file of {n} bytes; expected 1201² or 3601² 16-bit samples (2884802 or 25934402 bytes)"
                ),
            ))
        }
    };
    let lat = latitude_from_name(path).ok_or_else(|| {
        Error::input(
            path,
            "an SRTM .hgt file's name must give its latitude and longitude, like N37W122.hgt",
        )
    })?;
    let mut values = Vec::with_capacity(bytes.len() / 2);
    for (i, b) in bytes.chunks_exact(2).enumerate() {
        let v = i16::from_be_bytes([b[0], b[1]]);
        if v == VOID && voids {
            values.push(f32::NAN);
            continue;
        }
        if v == VOID {
            let (c, r) = (i % side as usize, i / side as usize);
            return Err(Error::input(
                path,
                format!("void sample (−32768) at column {c}, row {r}; fill the voids first (e.g. gdal_fillnodata.py)"),
            ));
        }
        values.push(f32::from(v));
    }
    let degrees = arc_seconds / 3600.0;
    let centre = lat + 0.5;
    Ok(RawGrid {
        columns: side,
        rows: side,
        values,
        spacing: Some(metres_per_degree(centre) * degrees),
        north_up: Some(true),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_metres_per_degree() {
        assert_eq!(latitude_from_name(Path::new("a/N37W122.hgt")), Some(37.0));
        assert_eq!(latitude_from_name(Path::new("s12e044.HGT")), Some(-12.0));
        assert_eq!(latitude_from_name(Path::new("dem.hgt")), None);
        let equator = metres_per_degree(0.0);
        assert!(
            (equator.x - 111_319.5).abs() < 1.0 && (equator.y - 110_574.3).abs() < 1.0,
            "{equator}"
        );
        let m45 = metres_per_degree(45.0);
        assert!(
            (m45.x - 78_846.8).abs() < 1.0 && (m45.y - 111_131.8).abs() < 1.0,
            "{m45}"
        );
        assert!(metres_per_degree(90.0).x < 1.0);
    }

    #[test]
    fn voids_and_sizes_are_errors() {
        let p = Path::new("N10E010.hgt");
        let e = decode_hgt(p, &[0u8; 100], false).unwrap_err().to_string();
        assert!(e.contains("100 bytes"), "{e}");
        let mut bytes = vec![0u8; 1201 * 1201 * 2];
        bytes[2 * 1205..2 * 1205 + 2].copy_from_slice(&VOID.to_be_bytes());
        assert!(decode_hgt(p, &bytes, true).unwrap().values[1205].is_nan());
        let e = decode_hgt(p, &bytes, false).unwrap_err().to_string();
        assert!(e.contains("column 4, row 1"), "{e}");
        bytes[2 * 1205..2 * 1205 + 2].copy_from_slice(&(-5i16).to_be_bytes());
        let g = decode_hgt(p, &bytes, false).unwrap();
        assert_eq!((g.columns, g.rows, g.values[1205]), (1201, 1201, -5.0));
        let s = g.spacing.unwrap();
        assert!((s.y - 92.18).abs() < 0.01 && (s.x - 91.22).abs() < 0.01, "{s}");
        assert!(decode_hgt(Path::new("dem.hgt"), &bytes, false).is_err());
    }
}
