//! `sky`: a full-screen triangle shading every pixel with the analytic sky
//! radiance along its view ray and clearing view-space depth to +inf. A
//! placeholder for the Perez/Preetham sky of §9.1 (ALGORITHMS.md §6).

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{Access, RenderGraph, ResourceId};
use crate::shaders;
use crate::view::FrameParams;
use crate::vulkan::{Context, Format, GraphicsPipeline, GraphicsPipelineDesc, LoadOp};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SkyPush {
    right: [f32; 4],
    up: [f32; 4],
    forward: [f32; 4],
    sun: [f32; 4],
}

/// Declares the `sky` pass writing `color` (HDR radiance) and `view_depth`.
pub fn add_sky_pass(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    color: ResourceId,
    view_depth: ResourceId,
) -> Result<()> {
    let pipeline = GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc::full_screen(
            "sky",
            (shaders::FULL_SCREEN_VERT, shaders::SKY_FRAG),
            vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT],
        ),
    )?;
    graph
        .pass("sky")
        .graphics()
        .write(color, Access::ColorAttachmentWrite)
        .write(view_depth, Access::ColorAttachmentWrite)
        .record(move |pass, params| {
            let (right, up, forward) = params.camera.ray_basis(params.aspect);
            let push = SkyPush {
                right: right.extend(0.0).to_array(),
                up: up.extend(0.0).to_array(),
                forward: forward.extend(0.0).to_array(),
                sun: params.sun.extend(0.0).to_array(),
            };
            let (color, view_depth) = (pass.image(color)?, pass.image(view_depth)?);
            let cmd = pass.cmd();
            cmd.begin_rendering(&[(color, LoadOp::DontCare), (view_depth, LoadOp::DontCare)], None);
            cmd.bind_graphics(&pipeline);
            cmd.push_constants(&push)?;
            cmd.draw(3, 1);
            cmd.end_rendering();
            Ok(())
        });
    Ok(())
}
