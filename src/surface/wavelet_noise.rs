//! Two-dimensional wavelet noise (Cook & DeRose, "Wavelet Noise", SIGGRAPH
//! 2005), recommended in dissertation §7.4.3 for procedural displacement and
//! bump mapping because its octaves are nearly band-limited: summing
//! octaves of it neither aliases nor loses detail, unlike Perlin noise
//! (§6.1).
//!
//! # Tile generation ([`noise_tile`])
//!
//! Follows the paper's reference code (`GenerateNoiseTile`) in 2D:
//!
//! 1. `R`: an `n×n` tile of independent standard Gaussian numbers from a
//!    SplitMix64 generator seeded with `seed` (Box–Muller, both outputs
//!    used), row-major (`tile[y·n + x]`).
//! 2. Each row, then each column of the result, is downsampled to `n/2`
//!    with the paper's 32 analysis coefficients `aCoeffs` and upsampled
//!    back to `n` with `pCoeffs = {¼, ¾, ¾, ¼}`, periodically (`Downsample`,
//!    `Upsample` below).
//! 3. `N = R − up(down(R))`: the tile minus its coarse-scale part.
//! 4. `N` is scaled so that its root mean square is exactly [`TILE_STD`]
//!    (the paper leaves the scale to the user). The evaluated noise then has
//!    a standard deviation of about 0.21 and stays within about ±1 (±1.2 at
//!    worst over 64 seeds; see [`TILE_STD`] for the measured figures).
//!
//! The paper's final step (adding a copy of the tile shifted by an odd
//! offset, to even out the variance of even and odd texels) is written for
//! its 3D tiles and is **not** done here; for this 2D tile the even/odd
//! variance difference is small (tested), and skipping the shift keeps the
//! tile exactly in the fine wavelet band (`down(N) ≈ 0`).
//!
//! `Downsample` in the paper loops `k = 2i−ARAD ..= 2i+ARAD` (33 taps),
//! which reads `aCoeffs[32]`, one past the end of the 32-entry array; this
//! implementation uses the 32 taps `k = 2i−16 .. 2i+16` (exclusive), i.e.
//! `to[i] = Σ_{j=0..32} aCoeffs[j] · from[(2i + j − 16) mod n]`.
//!
//! # Evaluation ([`evaluate`]; GLSL must match)
//!
//! The paper's quadratic B-spline evaluation (`WNoise`), in texel units
//! with period `n`; texel `c` is centred on the integer coordinate `c`.
//! Per axis, for coordinate `p`:
//!
//! ```text
//! mid = ceil(p − 0.5)            (integer)
//! t   = mid − (p − 0.5)          (in (0, 1])
//! w[0] = t² / 2                  tap mid − 1
//! w[2] = (1 − t)² / 2            tap mid + 1
//! w[1] = 1 − w[0] − w[2]         tap mid
//! noise(x, y) = Σ_{j,i ∈ 0..3} wy[j] · wx[i] · tile[mod(midy+j−1, n)·n + mod(midx+i−1, n)]
//! ```
//!
//! with `mod` the non-negative remainder. A GLSL version fetches the same
//! nine texels with `texelFetch(tile, ivec2(mod(midx + i − 1, n), mod(midy +
//! j − 1, n)), 0)` (x = column, y = row of the row-major tile, uploaded as
//! an `n×n` R32F image), so it matches this function to `f32` rounding.

use glam::DVec2;

use crate::error::{Error, Result};
use crate::random::SplitMix64;

/// Side of the wavelet noise tile the terrain and the surface layers
/// evaluate (also `NOISE_TILE` in the shader).
pub const NOISE_TILE: usize = 128;
/// Seed of that tile by default (the terrain's `noise_seed` setting).
pub const DEFAULT_NOISE_SEED: u64 = 7;

/// Default tile size (texels per side), as in the paper.
#[cfg(test)]
pub const TILE: usize = 128;

/// Root mean square of a tile after normalisation (step 4 of the module
/// docs). Measured on 128² tiles, seeds 0–63, evaluated at 4×4 points per
/// texel: the evaluated noise has mean 0 (|mean| < 1e-4), standard
/// deviation 0.210–0.215, and its values over all 64 tiles lie within
/// [−1.20, 1.20] (per tile typically within ±1.0–1.1). The quadratic
/// B-spline evaluation attenuates this high-frequency band: the evaluated
/// deviation is about 0.425 of the tile's. Even and odd texels' variances
/// differ by under 1 %.
pub const TILE_STD: f64 = 0.5;

