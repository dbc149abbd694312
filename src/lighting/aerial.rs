//! Aerial perspective (§6.3 "Aerial Perspective", eq. 6.16, 6.17; §9.1;
//! `ALGORITHMS.md` §6): the text's homogeneous medium, with the density of
//! each component graded along the ray (below).
//! GPU twin: `glsl/include/aerial_perspective.glsl`.
//!
//! Along a view ray of length s through a homogeneous medium of extinction
//! `β = β_R + β_M` (per channel) the radiance L₀ of a surface arrives as
//! `L = L₀·e^(−βs) + L_in` (eq. 6.16). With single scattering of the sun
//! only (irradiance E_sun, unattenuated along the ray), the in-scattered
//! part integrates in closed form (eq. 6.17):
//! `L_in = ∫₀ˢ e^(−βx)·E_sun·β(θ) dx = E_sun·(β(θ)/β)·(1 − e^(−βs))`,
//! `β(θ) = β_R·3/(16π)(1 + cos²θ) + β_M·f_HG(θ)` (Rayleigh and
//! Henyey–Greenstein phases, θ the angle between the view ray and the sun).
//! So `L_in = (1 − e^(−βs))·L_∞` where `L_∞ = E_sun·β(θ)/β` is the radiance
//! of an infinitely long ray: [`AerialCoefficients::single_scattering`].
//!
//! The renderer keeps that form but takes `L_∞` from the sky model instead:
//! `L_∞(d) = sky_radiance(d')`, d' the view direction with its elevation
//! clamped into the horizon band ([`horizon_band_direction`]). The sky just
//! above the horizon is (nearly) such an infinitely long ray through the
//! near-ground air, and it carries what single scattering misses (sky light,
//! multiple scattering, the model's absolute calibration). Above all, a
//! distant mountain then fades into exactly the sky behind it: as s → ∞,
//! L → the sky at the horizon. Where a sky model gives nothing, the single
//! scattering form is the fallback (the Preetham sky never does: it keeps a
//! twilight floor, see `preetham`).
//!
//! The text's medium is homogeneous, which holds for views near the ground
//! but fogs a view from above: looking down from 12 km, β at the ground
//! over 10 km of air gives a transmittance of about 0.4 at 550 nm, and the
//! ground all but vanishes. So the extinction is graded: `τ = (β_R·ρ_R +
//! β_M·ρ_M)·s`, where ρ is the mean relative density along the straight ray
//! of an exponential profile with the atmosphere's scale heights (8 km
//! Rayleigh, 1.2 km Mie; `LightingFrame.planet.zw`) above the terrain's
//! ground (`mie.w`): [`mean_density`], [`optical_depth`]. The same view
//! then keeps a transmittance of about 0.85. Rays near the ground are
//! nearly unchanged (ρ ≈ e^(−z/H)).
//!
//! Coefficients at the ground: Rayleigh from the molecular formula (§6.3
//! eq. 6.5, Preetham 1999 appendix) at the channel wavelengths 680, 550,
//! 440 nm, ≈ (5.8, 13.6, 33.1)·10⁻⁶/m, ∝ λ⁻⁴; Mie from the turbidity through
//! Ångström's law of Preetham's appendix A.1, the same aerosols that redden
//! the sun: aerosol optical depth `τ_M(λ) = β_Å·λ_µm^−1.3`, `β_Å = 0.04608T −
//! 0.04586`, spread over the aerosols' optical length at the zenith, 1.25 km
//! (§6.3 Fig. 6.7): `β_M(λ) = τ_M(λ) / 1250 m`. At T = 2 that is 8·10⁻⁵/m
//! at 550 nm, a meteorological range (3.912/β) of ≈ 41 km. This agrees with
//! the definition of turbidity (eq. 6.8): τ_M ≈ (T − 1)·τ_R. The Mie phase is
//! Henyey–Greenstein with g = [`MIE_G`].

#[cfg(test)]
use glam::Vec2;
use glam::Vec3;

use super::constants::LightingFrame;
use super::preetham::check_turbidity;
#[cfg(test)]
use super::preetham::COS_THETA_MIN;
use crate::error::Result;

