//! The terrain as a plain regular grid, generated on the GPU:
//! `terrain.grid` (compute) samples the height field and writes every vertex
//! into a storage buffer, and `terrain.draw` draws that buffer as its vertex
//! buffer — the render-to-vertex-buffer pair of §7.4.4 that the geometry-image
//! warping of §7.4 will feed with warped positions instead of a regular grid.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::graph::{Access, RenderGraph, ResourceId, Stage};
use crate::io::heightmap::HeightField;
use crate::renderer::FrameParams;
use crate::shaders;
use crate::vulkan::{
    Blend, Buffer, BufferDesc, BufferUsageFlags, CompareOp, ComputePipeline, Context, Format, GraphicsPipeline,
    GraphicsPipelineDesc, Image, ImageDesc, ImageUsageFlags, LoadOp, MemoryLocation, PrimitiveTopology,
    VertexAttribute,
};

/// Largest grid side; larger height fields are resampled (bilinearly).
pub const MAX_GRID_SIDE: u32 = 1024;
/// Bytes per vertex: position (vec4) and normal (vec4).
pub const VERTEX_STRIDE: u32 = 32;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GridPush {
    spacing: [f32; 4],
    grid: [u32; 4],
    handles: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct DrawPush {
    view_proj: [f32; 16],
    eye: [f32; 4],
    forward: [f32; 4],
    sun: [f32; 4],
}

/// GPU resources of the grid terrain: the height texture, the vertex buffer
/// the compute pass writes, and the fixed index buffer.
pub struct TerrainGrid {
    pub heights: Arc<Image>,
    pub vertices: Arc<Buffer>,
    pub indices: Arc<Buffer>,
    pub columns: u32,
    pub rows: u32,
    pub spacing: [f32; 2],
    pub height_size: [u32; 2],
}

/// Indices of the two triangles of every grid cell, counter-clockwise seen
/// from above (+Z).
pub fn grid_indices(columns: u32, rows: u32) -> Vec<u32> {
    let mut indices = Vec::with_capacity(((columns - 1) * (rows - 1) * 6) as usize);
    for r in 0..rows - 1 {
        for c in 0..columns - 1 {
            let i = r * columns + c;
            indices.extend_from_slice(&[i, i + 1, i + columns, i + 1, i + columns + 1, i + columns]);
        }
    }
    indices
}

impl TerrainGrid {
    /// Uploads the height field and creates the vertex and index buffers.
    pub fn new(ctx: &Context, field: &HeightField) -> Result<TerrainGrid> {
        let max = ctx.max_image_dimension();
        if field.columns > max || field.rows > max {
            return Err(Error::invalid(
                "height field",
                format!(
                    "{}×{} samples exceed the device's image limit of {max} per side",
                    field.columns, field.rows
                ),
            ));
        }
        let heights = Image::with_data(
            ctx,
            ImageDesc {
                name: "terrain heights".into(),
                width: field.columns,
                height: field.rows,
                format: Format::R32_SFLOAT,
                usage: ImageUsageFlags::SAMPLED,
            },
            bytemuck::cast_slice(&field.heights),
        )?;
        let columns = field.columns.min(MAX_GRID_SIDE);
        let rows = field.rows.min(MAX_GRID_SIDE);
        let vertices = Buffer::new(
            ctx,
            BufferDesc {
                name: "terrain vertices".into(),
                size: (columns * rows * VERTEX_STRIDE) as u64,
                usage: BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::VERTEX_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let indices = Buffer::with_data(
            ctx,
            "terrain indices",
            BufferUsageFlags::INDEX_BUFFER,
            bytemuck::cast_slice(&grid_indices(columns, rows)),
        )?;
        Ok(TerrainGrid {
            heights: Arc::new(heights),
            vertices: Arc::new(vertices),
            indices: Arc::new(indices),
            columns,
            rows,
            spacing: [field.spacing.x as f32, field.spacing.y as f32],
            height_size: [field.columns, field.rows],
        })
    }

    /// Declares `terrain.grid` and `terrain.draw`: the grid drawn with depth
    /// test into `color` and `view_depth` (loaded: the sky pass wrote them).
    pub fn add_passes(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<FrameParams>,
        color: ResourceId,
        view_depth: ResourceId,
        depth: ResourceId,
    ) -> Result<()> {
        let heights = graph.import_image(self.heights.clone());
        let vertices = graph.import_buffer(self.vertices.clone());
        let indices = graph.import_buffer(self.indices.clone());

        let grid_pipeline = ComputePipeline::new(ctx, shaders::TERRAIN_GRID)?;
        let (columns, rows, spacing, height_size) = (self.columns, self.rows, self.spacing, self.height_size);
        graph
            .pass("terrain.grid")
            .read(heights, Access::SampledImage(Stage::Compute))
            .write(vertices, Access::StorageBufferWrite(Stage::Compute))
            .record(move |pass, _params| {
                let push = GridPush {
                    spacing: [spacing[0], spacing[1], 1.0, 0.0],
                    grid: [columns, rows, height_size[0], height_size[1]],
                    handles: [pass.sampled(heights)?, pass.storage_buffer(vertices)?, 0, 0],
                };
                let cmd = pass.cmd();
                cmd.bind_compute(&grid_pipeline);
                cmd.push_constants(&push)?;
                cmd.dispatch(columns.div_ceil(8), rows.div_ceil(8), 1);
                Ok(())
            });

        let draw_pipeline = GraphicsPipeline::new(
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
        let index_count = (columns - 1) * (rows - 1) * 6;
        graph
            .pass("terrain.draw")
            .graphics()
            .read(vertices, Access::VertexBuffer)
            .read(indices, Access::IndexBuffer)
            .write(color, Access::ColorAttachmentReadWrite)
            .write(view_depth, Access::ColorAttachmentReadWrite)
            .write(depth, Access::DepthAttachmentWrite)
            .record(move |pass, params| {
                let camera = &params.camera;
                let push = DrawPush {
                    view_proj: camera.view_proj(params.aspect).to_cols_array(),
                    eye: camera.eye.as_vec3().extend(1.0).to_array(),
                    forward: camera.forward().as_vec3().extend(0.0).to_array(),
                    sun: params.sun.extend(params.snow_line).to_array(),
                };
                let (color, view_depth, depth) = (pass.image(color)?, pass.image(view_depth)?, pass.image(depth)?);
                let (vertices, indices) = (pass.buffer(vertices)?, pass.buffer(indices)?);
                let cmd = pass.cmd();
                cmd.begin_rendering(
                    &[(color, LoadOp::Load), (view_depth, LoadOp::Load)],
                    Some((depth, Some(1.0))),
                );
                cmd.bind_graphics(&draw_pipeline);
                cmd.push_constants(&push)?;
                cmd.bind_vertex_buffer(vertices);
                cmd.bind_index_buffer(indices);
                cmd.draw_indexed(index_count, 1);
                cmd.end_rendering();
                Ok(())
            });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::grid_indices;

    #[test]
    fn grid_indices_cover_every_cell_once() {
        let idx = grid_indices(3, 2);
        assert_eq!(idx, vec![0, 1, 3, 1, 4, 3, 1, 2, 4, 2, 5, 4]);
    }
}
