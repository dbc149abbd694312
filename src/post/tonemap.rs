//! `tonemap`: HDR radiance → 8-bit sRGB (exposure, ACES fit, sRGB curve).

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{Access, RenderGraph, ResourceId, Stage};
use crate::shaders;
use crate::view::FrameParams;
use crate::vulkan::{ComputePipeline, Context};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TonemapPush {
    handles: [u32; 4],
    size: [u32; 4],
    exposure: [f32; 4],
}

/// Declares the `tonemap` pass from `hdr` (RGBA32F) into `ldr` (RGBA8).
pub fn add_tonemap_pass(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    hdr: ResourceId,
    ldr: ResourceId,
    size: (u32, u32),
) -> Result<()> {
    let pipeline = ComputePipeline::new(ctx, shaders::TONEMAP)?;
    graph
        .pass("tonemap")
        .read(hdr, Access::StorageImageRead(Stage::Compute))
        .write(ldr, Access::StorageImageWrite(Stage::Compute))
        .record(move |pass, params| {
            let push = TonemapPush {
                handles: [pass.storage_image(hdr)?, pass.storage_image(ldr)?, 0, 0],
                size: [size.0, size.1, 0, 0],
                exposure: [params.exposure, 0.0, 0.0, 0.0],
            };
            let cmd = pass.cmd();
            cmd.bind_compute(&pipeline);
            cmd.push_constants(&push)?;
            cmd.dispatch(size.0.div_ceil(8), size.1.div_ceil(8), 1);
            Ok(())
        });
    Ok(())
}
