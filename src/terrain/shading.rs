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
use crate::graph::{
    Binding, BufferAccess, BufferId, ImageId, PassBuilder, PassContext, RenderGraph, Stage, UploadRegion,
};
use crate::shaders;
use crate::surface::gpu_layout::{DetailPush, LayerTable, TexturingFrame};
use crate::surface::input_maps::{InputMaps, MapBindings};
use crate::terrain::geometry_image::VERTEX_STRIDE;
use crate::terrain::TerrainFrame;
use crate::texturing::generation::AtlasBindings;
use crate::view::{Frame, LightingBindings, Provides, SceneTargets, ViewIndex};
use crate::vulkan::{
    Blend, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, LoadOp, PrimitiveTopology, VertexAttribute,
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
    pub surface: SurfaceInputs,
}

/// What the terrain's surface shading reads besides the geometry
/// (`glsl/include/terrain_shade.glsl`), in either path.
#[derive(Clone, Debug)]
pub struct SurfaceInputs {
    /// Noise tile and sketch atlas (sampled by direct texturing).
    pub noise: ImageId,
    pub heights: ImageId,
    /// The surface layers, their input maps and the frame's texturing constants.
    pub layers: LayerTable,
    pub maps: InputMaps,
    pub constants: UploadRegion,
    /// The texturing constants but for their heap handles.
    pub texturing: TexturingFrame,
    /// The texture atlas and page table (atlas texturing only).
    pub atlas: Option<AtlasBindings>,
    /// The streamed detail window (`crate::terrain::detail`), if the
    /// terrain has one: direct texturing reads the ground it draws.
    pub window: Option<ImageId>,
}

/// The bindings of [`SurfaceInputs`] on a shading pass.
pub struct SurfaceBindings {
    noise: Binding,
    heights: Binding,
    table: Binding,
    maps: MapBindings,
    constants: Binding,
    atlas: Option<AtlasSamples>,
    window: Option<Binding>,
    lighting: LightingBindings,
}

impl SurfaceBindings {
    /// The view's lighting constants and maps, as declared on the pass.
    pub fn lighting(&self) -> &LightingBindings {
        &self.lighting
    }
}

/// The heap handles the surface shading reads (`TerrainParams`).
pub struct SurfaceHandles {
    pub lighting: u32,
    pub noise_tile: u32,
    pub texturing_frame: u32,
}

impl SurfaceInputs {
    /// Declares that `builder` (shading at `stage`) reads the surface
    /// inputs and the view's lighting (`targets`).
    pub fn read_in<P: 'static>(
        &self,
        builder: &mut PassBuilder<'_, P>,
        targets: &SceneTargets,
        stage: Stage,
    ) -> SurfaceBindings {
        SurfaceBindings {
            noise: builder.sample(self.noise, stage),
            heights: builder.sample(self.heights, stage),
            table: self.layers.read_in(builder, stage),
            maps: self.maps.sample_in(builder, stage),
            constants: builder.upload(self.constants, stage),
            atlas: (self.atlas.as_ref()).map(|atlas| AtlasSamples::declare(builder, atlas, stage)),
            window: self.window.map(|w| builder.sample(w, stage)),
            lighting: targets.lighting.read_in(builder, stage),
        }
    }

    /// Writes the frame's layers table and texturing constants (with the
    /// handles of `bindings` and the frame's detail window `window`) while
    /// recording; returns what the shaders take in their push constants.
    pub fn write(
        &self,
        ctx: &mut PassContext<'_>,
        bindings: &SurfaceBindings,
        window: DetailPush,
    ) -> Result<SurfaceHandles> {
        let b = bindings;
        self.layers.write(ctx, b.table, &b.maps)?;
        let mut texturing = self.texturing;
        texturing.handles[..3].copy_from_slice(&[ctx.handle(b.table)?, ctx.handle(b.heights)?, ctx.handle(b.noise)?]);
        texturing.maps = b.maps.handles(ctx)?;
        if let Some(atlas) = &b.atlas {
            atlas.set_handles(ctx, &mut texturing)?;
        }
        texturing.window = window.bound(b.window, ctx)?;
        ctx.write_upload_pod(b.constants, &texturing)?;
        Ok(SurfaceHandles {
            lighting: ctx.handle(b.lighting.constants)?,
            noise_tile: ctx.handle(b.noise)?,
            texturing_frame: ctx.handle(b.constants)?,
        })
    }
}

