//! Classification of the image's pixels into surface types (§8.3,
//! "Surface Type Classification"): RGB and HSV together, near-grey pixels
//! in reserved classes, the chromatic ones clustered by `super::kmeans`
//! in the hue–saturation histogram.
//!
//! Decisions where the text leaves room:
//! * **HSV** of the image's sRGB-encoded values (the colours the text
//!   converts), hue in degrees, saturation `(max − min) / max`.
//! * **Near grey** (identified in RGB as the text does): `max − min ≤`
//!   [`GREY_SATURATION`]`· max` with `max ≥` [`GREY_MIN_VALUE`]. Instead of
//!   the text's reserved violet hue they go straight to two reserved
//!   classes, split by brightness as the hue–saturation plane cannot:
//!   **snow** ([`ClassKind::White`]) where the shade-normalised value
//!   `V / clamp(R, 0.4, 1.5)` (R: [`super::shading`]) reaches
//!   [`SNOW_VALUE`], **rock** ([`ClassKind::Grey`]) otherwise. Dark greys
//!   stay chromatic: their hue decides (forest, water).
//! * **Shade** (the image's baked-in light): a pixel darker than
//!   [`DARK_VALUE`] where the modelled direct light R is below
//!   [`SHADE_LIGHT`] (a wall facing away from the sun or in cast shadow)
//!   shows no reliable colour. It is set aside ([`PixelStatus::Shade`]):
//!   not clustered, not counted in the colours and distributions, and in
//!   the class map given the class of the nearest counted pixel (4-connected
//!   breadth-first fill, a shade-invariant choice: the wall is what
//!   surrounds it). Lakes are flat, fully lit and keep their class.
//! * **Cloud** (§8.3.2): snow below the minimum altitude is set aside the
//!   same way ([`PixelStatus::Cloud`]).
//! * **Excluded** (§8.3.2: the text leaves the land cultivated by humans
//!   out of the distribution functions): pixels under the `--mask`
//!   ([`PixelStatus::Masked`]) are neither clustered nor counted, and are
//!   left out of the class areas ([`Classification::fractions`]); the class
//!   map fills them like shade.

use std::collections::VecDeque;

use glam::Vec3;
use image::RgbImage;

use super::kmeans::{cluster, ColourHistogram};
use super::{FromImageOptions, Registration};
use crate::error::{Error, Result};

/// Largest `(max − min) / max` of a near-grey pixel.
pub const GREY_SATURATION: f64 = 0.10;
/// Darker pixels are never grey (their hue decides).
pub const GREY_MIN_VALUE: f64 = 0.30;
/// Shade-normalised value from which a grey pixel is snow.
pub const SNOW_VALUE: f64 = 0.90;
/// Pixels with modelled direct light below this (relative to flat ground)…
pub const SHADE_LIGHT: f32 = 0.35;
/// …and value below this are shade.
pub const DARK_VALUE: f64 = 0.22;

/// What a class is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClassKind {
    /// A k-means cluster of the hue–saturation histogram.
    Chromatic,
    /// Reserved: near grey, not snow (rock).
    Grey,
    /// Reserved: near grey and bright (snow).
    White,
}

/// Whether a pixel counts in the statistics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelStatus {
    Counted,
    /// Dark in modelled shadow (module docs).
    Shade,
    /// Snow below the minimum altitude.
    Cloud,
    /// Excluded by the mask (module docs).
    Masked,
}

/// One surface type.
#[derive(Clone, Debug, PartialEq)]
pub struct Class {
    pub kind: ClassKind,
    /// A name from the kind and mean colour (snow, rock, water, forest, …).
    pub name: String,
    /// Hue (degrees), saturation and shade-normalised value of the
    /// k-means centroid (chromatic).
    pub centroid: Option<(f64, f64, f64)>,
    /// Mean colour of its counted pixels, linear.
    pub linear: Vec3,
    /// Counted pixels.
    pub counted: usize,
    /// Pixels of the class map (set-aside pixels filled in, masked ones not).
    pub pixels: usize,
    /// The class this one is a level-2 sub-class of (`super::level2`).
    pub parent: Option<usize>,
}

/// The image's classification.
#[derive(Clone, Debug, PartialEq)]
pub struct Classification {
    pub registration: Registration,
    pub classes: Vec<Class>,
    /// Class per pixel, row-major from image row 0, set-aside pixels filled.
    pub labels: Vec<u8>,
    pub status: Vec<PixelStatus>,
    /// The chromatic classes' count and, for the automatic choice, the
    /// silhouette of each k tried.
    pub k: usize,
    pub silhouettes: Vec<(usize, f64)>,
}

impl Classification {
    /// Share of the image outside the mask each class covers in the class map.
    pub fn fractions(&self) -> Vec<f64> {
        let n = (self.labels.len() - self.count(PixelStatus::Masked)).max(1) as f64;
        self.classes.iter().map(|c| c.pixels as f64 / n).collect()
    }

    /// Pixels with `status`.
    pub fn count(&self, status: PixelStatus) -> usize {
        self.status.iter().filter(|&&s| s == status).count()
    }
}

