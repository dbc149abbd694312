//! Point objects as a technique (dissertation §10.1.7, §10.2): the splat
//! lists on the GPU, the points passes of each view, and per frame, in
//! `prepare`, the CPU selection (frustum culling, prefix by binary search,
//! object→camera in f64) whose plan the passes draw.

use std::sync::Arc;
use std::time::Instant;

use super::compute::{declare_ewa_compute, TRIANGLE_FEATURE};
use super::compute_opaque::declare_opaque_compute;
use super::gpu_layout::{frame_header, gaussian_table, pack_nodes, FrameHeader, HEADER_BYTES, INSTANCE_BYTES};
use super::object_space::ObjectSpaceResources;
use super::passes::{declare_ewa, declare_opaque, PointBuffers, PointView};
use super::selection::{plan_frame_into, FramePlan, ObjectLayout};
use super::single_pass::{check_backend, declare_single_pass, entry_capacity, TileCapacity};
use super::stats::{PointFrameStats, StatsLog};
use super::triangles::TriangleBuffer;
use super::{SplatMode, SplatPrimitive, SplatSettings, SptError};
use crate::error::{Error, Result};
use crate::graph::UploadRegion;
use crate::points::build::clusters::{cluster_normals, CLUSTER_COUNT};
use crate::points::scene::PointScene;
use crate::view::deferred::{GroundKeys, SplatSums};
use crate::view::{
    pass_name, per_view, Declare, FrameContext, Provides, SceneTargets, Technique, ViewGraph, ViewIndex,
};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, MemoryLocation};

/// What the points passes read this frame: each view's plan.
pub struct PointsFrame {
    pub views: Vec<PointViewFrame>,
}

/// One view's prepared selection.
pub struct PointViewFrame {
    pub view: ViewIndex,
    /// The header of the view's point frame, but the heap handle of the
    /// lighting constants (the shading pass writes it; the instance records
    /// follow it in the upload region, written by `prepare`).
    pub header: FrameHeader,
    pub plan: FramePlan,
}

impl PointsFrame {
    /// The prepared plan of view `index`.
    pub fn view(&self, index: ViewIndex) -> Result<&PointViewFrame> {
        per_view(&self.views, index, |v| v.view)
            .ok_or_else(|| Error::Graph(format!("points: view {index} was not prepared")))
    }
}

/// The GPU buffers of the point objects, uploaded once.
struct PointResources {
    splats: Arc<Buffer>,
    /// The Gaussian lookup table.
    table: Arc<Buffer>,
    /// Drawn-splat counters per frame slot (None without vertexPipelineStoresAndAtomics).
    counters: Option<Vec<Arc<Buffer>>>,
    /// Hybrid triangles (§10.1.8), when the scene has any.
    triangles: Option<TriangleBuffer>,
    /// Kernel texture, vertices and indices of the object-space primitives (§10.3).
    object: Option<ObjectSpaceResources>,
}

/// The point objects of a scene: splat lists uploaded once, the points
/// passes of every view, and the per-frame selection in `prepare`.
pub struct PointRenderer {
    settings: SplatSettings,
    scene: PointScene,
    layouts: Vec<ObjectLayout>,
    max_point_size: f32,
    draws_per_instance: usize,
    resources: PointResources,
    buffers: Option<PointBuffers>,
    views: Vec<PointView>,
    stats: StatsLog,
    /// The previous frame's plans, reused ([`Technique::recycle`]).
    spare: Vec<PointViewFrame>,
    /// EWA and opaque splats drawn by compute passes ([`super::compute`],
    /// [`super::compute_opaque`]), not the hardware rasterizer.
    compute: bool,
}

impl PointRenderer {
    /// Whether the splats are drawn by compute passes (EWA and opaque on
    /// the compute path; single-pass splatting is compute either way).
    pub fn draws_in_compute(&self) -> bool {
        self.compute && matches!(self.settings.mode, SplatMode::Ewa | SplatMode::Opaque)
    }

