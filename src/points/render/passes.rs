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
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, PassBuilder, RenderGraph, Stage, UploadRegion};
use crate::shaders;
use crate::view::{Frame, Provides, SceneTargets, ViewIndex};
use crate::vulkan::{
    Blend, Buffer, CommandRecorder, CompareOp, Context, GraphicsPipeline, GraphicsPipelineDesc, Image, LoadOp, SpirV,
};

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

/// Push constants of `points.normalize` (`glsl/points/normalize.frag`).
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
    /// The view's lighting constants.
    pub lighting: UploadRegion,
    /// Clear the depth buffer first (no terrain drew into it).
    pub clear_depth: bool,
}

impl PointView {
    /// Declares the writes of a pass that draws the view's shaded outputs
    /// (radiance, view depth, W with `weight`, visibility, normal, ids).
    pub(super) fn write_outputs<'g, S: Provides<PointsFrame> + 'static>(
        &self,
        builder: PassBuilder<'g, Frame<S>>,
        weight: ImageAccess,
    ) -> PassBuilder<'g, Frame<S>> {
        builder
            .write(self.radiance, ImageAccess::ColorAttachmentReadWrite)
            .write(self.view_depth, ImageAccess::ColorAttachmentReadWrite)
            .write(self.weight, weight)
            .write(self.visibility, ImageAccess::ColorAttachmentReadWrite)
            .write(self.normal, ImageAccess::ColorAttachmentReadWrite)
            .write(self.ids, ImageAccess::ColorAttachmentReadWrite)
    }

    /// The colour attachments of [`Self::write_outputs`]: every output
    /// loaded but W, which `weight` loads or clears.
    pub(super) fn output_attachments<'a>(
        &self,
        pass: &crate::graph::PassContext<'a>,
        weight: LoadOp,
    ) -> Result<[(&'a Image, LoadOp); 6]> {
        Ok([
            (pass.image(self.radiance)?, LoadOp::Load),
            (pass.image(self.view_depth)?, LoadOp::Load),
            (pass.image(self.weight)?, weight),
            (pass.image(self.visibility)?, LoadOp::Load),
            (pass.image(self.normal)?, LoadOp::Load),
            (pass.image(self.ids)?, LoadOp::Load),
        ])
    }

    /// Draws `pipeline` full screen with `push` into the outputs (W loaded
    /// or cleared by `weight`): the resolve passes.
    pub(super) fn draw_full_screen<T: Pod>(
        &self,
        pass: &mut crate::graph::PassContext<'_>,
        weight: LoadOp,
        pipeline: &GraphicsPipeline,
        push: &T,
    ) -> Result<()> {
        let colors = self.output_attachments(pass, weight)?;
        let cmd = pass.cmd();
        cmd.begin_rendering(&colors, None);
        cmd.bind_graphics(pipeline);
        cmd.push_constants(push)?;
        cmd.draw(3, 1);
        cmd.end_rendering();
        Ok(())
    }
}

