//! `sky`: a full-screen triangle shading every pixel with the analytic sky
//! radiance along its view ray and clearing view-space depth to +inf. A
//! placeholder for the Perez/Preetham sky of §9.1 (ALGORITHMS.md §6).

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{Access, RenderGraph, ResourceId};
use crate::renderer::FrameParams;
use crate::shaders;
use crate::vulkan::{
    Blend, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, LoadOp, PrimitiveTopology,
};

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
        &GraphicsPipelineDesc {
            name: "sky",
            vertex: shaders::SKY_VERT,
            fragment: shaders::SKY_FRAG,
            vertex_stride: 0,
            vertex_attributes: Vec::new(),
            topology: PrimitiveTopology::TRIANGLE_LIST,
            cull_back_faces: false,
            wireframe: false,
            color_formats: vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT],
            blend: Blend::None,
            depth_format: None,
            depth_test: false,
            depth_write: false,
            depth_compare: CompareOp::ALWAYS,
        },
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