    /// Uploads the splat lists of `scene` (re-derived for
    /// `settings.epsilon`, clustered when asked for); `compute`: draw EWA
    /// splats with compute passes (the compute raster path).
    pub fn new(ctx: &Context, scene: &PointScene, settings: SplatSettings, compute: bool) -> Result<PointRenderer> {
        settings.validate()?;
        if settings.mode == SplatMode::SinglePass {
            check_backend(ctx, settings.backend)?;
        }
        scene.validate()?;
        let mut scene = scene.clone();
        if let Some(epsilon) = settings.epsilon {
            for object in &mut scene.objects {
                *object = object.with_epsilon(epsilon)?;
            }
        }
        let triangles = TriangleBuffer::upload(ctx, &scene)?;
        let mut splats = Vec::with_capacity(scene.total_splats());
        let mut layouts = Vec::with_capacity(scene.objects.len());
        for (o, object) in scene.objects.iter().enumerate() {
            let first = u32::try_from(splats.len()).map_err(|_| Error::invalid("points", "too many splats"))?;
            let clusters = settings
                .normal_clusters
                .then(|| Arc::new(cluster_normals(&object.tree)));
            let view_dependent =
                (settings.error == SptError::ViewDependent).then_some((first, object.hybrid.is_some()));
            match &clusters {
                Some(c) => splats.extend(pack_nodes(&c.nodes, view_dependent)),
                None => splats.extend(pack_nodes(&object.tree.nodes, view_dependent)),
            }
            layouts.push(ObjectLayout {
                first,
                clusters,
                first_triangle: triangles.as_ref().map_or(0, |t| t.firsts[o]),
            });
        }
        if splats.len() > u32::MAX as usize / 6 {
            return Err(Error::invalid(
                "points",
                format!("{} splats exceed the limit", splats.len()),
            ));
        }
        let storage = BufferUsageFlags::STORAGE_BUFFER;
        // object-instanced reads the list as its per-instance vertex buffer.
        let splat_usage = match settings.primitive {
            SplatPrimitive::ObjectInstanced => storage | BufferUsageFlags::VERTEX_BUFFER,
            _ => storage,
        };
        let splat_buffer = Arc::new(Buffer::with_data(
            ctx,
            "splats",
            splat_usage,
            bytemuck::cast_slice(&splats),
        )?);
        let object = ObjectSpaceResources::upload(ctx, settings.primitive, &splats, settings.cutoff)?;
        let table = gaussian_table(settings.cutoff);
        let table = Arc::new(Buffer::with_data(
            ctx,
            "gaussian table",
            storage,
            bytemuck::cast_slice(&table),
        )?);
        let counters = match ctx.has_feature("vertexPipelineStoresAndAtomics") {
            true => Some(Buffer::per_frame(
                ctx,
                BufferDesc {
                    name: "splat counter".into(),
                    size: 32,
                    usage: storage,
                    location: MemoryLocation::CpuToGpu,
                },
            )?),
            false => None,
        };
        Ok(PointRenderer {
            draws_per_instance: if settings.normal_clusters { CLUSTER_COUNT } else { 1 },
            max_point_size: ctx.info().max_point_size,
            stats: StatsLog::new(counters.clone()),
            resources: PointResources {
                splats: splat_buffer,
                table,
                counters,
                triangles,
                object,
            },
            buffers: None,
            views: Vec::new(),
            settings,
            scene,
            layouts,
            spare: Vec::new(),
            compute,
        })
    }

    /// The error of the interval test (the shadow casters use the view's).
    pub(super) fn spt_error(&self) -> SptError {
        self.settings.error
    }

    /// The scene, where each object's list is, and the splat buffer: what
    /// `points.shadow` draws (`super::shadow`).
    pub(super) fn shadow_sources(&self) -> (&PointScene, &[ObjectLayout], &Arc<Buffer>) {
        (&self.scene, &self.layouts, &self.resources.splats)
    }

    /// Whether the splats' sums can be left to the ground's shading pass
    /// (`terrain.shade` on the compute path, issue 29): EWA splats on the
    /// compute path, with hybrid triangles only where they blend into the
    /// sums (their opaque fallback depth-tests with the hardware).
    pub fn sums_shaded_by_ground(&self, ctx: &Context) -> bool {
        let triangles_blend = self.resources.triangles.is_none() || ctx.has_feature(TRIANGLE_FEATURE);
        self.compute && self.settings.mode == SplatMode::Ewa && triangles_blend
    }

