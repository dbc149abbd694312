//! The per-frame sky light (§9.3–9.5): `lighting.environment` projects the
//! frame's sky (`sky_radiance()`, and the sun as a delta of its disc's
//! irradiance when `LIGHTING_SUN_IN_ENVIRONMENT` is set) into 25 RGB SH
//! coefficients and the 8×8 and 4×4 sky-patch radiances
//! (`glsl/lighting/environment.comp`); `lighting.sky_light` combines them
//! with the bake into the sky-light map by mode
//! (`glsl/lighting/sky_light_evaluate.comp`). Mode `reference` is written
//! by the Monte Carlo reference: this pass then records nothing.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::bake::SkyLightBake;
use super::ENVIRONMENT_VEC4S;
use crate::error::{Error, Result};
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::lighting::constants::{
    LightingFrame, SKY_LIGHT_AO, SKY_LIGHT_OFF, SKY_LIGHT_PATCHES, SKY_LIGHT_REFERENCE, SKY_LIGHT_SH,
};
use crate::shaders;
use crate::view::{Frame, SkyLightMode};
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, Format, Image, ImageDesc, ImageUsageFlags,
    MemoryLocation,
};

/// `models.z` of a sky-light mode.
pub fn mode_code(mode: SkyLightMode) -> u32 {
    match mode {
        SkyLightMode::Reference => SKY_LIGHT_REFERENCE,
        SkyLightMode::Sh => SKY_LIGHT_SH,
        SkyLightMode::Ao => SKY_LIGHT_AO,
        SkyLightMode::Patches => SKY_LIGHT_PATCHES,
        SkyLightMode::Off => SKY_LIGHT_OFF,
    }
}

/// Push constants of `environment.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct EnvironmentPush {
    /// Lighting frame (upload), environment (written).
    handles: [u32; 4],
}

/// Push constants of `sky_light_evaluate.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct EvaluatePush {
    /// Surface, transfer, environment, sky-light map (storage image).
    handles: [u32; 4],
    /// Columns, rows, mode, SH coefficients evaluated.
    grid: [u32; 4],
    /// SH coefficients baked, stride, patches per side.
    layout: [u32; 4],
}

/// What the passes that use the sky light read: declare
/// `map`/`horizon` as [`ImageAccess::Sampled`] and `environment` as
/// [`BufferAccess::StorageRead`].
#[derive(Clone, Copy, Debug)]
pub struct SkyLightIds {
    /// The sky-light map (RGBA32F, field-sized), written by `lighting.sky_light`.
    pub map: ImageId,
    /// The sun horizon map (baked once).
    pub horizon: ImageId,
    /// The environment (105 vec4), written by `lighting.environment`.
    pub environment: BufferId,
}

/// The sky light of a height field: its bake, the sky-light map and the
/// environment buffer (persistent; heap handles fixed for its lifetime).
pub struct SkyLight {
    bake: SkyLightBake,
    map: Arc<Image>,
    environment: Arc<Buffer>,
    environment_pipeline: Arc<ComputePipeline>,
    evaluate_pipeline: Arc<ComputePipeline>,
    /// Sampled map, sampled horizon map, environment storage.
    handles: [u32; 3],
}

fn handle(h: Option<u32>, what: &str) -> Result<u32> {
    h.ok_or_else(|| Error::Graph(format!("sky light: {what} has no heap handle")))
}

impl SkyLight {
    /// Creates the sky-light map and the environment buffer for `bake`.
    pub fn new(ctx: &Context, bake: SkyLightBake) -> Result<SkyLight> {
        let map = Arc::new(Image::new(
            ctx,
            ImageDesc {
                name: "sky-light map".into(),
                width: bake.columns,
                height: bake.rows,
                format: Format::R32G32B32A32_SFLOAT,
                usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC,
            },
        )?);
        let environment = Arc::new(Buffer::new(
            ctx,
            BufferDesc {
                name: "sky-light environment".into(),
                size: u64::from(ENVIRONMENT_VEC4S) * 16,
                usage: BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::GpuOnly,
            },
        )?);
        let handles = [
            handle(map.sampled_handle(), "the sky-light map")?,
            handle(bake.horizon_map.sampled_handle(), "the horizon map")?,
            handle(environment.storage_handle(), "the environment")?,
        ];
        Ok(SkyLight {
            environment_pipeline: Arc::new(ComputePipeline::new(ctx, shaders::LIGHTING_ENVIRONMENT)?),
            evaluate_pipeline: Arc::new(ComputePipeline::new(ctx, shaders::SKY_LIGHT_EVALUATE)?),
            bake,
            map,
            environment,
            handles,
        })
    }

