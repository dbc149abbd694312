//! The physical atmosphere's parameters: an Earth-like planet with Rayleigh
//! scattering by air molecules, Mie scattering and absorption by aerosols,
//! and ozone absorption, as in Bruneton 2017 ("A Qualitative and
//! Quantitative Evaluation of 8 Clear Sky Models", its reference
//! implementation `precomputed_atmospheric_scattering`) and Hillaire 2020
//! ("A Scalable and Production Ready Sky and Atmosphere Rendering
//! Technique", Table 1). SI units: metres, 1/m.
//!
//! The bottom of the atmosphere (radius [`AtmosphereParameters::bottom_radius`])
//! is the terrain's ground level, the world altitude `LightingFrame.mie.w`:
//! an altitude in the atmosphere is a world z minus that ground altitude.

use glam::Vec3;

use crate::error::{Error, Result};
use crate::lighting::constants::{
    LightingFrame, SUN_ANGULAR_RADIUS, SUN_COLOUR_EXTRATERRESTRIAL, SUN_LUMINANCE_EXTRATERRESTRIAL,
};

/// Aerosol (Mie) extinction coefficient at the ground (1/m, grey) of a sky
/// of turbidity `t` under the atmosphere `p`'s Rayleigh and Mie profiles.
///
/// Preetham, Shirley and Smits 1999 define the turbidity as the ratio of
/// the optical thickness of the atmosphere with haze to that of pure air,
/// T = (t_m + t_h) / t_m, so the aerosols' vertical optical thickness is
/// t_h = (T − 1) t_m: the Mie density is proportional to T − 1. Here t_m is
/// the Rayleigh thickness of the green (≈ 550 nm) channel, β_R,g H_R ≈ 0.108,
/// and t_h = β_M,ext H_M: T = 2 gives β_M,ext = 9.0·10⁻⁵ /m (visibility
/// ≈ 38 km), T = 3 twice that, T = 10 nine times. Hillaire's and
/// Bruneton's default (4.40·10⁻⁶ /m, thickness 0.0053) is an exceptionally
/// clear T ≈ 1.05, below the 1.7 the Lighting accepts; normalising T ≈ 2–3
/// to it would leave the zenith 5× darker than Preetham's at the same T.
pub fn mie_extinction_for_turbidity(p: &AtmosphereParameters, t: f32) -> f32 {
    let molecular = p.rayleigh_scattering.y * p.rayleigh_scale_height;
    ((t - 1.0) * molecular / p.mie_scale_height).max(0.0)
}

/// Solid angle of the sun's disc (sr): 2π (1 − cos α).
pub fn sun_solid_angle() -> f32 {
    // 1 − cos α = 2 sin²(α/2), exact in f32 for a small α.
    let s = (0.5 * SUN_ANGULAR_RADIUS).sin();
    4.0 * std::f32::consts::PI * s * s
}

/// Solar irradiance at the top of the atmosphere on a plane facing the sun,
/// linear sRGB with luminance in lux: the extraterrestrial disc luminance ×
/// its colour × its solid angle (the same absolute scale as the Preetham sky).
pub fn solar_irradiance() -> Vec3 {
    Vec3::from_array(SUN_COLOUR_EXTRATERRESTRIAL) * (SUN_LUMINANCE_EXTRATERRESTRIAL * sun_solid_angle())
}

