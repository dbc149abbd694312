//! Single-pass EWA splatting with a fuzzy depth test (dissertation §10.4;
//! `ALGORITHMS.md` §8) as render-graph passes. Each splat fragment
//! (C_s, A_s, z_s) meets the pixel's stored (C_d, A_d, z_d): nearer than
//! z_d − z_f it replaces them, within ±z_f it blends by weight
//! (C_d = (A_d·C_d + A_s·C_s)/(A_d + A_s), A_d += A_s, z_d kept, so z_d only
//! decreases), farther it is dropped. The kernels, clip lines and ray–plane
//! depth are the three-pass mode's (`glsl/include/splat_setup.glsl`), and
//! the resolve shades exactly as `points.normalize`
//! (`glsl/include/splat_resolve.glsl`), so the outputs are the same in kind:
//! radiance, view depth, W, visibility, world normal and ids.
//!
//! z is the distance along the view ray and z_f = ε·r_k with r_k the
//! incoming splat's radius in camera units and ε
//! [`super::SplatSettings::visibility_offset`]: the three-pass visibility
//! pass's push-back (§10.2.3), derived from the splat size, the same for
//! every scene.
//!
//! Passes of a view:
//! 1. `points.single_pass.triangles` (only with hybrid triangles, §10.1.8):
//!    the triangles opaque and shaded, with depth, so splats test against them;
//! 2. `points.single_pass.clear`: every pixel unlocked, z_d = +inf, no sums;
//! 3. `points.single_pass`: the splats ([`SplatBackend`]): a compute
//!    dispatch per planned draw, one invocation per splat rasterising its
//!    bounding box (boxes over 256 pixels shared by the whole workgroup),
//!    each pixel merged under a per-pixel spin lock (64-bit word
//!    z_d·2³² + lock with `shaderBufferInt64Atomics`, else 32-bit lock and
//!    z_d words), or the interlock backend's raster pass;
//! 4. `points.single_pass.resolve`: compute, per pixel: divide and shade.
//!
//! The compute backend's merges at fuzzy boundaries follow the invocation
//! order, which the GPU may vary between runs (the operator is not
//! commutative); the interlock backend follows primitive order.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::passes::{
    declare_opaque, plan_of, PointBuffers, PointView, ResolvedTargets, ShadingBindings, SplatBindings, SplatPush,
    NO_HANDLE, PASS_OPAQUE, PRIMITIVE_QUAD,
};
use super::{PointsFrame, SplatBackend, SplatPrimitive};
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
/// Invocations per workgroup of the compute passes.
const WORKGROUP_SIZE: u32 = 64;
/// Most workgroups per dispatch row (the guaranteed `maxComputeWorkGroupCount`).
const MAX_GROUPS_X: u32 = 65535;

/// Push constants of `points.single_pass` (`Push` in glsl/include/splat.glsl
/// with `SPLAT_SINGLE_PASS`): the splat passes' block, then `single`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SinglePassPush {
    splat: SplatPush,
    /// Pixel words, storage.
    words: u32,
    /// Pixel sums, storage.
    sums: u32,
    /// Depth buffer, sampled ([`NO_HANDLE`]: nothing drew into it).
    depth: u32,
    /// Splats of the draw.
    count: u32,
}

/// Push constants of `points.single_pass.clear` and `.resolve`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct StatePush {
    /// clear: words, sums, pixel count, 0; resolve: sums, point frame, 0, 0.
    handles: [u32; 4],
    mode: [u32; 4],
}

/// Push constants of `points.single_pass.resolve` (`Push` in
/// glsl/include/splat.glsl with `SPLAT_RESOLVE_COMPUTE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ResolvePush {
    /// Pixel sums, point frame, 1 to keep W where no splat is, 0.
    handles: [u32; 4],
    mode: [u32; 4],
    /// Storage: radiance, view depth, W, lighting AOVs.
    outputs: [u32; 4],
    /// Storage: normal, ids; width, height.
    more: [u32; 4],
}

/// The per-pixel state of a view's single-pass splatting.
#[derive(Clone, Copy, Debug)]
struct PixelState {
    words: BufferId,
    sums: BufferId,
    pixels: u32,
}

/// The pipelines of single-pass splatting, built once per view.
struct Pipelines {
    clear: ComputePipeline,
    splats: SplatPipeline,
    resolve: ComputePipeline,
}

