//! Clustering in the hue–saturation histogram (§8.3, Fig. 8.12): the text
//! proposes learning vector quantisation, self-organising maps or rules;
//! here it is weighted k-means over the histogram's bins.
//!
//! Decisions:
//! * **Histogram**: [`HUE_BINS`] hue bins of 10° by [`SATURATION_BINS`]
//!   saturation bins of 0.05 by [`VALUE_BINS`] bins of the shade-normalised
//!   value (see below). The hue axis is cut at magenta (300°), a hue no
//!   terrain shows, and scaled so the full circle spans 1 (36° of hue weigh
//!   as much as 0.1 of saturation). Each non-empty bin is a point at its
//!   centre weighted by its pixel count, so the clustering is that of the
//!   pixels, quantised.
//! * **Value**: the text clusters hue and saturation alone. In the Rocky
//!   Mountain image conifer forest (olive) and alpine tundra (tan) share
//!   saturation (0.15–0.35) and nearly share hue (50–80° against 30–50°);
//!   they differ in brightness. So the value, shade-normalised
//!   ([`super::classify`]), is a third axis weighted by
//!   `FromImageOptions::value_weight` (0.5 by default; 0 gives the text's
//!   hue–saturation histogram).
//! * **k-means**: k-means++ seeding from `SplitMix64(seed)`, Lloyd
//!   iterations to convergence (at most 100), the best of [`RESTARTS`]
//!   restarts by weighted inertia: deterministic for a seed.
//! * **Automatic k**: the k of [`super::AUTO_CLASSES`] with the largest
//!   mean silhouette (Rousseeuw 1987), pixel-weighted over the bins; the
//!   smaller k on ties.

use crate::error::{Error, Result};
use crate::random::SplitMix64;

use super::{ClassCount, AUTO_CLASSES};

/// Hue bins (10° each).
pub const HUE_BINS: usize = 36;
/// Saturation bins (0.05 each).
pub const SATURATION_BINS: usize = 20;
/// Bins of the shade-normalised value over [0, 1] (1/16 each).
pub const VALUE_BINS: usize = 16;
/// k-means restarts.
pub const RESTARTS: usize = 8;
/// Where the hue axis is cut (degrees).
const HUE_CUT: f64 = 300.0;

/// Pixel counts over hue × saturation × shade-normalised value.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourHistogram {
    pub counts: Vec<u32>,
    /// Weight of the value axis.
    pub value_weight: f64,
}

type Point = [f64; 3];

/// A point of the clustering space.
fn feature(hue: f64, saturation: f64, value: f64, value_weight: f64) -> Point {
    [
        (hue - HUE_CUT).rem_euclid(360.0) / 360.0,
        saturation,
        value_weight * value.clamp(0.0, 1.0),
    ]
}

fn bin(x: f64, bins: usize) -> usize {
    ((x * bins as f64).max(0.0) as usize).min(bins - 1)
}

impl ColourHistogram {
    pub fn new(value_weight: f64) -> ColourHistogram {
        ColourHistogram {
            counts: vec![0; HUE_BINS * SATURATION_BINS * VALUE_BINS],
            value_weight,
        }
    }

    /// Adds a pixel of `hue` degrees, `saturation` and (shade-normalised) `value` in [0, 1].
    pub fn add(&mut self, hue: f64, saturation: f64, value: f64) {
        let [x, y, _] = feature(hue, saturation, 0.0, 0.0);
        let v = if self.value_weight > 0.0 {
            bin(value, VALUE_BINS)
        } else {
            0
        };
        self.counts[(v * SATURATION_BINS + bin(y, SATURATION_BINS)) * HUE_BINS + bin(x, HUE_BINS)] += 1;
    }

    /// Non-empty bins as (point, weight).
    fn points(&self) -> Vec<(Point, f64)> {
        let centre = |i: usize, n: usize| (i as f64 + 0.5) / n as f64;
        self.counts
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .map(|(i, &c)| {
                let (h, s, v) = (
                    i % HUE_BINS,
                    (i / HUE_BINS) % SATURATION_BINS,
                    i / (HUE_BINS * SATURATION_BINS),
                );
                let value = self.value_weight * centre(v, VALUE_BINS);
                ([centre(h, HUE_BINS), centre(s, SATURATION_BINS), value], f64::from(c))
            })
            .collect()
    }
}

