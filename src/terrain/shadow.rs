//! `terrain.shadow`: the view's warped geometry image (the vertex buffer
//! `terrain.warp` wrote, §7.4.2) drawn depth-only into each cascade's
//! quadrant of the view's shadow atlas (§9.5; [`crate::lighting::shadows`]),
//! with a slope-scaled bias applied in the vertex stage along the sun
//! direction (`glsl/lighting/shadow_terrain.vert`).
//!
//! The geometry image covers what the view's warp selected; terrain far
//! outside the view frustum that could shadow it is only as detailed as the
//! warp made it there.
//!
//! On the compute path ([`Terrain::use_compute_raster`], issue 28) the
//! casters are rasterized by compute shaders instead ([`ComputeCasters`]),
//! culled per cascade, into the atlas's buffer of depth bits
//! ([`ShadowTarget::depths`]), which the point casters write too and
//! `shadow.copy` then copies into the atlas (which `shadow.clear` need not
//! clear):
//!
//! | pass | does |
//! |---|---|
//! | `terrain.shadow_clear` | the depth buffer at 1, the big-triangle lists empty |
//! | `terrain.shadow` | per cascade, one thread a triangle: culls against the quadrant and depth range, rasterizes the small ones (`atomicMin` of the depth bits), lists the rest |
//! | `terrain.shadow_big` | per cascade, one workgroup a listed triangle |
//! | (`points.shadow`, `shadow.copy`) | the point casters; the depth buffer into the D32 atlas |
//!
//! Shaders: `glsl/terrain/shadow_clear.comp`, `shadow_raster.comp`,
//! `shadow_raster_big.comp`; `glsl/include/terrain_shadow_raster.glsl`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use super::geometry_image::VERTEX_STRIDE;
use super::Terrain;
use crate::error::{Error, Result};
use crate::graph::{stride_groups, BufferAccess, BufferId, BufferInfo, RenderGraph, Stage};
use crate::lighting::constants::MAX_CASCADES;
use crate::lighting::shadows::{
    cascade_pushes, record_cascades, SceneBounds, ShadowFrame, ShadowTarget, SHADOW_FORMAT,
};
use crate::shaders;
use crate::view::{pass_name, Frame, Provides, View, ViewIndex};
use crate::vulkan::{
    CompareOp, ComputePipeline, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, MemoryLocation,
    PrimitiveTopology, VertexAttribute,
};

/// Margin (m) above the highest sample for the procedural detail the warp adds.
const DETAIL_MARGIN: f64 = 50.0;

/// The depth-only pipeline of `terrain.shadow`.
pub fn shadow_pipeline(ctx: &Context) -> Result<GraphicsPipeline> {
    let attribute = |location, offset| VertexAttribute {
        location,
        format: Format::R32G32B32A32_SFLOAT,
        offset,
    };
    GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc {
            name: "terrain.shadow",
            vertex: shaders::SHADOW_TERRAIN_VERT,
            fragment: shaders::SHADOW_DEPTH_FRAG,
            vertex_stride: VERTEX_STRIDE,
            vertex_attributes: vec![attribute(0, 0), attribute(1, 16)],
            topology: PrimitiveTopology::TRIANGLE_LIST,
            cull_back_faces: false,
            wireframe: false,
            color_formats: Vec::new(),
            blend: crate::vulkan::Blend::None,
            depth_format: Some(SHADOW_FORMAT),
            depth_test: true,
            depth_write: true,
            depth_compare: CompareOp::LESS_OR_EQUAL,
        },
    )
}

/// Push constants of the compute casters (`Push` in
/// `glsl/include/terrain_shadow_raster.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct CasterRasterPush {
    /// World → atlas clip space of the cascade.
    view_proj: [f32; 16],
    /// xyz: towards the sun; w: texel size (m).
    sun_texel: [f32; 4],
    /// Grid vertices, depth buffer, big-triangle lists, cascade.
    handles: [u32; 4],
    /// Grid side, triangles, atlas side, texels.
    grid: [u32; 4],
    /// The cascade's receivers' texel box (first x, y, last x, y).
    receivers: [u32; 4],
}

/// Workgroups of `terrain.shadow_big` (each loops over the list).
const BIG_WORKGROUPS: u32 = 256;

/// The compute path's shadow casters: pipelines shared by every view.
pub struct ComputeCasters {
    clear: Arc<ComputePipeline>,
    raster: Arc<ComputePipeline>,
    big: Arc<ComputePipeline>,
}

/// What one view's compute casters read and write.
struct CasterBuffers {
    vertices: BufferId,
    depths: BufferId,
    lists: BufferId,
}

impl ComputeCasters {
    /// Builds the pipelines.
    pub fn new(ctx: &Context) -> Result<ComputeCasters> {
        let pipeline = |spirv| ComputePipeline::new(ctx, spirv).map(Arc::new);
        Ok(ComputeCasters {
            clear: pipeline(shaders::TERRAIN_SHADOW_CLEAR)?,
            raster: pipeline(shaders::TERRAIN_SHADOW_RASTER)?,
            big: pipeline(shaders::TERRAIN_SHADOW_RASTER_BIG)?,
        })
    }

