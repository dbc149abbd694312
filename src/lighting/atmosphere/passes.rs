//! The physical atmosphere's lookup tables and the compute passes that fill
//! them every frame (Hillaire 2020 §5): `lighting.transmittance`,
//! `lighting.multiscattering` and, per view, `lighting.sky_view`.
//!
//! Inputs: the LUT passes read the view's `LightingFrame` (its upload
//! region) for the sun direction (`sun.xyz`), the planet (`planet`), the
//! Rayleigh and Mie scattering at the ground and the Mie g (`rayleigh`,
//! `mie.rgb`, filled by [`super::AtmosphereParameters::fill`]) and the
//! camera altitude (`atmosphere.w`, [`PhysicalAtmosphere::fill_altitude`]);
//! what the LightingFrame has no room for (ozone, the Mie absorption, the
//! ground albedo, the solar irradiance) comes in push constants from the
//! [`AtmosphereParameters`] the tables were created with, which do not
//! depend on the turbidity. `lighting.transmittance` and
//! `lighting.multiscattering` read the first view's LightingFrame.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::parameters::AtmosphereParameters;
use crate::error::{Error, Result};
use crate::graph::{ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::lighting::constants::LightingFrame;
use crate::shaders;
use crate::view::{pass_name, ViewIndex};
use crate::vulkan::{ComputePipeline, Context, Format, Image, ImageDesc, ImageUsageFlags};

/// Sizes (width, height) of the lookup tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LutSizes {
    /// Transmittance: x zenith cosine (Bruneton's mapping), y altitude.
    pub transmittance: (u32, u32),
    /// Multiple scattering: x sun zenith cosine, y altitude.
    pub multiscattering: (u32, u32),
    /// Sky view: x azimuth from the sun, y zenith angle (horizon mapping).
    pub sky_view: (u32, u32),
}

impl Default for LutSizes {
    /// Hillaire 2020's sizes: 256×64, 32×32, 192×108.
    fn default() -> Self {
        LutSizes {
            transmittance: (256, 64),
            multiscattering: (32, 32),
            sky_view: (192, 108),
        }
    }
}

/// Push constants of the table passes (`AtmospherePush` in
/// `glsl/include/atmosphere_physical.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct AtmospherePush {
    /// LightingFrame (storage), output (storage), transmittance and
    /// multiple scattering (sampled).
    handles: [u32; 4],
    /// Output width, height.
    size: [u32; 4],
    /// rgb: ozone absorption at the peak (1/m); w: altitude of the peak (m).
    ozone: [f32; 4],
    /// rgb: ground albedo; w: half-width of the ozone tent (m).
    albedo: [f32; 4],
    /// rgb: solar irradiance at the top of the atmosphere; w: Mie
    /// extinction / scattering.
    sun: [f32; 4],
}

impl AtmospherePush {
    fn new(params: &AtmosphereParameters) -> AtmospherePush {
        AtmospherePush {
            handles: [0; 4],
            size: [0; 4],
            ozone: params.ozone_absorption.extend(params.ozone_center).to_array(),
            albedo: params.ground_albedo.extend(params.ozone_half_width).to_array(),
            sun: params.solar_irradiance.extend(params.mie_extinction_ratio()).to_array(),
        }
    }
}

/// The graph images of the tables, for the passes that sample them: each
/// consumer declares `ImageAccess::Sampled` reads of [`AtmosphereLuts::reads`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AtmosphereLuts {
    pub transmittance: ImageId,
    pub multiscattering: ImageId,
    /// One per view, by [`ViewIndex`].
    pub sky_views: Vec<ImageId>,
}

impl AtmosphereLuts {
    /// Every table view `view` samples: transmittance, multiple
    /// scattering, its sky view.
    pub fn reads(&self, view: ViewIndex) -> Result<[ImageId; 3]> {
        let sky_view = self
            .sky_views
            .get(view)
            .ok_or_else(|| Error::Graph(format!("the atmosphere has no sky-view table for view {view}")))?;
        Ok([self.transmittance, self.multiscattering, *sky_view])
    }
}

