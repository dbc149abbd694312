//! `terrain.draw`: the geometry image drawn as a fixed-topology grid from the
//! vertex buffer `terrain.warp` wrote, with per-pixel bump mapping of the
//! detail octaves above the split octave and surface types from altitude,
//! slope and orientation (dissertation §7.4.3 "Procedural Detail" and
//! "Colour"; `ALGORITHMS.md` §3 items 6–8). Shaders:
//! `glsl/terrain/draw.vert`, `glsl/terrain/draw.frag`.

use bytemuck::{Pod, Zeroable};

use crate::error::Error;
use crate::error::Result;
use crate::graph::{Access, RenderGraph, ResourceId, Stage};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::terrain::geometry_image::{GeometryImage, VERTEX_STRIDE};
use crate::texturing::generation::{add_generation_passes, locked, AtlasResources, GenerationInputs, TextureStreaming};
use crate::texturing::gpu_layout::{pack_layers, TexturingFrame, TexturingMode};
use crate::texturing::input_maps::InputMaps;
use crate::texturing::layers::LayerTree;
use crate::view::FrameParams;
use crate::vulkan::{
    Blend, Buffer, BufferDesc, BufferUsageFlags, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc,
    LoadOp, MemoryLocation, PrimitiveTopology, VertexAttribute,
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
    /// amplitude, H, handles (bits: noise tile | texturing constants << 16,
    /// 0xffff: none), flags (bits).
    params: [f32; 4],
}

/// How `terrain.draw` colours the surface (§7.4.3 or §8.2).
pub struct TerrainTexturing<'a> {
    pub mode: TexturingMode,
    pub layers: &'a LayerTree,
    /// Atlas streaming (used by [`TexturingMode::Atlas`]).
    pub streaming: TextureStreaming,
    /// Extra input maps of the layers ([`crate::renderer::Scene::input_maps`]).
    pub input_maps: &'a [Option<HeightField>; 3],
}

/// Declares `terrain.draw` into `color` and `view_depth` (loaded: the sky
/// pass wrote them) with depth buffer `depth`; `heights` is the sketch atlas.
/// In [`TexturingMode::Atlas`] the tile generation passes come first
/// ([`add_generation_passes`]); their resources are returned.
pub fn add_draw_pass(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    terrain: &GeometryImage,
    (vertices, noise, heights): (ResourceId, ResourceId, ResourceId),
    (color, view_depth, depth): (ResourceId, ResourceId, ResourceId),
    image_height: u32,
    texturing: &TerrainTexturing,
) -> Result<Option<AtlasResources>> {
    let maps = InputMaps::import(ctx, graph, texturing.layers, texturing.input_maps)?;
    let layer_count = texturing.layers.layers.len() as u32;
    if layer_count == 0 {
        return Err(Error::invalid("surface layers", "the tree has no layer"));
    }
    let layer_buffer = Buffer::with_data(
        ctx,
        "surface layers",
        BufferUsageFlags::STORAGE_BUFFER,
        bytemuck::cast_slice(&pack_layers(texturing.layers)),
    )?;
    let layers = graph.import_buffer(std::sync::Arc::new(layer_buffer));
    let atlas = match texturing.mode {
        TexturingMode::Atlas => Some(add_generation_passes(
            ctx,
            graph,
            GenerationInputs {
                field: terrain.field.clone(),
                heights,
                noise,
                layers,
                maps,
                tree: texturing.layers,
                image_height,
            },
            texturing.streaming,
        )?),
        _ => None,
    };
    let frames = graph.import_buffers_per_frame(Buffer::per_frame(
        ctx,
        BufferDesc {
            name: "terrain texturing".into(),
            size: std::mem::size_of::<TexturingFrame>() as u64,
            usage: BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )?);
    let mode = texturing.mode;
    let field = terrain.field.clone();
    let (lo, hi) = field.min_max();
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
    let mut pass = graph
        .pass("terrain.draw")
        .graphics()
        .read(vertices, Access::VertexBuffer)
        .read(indices, Access::IndexBuffer)
        .read(noise, Access::SampledImage(Stage::Fragment))
        .read(heights, Access::SampledImage(Stage::Fragment))
        .read(layers, Access::StorageBufferRead(Stage::Fragment))
        .read(frames, Access::StorageBufferRead(Stage::Fragment));
    let extent = field.extent();
    for map in maps.present() {
        pass = pass.read(map, Access::SampledImage(Stage::Fragment));
    }
    let atlas_for_draw = atlas.clone();
    if let Some(a) = &atlas_for_draw {
        pass = pass.read(a.page_table, Access::StorageBufferRead(Stage::Fragment));
        for &image in a.colors.iter().chain(&a.normals) {
            pass = pass.read(image, Access::SampledImage(Stage::Fragment));
        }
    }
    pass.write(color, Access::ColorAttachmentReadWrite)
        .write(view_depth, Access::ColorAttachmentReadWrite)
        .write(depth, Access::DepthAttachmentWrite)
        .record(move |pass, params| {
            let camera = &params.camera;
            let pixel_footprint = 2.0 * (0.5 * camera.fov_y_deg.to_radians()).tan() / f64::from(image_height);
            let noise_handle = pass.sampled(noise)?;
            let mut frame = TexturingFrame {
                handles: [
                    pass.storage_buffer(layers)?,
                    pass.sampled(heights)?,
                    noise_handle,
                    mode.code(),
                ],
                grid: [field.columns, field.rows, layer_count, 0],
                spacing_range: [field.spacing.x as f32, field.spacing.y as f32, lo, hi],
                extent: [extent.x as f32, extent.y as f32, 0.0, 0.0],
                maps: maps.handles(|id| pass.sampled(id))?,
                ..TexturingFrame::zeroed()
            };
            if let Some(a) = &atlas_for_draw {
                let words = std::mem::take(&mut locked(&a.state)?.page_words);
                pass.buffer(a.page_table)?.write(0, bytemuck::cast_slice(&words))?;
                frame.atlas = [
                    pass.storage_buffer(a.page_table)?,
                    a.colors.len() as u32,
                    a.atlas_size,
                    0,
                ];
                for (k, (&c, &n)) in a.colors.iter().zip(&a.normals).enumerate() {
                    (frame.color[k], frame.normal[k]) = (pass.sampled(c)?, pass.sampled(n)?);
                }
            }
            let frame_handle = pass.storage_buffer(frames)?;
            pass.buffer(frames)?.write(0, bytemuck::bytes_of(&frame))?;
            if noise_handle > 0xffff || frame_handle >= 0xffff {
                return Err(Error::Graph("terrain.draw: descriptor handles exceed 16 bits".into()));
            }
            let push = TerrainDrawPush {
                view_proj: camera.view_proj(params.aspect).to_cols_array(),
                eye: camera.eye.as_vec3().extend(d0).to_array(),
                forward: camera.forward().as_vec3().extend(pixel_footprint as f32).to_array(),
                sun: params.sun.extend(params.snow_line).to_array(),
                params: [
                    settings.detail_amplitude,
                    settings.detail_h,
                    f32::from_bits(noise_handle | frame_handle << 16),
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
    Ok(atlas)
}
