//! The opaque splat mode on the compute path (§10.2.2's opaque baseline,
//! as `points.opaque` draws it on the hardware path: each splat's cut-off
//! ellipse with ray–plane depth, depth-tested, no blending; issue 29):
//!
//! 1. `points.triangles` (only with hybrid triangles, §10.1.8): the
//!    triangles opaque on the hardware path, with depth;
//! 2. `points.clear`: each pixel's nearest word from the depth buffer (no
//!    sums);
//! 3. `points.opaque`: one dispatch for all the view's draws; each
//!    fragment raises the pixel's nearest word with its depth and the
//!    splat's index in the draw table (64-bit `atomicMax`: the nearest
//!    splat wins whatever the order, so frames are the same to the byte);
//! 4. `points.opaque.resolve`: per pixel, the winning splat set up again
//!    and shaded at the pixel as `glsl/points/opaque.frag` shades it.
//!
//! Shaders: `glsl/points/compute_clear.comp`, `compute_opaque.comp`,
//! `compute_opaque_resolve.comp`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::compute::{declare_clear, declare_opaque_triangles, declare_splats, SplatState};
use super::passes::{PointBuffers, PointView, ResolvedTargets, ShadingBindings, SplatBindings, SplatPush, PASS_OPAQUE};
use super::PointsFrame;
use crate::error::{Error, Result};
use crate::graph::{BufferAccess, BufferInfo, ImageAccess, RenderGraph, Stage};
use crate::shaders;
use crate::view::{Frame, Provides, SceneTargets};
use crate::vulkan::{ComputePipeline, Context, MemoryLocation};

/// Push constants of `points.opaque.resolve` (`Push` in
/// glsl/include/splat.glsl with `SPLAT_RESOLVE_COMPUTE` and `SPLAT_COMPUTE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ResolvePush {
    splat: SplatPush,
    outputs: [u32; 4],
    more: [u32; 4],
    /// Nearest words, 1 to keep W where no splat won, 0, 0.
    raster: [u32; 4],
    /// The draw table, draws, 0, 0.
    draws: [u32; 4],
}

/// Declares the compute path's opaque passes of one view (the module's
/// list); `name` gives a pass's name for the view.
pub(super) fn declare_opaque_compute<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
) -> Result<()> {
    let clear = ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_CLEAR)?;
    let opaque = ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_OPAQUE)?;
    let resolve = ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_OPAQUE_RESOLVE)?;
    let pixels = u64::from(targets.width * targets.height).max(1);
    let info = BufferInfo {
        size: 8 * pixels,
        location: MemoryLocation::GpuOnly,
    };
    let state = SplatState {
        nearest: graph.create_buffer("splat nearest depth and splat", info),
        accumulation: None,
        size: [targets.width, targets.height],
    };
    let triangles = buffers.triangles.is_some();
    if triangles {
        declare_opaque_triangles(ctx, graph, &name("points.triangles"), (buffers, view), targets)?;
    }
    let depth_written = triangles || !view.clear_depth;
    declare_clear(graph, &name("points.clear"), (view, state, depth_written, None), clear);
    let splats = (buffers, view, state);
    declare_splats(graph, &name("points.opaque"), (splats, None), true, opaque)?;
    declare_resolve(
        graph,
        &name("points.opaque.resolve"),
        splats,
        (targets, triangles),
        resolve,
    )
}

/// `points.opaque.resolve`: a compute pass over the view's pixels shading
/// the splat that won each (W set to 0 where none did unless the hybrid
/// `triangles` wrote it).
fn declare_resolve<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view, state): (PointBuffers, PointView, SplatState),
    (targets, triangles): (&SceneTargets, bool),
    pipeline: ComputePipeline,
) -> Result<()> {
    let pipeline = Arc::new(pipeline);
    let compute = Stage::Compute;
    let mut builder = graph.pass(name);
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), compute);
    let buffers = PointBuffers {
        counter: None,
        ..buffers
    };
    let (mut builder, splat): (_, SplatBindings) = buffers.read_by_at(builder, shading.frame, (compute, compute));
    let table = view
        .draws
        .ok_or_else(|| Error::Graph(format!("{name}: the view has no draw table")))?;
    let table = builder.upload(table, compute);
    let nearest = builder.storage_buffer(state.nearest, BufferAccess::StorageRead(compute));
    let weight = match triangles {
        true => ImageAccess::StorageReadWrite(compute),
        false => ImageAccess::StorageWrite(compute),
    };
    let outputs = ResolvedTargets::declare(&mut builder, (&view, targets), weight);
    builder.record(move |pass, frame| {
        shading.write_header(pass, frame, view.index)?;
        let plan = super::passes::plan_of(frame, view.index)?;
        let draws = u32::try_from(plan.draws.len()).map_err(|_| Error::invalid("points", "too many draws"))?;
        let (outputs_push, more) = outputs.push(pass)?;
        let push = ResolvePush {
            splat: splat.push(pass, PASS_OPAQUE)?,
            outputs: outputs_push,
            more,
            raster: [pass.handle(nearest)?, u32::from(triangles), 0, 0],
            draws: [pass.handle(table)?, draws, 0, 0],
        };
        pass.dispatch(&pipeline, &push, outputs.groups())
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resolve_push_constants_match_the_shader_block() {
        // handles, mode, outputs, more, raster, draws.
        assert_eq!(std::mem::size_of::<ResolvePush>(), 96);
    }
}
