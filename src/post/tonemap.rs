//! `tonemap`: absolute HDR radiance → 8-bit sRGB: the frame's exposure
//! (`exposure.meter`), a filmic tone curve (Hill's ACES fit), the sRGB curve.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, ImageAccess, Stage};
use crate::shaders;
use crate::view::{pass_name, Declare, SceneTargets, ViewGraph};
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
}

/// `tonemap` of a view: its (post-processed) targets and exposure buffer
/// in, nothing out.
impl<S: 'static> Declare<S> for Tonemap {
    type Inputs<'a> = (&'a SceneTargets, BufferId);
    type Outputs = ();

    /// Declares `tonemap` for the view: its radiance, exposed by
    /// `exposure`, into its display image.
    fn declare(&mut self, at: ViewGraph<'_, S>, (targets, exposure): Self::Inputs<'_>) -> Result<()> {
        let (graph, view) = (at.graph, at.view);
        let pipeline = self.pipeline.clone();
        let (radiance, display, width, height) = (targets.radiance, targets.display, targets.width, targets.height);
        let mut pass = graph.pass(&pass_name("tonemap", &view.name));
        let radiance = pass.storage_image(radiance, ImageAccess::StorageRead(Stage::Compute));
        let exposure = pass.storage_buffer(exposure, BufferAccess::StorageRead(Stage::Compute));
        let display = pass.storage_image(display, ImageAccess::StorageWrite(Stage::Compute));
        pass.record(move |ctx, _| {
            let push = TonemapPush {
                radiance: ctx.handle(radiance)?,
                display: ctx.handle(display)?,
                exposure: ctx.handle(exposure)?,
                width,
                height,
                ..TonemapPush::zeroed()
            };
            ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
        });
        Ok(())
    }
}
