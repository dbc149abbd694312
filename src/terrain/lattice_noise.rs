//! The three lattice noises of dissertation §6.1.1, Fig. 6.1 ("noise
//! functions and the corresponding interpolation method: value noise, gradient
//! noise and lattice convolution noise"; Ebert et al., *Texturing &
//! Modeling*, ch. 2), beside the gradient noise the terrain models use
//! ([`super::procedural::gradient_noise`]). Only the figure and its tests use
//! the other two: alpenglow's terrains are built on gradient noise.
//!
//! * **Value noise**: a random value in [−1, 1] at each integer lattice
//!   point (the hash of [`super::procedural`]), interpolated bilinearly
//!   with the same quintic fade as the gradient noise. It takes the
//!   lattice values at the lattice points.
//! * **Gradient noise**: zero at every lattice point, a random gradient
//!   there (Perlin).
//! * **Lattice convolution noise**: the lattice values convolved with the
//!   radially symmetric Catmull–Rom filter of radius 2
//!   (`vcnoise` of *Texturing & Modeling*): `Σ_p v_p·k(|x − p|)` over the
//!   lattice points within distance 2. Samples farther apart than 4 depend
//!   on disjoint lattice values, so they are independent.

use super::procedural::{gradient_noise, hash as lattice_hash};

