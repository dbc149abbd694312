//! `tonemap`: absolute HDR radiance → 8-bit sRGB: the frame's exposure
//! (`exposure.meter`), a filmic tone curve (Hill's ACES fit), the sRGB curve.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, ImageAccess, RenderGraph, Stage};
use crate::shaders;
use crate::view::{pass_name, Frame, SceneTargets, View};
use crate::vulkan::{ComputePipeline, Context};

/// Push constants of `tonemap` (`glsl/post/tonemap.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TonemapPush {
    /// Storage image handles: HDR radiance (read), sRGB (written).
    radiance: u32,
    display: u32,
    /// Storage handle of the exposure buffer (`exposure.meter`).
    exposure: u32,
    _pad: u32,
    width: u32,
    height: u32,
    _pad2: [u32; 2],
}

/// Tone mapping: a pipeline, and one `tonemap` pass per view.
pub struct Tonemap {
    pipeline: Arc<ComputePipeline>,
}

impl Tonemap {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<Tonemap> {
        Ok(Tonemap {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::TONEMAP)?),
        })
    }

    /// Declares `tonemap` for `view`: its radiance, exposed by `exposure`,
    /// into its display image.
    pub fn declare<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        targets: &SceneTargets,
        exposure: BufferId,
    ) {
        let pipeline = self.pipeline.clone();
        let (radiance, display, width, height) = (targets.radiance, targets.display, targets.width, targets.height);
        graph
            .pass(&pass_name("tonemap", &view.name))
            .read(radiance, ImageAccess::StorageRead(Stage::Compute))
            .read(exposure, BufferAccess::StorageRead(Stage::Compute))
            .write(display, ImageAccess::StorageWrite(Stage::Compute))
            .record(move |pass, _| {
                let push = TonemapPush {
                    radiance: pass.storage_image(radiance)?,
                    display: pass.storage_image(display)?,
                    exposure: pass.storage_buffer(exposure)?,
                    width,
                    height,
                    ..TonemapPush::zeroed()
                };
                let cmd = pass.cmd();
                cmd.bind_compute(&pipeline);
                cmd.push_constants(&push)?;
                cmd.dispatch(width.div_ceil(8), height.div_ceil(8), 1);
                Ok(())
            });
    }
}
