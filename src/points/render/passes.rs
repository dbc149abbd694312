//! The points passes as render-graph declarations (see the table in
//! [`super`]): pipelines, buffers and the recording of the draws.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use bytemuck::{Pod, Zeroable};

use super::gpu_layout::{frame_header, gaussian_table, pack_nodes, HEADER_BYTES, INSTANCE_BYTES};
use super::selection::{plan_frame, FramePlan, ObjectLayout};
use super::stats::{PointFrameStats, StatsLog};
use super::triangles::{draw_triangles, TriangleBuffer};
use super::{SharedStats, SplatMode, SplatPrimitive, SplatSettings};
use crate::error::{Error, Result};
use crate::graph::{Access, ImageInfo, PassContext, RenderGraph, ResourceId, Stage};
use crate::points::build::clusters::{cluster_normals, CLUSTER_COUNT};
use crate::points::scene::PointScene;
use crate::shaders;
use crate::view::FrameParams;
use crate::vulkan::{
    Blend, Buffer, BufferDesc, BufferUsageFlags, CommandRecorder, CompareOp, Context, Format, GraphicsPipeline,
    GraphicsPipelineDesc, LoadOp, MemoryLocation, PrimitiveTopology, SpirV,
};

const PASS_VISIBILITY: u32 = 0;
const PASS_ACCUMULATE: u32 = 1;
const PASS_OPAQUE: u32 = 2;
const PRIMITIVE_QUAD: u32 = 0;
const PRIMITIVE_INSTANCED: u32 = 1;
const PRIMITIVE_POINT: u32 = 2;
const SIZE_ANY: u32 = 0;
const SIZE_POINT: u32 = 1;
const SIZE_OVERSIZE: u32 = 2;
const NO_HANDLE: u32 = u32::MAX;

/// Push constants of the points passes (`Push` in glsl/include/splat.glsl).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct SplatPush {
    /// Splats (or hybrid triangles), point frame, drawn counter, Gaussian table.
    pub handles: [u32; 4],
    /// Pass, primitive, size class, instance record.
    pub mode: [u32; 4],
}

/// The images the points passes draw into (declared by the renderer).
#[derive(Clone, Copy, Debug)]
pub struct SplatTargets {
    /// Radiance (RGBA32F), loaded.
    pub radiance: ResourceId,
    /// View depth (R32F), loaded.
    pub view_depth: ResourceId,
    /// Depth buffer (D32F).
    pub depth: ResourceId,
    /// W: the accumulated EWA weight (R32F), written everywhere.
    pub weight: ResourceId,
    /// Clear the depth buffer first (no terrain drew into it).
    pub clear_depth: bool,
}

/// Resources the renderer keeps for the points passes.
pub struct PointPasses {
    pub(crate) stats: SharedStats,
    _splats: Arc<Buffer>,
    _triangles: Option<Arc<Buffer>>,
}

impl PointPasses {
    /// Statistics of every completed frame not yet taken (call after all frames completed).
    pub fn take_stats(&self) -> Result<Vec<PointFrameStats>> {
        locked(&self.stats)?.take_all_completed()
    }
}

/// The value behind `mutex` (shared between the passes' recording closures).
fn locked<T>(mutex: &Mutex<T>) -> Result<std::sync::MutexGuard<'_, T>> {
    mutex
        .lock()
        .map_err(|_| Error::Graph("points pass state lock poisoned".into()))
}

fn pipeline(
    ctx: &Context,
    name: &'static str,
    (vertex, fragment): (SpirV, SpirV),
    points: bool,
    color_formats: Vec<Format>,
    blend: Blend,
    (depth_write, depth_compare): (bool, CompareOp),
) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        ctx,
        &GraphicsPipelineDesc {
            name,
            vertex,
            fragment,
            vertex_stride: 0,
            vertex_attributes: Vec::new(),
            topology: if points {
                PrimitiveTopology::POINT_LIST
            } else {
                PrimitiveTopology::TRIANGLE_LIST
            },
            cull_back_faces: false,
            wireframe: false,
            color_formats,
            blend,
            depth_format: Some(Format::D32_SFLOAT),
            depth_test: true,
            depth_write,
            depth_compare,
        },
    )
}

/// Triangle pipeline plus, for point primitives, the point pipeline.
struct PassPipelines {
    triangles: GraphicsPipeline,
    points: Option<GraphicsPipeline>,
}