/// Hue (degrees), saturation and value of an sRGB-encoded pixel.
pub fn hsv(pixel: [u8; 3]) -> (f64, f64, f64) {
    let [r, g, b] = pixel.map(|c| f64::from(c) / 255.0);
    let max = r.max(g).max(b);
    let chroma = max - r.min(g).min(b);
    let hue = if chroma <= 0.0 {
        0.0
    } else if max == r {
        60.0 * ((g - b) / chroma).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / chroma + 2.0)
    } else {
        60.0 * ((r - g) / chroma + 4.0)
    };
    (hue, if max > 0.0 { chroma / max } else { 0.0 }, max)
}

/// sRGB code value → linear.
pub fn srgb_to_linear(c: u8) -> f32 {
    let s = f32::from(c) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// The first pass's verdict on a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    Chromatic,
    Grey,
    White,
    Shade,
    Masked,
}

/// The value `V / clamp(R, 0.4, 1.5)` of a pixel of value `v` under modelled light `light`.
pub fn shade_normalised(v: f64, light: f32) -> f64 {
    v / f64::from(light.clamp(0.4, 1.5))
}

fn verdict(pixel: [u8; 3], light: f32, shade_handling: bool) -> Verdict {
    let (_, s, v) = hsv(pixel);
    if shade_handling && light < SHADE_LIGHT && v < DARK_VALUE {
        return Verdict::Shade;
    }
    if s <= GREY_SATURATION && v >= GREY_MIN_VALUE {
        return if shade_normalised(v, light) >= SNOW_VALUE {
            Verdict::White
        } else {
            Verdict::Grey
        };
    }
    Verdict::Chromatic
}

/// Classifies every pixel (module docs). `light` is R per pixel,
/// `altitude` the surface height per pixel (metres).
pub fn classify(
    image: &RgbImage,
    registration: &Registration,
    light: &[f32],
    altitude: &[f32],
    snow_min_altitude: f32,
    options: &FromImageOptions,
) -> Result<Classification> {
    let pixels: Vec<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    let excluded = |i: usize| options.exclude.as_ref().is_some_and(|m| m[i]);
    let verdicts: Vec<Verdict> = (pixels.iter().zip(light).enumerate())
        .map(|(i, (&p, &l))| {
            if excluded(i) {
                Verdict::Masked
            } else {
                verdict(p, l, options.shade_handling)
            }
        })
        .collect();
    let mut histogram = ColourHistogram::new(options.value_weight);
    for ((p, v), &l) in pixels.iter().zip(&verdicts).zip(light) {
        if *v == Verdict::Chromatic {
            let (h, s, value) = hsv(*p);
            histogram.add(h, s, shade_normalised(value, l));
        }
    }
    let clusters = cluster(&histogram, options.classes, options.seed)?;
    // Classes: the chromatic clusters, then the reserved grey and white ones present.
    let mut kinds: Vec<ClassKind> = vec![ClassKind::Chromatic; clusters.centroids.len()];
    let grey = verdicts.contains(&Verdict::Grey).then(|| {
        kinds.push(ClassKind::Grey);
        kinds.len() - 1
    });
    let white = verdicts.contains(&Verdict::White).then(|| {
        kinds.push(ClassKind::White);
        kinds.len() - 1
    });
    let mut labels = vec![u8::MAX; pixels.len()];
    let mut status = vec![PixelStatus::Counted; pixels.len()];
    for (i, (p, v)) in pixels.iter().zip(&verdicts).enumerate() {
        let class = match v {
            Verdict::Shade => {
                status[i] = PixelStatus::Shade;
                continue;
            }
            Verdict::Masked => {
                status[i] = PixelStatus::Masked;
                continue;
            }
            Verdict::Chromatic => {
                let (h, s, value) = hsv(*p);
                clusters.nearest(h, s, shade_normalised(value, light[i]))
            }
            Verdict::Grey => grey.unwrap_or(0),
            Verdict::White => {
                if altitude.get(i).is_some_and(|&a| a < snow_min_altitude) {
                    status[i] = PixelStatus::Cloud;
                    continue;
                }
                white.unwrap_or(0)
            }
        };
        labels[i] = class as u8;
    }
    fill_set_aside(&mut labels, registration.width as usize)?;
    let parents = vec![None; kinds.len()];
    let classes = summarise(&kinds, &parents, &clusters.centroids, &pixels, &labels, &status);
    Ok(Classification {
        registration: *registration,
        classes,
        labels,
        status,
        k: clusters.centroids.len(),
        silhouettes: clusters.silhouettes,
    })
}

