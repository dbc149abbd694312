//! The generic SH basis up to 26 bands and its windowed projection
//! (`lighting::sh_bands`, §9.3, Fig. 9.4) against independent references:
//! quadrature (orthonormality), the closed forms and the factorial
//! definition (agreement), the addition theorem, and exact integrals of a
//! horizon step (convergence, Gibbs overshoot, the Fig. 9.4 table).

use std::f64::consts::PI;

use glam::DVec3;

use crate::lighting::sh::{self, gauss_legendre};
use crate::lighting::sh_bands::{self, Window, MAX_GENERIC_BANDS};

fn directions() -> Vec<DVec3> {
    let mut v = vec![DVec3::Z, -DVec3::Z, DVec3::X, DVec3::new(1e-9, 0.0, 1.0).normalize()];
    for k in 0..40 {
        let z = -0.99 + 1.98 * (k as f64 + 0.5) / 40.0;
        let phi = k as f64 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        v.push(DVec3::new(r * phi.cos(), r * phi.sin(), z));
    }
    v
}

#[test]
fn generic_basis_is_orthonormal_to_26_bands() {
    // Gauss–Legendre 26 × 52 azimuths integrates every product of two
    // functions of band < 26 (degree ≤ 50) exactly.
    let bands = MAX_GENERIC_BANDS;
    let count = bands * bands;
    let n = bands;
    let na = 2 * n;
    let mut gram = vec![0.0; count * count];
    let mut y = vec![0.0; count];
    for (z, wz) in gauss_legendre(n) {
        let r = (1.0 - z * z).sqrt();
        for i in 0..na {
            let phi = 2.0 * PI * (i as f64 + 0.5) / na as f64;
            sh_bands::basis(DVec3::new(r * phi.cos(), r * phi.sin(), z), bands, &mut y);
            let w = wz * 2.0 * PI / na as f64;
            for a in 0..count {
                let wa = w * y[a];
                let row = &mut gram[a * count..a * count + a + 1];
                for (g, yb) in row.iter_mut().zip(&y) {
                    *g += wa * yb;
                }
            }
        }
    }
    let mut worst: f64 = 0.0;
    for a in 0..count {
        for b in 0..=a {
            let want = if a == b { 1.0 } else { 0.0 };
            worst = worst.max((gram[a * count + b] - want).abs());
        }
    }
    assert!(worst < 1e-10, "largest deviation of the Gram matrix from I: {worst:e}");
}

#[test]
fn generic_basis_matches_the_five_band_path_and_the_definition() {
    let mut y = vec![0.0; MAX_GENERIC_BANDS * MAX_GENERIC_BANDS];
    for d in directions() {
        sh_bands::basis(d, MAX_GENERIC_BANDS, &mut y);
        // The five-band path of the bake (and of glsl/include/sh.glsl).
        let five = sh::basis_all(d);
        for (i, (a, b)) in y.iter().zip(five).enumerate() {
            assert!((a - b).abs() < 1e-12, "y{i} at {d}: {a} vs {b}");
        }
        // Closed forms (Condon–Shortley phase).
        let (x, yy, z) = (d.x, d.y, d.z);
        let y40 = 3.0 / 16.0 * (1.0 / PI).sqrt() * (35.0 * z.powi(4) - 30.0 * z * z + 3.0);
        let y44 = 3.0 / 16.0 * (35.0 / PI).sqrt() * (x.powi(4) - 6.0 * x * x * yy * yy + yy.powi(4));
        let y3m3 = -0.25 * (35.0 / (2.0 * PI)).sqrt() * (3.0 * x * x - yy * yy) * yy;
        assert!((y[sh::index(4, 0)] - y40).abs() < 1e-12);
        assert!((y[sh::index(4, 4)] - y44).abs() < 1e-12);
        assert!((y[sh::index(3, -3)] - y3m3).abs() < 1e-12);
        // Every band against the factorial definition K_l^m P_l^m (the
        // unnormalised recurrence of Eq. 9.15) in θ, φ.
        let (theta, phi) = (z.clamp(-1.0, 1.0).acos(), yy.atan2(x));
        // (At the poles θ loses x, y of 1e-9: m > 0 there only from the closed forms.)
        let pole = x.hypot(yy) < 1e-6;
        for l in 0..MAX_GENERIC_BANDS {
            for m in (0..=l).filter(|&m| m == 0 || !pole) {
                let p = sh::normalisation(l, m) * sh::legendre(l, m, theta.cos());
                let scale = p.abs().max(1.0);
                if m == 0 {
                    assert!((y[l * (l + 1)] - p).abs() < 1e-9 * scale, "y_{l}^0 at {d}");
                } else {
                    let s = std::f64::consts::SQRT_2 * p;
                    let (c, sn) = ((m as f64 * phi).cos(), (m as f64 * phi).sin());
                    assert!((y[l * (l + 1) + m] - s * c).abs() < 1e-9 * scale, "y_{l}^{m} at {d}");
                    assert!((y[l * (l + 1) - m] - s * sn).abs() < 1e-9 * scale, "y_{l}^-{m} at {d}");
                }
            }
            // Addition theorem: Σ_m (y_l^m)² = (2l+1)/(4π).
            let sum: f64 = y[l * l..(l + 1) * (l + 1)].iter().map(|v| v * v).sum();
            let want = (2 * l + 1) as f64 / (4.0 * PI);
            assert!((sum - want).abs() < 1e-11 * want.max(1.0), "band {l}: {sum} vs {want}");
        }
    }
}

