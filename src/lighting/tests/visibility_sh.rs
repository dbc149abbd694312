//! Fig. 9.2 of the dissertation (§9.3): the cosine term and the visibility
//! function at a point on a terrain's surface, and their product
//! approximated by spherical harmonics with 5 bands (25 coefficients), on
//! the Jacksboro DEM with heights ×3 (CPU: `HeightFieldTracer`, `sh`).
//!
//! The point is the most enclosed sample of a coarse grid (largest mean
//! horizon elevation over 16 azimuths, the horizon found by marching the
//! height samples). `f(ω) = max(0, n·ω)·V(ω)`, `V` = 1 where the exact ray
//! cast of the bilinear patches escapes. Its projection `c` on 5 bands is
//! taken by the Gauss–Legendre sphere quadrature of `sh::project`; the
//! independent reference is a Monte Carlo projection with uniformly random
//! directions: every coefficient agrees within 4 standard errors (and
//! 0.02). The reconstruction is the best L² fit, so its error obeys
//! Parseval, `‖f − f̂‖² = ‖f‖² − Σc²` (checked by quadrature to 2 %), and
//! falls from 3 to 5 bands.
//!
//! With `ALPENGLOW_DUMP=DIR`: `N-cosine-visibility-sh.png`, the upper
//! hemisphere seen from above (azimuthal equidistant: zenith at the
//! centre, horizon on the rim, north up) of the cosine, the visibility,
//! their product and its 5-band reconstruction (grey 0–1, negative
//! values red).

use glam::{DVec2, DVec3};

use crate::io::heightmap::HeightField;
use crate::lighting::reference::{ray_offset, HeightFieldTracer};
use crate::lighting::sh;
use crate::random::SplitMix64;
use crate::test_support::jacksboro_field;

/// Vertical exaggeration of the DEM: at 1 the most enclosed point sees
/// 94 % of its unoccluded ‖cos‖² (gentle Appalachian ridges), too little
/// occlusion to show.
const EXAGGERATION: f32 = 3.0;
/// Side of each hemisphere panel.
const PANEL: u32 = 96;
/// Gauss–Legendre nodes in z of the quadrature (× twice as many azimuths).
const NODES: usize = 48;
/// Monte Carlo directions of the reference projection.
const SAMPLES: usize = 20_000;

/// Horizon elevation (tangent) from sample `(c, r)` towards `dir`,
/// marching the samples up to 64 steps.
fn horizon_tangent(field: &HeightField, c: u32, r: u32, dir: DVec2) -> f64 {
    let h0 = f64::from(field.height(c, r));
    let mut best = f64::NEG_INFINITY;
    for step in 1..=64 {
        let (x, y) = (
            f64::from(c) + dir.x * f64::from(step),
            f64::from(r) + dir.y * f64::from(step),
        );
        if x < 0.0 || y < 0.0 || x > f64::from(field.columns - 1) || y > f64::from(field.rows - 1) {
            break;
        }
        let h = f64::from(field.height(x.round() as u32, y.round() as u32));
        let distance = (dir * f64::from(step) * field.spacing).length();
        best = best.max((h - h0) / distance);
    }
    best
}

/// The most enclosed sample of a coarse grid away from the border.
fn enclosed_sample(field: &HeightField) -> (u32, u32) {
    let mut best = (f64::NEG_INFINITY, (0, 0));
    for r in (64..field.rows - 64).step_by(8) {
        for c in (64..field.columns - 64).step_by(8) {
            let mean = (0..16)
                .map(|k| {
                    let a = std::f64::consts::TAU * f64::from(k) / 16.0;
                    horizon_tangent(field, c, r, DVec2::new(a.cos(), a.sin())).atan()
                })
                .sum::<f64>()
                / 16.0;
            if mean > best.0 {
                best = (mean, (c, r));
            }
        }
    }
    best.1
}

/// A direction of the upper hemisphere under pixel `(x, y)` of a panel
/// (azimuthal equidistant), or `None` outside the disc.
fn panel_direction(x: u32, y: u32) -> Option<DVec3> {
    let half = f64::from(PANEL) / 2.0;
    let p = DVec2::new(f64::from(x) + 0.5 - half, half - f64::from(y) - 0.5) / half;
    let rho = p.length();
    if rho > 1.0 {
        return None;
    }
    let theta = rho * std::f64::consts::FRAC_PI_2;
    let azimuth = p.y.atan2(p.x);
    Some(DVec3::new(
        theta.sin() * azimuth.cos(),
        theta.sin() * azimuth.sin(),
        theta.cos(),
    ))
}

