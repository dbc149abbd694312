//! `terrain.shadow`: the view's warped geometry image (the vertex buffer
//! `terrain.warp` wrote, §7.4.2) drawn depth-only into each cascade's
//! quadrant of the view's shadow atlas (§9.5; [`crate::lighting::shadows`]),
//! with a slope-scaled bias applied in the vertex stage along the sun
//! direction (`glsl/lighting/shadow_terrain.vert`).
//!
//! The geometry image covers what the view's warp selected; terrain far
//! outside the view frustum that could shadow it is only as detailed as the
//! warp made it there.

use glam::DVec3;

use super::geometry_image::VERTEX_STRIDE;
use super::Terrain;
use crate::error::Result;
use crate::graph::{BufferAccess, RenderGraph};
use crate::lighting::shadows::{record_cascades, SceneBounds, ShadowFrame, ShadowTarget, SHADOW_FORMAT};
use crate::shaders;
use crate::view::{pass_name, Frame, Provides, View, ViewIndex};
use crate::vulkan::{
    CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, PrimitiveTopology, VertexAttribute,
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

    /// Declares `terrain.shadow` of view `index` into its atlas `target`
    /// (after `terrain.warp` of that view and `shadow.clear`; the cascades
    /// come from the frame's [`ShadowFrame`]).
    pub fn declare_shadow<S: Provides<ShadowFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
        target: ShadowTarget,
    ) -> Result<()> {
        let (vertices, indices, index_count, _) = self.shadow_geometry(index)?;
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
                let (image, vertices, indices) = (ctx.image(atlas)?, ctx.buffer(vertices)?, ctx.buffer(indices)?);
                record_cascades(ctx.cmd(), image, plan, |cmd, push| {
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
