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
use crate::error::Result;
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
        Ok(SkyLight {
            environment_pipeline: Arc::new(ComputePipeline::new(ctx, shaders::LIGHTING_ENVIRONMENT)?),
            evaluate_pipeline: Arc::new(ComputePipeline::new(ctx, shaders::SKY_LIGHT_EVALUATE)?),
            bake,
            map,
            environment,
        })
    }

    /// The bake.
    #[cfg(test)]
    pub fn bake(&self) -> &SkyLightBake {
        &self.bake
    }

    /// Writes the sky-light field of a view's lighting constants, `field`
    /// (extent, texel counts − 1); the maps' heap handles (`maps.x`,
    /// `maps.y`, `maps.w`) are written by the pass that declares them
    /// ([`crate::view::LightingMap`]).
    pub fn fill(&self, frame: &mut LightingFrame) {
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
    /// the persistent resources. Once per graph. Both run on the frames
    /// `refresh` says; other frames keep the environment and the map.
    pub fn declare<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        lighting: UploadRegion,
        sky_inputs: &[ImageId],
        refresh: fn(&Frame<S>) -> bool,
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
        let compute = Stage::Compute;
        let mut pass = graph.pass("lighting.environment");
        let constants = pass.upload(lighting, compute);
        for &image in sky_inputs {
            pass.sample(image, compute);
        }
        let output = pass.storage_buffer(environment, BufferAccess::StorageReadWrite(compute));
        pass.record(move |ctx, frame| {
            if !refresh(frame) {
                return Ok(());
            }
            let push = EnvironmentPush {
                handles: [ctx.handle(constants)?, ctx.handle(output)?, 0, 0],
            };
            ctx.dispatch(&pipeline, &push, [1, 1, 1])
        });

        let pipeline = self.evaluate_pipeline.clone();
        let (columns, rows) = (self.bake.columns, self.bake.rows);
        let baked = self.bake.settings;
        let mut pass = graph.pass("lighting.sky_light");
        let handles = [
            pass.storage_buffer(surface, BufferAccess::StorageRead(compute)),
            pass.storage_buffer(transfer, BufferAccess::StorageRead(compute)),
            pass.storage_buffer(environment, BufferAccess::StorageRead(compute)),
            pass.storage_image(ids.map, ImageAccess::StorageReadWrite(compute)),
        ];
        pass.record(move |ctx, frame: &Frame<S>| {
            let lighting = &frame.lighting;
            if lighting.sky_light == SkyLightMode::Reference || !refresh(frame) {
                return Ok(());
            }
            let bands = lighting.sh_bands.min(baked.sh_bands);
            let push = EvaluatePush {
                handles: [
                    ctx.handle(handles[0])?,
                    ctx.handle(handles[1])?,
                    ctx.handle(handles[2])?,
                    ctx.handle(handles[3])?,
                ],
                grid: [columns, rows, mode_code(lighting.sky_light), bands * bands],
                layout: [baked.coefficients(), baked.stride(), lighting.sky_patches, 0],
            };
            ctx.dispatch(&pipeline, &push, [columns.div_ceil(8), rows.div_ceil(8), 1])
        });
        ids
    }
}
