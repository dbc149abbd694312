//! `terrain.draw`: the geometry image drawn as a fixed-topology grid from the
//! vertex buffer `terrain.warp` wrote, with per-pixel bump mapping of the
//! detail octaves above the split octave and surface types from altitude,
//! slope and orientation (dissertation §7.4.3 "Procedural Detail" and
//! "Colour"; `ALGORITHMS.md` §3 items 6–8). Shaders:
//! `glsl/terrain/draw.vert`, `glsl/terrain/draw.frag`.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{Access, RenderGraph, ResourceId, Stage};
use crate::renderer::FrameParams;
use crate::shaders;
use crate::terrain::geometry_image::{GeometryImage, VERTEX_STRIDE};
use crate::vulkan::{
    Blend, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, LoadOp, PrimitiveTopology,
    VertexAttribute,
};

/// Push constants of `terrain.draw` (`glsl/include/terrain_draw.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TerrainDrawPush {
    view_proj: [f32; 16],
    /// xyz, w = d0.
    eye: [f32; 4],
    /// xyz, w = pixel footprint per metre of depth.
    forward: [f32; 4],
    /// xyz, w = snow line.
    sun: [f32; 4],
    /// amplitude, H, noise tile handle (bits), flags (bits).
    params: [f32; 4],
}

/// Declares `terrain.draw` into `color` and `view_depth` (loaded: the sky
/// pass wrote them) with depth buffer `depth`.
pub fn add_draw_pass(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    terrain: &GeometryImage,
    (vertices, noise): (ResourceId, ResourceId),
    (color, view_depth, depth): (ResourceId, ResourceId, ResourceId),
    image_height: u32,
) -> Result<()> {
    let pipeline = GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc {
            name: "terrain.draw",
            vertex: shaders::TERRAIN_DRAW_VERT,
            fragment: shaders::TERRAIN_DRAW_FRAG,
            vertex_stride: VERTEX_STRIDE,
            vertex_attributes: vec![
                VertexAttribute {
                    location: 0,
                    format: Format::R32G32B32A32_SFLOAT,
                    offset: 0,
                },
                VertexAttribute {
                    location: 1,
                    format: Format::R32G32B32A32_SFLOAT,
                    offset: 16,
                },
            ],
            topology: PrimitiveTopology::TRIANGLE_LIST,
            cull_back_faces: false,
            wireframe: false,
            color_formats: vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT],
            blend: Blend::None,
            depth_format: Some(Format::D32_SFLOAT),
            depth_test: true,
            depth_write: true,
            depth_compare: CompareOp::LESS,
        },
    )?;
    let indices = graph.import_buffer(terrain.indices.clone());
    let side = terrain.settings.grid_side;
    let index_count = (side - 1) * (side - 1) * 6;
    let settings = terrain.settings;
    let d0 = terrain.atlas_spacing();
    graph
        .pass("terrain.draw")
        .graphics()
        .read(vertices, Access::VertexBuffer)
        .read(indices, Access::IndexBuffer)
        .read(noise, Access::SampledImage(Stage::Fragment))
        .write(color, Access::ColorAttachmentReadWrite)
        .write(view_depth, Access::ColorAttachmentReadWrite)
        .write(depth, Access::DepthAttachmentWrite)
        .record(move |pass, params| {
            let camera = &params.camera;
            let pixel_footprint = 2.0 * (0.5 * camera.fov_y_deg.to_radians()).tan() / f64::from(image_height);
            let push = TerrainDrawPush {
                view_proj: camera.view_proj(params.aspect).to_cols_array(),
                eye: camera.eye.as_vec3().extend(d0).to_array(),
                forward: camera.forward().as_vec3().extend(pixel_footprint as f32).to_array(),
                sun: params.sun.extend(params.snow_line).to_array(),
                params: [
                    settings.detail_amplitude,
                    settings.detail_h,
                    f32::from_bits(pass.sampled(noise)?),
                    f32::from_bits(settings.draw_flags()),
                ],
            };
            let (color, view_depth, depth) = (pass.image(color)?, pass.image(view_depth)?, pass.image(depth)?);
            let (vertices, indices) = (pass.buffer(vertices)?, pass.buffer(indices)?);
            let cmd = pass.cmd();
            cmd.begin_rendering(
                &[(color, LoadOp::Load), (view_depth, LoadOp::Load)],
                Some((depth, Some(1.0))),
            );
            cmd.bind_graphics(&pipeline);
            cmd.push_constants(&push)?;
            cmd.bind_vertex_buffer(vertices);
            cmd.bind_index_buffer(indices);
            cmd.draw_indexed(index_count, 1);
            cmd.end_rendering();
            Ok(())
        });
    Ok(())
}
