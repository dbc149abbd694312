//! `exposure.meter` and `exposure.average`: the exposure of a frame of
//! absolute radiance (§9, the HDR target holds cd/m²-scaled linear sRGB).
//! Automatic: the mean log2 luminance of the view, metered on the GPU by a
//! parallel reduction in a fixed order (deterministic frames): a workgroup
//! per 128×64-pixel tile (every second pixel), then one workgroup over the
//! tiles; mapped to a camera's saturation-based exposure
//! (EV100 = log2(L_avg·S/K), S = 100, K = 12.5; multiplier
//! 1/(1.2·2^EV100)). Manual: `--exposure EV100`. The multiplier goes into a
//! small GPU buffer the tone curve reads. Shaders: `glsl/post/exposure.comp`,
//! `glsl/post/exposure_average.comp`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, BufferInfo, ImageAccess, Stage};
use crate::shaders;
use crate::view::{pass_name, Declare, Exposure, SceneTargets, ViewGraph};
use crate::vulkan::{ComputePipeline, Context, MemoryLocation};

/// Bytes of the exposure buffer: multiplier, EV100, mean log2 luminance, pad.
pub const EXPOSURE_BYTES: u64 = 16;

/// Push constants of `exposure.meter`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MeterPush {
    /// Storage handles: radiance, the tiles' sums.
    radiance: u32,
    partials: u32,
    _pad: [u32; 2],
    width: u32,
    height: u32,
    _pad2: [u32; 2],
}

/// Push constants of `exposure.average`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct AveragePush {
    /// Storage handles: the tiles' sums, the exposure buffer; the tiles.
    partials: u32,
    exposure: u32,
    tiles: u32,
    _pad: u32,
    /// Manual multiplier (0: automatic).
    manual: f32,
    /// EV compensation (automatic only).
    compensation: f32,
    _pad2: [f32; 2],
}

/// Pixels of the tile one `exposure.meter` workgroup meters (16×16
/// threads, every second pixel, eight a thread).
const TILE: [u32; 2] = [128, 64];

/// The exposure multiplier of a manual EV100.
pub fn multiplier_of_ev100(ev100: f32) -> f32 {
    1.0 / (1.2 * ev100.exp2())
}

/// The exposure meter: its pipelines, and `exposure.meter` and
/// `exposure.average` per view.
pub struct ExposureMeter {
    meter: Arc<ComputePipeline>,
    average: Arc<ComputePipeline>,
}

impl ExposureMeter {
    /// Builds the pipelines.
    pub fn new(ctx: &Context) -> Result<ExposureMeter> {
        Ok(ExposureMeter {
            meter: Arc::new(ComputePipeline::new(ctx, shaders::EXPOSURE_METER)?),
            average: Arc::new(ComputePipeline::new(ctx, shaders::EXPOSURE_AVERAGE)?),
        })
    }
}

/// `exposure.meter` and `exposure.average` of a view: its (post-processed)
/// targets in, its exposure buffer out.
impl<S: 'static> Declare<S> for ExposureMeter {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = BufferId;

    /// Declares the view's metering: `exposure.meter` reads its radiance
    /// into the tiles' sums, `exposure.average` writes and returns the
    /// view's exposure buffer (read by `tonemap`).
    fn declare(&mut self, at: ViewGraph<'_, S>, targets: &SceneTargets) -> Result<BufferId> {
        let (graph, view) = (at.graph, at.view);
        let (width, height) = (targets.width, targets.height);
        let groups = [width.div_ceil(TILE[0]), height.div_ceil(TILE[1])];
        let tiles = groups[0] * groups[1];
        let buffer = |graph: &mut crate::graph::RenderGraph<_>, name: &str, size: u64| {
            let location = MemoryLocation::GpuOnly;
            graph.create_buffer(&pass_name(name, &view.name), BufferInfo { size, location })
        };
        let partials = buffer(graph, "exposure tiles", 8 * u64::from(tiles));
        let exposure = buffer(graph, "exposure", EXPOSURE_BYTES);
        let compute = Stage::Compute;

        let pipeline = self.meter.clone();
        let mut pass = graph.pass(&pass_name("exposure.meter", &view.name));
        let radiance = pass.storage_image(targets.radiance, ImageAccess::StorageRead(compute));
        let sums = pass.storage_buffer(partials, BufferAccess::StorageWrite(compute));
        pass.record(move |ctx, _| {
            let push = MeterPush {
                radiance: ctx.handle(radiance)?,
                partials: ctx.handle(sums)?,
                width,
                height,
                ..MeterPush::zeroed()
            };
            ctx.dispatch(&pipeline, &push, [groups[0], groups[1], 1])
        });

        let pipeline = self.average.clone();
        let mut pass = graph.pass(&pass_name("exposure.average", &view.name));
        let sums = pass.storage_buffer(partials, BufferAccess::StorageRead(compute));
        let output = pass.storage_buffer(exposure, BufferAccess::StorageWrite(compute));
        pass.record(move |ctx, frame| {
            let manual = match frame.lighting.exposure {
                Exposure::Auto => 0.0,
                Exposure::Ev100(ev) => multiplier_of_ev100(ev),
            };
            let push = AveragePush {
                partials: ctx.handle(sums)?,
                exposure: ctx.handle(output)?,
                tiles,
                manual,
                ..AveragePush::zeroed()
            };
            ctx.dispatch(&pipeline, &push, [1, 1, 1])
        });
        Ok(exposure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ev100_halves_per_stop() {
        assert!((multiplier_of_ev100(1.0) * 2.0 - multiplier_of_ev100(0.0)).abs() < 1e-7);
        // Sunny 16: EV100 15 exposes about 1/(1.2·32768).
        assert!((multiplier_of_ev100(15.0) - 1.0 / (1.2 * 32768.0)).abs() < 1e-9);
    }
}
