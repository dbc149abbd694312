//! The interlock backend of single-pass splatting (dissertation §10.4;
//! [`super::SplatBackend::Interlock`]): the splats drawn as quads whose
//! fragments merge into a per-pixel state inside a pixel-ordered critical
//! section (`VK_EXT_fragment_shader_interlock`, `glsl/points/single_pass_interlock.frag`):
//! merges follow primitive order, so the result is deterministic. Passes:
//! `points.single_pass.clear` (z_d = +inf, no sums), `points.single_pass`,
//! `points.single_pass.resolve` (compute: divide and shade as `points.normalize`).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::super::passes::{
    plan_of, PointBuffers, PointView, ResolvedTargets, ShadingBindings, SplatBindings, SplatPush, NO_HANDLE,
    PASS_OPAQUE, PRIMITIVE_QUAD,
};
use super::super::PointsFrame;
use super::{declare_clear, ResolvedPush, SinglePassPush, ViewPasses, Written};
use crate::error::{Error, Result};
use crate::graph::{
    Binding, BufferAccess, BufferId, BufferInfo, ImageAccess, LoadOp, PassBuilder, PassContext, RenderGraph, Stage,
};
use crate::shaders;
use crate::view::{Frame, Provides, SceneTargets};
use crate::vulkan::{
    ComputePipeline, Context, GraphicsPipeline, GraphicsPipelineDesc, MemoryLocation, PrimitiveTopology,
};

/// Bytes of a pixel's lock and z_d (`glsl/include/single_pass_merge.glsl`).
const PIXEL_WORD_BYTES: u64 = 8;
/// Bytes of a pixel's sums (`PixelSums` in `glsl/include/single_pass_state.glsl`).
const PIXEL_SUM_BYTES: u64 = 48;

/// Push constants of `points.single_pass.resolve` (`Push` in
/// glsl/include/splat.glsl with `SPLAT_RESOLVE_COMPUTE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ResolvePush {
    /// Pixel sums, point frame, 1 to keep W where no splat is, 0.
    handles: [u32; 4],
    mode: [u32; 4],
    resolved: ResolvedPush,
}

/// The per-pixel state of the interlock backend.
#[derive(Clone, Copy, Debug)]
struct PixelState {
    words: BufferId,
    sums: BufferId,
}

/// The interlock backend's passes of one view (see the module's doc).
pub(super) fn declare<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    at: ViewPasses<'_>,
) -> Result<()> {
    let (name, targets, written) = (at.name, at.targets, at.written);
    let (buffers, view) = (at.buffers, at.view);
    let pixels = targets.width * targets.height;
    let buffer = |graph: &mut RenderGraph<Frame<S>>, what, bytes: u64| {
        graph.create_buffer(
            what,
            BufferInfo {
                size: bytes * u64::from(pixels.max(1)),
                location: MemoryLocation::GpuOnly,
            },
        )
    };
    let state = PixelState {
        words: buffer(graph, "splat pixel z_d and lock", PIXEL_WORD_BYTES),
        sums: buffer(graph, "splat pixel sums", PIXEL_SUM_BYTES),
    };
    let clear = ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_CLEAR)?;
    let splats = GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc {
            topology: PrimitiveTopology::TRIANGLE_LIST,
            ..GraphicsPipelineDesc::full_screen(
                "points.single_pass.interlock",
                (shaders::SPLAT_VERT, shaders::SPLAT_SINGLE_PASS_INTERLOCK_FRAG),
                vec![targets.formats.weight],
            )
        },
    )?;
    let resolve = ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RESOLVE)?;
    // Every pixel: z_d = +inf, sums 0.
    let cleared = [state.words, state.sums];
    declare_clear(graph, &name("points.single_pass.clear"), (&cleared, pixels), clear);
    let splat_pass = (name("points.single_pass"), buffers, view);
    declare_interlock(graph, splat_pass, state, written, splats);
    declare_resolve(
        graph,
        &name("points.single_pass.resolve"),
        view,
        targets,
        (state, written.weight),
        resolve,
    );
    Ok(())
}

/// The heap bindings of the splat pass.
#[derive(Clone, Copy, Debug)]
struct SplatPassBindings {
    splat: SplatBindings,
    words: Binding,
    sums: Binding,
    /// The depth buffer, when written before.
    depth: Option<Binding>,
}

