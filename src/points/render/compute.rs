//! Three-pass EWA splatting on the compute path (dissertation §10.2.3,
//! Table 10.1; issue 29): the same perspective-accurate set-up and kernel
//! as the hardware passes (`glsl/include/splat_setup.glsl`), one invocation
//! per splat rasterising its bounding box, into per-pixel buffers
//! (`glsl/include/splat_compute_state.glsl`):
//!
//! 1. `points.clear`: each pixel's nearest word from the depth buffer
//!    (terrain), sums and last record 0;
//! 2. `points.visibility.triangles` and `points.accumulate.triangles` (only
//!    with hybrid triangles, §10.1.8), before the splats' passes 3 and 4:
//!    the triangles' fragments raise the nearest words and add weight 1 to
//!    the sums as the hardware path's triangles do (without
//!    `fragmentStoresAndAtomics`: one `points.triangles` pass first, the
//!    triangles opaque and shaded with depth, as single-pass splatting
//!    draws them);
//! 3. `points.visibility`: one dispatch for all the view's draws (a draw
//!    table written by `prepare` maps each invocation to its draw); the ray–plane depth pushed back by ε, raised into
//!    the nearest word with the splat's instance record (64-bit `atomicMax`);
//! 4. `points.accumulate`: fragments at or in front of it add w·(colour, 1)
//!    and w·(normal, view depth) to fixed-point 64-bit integer sums
//!    (`atomicAdd`): the sums do not depend on the order of the fragments,
//!    so frames are the same to the byte;
//! 5. `points.normalize`: per pixel, divide and shade as the hardware
//!    path's normalization (`glsl/include/splat_resolve.glsl`).
//!
//! With the terrain on the compute path too, `points.clear` takes the
//! nearest words from the terrain's visibility keys ([`GroundKeys`]), and
//! there is no `points.normalize`: the sums go back ([`SplatSums`]) to the
//! frame's shading pass, `terrain.shade`, which normalizes and shades them
//! in its one pass over the pixels (issue 29). `points.accumulate` then
//! writes the point frame's header.
//!
//! The primitive setting (§10.3) belongs to the hardware path: compute
//! rasterises the screen-space ellipse itself.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::passes::{
    declare_opaque, plan_of, PointBuffers, PointView, ResolvedTargets, ShadingBindings, SplatBindings, SplatPush,
    NO_HANDLE, PASS_OPAQUE,
};
use super::pipeline_spec::PipelineSpec;
use super::triangles::draw_triangles_with;
use super::{PointsFrame, SplatPrimitive};
use crate::error::{Error, Result};
use crate::graph::{
    stride_groups, Binding, BufferAccess, BufferId, BufferInfo, ImageAccess, PassContext, RenderGraph, Stage,
};
use crate::shaders;
use crate::view::deferred::{GroundKeys, SplatSums};
use crate::view::depth::FAR_DEPTH;
use crate::view::{Frame, Provides, SceneTargets};
use crate::vulkan::{Blend, CompareOp, ComputePipeline, Context, GraphicsPipeline, MemoryLocation};

/// Bytes per pixel of the nearest word, the sums (8 × i64) and the last record.
const NEAREST_BYTES: u64 = 8;
const SUMS_BYTES: u64 = 64;
const LAST_BYTES: u64 = 4;
/// Invocations per workgroup of the splat passes (`glsl/include/splat_compute.glsl`).
const SPLATS_PER_GROUP: u32 = 64;

/// Push constants of `points.visibility` and `points.accumulate` (`Push` in
/// glsl/include/splat.glsl with `SPLAT_COMPUTE`): the splat passes' block,
/// then nearest words, sums, last records and the draw's splat count.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ComputeSplatPush {
    splat: SplatPush,
    raster: [u32; 4],
    /// The draw table (storage), draws, 0, 0.
    draws: [u32; 4],
}

