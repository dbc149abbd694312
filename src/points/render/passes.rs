//! The points passes as render-graph declarations (see the table in
//! [`super`]): pipelines and the recording of the draws of a view's
//! prepared [`FramePlan`]. Each pass reads like a sentence; the plan comes
//! from [`super::PointRenderer`]'s `prepare`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::object_space::{self, ObjectSpaceBuffers};
use super::pipeline_spec::PipelineSpec;
use super::selection::FramePlan;
use super::triangles::draw_triangles;
use super::{PointsFrame, SplatPrimitive};
use crate::error::{Error, Result};
use crate::graph::{
    Binding, BufferAccess, BufferId, ImageAccess, ImageId, LoadOp, PassBuilder, PassContext, RenderGraph, Stage,
    UploadRegion,
};
use crate::shaders;
use crate::view::depth::{FAR_DEPTH, NEARER, NEARER_OR_EQUAL};
use crate::view::{Frame, Provides, SceneTargets, ViewIndex};
use crate::vulkan::{Blend, Buffer, CommandRecorder, ComputePipeline, Context, GraphicsPipeline, SpirV};

/// `SplatPush.pass`: which pass the shaders run in.
const PASS_VISIBILITY: u32 = 0;
const PASS_ACCUMULATE: u32 = 1;
pub(super) const PASS_OPAQUE: u32 = 2;
/// `SplatPush.primitive`.
pub(super) const PRIMITIVE_QUAD: u32 = 0;
const PRIMITIVE_INSTANCED: u32 = 1;
const PRIMITIVE_POINT: u32 = 2;
/// `SplatPush.size_class`: every splat, only those a point can cover, only larger ones.
const SIZE_ANY: u32 = 0;
const SIZE_POINT: u32 = 1;
const SIZE_OVERSIZE: u32 = 2;
pub(super) const NO_HANDLE: u32 = u32::MAX;

/// Push constants of the points passes (`Push` in glsl/include/splat.glsl:
/// `handles`, then `mode`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct SplatPush {
    /// Splats (or hybrid triangles), storage.
    pub splats: u32,
    /// The view's point frame (header and instance records), storage.
    pub frame: u32,
    /// Drawn-splat counter, storage ([`NO_HANDLE`]: do not count).
    pub counter: u32,
    /// Gaussian table, storage (object-space primitives: the kernel texture, sampled).
    pub table: u32,
    /// `PASS_*`.
    pub pass: u32,
    /// `PRIMITIVE_*`.
    pub primitive: u32,
    /// `SIZE_*`.
    pub size_class: u32,
    /// Instance record of the draw.
    pub record: u32,
}

/// Push constants of `points.normalize` (`glsl/points/normalize.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct NormalizePush {
    /// Sampled (colour·w, w) target.
    color_weight: u32,
    /// The view's point frame, storage.
    frame: u32,
    /// Sampled (normal·w, depth·w) target.
    normal_depth: u32,
    _pad: u32,
    /// Sampled ids of the nearest surfel and of any accumulated surfel.
    nearest_ids: u32,
    any_ids: u32,
    _pad2: [u32; 2],
    /// Storage: radiance, view depth, W, lighting AOVs.
    outputs: [u32; 4],
    /// Storage: normal, ids; width, height.
    more: [u32; 4],
}

/// The buffers every points pass reads, and the splat settings they use.
#[derive(Clone, Copy, Debug)]
pub(super) struct PointBuffers {
    pub splats: BufferId,
    pub table: BufferId,
    /// GPU counters, per frame slot (None without vertexPipelineStoresAndAtomics).
    pub counter: Option<BufferId>,
    /// Hybrid triangles (§10.1.8), when the scene has any.
    pub triangles: Option<BufferId>,
    pub primitive: SplatPrimitive,
    /// Vertices, indices and kernel texture of the object-space primitives (§10.3).
    pub object: Option<ObjectSpaceBuffers>,
}

/// One view's points passes: its index, frame region and targets.
#[derive(Clone, Copy, Debug)]
pub(super) struct PointView {
    pub index: ViewIndex,
    pub frame: UploadRegion,
    pub radiance: ImageId,
    pub view_depth: ImageId,
    pub depth: ImageId,
    pub weight: ImageId,
    /// The lighting AOVs.
    pub visibility: ImageId,
    /// The world normal and ids AOVs (`crate::view::aov`).
    pub normal: ImageId,
    pub ids: ImageId,
    /// Clear the depth buffer first (no terrain drew into it).
    pub clear_depth: bool,
    /// The draw table of the compute path's splat passes (per draw: its
    /// first splat counted over the view's draws, its instance record),
    /// written by `prepare`; None on the hardware path.
    pub draws: Option<UploadRegion>,
}

