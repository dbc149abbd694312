//! The lighting a frame asks for (§6.3, §9; `ALGORITHMS.md` §6): where the
//! sun is, which sky model, exposure, sun shadows and sky light. Per frame:
//! a simulator changes the time of day between frames. The lighting
//! technique (`crate::lighting`) turns it into the per-view GPU constants
//! every shading pass reads (`glsl/include/lighting.glsl`).
//!
//! A [`Lighting`] is two things: what the renderer is built with
//! ([`LightingSetup`]: the sky-light bake, the atmosphere's lookup tables,
//! whether the Monte Carlo reference exists; changing it needs a new
//! renderer) and what each frame lights with ([`FrameLighting`]: the
//! lighting validated once, when it is set, with its derived values — the
//! sun's direction — computed once, for every technique's prepare).

use glam::Vec3;

use crate::error::{Error, Result};

/// Which sky (and aerial perspective) model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SkyModel {
    /// Preetham, Shirley and Smits 1999: the Perez distribution (§6.3).
    Preetham,
    /// Rayleigh + Mie + ozone, single and multiple scattering in lookup
    /// tables (Hillaire 2020); right for a low sun.
    #[default]
    Physical,
    /// The CIE clear sky (Pokrowski, improved by Kittler; §6.3 eq. 6.18):
    /// its luminance distribution with Preetham's zenith luminance and
    /// chromaticity at the turbidity.
    CieClear,
    /// The CIE overcast sky (Moon and Spencer; §6.3 eq. 6.19): luminance
    /// `Y_z (1 + 2 cos θ) / 3`, no direct sun, white (D65).
    CieOvercast,
}

/// Sun shadows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadowMode {
    /// Cascaded shadow maps over the view distance (terrain and points).
    #[default]
    Cascaded,
    /// Horizon maps of the height field (terrain self-shadowing, Hoffman).
    Horizon,
    Off,
}

/// How sun shadows treat the sun's disc (angular radius
/// [`crate::lighting::constants::SUN_ANGULAR_RADIUS`], 0.27°).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SunDisc {
    /// Shadow edges as sharp as the shadow map's filter (PCF tent) and a
    /// smoothstep over the disc at the horizon map's horizon.
    #[default]
    Hard,
    /// Penumbrae of the disc: the horizon map gives the disc's fraction above
    /// the horizon (a circular segment), the cascades filter with the disc
    /// at the blocker's distance (percentage-closer soft shadows, §9.5).
    Soft,
}

/// Sky light on the terrain (§9.3–9.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SkyLightMode {
    /// Monte Carlo ray tracing of the height field (still frames).
    Reference,
    /// Precomputed radiance transfer in spherical harmonics.
    #[default]
    Sh,
    /// Ambient occlusion with bent normals (eq. 9.18, 9.19).
    Ao,
    /// The sky as N×N constant patches with per-patch visibility.
    Patches,
    /// Unoccluded sky light.
    Off,
}

/// How the HDR radiance is exposed for the PNG.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Exposure {
    /// From the frame's mean log luminance (metered on the GPU).
    #[default]
    Auto,
    /// Manual exposure value at ISO 100.
    Ev100(f32),
}

/// Where the sun is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SunPosition {
    /// Elevation above the horizon and azimuth clockwise from +Y ("north"),
    /// degrees.
    Angles { elevation_deg: f32, azimuth_deg: f32 },
    /// A unit direction towards the sun (+Z up).
    Direction(Vec3),
}

/// The lighting of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    pub sun: SunPosition,
    pub sky: SkyModel,
    /// Atmospheric turbidity T (Preetham: 1.7–10; also sets the physical
    /// model's aerosol density).
    pub turbidity: f32,
    pub exposure: Exposure,
    pub shadows: ShadowMode,
    /// Penumbrae of the sun's disc in the sun shadows.
    pub sun_disc: SunDisc,
    pub sky_light: SkyLightMode,
    /// SH bands of [`SkyLightMode::Sh`]: 3 or 5.
    pub sh_bands: u32,
    /// Interreflection bounces of the sky-light transfer (0–2).
    pub bounces: u32,
    /// Sky patches per side of [`SkyLightMode::Patches`]: 4 or 8.
    pub sky_patches: u32,
    /// Every surface this albedo (white diffuse: 1) instead of its texture.
    pub albedo_override: Option<f32>,
    /// The sun is part of the sky-light environment (projected into SH,
    /// patches, sampled by the reference) instead of a separate direct term
    /// with shadows: the text's "sun + sky" comparisons (Fig. 9.4).
    pub sun_in_sky_light: bool,
    /// Aerial perspective on everything drawn (false: surfaces as if seen
    /// from up close; checks and figures).
    pub aerial_perspective: bool,
    /// Altitude (m) above which flat ground is snow-covered (classic texturing).
    pub snow_line: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            sun: SunPosition::Angles {
                elevation_deg: 25.0,
                azimuth_deg: 231.0,
            },
            sky: SkyModel::default(),
            turbidity: 3.0,
            exposure: Exposure::default(),
            shadows: ShadowMode::default(),
            sun_disc: SunDisc::default(),
            sky_light: SkyLightMode::default(),
            sh_bands: 5,
            bounces: 1,
            sky_patches: 8,
            albedo_override: None,
            sun_in_sky_light: false,
            aerial_perspective: true,
            snow_line: f32::INFINITY,
        }
    }
}

/// Unit vector towards the sun at `elevation_deg` above the horizon and
/// `azimuth_deg` clockwise from +Y (+X is east, +Z up).
pub fn sun_direction(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.sin(), e.cos() * a.cos(), e.sin())
}

