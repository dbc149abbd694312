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
use crate::view::{
    pass_name, FrameContext, FrameLighting, ShadowMode, SkyLightMode, SkyModel, SunDisc, Technique, View,
};

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
    /// Which sky tables this frame recomputes.
    pub refresh: SkyRefresh,
}

/// Which of the sky's tables a frame recomputes (issue 28): only those
/// whose inputs changed since the last frame that computed them. The
/// transmittance and multiple-scattering tables depend on the atmosphere
/// and the sky model; a view's sky-view table also on the sun and the
/// eye's altitude; the environment and the sky-light map on everything the
/// first view's sky shows and on the sky-light mode. A simulator moving
/// the sun every frame still gets all of them every frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SkyRefresh {
    pub tables: bool,
    /// Bit k: view k's sky-view table.
    pub sky_views: u32,
    pub environment: bool,
}

impl SkyRefresh {
    /// Whether view `index`'s sky-view table is recomputed (a view beyond
    /// the mask: yes).
    pub fn sky_view(&self, index: usize) -> bool {
        index >= 32 || self.sky_views & (1 << index) != 0
    }
}

/// The inputs of the transmittance and multiple-scattering tables: the
/// atmosphere's coefficients and planet, the sky model.
type TablesKey = [u32; 13];
/// A view's sky-view table's: the tables' and the sun and eye altitude.
type ViewKey = [u32; 18];
/// The environment's and the sky-light map's: the first view's sky and the
/// sky-light mode, flags, bands and patches.
type EnvironmentKey = [u32; 58];

fn bits<const N: usize>(rows: &[[f32; 4]]) -> [u32; N] {
    let mut key = [0; N];
    for (k, v) in rows.iter().flatten().enumerate().take(N) {
        key[k] = v.to_bits();
    }
    key
}

fn tables_key(f: &LightingFrame) -> TablesKey {
    let mut key: TablesKey = bits(&[f.rayleigh, f.mie, f.planet]);
    key[12] = f.models[0];
    key
}

fn view_key(f: &LightingFrame) -> ViewKey {
    let mut key = [0; 18];
    key[..13].copy_from_slice(&tables_key(f));
    key[13..17].copy_from_slice(&f.sun.map(f32::to_bits));
    key[17] = f.atmosphere[3];
    key
}

fn environment_key(f: &LightingFrame, lighting: &FrameLighting) -> EnvironmentKey {
    let mut key = [0; 58];
    key[..18].copy_from_slice(&view_key(f));
    let sky: [u32; 36] = bits(&[
        f.sun_radiance,
        f.sun_irradiance,
        f.zenith,
        f.perez_norm,
        f.perez[0],
        f.perez[1],
        f.perez[2],
        f.perez[3],
        f.perez[4],
    ]);
    key[18..54].copy_from_slice(&sky);
    key[54..].copy_from_slice(&[f.models[2], f.models[3], lighting.sh_bands, lighting.sky_patches]);
    key
}

/// What the sky tables of the last frame were computed from (updated in
/// place: a steady frame allocates nothing).
#[derive(Clone, Debug, Default)]
struct SkyKeys {
    /// None before the first frame.
    tables: Option<TablesKey>,
    sky_views: Vec<ViewKey>,
    environment: Option<EnvironmentKey>,
}