impl PointView {
    /// Declares the colour attachments of a pass that draws the view's
    /// shaded outputs (radiance, view depth, W, visibility, normal, ids):
    /// every output loaded but W, which `weight` loads or clears.
    pub(super) fn write_outputs<'g, S: Provides<PointsFrame> + 'static>(
        &self,
        builder: PassBuilder<'g, Frame<S>>,
        weight: LoadOp,
    ) -> PassBuilder<'g, Frame<S>> {
        builder
            .color(self.radiance, LoadOp::Load)
            .color(self.view_depth, LoadOp::Load)
            .color(self.weight, weight)
            .color(self.visibility, LoadOp::Load)
            .color(self.normal, LoadOp::Load)
            .color(self.ids, LoadOp::Load)
    }
}

/// The targets a compute pass that resolves splats writes (storage):
/// radiance, view depth, lighting AOVs, normal, ids (read and written:
/// pixels without splats keep what the terrain and sky wrote), and W.
#[derive(Clone, Copy, Debug)]
pub(super) struct ResolvedTargets {
    kept: [Binding; 5],
    weight: Binding,
    size: [u32; 2],
}

impl ResolvedTargets {
    /// Declares the writes of `view`'s outputs on `builder` (a compute
    /// pass); `weight`: how W is accessed.
    pub(super) fn declare<P: 'static>(
        builder: &mut PassBuilder<'_, P>,
        (view, targets): (&PointView, &SceneTargets),
        weight: ImageAccess,
    ) -> ResolvedTargets {
        let kept = ImageAccess::StorageReadWrite(Stage::Compute);
        ResolvedTargets {
            kept: [view.radiance, view.view_depth, view.visibility, view.normal, view.ids]
                .map(|image| builder.storage_image(image, kept)),
            weight: builder.storage_image(view.weight, weight),
            size: [targets.width, targets.height],
        }
    }

    /// The shaders' `outputs` and `more` push constants (`splat.glsl`).
    pub(super) fn push(&self, ctx: &PassContext<'_>) -> Result<([u32; 4], [u32; 4])> {
        let kept = |k: usize| ctx.handle(self.kept[k]);
        Ok((
            [kept(0)?, kept(1)?, ctx.handle(self.weight)?, kept(2)?],
            [kept(3)?, kept(4)?, self.size[0], self.size[1]],
        ))
    }

    /// The workgroups of an 8×8-pixel dispatch over the targets.
    pub(super) fn groups(&self) -> [u32; 3] {
        [self.size[0].div_ceil(8), self.size[1].div_ceil(8), 1]
    }
}

/// The heap bindings of a shading pass of the points: the view's point
/// frame and lighting constants. The pass writes the frame's header (which
/// names the lighting constants) while recording.
#[derive(Clone, Copy, Debug)]
pub(super) struct ShadingBindings {
    pub frame: Binding,
    pub lighting: Binding,
}

impl ShadingBindings {
    /// Declares the reads of a pass that shades view `view`'s points (its
    /// point frame read at `stage`).
    pub(super) fn read_in<P: 'static>(
        pass: &mut PassBuilder<'_, P>,
        (view, targets): (&PointView, &SceneTargets),
        stage: Stage,
    ) -> ShadingBindings {
        let lighting = targets.lighting.read_in(pass, stage).constants;
        let frame = pass.upload(view.frame, stage);
        ShadingBindings { frame, lighting }
    }

    /// Writes the header of the view's point frame (prepared, with the
    /// heap handle of the lighting constants), and returns the frame's handle.
    pub(super) fn write_header<S: Provides<PointsFrame>>(
        &self,
        ctx: &mut PassContext<'_>,
        frame: &Frame<S>,
        index: ViewIndex,
    ) -> Result<u32> {
        let mut header = frame.prepared::<PointsFrame>()?.view(index)?.header;
        header.lighting[0] = ctx.handle(self.lighting)?;
        ctx.write_upload_pod(self.frame, &header)?;
        ctx.handle(self.frame)
    }
}

