//! Free synthesis (dissertation §7.3, Fig. 7.1; `synthesis::free`): a new
//! 64² field grown from the 128² Jacksboro crop of `super::fill` alone,
//! with the CPU search.
//!
//! Criteria (README "Height-field synthesis"), each checked against the
//! exemplar, an independent reference the growth never sees as a target:
//!
//! * **Statistics** (interior samples): Kolmogorov–Smirnov statistic of
//!   the slopes at most `ks_slope`, of the heights at most
//!   `ks_height` (a 64² field covers a quarter of the exemplar's area,
//!   so its height range is narrower); the mean squared height difference
//!   at lags 1, 2, 4 and 8 samples (the variogram, the spectrum's energy
//!   above each band) within a factor `variogram` of the
//!   exemplar's.
//! * **Not a copy**: of the 16² windows of the output (stride 8), at most
//!   `copied_share` match any exemplar window to within an RMS of
//!   `copy_rms` of the exemplar's height deviation (after removing the
//!   mean difference, as pasting adds offsets).
//! * The criteria can fail: a 64² crop of the exemplar passes the
//!   statistics and fails the copy check; the exemplar's heights shuffled
//!   fail the slope and variogram checks.
//! * The same seed gives the same field, another seed another one.
//!
//! The exemplar's and the output's hillshades are written side by side to
//! `target/tmp/synthesis-free-hillshade.png` for a look.

use glam::DVec2;

use super::fill::{crop, hillshade, ks, slope_curvature};
use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::synthesis::fill::FillParams;
use crate::synthesis::free::{grow_free_cpu, plan_free_growth, FREE_GROWTH};

/// Side of the grown field.
const OUT: u32 = 64;
/// The bounds of the module docs.
struct Bounds {
    ks_slope: f64,
    ks_height: f64,
    /// Largest ratio of the variograms, either way.
    variogram: f64,
    copied_share: f64,
    /// A window is copied below this RMS, in exemplar height deviations.
    copy_rms: f64,
}

const BOUNDS: Bounds = Bounds {
    ks_slope: 0.25,
    ks_height: 0.35,
    variogram: 2.0,
    copied_share: 0.25,
    copy_rms: 0.02,
};

/// The growth's defaults (`FREE_GROWTH`: one sample a wave) with `seed`
/// and at most 2048 candidates (of 14884), to keep the unoptimised build
/// within seconds.
fn params(seed: u32) -> FillParams {
    FillParams {
        seed,
        candidates: 2048,
        ..FREE_GROWTH
    }
}

pub(super) fn interior(f: &HeightField) -> impl Iterator<Item = (u32, u32)> + '_ {
    (1..f.rows - 1).flat_map(move |r| (1..f.columns - 1).map(move |c| (c, r)))
}

pub(super) fn slopes(f: &HeightField) -> Vec<f64> {
    interior(f).map(|(c, r)| slope_curvature(f, c, r).0).collect()
}

pub(super) fn heights(f: &HeightField) -> Vec<f64> {
    f.heights.iter().map(|&h| f64::from(h)).collect()
}

/// Mean squared height difference at `lag` samples, along x and y.
fn variogram(f: &HeightField, lag: u32) -> f64 {
    let (mut sum, mut n) = (0.0, 0.0);
    for r in 0..f.rows {
        for c in 0..f.columns {
            let h = f64::from(f.height(c, r));
            if c + lag < f.columns {
                sum += (f64::from(f.height(c + lag, r)) - h).powi(2);
                n += 1.0;
            }
            if r + lag < f.rows {
                sum += (f64::from(f.height(c, r + lag)) - h).powi(2);
                n += 1.0;
            }
        }
    }
    sum / n
}

/// The largest ratio (either way) of the variograms at lags 1, 2, 4, 8.
pub(super) fn variogram_mismatch(a: &HeightField, b: &HeightField) -> f64 {
    [1, 2, 4, 8]
        .iter()
        .map(|&l| {
            let q = variogram(a, l) / variogram(b, l);
            q.max(1.0 / q)
        })
        .fold(1.0, f64::max)
}