/// An Earth-like atmosphere (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtmosphereParameters {
    /// Radius of the ground, the bottom of the atmosphere (m).
    pub bottom_radius: f32,
    /// Radius of the top of the atmosphere (m).
    pub top_radius: f32,
    /// Rayleigh scattering coefficient at the bottom (1/m); Rayleigh does
    /// not absorb, so it is the extinction too.
    pub rayleigh_scattering: Vec3,
    /// Rayleigh density exp(−h / H_R): H_R (m).
    pub rayleigh_scale_height: f32,
    /// Mie scattering coefficient at the bottom (1/m).
    pub mie_scattering: Vec3,
    /// Mie extinction coefficient at the bottom (1/m): scattering + absorption.
    pub mie_extinction: Vec3,
    /// Mie density exp(−h / H_M): H_M (m).
    pub mie_scale_height: f32,
    /// Asymmetry g of the Cornette–Shanks phase function of Mie scattering.
    pub mie_g: f32,
    /// Ozone absorption coefficient at the peak of its layer (1/m).
    pub ozone_absorption: Vec3,
    /// Altitude of the ozone peak (m); the density is a tent falling
    /// linearly to 0 at ± [`AtmosphereParameters::ozone_half_width`].
    pub ozone_center: f32,
    /// Half-width of the ozone tent (m).
    pub ozone_half_width: f32,
    /// Lambertian albedo of the ground under the atmosphere (only in the
    /// multiple-scattering lookup table).
    pub ground_albedo: Vec3,
    /// Solar irradiance at the top of the atmosphere ([`solar_irradiance`]).
    pub solar_irradiance: Vec3,
}

impl Default for AtmosphereParameters {
    /// The Earth of Bruneton 2017 / Hillaire 2020 (its aerosols: turbidity
    /// ≈ 1.05, see [`mie_extinction_for_turbidity`]).
    fn default() -> Self {
        AtmosphereParameters {
            bottom_radius: 6_360_000.0,
            top_radius: 6_460_000.0,
            rayleigh_scattering: Vec3::new(5.802e-6, 13.558e-6, 33.1e-6),
            rayleigh_scale_height: 8_000.0,
            mie_scattering: Vec3::splat(3.996e-6),
            mie_extinction: Vec3::splat(4.40e-6),
            mie_scale_height: 1_200.0,
            mie_g: 0.8,
            ozone_absorption: Vec3::new(0.650e-6, 1.881e-6, 0.085e-6),
            ozone_center: 25_000.0,
            ozone_half_width: 15_000.0,
            ground_albedo: Vec3::splat(0.3),
            solar_irradiance: solar_irradiance(),
        }
    }
}

impl AtmosphereParameters {
    /// The Earth atmosphere with the aerosols of turbidity `t`
    /// ([`mie_extinction_for_turbidity`], the single-scattering albedo of
    /// the default kept); `t` must be finite and in 1..=20.
    pub fn for_turbidity(t: f32) -> Result<AtmosphereParameters> {
        if !(1.0..=20.0).contains(&t) {
            return Err(Error::invalid(
                "lighting.turbidity",
                format!("{t}; the physical atmosphere needs 1..=20"),
            ));
        }
        let base = AtmosphereParameters::default();
        let extinction = mie_extinction_for_turbidity(&base, t);
        let albedo = base.mie_scattering / base.mie_extinction;
        Ok(AtmosphereParameters {
            mie_scattering: albedo * extinction,
            mie_extinction: Vec3::splat(extinction),
            ..base
        })
    }

    /// Thickness of the atmosphere (m).
    pub fn thickness(&self) -> f32 {
        self.top_radius - self.bottom_radius
    }

    /// Mie extinction over scattering (≥ 1; 4.40 / 3.996 for the Earth),
    /// which the shaders apply to `LightingFrame.mie`.
    pub fn mie_extinction_ratio(&self) -> f32 {
        let s = self.mie_scattering.max_element();
        if s > 0.0 {
            (self.mie_extinction.max_element() / s).max(1.0)
        } else {
            1.0
        }
    }

    /// Rayleigh density at altitude `h` (m) above the bottom, in 0..=1 at h ≥ 0.
    pub fn rayleigh_density(&self, h: f64) -> f64 {
        (-h / f64::from(self.rayleigh_scale_height)).exp()
    }

    /// Mie density at altitude `h` (m).
    pub fn mie_density(&self, h: f64) -> f64 {
        (-h / f64::from(self.mie_scale_height)).exp()
    }

    /// Ozone density (tent) at altitude `h` (m).
    pub fn ozone_density(&self, h: f64) -> f64 {
        let (c, w) = (f64::from(self.ozone_center), f64::from(self.ozone_half_width));
        (1.0 - (h - c).abs() / w).max(0.0)
    }

