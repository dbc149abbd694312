//! The three-channel image of height-field synthesis (dissertation §7.3.3)
//! and the candidate windows a search compares against.
//!
//! # Channels
//!
//! Each sample becomes `(h, ∂h/∂x, ∂h/∂y)`: the height in metres and its
//! slopes along the columns and rows (metres per metre, using the field's
//! spacing). A known sample's derivative is the central difference where
//! both neighbours along that axis are known, the one-sided difference
//! where only one is, and 0 where neither is.
//!
//! The channels are normalised before they are compared ([`Normalisation`]):
//! both slopes as `∂h/σ_s`, σ_s the RMS of the known slope components, and
//! heights as `(h − mean)/(σ_s·d)`, `mean` that of the known heights and
//! `d = (dx + dy)/2` the mean spacing: the height unit is the typical step
//! between neighbouring samples. A height mismatch of one such step then
//! weighs as much as a mismatch of one typical slope, whatever the units
//! and relief of the DEM, and λ (`--lambda`) is a dimensionless balance.
//!
//! (Measured on the Jacksboro DEM, 32² holes: with heights in units of
//! their standard deviation instead (many steps), the height
//! channel barely constrains the match and the copied heights are visibly
//! noisy; a unit of 4 steps is still noisy; 1 step gives the smoothest
//! fills. Scaling the unit by `k` is the same as dividing λ by `k²`.)
//!
//! # Candidates
//!
//! The candidate windows are the centres of the n×n windows that lie
//! inside the grid and hold only known samples. A large DEM has about a
//! million of them, more than a pixel-by-pixel search can afford, so at
//! most a given number are kept: those nearest the unknown samples first
//! (chessboard distance from the window's centre to the nearest unknown
//! sample), ties in a seeded hash order. Terrain near a hole is the best
//! model of what is missing, and the choice is deterministic for a seed.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::synthesis::search::lowbias32;

/// How the channels are scaled before they are compared (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalisation {
    /// Mean of the known heights in metres.
    pub height_mean: f64,
    /// Height unit in metres: the RMS height step between neighbouring
    /// samples, `slope_scale · (dx + dy)/2` (1 if the field is flat).
    pub height_scale: f64,
    /// RMS of the known slope components (1 if the field is flat).
    pub slope_scale: f64,
}

impl Normalisation {
    /// The statistics of the known samples of `field` (with its unknown
    /// mask and slopes, as [`slopes`] gives them).
    pub fn of(field: &HeightField, unknown: &[bool], slopes: &[[f32; 2]]) -> Normalisation {
        let (mut count, mut sum, mut slope_sq) = (0.0f64, 0.0f64, 0.0f64);
        for ((&h, &u), s) in field.heights.iter().zip(unknown).zip(slopes) {
            if !u {
                count += 1.0;
                sum += f64::from(h);
                slope_sq += f64::from(s[0]).powi(2) + f64::from(s[1]).powi(2);
            }
        }
        let count = count.max(1.0);
        let mean = sum / count;
        let positive_or_one = |v: f64| if v > 0.0 && v.is_finite() { v } else { 1.0 };
        let slope_scale = positive_or_one((slope_sq / (2.0 * count)).sqrt());
        let spacing = (field.spacing.x + field.spacing.y) / 2.0;
        Normalisation {
            height_mean: mean,
            height_scale: positive_or_one(slope_scale * spacing),
            slope_scale,
        }
    }

    /// The normalised texel of height `h` and slopes `s`.
    pub fn texel(&self, h: f32, s: [f32; 2]) -> [f32; 3] {
        [
            ((f64::from(h) - self.height_mean) / self.height_scale) as f32,
            (f64::from(s[0]) / self.slope_scale) as f32,
            (f64::from(s[1]) / self.slope_scale) as f32,
        ]
    }
}

/// Slopes `(∂h/∂x, ∂h/∂y)` of every known sample (module docs); `[0, 0]`
/// at unknown samples.
pub fn slopes(field: &HeightField, unknown: &[bool]) -> Vec<[f32; 2]> {
    let (w, h) = (field.columns as usize, field.rows as usize);
    let known = |c: usize, r: usize| !unknown[r * w + c];
    let at = |c: usize, r: usize| field.heights[r * w + c];
    // Difference quotient along one axis from the known neighbours.
    let derivative = |prev: Option<f32>, here: f32, next: Option<f32>, step: f64| -> f32 {
        match (prev, next) {
            (Some(p), Some(n)) => ((f64::from(n) - f64::from(p)) / (2.0 * step)) as f32,
            (None, Some(n)) => ((f64::from(n) - f64::from(here)) / step) as f32,
            (Some(p), None) => ((f64::from(here) - f64::from(p)) / step) as f32,
            (None, None) => 0.0,
        }
    };
    let mut out = vec![[0.0; 2]; w * h];
    for r in 0..h {
        for c in 0..w {
            if !known(c, r) {
                continue;
            }
            let left = (c > 0 && known(c - 1, r)).then(|| at(c - 1, r));
            let right = (c + 1 < w && known(c + 1, r)).then(|| at(c + 1, r));
            let down = (r > 0 && known(c, r - 1)).then(|| at(c, r - 1));
            let up = (r + 1 < h && known(c, r + 1)).then(|| at(c, r + 1));
            out[r * w + c] = [
                derivative(left, at(c, r), right, field.spacing.x),
                derivative(down, at(c, r), up, field.spacing.y),
            ];
        }
    }
    out
}

/// The normalised texels of `field` (`[0; 3]` at unknown samples).
pub fn texels(field: &HeightField, unknown: &[bool], slopes: &[[f32; 2]], norm: &Normalisation) -> Vec<[f32; 3]> {
    field
        .heights
        .iter()
        .zip(unknown)
        .zip(slopes)
        .map(|((&h, &u), &s)| if u { [0.0; 3] } else { norm.texel(h, s) })
        .collect()
}