/// A lattice value in [−1, 1) from the hash of `(seed, i, j)`.
fn lattice_value(seed: u64, i: i64, j: i64) -> f64 {
    // The top 53 bits as a fraction in [0, 1).
    (lattice_hash(seed ^ 0x5851_f42d_4c95_7f2d, i, j) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Quintic fade, as [`gradient_noise`]'s.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Value noise (module docs).
pub fn value_noise(seed: u64, x: f64, y: f64) -> f64 {
    let (xf, yf) = (x.floor(), y.floor());
    let (i, j) = (xf as i64, yf as i64);
    let (u, v) = (fade(x - xf), fade(y - yf));
    let at = |di: i64, dj: i64| lattice_value(seed, i.wrapping_add(di), j.wrapping_add(dj));
    let a = at(0, 0) + u * (at(1, 0) - at(0, 0));
    let b = at(0, 1) + u * (at(1, 1) - at(0, 1));
    a + v * (b - a)
}

/// The Catmull–Rom filter of radius 2 at distance `d` (1 at 0, 0 at the
/// other integers, negative lobes between 1 and 2).
pub fn catmull_rom(d: f64) -> f64 {
    let d = d.abs();
    if d < 1.0 {
        1.5 * d * d * d - 2.5 * d * d + 1.0
    } else if d < 2.0 {
        -0.5 * d * d * d + 2.5 * d * d - 4.0 * d + 2.0
    } else {
        0.0
    }
}

/// Lattice convolution noise (module docs).
pub fn convolution_noise(seed: u64, x: f64, y: f64) -> f64 {
    let (i, j) = (x.floor() as i64, y.floor() as i64);
    let mut sum = 0.0;
    for dj in -1..=2 {
        for di in -1..=2 {
            let (pi, pj) = (i.wrapping_add(di), j.wrapping_add(dj));
            let d = ((x - pi as f64).powi(2) + (y - pj as f64).powi(2)).sqrt();
            sum += lattice_value(seed, pi, pj) * catmull_rom(d);
        }
    }
    sum
}

/// A noise: `(seed, x, y) → value`.
pub type Noise = fn(u64, f64, f64) -> f64;

/// The three noises of Fig. 6.1, in the figure's order.
pub const NOISES: [(&str, Noise); 3] = [
    ("value", value_noise),
    ("gradient", gradient_noise),
    ("convolution", convolution_noise),
];

mod tests {
    use super::*;

    /// `count` samples of `noise` on a jittered grid of step 0.37 (not a
    /// lattice fraction).
    fn samples(noise: Noise, seed: u64, count: usize) -> Vec<f64> {
        (0..count)
            .map(|k| noise(seed, (k % 500) as f64 * 0.37 + 0.11, (k / 500) as f64 * 0.37 - 40.0))
            .collect()
    }

    /// Correlation of `noise` at points `lag` apart, over many points.
    fn correlation(noise: Noise, lag: (f64, f64)) -> f64 {
        let (mut sab, mut saa, mut sbb, mut sa, mut sb) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let n = 40_000;
        for k in 0..n {
            let (x, y) = ((k % 200) as f64 * 1.37 + 0.21, (k / 200) as f64 * 1.13 + 0.47);
            let (a, b) = (noise(3, x, y), noise(3, x + lag.0, y + lag.1));
            sab += a * b;
            saa += a * a;
            sbb += b * b;
            sa += a;
            sb += b;
        }
        let n = n as f64;
        let cov = sab / n - sa / n * sb / n;
        cov / ((saa / n - (sa / n).powi(2)) * (sbb / n - (sb / n).powi(2))).sqrt()
    }

    #[test]
    fn lattice_values_and_zeros() {
        for (i, j) in [(0, 0), (3, -5), (-17, 40)] {
            let (x, y) = (i as f64, j as f64);
            assert_eq!(
                value_noise(9, x, y),
                lattice_value(9, i, j),
                "value noise takes the lattice value"
            );
            assert_eq!(gradient_noise(9, x, y), 0.0, "gradient noise is zero on the lattice");
        }
        assert_eq!((catmull_rom(0.0), catmull_rom(1.0), catmull_rom(2.0)), (1.0, 0.0, 0.0));
        assert!(catmull_rom(1.5) < 0.0, "negative lobe");
        // In 1-D the Catmull–Rom weights of the four nearest points sum to 1.
        for x in [0.1, 0.37, 0.5, 0.93] {
            let sum: f64 = (-1..=2).map(|k| catmull_rom(x - f64::from(k))).sum();
            assert!((sum - 1.0).abs() < 1e-12, "{x}: {sum}");
        }
        assert_ne!(value_noise(1, 0.5, 0.5), value_noise(2, 0.5, 0.5), "seeded");
    }

    #[test]
    fn bounded_zero_mean_and_spread() {
        // Bound of the convolution noise: Σ|k| over the 16 lattice points, at most.
        for (name, noise) in NOISES {
            let s = samples(noise, 5, 100_000);
            let mean = s.iter().sum::<f64>() / s.len() as f64;
            let sd = (s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / s.len() as f64).sqrt();
            let (lo, hi) = s
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            eprintln!("{name}: mean {mean:.4}, sd {sd:.3}, range {lo:.3}..{hi:.3}");
            assert!(lo >= -1.5 && hi <= 1.5, "{name}: range {lo} {hi}");
            assert!(mean.abs() < 0.03, "{name}: mean {mean}");
            assert!(sd > 0.15, "{name}: sd {sd}");
        }
    }

    #[test]
    fn correlation_shapes() {
        let rows: Vec<(&str, [f64; 4])> = NOISES
            .iter()
            .map(|&(name, noise)| (name, [0.25, 1.0, 2.0, 4.5].map(|lag| correlation(noise, (lag, 0.0)))))
            .collect();
        for (name, c) in &rows {
            eprintln!("{name}: correlation at lags 0.25, 1, 2, 4.5: {c:.3?}");
        }
        let [value, gradient, convolution] = [&rows[0].1, &rows[1].1, &rows[2].1];
        // Close points agree in every noise.
        assert!(value[0] > 0.7 && gradient[0] > 0.5 && convolution[0] > 0.7);
        // Beyond the support of the interpolation (value: 1 cell; convolution: 4) samples
        // are independent; the gradient noise's band-pass leaves a negative lobe at 1.
        for c in [value[2], value[3], gradient[3], convolution[3]] {
            assert!(c.abs() < 0.03, "independent samples correlate: {c}");
        }
        assert!(
            gradient[1] < -0.05,
            "gradient noise lacks the negative lobe: {}",
            gradient[1]
        );
        assert!(value[1] > gradient[1], "value noise keeps more low frequencies");
        // Isotropic on the lattice's axes: the same correlation along y.
        for (name, noise) in NOISES {
            let (x, y) = (correlation(noise, (0.5, 0.0)), correlation(noise, (0.0, 0.5)));
            assert!((x - y).abs() < 0.03, "{name}: correlation along x {x}, along y {y}");
        }
    }

    /// A profile plot of `noise` along `y` over `cells` cells: the curve in
    /// white, the zero line grey, lattice points as grey ticks.
    fn profile(noise: Noise, y: f64, side: u32, cells: f64) -> Vec<u8> {
        let mut rgba: Vec<u8> = (0..side * side).flat_map(|_| [0, 0, 0, 255]).collect();
        let mut put = |x: u32, py: u32, v: u8| {
            let i = ((py.min(side - 1) * side + x) * 4) as usize;
            rgba[i..i + 4].copy_from_slice(&[v, v, v, 255]);
        };
        let to_row = |v: f64| {
            ((0.5 - v * 0.4) * f64::from(side))
                .round()
                .clamp(0.0, f64::from(side - 1)) as u32
        };
        for x in 0..side {
            put(x, side / 2, 90);
            let lattice = (f64::from(x) * cells / f64::from(side)).fract() < cells / f64::from(side);
            if lattice {
                for py in side / 2 - 4..side / 2 + 4 {
                    put(x, py, 150);
                }
            }
        }
        let mut previous = None;
        for x in 0..side {
            let row = to_row(noise(7, f64::from(x) * cells / f64::from(side), y));
            let (a, b) = previous.map_or((row, row), |p: u32| (p.min(row), p.max(row)));
            for py in a..=b {
                put(x, py, 255);
            }
            previous = Some(row);
        }
        rgba
    }

    #[test]
    fn figure_6_1_images() {
        // One row a noise: the noise over 8×8 cells (grey, −1 black, 1 white),
        // and its profile along the image's middle row.
        const SIDE: u32 = 128;
        const CELLS: f64 = 8.0;
        let mut strip = Vec::new();
        for (_, noise) in NOISES {
            let y = |r: u32| (f64::from(r) + 0.5) * CELLS / f64::from(SIDE);
            let image: Vec<u8> = (0..SIDE * SIDE)
                .flat_map(|i| {
                    let v = noise(7, f64::from(i % SIDE) * CELLS / f64::from(SIDE), y(i / SIDE));
                    let g = ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0).round() as u8;
                    [g, g, g, 255]
                })
                .collect();
            let plot = profile(noise, y(SIDE / 2), SIDE, CELLS);
            let row = SIDE as usize * 4;
            for r in 0..SIDE as usize {
                strip.extend_from_slice(&image[r * row..(r + 1) * row]);
                strip.extend_from_slice(&plot[r * row..(r + 1) * row]);
            }
            // The image's middle row is the profile's curve: check one column.
            let v = noise(7, 3.0 * CELLS / f64::from(SIDE), y(SIDE / 2));
            let grey = image[(SIDE / 2 * SIDE + 3) as usize * 4];
            assert_eq!(grey, ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0).round() as u8);
        }
        crate::test_support::dump_pngs(&[("lattice-noises", &strip)], 2 * SIDE, 3 * SIDE);
    }
}