/// Half the number of analysis taps (`ARAD` in the paper).
const ARAD: usize = 16;

/// The paper's analysis (downsampling) coefficients, verbatim (including its
/// slight asymmetry, 0.003545 vs 0.003546).
#[rustfmt::skip]
const A_COEFFS: [f64; 2 * ARAD] = [
    0.000334, -0.001528, 0.000410, 0.003545, -0.000938, -0.008233, 0.002172, 0.019120,
    -0.005040, -0.044412, 0.011655, 0.103311, -0.025936, -0.243780, 0.033979, 0.655340,
    0.655340, 0.033979, -0.243780, -0.025936, 0.103311, 0.011655, -0.044412, -0.005040,
    0.019120, 0.002172, -0.008233, -0.000938, 0.003546, 0.000410, -0.001528, 0.000334,
];

/// The paper's refinement (upsampling) coefficients of the quadratic
/// B-spline.
const P_COEFFS: [f64; 4] = [0.25, 0.75, 0.75, 0.25];

/// The paper's `Downsample`: `to[i] = Σ_{j=0..32} aCoeffs[j] · from[(2i + j − 16) mod n]`
/// for `i < n/2` (`n = from.len()`, even).
fn downsample(from: &[f64], to: &mut [f64]) {
    let n = from.len() as i64;
    for (i, out) in to.iter_mut().enumerate() {
        let base = 2 * i as i64 - ARAD as i64;
        *out = A_COEFFS
            .iter()
            .enumerate()
            .map(|(j, a)| a * from[(base + j as i64).rem_euclid(n) as usize])
            .sum();
    }
}

/// The paper's `Upsample`: `to[i] = Σ_{k = i/2}^{i/2+1} p[i − 2k] · from[k mod n/2]`
/// with `p = &pCoeffs[2]`, for `i < n` (`n = to.len()`, `from.len() = n/2`).
fn upsample(from: &[f64], to: &mut [f64]) {
    let half = from.len();
    for (i, out) in to.iter_mut().enumerate() {
        let k = i / 2;
        // i − 2k is 0 or 1 for k = i/2, −2 or −1 for k = i/2 + 1.
        let r = i - 2 * k;
        *out = P_COEFFS[2 + r] * from[k % half] + P_COEFFS[r] * from[(k + 1) % half];
    }
}

/// 2D analysis of a row-major `n×n` tile: downsample every row, then every
/// column, to a row-major `n/2 × n/2` tile (tests the band limitation).
#[cfg(test)]
fn down_2d(tile: &[f64], n: usize) -> Vec<f64> {
    let h = n / 2;
    let mut rows = vec![0.0; n * h]; // n rows of h
    for (src, dst) in tile.chunks_exact(n).zip(rows.chunks_exact_mut(h)) {
        downsample(src, dst);
    }
    let mut out = vec![0.0; h * h];
    let (mut col, mut half) = (vec![0.0; n], vec![0.0; h]);
    for x in 0..h {
        for (y, v) in col.iter_mut().enumerate() {
            *v = rows[y * h + x];
        }
        downsample(&col, &mut half);
        for (y, &v) in half.iter().enumerate() {
            out[y * h + x] = v;
        }
    }
    out
}

/// The paper's coarse part `up(down(R))` of a row-major `n×n` tile: per row
/// down- and upsample, then the same per column of the result.
fn coarse_2d(tile: &[f64], n: usize) -> Vec<f64> {
    let h = n / 2;
    let mut half = vec![0.0; h];
    let mut rows = vec![0.0; n * n];
    for (src, dst) in tile.chunks_exact(n).zip(rows.chunks_exact_mut(n)) {
        downsample(src, &mut half);
        upsample(&half, dst);
    }
    let mut out = vec![0.0; n * n];
    let (mut col, mut full) = (vec![0.0; n], vec![0.0; n]);
    for x in 0..n {
        for (y, v) in col.iter_mut().enumerate() {
            *v = rows[y * n + x];
        }
        downsample(&col, &mut half);
        upsample(&half, &mut full);
        for (y, &v) in full.iter().enumerate() {
            out[y * n + x] = v;
        }
    }
    out
}

