//! Distribution functions of the surface types (§8.3, "Estimating
//! Distribution Functions", Fig. 8.13): for each class and each input
//! quantity, the histogram of the quantity where the class occurs, scaled
//! so that its mean is 0.5 and clamped to [0, 1]. These sampled functions
//! replace the layers' hat functions; a layer's coverage is their product.
//!
//! Decisions:
//! * **Quantities** at each pixel centre: the altitude and slope of the
//!   surface the renderer draws (the height field's cubic B-spline, its
//!   analytic gradient in degrees), and every extra input map sampled as
//!   the renderer samples it (bilinear, the grid spanning the terrain
//!   corner to corner), so the render evaluates the functions on the
//!   quantities they were estimated from.
//! * **Domains**: altitude over the field's lowest to highest sample (as
//!   `altitude` with `min`/`max`); slope from 0° to the steepest slope
//!   found, rounded up to 5°; each input map over its own range.
//! * **Samples**: `n` equal bins over the domain, sample b being bin b's
//!   value (the format puts it at the bin's centre). Only counted pixels
//!   ([`super::PixelStatus::Counted`]) enter the histograms.
//! * **Level 2**: a class's histograms count the pixels of its level-2
//!   sub-classes too (`super::level2`): the parent layer covers the
//!   whole class, its children refine it.
//! * **Scaling**: `F_b = clamp(0.5 · h_b / mean(h), 0, 1)`, the mean over
//!   all n bins (empty ones too), as in the text.

use glam::DVec2;

use super::classify::{Classification, PixelStatus};
use crate::error::Result;
use crate::io::heightmap::HeightField;
use crate::surface::bspline::{sample_bspline, sample_bspline_gradient};
use crate::surface::layers::{LayerTree, SampledFunction, INPUT_NAMES};
use crate::texturing::reference::ReferenceSurface;

/// The input quantities at every pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    /// Metres.
    pub altitude: Vec<f32>,
    /// Degrees.
    pub slope: Vec<f32>,
    /// Extra input maps ([`INPUT_NAMES`] order), where given.
    pub maps: [Option<Vec<f32>>; 3],
    /// Domain of the altitude: the field's lowest and highest sample.
    pub altitude_range: (f32, f32),
}

impl Samples {
    /// The quantities at world positions `positions`.
    pub fn at(field: &HeightField, maps: &[Option<HeightField>; 3], positions: &[DVec2]) -> Result<Samples> {
        let empty = LayerTree { layers: Vec::new() };
        let reference = ReferenceSurface::new(field, &empty, maps, 0)?;
        let altitude = positions
            .iter()
            .map(|p| sample_bspline(field, p.x, p.y) as f32)
            .collect();
        let slope = positions
            .iter()
            .map(|p| sample_bspline_gradient(field, p.x, p.y).length().atan().to_degrees() as f32)
            .collect();
        let maps = [0, 1, 2].map(|k| {
            maps[k]
                .as_ref()
                .map(|_| positions.iter().map(|&p| reference.input_map(k, p)).collect())
        });
        Ok(Samples {
            altitude,
            slope,
            maps,
            altitude_range: field.min_max(),
        })
    }
}

/// One quantity's domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain {
    pub min: f32,
    pub max: f32,
}

/// The distribution functions of every class.
#[derive(Clone, Debug, PartialEq)]
pub struct Distributions {
    /// Per class: altitude, slope, then each present input map.
    pub classes: Vec<ClassFunctions>,
}

/// The distribution functions of one class.
#[derive(Clone, Debug, PartialEq)]
pub struct ClassFunctions {
    pub altitude: SampledFunction,
    pub slope: SampledFunction,
    /// [`INPUT_NAMES`] order.
    pub maps: [Option<SampledFunction>; 3],
}