struct Pipelines {
    transmittance: ComputePipeline,
    multiscattering: ComputePipeline,
    sky_view: ComputePipeline,
}

/// The physical atmosphere's persistent tables (RGBA32F, storage and
/// sampled) and pipelines. The tables' sampled heap handles never change,
/// so the LightingFrame can name them (written by the view's `sky` pass,
/// which declares them: [`crate::view::LightingMap`]).
pub struct PhysicalAtmosphere {
    params: AtmosphereParameters,
    sizes: LutSizes,
    transmittance: Arc<Image>,
    multiscattering: Arc<Image>,
    sky_views: Vec<Arc<Image>>,
    pipelines: Arc<Pipelines>,
}

fn lut_image(ctx: &Context, name: &str, (width, height): (u32, u32)) -> Result<Arc<Image>> {
    Ok(Arc::new(Image::new(
        ctx,
        ImageDesc {
            name: name.into(),
            width,
            height,
            format: Format::R32G32B32A32_SFLOAT,
            usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC,
        },
    )?))
}

impl PhysicalAtmosphere {
    /// Creates the tables of `sizes` (one sky view per view, `views` ≥ 1)
    /// and the pipelines. `params` gives what the push constants carry
    /// (ozone, Mie absorption, ground albedo, solar irradiance); use the
    /// same planet when filling the LightingFrame.
    pub fn new(ctx: &Context, params: &AtmosphereParameters, sizes: LutSizes, views: usize) -> Result<Self> {
        if views == 0 {
            return Err(Error::invalid("atmosphere views", "0; at least one view"));
        }
        for (what, (w, h)) in [
            ("transmittance", sizes.transmittance),
            ("multiscattering", sizes.multiscattering),
            ("sky_view", sizes.sky_view),
        ] {
            if !(2..=4096).contains(&w) || !(2..=4096).contains(&h) {
                return Err(Error::invalid(
                    format!("atmosphere.{what}_size"),
                    format!("{w}x{h}; each side must be in 2..=4096"),
                ));
            }
        }
        let sky_views = (0..views)
            .map(|i| lut_image(ctx, &format!("lighting.sky_view#{i}"), sizes.sky_view))
            .collect::<Result<Vec<_>>>()?;
        Ok(PhysicalAtmosphere {
            params: *params,
            sizes,
            transmittance: lut_image(ctx, "lighting.transmittance", sizes.transmittance)?,
            multiscattering: lut_image(ctx, "lighting.multiscattering", sizes.multiscattering)?,
            sky_views,
            pipelines: Arc::new(Pipelines {
                transmittance: ComputePipeline::new(ctx, shaders::ATMOSPHERE_TRANSMITTANCE)?,
                multiscattering: ComputePipeline::new(ctx, shaders::ATMOSPHERE_MULTISCATTERING)?,
                sky_view: ComputePipeline::new(ctx, shaders::ATMOSPHERE_SKY_VIEW)?,
            }),
        })
    }

    /// Writes, as f32 bits in `frame.atmosphere.w`, the camera altitude
    /// above the ground level: `eye_z` (world, m) − `frame.mie[3]` (the
    /// ground altitude; set it first). The sky-view pass and `physical_sky`
    /// both read it. The tables' handles (`atmosphere.xyz`) are written by
    /// the pass that declares the tables ([`crate::view::LightingMap`]).
    /// `view` must have a sky-view table.
    pub fn fill_altitude(&self, view: ViewIndex, eye_z: f64, frame: &mut LightingFrame) -> Result<()> {
        if view >= self.sky_views.len() {
            return Err(Error::Graph(format!(
                "the atmosphere has no sky-view table for view {view}"
            )));
        }
        let altitude = (eye_z - f64::from(frame.mie[3])) as f32;
        if !altitude.is_finite() {
            return Err(Error::invalid("camera", "the eye's altitude is not finite"));
        }
        frame.atmosphere[3] = altitude.to_bits();
        Ok(())
    }