/// The heap bindings of a splat pass ([`PointBuffers::read_by`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct SplatBindings {
    splats: Binding,
    frame: Binding,
    counter: Option<Binding>,
    /// The Gaussian table, or the object-space primitives' kernel texture.
    table: Binding,
    triangles: Option<Binding>,
}

impl SplatBindings {
    /// The push constants of `pass` (the drawn splats counted when the
    /// pass declared the counter).
    pub(super) fn push(&self, ctx: &PassContext<'_>, pass: u32) -> Result<SplatPush> {
        Ok(SplatPush {
            splats: ctx.handle(self.splats)?,
            frame: ctx.handle(self.frame)?,
            counter: self.counter.map(|c| ctx.handle(c)).transpose()?.unwrap_or(NO_HANDLE),
            table: ctx.handle(self.table)?,
            pass,
            primitive: PRIMITIVE_QUAD,
            size_class: SIZE_ANY,
            record: 0,
        })
    }

    /// The triangle buffer's handle in the pass.
    pub(super) fn triangle_handle(&self, ctx: &PassContext<'_>) -> Result<Option<u32>> {
        self.triangles.map(|t| ctx.handle(t)).transpose()
    }
}

impl PointBuffers {
    /// Declares the reads every splat pass makes (and the counter's write
    /// when `count`); `frame`: the binding of the view's point frame,
    /// declared by the pass.
    pub(super) fn read_by<'g, S: 'static>(
        &self,
        builder: PassBuilder<'g, Frame<S>>,
        frame: Binding,
        count: bool,
    ) -> (PassBuilder<'g, Frame<S>>, SplatBindings) {
        let buffers = PointBuffers {
            counter: self.counter.filter(|_| count),
            ..*self
        };
        let (mut builder, mut bindings) = buffers.read_by_at(builder, frame, (Stage::Vertex, Stage::Fragment));
        bindings.triangles =
            (self.triangles).map(|t| builder.storage_buffer(t, BufferAccess::StorageRead(Stage::Vertex)));
        match &self.object {
            Some(object) => {
                let (builder, kernel) = object.read_by(builder);
                bindings.table = kernel;
                (builder, bindings)
            }
            None => (builder, bindings),
        }
    }

    /// Declares the splats' read at `vertex`, the Gaussian table's at
    /// `fragment` and the counter's write (if any) at `vertex`.
    pub(super) fn read_by_at<'g, S: 'static>(
        &self,
        mut builder: PassBuilder<'g, Frame<S>>,
        frame: Binding,
        (vertex, fragment): (Stage, Stage),
    ) -> (PassBuilder<'g, Frame<S>>, SplatBindings) {
        let splats = builder.storage_buffer(self.splats, BufferAccess::StorageRead(vertex));
        let table = builder.storage_buffer(self.table, BufferAccess::StorageRead(fragment));
        let counter = (self.counter).map(|c| builder.storage_buffer(c, BufferAccess::StorageReadWrite(vertex)));
        let bindings = SplatBindings {
            splats,
            frame,
            counter,
            table,
            triangles: None,
        };
        (builder, bindings)
    }

    /// The vertex and index buffers of the object-space primitives in a pass.
    fn object_buffers<'a>(&self, ctx: &PassContext<'a>) -> Result<Option<(&'a Buffer, &'a Buffer)>> {
        self.object
            .map(|o| Ok((ctx.buffer(o.vertices)?, ctx.buffer(o.indices)?)))
            .transpose()
    }
}

/// The plan of view `index` in `frame`.
pub(super) fn plan_of<S: Provides<PointsFrame> + 'static>(frame: &Frame<S>, index: ViewIndex) -> Result<&FramePlan> {
    Ok(&frame.prepared::<PointsFrame>()?.view(index)?.plan)
}

/// A pass's pipelines: splats as triangles (screen-space quads, or the
/// object-space quads of §10.3), as points (point primitive), and hybrid
/// triangles (when the scene has any).
pub(super) struct PassPipelines {
    triangles: GraphicsPipeline,
    points: Option<GraphicsPipeline>,
    hybrid: Option<GraphicsPipeline>,
}