    /// The bake.
    #[cfg(test)]
    pub fn bake(&self) -> &SkyLightBake {
        &self.bake
    }

    /// Writes the sky-light fields of a view's lighting constants:
    /// `maps.x` (sky-light map), `maps.y` (horizon map), `maps.w`
    /// (environment) and `field` (extent, texel counts − 1).
    pub fn fill(&self, frame: &mut LightingFrame) {
        frame.maps[0] = self.handles[0];
        frame.maps[1] = self.handles[1];
        frame.maps[3] = self.handles[2];
        let (c, r) = ((self.bake.columns - 1) as f32, (self.bake.rows - 1) as f32);
        frame.field = [
            (f64::from(c) * self.bake.spacing.x) as f32,
            (f64::from(r) * self.bake.spacing.y) as f32,
            c,
            r,
        ];
    }

    /// Declares `lighting.environment` (reading the frame's lighting
    /// constants in `lighting` and the sampled images in `sky_inputs`, e.g.
    /// the atmosphere's lookup tables) and `lighting.sky_light`; imports
    /// the persistent resources. Once per graph.
    pub fn declare<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        lighting: UploadRegion,
        sky_inputs: &[ImageId],
    ) -> SkyLightIds {
        let ids = SkyLightIds {
            map: graph.import_image(self.map.clone()),
            horizon: graph.import_image(self.bake.horizon_map.clone()),
            environment: graph.import_buffer(self.environment.clone()),
        };
        let surface = graph.import_buffer(self.bake.surface.clone());
        let transfer = graph.import_buffer(self.bake.transfer.clone());

        let pipeline = self.environment_pipeline.clone();
        let environment = ids.environment;
        let mut pass = graph
            .pass("lighting.environment")
            .read(lighting, BufferAccess::StorageRead(Stage::Compute));
        for &image in sky_inputs {
            pass = pass.read(image, ImageAccess::Sampled(Stage::Compute));
        }
        pass.write(environment, BufferAccess::StorageWrite(Stage::Compute))
            .record(move |pass, _frame| {
                let push = EnvironmentPush {
                    handles: [pass.upload(lighting)?, pass.storage_buffer(environment)?, 0, 0],
                };
                let cmd = pass.cmd();
                cmd.bind_compute(&pipeline);
                cmd.push_constants(&push)?;
                cmd.dispatch(1, 1, 1);
                Ok(())
            });

        let pipeline = self.evaluate_pipeline.clone();
        let (map, columns, rows) = (ids.map, self.bake.columns, self.bake.rows);
        let baked = self.bake.settings;
        graph
            .pass("lighting.sky_light")
            .read(surface, BufferAccess::StorageRead(Stage::Compute))
            .read(transfer, BufferAccess::StorageRead(Stage::Compute))
            .read(environment, BufferAccess::StorageRead(Stage::Compute))
            .write(map, ImageAccess::StorageWrite(Stage::Compute))
            .record(move |pass, frame: &Frame<S>| {
                let lighting = &frame.lighting;
                if lighting.sky_light == SkyLightMode::Reference {
                    return Ok(());
                }
                let bands = lighting.sh_bands.min(baked.sh_bands);
                let push = EvaluatePush {
                    handles: [
                        pass.storage_buffer(surface)?,
                        pass.storage_buffer(transfer)?,
                        pass.storage_buffer(environment)?,
                        pass.storage_image(map)?,
                    ],
                    grid: [columns, rows, mode_code(lighting.sky_light), bands * bands],
                    layout: [baked.coefficients(), baked.stride(), lighting.sky_patches, 0],
                };
                let cmd = pass.cmd();
                cmd.bind_compute(&pipeline);
                cmd.push_constants(&push)?;
                cmd.dispatch(columns.div_ceil(8), rows.div_ceil(8), 1);
                Ok(())
            });
        ids
    }
}
