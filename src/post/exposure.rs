//! `exposure.meter`: the exposure of a frame of absolute radiance (§9, the
//! HDR target holds cd/m²-scaled linear sRGB). Automatic: the mean log2
//! luminance of the view, metered on the GPU by one workgroup in a fixed
//! order (deterministic frames), mapped to a camera's saturation-based
//! exposure (EV100 = log2(L_avg·S/K), S = 100, K = 12.5; multiplier
//! 1/(1.2·2^EV100)). Manual: `--exposure EV100`. The multiplier goes into a
//! small GPU buffer the tone curve reads. Shader: `glsl/post/exposure.comp`.

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
    radiance: u32,
    exposure: u32,
    _pad: [u32; 2],
    width: u32,
    height: u32,
    _pad2: [u32; 2],
    /// Manual multiplier (0: automatic).
    manual: f32,
    /// EV compensation (automatic only).
    compensation: f32,
    _pad3: [f32; 2],
}

/// The exposure multiplier of a manual EV100.
pub fn multiplier_of_ev100(ev100: f32) -> f32 {
    1.0 / (1.2 * ev100.exp2())
}

/// The exposure meter: a pipeline, and one `exposure.meter` pass per view.
pub struct ExposureMeter {
    pipeline: Arc<ComputePipeline>,
}

impl ExposureMeter {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<ExposureMeter> {
        Ok(ExposureMeter {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::EXPOSURE_METER)?),
        })
    }
}

/// `exposure.meter` of a view: its (post-processed) targets in, its
/// exposure buffer out.
impl<S: 'static> Declare<S> for ExposureMeter {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = BufferId;

    /// Declares `exposure.meter` for the view: reads its radiance, writes
    /// and returns the view's exposure buffer (read by `tonemap`).
    fn declare(&mut self, at: ViewGraph<'_, S>, targets: &SceneTargets) -> Result<BufferId> {
        let (graph, view) = (at.graph, at.view);
        let exposure = graph.create_buffer(
            &pass_name("exposure", &view.name),
            BufferInfo {
                size: EXPOSURE_BYTES,
                location: MemoryLocation::GpuOnly,
            },
        );
        let pipeline = self.pipeline.clone();
        let (radiance, width, height) = (targets.radiance, targets.width, targets.height);
        let mut pass = graph.pass(&pass_name("exposure.meter", &view.name));
        let radiance = pass.storage_image(radiance, ImageAccess::StorageRead(Stage::Compute));
        let output = pass.storage_buffer(exposure, BufferAccess::StorageWrite(Stage::Compute));
        pass.record(move |ctx, frame| {
            let manual = match frame.lighting.exposure {
                Exposure::Auto => 0.0,
                Exposure::Ev100(ev) => multiplier_of_ev100(ev),
            };
            let push = MeterPush {
                radiance: ctx.handle(radiance)?,
                exposure: ctx.handle(output)?,
                width,
                height,
                manual,
                ..MeterPush::zeroed()
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