/// Push constants of `points.clear`: nearest, sums, last, depth buffer
/// (sampled, [`NO_HANDLE`]: far); width, height, the ground's visibility
/// keys ([`NO_HANDLE`]: none) and the point frame's depth row (P22, P32)
/// that turns their view depths into the depth buffer's.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ClearPush {
    handles: [u32; 4],
    size: [u32; 4],
    row: [f32; 4],
}

/// Push constants of `points.normalize` (`Push` with `SPLAT_RESOLVE_COMPUTE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct NormalizePush {
    /// Sums, point frame, 1 to keep W where no splat is, nearest words.
    handles: [u32; 4],
    /// Last records, 0, 0, 0.
    mode: [u32; 4],
    outputs: [u32; 4],
    more: [u32; 4],
}

/// A view's per-pixel splat state: the nearest words, and for EWA the
/// sums and last records (None: opaque splats, [`super::compute_opaque`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct SplatState {
    pub nearest: BufferId,
    pub accumulation: Option<(BufferId, BufferId)>,
    pub size: [u32; 2],
}

impl SplatState {
    /// The sums and last records (EWA only).
    fn accumulation(&self) -> Result<(BufferId, BufferId)> {
        (self.accumulation).ok_or_else(|| Error::Graph("points: opaque splats have no sums".into()))
    }
}

/// The bindings of one of the state's buffers in each pass that uses it.
#[derive(Clone, Copy, Debug)]
struct StateBindings {
    nearest: Binding,
    sums: Option<Binding>,
    last: Option<Binding>,
}

impl StateBindings {
    /// The `raster` push constants: nearest, sums, last ([`NO_HANDLE`]
    /// where not declared) and `count`.
    fn handles(&self, pass: &PassContext<'_>, count: u32) -> Result<[u32; 4]> {
        let optional = |b: Option<Binding>| b.map(|b| pass.handle(b)).transpose().map(|h| h.unwrap_or(NO_HANDLE));
        Ok([
            pass.handle(self.nearest)?,
            optional(self.sums)?,
            optional(self.last)?,
            count,
        ])
    }
}

/// The pipelines of the compute path's splat passes.
struct Pipelines {
    clear: ComputePipeline,
    visibility: ComputePipeline,
    accumulate: ComputePipeline,
    /// None: the ground's shading pass resolves the sums.
    normalize: Option<ComputePipeline>,
}