impl PassPipelines {
    fn new(
        ctx: &Context,
        targets: &SceneTargets,
        buffers: &PointBuffers,
        (splats, object_fragment): (PipelineSpec, SpirV),
        hybrid: PipelineSpec,
    ) -> Result<Self> {
        let depth = targets.formats.depth;
        let points = if buffers.primitive == SplatPrimitive::Point {
            if !ctx.has_feature("largePoints") {
                return Err(Error::invalid(
                    "points.primitive",
                    "point: the device lacks feature largePoints (use quad or instanced)",
                ));
            }
            Some(splats.build(ctx, depth, true)?)
        } else {
            None
        };
        let triangles = match buffers.primitive.is_object_space() {
            true => splats.build_object_space(ctx, depth, buffers.primitive, object_fragment)?,
            false => splats.build(ctx, depth, false)?,
        };
        Ok(PassPipelines {
            triangles,
            points,
            hybrid: buffers.triangles.map(|_| hybrid.build(ctx, depth, false)).transpose()?,
        })
    }

    /// Declares the pipelines on `builder` (their formats are checked
    /// against the pass's attachments).
    fn declare_on<'g, S: 'static>(&self, builder: PassBuilder<'g, Frame<S>>) -> PassBuilder<'g, Frame<S>> {
        let builder = builder.pipeline(&self.triangles);
        let builder = match &self.points {
            Some(p) => builder.pipeline(p),
            None => builder,
        };
        match &self.hybrid {
            Some(p) => builder.pipeline(p),
            None => builder,
        }
    }

    /// Records one draw per planned instance (`object`: the vertex and index
    /// buffers of the object-space primitives).
    fn draw(
        &self,
        cmd: &mut CommandRecorder,
        plan: &FramePlan,
        (primitive, object): (SplatPrimitive, Option<(&Buffer, &Buffer)>),
        mut push: SplatPush,
    ) -> Result<()> {
        let six = |n: u32| {
            n.checked_mul(6)
                .ok_or_else(|| Error::invalid("splat count", format!("{n} splats exceed one draw")))
        };
        // One draw per instance; `counts(n)`: vertices and instances for n splats.
        let each = |cmd: &mut CommandRecorder, push: &mut SplatPush, counts: &dyn Fn(u32) -> Result<(u32, u32)>| {
            for d in &plan.draws {
                push.record = d.record;
                cmd.push_constants(push)?;
                let (vertices, instances) = counts(d.count)?;
                cmd.draw(vertices, instances);
            }
            Ok::<(), Error>(())
        };
        match (primitive, &self.points) {
            (SplatPrimitive::ObjectQuad | SplatPrimitive::ObjectInstanced, _) => {
                let object = object
                    .ok_or_else(|| Error::Graph("points: the object-space primitives' buffers are missing".into()))?;
                object_space::draw(cmd, &self.triangles, plan, (primitive, push), object)?;
            }
            (SplatPrimitive::Point, Some(points)) => {
                cmd.bind_graphics(points);
                (push.primitive, push.size_class) = (PRIMITIVE_POINT, SIZE_POINT);
                each(cmd, &mut push, &|n| Ok((n, 1)))?;
                // Fallback: splats larger than the largest point size as quads.
                cmd.bind_graphics(&self.triangles);
                (push.primitive, push.size_class) = (PRIMITIVE_QUAD, SIZE_OVERSIZE);
                each(cmd, &mut push, &|n| Ok((six(n)?, 1)))?;
            }
            (SplatPrimitive::Instanced, _) => {
                cmd.bind_graphics(&self.triangles);
                (push.primitive, push.size_class) = (PRIMITIVE_INSTANCED, SIZE_ANY);
                each(cmd, &mut push, &|n| Ok((6, n)))?;
            }
            _ => {
                cmd.bind_graphics(&self.triangles);
                (push.primitive, push.size_class) = (PRIMITIVE_QUAD, SIZE_ANY);
                each(cmd, &mut push, &|n| Ok((six(n)?, 1)))?;
            }
        }
        Ok(())
    }

    /// Records the hybrid triangles, if any (`triangles`: their buffer's handle).
    fn draw_hybrid(
        &self,
        cmd: &mut CommandRecorder,
        plan: &FramePlan,
        push: SplatPush,
        triangles: Option<u32>,
    ) -> Result<()> {
        match (&self.hybrid, triangles) {
            (Some(pipeline), Some(handle)) => draw_triangles(cmd, pipeline, plan, push, handle),
            _ => Ok(()),
        }
    }
}

/// `points.opaque` (the `--splat opaque` baseline): shaded opaque discs
/// with ray–plane depth, and the hybrid triangles; without `draw_splats`
/// only the triangles (`points.single_pass.triangles`).
pub(super) fn declare_opaque<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    draw_splats: bool,
) -> Result<()> {
    let f = &targets.formats;
    let formats = vec![f.radiance, f.view_depth, f.weight, f.visibility, f.normal, f.ids];
    let spec = |name, fragment| PipelineSpec {
        name,
        shaders: (shaders::SPLAT_VERT, fragment),
        color_formats: formats.clone(),
        blend: Blend::None,
        depth: (true, NEARER),
    };
    let pipelines = PassPipelines::new(
        ctx,
        targets,
        &buffers,
        (
            spec("points.opaque", shaders::SPLAT_OPAQUE_FRAG),
            shaders::OBJECT_OPAQUE_FRAG,
        ),
        PipelineSpec {
            shaders: (shaders::HYBRID_VERT, shaders::HYBRID_OPAQUE_FRAG),
            ..spec("points.opaque.triangles", shaders::HYBRID_OPAQUE_FRAG)
        },
    )?;
    let mut builder = graph.pass(name).graphics();
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), Stage::Graphics);
    let (builder, splat) = buffers.read_by(builder, shading.frame, true);
    let builder = view.write_outputs(pipelines.declare_on(builder), LoadOp::Clear([0.0; 4]));
    builder
        .depth(view.depth, view.clear_depth.then_some(FAR_DEPTH))
        .record(move |pass, frame| {
            shading.write_header(pass, frame, view.index)?;
            let plan = plan_of(frame, view.index)?;
            let push = splat.push(pass, PASS_OPAQUE)?;
            let triangles = splat.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let cmd = pass.cmd();
            if draw_splats {
                pipelines.draw(cmd, plan, (buffers.primitive, object), push)?;
            }
            pipelines.draw_hybrid(cmd, plan, push, triangles)
        });
    Ok(())
}