impl Lighting {
    /// The unit direction towards the sun.
    pub fn sun_direction(&self) -> Vec3 {
        match self.sun {
            SunPosition::Angles {
                elevation_deg,
                azimuth_deg,
            } => sun_direction(elevation_deg, azimuth_deg),
            SunPosition::Direction(d) => d.normalize_or_zero(),
        }
    }

    /// Checks every parameter; the error names the one out of range.
    pub fn validate(&self) -> Result<()> {
        match self.sun {
            SunPosition::Angles {
                elevation_deg,
                azimuth_deg,
            } => {
                if !(-90.0..=90.0).contains(&elevation_deg) {
                    return Err(Error::invalid(
                        "lighting.sun_elevation",
                        format!("{elevation_deg}; must be in -90..=90 degrees"),
                    ));
                }
                if !azimuth_deg.is_finite() {
                    return Err(Error::invalid(
                        "lighting.sun_azimuth",
                        format!("{azimuth_deg}; must be finite"),
                    ));
                }
            }
            SunPosition::Direction(d) => {
                if !d.is_finite() || d.length() < 1e-6 {
                    return Err(Error::invalid(
                        "lighting.sun",
                        format!("{d}; must be a finite non-zero vector"),
                    ));
                }
            }
        }
        if !(1.7..=10.0).contains(&self.turbidity) {
            return Err(Error::invalid(
                "lighting.turbidity",
                format!("{}; must be in 1.7..=10", self.turbidity),
            ));
        }
        if let Exposure::Ev100(ev) = self.exposure {
            if !(-10.0..=30.0).contains(&ev) {
                return Err(Error::invalid(
                    "lighting.exposure",
                    format!("EV100 {ev}; must be in -10..=30"),
                ));
            }
        }
        if !matches!(self.sh_bands, 3 | 5) {
            return Err(Error::invalid(
                "lighting.sh_bands",
                format!("{}; must be 3 or 5", self.sh_bands),
            ));
        }
        if self.bounces > 2 {
            return Err(Error::invalid(
                "lighting.bounces",
                format!("{}; must be 0, 1 or 2", self.bounces),
            ));
        }
        if !matches!(self.sky_patches, 4 | 8) {
            return Err(Error::invalid(
                "lighting.sky_patches",
                format!("{}; must be 4 or 8", self.sky_patches),
            ));
        }
        if let Some(a) = self.albedo_override {
            if !(0.0..=1.0).contains(&a) {
                return Err(Error::invalid(
                    "lighting.albedo_override",
                    format!("{a}; must be in 0..=1"),
                ));
            }
        }
        if self.snow_line.is_nan() {
            return Err(Error::invalid("lighting.snow_line", "NaN"));
        }
        Ok(())
    }
}

/// What of a [`Lighting`] the renderer is built with: the sky-light bake's
/// parameters, the physical atmosphere's lookup tables and whether the
/// Monte Carlo reference is built. Later lightings keep these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightingSetup {
    /// The aerosols of the atmosphere's lookup tables.
    pub turbidity: f32,
    /// SH bands of the sky-light transfer: 3 or 5.
    pub sh_bands: u32,
    /// Interreflection bounces of the bake and the reference (0–2).
    pub bounces: u32,
    /// Albedo of those bounces.
    pub bounce_albedo: f32,
    /// Build the Monte Carlo reference ([`SkyLightMode::Reference`]).
    pub reference: bool,
}

/// The lighting of a frame: a validated [`Lighting`] (read its fields
/// through `Deref`) and the values derived from it, computed once when it
/// is made rather than in each technique's prepare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameLighting {
    lighting: Lighting,
    /// Unit vector towards the sun.
    pub sun: Vec3,
}

impl FrameLighting {
    /// Validates `lighting` (the error names the parameter out of range)
    /// and derives the sun's direction.
    pub fn new(lighting: Lighting) -> Result<FrameLighting> {
        lighting.validate()?;
        Ok(FrameLighting {
            sun: lighting.sun_direction(),
            lighting,
        })
    }

    /// The lighting as requested.
    pub fn lighting(&self) -> &Lighting {
        &self.lighting
    }
}

impl Default for FrameLighting {
    fn default() -> Self {
        let lighting = Lighting::default();
        FrameLighting {
            sun: lighting.sun_direction(),
            lighting,
        }
    }
}

impl std::ops::Deref for FrameLighting {
    type Target = Lighting;

    fn deref(&self) -> &Lighting {
        &self.lighting
    }
}

impl Lighting {
    /// What of this lighting the renderer is built with.
    pub fn setup(&self) -> LightingSetup {
        LightingSetup {
            turbidity: self.turbidity,
            sh_bands: self.sh_bands,
            bounces: self.bounces,
            bounce_albedo: self.albedo_override.unwrap_or(0.3),
            reference: self.sky_light == SkyLightMode::Reference,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuth_is_clockwise_from_north() {
        assert!((sun_direction(0.0, 0.0) - Vec3::Y).length() < 1e-6);
        assert!((sun_direction(0.0, 90.0) - Vec3::X).length() < 1e-6);
        assert!((sun_direction(90.0, 17.0) - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn bad_parameters_are_named() {
        let bad = |l: Lighting| l.validate().unwrap_err().parameter().map(str::to_string);
        let mut l = Lighting::default();
        assert!(l.validate().is_ok());
        l.turbidity = 1.0;
        assert_eq!(bad(l).as_deref(), Some("lighting.turbidity"));
        l = Lighting {
            sun: SunPosition::Angles {
                elevation_deg: 91.0,
                azimuth_deg: 0.0,
            },
            ..Lighting::default()
        };
        assert_eq!(bad(l).as_deref(), Some("lighting.sun_elevation"));
        l = Lighting {
            sh_bands: 4,
            ..Lighting::default()
        };
        assert_eq!(bad(l).as_deref(), Some("lighting.sh_bands"));
    }
}
