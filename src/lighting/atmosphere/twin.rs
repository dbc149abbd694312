//! The CPU twin of the transmittance lookup table (Bruneton 2017 §"Transmittance",
//! Hillaire 2020 §5.1): the transmittance from a point at radius r along a
//! direction of zenith cosine μ to the top of the atmosphere, by numerical
//! integration of the extinction in f64; and the mapping between the
//! table's texels and (r, μ) that `glsl/include/atmosphere_physical.glsl`
//! implements. The renderer uses [`sun_transmittance`] for the sun's
//! radiance at the ground (`LightingFrame.sun_radiance`).

use glam::Vec3;

use super::parameters::AtmosphereParameters;

/// Integration steps of the CPU twin (midpoint rule).
pub const TWIN_STEPS: usize = 1024;

/// Distance (m) from radius `r` along zenith cosine `mu` to the top of the
/// atmosphere (0 above it).
pub fn distance_to_top(p: &AtmosphereParameters, r: f64, mu: f64) -> f64 {
    let top = f64::from(p.top_radius);
    let discriminant = (top - r) * (top + r) + r * r * mu * mu;
    (-r * mu + discriminant.max(0.0).sqrt()).max(0.0)
}

/// Whether the ray from radius `r` along zenith cosine `mu` meets the ground.
pub fn hits_ground(p: &AtmosphereParameters, r: f64, mu: f64) -> bool {
    let bottom = f64::from(p.bottom_radius);
    mu < 0.0 && (bottom - r) * (bottom + r) + r * r * mu * mu >= 0.0
}

/// Optical depth (per channel, dimensionless) from radius `r` (m) along
/// zenith cosine `mu` to the top of the atmosphere, ignoring the ground.
pub fn optical_depth_to_top(p: &AtmosphereParameters, r: f64, mu: f64) -> [f64; 3] {
    let length = distance_to_top(p, r, mu);
    let dt = length / TWIN_STEPS as f64;
    let bottom = f64::from(p.bottom_radius);
    let mut depth = [0.0f64; 3];
    for i in 0..TWIN_STEPS {
        let t = (i as f64 + 0.5) * dt;
        let radius = (r * r + t * t + 2.0 * r * mu * t).max(0.0).sqrt();
        let sigma = p.extinction(radius - bottom);
        for (d, s) in depth.iter_mut().zip(sigma) {
            *d += s * dt;
        }
    }
    depth
}

/// Transmittance from radius `r` (m) along zenith cosine `mu` to the top of
/// the atmosphere, ignoring the ground (what the lookup table stores).
pub fn transmittance_to_top(p: &AtmosphereParameters, r: f64, mu: f64) -> Vec3 {
    let d = optical_depth_to_top(p, r, mu);
    Vec3::new((-d[0]).exp() as f32, (-d[1]).exp() as f32, (-d[2]).exp() as f32)
}

/// Transmittance of sunlight reaching altitude `altitude_m` (m above the
/// ground level, the bottom of the atmosphere) from the direction
/// `sun_dir` (towards the sun, +Z up, normalised here): 0 when the centre
/// of the sun is below the planet's horizon; 1 above the atmosphere; 0 for
/// a direction that is not a finite non-zero vector.
pub fn sun_transmittance(p: &AtmosphereParameters, altitude_m: f32, sun_dir: Vec3) -> Vec3 {
    let dir = sun_dir.normalize_or_zero();
    if dir == Vec3::ZERO || !altitude_m.is_finite() {
        return Vec3::ZERO;
    }
    let r = f64::from(p.bottom_radius) + f64::from(altitude_m.clamp(0.0, p.thickness()));
    let mu = f64::from(dir.z);
    if hits_ground(p, r, mu) {
        return Vec3::ZERO;
    }
    transmittance_to_top(p, r, mu)
}

/// (r, μ) of the transmittance table at unit coordinates `(x_mu, x_r)` in
/// 0..=1 (the texel centres of a W×H table are x_mu = i / (W − 1),
/// x_r = j / (H − 1)). Bruneton's mapping: x_r is the distance to the
/// horizon, x_mu the distance to the top between its minimum and maximum,
/// so every row spans zenith (x_mu = 0) to horizon (x_mu = 1).
#[cfg(test)]
pub fn transmittance_lut_r_mu(p: &AtmosphereParameters, x_mu: f64, x_r: f64) -> (f64, f64) {
    let (bottom, top) = (f64::from(p.bottom_radius), f64::from(p.top_radius));
    let h = (top * top - bottom * bottom).sqrt();
    let rho = h * x_r.clamp(0.0, 1.0);
    let r = (rho * rho + bottom * bottom).sqrt();
    let (d_min, d_max) = (top - r, rho + h);
    let d = d_min + x_mu.clamp(0.0, 1.0) * (d_max - d_min);
    let mu = if d <= 0.0 {
        1.0
    } else {
        ((h * h - rho * rho - d * d) / (2.0 * r * d)).clamp(-1.0, 1.0)
    };
    (r, mu)
}