impl PassPipelines {
    fn new(ctx: &Context, primitive: SplatPrimitive, build: impl Fn(bool) -> Result<GraphicsPipeline>) -> Result<Self> {
        Ok(PassPipelines {
            triangles: build(false)?,
            points: if primitive == SplatPrimitive::Point {
                if !ctx.has_feature("largePoints") {
                    return Err(Error::invalid(
                        "--splat-primitive point",
                        "the device lacks feature largePoints (use quad or instanced)",
                    ));
                }
                Some(build(true)?)
            } else {
                None
            },
        })
    }

    /// Records one draw per planned instance.
    fn draw(
        &self,
        cmd: &mut CommandRecorder,
        plan: &FramePlan,
        primitive: SplatPrimitive,
        mut push: SplatPush,
    ) -> Result<()> {
        let six = |n: u32| {
            n.checked_mul(6)
                .ok_or_else(|| Error::invalid("splat count", format!("{n} splats exceed one draw")))
        };
        match (primitive, &self.points) {
            (SplatPrimitive::Point, Some(points)) => {
                cmd.bind_graphics(points);
                push.mode[1] = PRIMITIVE_POINT;
                push.mode[2] = SIZE_POINT;
                for d in &plan.draws {
                    push.mode[3] = d.record;
                    cmd.push_constants(&push)?;
                    cmd.draw(d.count, 1);
                }
                // Fallback: splats larger than the largest point size as quads.
                cmd.bind_graphics(&self.triangles);
                push.mode[1] = PRIMITIVE_QUAD;
                push.mode[2] = SIZE_OVERSIZE;
                for d in &plan.draws {
                    push.mode[3] = d.record;
                    cmd.push_constants(&push)?;
                    cmd.draw(six(d.count)?, 1);
                }
            }
            _ => {
                cmd.bind_graphics(&self.triangles);
                let instanced = primitive == SplatPrimitive::Instanced;
                push.mode[1] = if instanced { PRIMITIVE_INSTANCED } else { PRIMITIVE_QUAD };
                push.mode[2] = SIZE_ANY;
                for d in &plan.draws {
                    push.mode[3] = d.record;
                    cmd.push_constants(&push)?;
                    if instanced {
                        cmd.draw(6, d.count);
                    } else {
                        cmd.draw(six(d.count)?, 1);
                    }
                }
            }
        }
        Ok(())
    }
}