/// Representative wavelengths (nm) of R, G, B.
pub const WAVELENGTHS_NM: [f32; 3] = [680.0, 550.0, 440.0];
/// Henyey–Greenstein asymmetry of aerosol scattering.
pub const MIE_G: f32 = 0.76;
/// Optical length of the aerosols at the zenith (m), §6.3 Fig. 6.7.
pub const AEROSOL_OPTICAL_LENGTH_M: f32 = 1250.0;
/// Scale heights (m) of the density of molecules and aerosols with these
/// coefficients: the molecules' optical length at the zenith (8.4 km, which
/// the Rayleigh coefficients give with the standard atmosphere's optical
/// depth) and [`AEROSOL_OPTICAL_LENGTH_M`], so that the graded columns
/// integrate to the same optical depths the coefficients were made from.
pub const SCALE_HEIGHTS_M: (f32, f32) = (8_400.0, AEROSOL_OPTICAL_LENGTH_M);
/// `sin` of the top of the horizon band (10°) the distant radiance is read
/// from; the bottom is `preetham::COS_THETA_MIN` (≈ 0.57°).
#[cfg(test)]
pub const HORIZON_BAND_SIN: f32 = 0.173_648_18;

/// Sea-level Rayleigh scattering coefficient (1/m) at `lambda_nm`:
/// `8π³(n² − 1)²/(3Nλ⁴)·(6 + 3p)/(6 − 7p)`, n = 1.0003, N = 2.545·10²⁵/m³,
/// depolarisation p = 0.035.
pub fn rayleigh_coefficient(lambda_nm: f32) -> f32 {
    let (n, big_n, p) = (1.0003f64, 2.545e25f64, 0.035f64);
    let l = lambda_nm as f64 * 1e-9;
    let pi3 = std::f64::consts::PI.powi(3);
    (8.0 * pi3 * (n * n - 1.0).powi(2) / (3.0 * big_n * l.powi(4)) * (6.0 + 3.0 * p) / (6.0 - 7.0 * p)) as f32
}

/// Ground-level Mie (aerosol) scattering coefficient (1/m) at `lambda_nm`
/// for turbidity `t` (see the module documentation).
pub fn mie_coefficient(lambda_nm: f32, t: f32) -> f32 {
    let beta = (0.04608 * t - 0.04586).max(0.0);
    beta * (lambda_nm / 1000.0).powf(-1.3) / AEROSOL_OPTICAL_LENGTH_M
}

/// Rayleigh phase function `3/(16π)(1 + cos²θ)` (1/sr).
#[cfg(test)]
pub fn rayleigh_phase(cos_theta: f32) -> f32 {
    3.0 / (16.0 * std::f32::consts::PI) * (1.0 + cos_theta * cos_theta)
}

/// Henyey–Greenstein phase `(1 − g²)/(4π(1 + g² − 2g cos θ)^(3/2))` (eq. 6.7).
#[cfg(test)]
pub fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    (1.0 - g * g) / (4.0 * std::f32::consts::PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// Scattering coefficients of the air at the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AerialCoefficients {
    /// β_R per channel (1/m).
    pub rayleigh: Vec3,
    /// β_M per channel (1/m).
    pub mie: Vec3,
    /// Henyey–Greenstein g of the Mie phase.
    pub g: f32,
}

impl AerialCoefficients {
    /// The coefficients at turbidity `t` (1.7..=10).
    pub fn for_turbidity(t: f32) -> Result<AerialCoefficients> {
        check_turbidity(t)?;
        Ok(AerialCoefficients {
            rayleigh: Vec3::from_array(WAVELENGTHS_NM.map(rayleigh_coefficient)),
            mie: Vec3::from_array(WAVELENGTHS_NM.map(|l| mie_coefficient(l, t))),
            g: MIE_G,
        })
    }

    /// β = β_R + β_M.
    #[cfg(test)]
    pub fn extinction(&self) -> Vec3 {
        self.rayleigh + self.mie
    }