/// Inverse of [`transmittance_lut_r_mu`]: unit coordinates (x_mu, x_r) of
/// (r, μ) for a direction above the horizon.
#[cfg(test)]
pub fn transmittance_lut_unit(p: &AtmosphereParameters, r: f64, mu: f64) -> (f64, f64) {
    let (bottom, top) = (f64::from(p.bottom_radius), f64::from(p.top_radius));
    let h = (top * top - bottom * bottom).sqrt();
    let rho = (r * r - bottom * bottom).max(0.0).sqrt();
    let d = distance_to_top(p, r, mu);
    let (d_min, d_max) = (top - r, rho + h);
    let x_mu = if d_max > d_min {
        (d - d_min) / (d_max - d_min)
    } else {
        0.0
    };
    (x_mu.clamp(0.0, 1.0), (rho / h).clamp(0.0, 1.0))
}

/// Azimuth from the sun's φ and zenith angle θ (rad) of the sky-view
/// table at unit coordinates `(x, y)` for a camera at radius `r` (m), as
/// `atmosphere_sky_view_angles` in the GLSL: φ = π x², and the horizon
/// mapping of Hillaire 2020 §5.3, θ = θ_h (1 − (1 − 2y)²) above the horizon
/// (y < 1/2), θ_h + β (2y − 1)² below it, cos β = √(r² − R²) / r,
/// θ_h = π − β.
#[cfg(test)]
pub fn sky_view_angles(p: &AtmosphereParameters, r: f64, x: f64, y: f64) -> (f64, f64) {
    let beta = sky_view_beta(p, r);
    let horizon = std::f64::consts::PI - beta;
    let theta = if y < 0.5 {
        let c = 1.0 - 2.0 * y;
        horizon * (1.0 - c * c)
    } else {
        let c = 2.0 * y - 1.0;
        horizon + beta * c * c
    };
    (std::f64::consts::PI * x * x, theta)
}

/// Inverse of [`sky_view_angles`] (`atmosphere_sky_view_unit` in the GLSL).
#[cfg(test)]
pub fn sky_view_unit(p: &AtmosphereParameters, r: f64, phi: f64, theta: f64) -> (f64, f64) {
    let beta = sky_view_beta(p, r);
    let horizon = std::f64::consts::PI - beta;
    let y = if theta < horizon {
        0.5 * (1.0 - (1.0 - theta / horizon).max(0.0).sqrt())
    } else {
        0.5 + 0.5 * ((theta - horizon) / beta.max(1e-6)).clamp(0.0, 1.0).sqrt()
    };
    let x = (phi / std::f64::consts::PI).clamp(0.0, 1.0).sqrt();
    (x.clamp(0.0, 1.0), y.clamp(0.0, 1.0))
}