/// Declares the compute path's EWA passes of one view (see the module's
/// list); `name` gives a pass's name for the view. With the `ground`'s
/// visibility keys the splats are tested against them and the sums are
/// returned for the ground's shading pass (no `points.normalize`).
pub(super) fn declare_ewa_compute<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    (buffers, view, ground): (PointBuffers, PointView, Option<GroundKeys>),
    targets: &SceneTargets,
) -> Result<Option<SplatSums>> {
    let pipelines = Pipelines {
        clear: ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_CLEAR)?,
        visibility: ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_VISIBILITY)?,
        accumulate: ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_ACCUMULATE)?,
        normalize: match ground {
            Some(_) => None,
            None => Some(ComputePipeline::new(ctx, shaders::SPLAT_COMPUTE_NORMALIZE)?),
        },
    };
    let pixels = u64::from(targets.width * targets.height).max(1);
    let mut buffer = |what, bytes: u64| {
        let info = BufferInfo {
            size: bytes * pixels,
            location: MemoryLocation::GpuOnly,
        };
        graph.create_buffer(what, info)
    };
    let state = SplatState {
        nearest: buffer("splat nearest depth and record", NEAREST_BYTES),
        accumulation: Some((
            buffer("splat fixed-point sums", SUMS_BYTES),
            buffer("splat last record", LAST_BYTES),
        )),
        size: [targets.width, targets.height],
    };
    // Hybrid triangles (§10.1.8): in the splats' state, as the hardware
    // passes blend them (fragment stores and atomics), or else opaque and
    // shaded first, with depth and W = 1, for the splats to test against.
    let hybrid = buffers.triangles.is_some();
    let blended = match hybrid && ctx.has_feature(TRIANGLE_FEATURE) {
        true => Some(TrianglePipelines::new(ctx, targets)?),
        false => None,
    };
    let opaque = hybrid && blended.is_none();
    if opaque && ground.is_some() {
        return Err(Error::Graph(format!(
            "points: opaque hybrid triangles (no {TRIANGLE_FEATURE}) cannot be shaded by the ground's pass"
        )));
    }
    if opaque {
        declare_opaque_triangles(ctx, graph, &name("points.triangles"), (buffers, view), targets)?;
    }
    let depth_written = (opaque || !view.clear_depth) && ground.is_none();
    declare_clear(
        graph,
        &name("points.clear"),
        (view, state, depth_written, ground),
        pipelines.clear,
    );
    let splats = (buffers, view, state);
    if let Some(t) = &blended {
        let pass = (true, t.visibility.clone());
        declare_triangles(graph, &name("points.visibility.triangles"), splats, pass)?;
    }
    declare_splats(
        graph,
        &name("points.visibility"),
        (splats, None),
        true,
        pipelines.visibility,
    )?;
    if let Some(t) = blended {
        declare_triangles(
            graph,
            &name("points.accumulate.triangles"),
            splats,
            (false, t.accumulate),
        )?;
    }
    let header = ground.is_some().then_some(targets);
    declare_splats(
        graph,
        &name("points.accumulate"),
        (splats, header),
        false,
        pipelines.accumulate,
    )?;
    let Some(normalize_pipeline) = pipelines.normalize else {
        let (sums, last) = state.accumulation()?;
        return Ok(Some(SplatSums {
            nearest: state.nearest,
            sums,
            last,
            frame: view.frame,
        }));
    };
    let normalize = name("points.normalize");
    declare_normalize(
        graph,
        (normalize.as_str(), normalize_pipeline),
        (view, targets),
        state,
        opaque,
    )?;
    Ok(None)
}

/// `points.triangles`: the hybrid triangles (§10.1.8) opaque and shaded
/// on the hardware path, with depth and W = 1, for the splats' compute
/// passes to test against.
pub(super) fn declare_opaque_triangles<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
) -> Result<()> {
    let triangles_only = PointBuffers {
        primitive: SplatPrimitive::Quad,
        ..buffers
    };
    declare_opaque(ctx, graph, name, (triangles_only, view), targets, false)
}

/// The device feature the hybrid triangles' passes need on the compute
/// path (their fragments write the splats' state).
pub(super) const TRIANGLE_FEATURE: &str = "fragmentStoresAndAtomics";

/// The hybrid triangles' pipelines (`glsl/points/hybrid.vert` with the
/// compute path's fragment stages): no attachment written, no depth test
/// (the depth buffer's depth is in the nearest words).
struct TrianglePipelines {
    visibility: Arc<GraphicsPipeline>,
    accumulate: Arc<GraphicsPipeline>,
}

impl TrianglePipelines {
    fn new(ctx: &Context, targets: &SceneTargets) -> Result<Self> {
        let build = |name, fragment| {
            let spec = PipelineSpec {
                name,
                shaders: (shaders::HYBRID_VERT, fragment),
                color_formats: Vec::new(),
                blend: Blend::None,
                depth: (false, CompareOp::ALWAYS),
            };
            spec.build(ctx, targets.formats.depth, false).map(Arc::new)
        };
        Ok(TrianglePipelines {
            visibility: build("points.visibility.triangles", shaders::HYBRID_COMPUTE_VISIBILITY_FRAG)?,
            accumulate: build("points.accumulate.triangles", shaders::HYBRID_COMPUTE_ACCUMULATE_FRAG)?,
        })
    }
}

