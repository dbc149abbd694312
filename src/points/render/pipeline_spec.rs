//! The fixed-function state of one points pass's splat or hybrid-triangle
//! pipeline ([`super::passes`]; the object-space primitives' variant is in
//! [`super::object_space`]).

use crate::error::Result;
use crate::vulkan::{
    Blend, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, PrimitiveTopology, SpirV,
};

/// A splat or hybrid-triangle pipeline of one pass.
pub(super) struct PipelineSpec {
    pub name: &'static str,
    pub shaders: (SpirV, SpirV),
    pub color_formats: Vec<Format>,
    pub blend: Blend,
    pub depth: (bool, CompareOp),
}

impl PipelineSpec {
    /// The pipeline's description without vertex input.
    pub(super) fn desc(&self, depth_format: Format, topology: PrimitiveTopology) -> GraphicsPipelineDesc {
        GraphicsPipelineDesc {
            name: self.name,
            vertex: self.shaders.0,
            fragment: self.shaders.1,
            vertex_stride: 0,
            vertex_attributes: Vec::new(),
            topology,
            cull_back_faces: false,
            wireframe: false,
            color_formats: self.color_formats.clone(),
            blend: self.blend,
            depth_format: Some(depth_format),
            depth_test: true,
            depth_write: self.depth.0,
            depth_compare: self.depth.1,
        }
    }

    /// The pipeline, drawing points or triangles.
    pub(super) fn build(&self, ctx: &Context, depth_format: Format, points: bool) -> Result<GraphicsPipeline> {
        let topology = match points {
            true => PrimitiveTopology::POINT_LIST,
            false => PrimitiveTopology::TRIANGLE_LIST,
        };
        GraphicsPipeline::new(ctx, &self.desc(depth_format, topology))
    }
}