/// Generates an `n×n` wavelet noise tile (row-major, `tile[y·n + x]`) from
/// `seed` (§7.4.3; Cook & DeRose 2005; steps in the module docs). The same
/// seed and size always give the same tile. The tile tiles seamlessly
/// (period `n` in both axes) and has root mean square [`TILE_STD`].
///
/// Errors unless `n` is even and `8 ≤ n ≤ 1024`.
pub fn noise_tile(seed: u64, n: usize) -> Result<Vec<f32>> {
    if n % 2 != 0 || !(8..=1024).contains(&n) {
        return Err(Error::invalid(
            "wavelet noise tile size",
            format!("{n} texels; it must be even and between 8 and 1024"),
        ));
    }
    let mut rng = SplitMix64(seed);
    let mut r = Vec::with_capacity(n * n);
    while r.len() < n * n {
        let (a, b) = rng.gaussian_pair();
        r.push(a);
        r.push(b); // n·n is even
    }
    let coarse = coarse_2d(&r, n);
    let noise: Vec<f64> = r.iter().zip(&coarse).map(|(r, c)| r - c).collect();
    let rms = (noise.iter().map(|v| v * v).sum::<f64>() / (n * n) as f64).sqrt();
    let scale = if rms > 0.0 { TILE_STD / rms } else { 0.0 };
    Ok(noise.iter().map(|v| (v * scale) as f32).collect())
}

/// One axis of the quadratic B-spline evaluation: tap indices
/// `mid−1, mid, mid+1` (mod `n`), weights and their derivatives `dw/dp`.
fn quadratic_axis(p: f64, n: usize) -> ([usize; 3], [f64; 3], [f64; 3]) {
    let mid = (p - 0.5).ceil();
    let t = mid - (p - 0.5);
    let w0 = 0.5 * t * t;
    let w2 = 0.5 * (1.0 - t) * (1.0 - t);
    // dt/dp = −1.
    let weights = [w0, 1.0 - w0 - w2, w2];
    let derivs = [-t, 2.0 * t - 1.0, 1.0 - t];
    // Reduce `mid` modulo n in floating point first so that huge or
    // non-finite coordinates cannot overflow the integer arithmetic
    // (NaN maps to 0; its weights are NaN anyway).
    let n_i = n as i64;
    let m = (mid.rem_euclid(n as f64) as i64).rem_euclid(n_i);
    let tap = |f: i64| (m + f).rem_euclid(n_i) as usize;
    ([tap(-1), tap(0), tap(1)], weights, derivs)
}

/// Whether `tile` is a usable `n×n` tile.
fn tile_ok(tile: &[f32], n: usize) -> bool {
    n > 0 && n.checked_mul(n) == Some(tile.len())
}

/// Wavelet noise at `(x, y)` in tile texels (period `n`; texel `(c, r)` is
/// centred on the integer point `(c, r)`): the paper's quadratic B-spline
/// over the 3×3 texels around `mid = ceil(p − 0.5)` (§7.4.3; exact formulas
/// in the module docs, which a GLSL `texelFetch` version must follow).
///
/// Returns NaN when `tile.len() != n·n` or `n == 0`, or for non-finite
/// coordinates.
#[cfg(test)]
pub fn evaluate(tile: &[f32], n: usize, x: f64, y: f64) -> f64 {
    if !tile_ok(tile, n) {
        return f64::NAN;
    }
    let (cx, wx, _) = quadratic_axis(x, n);
    let (cy, wy, _) = quadratic_axis(y, n);
    let mut sum = 0.0;
    for (&r, &w_r) in cy.iter().zip(&wy) {
        let row = &tile[r * n..r * n + n];
        sum += w_r * cx.iter().zip(&wx).map(|(&c, &w)| w * f64::from(row[c])).sum::<f64>();
    }
    sum
}

