//! `sky`: a compute pass shading every pixel of a view with the frame's
//! sky model (the Perez/Preetham sky of §6.3 or the physical atmosphere;
//! `glsl/include/sky.glsl`) along its view ray plus the sun disc, in
//! absolute units, and clearing view-space depth to +inf, the lighting
//! AOVs to (1, 1), the world normal to 0 and the class and instance ids to
//! sky (0, 0; `crate::view::aov`); `glsl/include/sky_pixel.glsl` per pixel.
//! It also writes the view's lighting constants ([`write_view_lighting`]):
//! it declares every lighting map, so the constants can name their heap
//! handles. On the compute path the terrain's deferred shading
//! (`terrain.shade`) shades the sky itself where no terrain covers a
//! pixel, one pass over the pixels instead of two, and writes the
//! constants instead.

use bytemuck::{Pod, Zeroable};

use std::sync::Arc;

use crate::error::Result;
use crate::graph::{ImageAccess, PassContext, Stage};
use crate::lighting::technique::PreparedLighting;
use crate::shaders;
use crate::view::{pass_name, Declare, Frame, LightingBindings, Provides, SceneTargets, ViewGraph, ViewIndex};
use crate::vulkan::{ComputePipeline, Context};

/// Push constants of `sky` (`glsl/lighting/sky.comp`): the view ray basis
/// and the targets.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SkyPush {
    /// Right axis scaled by the half-width of the image plane at distance 1.
    right: [f32; 4],
    /// Image up axis scaled by the half-height.
    up: [f32; 4],
    forward: [f32; 4],
    /// Storage handle of the view's lighting constants, width, height,
    /// storage handle of the ids.
    lighting: [u32; 4],
    /// Storage handles of radiance, view depth, lighting AOVs and normal.
    images: [u32; 4],
}

/// Writes view `index`'s lighting constants (the values the lighting
/// prepared, with the heap handles of the lighting maps `bindings` holds,
/// declared on the pass recording) and returns their heap handle: the job
/// of the first pass to shade a view, `sky` or, on the compute path,
/// `terrain.shade`.
pub fn write_view_lighting<S: Provides<PreparedLighting> + 'static>(
    ctx: &mut PassContext<'_>,
    frame: &Frame<S>,
    index: ViewIndex,
    bindings: &LightingBindings,
) -> Result<u32> {
    let mut constants = *frame.prepared::<PreparedLighting>()?.view(index)?;
    constants.set_map_handles(ctx, bindings)?;
    ctx.write_upload_pod(bindings.constants, &constants)?;
    ctx.handle(bindings.constants)
}

/// The sky: a pipeline, and one `sky` pass per view.
pub struct Sky {
    pipeline: Arc<ComputePipeline>,
}

impl Sky {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<Sky> {
        Ok(Sky {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::SKY)?),
        })
    }
}

/// `sky` of a view: its targets in, nothing out.
impl<S: Provides<PreparedLighting> + 'static> Declare<S> for Sky {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = ();

    /// Declares `sky` for view `index`: writes its radiance, view depth,
    /// lighting AOVs, normal and ids, and the view's lighting constants.
    fn declare(&mut self, at: ViewGraph<'_, S>, targets: &SceneTargets) -> Result<()> {
        let ViewGraph { graph, index, view, .. } = at;
        let pipeline = self.pipeline.clone();
        let mut pass = graph.pass(&pass_name("sky", &view.name));
        let lighting = targets.lighting.read_in(&mut pass, Stage::Compute);
        let write = ImageAccess::StorageWrite(Stage::Compute);
        let images = targets.shaded().map(|image| pass.storage_image(image, write));
        let (width, height) = (targets.width, targets.height);
        pass.record(move |ctx, frame| {
            let constants = write_view_lighting(ctx, frame, index, &lighting)?;
            let (right, up, forward) = frame.view(index)?.ray_basis();
            let image = |k: usize| ctx.handle(images[k]);
            let push = SkyPush {
                right: right.extend(0.0).to_array(),
                up: up.extend(0.0).to_array(),
                forward: forward.extend(0.0).to_array(),
                lighting: [constants, width, height, image(4)?],
                images: [image(0)?, image(1)?, image(2)?, image(3)?],
            };
            ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
        });
        Ok(())
    }
}