    /// The most splats a frame can plan: every instance's whole list.
    fn planned_splats(&self) -> u64 {
        let list = |i: &crate::points::scene::PointInstance| self.scene.objects[i.object].tree.nodes.len() as u64;
        self.scene.instances.iter().map(list).sum()
    }

    /// Statistics of every completed frame not yet taken (call after all
    /// frames completed).
    pub fn take_stats(&mut self) -> Result<Vec<PointFrameStats>> {
        self.stats.take_all_completed()
    }
}

/// The points passes of a view: its targets (W required), whether they
/// clear the depth buffer (no terrain drew into it) and the ground's
/// visibility keys (the compute path's, when its shading pass resolves the
/// splats: [`PointRenderer::sums_shaded_by_ground`]) in; out, in that
/// case, the splat sums for it.
impl<S: Provides<PointsFrame> + 'static> Declare<S> for PointRenderer {
    type Inputs<'a> = (&'a SceneTargets, bool, Option<GroundKeys>);
    type Outputs = Option<SplatSums>;

    /// Declares the points passes of view `index` into `targets` (W
    /// required): `points.visibility`, `points.accumulate`,
    /// `points.normalize` for EWA splats (no `points.normalize` when the
    /// ground's shading pass resolves them), `points.single_pass*` for
    /// single-pass splats (§10.4), or `points.opaque`.
    /// `clear_depth`: no terrain drew into the depth buffer.
    fn declare(
        &mut self,
        at: ViewGraph<'_, S>,
        (targets, clear_depth, ground): Self::Inputs<'_>,
    ) -> Result<Option<SplatSums>> {
        let (ctx, graph, index, view) = (at.ctx, at.graph, at.index, at.view);
        if ground.is_some() && !self.sums_shaded_by_ground(ctx) {
            return Err(Error::Graph(
                "points: handed the ground's visibility keys, but their splats are not resolved by the ground".into(),
            ));
        }
        if targets.width > 0xffff || targets.height > 0xffff {
            return Err(Error::invalid(
                "image size",
                "points passes support at most 65535 pixels per side",
            ));
        }
        let weight = targets
            .weight
            .ok_or_else(|| Error::Graph("points: the view's targets have no splat weight".into()))?;
        let buffers = *self.buffers.get_or_insert_with(|| {
            let PointResources {
                splats,
                table,
                counters,
                triangles,
                object,
            } = &self.resources;
            let splats = graph.import_buffer(splats.clone());
            PointBuffers {
                object: object.as_ref().map(|o| o.import(graph, splats)),
                splats,
                table: graph.import_buffer(table.clone()),
                counter: counters.as_ref().map(|c| graph.import_buffers_per_frame(c.clone())),
                triangles: triangles.as_ref().map(|t| graph.import_buffer(t.buffer.clone())),
                primitive: self.settings.primitive,
            }
        });
        let records = (self.scene.instances.len() * self.draws_per_instance).max(1) as u64;
        let point_view = PointView {
            index,
            frame: graph.upload_region(
                &pass_name("point frame", &view.name),
                HEADER_BYTES + INSTANCE_BYTES * records,
            ),
            radiance: targets.radiance,
            view_depth: targets.view_depth,
            depth: targets.depth,
            weight,
            visibility: targets.visibility,
            normal: targets.normal,
            ids: targets.ids,
            // With the ground's keys nothing drew into the depth buffer.
            clear_depth: clear_depth || ground.is_some(),
            draws: (self.draws_in_compute())
                .then(|| graph.upload_region(&pass_name("point draws", &view.name), 8 * records)),
        };
        let name = |base: &str| pass_name(base, &view.name);
        let mut sums = None;
        match self.settings.mode {
            SplatMode::Opaque if self.compute => {
                declare_opaque_compute(ctx, graph, &name, (buffers, point_view), targets)?
            }
            SplatMode::Opaque => {
                declare_opaque(ctx, graph, &name("points.opaque"), (buffers, point_view), targets, true)?
            }
            SplatMode::Ewa if self.compute => {
                sums = declare_ewa_compute(ctx, graph, &name, (buffers, point_view, ground), targets)?
            }
            SplatMode::Ewa => {
                let names = [
                    name("points.visibility"),
                    name("points.accumulate"),
                    name("points.normalize"),
                ];
                let names = [names[0].as_str(), names[1].as_str(), names[2].as_str()];
                declare_ewa(ctx, graph, names, (buffers, point_view), targets)?
            }
            SplatMode::SinglePass => declare_single_pass(
                ctx,
                graph,
                &name,
                (buffers, point_view),
                targets,
                (
                    self.settings.backend,
                    TileCapacity {
                        entries: entry_capacity(self.planned_splats(), ctx.max_storage_buffer_range()),
                        splats: self.planned_splats(),
                        draws: records,
                    },
                ),
            )?,
        }
        self.views.push(point_view);
        Ok(sums)
    }
}