/// [`evaluate`] together with its analytic gradient `(∂/∂x, ∂/∂y)` per
/// texel (§7.4.3, for bump mapping): the same 3×3 taps with the derivative
/// `dw/dp` of the weights along one axis (`w[0]' = −t`, `w[1]' = 2t − 1`,
/// `w[2]' = 1 − t`). NaN in the same cases as [`evaluate`].
pub fn evaluate_gradient(tile: &[f32], n: usize, x: f64, y: f64) -> (f64, DVec2) {
    if !tile_ok(tile, n) {
        return (f64::NAN, DVec2::splat(f64::NAN));
    }
    let (cx, wx, dx) = quadratic_axis(x, n);
    let (cy, wy, dy) = quadratic_axis(y, n);
    let (mut value, mut gx, mut gy) = (0.0, 0.0, 0.0);
    for j in 0..3 {
        let row = &tile[cy[j] * n..cy[j] * n + n];
        let (mut v, mut d) = (0.0, 0.0);
        for i in 0..3 {
            let h = f64::from(row[cx[i]]);
            v += wx[i] * h;
            d += dx[i] * h;
        }
        value += wy[j] * v;
        gx += wy[j] * d;
        gy += dy[j] * v;
    }
    (value, DVec2::new(gx, gy))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f64s(tile: &[f32]) -> Vec<f64> {
        tile.iter().map(|&v| f64::from(v)).collect()
    }

    fn energy(v: &[f64]) -> f64 {
        v.iter().map(|x| x * x).sum()
    }

    /// Mean, standard deviation, minimum and maximum of the noise evaluated
    /// at `k×k` points per texel over the whole tile.
    fn dense_stats(tile: &[f32], n: usize, k: usize) -> (f64, f64, f64, f64) {
        let (mut sum, mut sum2, mut lo, mut hi) = (0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        let m = n * k;
        for j in 0..m {
            for i in 0..m {
                let x = (i as f64 + 0.37) / k as f64;
                let y = (j as f64 + 0.61) / k as f64;
                let v = evaluate(tile, n, x, y);
                sum += v;
                sum2 += v * v;
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let count = (m * m) as f64;
        let mean = sum / count;
        (mean, (sum2 / count - mean * mean).sqrt(), lo, hi)
    }

    #[test]
    fn tile_size_is_checked() {
        for n in [0, 2, 6, 7, 9, 127, 1025, 2048] {
            assert!(noise_tile(1, n).is_err(), "{n}");
        }
        for n in [8, 10, 64, TILE] {
            assert_eq!(noise_tile(1, n).unwrap().len(), n * n);
        }
    }

    #[test]
    fn deterministic_per_seed_and_different_between_seeds() {
        let a = noise_tile(7, 32).unwrap();
        assert_eq!(a, noise_tile(7, 32).unwrap());
        let b = noise_tile(8, 32).unwrap();
        assert_ne!(a, b);
        let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        assert!(differing > 32 * 32 * 9 / 10);
    }

    #[test]
    fn normalised_with_zero_mean() {
        for seed in 0..4 {
            let tile = f64s(&noise_tile(seed, TILE).unwrap());
            let count = tile.len() as f64;
            let mean = tile.iter().sum::<f64>() / count;
            let rms = (energy(&tile) / count).sqrt();
            assert!((rms - TILE_STD).abs() < 1e-6, "seed {seed}: rms {rms}");
            assert!(mean.abs() < 0.01 * TILE_STD, "seed {seed}: mean {mean}");
        }
    }

    #[test]
    fn band_limited_down_of_noise_is_small() {
        for seed in 0..4 {
            let n = TILE;
            let tile = f64s(&noise_tile(seed, n).unwrap());
            let down = down_2d(&tile, n);
            let ratio = energy(&down) / energy(&tile);
            // White noise would give about 0.25 (a quarter of the samples,
            // Σa² ≈ 1 per axis); wavelet noise almost nothing.
            assert!(ratio < 0.05, "seed {seed}: ‖down N‖² / ‖N‖² = {ratio}");
        }
    }

    #[test]
    fn even_and_odd_texels_have_similar_variance() {
        // Justifies skipping the paper's odd-offset fix-up in 2D.
        let n = TILE;
        let mut var = [[0.0; 2]; 2];
        for seed in 0..8 {
            let tile = noise_tile(seed, n).unwrap();
            for (i, v) in tile.iter().enumerate() {
                let (x, y) = (i % n, i / n);
                var[y % 2][x % 2] += f64::from(*v).powi(2);
            }
        }
        let all: Vec<f64> = var.iter().flatten().copied().collect();
        let (lo, hi) = all
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(hi / lo < 1.15, "parity variances {var:?}");
    }

    #[test]
    fn down_up_projection_reproduces_a_constant() {
        // Σ aCoeffs ≈ 1 and the upsampling weights per output sum to 1.
        let n = 16;
        let ones = vec![1.0; n * n];
        for v in coarse_2d(&ones, n) {
            assert!((v - 1.0).abs() < 1e-5, "{v}");
        }
    }

    #[test]
    fn periodic() {
        let n = 32;
        let tile = noise_tile(3, n).unwrap();
        let nf = n as f64;
        for k in 0..200 {
            let x = f64::from(k) * 0.377 - 5.0;
            let y = f64::from(k) * 0.213 - 3.0;
            let v = evaluate(&tile, n, x, y);
            for (dx, dy) in [(nf, 0.0), (0.0, nf), (-nf, 2.0 * nf)] {
                let w = evaluate(&tile, n, x + dx, y + dy);
                assert!((v - w).abs() < 1e-9, "({x}, {y}) + ({dx}, {dy}): {v} vs {w}");
            }
        }
    }

    #[test]
    fn evaluation_matches_the_formula_at_texel_centres() {
        // At p = integer c: t = ½, weights (⅛, ¾, ⅛) on c−1, c, c+1.
        let n = 8;
        let tile = noise_tile(11, n).unwrap();
        let at = |c: usize, r: usize| f64::from(tile[(r % n) * n + c % n]);
        let w = [0.125, 0.75, 0.125];
        let mut expected = 0.0;
        for (j, wy) in w.iter().enumerate() {
            for (i, wx) in w.iter().enumerate() {
                expected += wy * wx * at(n - 1 + i, 2 + j); // x taps n−1, 0, 1; y taps 2, 3, 4
            }
        }
        assert!((evaluate(&tile, n, 0.0, 3.0) - expected).abs() < 1e-12);
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let n = 32;
        let tile = noise_tile(5, n).unwrap();
        let e = 1e-6;
        for k in 0..300 {
            let x = f64::from(k) * 0.1931 - 7.0;
            let y = f64::from(k) * 0.0773 + 1.0;
            let (v, g) = evaluate_gradient(&tile, n, x, y);
            assert!((v - evaluate(&tile, n, x, y)).abs() < 1e-12);
            let fx = (evaluate(&tile, n, x + e, y) - evaluate(&tile, n, x - e, y)) / (2.0 * e);
            let fy = (evaluate(&tile, n, x, y + e) - evaluate(&tile, n, x, y - e)) / (2.0 * e);
            assert!(
                (g.x - fx).abs() < 1e-6 && (g.y - fy).abs() < 1e-6,
                "({x}, {y}): {g} vs ({fx}, {fy})"
            );
        }
    }

    #[test]
    fn evaluated_range_and_deviation() {
        for seed in 0..3 {
            let tile = noise_tile(seed, TILE).unwrap();
            let (mean, std, lo, hi) = dense_stats(&tile, TILE, 3);
            assert!(mean.abs() < 0.02, "seed {seed}: mean {mean}");
            assert!((0.15..=0.5).contains(&std), "seed {seed}: std {std}");
            assert!(lo >= -1.5 && hi <= 1.5, "seed {seed}: range [{lo}, {hi}]");
        }
    }

    #[test]
    fn bad_tiles_give_nan() {
        let tile = noise_tile(1, 8).unwrap();
        assert!(evaluate(&tile, 9, 1.0, 1.0).is_nan());
        assert!(evaluate(&tile, 0, 1.0, 1.0).is_nan());
        assert!(evaluate(&tile[..10], 8, 1.0, 1.0).is_nan());
        assert!(evaluate_gradient(&tile, 7, 1.0, 1.0).0.is_nan());
        assert!(evaluate(&tile, 8, f64::NAN, 1.0).is_nan());
        assert!(evaluate(&tile, 8, f64::INFINITY, 1.0).is_nan());
        assert!(evaluate(&tile, 8, 1e300, -1e300).is_finite());
    }

    /// Prints the figures quoted in the docs of [`TILE_STD`] (`--nocapture`)
    /// and checks the range they quote.
    #[test]
    fn measure() {
        let (mut glo, mut ghi) = (f64::INFINITY, f64::NEG_INFINITY);
        for seed in 0..8 {
            let tile = noise_tile(seed, TILE).unwrap();
            let (mean, std, lo, hi) = dense_stats(&tile, TILE, 4);
            let t = f64s(&tile);
            let ratio = energy(&down_2d(&t, TILE)) / energy(&t);
            println!("seed {seed}: mean {mean:.4} std {std:.4} range [{lo:.3}, {hi:.3}] down ratio {ratio:.5}");
            glo = glo.min(lo);
            ghi = ghi.max(hi);
        }
        println!("overall [{glo:.3}, {ghi:.3}]; Σa = {}", A_COEFFS.iter().sum::<f64>());
        assert!(glo > -1.5 && ghi < 1.5, "range [{glo}, {ghi}]");
    }
}