enum SplatPipeline {
    Compute(ComputePipeline),
    Interlock(GraphicsPipeline),
}

/// Fails with a one-line error when the device cannot run `backend`.
pub(super) fn check_backend(ctx: &Context, backend: SplatBackend) -> Result<()> {
    if backend != SplatBackend::Interlock {
        return Ok(());
    }
    let missing: Vec<&str> = [
        (
            "fragmentShaderPixelInterlock (VK_EXT_fragment_shader_interlock)",
            "fragmentShaderPixelInterlock",
        ),
        ("fragmentStoresAndAtomics", "fragmentStoresAndAtomics"),
    ]
    .into_iter()
    .filter(|(_, feature)| !ctx.has_feature(feature))
    .map(|(named, _)| named)
    .collect();
    match missing.is_empty() {
        true => Ok(()),
        false => Err(Error::invalid(
            "splat backend interlock",
            format!(
                "the device ({}) lacks {}; use the compute backend",
                ctx.info().name,
                missing.join(" and ")
            ),
        )),
    }
}

impl Pipelines {
    fn new(ctx: &Context, targets: &SceneTargets, (backend, force_32bit_locks): (SplatBackend, bool)) -> Result<Self> {
        check_backend(ctx, backend)?;
        let f = &targets.formats;
        let splats = match backend {
            SplatBackend::Compute if ctx.has_feature("shaderBufferInt64Atomics") && !force_32bit_locks => {
                SplatPipeline::Compute(ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS)?)
            }
            SplatBackend::Compute => {
                SplatPipeline::Compute(ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_LOCK32)?)
            }
            SplatBackend::Interlock => SplatPipeline::Interlock(GraphicsPipeline::new(
                ctx,
                &GraphicsPipelineDesc {
                    topology: PrimitiveTopology::TRIANGLE_LIST,
                    ..GraphicsPipelineDesc::full_screen(
                        "points.single_pass.interlock",
                        (shaders::SPLAT_VERT, shaders::SPLAT_SINGLE_PASS_INTERLOCK_FRAG),
                        vec![f.weight],
                    )
                },
            )?),
        };
        Ok(Pipelines {
            clear: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_CLEAR)?,
            splats,
            resolve: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RESOLVE)?,
        })
    }
}

/// The passes of single-pass splatting of one view (see the module's
/// list); `name` gives a pass's name for the view.
pub(super) fn declare_single_pass<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    backend: (SplatBackend, bool),
) -> Result<()> {
    let pipelines = Pipelines::new(ctx, targets, backend)?;
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
        pixels,
    };
    let Pipelines { clear, splats, resolve } = pipelines;
    // Hybrid triangles (§10.1.8) as opaque shaded triangles with depth, W = 1,
    // before the splats test against them.
    let depth_written = match buffers.triangles {
        Some(_) => {
            let triangles_only = PointBuffers {
                primitive: SplatPrimitive::Quad,
                ..buffers
            };
            let name = name("points.single_pass.triangles");
            declare_opaque(ctx, graph, &name, (triangles_only, view), targets, false)?;
            true
        }
        None => !view.clear_depth,
    };
    declare_clear(graph, &name("points.single_pass.clear"), state, clear);
    let splat_pass = (name("points.single_pass"), buffers, view);
    let weight_written = buffers.triangles.is_some();
    match splats {
        SplatPipeline::Compute(p) => declare_compute(graph, splat_pass, state, depth_written, p),
        SplatPipeline::Interlock(p) => declare_interlock(graph, splat_pass, state, (depth_written, weight_written), p),
    }
    declare_resolve(
        graph,
        &name("points.single_pass.resolve"),
        view,
        targets,
        (state, weight_written),
        resolve,
    );
    Ok(())
}

/// `points.single_pass.clear`: every pixel unlocked, z_d = +inf, sums 0.
fn declare_clear<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    state: PixelState,
    pipeline: ComputePipeline,
) {
    let mut pass = graph.pass(name);
    let words = pass.storage_buffer(state.words, BufferAccess::StorageWrite(Stage::Compute));
    let sums = pass.storage_buffer(state.sums, BufferAccess::StorageWrite(Stage::Compute));
    pass.record(move |ctx, _| {
        let push = StatePush {
            handles: [ctx.handle(words)?, ctx.handle(sums)?, state.pixels, 0],
            mode: [0; 4],
        };
        let (x, y) = workgroups(state.pixels);
        ctx.dispatch(&pipeline, &push, [x, y, 1])
    });
}

