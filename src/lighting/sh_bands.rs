//! Real spherical harmonics of any band count up to [`MAX_GENERIC_BANDS`]
//! (26, the most Fig. 9.4 of the text uses), and the *windowed* (filtered)
//! projection that §9.3 suggests against the Gibbs phenomenon ("possible
//! ways to reduce these 'ringing' artifacts are discussed by Navarra et
//! al. [123]"; Fig. 9.4's lower row, "SH filtered").
//!
//! The basis is the one of [`crate::lighting::sh`] (§9.3, Eq. 9.14–9.16,
//! Condon–Shortley phase, index `l(l+1) + m`), evaluated with the standard
//! stable recurrence of the *fully normalised* associated Legendre
//! functions `P̄_l^m = K_l^m P_l^m` (no factorials, so no overflow at high
//! bands), in the reduced form `P̄_l^m / sin^m θ` with
//! `sin^m θ (cos mφ, sin mφ) = (x + i y)^m`:
//!
//! ```text
//! P̄_0^0 = 1/√(4π),   P̄_m^m = −√((2m+1)/(2m)) P̄_{m−1}^{m−1}
//! P̄_{m+1}^m = √(2m+3) z P̄_m^m
//! P̄_l^m = a_lm (z P̄_{l−1}^m − b_lm P̄_{l−2}^m),
//!   a_lm = √((4l²−1)/(l²−m²)),  b_lm = √(((l−1)²−m²)/(4(l−1)²−1))
//! ```
//!
//! The closed-form five-band path ([`crate::lighting::sh::basis`], the
//! bake's tables and `glsl/include/sh.glsl`) is unchanged; the tests check
//! that both agree.
//!
//! Windowing scales band `l` of a projection of `L` bands by `σ_l`:
//! Hanning `σ_l = (1 + cos(π l / L)) / 2` or Lanczos `σ_l = sinc(l / L)`
//! (`sinc x = sin(πx)/(πx)`), both 1 at `l = 0` (the mean is kept) and
//! falling smoothly towards the truncation, which trades the overshoot of a
//! truncated series at a discontinuity for a wider edge.

use std::f64::consts::{PI, SQRT_2};

use glam::DVec3;

use crate::lighting::sh::sphere_quadrature;

/// The most bands the generic basis evaluates.
pub const MAX_GENERIC_BANDS: usize = 26;

/// Per-band scale factors of a windowed projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Window {
    /// The plain truncated series.
    None,
    /// `σ_l = (1 + cos(π l / L)) / 2`.
    Hanning,
    /// `σ_l = sinc(l / L)` (Lanczos sigma factors).
    Lanczos,
}

impl Window {
    /// `σ_l` for a projection of `bands` bands.
    pub fn factor(self, l: usize, bands: usize) -> f64 {
        let t = l as f64 / bands.max(1) as f64;
        match self {
            Window::None => 1.0,
            Window::Hanning => 0.5 * (1.0 + (PI * t).cos()),
            Window::Lanczos if l == 0 => 1.0,
            Window::Lanczos => (PI * t).sin() / (PI * t),
        }
    }

    /// Scales `coefficients` (`bands²` of them) band by band.
    pub fn apply(self, coefficients: &mut [f64], bands: usize) {
        for l in 0..bands {
            let s = self.factor(l, bands);
            for c in coefficients.iter_mut().skip(l * l).take(2 * l + 1) {
                *c *= s;
            }
        }
    }
}

/// Evaluates the first `bands²` basis functions (`bands ≤ 26`) at unit
/// direction `dir` into `out` (at least `bands²` long).
pub fn basis(dir: DVec3, bands: usize, out: &mut [f64]) {
    let bands = bands.min(MAX_GENERIC_BANDS);
    let z = dir.z;
    let (mut re, mut im) = (1.0, 0.0);
    let mut pmm = 0.5 / PI.sqrt();
    for m in 0..bands {
        if m > 0 {
            pmm *= -((2 * m + 1) as f64 / (2 * m) as f64).sqrt();
            (re, im) = (re * dir.x - im * dir.y, re * dir.y + im * dir.x);
        }
        let (mut p2, mut p1) = (0.0, pmm);
        for l in m..bands {
            let p = if l == m {
                pmm
            } else if l == m + 1 {
                ((2 * m + 3) as f64).sqrt() * z * pmm
            } else {
                let (lf, mf) = (l as f64, m as f64);
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let l1 = lf - 1.0;
                let b = ((l1 * l1 - mf * mf) / (4.0 * l1 * l1 - 1.0)).sqrt();
                a * (z * p1 - b * p2)
            };
            if l > m {
                p2 = p1;
                p1 = p;
            }
            let i = l * (l + 1);
            if m == 0 {
                out[i] = p;
            } else {
                out[i + m] = SQRT_2 * p * re;
                out[i - m] = SQRT_2 * p * im;
            }
        }
    }
}

/// Projection `c_i = ∫ f y_i dω` onto `bands` bands by
/// [`sphere_quadrature`] of `n` (exact for polynomials of degree < 2n).
pub fn project(f: impl Fn(DVec3) -> f64, bands: usize, n: usize) -> Vec<f64> {
    let bands = bands.min(MAX_GENERIC_BANDS);
    let mut c = vec![0.0; bands * bands];
    let mut y = vec![0.0; bands * bands];
    for (dir, w) in sphere_quadrature(n) {
        let v = f(dir) * w;
        if v == 0.0 {
            continue;
        }
        basis(dir, bands, &mut y);
        for (c, y) in c.iter_mut().zip(&y) {
            *c += v * y;
        }
    }
    c
}

/// The windowed projection: [`project`], then `window` per band.
pub fn project_windowed(f: impl Fn(DVec3) -> f64, bands: usize, n: usize, window: Window) -> Vec<f64> {
    let mut c = project(f, bands, n);
    window.apply(&mut c, bands.min(MAX_GENERIC_BANDS));
    c
}