/// One panel of `g` over the hemisphere (grey 0–1; negative values red).
fn panel(g: &dyn Fn(DVec3) -> f64) -> Vec<u8> {
    (0..PANEL * PANEL)
        .flat_map(|i| match panel_direction(i % PANEL, i / PANEL) {
            None => [40, 40, 60, 255],
            Some(d) => {
                let v = g(d);
                let grey = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
                if v < 0.0 {
                    [((-v * 4.0).clamp(0.0, 1.0) * 255.0) as u8, 0, 0, 255]
                } else {
                    [grey, grey, grey, 255]
                }
            }
        })
        .collect()
}

#[test]
fn sh_fit_of_cosine_times_visibility_matches_a_monte_carlo_projection() {
    let mut field = jacksboro_field();
    for h in &mut field.heights {
        *h *= EXAGGERATION;
    }
    let tracer = HeightFieldTracer::new(&field).unwrap();
    let (c, r) = enclosed_sample(&field);
    let normal = tracer.vertex_normal(c.into(), r.into());
    let origin = tracer.sample_position(c, r) + DVec3::Z * f64::from(ray_offset(&field)) * 10.0;
    let visible = |d: DVec3| if tracer.trace(origin, d).is_none() { 1.0 } else { 0.0 };
    let f = |d: DVec3| {
        let cosine = normal.dot(d);
        if cosine <= 0.0 {
            0.0
        } else {
            cosine * visible(d)
        }
    };

    let coefficients = sh::project(f, 5, NODES);
    // The reference: Monte Carlo over uniformly random directions.
    let mut rng = SplitMix64(92);
    let mut sum = [0.0; 25];
    let mut sum_sq = [0.0; 25];
    let mut y = [0.0; 25];
    for _ in 0..SAMPLES {
        let z = 2.0 * rng.next_f64() - 1.0;
        let a = std::f64::consts::TAU * rng.next_f64();
        let s = (1.0 - z * z).max(0.0).sqrt();
        let d = DVec3::new(s * a.cos(), s * a.sin(), z);
        let v = f(d) * 4.0 * std::f64::consts::PI;
        sh::basis(d, 5, &mut y);
        for i in 0..25 {
            sum[i] += v * y[i];
            sum_sq[i] += (v * y[i]).powi(2);
        }
    }
    let n = SAMPLES as f64;
    let mut worst_sigmas = 0.0f64;
    for i in 0..25 {
        let mean = sum[i] / n;
        let error = ((sum_sq[i] / n - mean * mean) / n).sqrt();
        let off = (coefficients[i] - mean).abs();
        worst_sigmas = worst_sigmas.max(off / error.max(1e-9));
        assert!(
            off <= 4.0 * error && off <= 0.02,
            "coefficient {i}: quadrature {} vs Monte Carlo {mean} ± {error}",
            coefficients[i]
        );
    }

    // Parseval: the residual of the 5-band fit, and 3 bands fit worse.
    let quadrature = |g: &dyn Fn(DVec3) -> f64| sh::sphere_quadrature(NODES).map(|(d, w)| g(d) * w).sum::<f64>();
    let norm = quadrature(&|d| f(d).powi(2));
    let residual = |bands: usize| quadrature(&|d| (f(d) - sh::evaluate(&coefficients[..bands * bands], d)).powi(2));
    let (five, three) = (residual(5), residual(3));
    let parseval = norm - coefficients.iter().map(|c| c * c).sum::<f64>();
    let cosine_only = quadrature(&|d| normal.dot(d).max(0.0).powi(2));
    eprintln!(
        "sample ({c}, {r}), normal {normal:.3}: ‖f‖² {norm:.4} (unoccluded {cosine_only:.4}); residual 5 bands {five:.4} \
         (Parseval {parseval:.4}), 3 bands {three:.4}; worst coefficient {worst_sigmas:.2} σ from Monte Carlo"
    );
    assert!(
        norm < 0.8 * cosine_only,
        "the point is hardly occluded: {norm} vs {cosine_only}"
    );
    assert!((five - parseval).abs() <= 0.02 * norm, "Parseval: {five} vs {parseval}");
    assert!(five < three, "5 bands fit worse than 3: {five} vs {three}");

    let cosine = |d: DVec3| normal.dot(d).max(0.0);
    let fit = |d: DVec3| sh::evaluate(&coefficients, d);
    let panels = [panel(&cosine), panel(&visible), panel(&f), panel(&fit)];
    let strip = crate::test_support::side_by_side(&panels, PANEL);
    crate::test_support::dump_pngs(&[("cosine-visibility-sh", &strip)], 4 * PANEL, PANEL);
}
