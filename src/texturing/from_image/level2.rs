//! Level-2 layers (§8.3, "Surface Layer Hierarchy"): "we assign child
//! nodes to those level-1 nodes which represent larger clusters in the
//! histogram (e.g. the vegetation cluster). These nodes are created with
//! slightly, arbitrary modified distribution functions and other colors
//! from within the HSV cluster."
//!
//! The text leaves the children's colours and functions arbitrary; here
//! they are measured, by a second clustering inside the class:
//! * **Which classes**: the chromatic level-1 classes (not the root, not
//!   the reserved rock and snow, which are no histogram clusters) with at
//!   least [`MIN_SHARE`] of the counted pixels.
//! * **Sub-classes**: k-means with k = `FromImageOptions::level2` over the
//!   class's own counted pixels in the same hue × saturation ×
//!   shade-normalised value histogram as level 1 (`super::kmeans`, same
//!   seed). A class whose pixels fill fewer bins than k stays whole.
//! * **Tree**: as level 1 mirrors the root, the class keeps the colour of
//!   its largest sub-class and its own (whole-class) distribution
//!   functions; every other sub-class becomes a child of it with the
//!   sub-class's mean colour and distribution functions (the histograms
//!   where that sub-class occurs, `super::distributions`). The child's
//!   coverage is multiplied by the parent's (§8.2), so it only refines
//!   where the class lies.
//! * Shade pixels filled with the class keep the parent's label.

use image::RgbImage;

use super::classify::{hsv, shade_normalised, summarise, ClassKind, Classification, PixelStatus};
use super::kmeans::{cluster, ColourHistogram};
use super::ClassCount;

/// Smallest share of the counted pixels a class needs to be refined.
pub const MIN_SHARE: f64 = 0.10;
/// Most sub-classes per class (`--level2`).
pub const MAX_SUBCLASSES: usize = 4;

/// Splits the larger chromatic level-1 classes of `classification` into
/// `k` sub-classes each (module docs); `light` is the modelled light per
/// pixel, `value_weight` and `seed` those of level 1.
pub fn refine(
    classification: &mut Classification,
    image: &RgbImage,
    light: &[f32],
    k: usize,
    value_weight: f64,
    seed: u64,
) {
    let c = classification;
    let total: usize = c.classes.iter().map(|class| class.counted).sum();
    let root = (0..c.classes.len()).max_by_key(|&i| (c.classes[i].counted, std::cmp::Reverse(i)));
    let mut kinds: Vec<ClassKind> = c.classes.iter().map(|class| class.kind).collect();
    let mut parents: Vec<Option<usize>> = vec![None; kinds.len()];
    let pixels: Vec<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    let feature = |i: usize| {
        let (h, s, v) = hsv(pixels[i]);
        (h, s, shade_normalised(v, light[i]))
    };
    for class in 0..c.classes.len() {
        let eligible = Some(class) != root
            && c.classes[class].kind == ClassKind::Chromatic
            && c.classes[class].counted as f64 >= MIN_SHARE * total as f64;
        if !eligible {
            continue;
        }
        let members: Vec<usize> = (0..c.labels.len())
            .filter(|&i| usize::from(c.labels[i]) == class && c.status[i] == PixelStatus::Counted)
            .collect();
        let mut histogram = ColourHistogram::new(value_weight);
        for &i in &members {
            let (h, s, v) = feature(i);
            histogram.add(h, s, v);
        }
        let Ok(clusters) = cluster(&histogram, ClassCount::Fixed(k), seed) else {
            continue;
        };
        let sub: Vec<usize> = (members.iter())
            .map(|&i| {
                let (h, s, v) = feature(i);
                clusters.nearest(h, s, v)
            })
            .collect();
        let mut counts = vec![0usize; clusters.centroids.len()];
        for &s in &sub {
            counts[s] += 1;
        }
        let largest = (0..counts.len()).max_by_key(|&s| (counts[s], std::cmp::Reverse(s)));
        // The other non-empty sub-classes, most pixels first, as new classes.
        let mut others: Vec<usize> = (0..counts.len())
            .filter(|&s| Some(s) != largest && counts[s] > 0)
            .collect();
        others.sort_by_key(|&s| (std::cmp::Reverse(counts[s]), s));
        let mut label_of = vec![class as u8; counts.len()];
        for s in others {
            label_of[s] = kinds.len() as u8;
            kinds.push(ClassKind::Chromatic);
            parents.push(Some(class));
        }
        for (&i, &s) in members.iter().zip(&sub) {
            c.labels[i] = label_of[s];
        }
    }
    if kinds.len() == c.classes.len() {
        return;
    }
    let centroids: Vec<(f64, f64, f64)> = c.classes.iter().filter_map(|class| class.centroid).collect();
    c.classes = summarise(&kinds, &parents, &centroids, &pixels, &c.labels, &c.status);
}
#[cfg(test)]
mod tests;