impl SplatPassBindings {
    /// The push constants of the splat pass.
    fn push(&self, ctx: &PassContext<'_>) -> Result<SinglePassPush> {
        Ok(SinglePassPush {
            splat: SplatPush {
                primitive: PRIMITIVE_QUAD,
                ..self.splat.push(ctx, PASS_OPAQUE)?
            },
            single: [
                ctx.handle(self.words)?,
                ctx.handle(self.sums)?,
                self.depth.map(|d| ctx.handle(d)).transpose()?.unwrap_or(NO_HANDLE),
                0,
            ],
        })
    }
}

/// The reads and writes of the splat pass: splats, frame,
/// table, counter, the pixel state and the depth buffer when written.
fn splat_pass_uses<'g, S: Provides<PointsFrame> + 'static>(
    mut builder: PassBuilder<'g, Frame<S>>,
    (buffers, view): (PointBuffers, PointView),
    state: PixelState,
    depth_written: bool,
) -> (PassBuilder<'g, Frame<S>>, SplatPassBindings) {
    let (vertex, fragment) = (Stage::Vertex, Stage::Fragment);
    let frame = builder.upload(view.frame, Stage::Graphics);
    let words = builder.storage_buffer(state.words, BufferAccess::StorageReadWrite(fragment));
    let sums = builder.storage_buffer(state.sums, BufferAccess::StorageReadWrite(fragment));
    let depth = depth_written.then(|| builder.sample(view.depth, fragment));
    let (builder, splat) = buffers.read_by_at(builder, frame, (vertex, fragment));
    let bindings = SplatPassBindings {
        splat,
        words,
        sums,
        depth,
    };
    (builder, bindings)
}

/// `points.single_pass`, interlock backend: the splats as quads whose
/// fragments merge in a pixel-ordered critical section
/// (`glsl/points/single_pass_interlock.frag`); W is its nominal target,
/// never written (loaded when the triangles pass wrote it).
fn declare_interlock<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, buffers, view): (String, PointBuffers, PointView),
    state: PixelState,
    written: Written,
    pipeline: GraphicsPipeline,
) {
    let builder = graph.pass(&name).graphics();
    let weight_load = match written.weight {
        true => LoadOp::Load,
        false => LoadOp::DontCare,
    };
    let (builder, bindings) = splat_pass_uses(builder, (buffers, view), state, written.depth);
    builder
        .pipeline(&pipeline)
        .color(view.weight, weight_load)
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let mut push = bindings.push(pass)?;
            let cmd = pass.cmd();
            cmd.bind_graphics(&pipeline);
            for d in &plan.draws {
                let vertices = d
                    .count
                    .checked_mul(6)
                    .ok_or_else(|| Error::invalid("splat count", format!("{} splats exceed one draw", d.count)))?;
                (push.splat.record, push.single[3]) = (d.record, d.count);
                cmd.push_constants(&push)?;
                cmd.draw(vertices, 1);
            }
            Ok(())
        });
}

/// `points.single_pass.resolve`: a compute pass over the view's pixels, as
/// `points.normalize`, from the pixel sums; W set to 0 where no splat is
/// unless the triangles pass wrote it.
fn declare_resolve<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    view: PointView,
    targets: &SceneTargets,
    (state, weight_written): (PixelState, bool),
    pipeline: ComputePipeline,
) {
    let pipeline = Arc::new(pipeline);
    let compute = Stage::Compute;
    let weight = match weight_written {
        true => ImageAccess::StorageReadWrite(compute),
        false => ImageAccess::StorageWrite(compute),
    };
    let mut builder = graph.pass(name);
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), compute);
    let sums = builder.storage_buffer(state.sums, BufferAccess::StorageRead(compute));
    let outputs = ResolvedTargets::declare(&mut builder, (&view, targets), weight);
    builder.record(move |pass, frame| {
        let frame = shading.write_header(pass, frame, view.index)?;
        let push = ResolvePush {
            handles: [pass.handle(sums)?, frame, u32::from(weight_written), 0],
            mode: [0; 4],
            resolved: ResolvedPush::of(&outputs, pass)?,
        };
        pass.dispatch(&pipeline, &push, outputs.groups())
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_constants_match_the_shader_block() {
        assert_eq!(std::mem::size_of::<ResolvePush>(), 64);
    }
}