    /// Declares the compute casters of view `index` (a `grid_side`² grid in
    /// `vertices`) into its atlas `target`: every texel written, so the
    /// atlas needs no `shadow.clear`.
    fn declare<S: Provides<ShadowFrame> + 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
        (vertices, grid_side): (BufferId, u32),
        target: ShadowTarget,
    ) -> Result<()> {
        let side = grid_side.max(2);
        let triangles = 2 * (side - 1) * (side - 1);
        let texels = target.size * target.size;
        let buffer = |graph: &mut RenderGraph<Frame<S>>, name, size| {
            let location = MemoryLocation::GpuOnly;
            graph.create_buffer(&pass_name(name, &view.name), BufferInfo { size, location })
        };
        let depths =
            (target.depths).ok_or_else(|| Error::Graph("terrain.shadow: the atlas has no depth bits".into()))?;
        let lists = buffer(
            graph,
            "terrain shadow big triangles",
            16 + 4 * MAX_CASCADES as u64 * u64::from(triangles),
        );
        let buffers = CasterBuffers {
            vertices,
            depths,
            lists,
        };
        let grid = [side, triangles, target.size, texels];
        self.declare_clear(graph, view, &buffers, grid);
        let rasters = [
            ("terrain.shadow", self.raster.clone(), stride_groups(triangles, 64)),
            ("terrain.shadow_big", self.big.clone(), BIG_WORKGROUPS),
        ];
        for (base, pipeline, groups) in rasters {
            let compute = Stage::Compute;
            let mut pass = graph.pass(&pass_name(base, &view.name));
            let vertices = pass.storage_buffer(buffers.vertices, BufferAccess::StorageRead(compute));
            let depths = pass.storage_buffer(buffers.depths, BufferAccess::StorageReadWrite(compute));
            let lists = pass.storage_buffer(buffers.lists, BufferAccess::StorageReadWrite(compute));
            pass.record(move |ctx, frame| {
                let plan = frame.prepared::<ShadowFrame>()?.view(index)?;
                let handles = [ctx.handle(vertices)?, ctx.handle(depths)?, ctx.handle(lists)?];
                for (cascade, receivers, push) in cascade_pushes(plan) {
                    let push = CasterRasterPush {
                        view_proj: push.view_proj,
                        sun_texel: push.sun_texel,
                        handles: [handles[0], handles[1], handles[2], cascade],
                        grid,
                        receivers,
                    };
                    ctx.dispatch(&pipeline, &push, [groups, 1, 1])?;
                }
                Ok(())
            });
        }
        Ok(())
    }

    /// `terrain.shadow_clear`.
    fn declare_clear<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        buffers: &CasterBuffers,
        grid: [u32; 4],
    ) {
        let compute = Stage::Compute;
        let pipeline = self.clear.clone();
        let mut pass = graph.pass(&pass_name("terrain.shadow_clear", &view.name));
        let depths = pass.storage_buffer(buffers.depths, BufferAccess::StorageWrite(compute));
        let lists = pass.storage_buffer(buffers.lists, BufferAccess::StorageWrite(compute));
        pass.record(move |ctx, _| {
            let push = CasterRasterPush {
                handles: [0, ctx.handle(depths)?, ctx.handle(lists)?, 0],
                grid,
                ..CasterRasterPush::zeroed()
            };
            ctx.dispatch(&pipeline, &push, [stride_groups(grid[3], 256), 1, 1])
        });
    }
}

impl Terrain {
    /// The box holding the terrain's casters (the height field's extent and
    /// height range, with a margin for procedural detail), for
    /// [`crate::lighting::shadows::ShadowMaps::new`].
    pub fn shadow_bounds(&self, index: ViewIndex) -> Result<SceneBounds> {
        let (_, _, _, b) = self.shadow_geometry(index)?;
        Ok(SceneBounds {
            min: DVec3::new(b[0], b[1], b[2] - DETAIL_MARGIN),
            max: DVec3::new(b[3], b[4], b[5] + DETAIL_MARGIN),
        })
    }

    /// Whether the terrain's shadow casters write every texel of the
    /// atlas (the compute path's do: the atlas needs no `shadow.clear`).
    pub fn casts_in_compute(&self) -> bool {
        self.compute_casters().is_some()
    }

    /// Declares `terrain.shadow` of view `index` into its atlas `target`
    /// (after `terrain.warp` of that view; on the hardware path after
    /// `shadow.clear`; the cascades come from the frame's [`ShadowFrame`]).
    pub fn declare_shadow<S: Provides<ShadowFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
        target: ShadowTarget,
    ) -> Result<()> {
        let (vertices, indices, index_count, _) = self.shadow_geometry(index)?;
        if let Some(casters) = self.compute_casters() {
            if target.size % 2 != 0 {
                return Err(Error::invalid("shadows.atlas_size", "must be even"));
            }
            return casters.declare(graph, (index, view), (vertices, self.grid_side()), target);
        }
        let pipeline = shadow_pipeline(ctx)?;
        let atlas = target.atlas;
        graph
            .pass(&pass_name("terrain.shadow", &view.name))
            .graphics()
            .read(vertices, BufferAccess::Vertex)
            .read(indices, BufferAccess::Index)
            .pipeline(&pipeline)
            .depth(atlas, None)
            .record(move |ctx, frame| {
                let plan = frame.prepared::<ShadowFrame>()?.view(index)?;
                let (vertices, indices) = (ctx.buffer(vertices)?, ctx.buffer(indices)?);
                record_cascades(ctx.cmd(), plan, |cmd, push| {
                    cmd.bind_graphics(&pipeline);
                    cmd.push_constants(&push)?;
                    cmd.bind_vertex_buffer(vertices);
                    cmd.bind_index_buffer(indices);
                    cmd.draw_indexed(index_count, 1);
                    Ok(())
                })
            });
        Ok(())
    }
}
