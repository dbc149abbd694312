//! Obtained over demanded sample density of a warped geometry image
//! (dissertation §7.4.2, Fig. 7.12), and a small histogram helper.

#[cfg(test)]
use std::fmt;

use glam::{DMat2, DVec2, DVec3};

use super::{bilinear, clean};
use crate::error::{Error, Result};
use crate::terrain::importance::check_grid;

/// Obtained over demanded sample density per warped texel (Fig. 7.12).
#[derive(Clone, Debug, PartialEq)]
pub struct DensityRatio {
    /// `sqrt(along_rows · along_columns)`: the isotropic ratio.
    pub combined: Vec<f64>,
    /// `(1 / spacing along the row) / demanded`.
    pub along_rows: Vec<f64>,
    /// `(1 / spacing along the column) / demanded`.
    pub along_columns: Vec<f64>,
}

/// Measures how well a warp meets the importance map (Fig. 7.12).
///
/// * Obtained density of warped texel `(r, c)`: `1 / s` per direction,
///   where `s` is the planar world distance between its two row (column)
///   neighbours divided by their index distance (central difference,
///   one-sided at the border).
/// * Demanded density: `k · I(x, y)`, the importance map bilinearly
///   interpolated at the texel's warped `(x, y)` in the frame of the
///   (affine, regular) `sketch` map, with `k = (n − 1) / sqrt(∬ I² dA)`
///   (trapezoid rule over the sketch map) so that an isotropic density
///   `k·I` would place exactly the `(n − 1)²` cells of the mesh. Uniform
///   importance on a square-celled map gives ratio 1.
///
/// Errors on wrong sizes, a degenerate sketch frame or an all-zero map.
pub fn density_ratio(warped: &[DVec3], sketch: &[DVec3], importance: &[f64], n: usize) -> Result<DensityRatio> {
    check_grid("warped image", warped.len(), n)?;
    check_grid("sketch map", sketch.len(), n)?;
    check_grid("importance map", importance.len(), n)?;
    let m = (n - 1) as f64;
    let origin = sketch[0].truncate();
    let a = (sketch[n - 1].truncate() - origin) / m;
    let b = (sketch[n * (n - 1)].truncate() - origin) / m;
    let frame = DMat2::from_cols(a, b);
    let det = frame.determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err(Error::invalid("sketch map", "corner texels span no area"));
    }
    let inv = frame.inverse();
    let edge = |k: usize| if k == 0 || k == n - 1 { 0.5 } else { 1.0 };
    let sum_sq: f64 = (0..n * n)
        .map(|k| edge(k % n) * edge(k / n) * clean(importance[k]).powi(2))
        .sum();
    let integral = sum_sq * det.abs();
    if !(integral.is_finite() && integral > 0.0) {
        return Err(Error::invalid("importance map", "no positive finite importance"));
    }
    let k = m / integral.sqrt();
    let cleaned: Vec<f64> = importance.iter().map(|&i| clean(i)).collect();
    let lookup = |xy: DVec2| -> f64 { bilinear(&cleaned, n, inv * (xy - origin)) };
    let xy = |r: usize, c: usize| warped[r * n + c].truncate();
    let spacing = |p: DVec2, q: DVec2, steps: usize| (q - p).length() / steps as f64;
    let mut out = DensityRatio {
        combined: Vec::with_capacity(n * n),
        along_rows: Vec::with_capacity(n * n),
        along_columns: Vec::with_capacity(n * n),
    };
    for r in 0..n {
        let (r0, r1) = (r.saturating_sub(1), (r + 1).min(n - 1));
        for c in 0..n {
            let (c0, c1) = (c.saturating_sub(1), (c + 1).min(n - 1));
            let demanded = k * lookup(xy(r, c));
            let row = 1.0 / spacing(xy(r, c0), xy(r, c1), c1 - c0) / demanded;
            let col = 1.0 / spacing(xy(r0, c), xy(r1, c), r1 - r0) / demanded;
            out.along_rows.push(row);
            out.along_columns.push(col);
            out.combined.push((row * col).sqrt());
        }
    }
    Ok(out)
}

/// A histogram over fixed bin edges: bin `k` counts values in
/// `[edges[k], edges[k + 1])`.
#[derive(Clone, Debug, PartialEq)]
#[cfg(test)]
pub struct Histogram {
    /// Ascending bin edges (at least two).
    pub edges: Vec<f64>,
    /// One count per bin.
    pub counts: Vec<usize>,
    /// Values below the first edge.
    pub below: usize,
    /// Values at or above the last edge (including +∞).
    pub above: usize,
    /// NaN values.
    pub nan: usize,
}

/// Counts `values` into the bins given by ascending `edges` (fewer than
/// two edges: everything is counted as below/above/NaN only).
#[cfg(test)]
pub fn histogram(values: &[f64], edges: &[f64]) -> Histogram {
    let bins = edges.len().saturating_sub(1);
    let mut h = Histogram {
        edges: edges.to_vec(),
        counts: vec![0; bins],
        below: 0,
        above: 0,
        nan: 0,
    };
    for &v in values {
        if v.is_nan() {
            h.nan += 1;
        } else if bins == 0 || v < edges[0] {
            h.below += 1;
        } else if v >= edges[bins] {
            h.above += 1;
        } else {
            // First edge above v, minus one: v's bin.
            let k = edges.partition_point(|&e| e <= v).saturating_sub(1).min(bins - 1);
            h.counts[k] += 1;
        }
    }
    h
}

/// Fraction of `values` in the closed interval `[lo, hi]` (0 if empty).
#[cfg(test)]
pub fn fraction_within(values: &[f64], lo: f64, hi: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.iter().filter(|&&v| v >= lo && v <= hi).count() as f64 / values.len() as f64
}

#[cfg(test)]
impl fmt::Display for Histogram {
    /// One line per bin: range, count, percentage and a bar.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let total = (self.counts.iter().sum::<usize>() + self.below + self.above + self.nan).max(1);
        let mut line = |label: String, count: usize| {
            let pct = 100.0 * count as f64 / total as f64;
            writeln!(
                f,
                "{label:>16} {count:>7} {pct:>6.2} % {}",
                "#".repeat((pct / 2.0).round() as usize)
            )
        };
        if let Some(&first) = self.edges.first() {
            line(format!("< {first}"), self.below)?;
        }
        for (k, &count) in self.counts.iter().enumerate() {
            line(format!("[{}, {})", self.edges[k], self.edges[k + 1]), count)?;
        }
        if let Some(&last) = self.edges.last() {
            line(format!(">= {last}"), self.above)?;
        }
        if self.nan > 0 {
            line("NaN".to_string(), self.nan)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_density_ratio_is_one() {
        let n = 5;
        let g: Vec<DVec3> = (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * 2.0, (k / n) as f64 * 2.0, 0.0))
            .collect();
        let d = density_ratio(&g, &g, &vec![3.0; n * n], n).unwrap();
        assert!(d.combined.iter().all(|&v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn histogram_bins() {
        let h = histogram(&[0.1, 0.5, 0.7, 1.0, 2.0, f64::NAN, f64::INFINITY], &[0.5, 1.0, 1.5]);
        assert_eq!((h.below, h.counts.clone(), h.above, h.nan), (1, vec![2, 1], 2, 1));
        assert!(h.to_string().contains("[0.5, 1)"));
        assert_eq!(fraction_within(&[0.5, 1.0, 1.1, 0.2], 0.5, 1.0), 0.5);
    }
}