/// One host-written storage buffer per frame slot.
fn host_buffers(ctx: &Context, name: &str, size: u64) -> Result<Vec<Arc<Buffer>>> {
    Buffer::per_frame(
        ctx,
        BufferDesc {
            name: name.into(),
            size,
            usage: BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )
}

/// Uploads the splat lists of `scene` and declares the points passes of
/// `settings.mode` into `graph`, after the terrain.
pub fn add_point_passes(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    scene: &PointScene,
    settings: SplatSettings,
    targets: SplatTargets,
    (width, height): (u32, u32),
) -> Result<PointPasses> {
    settings.validate()?;
    scene.validate()?;
    let mut scene = scene.clone();
    if let Some(epsilon) = settings.epsilon {
        for object in &mut scene.objects {
            *object = object.with_epsilon(epsilon)?;
        }
    }
    let triangle_buffer = TriangleBuffer::upload(ctx, &scene)?;
    let mut splats = Vec::with_capacity(scene.total_splats());
    let mut layouts = Vec::with_capacity(scene.objects.len());
    for (o, object) in scene.objects.iter().enumerate() {
        let first = u32::try_from(splats.len()).map_err(|_| Error::invalid("points", "too many splats"))?;
        let clusters = settings
            .normal_clusters
            .then(|| Arc::new(cluster_normals(&object.tree)));
        match &clusters {
            Some(c) => splats.extend(pack_nodes(&c.nodes)),
            None => splats.extend(pack_nodes(&object.tree.nodes)),
        }
        layouts.push(ObjectLayout {
            first,
            clusters,
            first_triangle: triangle_buffer.as_ref().map_or(0, |t| t.firsts[o]),
        });
    }
    if splats.len() > u32::MAX as usize / 6 {
        return Err(Error::invalid(
            "points",
            format!("{} splats exceed the limit", splats.len()),
        ));
    }
    let splat_buffer = Arc::new(Buffer::with_data(
        ctx,
        "splats",
        BufferUsageFlags::STORAGE_BUFFER,
        bytemuck::cast_slice(&splats),
    )?);
    let table = Arc::new(Buffer::with_data(
        ctx,
        "gaussian table",
        BufferUsageFlags::STORAGE_BUFFER,
        bytemuck::cast_slice(&gaussian_table(settings.cutoff)),
    )?);
    let draws_per_instance = if settings.normal_clusters { CLUSTER_COUNT } else { 1 };
    let frame_bytes = HEADER_BYTES + INSTANCE_BYTES * (scene.instances.len() * draws_per_instance).max(1) as u64;
    let frame_buffers = host_buffers(ctx, "point frame", frame_bytes)?;
    let counting = ctx.has_feature("vertexPipelineStoresAndAtomics");
    let counters = if counting {
        Some(host_buffers(ctx, "splat counter", 16)?)
    } else {
        None
    };
    let stats: SharedStats = Arc::new(Mutex::new(StatsLog::new(counters.clone())));

    let splats_id = graph.import_buffer(splat_buffer.clone());
    let table_id = graph.import_buffer(table);
    let frame_id = graph.import_buffers_per_frame(frame_buffers);
    let counter_id = counters.map(|c| graph.import_buffers_per_frame(c));
    let triangles_id = triangle_buffer.as_ref().map(|t| graph.import_buffer(t.buffer.clone()));
    // The hybrid triangles' pipeline of a pass (§10.1.8), when the scene has any.
    let triangle_pipeline = |name: &'static str, fragment: SpirV, formats: Vec<Format>, blend, depth| {
        triangles_id
            .map(|_| {
                pipeline(
                    ctx,
                    name,
                    (shaders::HYBRID_VERT, fragment),
                    false,
                    formats,
                    blend,
                    depth,
                )
            })
            .transpose()
    };
    // The triangle buffer's handle in a pass.
    let triangle_handle = move |pass: &PassContext<'_>| -> Result<Option<u32>> {
        triangles_id.map(|t| pass.storage_buffer(t)).transpose()
    };
    let max_point_size = ctx.info().max_point_size;
    let plan = Arc::new(Mutex::new(FramePlan::default()));

    // The first pass plans the frame: prefixes, instance records, statistics.
    let scene = Arc::new(scene);
    let layouts = Arc::new(layouts);
    let plan_frame_into = {
        let (plan, stats, scene, layouts) = (plan.clone(), stats.clone(), scene.clone(), layouts.clone());
        move |pass: &mut PassContext<'_>, params: &FrameParams| -> Result<()> {
            let started = Instant::now();
            let camera = &params.camera;
            let (header, view) = frame_header(camera, (width, height), params.sun, &settings, max_point_size);
            let view_proj = camera.view_proj_f64(params.aspect);
            let new_plan = plan_frame(&scene, &layouts, camera.eye, view, view_proj);
            let buffer = pass.buffer(frame_id)?;
            buffer.write(0, bytemuck::bytes_of(&header))?;
            buffer.write(HEADER_BYTES, bytemuck::cast_slice(&new_plan.records))?;
            let frame_stats = PointFrameStats {
                frame: pass.frame(),
                instances: new_plan.instances,
                instances_drawn: new_plan.instances_drawn,
                list_splats: new_plan.list_splats,
                prefix_splats: new_plan.prefix_splats,
                prefix_triangles: new_plan.prefix_triangles,
                triangles_drawn: None,
                interval_passed: None,
                drawn_splats: None,
                cpu_ms: started.elapsed().as_secs_f64() * 1e3,
            };
            locked(&stats)?.begin_frame(frame_stats)?;
            *locked(&plan)? = new_plan;
            Ok(())
        }
    };
    let push_for = move |pass: &PassContext<'_>, kind: u32, count: bool| -> Result<SplatPush> {
        Ok(SplatPush {
            handles: [
                pass.storage_buffer(splats_id)?,
                pass.storage_buffer(frame_id)?,
                match (count, counter_id) {
                    (true, Some(c)) => pass.storage_buffer(c)?,
                    _ => NO_HANDLE,
                },
                pass.storage_buffer(table_id)?,
            ],
            mode: [kind, PRIMITIVE_QUAD, SIZE_ANY, 0],
        })
    };
    let depth_load = if targets.clear_depth { Some(1.0) } else { None };
    let primitive = settings.primitive;
    if width > 0xffff || height > 0xffff {
        return Err(Error::invalid(
            "image size",
            "points passes support at most 65535 pixels per side",
        ));
    }

    match settings.mode {
        SplatMode::Opaque => {
            let pipes = PassPipelines::new(ctx, primitive, |points| {
                pipeline(
                    ctx,
                    "points.opaque",
                    (shaders::SPLAT_VERT, shaders::SPLAT_OPAQUE_FRAG),
                    points,
                    vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT, Format::R32_SFLOAT],
                    Blend::None,
                    (true, CompareOp::LESS),
                )
            })?;
            let opaque_triangles = triangle_pipeline(
                "points.opaque.triangles",
                shaders::HYBRID_OPAQUE_FRAG,
                vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT, Format::R32_SFLOAT],
                Blend::None,
                (true, CompareOp::LESS),
            )?;
            let mut builder = graph
                .pass("points.opaque")
                .graphics()
                .read(splats_id, Access::StorageBufferRead(Stage::Vertex))
                .read(frame_id, Access::StorageBufferRead(Stage::Graphics))
                .read(table_id, Access::StorageBufferRead(Stage::Fragment))
                .write(targets.radiance, Access::ColorAttachmentReadWrite)
                .write(targets.view_depth, Access::ColorAttachmentReadWrite)
                .write(targets.weight, Access::ColorAttachmentWrite)
                .write(targets.depth, Access::DepthAttachmentWrite);
            if let Some(c) = counter_id {
                builder = builder.write(c, Access::StorageBufferReadWrite(Stage::Vertex));
            }
            if let Some(t) = triangles_id {
                builder = builder.read(t, Access::StorageBufferRead(Stage::Vertex));
            }
            builder.record(move |pass, params| {
                plan_frame_into(pass, params)?;
                let push = push_for(pass, PASS_OPAQUE, true)?;
                let triangles = triangle_handle(pass)?;
                let (radiance, view_depth, weight, depth) = (
                    pass.image(targets.radiance)?,
                    pass.image(targets.view_depth)?,
                    pass.image(targets.weight)?,
                    pass.image(targets.depth)?,
                );
                let plan = locked(&plan)?;
                let cmd = pass.cmd();
                cmd.begin_rendering(
                    &[
                        (radiance, LoadOp::Load),
                        (view_depth, LoadOp::Load),
                        (weight, LoadOp::Clear([0.0; 4])),
                    ],
                    Some((depth, depth_load)),
                );
                pipes.draw(cmd, &plan, primitive, push)?;
                if let (Some(pipeline), Some(handle)) = (&opaque_triangles, triangles) {
                    draw_triangles(cmd, pipeline, &plan, push, handle)?;
                }
                cmd.end_rendering();
                Ok(())
            });
        }
        SplatMode::Ewa => {
            let visibility = PassPipelines::new(ctx, primitive, |points| {
                pipeline(
                    ctx,
                    "points.visibility",
                    (shaders::SPLAT_VERT, shaders::SPLAT_VISIBILITY_FRAG),
                    points,
                    Vec::new(),
                    Blend::None,
                    (true, CompareOp::LESS),
                )
            })?;
            let visibility_triangles = triangle_pipeline(
                "points.visibility.triangles",
                shaders::HYBRID_VISIBILITY_FRAG,
                Vec::new(),
                Blend::None,
                (true, CompareOp::LESS),
            )?;
            let accumulate = PassPipelines::new(ctx, primitive, |points| {
                pipeline(
                    ctx,
                    "points.accumulate",
                    (shaders::SPLAT_VERT, shaders::SPLAT_ACCUMULATE_FRAG),
                    points,
                    vec![Format::R32G32B32A32_SFLOAT, Format::R32G32B32A32_SFLOAT],
                    Blend::Additive,
                    (false, CompareOp::LESS_OR_EQUAL),
                )
            })?;
            let accumulate_triangles = triangle_pipeline(
                "points.accumulate.triangles",
                shaders::HYBRID_ACCUMULATE_FRAG,
                vec![Format::R32G32B32A32_SFLOAT, Format::R32G32B32A32_SFLOAT],
                Blend::Additive,
                (false, CompareOp::LESS_OR_EQUAL),
            )?;
            let normalize = GraphicsPipeline::new(
                ctx,
                &GraphicsPipelineDesc::full_screen(
                    "points.normalize",
                    (shaders::FULL_SCREEN_VERT, shaders::SPLAT_NORMALIZE_FRAG),
                    vec![Format::R32G32B32A32_SFLOAT, Format::R32_SFLOAT, Format::R32_SFLOAT],
                ),
            )?;
            let color_weight = graph.create_image(
                "splat colour·w, w",
                ImageInfo::new(width, height, Format::R32G32B32A32_SFLOAT),
            );
            let normal_depth = graph.create_image(
                "splat normal·w, depth·w",
                ImageInfo::new(width, height, Format::R32G32B32A32_SFLOAT),
            );

            let mut builder = graph
                .pass("points.visibility")
                .graphics()
                .read(splats_id, Access::StorageBufferRead(Stage::Vertex))
                .read(frame_id, Access::StorageBufferRead(Stage::Graphics))
                .read(table_id, Access::StorageBufferRead(Stage::Fragment))
                .write(targets.depth, Access::DepthAttachmentWrite);
            if let Some(c) = counter_id {
                builder = builder.write(c, Access::StorageBufferReadWrite(Stage::Vertex));
            }
            if let Some(t) = triangles_id {
                builder = builder.read(t, Access::StorageBufferRead(Stage::Vertex));
            }
            let visibility_plan = plan.clone();
            builder.record(move |pass, params| {
                plan_frame_into(pass, params)?;
                let push = push_for(pass, PASS_VISIBILITY, true)?;
                let triangles = triangle_handle(pass)?;
                let depth = pass.image(targets.depth)?;
                let plan = locked(&visibility_plan)?;
                let cmd = pass.cmd();
                cmd.begin_rendering(&[], Some((depth, depth_load)));
                if let (Some(pipeline), Some(handle)) = (&visibility_triangles, triangles) {
                    draw_triangles(cmd, pipeline, &plan, push, handle)?;
                }
                visibility.draw(cmd, &plan, primitive, push)?;
                cmd.end_rendering();
                Ok(())
            });

            let mut builder = graph
                .pass("points.accumulate")
                .graphics()
                .read(splats_id, Access::StorageBufferRead(Stage::Vertex))
                .read(frame_id, Access::StorageBufferRead(Stage::Graphics))
                .read(table_id, Access::StorageBufferRead(Stage::Fragment))
                .read(targets.depth, Access::DepthAttachmentRead)
                .write(color_weight, Access::ColorAttachmentWrite)
                .write(normal_depth, Access::ColorAttachmentWrite);
            if let Some(t) = triangles_id {
                builder = builder.read(t, Access::StorageBufferRead(Stage::Vertex));
            }
            builder.record(move |pass, _| {
                let push = push_for(pass, PASS_ACCUMULATE, false)?;
                let triangles = triangle_handle(pass)?;
                let (cw, nd, depth) = (
                    pass.image(color_weight)?,
                    pass.image(normal_depth)?,
                    pass.image(targets.depth)?,
                );
                let plan = locked(&plan)?;
                let cmd = pass.cmd();
                cmd.begin_rendering(
                    &[(cw, LoadOp::Clear([0.0; 4])), (nd, LoadOp::Clear([0.0; 4]))],
                    Some((depth, None)),
                );
                accumulate.draw(cmd, &plan, primitive, push)?;
                if let (Some(pipeline), Some(handle)) = (&accumulate_triangles, triangles) {
                    draw_triangles(cmd, pipeline, &plan, push, handle)?;
                }
                cmd.end_rendering();
                Ok(())
            });

            graph
                .pass("points.normalize")
                .graphics()
                .read(color_weight, Access::SampledImage(Stage::Fragment))
                .read(normal_depth, Access::SampledImage(Stage::Fragment))
                .read(frame_id, Access::StorageBufferRead(Stage::Fragment))
                .write(targets.radiance, Access::ColorAttachmentReadWrite)
                .write(targets.view_depth, Access::ColorAttachmentReadWrite)
                .write(targets.weight, Access::ColorAttachmentWrite)
                .record(move |pass, _| {
                    let push = SplatPush {
                        handles: [
                            pass.sampled(color_weight)?,
                            pass.storage_buffer(frame_id)?,
                            pass.sampled(normal_depth)?,
                            0,
                        ],
                        mode: [0; 4],
                    };
                    let (radiance, view_depth, weight) = (
                        pass.image(targets.radiance)?,
                        pass.image(targets.view_depth)?,
                        pass.image(targets.weight)?,
                    );
                    let cmd = pass.cmd();
                    cmd.begin_rendering(
                        &[
                            (radiance, LoadOp::Load),
                            (view_depth, LoadOp::Load),
                            (weight, LoadOp::Clear([0.0; 4])),
                        ],
                        None,
                    );
                    cmd.bind_graphics(&normalize);
                    cmd.push_constants(&push)?;
                    cmd.draw(3, 1);
                    cmd.end_rendering();
                    Ok(())
                });
        }
    }
    Ok(PointPasses {
        stats,
        _splats: splat_buffer,
        _triangles: triangle_buffer.map(|t| t.buffer),
    })
}