/// β: the angle between the nadir and the horizon seen from radius `r`.
#[cfg(test)]
fn sky_view_beta(p: &AtmosphereParameters, r: f64) -> f64 {
    let bottom = f64::from(p.bottom_radius);
    ((r * r - bottom * bottom).max(0.0).sqrt() / r).clamp(-1.0, 1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn earth() -> AtmosphereParameters {
        AtmosphereParameters::default()
    }

    #[test]
    fn vertical_optical_depth_matches_the_closed_form() {
        // Straight up from the ground: τ = β_R H_R + β_M,ext H_M + ozone tent
        // area (the exponentials are cut at the top, exp(−100/8) ≈ 4·10⁻⁶).
        let p = earth();
        let d = optical_depth_to_top(&p, f64::from(p.bottom_radius), 1.0);
        for (i, got) in d.into_iter().enumerate() {
            let expected = f64::from(p.rayleigh_scattering[i]) * 8_000.0
                + f64::from(p.mie_extinction[i]) * 1_200.0
                + f64::from(p.ozone_absorption[i]) * 15_000.0;
            assert!((got / expected - 1.0).abs() < 1e-3, "channel {i}: {got} vs {expected}");
        }
    }

    #[test]
    fn the_sun_reddens_towards_the_horizon() {
        let p = earth();
        let noon = sun_transmittance(&p, 0.0, Vec3::Z);
        let low = sun_transmittance(&p, 0.0, Vec3::new(0.98, 0.0, 0.2).normalize());
        let horizon = sun_transmittance(&p, 0.0, Vec3::X);
        assert!(noon.x > 0.8 && noon.z > 0.6, "{noon}");
        assert!(low.x / low.z > noon.x / noon.z);
        assert!(horizon.x / horizon.z > low.x / low.z);
        assert!(horizon.max_element() < 0.2 && horizon.min_element() >= 0.0, "{horizon}");
        assert_eq!(sun_transmittance(&p, 0.0, Vec3::new(1.0, 0.0, -0.1)), Vec3::ZERO);
        assert_eq!(sun_transmittance(&p, 0.0, Vec3::ZERO), Vec3::ZERO);
        // Higher up, more light and a sun just below the local horizontal is seen.
        let high = sun_transmittance(&p, 3_000.0, Vec3::new(0.98, 0.0, 0.2).normalize());
        assert!(high.z > low.z);
        assert!(sun_transmittance(&p, 3_000.0, Vec3::new(1.0, 0.0, -0.01)).z > 0.0);
    }

    #[test]
    fn lut_mapping_round_trips_and_spans_zenith_to_horizon() {
        let p = earth();
        for &x_r in &[0.0, 0.1, 0.5, 1.0] {
            let (r0, mu0) = transmittance_lut_r_mu(&p, 0.0, x_r);
            assert!((mu0 - 1.0).abs() < 1e-9, "zenith at x_mu = 0");
            let (r1, mu1) = transmittance_lut_r_mu(&p, 1.0, x_r);
            assert_eq!(r0, r1);
            // x_mu = 1 is the horizon: the ray grazes the ground.
            let horizon = -((r1 * r1 - f64::from(p.bottom_radius).powi(2)).max(0.0).sqrt() / r1);
            assert!((mu1 - horizon).abs() < 1e-6, "{mu1} vs {horizon}");
            for &x_mu in &[0.05, 0.3, 0.7, 0.95] {
                let (r, mu) = transmittance_lut_r_mu(&p, x_mu, x_r);
                let (u, v) = transmittance_lut_unit(&p, r, mu);
                assert!((u - x_mu).abs() < 1e-6 && (v - x_r).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn more_aerosols_less_sun() {
        let clear = AtmosphereParameters::for_turbidity(2.0).unwrap();
        let hazy = AtmosphereParameters::for_turbidity(6.0).unwrap();
        let dir = Vec3::new(0.8, 0.0, 0.6);
        assert!(sun_transmittance(&hazy, 0.0, dir).y < sun_transmittance(&clear, 0.0, dir).y);
    }

    #[test]
    fn sky_view_mapping_puts_the_horizon_in_the_middle() {
        let p = earth();
        let r = f64::from(p.bottom_radius) + 500.0;
        let (_, zenith) = sky_view_angles(&p, r, 0.3, 0.0);
        assert_eq!(zenith, 0.0);
        let (_, nadir) = sky_view_angles(&p, r, 0.3, 1.0);
        assert!((nadir - std::f64::consts::PI).abs() < 1e-9);
        // The geometric horizon, a little below the horizontal (0.72° at 500 m).
        let (_, horizon) = sky_view_angles(&p, r, 0.0, 0.5);
        let dip = horizon - std::f64::consts::FRAC_PI_2;
        assert!(
            (dip - (2.0 * 500.0 / f64::from(p.bottom_radius)).sqrt()).abs() < 1e-4,
            "{dip}"
        );
        let (sun_side, _) = sky_view_angles(&p, r, 0.0, 0.2);
        assert_eq!(sun_side, 0.0);
        for &(x, y) in &[(0.1, 0.1), (0.5, 0.49), (0.9, 0.51), (1.0, 0.8)] {
            let (phi, theta) = sky_view_angles(&p, r, x, y);
            let (u, v) = sky_view_unit(&p, r, phi, theta);
            assert!((u - x).abs() < 1e-9 && (v - y).abs() < 1e-9, "({x}, {y}) → ({u}, {v})");
        }
    }
}