    /// The single-scattering radiance of an infinitely long ray,
    /// `L_∞ = E_sun·β(θ)/β`, for sun irradiance `e_sun` and the cosine of
    /// the angle between the view ray and the sun.
    #[cfg(test)]
    pub fn single_scattering(&self, e_sun: Vec3, cos_theta: f32) -> Vec3 {
        let cos_theta = cos_theta.clamp(-1.0, 1.0);
        let angular = self.rayleigh * rayleigh_phase(cos_theta) + self.mie * henyey_greenstein(cos_theta, self.g);
        e_sun * angular / self.extinction()
    }

    /// Writes `rayleigh` (rgb β_R, w g), `mie.rgb` (β_M) and the scale
    /// heights `planet.zw` ([`SCALE_HEIGHTS_M`]); `mie.w` (the ground
    /// altitude) and the radii `planet.xy` are left alone.
    pub fn fill(&self, frame: &mut LightingFrame) {
        frame.rayleigh = self.rayleigh.extend(self.g).to_array();
        frame.mie[..3].copy_from_slice(&self.mie.to_array());
        frame.planet[2] = SCALE_HEIGHTS_M.0;
        frame.planet[3] = SCALE_HEIGHTS_M.1;
    }
}

/// `L = L₀·e^(−τ) + (1 − e^(−τ))·L_∞`: radiance `l0` seen through air of
/// optical depth `tau` ([`optical_depth`]) whose infinitely long ray has
/// radiance `l_inf`. CPU twin of the GLSL `aerial_perspective`.
#[cfg(test)]
pub fn aerial_perspective(l0: Vec3, tau: Vec3, l_inf: Vec3) -> Vec3 {
    let t = (-tau.max(Vec3::ZERO)).exp();
    l0 * t + (Vec3::ONE - t) * l_inf
}

/// Mean density along a straight ray between heights `z0` and `z1` (m)
/// above the ground, relative to the ground's, for an exponential profile
/// of scale height `h` (m): `(e^(−z0/h) − e^(−z1/h)) / ((z1 − z0)/h)`, and
/// `e^(−z̄/h)` for a level ray. Heights below the ground count as the
/// ground; `h ≤ 0` means constant density (1). Twin of
/// `aerial_mean_density`.
#[cfg(test)]
pub fn mean_density(z0: f32, z1: f32, h: f32) -> f32 {
    if h.is_nan() || h <= 0.0 {
        return 1.0;
    }
    let (a, b) = (z0.max(0.0) / h, z1.max(0.0) / h);
    let d = b - a;
    if d.abs() < 1e-3 {
        (-0.5 * (a + b)).exp()
    } else {
        ((-a).exp() - (-b).exp()) / d
    }
}

/// Optical depth τ (per channel) of `s` metres of air between heights
/// `z0` and `z1` above the ground: the ground coefficients scaled by the
/// mean density of their components (`scale_heights`: Rayleigh, Mie, m).
#[cfg(test)]
pub fn optical_depth(coefficients: &AerialCoefficients, s: f32, z0: f32, z1: f32, scale_heights: (f32, f32)) -> Vec3 {
    let rho_r = mean_density(z0, z1, scale_heights.0);
    let rho_m = mean_density(z0, z1, scale_heights.1);
    (coefficients.rayleigh * rho_r + coefficients.mie * rho_m) * s.max(0.0)
}

/// The direction the distant radiance is read from: `d` (any length) with
/// its elevation clamped into the horizon band, azimuth kept (straight up or
/// down: north). Twin of `aerial_sky_direction` (aerial_perspective.glsl).
#[cfg(test)]
pub fn horizon_band_direction(d: Vec3) -> Vec3 {
    let d = d.normalize_or(Vec3::Y);
    let z = d.z.clamp(COS_THETA_MIN, HORIZON_BAND_SIN);
    let h = d.truncate().length();
    let xy = if h > 1e-6 { d.truncate() / h } else { Vec2::Y };
    (xy * (1.0 - z * z).sqrt()).extend(z)
}