/// The two float targets of EWA accumulation (§10.2): (colour·w, w) and
/// (normal·w, depth·w); and the ids (`crate::view::aov`) of the surfel that
/// won the visibility pass, and of the last surfel accumulated (where the
/// winner's pushed-back depth lost against the terrain's, but the surface
/// is in front of it).
#[derive(Clone, Copy, Debug)]
pub(super) struct Accumulation {
    pub color_weight: ImageId,
    pub normal_depth: ImageId,
    pub nearest_ids: ImageId,
    pub any_ids: ImageId,
}

/// `points.visibility`, `points.accumulate` and `points.normalize`: the
/// three passes of perspective-accurate EWA splatting (§10.2, Table 10.1).
pub(super) fn declare_ewa<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    names: [&str; 3],
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
) -> Result<()> {
    let info = |format| crate::graph::ImageInfo::new(targets.width, targets.height, format);
    let accumulation = Accumulation {
        color_weight: graph.create_image("splat colour·w, w", info(targets.formats.accumulation)),
        normal_depth: graph.create_image("splat normal·w, depth·w", info(targets.formats.accumulation)),
        nearest_ids: graph.create_image("splat ids, nearest", info(targets.formats.ids)),
        any_ids: graph.create_image("splat ids, any", info(targets.formats.ids)),
    };
    declare_visibility(ctx, graph, names[0], (buffers, view), targets, accumulation.nearest_ids)?;
    declare_accumulate(ctx, graph, names[1], (buffers, view), targets, accumulation)?;
    declare_normalize(ctx, graph, names[2], view, targets, accumulation)
}

