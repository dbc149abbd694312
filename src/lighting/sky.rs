//! `sky`: a full-screen triangle shading every pixel with the frame's sky
//! model (the Perez/Preetham sky of §6.3 or the physical atmosphere;
//! `glsl/include/sky.glsl`) along its view ray plus the sun disc, in
//! absolute units, and clearing view-space depth to +inf, the lighting
//! AOVs to (1, 1), the world normal to 0 and the class and instance ids to
//! sky (0, 0; `crate::view::aov`).

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{ImageAccess, RenderGraph, Stage};
use crate::shaders;
use crate::view::{pass_name, Declare, Frame, SceneTargets, TargetFormats, View, ViewIndex};
use crate::vulkan::{Context, GraphicsPipeline, GraphicsPipelineDesc, LoadOp};

/// Push constants of `sky` (`glsl/lighting/sky.frag`): the view ray basis
/// and the sun.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SkyPush {
    /// Right axis scaled by the half-width of the image plane at distance 1.
    right: [f32; 4],
    /// Image up axis scaled by the half-height.
    up: [f32; 4],
    forward: [f32; 4],
    /// x: storage handle of the view's lighting constants.
    lighting: [u32; 4],
}

/// The sky: a pipeline, and one `sky` pass per view.
pub struct Sky {
    pipeline: std::sync::Arc<GraphicsPipeline>,
}

impl Sky {
    /// Builds the pipeline for targets of `formats`.
    pub fn new(ctx: &Context, formats: &TargetFormats) -> Result<Sky> {
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsPipelineDesc::full_screen(
                "sky",
                (shaders::FULL_SCREEN_VERT, shaders::SKY_FRAG),
                vec![
                    formats.radiance,
                    formats.view_depth,
                    formats.visibility,
                    formats.normal,
                    formats.ids,
                ],
            ),
        )?;
        Ok(Sky {
            pipeline: std::sync::Arc::new(pipeline),
        })
    }

    /// Declares `sky` for view `index`: writes its radiance, view depth,
    /// lighting AOVs, normal and ids.
    pub fn declare<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
        targets: &SceneTargets,
    ) {
        let pipeline = self.pipeline.clone();
        let (radiance, view_depth, visibility) = (targets.radiance, targets.view_depth, targets.visibility);
        let (normal, ids) = (targets.normal, targets.ids);
        let lighting = targets.lighting.constants;
        let builder = graph.pass(&pass_name("sky", &view.name)).graphics();
        targets
            .lighting
            .read_in(builder, Stage::Fragment)
            .write(radiance, ImageAccess::ColorAttachmentWrite)
            .write(view_depth, ImageAccess::ColorAttachmentWrite)
            .write(visibility, ImageAccess::ColorAttachmentWrite)
            .write(normal, ImageAccess::ColorAttachmentWrite)
            .write(ids, ImageAccess::ColorAttachmentWrite)
            .record(move |pass, frame| {
                let view = frame.view(index)?;
                let (right, up, forward) = view.ray_basis();
                let push = SkyPush {
                    right: right.extend(0.0).to_array(),
                    up: up.extend(0.0).to_array(),
                    forward: forward.extend(0.0).to_array(),
                    lighting: [pass.upload(lighting)?, 0, 0, 0],
                };
                let (radiance, view_depth) = (pass.image(radiance)?, pass.image(view_depth)?);
                let (visibility, normal, ids) = (pass.image(visibility)?, pass.image(normal)?, pass.image(ids)?);
                let cmd = pass.cmd();
                cmd.begin_rendering(
                    &[
                        (radiance, LoadOp::DontCare),
                        (view_depth, LoadOp::DontCare),
                        (visibility, LoadOp::DontCare),
                        (normal, LoadOp::DontCare),
                        (ids, LoadOp::DontCare),
                    ],
                    None,
                );
                cmd.bind_graphics(&pipeline);
                cmd.push_constants(&push)?;
                cmd.draw(3, 1);
                cmd.end_rendering();
                Ok(())
            });
    }
}

/// `sky` of a view: its targets in, nothing out.
impl<S: 'static> Declare<S> for Sky {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = ();

    fn declare(
        &mut self,
        _: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        view: (ViewIndex, &View),
        targets: &SceneTargets,
    ) -> Result<()> {
        Sky::declare(self, graph, view, targets);
        Ok(())
    }
}