/// Gives each unlabelled pixel the label of the nearest labelled one
/// (4-connected breadth-first, row-major order among equals).
fn fill_set_aside(labels: &mut [u8], width: usize) -> Result<()> {
    let mut queue: VecDeque<usize> = (0..labels.len()).filter(|&i| labels[i] != u8::MAX).collect();
    if queue.is_empty() {
        return Err(Error::invalid(
            "from_image.image",
            "no pixel could be classified (all in shade or cloud)",
        ));
    }
    let height = labels.len() / width.max(1);
    while let Some(i) = queue.pop_front() {
        let (x, y) = (i % width, i / width);
        let neighbours = [
            (x > 0).then(|| i - 1),
            (x + 1 < width).then(|| i + 1),
            (y > 0).then(|| i - width),
            (y + 1 < height).then(|| i + width),
        ];
        for n in neighbours.into_iter().flatten() {
            if labels[n] == u8::MAX {
                labels[n] = labels[i];
                queue.push_back(n);
            }
        }
    }
    Ok(())
}

/// Counts, mean colours and names of the classes; a sub-class is named
/// after its parent (`forest.2`: the parent keeps its largest sub-class).
pub fn summarise(
    kinds: &[ClassKind],
    parents: &[Option<usize>],
    centroids: &[(f64, f64, f64)],
    pixels: &[[u8; 3]],
    labels: &[u8],
    status: &[PixelStatus],
) -> Vec<Class> {
    let mut sums = vec![(Vec3::ZERO, 0usize, 0usize); kinds.len()];
    for ((p, &l), s) in pixels.iter().zip(labels).zip(status) {
        let Some(entry) = sums.get_mut(usize::from(l)) else {
            continue;
        };
        if *s != PixelStatus::Masked {
            entry.2 += 1;
        }
        if *s == PixelStatus::Counted {
            entry.0 += Vec3::from(p.map(srgb_to_linear));
            entry.1 += 1;
        }
    }
    let mut names: Vec<String> = Vec::new();
    kinds
        .iter()
        .zip(sums)
        .enumerate()
        .map(|(k, (&kind, (sum, counted, total)))| {
            let linear = sum / counted.max(1) as f32;
            let parent = parents.get(k).copied().flatten();
            let name = if let Some(p) = parent {
                let siblings = parents[..k].iter().filter(|&&q| q == Some(p)).count();
                format!("{}.{}", names.get(p).map_or("class", |n| n.as_str()), siblings + 2)
            } else {
                let base = class_name(kind, linear);
                let same = names.iter().filter(|n| n.split(' ').next() == Some(base)).count();
                if same == 0 {
                    base.to_string()
                } else {
                    format!("{base} {}", same + 1)
                }
            };
            names.push(name.clone());
            Class {
                kind,
                name,
                centroid: centroids.get(k).copied(),
                linear,
                counted,
                pixels: total,
                parent,
            }
        })
        .collect()
}

/// A descriptive name from the kind and the mean colour's hue and value.
fn class_name(kind: ClassKind, linear: Vec3) -> &'static str {
    match kind {
        ClassKind::White => return "snow",
        ClassKind::Grey => return "rock",
        ClassKind::Chromatic => {}
    }
    let srgb = crate::texturing::reference::srgb8(linear);
    let (h, s, v) = hsv(srgb);
    match h {
        _ if s < 0.12 => "rock",
        h if (170.0..270.0).contains(&h) => "water",
        h if (50.0..170.0).contains(&h) && v < 0.4 => "forest",
        h if (50.0..170.0).contains(&h) => "grass",
        _ => "bare",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hsv_of_primaries_and_grey() {
        assert_eq!(hsv([255, 0, 0]), (0.0, 1.0, 1.0));
        assert_eq!(hsv([0, 255, 0]).0, 120.0);
        assert_eq!(hsv([0, 0, 255]).0, 240.0);
        assert_eq!(hsv([255, 0, 255]).0, 300.0);
        assert_eq!(hsv([128, 128, 128]).1, 0.0);
        assert_eq!(hsv([0, 0, 0]), (0.0, 0.0, 0.0));
    }

    #[test]
    fn verdicts_follow_grey_snow_and_shade_rules() {
        assert_eq!(verdict([240, 240, 236], 1.0, true), Verdict::White);
        assert_eq!(verdict([150, 148, 140], 1.0, true), Verdict::Grey);
        // Snow in shade is still snow; grey rock on a sunlit wall is not.
        assert_eq!(verdict([150, 150, 152], 0.3, true), Verdict::White);
        assert_eq!(verdict([240, 240, 236], 1.5, true), Verdict::Grey);
        // Dark and in modelled shade: set aside, unless shade handling is off.
        assert_eq!(verdict([10, 20, 40], 0.1, true), Verdict::Shade);
        assert_eq!(verdict([10, 20, 40], 0.1, false), Verdict::Chromatic);
        // A dark lake in full light stays chromatic.
        assert_eq!(verdict([7, 13, 29], 1.0, true), Verdict::Chromatic);
        // Dark grey is chromatic (its hue decides).
        assert_eq!(verdict([40, 40, 41], 1.0, true), Verdict::Chromatic);
    }

    #[test]
    fn the_fill_takes_the_nearest_label() {
        let x = u8::MAX;
        let mut labels = vec![0, x, x, x, 1, x, x, x, x];
        fill_set_aside(&mut labels, 3).unwrap();
        assert_eq!(labels, vec![0, 0, 0, 0, 1, 1, 0, 1, 1]);
        assert!(fill_set_aside(&mut [x, x], 2).is_err());
    }
}