impl SkyKeys {
    /// What a frame whose views have the constants `views` recomputes
    /// after the frames so far; remembers its keys.
    fn update(&mut self, views: &[LightingFrame], lighting: &FrameLighting) -> SkyRefresh {
        let mut refresh = SkyRefresh::default();
        let Some(first) = views.first() else {
            return refresh;
        };
        let tables = Some(tables_key(first));
        refresh.tables = self.tables != tables;
        self.tables = tables;
        self.sky_views.resize(views.len(), [u32::MAX; 18]);
        for (k, (view, last)) in views.iter().zip(&mut self.sky_views).enumerate() {
            let key = view_key(view);
            if *last != key || self.environment.is_none() {
                refresh.sky_views |= 1u32.checked_shl(k as u32).unwrap_or(0);
                *last = key;
            }
        }
        let environment = Some(environment_key(first, lighting));
        refresh.environment = self.environment != environment;
        self.environment = environment;
        refresh
    }
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
    /// What the sky tables were last computed from.
    sky_keys: SkyKeys,
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
            sky_keys: SkyKeys::default(),
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
        // The Preetham sun (and, for the physical sky, its aerial constants'
        // defaults) first; an analytic sky then writes its own constants.
        PreethamSky::new(sun, lighting.turbidity)?.fill(&mut f);
        f.mie[3] = self.field.ground;
        match lighting.sky {
            SkyModel::Preetham | SkyModel::CieClear | SkyModel::CieOvercast => {
                if let Some(sky) = PreethamSky::for_model(lighting.sky, sun, lighting.turbidity)? {
                    sky.fill(&mut f);
                }
                AerialCoefficients::for_turbidity(lighting.turbidity)?.fill(&mut f)
            }
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
                SkyModel::Preetham | SkyModel::CieClear | SkyModel::CieOvercast => SKY_PREETHAM,
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
            } | match lighting.sun_disc {
                SunDisc::Hard => 0,
                SunDisc::Soft => LIGHTING_SOFT_SUN,
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
        let refresh = self.sky_keys.update(&views, frame.lighting);
        Ok(PreparedLighting {
            views,
            reference: reference_work,
            refresh,
        })
    }

    fn recycle(&mut self, previous: PreparedLighting) {
        self.spare = previous.views;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::{Lighting, SunPosition};

    fn frames(elevation_deg: f32, altitudes: &[f32]) -> (Vec<LightingFrame>, FrameLighting) {
        let lighting = FrameLighting::new(Lighting {
            sun: SunPosition::Angles {
                elevation_deg,
                azimuth_deg: 150.0,
            },
            ..Lighting::default()
        })
        .expect("lighting");
        let field = FieldInfo {
            extent: [1000.0, 1000.0],
            texels: [10.0, 10.0],
            ground: 0.0,
        };
        let lit = SceneLighting::new(Vec::new(), field);
        let shared = lit.constants(&lighting).expect("constants");
        let views = (altitudes.iter())
            .map(|&a| {
                let mut f = shared;
                f.atmosphere[3] = a.to_bits();
                f
            })
            .collect();
        (views, lighting)
    }

    #[test]
    fn sky_tables_are_recomputed_only_when_their_inputs_change() {
        let (views, lighting) = frames(30.0, &[100.0, 100.0]);
        let mut keys = SkyKeys::default();
        let all = SkyRefresh {
            tables: true,
            sky_views: 0b11,
            environment: true,
        };
        assert_eq!(
            keys.update(&views, &lighting),
            all,
            "the first frame computes every table"
        );
        assert_eq!(
            keys.update(&views, &lighting),
            SkyRefresh::default(),
            "an unchanged frame keeps them"
        );
        // The second view climbs: its sky view only.
        let (climbed, _) = frames(30.0, &[100.0, 400.0]);
        let refresh = keys.update(&climbed, &lighting);
        assert_eq!(
            (refresh.sky_views, refresh.tables, refresh.environment),
            (0b10, false, false)
        );
        assert!(!refresh.sky_view(0) && refresh.sky_view(1));
        // The sun moves: every sky view and the environment, not the atmosphere's tables.
        let (moved, lighting) = frames(
            31.0,
            &climbed
                .iter()
                .map(|f| f32::from_bits(f.atmosphere[3]))
                .collect::<Vec<_>>(),
        );
        let refresh = keys.update(&moved, &lighting);
        assert_eq!(
            (refresh.sky_views, refresh.tables, refresh.environment),
            (0b11, false, true)
        );
    }
}