/// `points.visibility`: ray–plane depth pushed back by ε (§10.2.3), hybrid
/// triangles first; the ids of the surfel that wins the depth test (a
/// single surfel per pixel: ids are never blended) into `ids`.
fn declare_visibility<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    ids: ImageId,
) -> Result<()> {
    let spec = |name, shaders| PipelineSpec {
        name,
        shaders,
        color_formats: vec![targets.formats.ids],
        blend: Blend::None,
        depth: (true, NEARER),
    };
    let pipelines = PassPipelines::new(
        ctx,
        targets,
        &buffers,
        (
            spec(
                "points.visibility",
                (shaders::SPLAT_VERT, shaders::SPLAT_VISIBILITY_FRAG),
            ),
            shaders::OBJECT_VISIBILITY_FRAG,
        ),
        spec(
            "points.visibility.triangles",
            (shaders::HYBRID_VERT, shaders::HYBRID_VISIBILITY_FRAG),
        ),
    )?;
    let mut builder = graph.pass(name).graphics();
    let frame = builder.upload(view.frame, Stage::Graphics);
    let (builder, splat) = buffers.read_by(builder, frame, true);
    pipelines
        .declare_on(builder)
        .color(ids, LoadOp::Clear([0.0; 4]))
        .depth(view.depth, view.clear_depth.then_some(FAR_DEPTH))
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let push = splat.push(pass, PASS_VISIBILITY)?;
            let triangles = splat.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let cmd = pass.cmd();
            pipelines.draw_hybrid(cmd, plan, push, triangles)?;
            pipelines.draw(cmd, plan, (buffers.primitive, object), push)
        });
    Ok(())
}

/// `points.accumulate`: depth test ≤ without writes, additive (w·colour,
/// w) and (w·normal, w·depth) into the float targets (§10.2); the ids of
/// the last accumulated surfel (never blended).
fn declare_accumulate<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    accumulation: Accumulation,
) -> Result<()> {
    let spec = |name, shaders| PipelineSpec {
        name,
        shaders,
        color_formats: vec![
            targets.formats.accumulation,
            targets.formats.accumulation,
            targets.formats.ids,
        ],
        blend: Blend::Additive,
        depth: (false, NEARER_OR_EQUAL),
    };
    let pipelines = PassPipelines::new(
        ctx,
        targets,
        &buffers,
        (
            spec(
                "points.accumulate",
                (shaders::SPLAT_VERT, shaders::SPLAT_ACCUMULATE_FRAG),
            ),
            shaders::OBJECT_ACCUMULATE_FRAG,
        ),
        spec(
            "points.accumulate.triangles",
            (shaders::HYBRID_VERT, shaders::HYBRID_ACCUMULATE_FRAG),
        ),
    )?;
    let mut builder = graph.pass(name).graphics();
    let frame = builder.upload(view.frame, Stage::Graphics);
    let (builder, splat) = buffers.read_by(builder, frame, false);
    let clear = LoadOp::Clear([0.0; 4]);
    pipelines
        .declare_on(builder)
        .color(accumulation.color_weight, clear)
        .color(accumulation.normal_depth, clear)
        .color(accumulation.any_ids, clear)
        .depth_read(view.depth)
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let push = splat.push(pass, PASS_ACCUMULATE)?;
            let triangles = splat.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let cmd = pass.cmd();
            pipelines.draw(cmd, plan, (buffers.primitive, object), push)?;
            pipelines.draw_hybrid(cmd, plan, push, triangles)
        });
    Ok(())
}

/// `points.normalize`: a compute pass over the view's pixels: divide by w,
/// shade (sun, sky, haze), write radiance, view depth, W, the world normal
/// and the ids (the nearest surfel's, else the last accumulated one's)
/// where splats were accumulated, and W = 0 elsewhere (§10.2.3 pass 3).
fn declare_normalize<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    view: PointView,
    targets: &SceneTargets,
    accumulation: Accumulation,
) -> Result<()> {
    let pipeline = Arc::new(ComputePipeline::new(ctx, shaders::SPLAT_NORMALIZE)?);
    let compute = Stage::Compute;
    let mut builder = graph.pass(name);
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), compute);
    let sampled = [
        accumulation.color_weight,
        accumulation.normal_depth,
        accumulation.nearest_ids,
        accumulation.any_ids,
    ]
    .map(|image| builder.sample(image, compute));
    let outputs = ResolvedTargets::declare(&mut builder, (&view, targets), ImageAccess::StorageWrite(compute));
    builder.record(move |pass, frame| {
        let frame = shading.write_header(pass, frame, view.index)?;
        let (outputs_push, more) = outputs.push(pass)?;
        let push = NormalizePush {
            color_weight: pass.handle(sampled[0])?,
            frame,
            normal_depth: pass.handle(sampled[1])?,
            nearest_ids: pass.handle(sampled[2])?,
            any_ids: pass.handle(sampled[3])?,
            outputs: outputs_push,
            more,
            ..NormalizePush::zeroed()
        };
        pass.dispatch(&pipeline, &push, outputs.groups())
    });
    Ok(())
}