    /// Extinction coefficient (1/m) at altitude `h` (m), per channel.
    pub fn extinction(&self, h: f64) -> [f64; 3] {
        let (r, m, o) = (self.rayleigh_density(h), self.mie_density(h), self.ozone_density(h));
        std::array::from_fn(|i| {
            f64::from(self.rayleigh_scattering[i]) * r
                + f64::from(self.mie_extinction[i]) * m
                + f64::from(self.ozone_absorption[i]) * o
        })
    }

    /// Writes what the shaders read of the atmosphere into `frame`:
    /// `planet` (bottom and top radius, Rayleigh and Mie scale heights, m),
    /// `rayleigh` (rgb: Rayleigh scattering at the ground, 1/m; w: Mie g),
    /// `mie.rgb` (Mie scattering at the ground, 1/m). `mie.w` (the world
    /// altitude of the ground), the sun and the handles are left as they are.
    pub fn fill(&self, frame: &mut LightingFrame) {
        frame.planet = [
            self.bottom_radius,
            self.top_radius,
            self.rayleigh_scale_height,
            self.mie_scale_height,
        ];
        frame.rayleigh = self.rayleigh_scattering.extend(self.mie_g).to_array();
        let ground = frame.mie[3];
        frame.mie = self.mie_scattering.extend(ground).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turbidity_scales_the_aerosols_only() {
        let default = AtmosphereParameters::default();
        let reference = AtmosphereParameters::for_turbidity(3.0).unwrap();
        // T = 3: the aerosols' optical thickness twice the molecular one.
        let molecular = default.rayleigh_scattering.y * default.rayleigh_scale_height;
        let aerosols = reference.mie_extinction.y * reference.mie_scale_height;
        assert!((aerosols / molecular - 2.0).abs() < 1e-4);
        // The default is a turbidity of about 1.05.
        let t = 1.0 + default.mie_extinction.y * default.mie_scale_height / molecular;
        assert!((t - 1.05).abs() < 0.01, "{t}");
        let hazy = AtmosphereParameters::for_turbidity(6.0).unwrap();
        let clear = AtmosphereParameters::for_turbidity(1.7).unwrap();
        assert!(hazy.mie_scattering.x > reference.mie_scattering.x);
        assert!(clear.mie_scattering.x < reference.mie_scattering.x);
        assert_eq!(hazy.rayleigh_scattering, reference.rayleigh_scattering);
        assert!((hazy.mie_extinction_ratio() - 4.40 / 3.996).abs() < 1e-5);
        assert!(AtmosphereParameters::for_turbidity(f32::NAN).is_err());
        assert_eq!(
            AtmosphereParameters::for_turbidity(0.5)
                .unwrap_err()
                .parameter()
                .map(str::to_string)
                .as_deref(),
            Some("lighting.turbidity")
        );
    }

    #[test]
    fn solar_irradiance_is_luminance_times_solid_angle() {
        let e = solar_irradiance();
        let y = 0.2126 * e.x + 0.7152 * e.y + 0.0722 * e.z;
        let omega = std::f64::consts::PI * f64::from(SUN_ANGULAR_RADIUS).powi(2);
        // ≈ 1.33·10⁵ lux.
        assert!((f64::from(y) / (1.96e9 * omega) - 1.0).abs() < 1e-3, "{y}");
    }

    #[test]
    fn ozone_is_a_tent_from_10_to_40_km() {
        let p = AtmosphereParameters::default();
        assert_eq!(p.ozone_density(5_000.0), 0.0);
        assert!((p.ozone_density(25_000.0) - 1.0).abs() < 1e-12);
        assert!((p.ozone_density(17_500.0) - 0.5).abs() < 1e-12);
        assert_eq!(p.ozone_density(45_000.0), 0.0);
    }

    #[test]
    fn fill_keeps_the_ground_altitude() {
        let mut f: LightingFrame = bytemuck::Zeroable::zeroed();
        f.mie[3] = 412.0;
        AtmosphereParameters::default().fill(&mut f);
        assert_eq!(f.mie[3], 412.0);
        assert_eq!(f.planet[0], 6_360_000.0);
        assert_eq!(f.rayleigh[3], 0.8);
    }
}