#[test]
fn window_factors_are_as_documented() {
    for bands in [5, 10, 26] {
        for w in [Window::Hanning, Window::Lanczos] {
            assert_eq!(w.factor(0, bands), 1.0);
            let f: Vec<f64> = (0..bands).map(|l| w.factor(l, bands)).collect();
            assert!(f.windows(2).all(|p| p[1] < p[0] && p[1] > 0.0), "{w:?} {f:?}");
        }
        assert!(
            (Window::Hanning.factor(bands / 2, bands) - 0.5 * (1.0 + (PI * (bands / 2) as f64 / bands as f64).cos()))
                .abs()
                < 1e-15
        );
        assert!(Window::None.factor(bands - 1, bands) == 1.0);
    }
}

/// Visibility above a horizon whose elevation varies with the azimuth
/// (a terrain point's horizon: 0.1–0.5 rad), 1 above, 0 below.
fn horizon_visibility(d: DVec3) -> f64 {
    let phi = d.y.atan2(d.x);
    let h = 0.3 + 0.2 * (phi.cos() * 0.8 + (2.0 * phi).sin() * 0.2);
    if d.z > h.sin() {
        1.0
    } else {
        0.0
    }
}

struct Fit {
    l2: f64,
    overshoot: f64,
}

/// L2 error (over the sphere) and the largest excursion outside [0, 1] of
/// the `bands`-band reconstruction of [`horizon_visibility`].
fn fit(bands: usize, window: Window) -> Fit {
    let c = sh_bands::project_windowed(horizon_visibility, bands, 120, window);
    let mut y = vec![0.0; bands * bands];
    let (mut l2, mut overshoot): (f64, f64) = (0.0, 0.0);
    let n = 90;
    for (z, wz) in gauss_legendre(n) {
        let r = (1.0 - z * z).sqrt();
        for i in 0..2 * n {
            let phi = 2.0 * PI * (i as f64 + 0.25) / (2 * n) as f64;
            let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            sh_bands::basis(d, bands, &mut y);
            let v: f64 = c.iter().zip(&y).map(|(c, y)| c * y).sum();
            let e = v - horizon_visibility(d);
            l2 += e * e * wz * PI / n as f64;
            overshoot = overshoot.max(v - 1.0).max(-v);
        }
    }
    Fit {
        l2: l2.sqrt(),
        overshoot,
    }
}

#[test]
fn horizon_step_converges_and_the_window_reduces_ringing() {
    let plain: Vec<Fit> = [5, 10, 26].iter().map(|&b| fit(b, Window::None)).collect();
    let hann: Vec<Fit> = [5, 10, 26].iter().map(|&b| fit(b, Window::Hanning)).collect();
    let lanczos: Vec<Fit> = [5, 10, 26].iter().map(|&b| fit(b, Window::Lanczos)).collect();
    for (name, f) in [("plain", &plain), ("hanning", &hann), ("lanczos", &lanczos)] {
        eprintln!(
            "{name:8} L2 {:.4} {:.4} {:.4}  overshoot {:.4} {:.4} {:.4}",
            f[0].l2, f[1].l2, f[2].l2, f[0].overshoot, f[1].overshoot, f[2].overshoot
        );
        assert!(f[0].l2 > f[1].l2 && f[1].l2 > f[2].l2, "{name}: no convergence");
    }
    // Gibbs: the truncated series overshoots by 12–15 % of the jump
    // whatever the band count; the windows cut that to a fraction (at 5
    // bands, where the window's own smoothing spills over the azimuthal
    // bumps of the horizon, to about half).
    for i in 0..3 {
        assert!(plain[i].overshoot > 0.06, "plain overshoot {}", plain[i].overshoot);
        let most = if i == 0 { 0.6 } else { 0.25 };
        assert!(
            hann[i].overshoot < most * plain[i].overshoot,
            "hanning {}",
            hann[i].overshoot
        );
        assert!(
            lanczos[i].overshoot < 0.6 * plain[i].overshoot,
            "lanczos {}",
            lanczos[i].overshoot
        );
        // ... at the price of a wider edge: a larger L2 error.
        assert!(hann[i].l2 > plain[i].l2);
    }
}

/// One row of the Fig. 9.4-like table: shading of a white diffuse ground
/// point (normal +Z) in a round crater whose rim stands at elevation `h`,
/// under a uniform sky (radiance 1 above the horizon) and a sun of
/// irradiance `SUN` at elevation [`SUN_ELEVATION`] (a direction), exact and
/// from `bands`-band SH transfer (windowed) · SH light.
const SUN: f64 = 8.0;
const SUN_ELEVATION: f64 = 12.5 * PI / 180.0;