    /// Imports the tables into `graph` and declares the passes:
    /// `lighting.transmittance` and `lighting.multiscattering` once, and
    /// `lighting.sky_view[@name]` per view. `views`: per view (by
    /// [`ViewIndex`]), its name and the upload region of its LightingFrame.
    /// `refresh(frame, table)` says whether a frame recomputes a table
    /// (None: the transmittance and multiple-scattering tables, Some(k):
    /// view k's sky view); the tables persist across frames, so a frame
    /// may keep them.
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        views: &[(&str, UploadRegion)],
        refresh: fn(&P, Option<usize>) -> bool,
    ) -> Result<AtmosphereLuts> {
        let Some(&(_, first)) = views.first() else {
            return Err(Error::Graph("the atmosphere needs at least one view".into()));
        };
        if views.len() > self.sky_views.len() {
            return Err(Error::Graph(format!(
                "the atmosphere has sky-view tables for {} views, not {}",
                self.sky_views.len(),
                views.len()
            )));
        }
        let luts = AtmosphereLuts {
            transmittance: graph.import_image(self.transmittance.clone()),
            multiscattering: graph.import_image(self.multiscattering.clone()),
            sky_views: self.sky_views[..views.len()]
                .iter()
                .map(|image| graph.import_image(image.clone()))
                .collect(),
        };
        let push = AtmospherePush::new(&self.params);
        let (transmittance, multiscattering) = (luts.transmittance, luts.multiscattering);

        let pipelines = &self.pipelines;
        declare_table(
            graph,
            "lighting.transmittance",
            (pipelines.clone(), |p| &p.transmittance),
            (first, &[], transmittance),
            (self.sizes.transmittance, push),
            (refresh, None),
        );
        declare_table(
            graph,
            "lighting.multiscattering",
            (pipelines.clone(), |p| &p.multiscattering),
            (first, &[transmittance], multiscattering),
            (self.sizes.multiscattering, push),
            (refresh, None),
        );
        for (k, (&(name, region), &sky_view)) in views.iter().zip(&luts.sky_views).enumerate() {
            declare_table(
                graph,
                &pass_name("lighting.sky_view", name),
                (pipelines.clone(), |p| &p.sky_view),
                (region, &[transmittance, multiscattering], sky_view),
                (self.sizes.sky_view, push),
                (refresh, Some(k)),
            );
        }
        Ok(luts)
    }
}

/// Declares the table pass `name`: reads the LightingFrame in `region`,
/// samples `inputs` (handles 2, 3), writes the `size` table `output` with
/// the pipeline `pick` chooses, on the frames `refresh` says (the table
/// `table`); other frames keep it (read-write: its contents stay).
#[allow(clippy::type_complexity)]
fn declare_table<P: 'static>(
    graph: &mut RenderGraph<P>,
    name: &str,
    (pipelines, pick): (Arc<Pipelines>, fn(&Pipelines) -> &ComputePipeline),
    (region, inputs, output): (UploadRegion, &[ImageId], ImageId),
    ((w, h), push): ((u32, u32), AtmospherePush),
    (refresh, table): (fn(&P, Option<usize>) -> bool, Option<usize>),
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let lighting = pass.upload(region, compute);
    let inputs: Vec<_> = inputs.iter().map(|&image| pass.sample(image, compute)).collect();
    let output = pass.storage_image(output, ImageAccess::StorageReadWrite(compute));
    pass.record(move |ctx, frame| {
        if !refresh(frame, table) {
            return Ok(());
        }
        let mut handles = [ctx.handle(lighting)?, ctx.handle(output)?, 0, 0];
        for (slot, &input) in handles[2..].iter_mut().zip(&inputs) {
            *slot = ctx.handle(input)?;
        }
        let push = AtmospherePush {
            handles,
            size: [w, h, 0, 0],
            ..push
        };
        ctx.dispatch(pick(&pipelines), &push, [w.div_ceil(8), h.div_ceil(8), 1])
    });
}
