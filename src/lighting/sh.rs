//! Real spherical harmonics of the first five bands (l < 5, 25 functions),
//! the basis of precomputed radiance transfer (§9.3; `ALGORITHMS.md` §6),
//! exactly as defined there:
//!
//! ```text
//! K_l^m = sqrt((2l+1)/(4π) · (l−|m|)!/(l+|m|)!)
//! y_l^m = √2 K P_l^m(cos θ) cos(mφ)        m > 0
//!       = √2 K P_l^|m|(cos θ) sin(|m|φ)    m < 0
//!       = K P_l^0(cos θ)                  m = 0
//! P_m^m = (−1)^m (2m−1)!! (1−x²)^(m/2),  P_{m+1}^m = x(2m+1) P_m^m,
//! P_l^m = (x(2l−1) P_{l−1}^m − (l+m−1) P_{l−2}^m) / (l−m)
//! ```
//!
//! θ is the angle from +Z, φ the azimuth from +X towards +Y. Coefficient
//! `i = l(l+1) + m`. The same basis is in `glsl/include/sh.glsl`.
//!
//! Evaluation avoids θ and φ: with the *reduced* Legendre function
//! `P̃_l^m(z) = P_l^m(z) / (1−z²)^(m/2)` (same recurrences, without the
//! factor) and `sin^m θ · (cos mφ, sin mφ) = (Re, Im) (x + i y)^m`, every
//! basis function is a polynomial in the unit direction (x, y, z).

use std::f64::consts::PI;

#[cfg(test)]
use glam::DVec3;

/// Bands supported (l < 5).
pub const MAX_BANDS: usize = 5;
/// Coefficients of [`MAX_BANDS`] bands.
#[cfg(test)]
pub const MAX_COEFFICIENTS: usize = MAX_BANDS * MAX_BANDS;

/// Index of `y_l^m`: `l(l+1) + m`.
#[cfg(test)]
pub const fn index(l: usize, m: i32) -> usize {
    ((l * (l + 1)) as i32 + m) as usize
}

fn factorial(n: usize) -> f64 {
    (1..=n).map(|k| k as f64).product()
}

/// `K_l^m` for `m = |m|`.
pub fn normalisation(l: usize, m: usize) -> f64 {
    ((2 * l + 1) as f64 / (4.0 * PI) * factorial(l - m) / factorial(l + m)).sqrt()
}

/// The reduced associated Legendre function `P̃_l^m(z) = P_l^m(z) / (1−z²)^(m/2)`
/// (Condon–Shortley phase included), `0 ≤ m ≤ l`.
pub fn legendre_reduced(l: usize, m: usize, z: f64) -> f64 {
    // P̃_m^m = (−1)^m (2m−1)!!
    let mut pmm = 1.0;
    for k in 0..m {
        pmm *= -((2 * k + 1) as f64);
    }
    if l == m {
        return pmm;
    }
    let pm1 = z * (2 * m + 1) as f64 * pmm;
    if l == m + 1 {
        return pm1;
    }
    let (mut p2, mut p1) = (pmm, pm1);
    for ll in m + 2..=l {
        let p = (z * (2 * ll - 1) as f64 * p1 - (ll + m - 1) as f64 * p2) / (ll - m) as f64;
        p2 = p1;
        p1 = p;
    }
    p1
}

/// The associated Legendre function `P_l^m(z)` of the definition.
#[cfg(test)]
pub fn legendre(l: usize, m: usize, z: f64) -> f64 {
    legendre_reduced(l, m, z) * (1.0 - z * z).max(0.0).powf(m as f64 * 0.5)
}

/// Evaluates the first `bands²` basis functions at unit direction `dir` into
/// `out` (which must hold at least `bands²` values; extra entries are left).
#[cfg(test)]
pub fn basis(dir: DVec3, bands: usize, out: &mut [f64]) {
    let bands = bands.min(MAX_BANDS);
    // (re, im) of (x + i y)^m = sin^m θ (cos mφ, sin mφ).
    let mut power = [(1.0, 0.0); MAX_BANDS];
    for m in 1..MAX_BANDS {
        let (re, im) = power[m - 1];
        power[m] = (re * dir.x - im * dir.y, re * dir.y + im * dir.x);
    }
    for l in 0..bands {
        for (m, &(re, im)) in power.iter().enumerate().take(l + 1) {
            let p = normalisation(l, m) * legendre_reduced(l, m, dir.z);
            if m == 0 {
                if let Some(o) = out.get_mut(index(l, 0)) {
                    *o = p;
                }
            } else {
                let s = std::f64::consts::SQRT_2 * p;
                if let Some(o) = out.get_mut(index(l, m as i32)) {
                    *o = s * re;
                }
                if let Some(o) = out.get_mut(index(l, -(m as i32))) {
                    *o = s * im;
                }
            }
        }
    }
}