fn exact_shading(h: f64) -> f64 {
    let sky = PI * (1.0 - h.sin().powi(2));
    sky + if h < SUN_ELEVATION {
        SUN * SUN_ELEVATION.sin()
    } else {
        0.0
    }
}

/// `∫_{a}^{b} g(z) dz` by 64-point Gauss–Legendre.
fn integrate(a: f64, b: f64, g: impl Fn(f64) -> f64) -> f64 {
    gauss_legendre(64)
        .into_iter()
        .map(|(x, w)| 0.5 * (b - a) * w * g(a + 0.5 * (b - a) * (x + 1.0)))
        .sum()
}

/// `y_l^0` at `z`.
fn zonal(l: usize, z: f64) -> f64 {
    let mut y = vec![0.0; (l + 1) * (l + 1)];
    sh_bands::basis(DVec3::new((1.0 - z * z).max(0.0).sqrt(), 0.0, z), l + 1, &mut y);
    y[l * (l + 1)]
}

fn sh_shading(h: f64, bands: usize, window: Window) -> f64 {
    let sun = DVec3::new(SUN_ELEVATION.cos(), 0.0, SUN_ELEVATION.sin());
    let mut y = vec![0.0; bands * bands];
    sh_bands::basis(sun, bands, &mut y);
    // The transfer V·max(0, z) is zonal: only m = 0, integrated exactly
    // (the step at z = sin h is an integration limit).
    (0..bands)
        .map(|l| {
            let t = 2.0 * PI * integrate(h.sin(), 1.0, |z| z * zonal(l, z)) * window.factor(l, bands);
            let sky = 2.0 * PI * integrate(0.0, 1.0, |z| zonal(l, z));
            t * (sky + SUN * y[l * (l + 1)])
        })
        .sum()
}

#[test]
fn fig_9_4_table_sun_edge_rings_without_the_window_and_smears_with_it() {
    // Rim elevations 0..25° every 0.25°; the sun stands at 12.5°.
    let heights: Vec<f64> = (0..=100).map(|k| (k as f64 * 0.25).to_radians()).collect();
    let exact: Vec<f64> = heights.iter().map(|&h| exact_shading(h)).collect();
    let mean = exact.iter().sum::<f64>() / exact.len() as f64;
    let jump = SUN * SUN_ELEVATION.sin();
    eprintln!("bands window   relRMSE  ringing  leak+3deg  loss-3deg");
    let mut rows = Vec::new();
    for bands in [5, 10, 26] {
        for window in [Window::None, Window::Hanning, Window::Lanczos] {
            let s: Vec<f64> = heights.iter().map(|&h| sh_shading(h, bands, window)).collect();
            let rmse = (s.iter().zip(&exact).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / s.len() as f64).sqrt() / mean;
            // The sun's share of the SH shading: the shading less the exact
            // sky part, over the sun's exact contribution (1 lit, 0 shadowed).
            let share = |i: usize| (s[i] - PI * (1.0 - heights[i].sin().powi(2))) / jump;
            // Ringing: how far the share leaves [0, 1] (negative light in
            // the shadow, overshoot in the light).
            let ringing = (0..s.len())
                .map(|i| (share(i) - 1.0).max(-share(i)))
                .fold(0.0f64, f64::max);
            // Smear: the sun's share 3° inside the shadow and missing 3° inside the light.
            let at = |deg: f64| share(((12.5 + deg) / 0.25).round() as usize);
            let (leak, loss) = (at(3.0), 1.0 - at(-3.0));
            eprintln!("{bands:5} {window:8?} {rmse:8.4} {ringing:8.4} {leak:9.4} {loss:9.4}");
            rows.push((bands, window, rmse, ringing, leak));
        }
    }
    let get = |b: usize, w: Window| *rows.iter().find(|r| r.0 == b && r.1 == w).unwrap();
    for b in [5, 10, 26] {
        let p = get(b, Window::None);
        for w in [Window::Hanning, Window::Lanczos] {
            let f = get(b, w);
            // "Appropriate filtering reduces artifacts but increases the
            // angular distribution of the sun light enormously" (§9.5): less
            // ringing from 10 bands on (5 plain bands do not leave [0, 1]
            // along this profile; the smoothed lobe overshoots instead), more
            // sun leaking into the shadow at every band count.
            if b > 5 {
                assert!(
                    f.3 < 0.25 * p.3,
                    "{b} bands {w:?}: the window must ring less ({} vs {})",
                    f.3,
                    p.3
                );
            }
            assert!(
                f.4 > p.4,
                "{b} bands {w:?}: the window spreads the sun ({} vs {})",
                f.4,
                p.4
            );
        }
    }
    // More bands: smaller error and less sun leaking 3° into the shadow.
    for w in [Window::None, Window::Hanning, Window::Lanczos] {
        assert!(get(26, w).2 < get(10, w).2 && get(10, w).2 < get(5, w).2, "{w:?}");
        assert!(get(26, w).4 < get(10, w).4 && get(10, w).4 < get(5, w).4, "{w:?}");
    }
}