/// Workgroups for `n` invocations: (per row, rows).
fn workgroups(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(WORKGROUP_SIZE);
    let rows = groups.div_ceil(MAX_GROUPS_X).max(1);
    (groups.div_ceil(rows), rows)
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
            words: ctx.handle(self.words)?,
            sums: ctx.handle(self.sums)?,
            depth: self.depth.map(|d| ctx.handle(d)).transpose()?.unwrap_or(NO_HANDLE),
            count: 0,
        })
    }
}

/// The reads and writes of the splat pass at `stage`: splats, frame,
/// table, counter, the pixel state and the depth buffer when written.
fn splat_pass_uses<'g, S: Provides<PointsFrame> + 'static>(
    mut builder: PassBuilder<'g, Frame<S>>,
    (buffers, view): (PointBuffers, PointView),
    state: PixelState,
    depth_written: bool,
    (vertex, fragment): (Stage, Stage),
) -> (PassBuilder<'g, Frame<S>>, SplatPassBindings) {
    let frame = builder.upload(view.frame, if vertex == fragment { vertex } else { Stage::Graphics });
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

/// `points.single_pass`, compute backend: one dispatch per planned draw,
/// one invocation per splat (`glsl/include/single_pass.glsl`).
fn declare_compute<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, buffers, view): (String, PointBuffers, PointView),
    state: PixelState,
    depth_written: bool,
    pipeline: ComputePipeline,
) {
    let builder = graph.pass(&name);
    let stages = (Stage::Compute, Stage::Compute);
    let (builder, bindings) = splat_pass_uses(builder, (buffers, view), state, depth_written, stages);
    builder.record(move |pass, frame| {
        let plan = plan_of(frame, view.index)?;
        let mut push = bindings.push(pass)?;
        let cmd = pass.cmd();
        cmd.bind_compute(&pipeline);
        for d in &plan.draws {
            (push.splat.record, push.count) = (d.record, d.count);
            cmd.push_constants(&push)?;
            let (x, y) = workgroups(d.count);
            cmd.dispatch(x, y, 1);
        }
        Ok(())
    });
}

/// `points.single_pass`, interlock backend: the splats as quads whose
/// fragments merge in a pixel-ordered critical section
/// (`glsl/points/single_pass_interlock.frag`); W is its nominal target,
/// never written (loaded when the triangles pass wrote it).
fn declare_interlock<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, buffers, view): (String, PointBuffers, PointView),
    state: PixelState,
    (depth_written, weight_written): (bool, bool),
    pipeline: GraphicsPipeline,
) {
    let builder = graph.pass(&name).graphics();
    let stages = (Stage::Vertex, Stage::Fragment);
    let weight_load = match weight_written {
        true => LoadOp::Load,
        false => LoadOp::DontCare,
    };
    let (builder, bindings) = splat_pass_uses(builder, (buffers, view), state, depth_written, stages);
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
                (push.splat.record, push.count) = (d.record, d.count);
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
        let (outputs_push, more) = outputs.push(pass)?;
        let push = ResolvePush {
            handles: [pass.handle(sums)?, frame, u32::from(weight_written), 0],
            mode: [0; 4],
            outputs: outputs_push,
            more,
        };
        pass.dispatch(&pipeline, &push, outputs.groups())
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workgroups_cover_every_invocation_within_the_limit() {
        for n in [0, 1, 64, 65, 100_000, 64 * 65535, 64 * 65535 + 1, 50_000_000] {
            let (x, y) = workgroups(n);
            assert!(x <= MAX_GROUPS_X && y >= 1, "{n}: {x}×{y}");
            assert!(u64::from(x) * u64::from(y) * 64 >= u64::from(n), "{n}: {x}×{y}");
        }
    }

    #[test]
    fn push_constants_match_the_shader_block() {
        // handles, mode (SplatPush), single: 48 bytes.
        assert_eq!(std::mem::size_of::<SinglePassPush>(), 48);
        assert_eq!(std::mem::size_of::<StatePush>(), 32);
    }
}