/// `points.visibility.triangles` (`visibility`: raises the nearest words,
/// counts the triangles) or `points.accumulate.triangles` (adds to the
/// sums): the hybrid triangles of the view's plan (§10.1.8) drawn with the
/// depth buffer attached but neither tested nor written (cleared first
/// when nothing drew into it).
fn declare_triangles<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view, state): (PointBuffers, PointView, SplatState),
    (visibility, pipeline): (bool, Arc<GraphicsPipeline>),
) -> Result<()> {
    let mut builder = graph.pass(name).graphics();
    let frame = builder.upload(view.frame, Stage::Graphics);
    let (mut builder, splat) = buffers.read_by(builder, frame, visibility);
    let fragment = Stage::Fragment;
    let written = BufferAccess::StorageReadWrite(fragment);
    let bindings = match visibility {
        true => StateBindings {
            nearest: builder.storage_buffer(state.nearest, written),
            sums: None,
            last: None,
        },
        false => StateBindings {
            nearest: builder.storage_buffer(state.nearest, BufferAccess::StorageRead(fragment)),
            sums: Some(builder.storage_buffer(state.accumulation()?.0, written)),
            last: Some(builder.storage_buffer(state.accumulation()?.1, written)),
        },
    };
    let builder = builder.pipeline(&pipeline);
    let builder = match visibility {
        true => builder.depth(view.depth, view.clear_depth.then_some(FAR_DEPTH)),
        false => builder.depth_read(view.depth),
    };
    builder.record(move |pass, frame| {
        let plan = plan_of(frame, view.index)?;
        let push = ComputeSplatPush {
            splat: splat.push(pass, PASS_OPAQUE)?,
            raster: bindings.handles(pass, 0)?,
            draws: [0; 4],
        };
        let Some(triangles) = splat.triangle_handle(pass)? else {
            return Ok(());
        };
        draw_triangles_with(pass.cmd(), &pipeline, plan, (push, |p| &mut p.splat), triangles)
    });
    Ok(())
}

/// `points.clear`: the nearest words from the ground's visibility keys
/// (when given) or the depth buffer (when something drew into it), sums
/// and last records 0.
pub(super) fn declare_clear<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (view, state, depth_written, ground): (PointView, SplatState, bool, Option<GroundKeys>),
    pipeline: ComputePipeline,
) {
    let write = BufferAccess::StorageWrite(Stage::Compute);
    let mut pass = graph.pass(name);
    let nearest = pass.storage_buffer(state.nearest, write);
    let sums = (state.accumulation).map(|(s, l)| [s, l].map(|b| pass.storage_buffer(b, write)));
    let depth = depth_written.then(|| pass.sample(view.depth, Stage::Compute));
    let keys = ground.map(|g| pass.storage_buffer(g.0, BufferAccess::StorageRead(Stage::Compute)));
    pass.record(move |ctx, frame| {
        let depth = depth.map(|d| ctx.handle(d)).transpose()?.unwrap_or(NO_HANDLE);
        let keys = keys.map(|k| ctx.handle(k)).transpose()?.unwrap_or(NO_HANDLE);
        let row = frame.prepared::<PointsFrame>()?.view(view.index)?.header.depth;
        let [sums, last] = match sums {
            Some(buffers) => [ctx.handle(buffers[0])?, ctx.handle(buffers[1])?],
            None => [NO_HANDLE; 2],
        };
        let push = ClearPush {
            handles: [ctx.handle(nearest)?, sums, last, depth],
            size: [state.size[0], state.size[1], keys, 0],
            row: [row[0], row[1], 0.0, 0.0],
        };
        let groups = [state.size[0].div_ceil(8), state.size[1].div_ceil(8), 1];
        ctx.dispatch(&pipeline, &push, groups)
    });
}