/// Centres (`row·columns + column`) of the `window`×`window` windows of a
/// `columns`×`rows` grid that lie inside it and hold no unknown sample.
pub fn known_windows(columns: u32, rows: u32, unknown: &[bool], window: u32) -> Vec<u32> {
    let (w, h, n) = (columns as usize, rows as usize, window as usize);
    if n > w || n > h {
        return Vec::new();
    }
    // Summed-area table of unknown samples, (w+1)×(h+1).
    let mut table = vec![0u32; (w + 1) * (h + 1)];
    for r in 0..h {
        let mut row_sum = 0;
        for c in 0..w {
            row_sum += u32::from(unknown[r * w + c]);
            table[(r + 1) * (w + 1) + c + 1] = table[r * (w + 1) + c + 1] + row_sum;
        }
    }
    let half = n / 2;
    let mut centres = Vec::new();
    for r in 0..=h - n {
        for c in 0..=w - n {
            let at = |rr: usize, cc: usize| table[rr * (w + 1) + cc];
            let holes = at(r + n, c + n) + at(r, c) - at(r, c + n) - at(r + n, c);
            if holes == 0 {
                centres.push(((r + half) * w + c + half) as u32);
            }
        }
    }
    centres
}

/// Chessboard distance of every sample of a `columns`×`rows` grid to the
/// nearest unknown one (`u32::MAX` without unknown samples); two passes.
pub fn distance_to_unknown(columns: u32, rows: u32, unknown: &[bool]) -> Vec<u32> {
    let (w, h) = (columns as usize, rows as usize);
    let far = u32::MAX / 2;
    let mut d: Vec<u32> = unknown.iter().map(|&u| if u { 0 } else { far }).collect();
    for r in 0..h {
        for c in 0..w {
            let mut best = d[r * w + c];
            for (dc, dr) in [(-1i64, -1i64), (0, -1), (1, -1), (-1, 0)] {
                let (cc, rr) = (c as i64 + dc, r as i64 + dr);
                if cc >= 0 && rr >= 0 && (cc as usize) < w {
                    best = best.min(d[rr as usize * w + cc as usize] + 1);
                }
            }
            d[r * w + c] = best;
        }
    }
    for r in (0..h).rev() {
        for c in (0..w).rev() {
            let mut best = d[r * w + c];
            for (dc, dr) in [(1i64, 1i64), (0, 1), (-1, 1), (1, 0)] {
                let (cc, rr) = (c as i64 + dc, r as i64 + dr);
                if cc >= 0 && (rr as usize) < h && (cc as usize) < w {
                    best = best.min(d[rr as usize * w + cc as usize] + 1);
                }
            }
            d[r * w + c] = best;
        }
    }
    d.iter().map(|&v| if v >= far { u32::MAX } else { v }).collect()
}

/// The at most `max` candidates of `ranked` (`(distance, centre)` pairs)
/// nearest first, ties in the order of a hash of `seed` and the centre;
/// returned in ascending centre order.
pub fn nearest_candidates(mut ranked: Vec<(u32, u32)>, max: usize, seed: u32) -> Vec<u32> {
    let salt = lowbias32(seed ^ 0x9e37_79b9);
    ranked.sort_unstable_by_key(|&(d, c)| (d, lowbias32(c ^ salt), c));
    let mut chosen: Vec<u32> = ranked.into_iter().take(max).map(|(_, c)| c).collect();
    chosen.sort_unstable();
    chosen
}

/// Checks that a mask has one entry per sample of `field`.
pub fn check_mask(field: &HeightField, unknown: &[bool], what: &str) -> Result<()> {
    let samples = field.columns as usize * field.rows as usize;
    if unknown.len() != samples || field.heights.len() != samples {
        return Err(Error::invalid(
            what,
            format!(
                "{} mask samples for a {}×{} height field ({samples} samples)",
                unknown.len(),
                field.columns,
                field.rows
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn slopes_are_central_or_one_sided() {
        let field = HeightField::from_fn(4, 3, DVec2::new(2.0, 1.0), |c, r| (c * c + 10 * r) as f32);
        let mut unknown = vec![false; 12];
        unknown[2] = true; // column 2, row 0
        let s = slopes(&field, &unknown);
        assert_eq!(s[5], [(4.0 - 0.0) / 4.0, 10.0], "central in x and y");
        assert_eq!(s[1], [(1.0 - 0.0) / 2.0, 10.0], "one-sided next to the unknown sample");
        assert_eq!(s[2], [0.0, 0.0], "unknown");
        assert_eq!(s[3][0], 0.0, "no known neighbour in x");
    }

    #[test]
    fn windows_distances_and_candidates() {
        let mut unknown = vec![false; 6 * 5];
        unknown[2 * 6 + 4] = true; // column 4, row 2
        let windows = known_windows(6, 5, &unknown, 3);
        // Centres at columns 1..=4, rows 1..=3, except those whose window holds (4, 2).
        assert_eq!(windows, vec![7, 8, 13, 14, 19, 20]);
        let d = distance_to_unknown(6, 5, &unknown);
        assert_eq!((d[16], d[0], d[7]), (0, 4, 3));
        let ranked = windows.iter().map(|&c| (d[c as usize], c)).collect::<Vec<_>>();
        let two = nearest_candidates(ranked.clone(), 2, 1);
        assert!(two.len() == 2 && two.iter().all(|c| [8, 14, 20].contains(c)), "{two:?}");
        assert_eq!(nearest_candidates(ranked, 100, 1).len(), 6);
        assert!(known_windows(2, 2, &[false; 4], 3).is_empty());
    }
}