/// The basis at `dir` as an array (all 25 functions).
#[cfg(test)]
pub fn basis_all(dir: DVec3) -> [f64; MAX_COEFFICIENTS] {
    let mut y = [0.0; MAX_COEFFICIENTS];
    basis(dir, MAX_BANDS, &mut y);
    y
}

/// Reconstruction `Σ c_i y_i(dir)` of a band-limited function.
#[cfg(test)]
pub fn evaluate(coefficients: &[f64], dir: DVec3) -> f64 {
    let y = basis_all(dir);
    coefficients.iter().zip(y).map(|(c, y)| c * y).sum()
}

/// Gauss–Legendre nodes and weights of `n` points on [−1, 1].
#[cfg(test)]
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let n = n.max(1);
    (0..n)
        .map(|i| {
            // Newton's method from the Chebyshev-like initial guess.
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let p = if n == 1 { x } else { p1 };
                let prev = if n == 1 { 1.0 } else { p0 };
                dp = n as f64 * (x * p - prev) / (x * x - 1.0);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The nodes of the sphere quadrature: Gauss–Legendre in z (`n` nodes) ×
/// `2n` equally spaced azimuths, exact for polynomials of degree < 2n; each
/// node as (unit direction, weight).
#[cfg(test)]
pub fn sphere_quadrature(n: usize) -> impl Iterator<Item = (DVec3, f64)> {
    let na = 2 * n.max(1);
    gauss_legendre(n).into_iter().flat_map(move |(z, wz)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        (0..na).map(move |i| {
            let phi = 2.0 * PI * (i as f64 + 0.5) / na as f64;
            (DVec3::new(r * phi.cos(), r * phi.sin(), z), wz * 2.0 * PI / na as f64)
        })
    })
}

/// Projection `c_i = ∫ f y_i dω` of `f` onto `bands` bands by
/// [`sphere_quadrature`] of `n`.
#[cfg(test)]
pub fn project(f: impl Fn(DVec3) -> f64, bands: usize, n: usize) -> Vec<f64> {
    let bands = bands.min(MAX_BANDS);
    let mut c = vec![0.0; bands * bands];
    let mut y = [0.0; MAX_COEFFICIENTS];
    for (dir, w) in sphere_quadrature(n) {
        let v = f(dir) * w;
        basis(dir, bands, &mut y);
        for (c, y) in c.iter_mut().zip(y) {
            *c += v * y;
        }
    }
    c
}

/// `Â_l`: the clamped cosine `max(0, n·ω)` convolved with band `l`
/// (Ramamoorthi and Hanrahan 2001): `∫ max(0, n·ω) y_l^m(ω) dω = Â_l y_l^m(n)`.
/// π, 2π/3, π/4, 0, −π/24, … (0 for odd l > 1).
#[cfg(test)]
pub fn clamped_cosine_band(l: usize) -> f64 {
    match l {
        0 => PI,
        1 => 2.0 * PI / 3.0,
        l if l % 2 == 1 => 0.0,
        l => {
            let sign = if (l / 2) % 2 == 1 { 1.0 } else { -1.0 };
            let h = factorial(l / 2);
            2.0 * PI * sign / ((l + 2) as f64 * (l - 1) as f64) * factorial(l) / (2f64.powi(l as i32) * h * h)
        }
    }
}

/// The SH projection of the clamped cosine lobe `max(0, n·ω)` (bands²
/// coefficients).
#[cfg(test)]
pub fn clamped_cosine(n: DVec3, bands: usize) -> Vec<f64> {
    let y = basis_all(n);
    (0..bands.min(MAX_BANDS) * bands.min(MAX_BANDS))
        .map(|i| clamped_cosine_band(band_of(i)) * y[i])
        .collect()
}

/// The band `l` of coefficient `i`.
#[cfg(test)]
pub fn band_of(i: usize) -> usize {
    (i as f64).sqrt() as usize
}

/// Irradiance `E(n) = ∫ L(ω) max(0, n·ω) dω` at normal `n` from the
/// projected radiance `L` (clamped-cosine convolution).
#[cfg(test)]
pub fn irradiance(radiance: &[f64], n: DVec3) -> f64 {
    let y = basis_all(n);
    radiance
        .iter()
        .zip(y)
        .enumerate()
        .map(|(i, (c, y))| clamped_cosine_band(band_of(i)) * c * y)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, eps: f64) -> bool {
        (a - b).abs() <= eps
    }

    #[test]
    fn basis_is_orthonormal() {
        // Gram matrix by numerical integration.
        let n = 8;
        let mut gram = [[0.0; MAX_COEFFICIENTS]; MAX_COEFFICIENTS];
        for (i, row) in gram.iter_mut().enumerate() {
            let c = project(|d| basis_all(d)[i], MAX_BANDS, n);
            row.copy_from_slice(&c);
        }
        for (i, row) in gram.iter().enumerate() {
            for (j, g) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(close(*g, want, 1e-10), "<y{i}, y{j}> = {g}");
            }
        }
    }

    #[test]
    fn low_bands_match_the_closed_forms() {
        let d = DVec3::new(0.3, -0.5, 0.7).normalize();
        let y = basis_all(d);
        let k0 = 0.5 / PI.sqrt();
        let k1 = (3.0 / (4.0 * PI)).sqrt();
        assert!(close(y[0], k0, 1e-12));
        // Condon–Shortley phase: y_1^{±1} = −K x / −K y.
        assert!(close(y[index(1, -1)], -k1 * d.y, 1e-12));
        assert!(close(y[index(1, 0)], k1 * d.z, 1e-12));
        assert!(close(y[index(1, 1)], -k1 * d.x, 1e-12));
        let k20 = (5.0 / (16.0 * PI)).sqrt();
        assert!(close(y[index(2, 0)], k20 * (3.0 * d.z * d.z - 1.0), 1e-12));
        let k22 = (15.0 / (16.0 * PI)).sqrt();
        assert!(close(y[index(2, 2)], k22 * (d.x * d.x - d.y * d.y), 1e-12));
        // Against the θ/φ definition with the unreduced P_l^m.
        let (theta, phi) = (d.z.acos(), d.y.atan2(d.x));
        for l in 0..MAX_BANDS {
            for m in 1..=l {
                let p = std::f64::consts::SQRT_2 * normalisation(l, m) * legendre(l, m, theta.cos());
                assert!(close(y[index(l, m as i32)], p * (m as f64 * phi).cos(), 1e-10));
                assert!(close(y[index(l, -(m as i32))], p * (m as f64 * phi).sin(), 1e-10));
            }
        }
    }

    #[test]
    fn reconstructs_constant_and_linear_functions() {
        let c = project(|_| 2.5, 5, 8);
        assert!(close(c[0], 2.5 * 2.0 * PI.sqrt(), 1e-9));
        assert!(c[1..].iter().all(|c| c.abs() < 1e-9));
        let f = |d: DVec3| 1.0 + 3.0 * d.z - 0.5 * d.x;
        let c = project(f, 3, 8);
        for d in [DVec3::Z, DVec3::X, DVec3::new(0.2, 0.4, -0.9).normalize()] {
            assert!(close(evaluate(&c, d), f(d), 1e-10), "{d}");
        }
    }

    #[test]
    fn clamped_cosine_projection_matches_quadrature() {
        let n = DVec3::new(0.4, 0.1, 0.9).normalize();
        let numeric = project(|d| n.dot(d).max(0.0), 5, 160);
        let analytic = clamped_cosine(n, 5);
        for (a, b) in numeric.iter().zip(&analytic) {
            assert!(close(*a, *b, 2e-3), "{a} vs {b}");
        }
        assert!(close(clamped_cosine_band(2), PI / 4.0, 1e-12));
        assert!(close(clamped_cosine_band(4), -PI / 24.0, 1e-12));
        // The band-limited lobe is close to the lobe itself.
        for d in [n, DVec3::Z, DVec3::X] {
            assert!(close(evaluate(&analytic, d), n.dot(d).max(0.0), 0.06), "{d}");
        }
        // Irradiance of a constant sky L is π L for every normal.
        let sky = project(|_| 1.0, 5, 8);
        assert!(close(irradiance(&sky, n), PI, 1e-9));
    }
}
