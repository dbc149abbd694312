//! What share of the terrain each generated layer will cover, predicted on
//! the CPU, and the calibration of the layers' noise bias to the image's
//! class fractions.
//!
//! §8.3 scales every histogram to mean 0.5 whatever the class's size, so a
//! rare class (a lake) gets the same peak as a common one and, left alone,
//! covers every place that looks like its few pixels (every flat valley
//! floor at the lake's altitude). The text accepts such artefacts of its
//! simple heuristic; here each level-1 layer's coverage-noise bias c_S
//! (with n_S in proportion) is scaled, a few fixed-point steps, until the
//! share of the terrain where it is the dominant layer
//! (`crate::surface::dominant`) matches its class's share of the image
//! — c_S acts as the class's prior. The prediction is the CPU twin of the
//! renderer (`crate::texturing::reference`) at every [`STRIDE`]-th pixel
//! of every [`STRIDE`]-th row of the class map.

use glam::DVec2;

use super::classify::PixelStatus;
use super::tree::GeneratedLayer;
use crate::error::Result;
use crate::io::heightmap::HeightField;
use crate::surface::dominant::dominant_layer;
use crate::surface::layers::{LayerTree, MAX_NOISE_TERM};
use crate::texturing::reference::ReferenceSurface;

/// Image pixels between the points the calibration evaluates, each way.
pub const STRIDE: usize = 8;
/// Fixed-point steps of the calibration (twice as many with level-2
/// layers: on the RMNP pair with `--level2 2` 12 steps left rock at 10.5 %
/// of the terrain for 2.3 % of the image, 24 steps every class within
/// 0.01).
pub const STEPS: usize = 12;
/// Range of c_S the calibration keeps to.
const BIAS_RANGE: (f32, f32) = (0.02, 8.0);

/// Share of `positions` where each layer of `tree` dominates, noise
/// band-limited to `footprint` metres.
pub fn layer_fractions(
    tree: &LayerTree,
    field: &HeightField,
    maps: &[Option<HeightField>; 3],
    positions: &[DVec2],
    footprint: f64,
) -> Result<Vec<f64>> {
    let reference = ReferenceSurface::new(field, tree, maps, crate::surface::wavelet_noise::DEFAULT_NOISE_SEED)?;
    let mut counts = vec![0usize; tree.layers.len()];
    for &xy in positions {
        if let Some(k) = dominant_layer(&reference.evaluate(xy, footprint).coverage) {
            counts[k] += 1;
        }
    }
    let n = positions.len().max(1) as f64;
    Ok(counts.iter().map(|&c| c as f64 / n).collect())
}

/// Every [`STRIDE`]-th pixel position of every [`STRIDE`]-th row, those
/// the mask excludes left out (the class areas are those outside it).
pub fn sample_positions(positions: &[DVec2], width: usize, status: &[PixelStatus]) -> Vec<DVec2> {
    positions
        .iter()
        .enumerate()
        .filter(|(i, _)| (i % width.max(1)) % STRIDE == 0 && (i / width.max(1)) % STRIDE == 0)
        .filter(|(i, _)| status.get(*i) != Some(&PixelStatus::Masked))
        .map(|(_, &p)| p)
        .collect()
}

/// `fractions` with each level-2 layer's share also counted for its
/// parent (the level-1 layer before it): a refined class's area is where
/// it or one of its sub-classes dominates, so the parent's calibration
/// does not fight its children for their area.
pub fn with_children(layers: &[GeneratedLayer], mut fractions: Vec<f64>) -> Vec<f64> {
    let mut parent = 0;
    for (k, layer) in layers.iter().enumerate() {
        if layer.level == 2 {
            fractions[parent] += fractions[k];
        } else {
            parent = k;
        }
    }
    fractions
}

/// Largest absolute difference between `fractions` and `targets`.
fn worst_error(fractions: &[f64], targets: &[f64]) -> f64 {
    fractions
        .iter()
        .zip(targets)
        .map(|(f, t)| (f - t).abs())
        .fold(0.0, f64::max)
}

/// Scales the noise of `layers` (root first) until each layer below the root
/// dominates `targets[k]` of `positions` (module docs; a level-1 layer's
/// share and target include its level-2 children's, [`with_children`]);
/// returns the predicted fractions of the final layers.
///
/// Each layer's c_S is bisected in log space within a bracket that starts
/// at `BIAS_RANGE`: too much area lowers the bracket's top, too little
/// raises its bottom. All layers move at once, so the others' steps shift
/// each layer's answer a little; the brackets widen by 3 % a step to
/// follow. Dominance is nearly a threshold in c_S (the clamped histograms
/// have plateaus), so the steps may end up alternating; the step with the
/// smallest largest error is kept.
pub fn calibrate(
    layers: &mut [GeneratedLayer],
    targets: &[f64],
    build: impl Fn(&[GeneratedLayer]) -> Result<LayerTree>,
    field: &HeightField,
    maps: &[Option<HeightField>; 3],
    positions: &[DVec2],
) -> Result<Vec<f64>> {
    let footprint = field.spacing.min_element();
    let (lowest, highest) = (BIAS_RANGE.0, BIAS_RANGE.1.min(MAX_NOISE_TERM));
    let mut brackets = vec![(lowest, highest); layers.len()];
    let measure = |layers: &[GeneratedLayer]| -> Result<Vec<f64>> {
        let own = layer_fractions(&build(layers)?, field, maps, positions, footprint)?;
        Ok(with_children(layers, own))
    };
    let mut fractions = measure(layers)?;
    let mut best = (worst_error(&fractions, targets), layers.to_vec(), fractions.clone());
    let steps = if layers.iter().any(|l| l.level == 2) {
        2 * STEPS
    } else {
        STEPS
    };
    for _ in 0..steps {
        for (k, layer) in layers.iter_mut().enumerate().skip(1) {
            let (lo, hi) = &mut brackets[k];
            if fractions[k] > targets[k] {
                *hi = layer.noise_bias;
            } else {
                *lo = layer.noise_bias;
            }
            (*lo, *hi) = ((*lo / 1.03).max(lowest), (*hi * 1.03).min(highest));
            let bias = (*lo * *hi).sqrt();
            layer.noise_scale *= bias / layer.noise_bias;
            layer.noise_bias = bias;
        }
        fractions = measure(layers)?;
        let error = worst_error(&fractions, targets);
        if error < best.0 {
            best = (error, layers.to_vec(), fractions.clone());
        }
    }
    layers.clone_from_slice(&best.1);
    Ok(best.2)
}
