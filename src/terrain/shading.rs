//! `terrain.draw`: the geometry image drawn as a fixed-topology grid from the
//! vertex buffer `terrain.warp` wrote, with per-pixel bump mapping of the
//! detail octaves above the split octave and surface types from altitude,
//! slope and orientation (dissertation §7.4.3 "Procedural Detail" and
//! "Colour"; `ALGORITHMS.md` §3 items 6–8), or coloured by the surface-layer
//! tree (§8.2) per pixel or from the texture atlas through the page table.
//! Besides radiance and depth it writes the view's world shading normal and
//! semantic class (`crate::view::aov`).
//! Shaders: `glsl/terrain/draw.vert`, `glsl/terrain/draw.frag`.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::shaders;
use crate::surface::input_maps::InputMaps;
use crate::terrain::geometry_image::VERTEX_STRIDE;
use crate::texturing::generation::AtlasBindings;
use crate::view::{Frame, SceneTargets, ViewIndex};
use crate::vulkan::{
    Blend, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, LoadOp, PrimitiveTopology,
    VertexAttribute,
};

/// The classic surface types (§7.4.3) as the layers of the built-in tree
/// ([`crate::surface::layers::DEFAULT_LAYERS`]) their class reports:
/// (name, layer index), in the order of `CLASSIC_LAYER` in
/// `glsl/terrain/draw.frag`, which hard-codes the indices.
#[cfg(test)]
pub const CLASSIC_LAYERS: [(&str, u32); 4] = [("grass", 1), ("dry grass", 3), ("rock", 0), ("snow", 6)];

/// Push constants of `terrain.draw` (`glsl/include/terrain_draw.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TerrainDrawPush {
    pub view_proj: [f32; 16],
    /// xyz, w = d0.
    pub eye: [f32; 4],
    /// xyz, w = pixel footprint per metre of depth.
    pub forward: [f32; 4],
    /// x: storage handle of the view's lighting constants.
    pub lighting: [u32; 4],
    pub detail_amplitude: f32,
    pub detail_h: f32,
    /// Sampled handle of the wavelet noise tile.
    pub noise_tile: u32,
    /// Storage handle of this frame's texturing constants (`TexturingFrame`).
    pub texturing_frame: u32,
}

/// What one view's `terrain.draw` reads and writes.
#[derive(Clone, Debug)]
pub struct DrawPass {
    pub view: ViewIndex,
    /// The view's geometry image and the fixed grid's indices.
    pub vertices: BufferId,
    pub indices: BufferId,
    pub index_count: u32,
    /// Noise tile and sketch atlas (sampled by direct texturing).
    pub noise: ImageId,
    pub heights: ImageId,
    /// The surface layers, their input maps and the frame's texturing constants.
    pub layers: BufferId,
    pub maps: InputMaps,
    pub constants: UploadRegion,
    /// The texture atlas and page table (atlas texturing only).
    pub atlas: Option<AtlasBindings>,
}

fn pipeline(ctx: &Context, targets: &SceneTargets) -> Result<GraphicsPipeline> {
    let attribute = |location, offset| VertexAttribute {
        location,
        format: Format::R32G32B32A32_SFLOAT,
        offset,
    };
    GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc {
            name: "terrain.draw",
            vertex: shaders::TERRAIN_DRAW_VERT,
            fragment: shaders::TERRAIN_DRAW_FRAG,
            vertex_stride: VERTEX_STRIDE,
            vertex_attributes: vec![attribute(0, 0), attribute(1, 16)],
            topology: PrimitiveTopology::TRIANGLE_LIST,
            cull_back_faces: false,
            wireframe: false,
            color_formats: vec![
                targets.formats.radiance,
                targets.formats.view_depth,
                targets.formats.visibility,
                targets.formats.normal,
                targets.formats.ids,
            ],
            blend: Blend::None,
            depth_format: Some(targets.formats.depth),
            depth_test: true,
            depth_write: true,
            depth_compare: CompareOp::LESS,
        },
    )
}

/// Declares `terrain.draw` for one view into its radiance and view depth
/// (loaded: the sky pass wrote them) with its depth buffer (cleared). Its
/// push constants come from the view's [`crate::terrain::TerrainFrame`].
pub fn declare_draw_pass(
    ctx: &Context,
    graph: &mut RenderGraph<Frame>,
    name: &str,
    pass: DrawPass,
    targets: &SceneTargets,
) -> Result<()> {
    let pipeline = pipeline(ctx, targets)?;
    let mut builder = graph
        .pass(name)
        .graphics()
        .read(pass.vertices, BufferAccess::Vertex)
        .read(pass.indices, BufferAccess::Index)
        .read(pass.noise, ImageAccess::Sampled(Stage::Fragment))
        .read(pass.heights, ImageAccess::Sampled(Stage::Fragment))
        .read(pass.layers, BufferAccess::StorageRead(Stage::Fragment))
        .read(pass.constants, BufferAccess::StorageRead(Stage::Graphics));
    for map in pass.maps.present() {
        builder = builder.read(map, ImageAccess::Sampled(Stage::Fragment));
    }
    if let Some(atlas) = &pass.atlas {
        builder = builder.read(atlas.page_table, BufferAccess::StorageRead(Stage::Fragment));
        for &(image, _) in atlas.colors.iter().chain(&atlas.normals) {
            builder = builder.read(image, ImageAccess::Sampled(Stage::Fragment));
        }
    }
    let (radiance, view_depth, depth) = (targets.radiance, targets.view_depth, targets.depth);
    let (visibility, normal, ids) = (targets.visibility, targets.normal, targets.ids);
    builder = targets.lighting.read_in(builder, Stage::Fragment);
    builder
        .write(radiance, ImageAccess::ColorAttachmentReadWrite)
        .write(visibility, ImageAccess::ColorAttachmentReadWrite)
        .write(view_depth, ImageAccess::ColorAttachmentReadWrite)
        .write(normal, ImageAccess::ColorAttachmentReadWrite)
        .write(ids, ImageAccess::ColorAttachmentReadWrite)
        .write(depth, ImageAccess::DepthAttachmentWrite)
        .record(move |ctx, frame| {
            let push = frame.prepared::<crate::terrain::TerrainFrame>()?.view(pass.view)?.draw;
            let (radiance, view_depth, depth) = (ctx.image(radiance)?, ctx.image(view_depth)?, ctx.image(depth)?);
            let (vertices, indices) = (ctx.buffer(pass.vertices)?, ctx.buffer(pass.indices)?);
            let (visibility, normal, ids) = (ctx.image(visibility)?, ctx.image(normal)?, ctx.image(ids)?);
            let cmd = ctx.cmd();
            cmd.begin_rendering(
                &[
                    (radiance, LoadOp::Load),
                    (view_depth, LoadOp::Load),
                    (visibility, LoadOp::Load),
                    (normal, LoadOp::Load),
                    (ids, LoadOp::Load),
                ],
                Some((depth, Some(1.0))),
            );
            cmd.bind_graphics(&pipeline);
            cmd.push_constants(&push)?;
            cmd.bind_vertex_buffer(vertices);
            cmd.bind_index_buffer(indices);
            cmd.draw_indexed(pass.index_count, 1);
            cmd.end_rendering();
            Ok(())
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::CLASSIC_LAYERS;
    use crate::surface::layers::LayerTree;

    #[test]
    fn classic_types_name_layers_of_the_built_in_tree() {
        let tree = LayerTree::default_tree();
        for (name, index) in CLASSIC_LAYERS {
            assert_eq!(tree.layers[index as usize].layer.name, name);
        }
    }
}