/// `L_∞` of the renderer: `sky` (a sky model's radiance along a direction)
/// in the horizon band along `view`; where the sky gives nothing (all
/// zero), single scattering of `e_sun` from the unit direction `sun`.
#[cfg(test)]
pub fn distant_radiance(
    sky: impl Fn(Vec3) -> Vec3,
    coefficients: &AerialCoefficients,
    view: Vec3,
    sun: Vec3,
    e_sun: Vec3,
) -> Vec3 {
    let d = horizon_band_direction(view);
    let l = sky(d);
    if l.max_element() > 0.0 {
        l
    } else {
        coefficients.single_scattering(e_sun, d.dot(sun))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::preetham::PreethamSky;

    #[test]
    fn rayleigh_follows_lambda_to_the_minus_four() {
        let c = AerialCoefficients::for_turbidity(3.0).unwrap();
        let expected = (680.0f32 / 440.0).powi(4);
        assert!((c.rayleigh.z / c.rayleigh.x / expected - 1.0).abs() < 1e-4);
        for (got, want) in c.rayleigh.to_array().into_iter().zip([5.8e-6, 13.5e-6, 33.1e-6]) {
            assert!((got / want - 1.0).abs() < 0.02, "{got} vs {want}");
        }
    }

    #[test]
    fn mie_follows_turbidity() {
        let c2 = AerialCoefficients::for_turbidity(2.0).unwrap();
        let c6 = AerialCoefficients::for_turbidity(6.0).unwrap();
        assert!((c2.mie.y / 8.06e-5 - 1.0).abs() < 0.01, "{}", c2.mie.y);
        assert!(c6.mie.y > 4.0 * c2.mie.y && c2.mie.z > c2.mie.x);
        let range_km = 3.912 / c2.extinction().y / 1000.0;
        assert!((30.0..60.0).contains(&range_km), "{range_km}");
        // Turbidity's definition (eq. 6.8): τ_M ≈ (T − 1)·τ_R at 550 nm with
        // the molecules' optical length of 8.4 km.
        let tau_r = c2.rayleigh.y * 8400.0;
        assert!((c2.mie.y * AEROSOL_OPTICAL_LENGTH_M / tau_r - 1.0).abs() < 0.2);
        assert_eq!(
            AerialCoefficients::for_turbidity(1.0).unwrap_err().parameter(),
            Some("lighting.turbidity")
        );
    }

    #[test]
    fn aerial_perspective_is_extinction_plus_inscattering() {
        let (l0, l_inf) = (Vec3::new(100.0, 200.0, 50.0), Vec3::new(3000.0, 4000.0, 6000.0));
        let beta = AerialCoefficients::for_turbidity(3.0).unwrap().extinction();
        for d in [0.0f32, 100.0, 1e3, 1e4, 5e4] {
            let got = aerial_perspective(l0, beta * d, l_inf);
            for c in 0..3 {
                let t = (-(beta[c] as f64) * d as f64).exp();
                let want = l0[c] as f64 * t + (1.0 - t) * l_inf[c] as f64;
                assert!((got[c] as f64 / want - 1.0).abs() < 1e-5, "{d} {c}");
            }
        }
        assert_eq!(aerial_perspective(l0, Vec3::ZERO, l_inf), l0);
        assert!((aerial_perspective(l0, beta * 1e7, l_inf) - l_inf).length() < 1e-3);
    }

    /// The mean density against a numerical integral of e^(−z/h) along
    /// the ray, level rays, rays into the ground and the constant case.
    #[test]
    fn mean_density_integrates_the_exponential_profile() {
        for (z0, z1, h) in [
            (0.0f32, 10_000.0f32, 8_000.0f32),
            (12_000.0, 2_000.0, 1_200.0),
            (500.0, 500.4, 1_200.0),
            (0.0, 300.0, 1_200.0),
        ] {
            let n = 100_000;
            let numeric: f64 = (0..n)
                .map(|i| {
                    let z = z0 as f64 + (z1 - z0) as f64 * (i as f64 + 0.5) / n as f64;
                    (-z / h as f64).exp()
                })
                .sum::<f64>()
                / n as f64;
            let got = mean_density(z0, z1, h) as f64;
            assert!(
                (got / numeric - 1.0).abs() < 1e-3,
                "{z0}..{z1} h {h}: {got} vs {numeric}"
            );
        }
        assert_eq!(mean_density(-50.0, -10.0, 8_000.0), 1.0);
        assert_eq!(mean_density(100.0, 9_000.0, 0.0), 1.0);
        // Looking down from 10 km through a 1.2 km Mie layer: about an eighth.
        assert!((mean_density(10_000.0, 0.0, 1_200.0) - 0.12).abs() < 0.01);
    }

    #[test]
    fn single_scattering_matches_the_integral() {
        let c = AerialCoefficients::for_turbidity(2.5).unwrap();
        let e_sun = Vec3::new(1.0e5, 1.1e5, 0.9e5);
        for cos in [-1.0f32, 0.0, 0.7, 0.99] {
            let l_inf = c.single_scattering(e_sun, cos);
            let s = 20_000.0f64;
            let n = 4000;
            for ch in 0..3 {
                let beta = c.extinction()[ch] as f64;
                let angular = (c.rayleigh[ch] * rayleigh_phase(cos) + c.mie[ch] * henyey_greenstein(cos, c.g)) as f64;
                let dx = s / n as f64;
                let integral: f64 = (0..n)
                    .map(|i| (-beta * (i as f64 + 0.5) * dx).exp() * e_sun[ch] as f64 * angular * dx)
                    .sum();
                let closed = l_inf[ch] as f64 * (1.0 - (-beta * s).exp());
                assert!((closed / integral - 1.0).abs() < 1e-3, "{cos} {ch}");
            }
        }
        // Both phases integrate to 1 over the sphere.
        let n = 20_000;
        let (mut r, mut m) = (0.0f64, 0.0f64);
        for i in 0..n {
            let mu = -1.0 + 2.0 * (i as f32 + 0.5) / n as f32;
            let w = 2.0 * std::f64::consts::PI * 2.0 / n as f64;
            r += rayleigh_phase(mu) as f64 * w;
            m += henyey_greenstein(mu, MIE_G) as f64 * w;
        }
        assert!((r - 1.0).abs() < 1e-3 && (m - 1.0).abs() < 1e-2, "{r} {m}");
    }

    #[test]
    fn distant_radiance_is_the_sky_at_the_horizon() {
        let sky = PreethamSky::new(Vec3::new(0.3, -0.8, 0.4), 3.0).unwrap();
        let c = AerialCoefficients::for_turbidity(3.0).unwrap();
        for view in [
            Vec3::new(1.0, 0.0, -0.3),
            Vec3::new(0.0, 1.0, 0.05),
            Vec3::new(-1.0, 1.0, 2.0),
            -Vec3::Z,
        ] {
            let d = horizon_band_direction(view);
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(d.z >= COS_THETA_MIN - 1e-6 && d.z <= HORIZON_BAND_SIN + 1e-6);
            if view.truncate().length() > 0.0 {
                assert!(d.truncate().normalize().dot(view.truncate().normalize()) > 0.9999);
            }
            let l = distant_radiance(|x| sky.radiance(x), &c, view, sky.sun(), sky.sun_irradiance());
            assert_eq!(l, sky.radiance(d));
        }
        // A sky that gives nothing: single scattering of the sun.
        let e = Vec3::splat(1e5);
        let l = distant_radiance(|_| Vec3::ZERO, &c, Vec3::X, Vec3::Y, e);
        assert_eq!(l, c.single_scattering(e, horizon_band_direction(Vec3::X).dot(Vec3::Y)));
    }

    #[test]
    fn fill_keeps_the_ground_altitude() {
        let mut frame = <LightingFrame as bytemuck::Zeroable>::zeroed();
        frame.mie[3] = 1234.0;
        let c = AerialCoefficients::for_turbidity(2.0).unwrap();
        c.fill(&mut frame);
        assert_eq!(frame.mie, [c.mie.x, c.mie.y, c.mie.z, 1234.0]);
        assert_eq!(frame.rayleigh, [c.rayleigh.x, c.rayleigh.y, c.rayleigh.z, MIE_G]);
    }
}