impl PointBuffers {
    /// Declares the reads every splat pass makes (and the counter's write when `count`).
    fn read_by<'g, S: Provides<PointsFrame> + 'static>(
        &self,
        builder: PassBuilder<'g, Frame<S>>,
        frame: UploadRegion,
        count: bool,
    ) -> PassBuilder<'g, Frame<S>> {
        let mut builder = builder
            .read(self.splats, BufferAccess::StorageRead(Stage::Vertex))
            .read(frame, BufferAccess::StorageRead(Stage::Graphics))
            .read(self.table, BufferAccess::StorageRead(Stage::Fragment));
        if let (true, Some(c)) = (count, self.counter) {
            builder = builder.write(c, BufferAccess::StorageReadWrite(Stage::Vertex));
        }
        if let Some(t) = self.triangles {
            builder = builder.read(t, BufferAccess::StorageRead(Stage::Vertex));
        }
        match &self.object {
            Some(object) => object.read_by(builder),
            None => builder,
        }
    }

    /// The push constants of `pass` (counting the drawn splats when `count`).
    pub(super) fn push(
        &self,
        ctx: &crate::graph::PassContext<'_>,
        frame: UploadRegion,
        pass: u32,
        count: bool,
    ) -> Result<SplatPush> {
        Ok(SplatPush {
            splats: ctx.storage_buffer(self.splats)?,
            frame: ctx.upload(frame)?,
            counter: match (count, self.counter) {
                (true, Some(c)) => ctx.storage_buffer(c)?,
                _ => NO_HANDLE,
            },
            table: match &self.object {
                Some(object) => ctx.sampled(object.kernel)?,
                None => ctx.storage_buffer(self.table)?,
            },
            pass,
            primitive: PRIMITIVE_QUAD,
            size_class: SIZE_ANY,
            record: 0,
        })
    }

    /// The triangle buffer's handle in a pass.
    pub(super) fn triangle_handle(&self, ctx: &crate::graph::PassContext<'_>) -> Result<Option<u32>> {
        self.triangles.map(|t| ctx.storage_buffer(t)).transpose()
    }

    /// The vertex and index buffers of the object-space primitives in a pass.
    fn object_buffers<'a>(&self, ctx: &crate::graph::PassContext<'a>) -> Result<Option<(&'a Buffer, &'a Buffer)>> {
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
        depth: (true, CompareOp::LESS),
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
    let builder = buffers.read_by(graph.pass(name).graphics(), view.frame, true);
    let builder = targets.lighting.read_in(builder, Stage::Fragment);
    view.write_outputs(builder, ImageAccess::ColorAttachmentWrite)
        .write(view.depth, ImageAccess::DepthAttachmentWrite)
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let push = buffers.push(pass, view.frame, PASS_OPAQUE, true)?;
            let triangles = buffers.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let colors = view.output_attachments(pass, LoadOp::Clear([0.0; 4]))?;
            let depth = pass.image(view.depth)?;
            let cmd = pass.cmd();
            cmd.begin_rendering(&colors, Some((depth, view.clear_depth.then_some(1.0))));
            if draw_splats {
                pipelines.draw(cmd, plan, (buffers.primitive, object), push)?;
            }
            pipelines.draw_hybrid(cmd, plan, push, triangles)?;
            cmd.end_rendering();
            Ok(())
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
        depth: (true, CompareOp::LESS),
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
    let builder = buffers.read_by(graph.pass(name).graphics(), view.frame, true);
    builder
        .write(ids, ImageAccess::ColorAttachmentWrite)
        .write(view.depth, ImageAccess::DepthAttachmentWrite)
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let push = buffers.push(pass, view.frame, PASS_VISIBILITY, true)?;
            let triangles = buffers.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let (ids, depth) = (pass.image(ids)?, pass.image(view.depth)?);
            let cmd = pass.cmd();
            let clear = view.clear_depth.then_some(1.0);
            cmd.begin_rendering(&[(ids, LoadOp::Clear([0.0; 4]))], Some((depth, clear)));
            pipelines.draw_hybrid(cmd, plan, push, triangles)?;
            pipelines.draw(cmd, plan, (buffers.primitive, object), push)?;
            cmd.end_rendering();
            Ok(())
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
        depth: (false, CompareOp::LESS_OR_EQUAL),
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
    let builder = buffers.read_by(graph.pass(name).graphics(), view.frame, false);
    builder
        .read(view.depth, ImageAccess::DepthAttachmentRead)
        .write(accumulation.color_weight, ImageAccess::ColorAttachmentWrite)
        .write(accumulation.normal_depth, ImageAccess::ColorAttachmentWrite)
        .write(accumulation.any_ids, ImageAccess::ColorAttachmentWrite)
        .record(move |pass, frame| {
            let plan = plan_of(frame, view.index)?;
            let push = buffers.push(pass, view.frame, PASS_ACCUMULATE, false)?;
            let triangles = buffers.triangle_handle(pass)?;
            let object = buffers.object_buffers(pass)?;
            let (cw, nd) = (
                pass.image(accumulation.color_weight)?,
                pass.image(accumulation.normal_depth)?,
            );
            let (ids, depth) = (pass.image(accumulation.any_ids)?, pass.image(view.depth)?);
            let clear = LoadOp::Clear([0.0; 4]);
            let cmd = pass.cmd();
            cmd.begin_rendering(&[(cw, clear), (nd, clear), (ids, clear)], Some((depth, None)));
            pipelines.draw(cmd, plan, (buffers.primitive, object), push)?;
            pipelines.draw_hybrid(cmd, plan, push, triangles)?;
            cmd.end_rendering();
            Ok(())
        });
    Ok(())
}

/// `points.normalize`: full screen, divide by w, shade (sun, sky, haze),
/// write radiance, view depth, W, the world normal and the ids (the
/// nearest surfel's, else the last accumulated one's).
fn declare_normalize<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    view: PointView,
    targets: &SceneTargets,
    accumulation: Accumulation,
) -> Result<()> {
    let formats = &targets.formats;
    let pipeline = Arc::new(GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc::full_screen(
            "points.normalize",
            (shaders::FULL_SCREEN_VERT, shaders::SPLAT_NORMALIZE_FRAG),
            vec![
                formats.radiance,
                formats.view_depth,
                formats.weight,
                formats.visibility,
                formats.normal,
                formats.ids,
            ],
        ),
    )?);
    let builder = targets
        .lighting
        .read_in(graph.pass(name).graphics(), Stage::Fragment)
        .read(accumulation.color_weight, ImageAccess::Sampled(Stage::Fragment))
        .read(accumulation.normal_depth, ImageAccess::Sampled(Stage::Fragment))
        .read(accumulation.nearest_ids, ImageAccess::Sampled(Stage::Fragment))
        .read(accumulation.any_ids, ImageAccess::Sampled(Stage::Fragment))
        .read(view.frame, BufferAccess::StorageRead(Stage::Fragment));
    view.write_outputs(builder, ImageAccess::ColorAttachmentWrite)
        .record(move |pass, _| {
            let push = NormalizePush {
                color_weight: pass.sampled(accumulation.color_weight)?,
                frame: pass.upload(view.frame)?,
                normal_depth: pass.sampled(accumulation.normal_depth)?,
                nearest_ids: pass.sampled(accumulation.nearest_ids)?,
                any_ids: pass.sampled(accumulation.any_ids)?,
                ..NormalizePush::zeroed()
            };
            view.draw_full_screen(pass, LoadOp::Clear([0.0; 4]), &pipeline, &push)
        });
    Ok(())
}
