//! The lighting technique (§6.3, §9): its prepare step turns the frame's
//! [`FrameLighting`] into each view's [`LightingFrame`] constants (sun,
//! sky model coefficients, aerial perspective, cascades); the view's `sky`
//! pass adds the maps' heap handles and writes them into the view's upload
//! region ([`crate::view::LightingInputs::constants`]), which every shading
//! pass reads; the lighting passes (lookup tables, shadow casters, sky
//! light) are declared by its parts.

use glam::Vec3;

use super::aerial::AerialCoefficients;
use super::atmosphere::{sun_transmittance, AtmosphereParameters, PhysicalAtmosphere};
use super::constants::*;
use super::preetham::PreethamSky;
use super::reference::{MonteCarloReference, ReferenceWork};
use super::shadows::ShadowFrame;
use super::sky_light::SkyLight;
use crate::error::{Error, Result};
use crate::graph::{RenderGraph, UploadRegion};
use crate::view::{pass_name, FrameContext, FrameLighting, ShadowMode, SkyLightMode, SkyModel, Technique, View};

/// What the height field contributes to the constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldInfo {
    /// Extent (m) of the field: texel centres run from 0 to it.
    pub extent: [f32; 2],
    /// Columns − 1, rows − 1.
    pub texels: [f32; 2],
    /// Lowest height (m): the ground of the atmosphere.
    pub ground: f32,
}

/// The frame's lighting constants, per view, without the maps' heap
/// handles (the view's `sky` pass adds them and writes the constants).
pub struct PreparedLighting {
    pub views: Vec<LightingFrame>,
    /// What `lighting.reference` dispatches this frame (the reference mode).
    pub reference: Option<ReferenceWork>,
}

impl PreparedLighting {
    /// The constants of view `index`.
    pub fn view(&self, index: usize) -> Result<&LightingFrame> {
        self.views
            .get(index)
            .ok_or_else(|| Error::Graph(format!("lighting: view {index} was not prepared")))
    }
}

/// The lighting of a scene: per-view constant regions and the parts'
/// persistent state.
pub struct SceneLighting {
    /// The constants region of each view.
    regions: Vec<UploadRegion>,
    field: FieldInfo,
    /// Sky light on the terrain by SH, AO or patches (§9.3–9.5).
    pub sky_light: Option<SkyLight>,
    /// The Monte Carlo reference (§9.2), when the renderer was built for it.
    pub reference: Option<MonteCarloReference>,
    /// The physical atmosphere's lookup tables (Hillaire 2020).
    pub atmosphere: Option<PhysicalAtmosphere>,
    /// The previous frame's prepared data, reused ([`Technique::recycle`]).
    spare: Vec<LightingFrame>,
}

impl SceneLighting {
    /// Lighting for views whose constants go to `regions`.
    pub fn new(regions: Vec<UploadRegion>, field: FieldInfo) -> SceneLighting {
        SceneLighting {
            regions,
            field,
            sky_light: None,
            reference: None,
            atmosphere: None,
            spare: Vec::new(),
        }
    }