/// Share of the 16² windows of `out` (stride 8) that match some exemplar
/// window within `BOUNDS.copy_rms` of the exemplar's height deviation.
fn copied_share(out: &HeightField, exemplar: &HeightField) -> f64 {
    const P: u32 = 16;
    let h = heights(exemplar);
    let mean = h.iter().sum::<f64>() / h.len() as f64;
    let deviation = (h.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / h.len() as f64).sqrt();
    let window = |f: &HeightField, x: u32, y: u32| -> Vec<f64> {
        (0..P * P).map(|i| f64::from(f.height(x + i % P, y + i / P))).collect()
    };
    let mut copied = 0;
    let mut total = 0;
    for y in (0..=out.rows - P).step_by(8) {
        for x in (0..=out.columns - P).step_by(8) {
            let w = window(out, x, y);
            let best = (0..=exemplar.rows - P)
                .flat_map(|ey| (0..=exemplar.columns - P).map(move |ex| (ex, ey)))
                .map(|(ex, ey)| {
                    let e = window(exemplar, ex, ey);
                    let d: Vec<f64> = w.iter().zip(&e).map(|(a, b)| a - b).collect();
                    let m = d.iter().sum::<f64>() / d.len() as f64;
                    (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            total += 1;
            if best < BOUNDS.copy_rms * deviation {
                copied += 1;
            }
        }
    }
    copied as f64 / total as f64
}

/// (slope KS, height KS, variogram mismatch, copied share) of `out`.
fn criteria(out: &HeightField, exemplar: &HeightField) -> (f64, f64, f64, f64) {
    (
        ks(slopes(out), slopes(exemplar)),
        ks(heights(out), heights(exemplar)),
        variogram_mismatch(out, exemplar),
        copied_share(out, exemplar),
    )
}

#[test]
fn a_grown_field_has_the_exemplars_statistics_and_is_no_copy() {
    let exemplar = crop();
    let out = grow_free_cpu(&exemplar, OUT, OUT, &params(1), &mut |_, _| {}).unwrap();
    assert_eq!((out.columns, out.rows, out.spacing), (OUT, OUT, exemplar.spacing));
    assert!(out.heights.iter().all(|h| h.is_finite()));
    let side_by_side: Vec<u8> = {
        let (a, b) = (hillshade(&exemplar), hillshade(&out));
        let (wa, wb) = (exemplar.columns as usize * 4, OUT as usize * 4);
        (0..exemplar.rows as usize)
            .flat_map(|r| {
                let right: Vec<u8> = if r < OUT as usize {
                    b[r * wb..(r + 1) * wb].to_vec()
                } else {
                    vec![0; wb]
                };
                a[r * wa..(r + 1) * wa].iter().copied().chain(right)
            })
            .collect()
    };
    let path = crate::test_support::target_tmp().join("synthesis-free-hillshade.png");
    crate::io::image_out::write_png_rgba8(&path, &side_by_side, exemplar.columns + OUT, exemplar.rows).unwrap();

    let (slope_ks, height_ks, variogram, copied) = criteria(&out, &exemplar);
    eprintln!(
        "grown: KS slope {slope_ks:.3}, height {height_ks:.3}; variogram ratio {variogram:.2}; copied {copied:.3}"
    );
    assert!(slope_ks <= BOUNDS.ks_slope, "slope KS {slope_ks}");
    assert!(height_ks <= BOUNDS.ks_height, "height KS {height_ks}");
    assert!(variogram <= BOUNDS.variogram, "variogram ratio {variogram}");
    assert!(copied <= BOUNDS.copied_share, "{copied} of the windows copied");

    // The criteria can fail: a crop is a copy; shuffled heights are noise.
    let piece = HeightField::from_fn(OUT, OUT, exemplar.spacing, |c, r| exemplar.height(c + 30, r + 40));
    let (s, _, v, copied) = criteria(&piece, &exemplar);
    eprintln!("crop: KS slope {s:.3}, variogram ratio {v:.2}, copied {copied:.3}");
    assert!(
        copied > BOUNDS.copied_share,
        "a crop of the exemplar is not seen as a copy: {copied}"
    );
    let mut rng = SplitMix64(3);
    let n = exemplar.heights.len();
    let shuffled = HeightField {
        heights: (0..OUT * OUT)
            .map(|_| exemplar.heights[((rng.next_f64() * n as f64) as usize).min(n - 1)])
            .collect(),
        ..piece.clone()
    };
    let (s, h, v, _) = criteria(&shuffled, &exemplar);
    eprintln!("shuffled: KS slope {s:.3}, height {h:.3}, variogram ratio {v:.2}");
    assert!(
        s > BOUNDS.ks_slope && v > BOUNDS.variogram,
        "shuffled heights pass: {s}, {v}"
    );
}

#[test]
fn a_seed_determines_the_grown_field() {
    let exemplar = crop();
    let grow = |seed| grow_free_cpu(&exemplar, 40, 32, &params(seed), &mut |_, _| {}).unwrap();
    let (a, b, c) = (grow(7), grow(7), grow(8));
    assert_eq!(a, b, "same seed, same field");
    let differ = (0..a.heights.len()).filter(|&i| a.heights[i] != c.heights[i]).count();
    assert!(
        differ * 2 > a.heights.len(),
        "another seed changed only {differ} samples"
    );
}

#[test]
fn bad_inputs_are_one_line_errors_naming_the_parameter() {
    let exemplar = crop();
    let error = |exemplar: &HeightField, columns: u32, rows: u32, params: FillParams| {
        let e = plan_free_growth(exemplar, columns, rows, &params)
            .err()
            .expect("an error");
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
        e
    };
    assert_eq!(error(&exemplar, 5, 64, params(1)).parameter(), Some("--size"));
    assert_eq!(error(&exemplar, 64, 20000, params(1)).parameter(), Some("--size"));
    let big = FillParams {
        window: 129,
        ..params(1)
    };
    let e = error(&exemplar, 64, 64, big);
    assert!(
        e.parameter() == Some("--window") && e.to_string().contains("exemplar"),
        "{e}"
    );
    let mut void = exemplar.clone();
    void.heights[300] = f32::NAN;
    let e = error(&void, 64, 64, params(1));
    assert!(
        e.parameter() == Some("exemplar") && e.to_string().contains("column 44, row 2"),
        "{e}"
    );
    let tiny = HeightField::from_fn(4, 4, DVec2::ONE, |c, _| c as f32);
    assert_eq!(error(&tiny, 64, 64, params(1)).parameter(), Some("--window"));
}
