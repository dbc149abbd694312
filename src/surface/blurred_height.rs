//! Blurred height fields for `height_blur` layers (dissertation §8.2.3:
//! "snow is deposited in furrows by wind. The effect can be achieved when a
//! blurred elevation data serves as input for the slope constraint
//! evaluation"; `ALGORITHMS.md` §4): the height field convolved with a
//! Gaussian of standard deviation R metres, separable, σ = R/spacing
//! samples per axis, truncated at 3σ and normalised, the border sample
//! repeated outside the field. The CPU computes it once per distinct radius;
//! the GPU samples the result with the same cubic B-spline as the base
//! height ([`crate::surface::input_maps`] uploads it), and the CPU
//! reference ([`crate::texturing::reference`]) reads the same samples.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;

/// Largest σ in samples along an axis (the kernel has 2·⌈3σ⌉ + 1 taps).
pub const MAX_BLUR_SAMPLES: f64 = 64.0;

/// Normalised Gaussian taps of standard deviation `sigma` samples, from
/// −⌈3σ⌉ to +⌈3σ⌉.
fn gaussian_taps(sigma: f64) -> Vec<f64> {
    let half = (3.0 * sigma).ceil() as i64;
    let taps: Vec<f64> = (-half..=half)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.into_iter().map(|t| t / sum).collect()
}

/// One pass along rows (`along_x`) or columns of `values` (columns × rows).
fn convolve(values: &[f64], columns: usize, rows: usize, taps: &[f64], along_x: bool) -> Vec<f64> {
    let half = (taps.len() / 2) as i64;
    let mut out = vec![0.0; values.len()];
    for r in 0..rows {
        for c in 0..columns {
            let (at, len) = if along_x { (c, columns) } else { (r, rows) };
            let mut sum = 0.0;
            for (k, w) in taps.iter().enumerate() {
                let q = (at as i64 + k as i64 - half).clamp(0, len as i64 - 1) as usize;
                let index = if along_x { r * columns + q } else { q * columns + c };
                sum += w * values[index];
            }
            out[r * columns + c] = sum;
        }
    }
    out
}

/// `field` blurred with a Gaussian of standard deviation `radius` metres
/// (module docs); an error naming `what` when that is more than
/// [`MAX_BLUR_SAMPLES`] samples along an axis.
pub fn blurred_height(field: &HeightField, radius: f32, what: &str) -> Result<HeightField> {
    let sigma = field.spacing.map(|s| f64::from(radius) / s);
    if !(sigma.x > 0.0 && sigma.y > 0.0) || sigma.max_element() > MAX_BLUR_SAMPLES {
        return Err(Error::invalid(
            what,
            format!(
                "{radius} m is {:.1} × {:.1} samples of the height field; at most {MAX_BLUR_SAMPLES} per axis",
                sigma.x, sigma.y
            ),
        ));
    }
    let (columns, rows) = (field.columns as usize, field.rows as usize);
    if field.heights.len() != columns * rows {
        return Err(Error::invalid(
            "height_blur",
            "the height field's size does not match its samples",
        ));
    }
    let values: Vec<f64> = field.heights.iter().map(|&h| f64::from(h)).collect();
    let along_x = convolve(&values, columns, rows, &gaussian_taps(sigma.x), true);
    let both = convolve(&along_x, columns, rows, &gaussian_taps(sigma.y), false);
    Ok(HeightField {
        heights: both.into_iter().map(|h| h as f32).collect(),
        ..field.clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn field(columns: u32, rows: u32, spacing: f64, f: impl Fn(f64, f64) -> f64) -> HeightField {
        HeightField::from_fn(columns, rows, DVec2::splat(spacing), |c, r| {
            f(f64::from(c), f64::from(r)) as f32
        })
    }

    #[test]
    fn taps_are_a_normalised_gaussian_of_the_given_deviation() {
        let taps = gaussian_taps(2.5);
        assert_eq!(taps.len(), 2 * 8 + 1);
        assert!((taps.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let variance: f64 = (taps.iter().enumerate())
            .map(|(k, w)| w * (k as f64 - 8.0).powi(2))
            .sum();
        assert!((variance - 6.25).abs() < 0.05, "{variance}");
    }

    #[test]
    fn blur_keeps_planes_and_spreads_a_spike_as_a_gaussian() {
        // A plane stays a plane away from the border (a symmetric kernel).
        let plane = field(41, 31, 10.0, |c, r| 3.0 * c - 2.0 * r + 100.0);
        let blurred = blurred_height(&plane, 20.0, "plane").unwrap();
        for (c, r) in [(20, 15), (10, 8), (30, 20)] {
            assert!((blurred.height(c, r) - plane.height(c, r)).abs() < 1e-3);
        }
        // A spike of volume 1 at the centre: the blurred height at distance
        // d is the sampled Gaussian of σ = 2 samples (20 m / 10 m).
        let spike = field(41, 41, 10.0, |c, r| if c == 20.0 && r == 20.0 { 1.0 } else { 0.0 });
        let blurred = blurred_height(&spike, 20.0, "spike").unwrap();
        let taps = gaussian_taps(2.0);
        for (dc, dr) in [(0, 0), (1, 0), (2, 3), (6, 6)] {
            let expected = taps[6 + dc] * taps[6 + dr];
            let got = f64::from(blurred.height(20 + dc as u32, 20 + dr as u32));
            assert!((got - expected).abs() < 1e-7, "({dc}, {dr}): {got} vs {expected}");
        }
        assert_eq!(blurred.height(27, 20), 0.0);
        let total: f64 = blurred.heights.iter().map(|&h| f64::from(h)).sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn radii_beyond_the_kernel_limit_are_errors() {
        let flat = field(8, 8, 10.0, |_, _| 0.0);
        let message = blurred_height(&flat, 641.0, "layer 'snow': height_blur")
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("height_blur") && message.contains("at most 64"),
            "{message}"
        );
        assert!(blurred_height(&flat, 640.0, "flat").is_ok());
    }
}