    /// Declares the upload region of `view`'s lighting constants (one
    /// [`LightingFrame`]), which its [`crate::view::SceneTargets`] carry.
    pub fn declare_constants<P: 'static>(graph: &mut RenderGraph<P>, view: &View) -> UploadRegion {
        let bytes = std::mem::size_of::<LightingFrame>() as u64;
        graph.upload_region(&pass_name("lighting", &view.name), bytes)
    }

    /// The constants every view shares (the frame's, without view-dependent
    /// parts): the Preetham sky's coefficients and the transmitted sun
    /// (§6.3), the aerial perspective's scattering coefficients (§9.1), the
    /// modes.
    fn constants(&self, lighting: &FrameLighting) -> Result<LightingFrame> {
        let mut f = LightingFrame::zeroed_frame();
        let sun = lighting.sun;
        PreethamSky::new(sun, lighting.turbidity)?.fill(&mut f);
        f.mie[3] = self.field.ground;
        match lighting.sky {
            SkyModel::Preetham => AerialCoefficients::for_turbidity(lighting.turbidity)?.fill(&mut f),
            SkyModel::Physical => {
                // The same atmosphere scatters the sky, dims the sun and
                // hazes the distance.
                let params = AtmosphereParameters::for_turbidity(lighting.turbidity)?;
                params.fill(&mut f);
                let transmittance = sun_transmittance(&params, 0.0, sun);
                let outside = Vec3::from(SUN_COLOUR_EXTRATERRESTRIAL) * SUN_LUMINANCE_EXTRATERRESTRIAL;
                let centre = outside * transmittance;
                let u = f.sun_radiance[3];
                let solid_angle = std::f32::consts::PI * SUN_ANGULAR_RADIUS * SUN_ANGULAR_RADIUS;
                f.sun_radiance = centre.extend(u).to_array();
                f.sun_irradiance = (centre * (1.0 - u / 3.0) * solid_angle).extend(0.0).to_array();
            }
        }
        f.models = [
            match lighting.sky {
                SkyModel::Preetham => SKY_PREETHAM,
                SkyModel::Physical => SKY_PHYSICAL,
            },
            match lighting.shadows {
                ShadowMode::Off => SHADOWS_OFF,
                ShadowMode::Cascaded => SHADOWS_CASCADED,
                ShadowMode::Horizon => SHADOWS_HORIZON,
            },
            match lighting.sky_light {
                SkyLightMode::Off => SKY_LIGHT_OFF,
                SkyLightMode::Reference => SKY_LIGHT_REFERENCE,
                SkyLightMode::Sh => SKY_LIGHT_SH,
                SkyLightMode::Ao => SKY_LIGHT_AO,
                SkyLightMode::Patches => SKY_LIGHT_PATCHES,
            },
            match lighting.albedo_override {
                Some(_) => LIGHTING_ALBEDO_OVERRIDE,
                None => 0,
            } | match lighting.aerial_perspective {
                true => 0,
                false => LIGHTING_NO_AERIAL_PERSPECTIVE,
            } | match lighting.sun_in_sky_light {
                true => LIGHTING_SUN_IN_ENVIRONMENT | LIGHTING_NO_SUN_DIRECT,
                false => 0,
            },
        ];
        f.exposure = [0.0, 0.0, lighting.snow_line, lighting.albedo_override.unwrap_or(0.0)];
        f.field = [
            self.field.extent[0],
            self.field.extent[1],
            self.field.texels[0],
            self.field.texels[1],
        ];
        Ok(f)
    }
}

impl LightingFrame {
    /// All zeros.
    pub fn zeroed_frame() -> LightingFrame {
        bytemuck::Zeroable::zeroed()
    }
}

impl Technique for SceneLighting {
    type Prepared = PreparedLighting;
    /// The shadow cascades of every view (None: no shadow casters).
    type Needs<'a> = Option<&'a ShadowFrame>;

    fn name(&self) -> &'static str {
        "lighting"
    }

    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, shadows: Option<&ShadowFrame>) -> Result<PreparedLighting> {
        let mut views = std::mem::take(&mut self.spare);
        views.clear();
        let shared = self.constants(frame.lighting)?;
        let mut reference_work = None;
        for (k, view) in frame.views.iter().enumerate() {
            let mut constants = shared;
            if let Some(atmosphere) = &self.atmosphere {
                atmosphere.fill_altitude(k, view.camera.eye.z, &mut constants)?;
            }
            if let Some(shadows) = shadows {
                shadows.view(k)?.fill(&mut constants);
            }
            if let Some(sky_light) = &self.sky_light {
                sky_light.fill(&mut constants);
            }
            if frame.lighting.sky_light == SkyLightMode::Reference {
                let reference = self.reference.as_mut().ok_or_else(|| {
                    Error::invalid(
                        "lighting.sky_light",
                        "reference: the renderer was built without the Monte Carlo reference (start with it)",
                    )
                })?;
                reference_work = Some(reference.prepare(&constants).0);
                reference.fill(&mut constants);
            }
            if k >= self.regions.len() {
                return Err(Error::Graph(format!("view {k} has no lighting constants region")));
            }
            views.push(constants);
        }
        Ok(PreparedLighting {
            views,
            reference: reference_work,
        })
    }

    fn recycle(&mut self, previous: PreparedLighting) {
        self.spare = previous.views;
    }
}
