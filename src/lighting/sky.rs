//! `sky`: a full-screen triangle shading every pixel with the frame's sky
//! model (the Perez/Preetham sky of §6.3 or the physical atmosphere;
//! `glsl/include/sky.glsl`) along its view ray plus the sun disc, in
//! absolute units, and clearing view-space depth to +inf, the lighting
//! AOVs to (1, 1), the world normal to 0 and the class and instance ids to
//! sky (0, 0; `crate::view::aov`). It also writes the view's lighting
//! constants: it declares every lighting map, so the constants can name
//! their heap handles.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{LoadOp, Stage};
use crate::lighting::technique::PreparedLighting;
use crate::shaders;
use crate::view::{pass_name, Declare, Provides, SceneTargets, TargetFormats, ViewGraph};
use crate::vulkan::{Context, GraphicsPipeline, GraphicsPipelineDesc};

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
}

/// `sky` of a view: its targets in, nothing out.
impl<S: Provides<PreparedLighting> + 'static> Declare<S> for Sky {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = ();

    /// Declares `sky` for view `index`: writes its radiance, view depth,
    /// lighting AOVs, normal and ids, and the view's lighting constants
    /// (the values the lighting prepared, with the heap handles of the
    /// lighting maps this pass declares).
    fn declare(&mut self, at: ViewGraph<'_, S>, targets: &SceneTargets) -> Result<()> {
        let ViewGraph { graph, index, view, .. } = at;
        let pipeline = self.pipeline.clone();
        let mut pass = graph.pass(&pass_name("sky", &view.name)).graphics();
        let lighting = targets.lighting.read_in(&mut pass, Stage::Fragment);
        pass.pipeline(&pipeline)
            .color(targets.radiance, LoadOp::DontCare)
            .color(targets.view_depth, LoadOp::DontCare)
            .color(targets.visibility, LoadOp::DontCare)
            .color(targets.normal, LoadOp::DontCare)
            .color(targets.ids, LoadOp::DontCare)
            .record(move |ctx, frame| {
                let mut constants = *frame.prepared::<PreparedLighting>()?.view(index)?;
                constants.set_map_handles(ctx, &lighting)?;
                ctx.write_upload_pod(lighting.constants, &constants)?;
                let view = frame.view(index)?;
                let (right, up, forward) = view.ray_basis();
                let push = SkyPush {
                    right: right.extend(0.0).to_array(),
                    up: up.extend(0.0).to_array(),
                    forward: forward.extend(0.0).to_array(),
                    lighting: [ctx.handle(lighting.constants)?, 0, 0, 0],
                };
                ctx.draw_full_screen(&pipeline, &push)
            });
        Ok(())
    }
}