impl Technique for PointRenderer {
    type Prepared = PointsFrame;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "points"
    }

    /// Per view: the prefix of every visible instance and its record
    /// (object→camera in f64), uploaded with the view's header; the frame's
    /// statistics (the GPU counts of the slot's previous frame are read now).
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<PointsFrame> {
        let started = Instant::now();
        let mut views = std::mem::take(&mut self.spare);
        let mut stats = PointFrameStats {
            frame: frame.index,
            ..PointFrameStats::default()
        };
        views.truncate(self.views.len());
        for (k, point_view) in self.views.iter().enumerate() {
            let view = frame
                .views
                .get(point_view.index)
                .ok_or_else(|| Error::Graph(format!("points: the frame has no view {}", point_view.index)))?;
            let camera = &view.camera;
            // The header's handle of the lighting constants is the shading
            // pass's to write (`ShadingBindings::write_header`).
            let (header, view_matrix) = frame_header(view, &self.settings, self.max_point_size);
            let view_proj = view.view_proj_f64();
            let pixel = 1.0 / view.intrinsics().fy;
            // The previous frame's plan of this view, reused in place.
            if views.len() <= k {
                views.push(PointViewFrame {
                    view: point_view.index,
                    header,
                    plan: FramePlan::default(),
                });
            }
            let slot = &mut views[k];
            slot.view = point_view.index;
            slot.header = header;
            let eye_view = (camera.eye, view_matrix, view_proj);
            plan_frame_into(&mut slot.plan, &self.scene, &self.layouts, eye_view, pixel);
            let plan = &slot.plan;
            frame
                .uploads
                .write_at(point_view.frame, HEADER_BYTES, bytemuck::cast_slice(&plan.records))?;
            if let Some(region) = point_view.draws {
                write_draw_table(frame, region, plan)?;
            }
            stats.instances = plan.instances;
            stats.instances_drawn += plan.instances_drawn;
            stats.list_splats += plan.list_splats;
            stats.prefix_splats += plan.prefix_splats;
            stats.prefix_triangles += plan.prefix_triangles;
        }
        stats.cpu_ms = started.elapsed().as_secs_f64() * 1e3;
        self.stats.begin_frame(stats)?;
        Ok(PointsFrame { views })
    }

    fn recycle(&mut self, previous: PointsFrame) {
        self.spare = previous.views;
    }
}

/// Writes the compute path's draw table of `plan` into `region`: per draw
/// its first splat counted over the view's draws and its instance record
/// (`g_splat_draws` in glsl/include/splat_compute.glsl).
fn write_draw_table(frame: &mut FrameContext<'_, '_>, region: UploadRegion, plan: &FramePlan) -> Result<()> {
    let mut first = 0u32;
    for (k, d) in plan.draws.iter().enumerate() {
        let entry = [first, d.record];
        frame
            .uploads
            .write_at(region, 8 * k as u64, bytemuck::cast_slice(&entry))?;
        first = first
            .checked_add(d.count)
            .ok_or_else(|| Error::invalid("points", "a view's splats exceed 2³² in one frame"))?;
    }
    Ok(())
}