/// Smallest and largest finite value.
fn range(values: &[f32]) -> (f32, f32) {
    values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The histogram of `values` where `take` holds, scaled to mean 0.5 and
/// clamped (module docs).
pub fn distribution(values: &[f32], take: impl Fn(usize) -> bool, domain: Domain, bins: usize) -> SampledFunction {
    let mut counts = vec![0.0f64; bins];
    let width = f64::from(domain.max - domain.min).max(f64::MIN_POSITIVE);
    for (i, &v) in values.iter().enumerate() {
        if take(i) && v.is_finite() {
            let b = (f64::from(v - domain.min) / width * bins as f64).floor();
            counts[(b.max(0.0) as usize).min(bins - 1)] += 1.0;
        }
    }
    let mean = counts.iter().sum::<f64>() / bins as f64;
    SampledFunction {
        samples: counts
            .iter()
            .map(|&c| {
                if mean > 0.0 {
                    (0.5 * c / mean).clamp(0.0, 1.0) as f32
                } else {
                    0.0
                }
            })
            .collect(),
        min: domain.min,
        max: domain.max,
    }
}

/// The slope domain: 0 to the steepest slope rounded up to 5° (at most 90°).
fn slope_domain(slope: &[f32]) -> Domain {
    let steepest = range(slope).1.max(0.0);
    Domain {
        min: 0.0,
        max: ((steepest / 5.0).ceil() * 5.0).clamp(5.0, 90.0),
    }
}

/// A map's domain: its range, widened where it is a single value.
fn map_domain(values: &[f32]) -> Domain {
    let (lo, hi) = range(values);
    if !(lo.is_finite() && hi.is_finite()) {
        return Domain { min: 0.0, max: 1.0 };
    }
    let pad = if hi > lo { 0.0 } else { 0.5_f32.max(lo.abs() * 1e-3) };
    Domain {
        min: lo - pad,
        max: hi + pad,
    }
}

/// Narrowest altitude domain kept as it is (1 cm): the layer file writes
/// altitudes to 0.1 mm, so a field flatter than this (a `--height-scale`
/// of 1e-45 makes every height a denormal) would read back as min = max.
const MIN_ALTITUDE_SPAN: f32 = 0.01;

/// The altitude domain of a field whose heights span `(lo, hi)`: that
/// range, or 1 m above `lo` where the field is (nearly) flat.
fn altitude_domain((lo, hi): (f32, f32)) -> Domain {
    Domain {
        min: lo,
        max: if hi - lo >= MIN_ALTITUDE_SPAN { hi } else { lo + 1.0 },
    }
}

/// The distribution functions of every class of `classification`.
pub fn estimate(classification: &Classification, samples: &Samples, bins: usize) -> Distributions {
    let altitude_domain = altitude_domain(samples.altitude_range);
    let slope = slope_domain(&samples.slope);
    let map_domains = samples.maps.clone().map(|m| m.map(|v| (map_domain(&v), v)));
    let classes = (0..classification.classes.len())
        .map(|c| {
            // A class's pixels include those of its level-2 sub-classes.
            let take = |i: usize| {
                let label = usize::from(classification.labels[i]);
                let parent = classification.classes.get(label).and_then(|l| l.parent);
                classification.status[i] == PixelStatus::Counted && (label == c || parent == Some(c))
            };
            ClassFunctions {
                altitude: distribution(&samples.altitude, take, altitude_domain, bins),
                slope: distribution(&samples.slope, take, slope, bins),
                maps: [0, 1, 2].map(|k| {
                    map_domains[k]
                        .as_ref()
                        .map(|(domain, values)| distribution(values, take, *domain, bins))
                }),
            }
        })
        .collect();
    Distributions { classes }
}

/// The name of input map `k` in the layer format.
pub fn map_name(k: usize) -> &'static str {
    INPUT_NAMES.get(k).copied().unwrap_or("input")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_histogram_scaled_to_mean_one_half_and_clamped() {
        // 4 bins over [0, 4): counts 1, 3, 0, 0 → mean 1 → 0.5, 1.5 → clamped 1, 0, 0.
        let values = [0.5, 1.2, 1.5, 1.9, 3.5];
        let f = distribution(&values, |i| i < 4, Domain { min: 0.0, max: 4.0 }, 4);
        assert_eq!(f.samples, vec![0.5, 1.0, 0.0, 0.0]);
        assert_eq!((f.min, f.max), (0.0, 4.0));
        // Nothing taken: all zero.
        assert!(distribution(&values, |_| false, Domain { min: 0.0, max: 4.0 }, 4)
            .samples
            .iter()
            .all(|&s| s == 0.0));
    }

    #[test]
    fn domains() {
        assert_eq!(slope_domain(&[3.0, 31.2]), Domain { min: 0.0, max: 35.0 });
        assert_eq!(slope_domain(&[0.0]), Domain { min: 0.0, max: 5.0 });
        assert_eq!(map_domain(&[2.0, f32::NAN, 7.0]), Domain { min: 2.0, max: 7.0 });
        assert_eq!(altitude_domain((10.0, 250.0)), Domain { min: 10.0, max: 250.0 });
        // Flat, or flatter than the layer file can write (the property
        // test's `layers from-image --height-scale 1e-45`): 1 m wide.
        for hi in [0.0, 1e-45, 0.004] {
            assert_eq!(altitude_domain((0.0, hi)), Domain { min: 0.0, max: 1.0 });
        }
        let flat = map_domain(&[3.0, 3.0]);
        assert!(flat.min < 3.0 && flat.max > 3.0);
    }
}