/// What `terrain.draw` samples of the texture atlas.
struct AtlasSamples {
    page_table: Binding,
    colors: Vec<Binding>,
    normals: Vec<Binding>,
}

impl AtlasSamples {
    /// Declares that `builder` reads `atlas` at `stage`.
    fn declare<P: 'static>(builder: &mut PassBuilder<'_, P>, atlas: &AtlasBindings, stage: Stage) -> AtlasSamples {
        AtlasSamples {
            page_table: builder.upload(atlas.page_table, stage),
            colors: atlas.colors.iter().map(|&image| builder.sample(image, stage)).collect(),
            normals: atlas
                .normals
                .iter()
                .map(|&image| builder.sample(image, stage))
                .collect(),
        }
    }

    /// Puts the atlas's heap handles into `frame`.
    fn set_handles(&self, ctx: &PassContext<'_>, frame: &mut TexturingFrame) -> Result<()> {
        frame.atlas[0] = ctx.handle(self.page_table)?;
        for (k, (&color, &normal)) in self.colors.iter().zip(&self.normals).enumerate() {
            (frame.color[k], frame.normal[k]) = (ctx.handle(color)?, ctx.handle(normal)?);
        }
        Ok(())
    }
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
            depth_compare: crate::view::depth::NEARER,
        },
    )
}

/// Declares `terrain.draw` for one view into its radiance and view depth
/// (loaded: the sky pass wrote them) with its depth buffer (cleared). Its
/// push constants come from the view's [`crate::terrain::TerrainFrame`];
/// it writes the frame's layers buffer and texturing constants, which hold
/// the handles of what it declared.
pub fn declare_draw_pass<S: Provides<TerrainFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    pass: DrawPass,
    targets: &SceneTargets,
) -> Result<()> {
    let pipeline = pipeline(ctx, targets)?;
    let mut builder = graph
        .pass(name)
        .graphics()
        .read(pass.vertices, BufferAccess::Vertex)
        .read(pass.indices, BufferAccess::Index);
    let surface = pass.surface.read_in(&mut builder, targets, Stage::Fragment);
    let load = LoadOp::Load;
    builder
        .pipeline(&pipeline)
        .color(targets.radiance, load)
        .color(targets.view_depth, load)
        .color(targets.visibility, load)
        .color(targets.normal, load)
        .color(targets.ids, load)
        .depth(targets.depth, Some(crate::view::depth::FAR_DEPTH))
        .record(move |ctx, frame| {
            let prepared = frame.prepared::<crate::terrain::TerrainFrame>()?.view(pass.view)?.draw;
            let window = frame.prepared::<crate::terrain::TerrainFrame>()?.detail.push;
            let handles = pass.surface.write(ctx, &surface, window)?;
            let push = TerrainDrawPush {
                lighting: [handles.lighting, 0, 0, 0],
                noise_tile: handles.noise_tile,
                texturing_frame: handles.texturing_frame,
                ..prepared
            };
            let (vertices, indices) = (ctx.buffer(pass.vertices)?, ctx.buffer(pass.indices)?);
            let cmd = ctx.cmd();
            cmd.bind_graphics(&pipeline);
            cmd.push_constants(&push)?;
            cmd.bind_vertex_buffer(vertices);
            cmd.bind_index_buffer(indices);
            cmd.draw_indexed(pass.index_count, 1);
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