/// `points.visibility` (`visibility`: raises the nearest words, counts the
/// drawn splats) or `points.accumulate` (reads them, adds to the sums and
/// raises the last records): one dispatch for all the view's draws. With
/// `header` (the view's targets) the pass writes the point frame's header,
/// for the ground's shading pass to read.
pub(super) fn declare_splats<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    ((buffers, view, state), header): ((PointBuffers, PointView, SplatState), Option<&SceneTargets>),
    visibility: bool,
    pipeline: ComputePipeline,
) -> Result<()> {
    let compute = Stage::Compute;
    let mut builder = graph.pass(name);
    let shading = header.map(|targets| ShadingBindings::read_in(&mut builder, (&view, targets), compute));
    let frame = match &shading {
        Some(s) => s.frame,
        None => builder.upload(view.frame, compute),
    };
    let buffers = PointBuffers {
        counter: buffers.counter.filter(|_| visibility),
        ..buffers
    };
    let (mut builder, splat): (_, SplatBindings) = buffers.read_by_at(builder, frame, (compute, compute));
    let table = view
        .draws
        .ok_or_else(|| Error::Graph(format!("{name}: the view has no draw table")))?;
    let table = builder.upload(table, compute);
    let written = BufferAccess::StorageReadWrite(compute);
    let bindings = match visibility {
        true => StateBindings {
            nearest: builder.storage_buffer(state.nearest, written),
            sums: None,
            last: None,
        },
        false => StateBindings {
            nearest: builder.storage_buffer(state.nearest, BufferAccess::StorageRead(compute)),
            sums: Some(builder.storage_buffer(state.accumulation()?.0, written)),
            last: Some(builder.storage_buffer(state.accumulation()?.1, written)),
        },
    };
    builder.record(move |pass, frame| {
        if let Some(shading) = &shading {
            shading.write_header(pass, frame, view.index)?;
        }
        let plan = plan_of(frame, view.index)?;
        // The draw table was checked not to overflow when it was written.
        let splats = plan.draws.iter().map(|d| d.count).fold(0u32, u32::wrapping_add);
        let draws = u32::try_from(plan.draws.len()).map_err(|_| Error::invalid("points", "too many draws"))?;
        let push = ComputeSplatPush {
            splat: splat.push(pass, PASS_OPAQUE)?,
            raster: bindings.handles(pass, splats)?,
            draws: [pass.handle(table)?, draws, 0, 0],
        };
        if splats == 0 {
            return Ok(());
        }
        pass.dispatch(&pipeline, &push, [stride_groups(splats, SPLATS_PER_GROUP), 1, 1])
    });
    Ok(())
}

/// `points.normalize`: a compute pass over the view's pixels: the sums
/// divided and shaded into the view's targets; W set to 0 where no splat
/// is unless the hybrid triangles wrote it (`triangles`).
fn declare_normalize<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, pipeline): (&str, ComputePipeline),
    (view, targets): (PointView, &SceneTargets),
    state: SplatState,
    triangles: bool,
) -> Result<()> {
    let pipeline = Arc::new(pipeline);
    let compute = Stage::Compute;
    let weight = match triangles {
        true => ImageAccess::StorageReadWrite(compute),
        false => ImageAccess::StorageWrite(compute),
    };
    let mut builder = graph.pass(name);
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), compute);
    let read = BufferAccess::StorageRead(compute);
    let (sums, last) = state.accumulation()?;
    let [nearest, sums, last] = [state.nearest, sums, last].map(|b| builder.storage_buffer(b, read));
    let outputs = ResolvedTargets::declare(&mut builder, (&view, targets), weight);
    builder.record(move |pass, frame| {
        let frame = shading.write_header(pass, frame, view.index)?;
        let (outputs_push, more) = outputs.push(pass)?;
        let push = NormalizePush {
            handles: [pass.handle(sums)?, frame, u32::from(triangles), pass.handle(nearest)?],
            mode: [pass.handle(last)?, 0, 0, 0],
            outputs: outputs_push,
            more,
        };
        pass.dispatch(&pipeline, &push, outputs.groups())
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_constants_match_the_shader_blocks() {
        // handles, mode (SplatPush), raster, draws: 64 bytes; clear and normalize: 48 and 64.
        assert_eq!(std::mem::size_of::<ComputeSplatPush>(), 64);
        assert_eq!(std::mem::size_of::<ClearPush>(), 48);
        assert_eq!(std::mem::size_of::<NormalizePush>(), 64);
    }
}