/// The clusters found.
#[derive(Clone, Debug, PartialEq)]
pub struct Clusters {
    /// Centroids as (hue in degrees, saturation, shade-normalised value).
    pub centroids: Vec<(f64, f64, f64)>,
    /// The silhouette of each k tried (automatic choice only).
    pub silhouettes: Vec<(usize, f64)>,
    points: Vec<Point>,
    value_weight: f64,
}

impl Clusters {
    /// Index of the centroid nearest to `hue`, `saturation`, `value`.
    pub fn nearest(&self, hue: f64, saturation: f64, value: f64) -> usize {
        nearest(&self.points, feature(hue, saturation, value, self.value_weight)).0
    }
}

fn distance2(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

/// Index of and squared distance to the centre nearest `p` (first on ties).
fn nearest(centres: &[Point], p: Point) -> (usize, f64) {
    centres
        .iter()
        .enumerate()
        .map(|(i, &c)| (i, distance2(c, p)))
        .fold((0, f64::INFINITY), |best, x| if x.1 < best.1 { x } else { best })
}

/// Weighted k-means++ seeding.
fn seed_centres(points: &[(Point, f64)], k: usize, rng: &mut SplitMix64) -> Vec<Point> {
    let total: f64 = points.iter().map(|p| p.1).sum();
    let mut pick = rng.next_f64() * total;
    let first = points.iter().position(|p| {
        pick -= p.1;
        pick < 0.0
    });
    let mut centres = vec![points[first.unwrap_or(points.len() - 1)].0];
    while centres.len() < k {
        let d: Vec<f64> = points.iter().map(|(p, w)| w * nearest(&centres, *p).1).collect();
        let sum: f64 = d.iter().sum();
        if sum <= 0.0 {
            break;
        }
        let mut pick = rng.next_f64() * sum;
        let i = d.iter().position(|&x| {
            pick -= x;
            pick < 0.0
        });
        centres.push(points[i.unwrap_or(points.len() - 1)].0);
    }
    centres
}

/// Lloyd iterations from `centres`; returns the centres and the weighted inertia.
fn lloyd(points: &[(Point, f64)], mut centres: Vec<Point>) -> (Vec<Point>, f64) {
    for _ in 0..100 {
        let mut sums = vec![([0.0; 3], 0.0); centres.len()];
        for (p, w) in points {
            let s = &mut sums[nearest(&centres, *p).0];
            for (a, x) in s.0.iter_mut().zip(p) {
                *a += w * x;
            }
            s.1 += w;
        }
        let next: Vec<Point> = sums
            .iter()
            .zip(&centres)
            .map(|(s, c)| if s.1 > 0.0 { s.0.map(|a| a / s.1) } else { *c })
            .collect();
        let moved = next.iter().zip(&centres).any(|(a, b)| distance2(*a, *b) > 1e-14);
        centres = next;
        if !moved {
            break;
        }
    }
    let inertia = points.iter().map(|(p, w)| w * nearest(&centres, *p).1).sum();
    (centres, inertia)
}

/// The best of [`RESTARTS`] k-means runs.
fn kmeans(points: &[(Point, f64)], k: usize, seed: u64) -> Vec<Point> {
    let mut rng = SplitMix64(seed);
    let mut best: Option<(Vec<Point>, f64)> = None;
    for _ in 0..RESTARTS {
        let run = lloyd(points, seed_centres(points, k, &mut rng));
        if best.as_ref().map_or(true, |b| run.1 < b.1) {
            best = Some(run);
        }
    }
    best.map(|b| b.0).unwrap_or_default()
}

/// Mean silhouette of the clustering by `centres`, pixel-weighted.
pub fn silhouette(points: &[(Point, f64)], centres: &[Point]) -> f64 {
    let labels: Vec<usize> = points.iter().map(|(p, _)| nearest(centres, *p).0).collect();
    let mut weight = vec![0.0; centres.len()];
    for ((_, w), &l) in points.iter().zip(&labels) {
        weight[l] += w;
    }
    let (mut sum, mut total) = (0.0, 0.0);
    for (i, (p, w)) in points.iter().enumerate() {
        let mut mean = vec![0.0; centres.len()];
        for ((q, v), &l) in points.iter().zip(&labels) {
            mean[l] += v * distance2(*p, *q).sqrt();
        }
        let own = labels[i];
        let s = if weight[own] <= 1.0 {
            0.0
        } else {
            let a = mean[own] / (weight[own] - 1.0);
            let b = (0..centres.len())
                .filter(|&c| c != own && weight[c] > 0.0)
                .map(|c| mean[c] / weight[c])
                .fold(f64::INFINITY, f64::min);
            if b.is_finite() && a.max(b) > 0.0 {
                (b - a) / a.max(b)
            } else {
                0.0
            }
        };
        sum += w * s;
        total += w;
    }
    if total > 0.0 {
        sum / total
    } else {
        0.0
    }
}

/// Clusters `histogram` into `count` classes (module docs).
pub fn cluster(histogram: &ColourHistogram, count: ClassCount, seed: u64) -> Result<Clusters> {
    let points = histogram.points();
    let distinct = points.len();
    let (centres, silhouettes) = match count {
        _ if distinct == 0 => (Vec::new(), Vec::new()),
        ClassCount::Fixed(k) if k > distinct => {
            return Err(Error::invalid(
                "from_image.classes",
                format!("{k} classes but the image's colours fill only {distinct} hue–saturation bins"),
            ))
        }
        ClassCount::Fixed(k) => (kmeans(&points, k, seed), Vec::new()),
        ClassCount::Auto => {
            let mut tried = Vec::new();
            let mut best: Option<(Vec<Point>, f64)> = None;
            for k in AUTO_CLASSES.filter(|&k| k <= distinct) {
                let centres = kmeans(&points, k, seed);
                let s = silhouette(&points, &centres);
                tried.push((k, s));
                if best.as_ref().map_or(true, |b| s > b.1) {
                    best = Some((centres, s));
                }
            }
            let centres = best.map(|b| b.0).unwrap_or_else(|| kmeans(&points, 1, seed));
            (centres, tried)
        }
    };
    Ok(Clusters {
        centroids: centres
            .iter()
            .map(|c| {
                let value = if histogram.value_weight > 0.0 {
                    c[2] / histogram.value_weight
                } else {
                    0.0
                };
                ((c[0] * 360.0 + HUE_CUT).rem_euclid(360.0), c[1], value)
            })
            .collect(),
        silhouettes,
        points: centres,
        value_weight: histogram.value_weight,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tan, olive and blue blobs; the first two of equal hue and
    /// saturation and different value.
    fn three_blobs(value_weight: f64) -> ColourHistogram {
        let mut h = ColourHistogram::new(value_weight);
        let mut rng = SplitMix64(3);
        for (hue, sat, value, n) in [(35.0, 0.3, 0.7, 3000), (45.0, 0.3, 0.2, 2000), (220.0, 0.8, 0.1, 300)] {
            for _ in 0..n {
                let jitter = |rng: &mut SplitMix64, w: f64| w * (rng.next_f64() - 0.5);
                h.add(
                    hue + jitter(&mut rng, 8.0),
                    sat + jitter(&mut rng, 0.06),
                    value + jitter(&mut rng, 0.1),
                );
            }
        }
        h
    }

    #[test]
    fn three_blobs_give_three_clusters_automatically() {
        let clusters = cluster(&three_blobs(0.5), ClassCount::Auto, 1).unwrap();
        assert_eq!(clusters.centroids.len(), 3, "{:?}", clusters.silhouettes);
        for (hue, sat, value) in [(35.0, 0.3, 0.7), (45.0, 0.3, 0.2), (220.0, 0.8, 0.1)] {
            let c = clusters.centroids[clusters.nearest(hue, sat, value)];
            let near = (c.0 - hue).abs() < 5.0 && (c.1 - sat).abs() < 0.03 && (c.2 - value).abs() < 0.05;
            assert!(near, "{c:?} for {hue}, {sat}, {value}");
        }
        // Deterministic for a seed.
        assert_eq!(clusters, cluster(&three_blobs(0.5), ClassCount::Auto, 1).unwrap());
        // Hue and saturation alone (the text's histogram) cannot tell the first two apart.
        let plain = cluster(&three_blobs(0.0), ClassCount::Fixed(2), 1).unwrap();
        assert_eq!(plain.nearest(35.0, 0.3, 0.7), plain.nearest(45.0, 0.3, 0.2));
        assert_ne!(plain.nearest(35.0, 0.3, 0.7), plain.nearest(220.0, 0.8, 0.1));
    }

    #[test]
    fn fixed_k_and_its_limit() {
        assert_eq!(
            cluster(&three_blobs(0.5), ClassCount::Fixed(2), 1)
                .unwrap()
                .centroids
                .len(),
            2
        );
        let mut one = ColourHistogram::new(0.5);
        one.add(10.0, 0.5, 0.5);
        assert!(cluster(&one, ClassCount::Fixed(2), 1).is_err());
        assert!(cluster(&ColourHistogram::new(0.5), ClassCount::Auto, 1)
            .unwrap()
            .centroids
            .is_empty());
    }
}
