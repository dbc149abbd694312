//! The λ sweep of dissertation §7.3.3, Fig. 7.4 ("height field synthesis
//! with increasing weights for the derivatives; first: no derivatives at
//! all, last: only derivatives, no height criterion"): free growths of
//! the 128² Jacksboro crop of `super::fill` at λ = 0, 0.25, 4 and +∞
//! (`alpenglow synth grow --lambda L`, `inf` for slopes only), CPU search.
//!
//! Each growth is measured against the exemplar, an independent
//! reference the growth never sees as a target: the Kolmogorov–Smirnov
//! statistics of its slopes, curvatures (5-point Laplacian) and heights,
//! the share of its heights outside the exemplar's range and its RMS
//! curvature over the exemplar's. What the sweep shows, and the test
//! asserts (measured values in docs/FIGURES.md, row 7.4):
//!
//! * the RMS curvature falls strictly as λ rises (×1.74, 1.54, 1.28,
//!   1.00 of the exemplar's) and the curvature KS statistic falls from
//!   λ = 0 to 0.25 to 4: without the derivatives the field is rough, the
//!   text's "noisy artifacts" in the lit terrain;
//! * without a height criterion (λ = +∞) the heights drift out of the
//!   exemplar's range (26 % of the samples; none at finite λ): the
//!   text's "ignoring height information completely results in very
//!   severe errors".
//!
//! The slope and height KS statistics of a single 48² growth do not order
//! with λ (they are printed, not asserted).
//!
//! With `ALPENGLOW_DUMP=DIR` the heights (grey, the exemplar's range) and
//! hillshades of a 48² exemplar crop and of each growth are written as
//! `N-lambda-heights.png` and `N-lambda-hillshade.png` (one column each).

use super::fill::{crop, hillshade, ks, slope_curvature};
use super::free::{heights, interior, slopes};
use crate::io::heightmap::HeightField;
use crate::synthesis::fill::FillParams;
use crate::synthesis::free::{grow_free_cpu, FREE_GROWTH};
use crate::test_support::side_by_side;

/// Side of the grown fields.
const OUT: u32 = 48;
/// The sweep, in increasing weight of the derivatives.
const LAMBDAS: [f32; 4] = [0.0, 0.25, 4.0, f32::INFINITY];

fn curvatures(f: &HeightField) -> Vec<f64> {
    interior(f).map(|(c, r)| slope_curvature(f, c, r).1).collect()
}

/// (slope KS, curvature KS, height KS, share of heights outside the
/// exemplar's range, RMS curvature over the exemplar's) of `out`.
fn statistics(out: &HeightField, exemplar: &HeightField) -> [f64; 5] {
    let (lo, hi) = exemplar.min_max();
    let outside = out.heights.iter().filter(|&&h| h < lo || h > hi).count() as f64 / out.heights.len() as f64;
    let rms = |v: Vec<f64>| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    [
        ks(slopes(out), slopes(exemplar)),
        ks(curvatures(out), curvatures(exemplar)),
        ks(heights(out), heights(exemplar)),
        outside,
        rms(curvatures(out)) / rms(curvatures(exemplar)),
    ]
}

/// Grey heights of `f`, black at `lo` and white at `hi`, as RGBA.
fn grey(f: &HeightField, lo: f32, hi: f32) -> Vec<u8> {
    f.heights
        .iter()
        .flat_map(|&h| {
            let v = ((h - lo) / (hi - lo) * 255.0).clamp(0.0, 255.0) as u8;
            [v, v, v, 255]
        })
        .collect()
}

#[test]
fn derivative_weight_trades_relief_for_heights() {
    let exemplar = crop();
    let fields: Vec<HeightField> = LAMBDAS
        .iter()
        .map(|&lambda| {
            let params = FillParams {
                lambda,
                candidates: 2048,
                ..FREE_GROWTH
            };
            grow_free_cpu(&exemplar, OUT, OUT, &params, &mut |_, _| {}).unwrap()
        })
        .collect();
    let stats: Vec<[f64; 5]> = fields.iter().map(|f| statistics(f, &exemplar)).collect();
    for (lambda, [slope, curvature, height, outside, roughness]) in LAMBDAS.iter().zip(&stats) {
        eprintln!(
            "λ {lambda}: KS slope {slope:.3}, curvature {curvature:.3}, height {height:.3}; \
             {outside:.3} outside the exemplar's heights; RMS curvature ×{roughness:.2}"
        );
    }

    let piece = HeightField::from_fn(OUT, OUT, exemplar.spacing, |c, r| exemplar.height(c + 30, r + 40));
    let (lo, hi) = exemplar
        .heights
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
            (lo.min(h), hi.max(h))
        });
    let columns: Vec<&HeightField> = std::iter::once(&piece).chain(&fields).collect();
    let width = OUT * columns.len() as u32;
    let greys: Vec<Vec<u8>> = columns.iter().map(|f| grey(f, lo, hi)).collect();
    let shades: Vec<Vec<u8>> = columns.iter().map(|f| hillshade(f)).collect();
    crate::test_support::dump_pngs(&[("lambda-heights", &side_by_side(&greys, OUT))], width, OUT);
    crate::test_support::dump_pngs(&[("lambda-hillshade", &side_by_side(&shades, OUT))], width, OUT);

    let [none, low, high, only] = [&stats[0], &stats[1], &stats[2], &stats[3]];
    assert!(
        low[1] < none[1] && high[1] < low[1],
        "the curvature KS falls as λ rises: {:.3} {:.3} {:.3}",
        none[1],
        low[1],
        high[1]
    );
    assert!(
        stats.windows(2).all(|w| w[1][4] < w[0][4]),
        "the RMS curvature (noise in the lit field) falls as λ rises: {:?}",
        stats.iter().map(|s| s[4]).collect::<Vec<_>>()
    );
    let worst_outside = stats[..3].iter().map(|s| s[3]).fold(0.0, f64::max);
    assert!(
        only[3] > 0.1 && only[3] > 5.0 * worst_outside,
        "without a height criterion the heights leave the exemplar's range: {} vs {worst_outside}",
        only[3]
    );
}
