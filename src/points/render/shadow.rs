//! `points.shadow`: the point objects (rocks, scans) as casters in the
//! view's cascaded shadow maps (§9.5; [`crate::lighting::shadows`]).
//!
//! Each splat of an instance's prefix (§10.1.7: r_lo from the view's eye,
//! so the shadow uses the level of detail the view draws) that passes the
//! interval test r_min ≤ r < r_max in the vertex stage becomes a depth-only
//! disc of its radius in its tangent plane: a quad of six pulled vertices
//! whose fragment stage discards outside the disc
//! (`glsl/lighting/shadow_points.vert`, `.frag`). Simplifications: the
//! splats' clip lines (sharp edges) are ignored, so edges cast slightly
//! rounder shadows; both faces cast; the triangles of hybrid objects
//! (§10.1.8) do not cast, their splats do. Instances whose bounding sphere
//! cannot reach any cascade's box are skipped ([`CascadePlan::may_cast`]),
//! and so are those the view thins ([`super::selection::keeps_instance`]).
//!
//! Instance records (object → world, in f32 world coordinates like the
//! terrain's vertices) go into one upload region per view, written in
//! `prepare`.
//!
//! On the compute path (the atlas has [`ShadowTarget::depths`]) the discs
//! are rasterized by a compute pass into the depth bits the terrain's
//! compute casters write, one dispatch a cascade for all the view's draws
//! (`glsl/lighting/shadow_points.comp`).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use super::selection::{keeps_instance, ObjectLayout};
use super::{PointRenderer, SptError};
use crate::error::{Error, Result};
use crate::graph::{stride_groups, BufferAccess, BufferId, RenderGraph, Stage, UploadRegion};
use crate::lighting::shadows::{
    cascade_pushes, plan_cascades, plan_cascades_into, record_cascades, splat_caster_desc, CascadePlan, SceneBounds,
    ShadowFrame, ShadowMaps, ShadowSettings, ShadowTarget,
};
use crate::points::scene::PointScene;
use crate::shaders;
use crate::view::{
    pass_name, per_view, Declare, Frame, FrameContext, Provides, ShadowMode, Technique, ViewGraph, ViewIndex,
};
use crate::vulkan::{Buffer, ComputePipeline, GraphicsPipeline};

/// Header of a view's shadow records (`ShadowPoints` in shadow_points.vert).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ShadowHeader {
    /// World eye position of the view; w: the interval test (u32 bits, [`SptError::code`]).
    eye: [f32; 4],
}

/// One caster record (`ShadowInstance` in shadow_points.vert).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ShadowInstance {
    /// Object → world, column-major.
    model: [f32; 16],
    /// Scale, first splat (u32 bits), prefix length (u32 bits), 0.
    params: [f32; 4],
}

const HEADER_BYTES: u64 = std::mem::size_of::<ShadowHeader>() as u64;
const RECORD_BYTES: u64 = std::mem::size_of::<ShadowInstance>() as u64;

/// One draw of `points.shadow`: record index and splats of its prefix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowDraw {
    pub record: u32,
    pub count: u32,
}

/// What `points.shadow` draws this frame, per view.
#[derive(Clone, Debug, Default)]
pub struct PointShadowFrame {
    pub views: Vec<(ViewIndex, Vec<ShadowDraw>)>,
}

impl PointShadowFrame {
    fn view(&self, index: ViewIndex) -> Result<&[ShadowDraw]> {
        per_view(&self.views, index, |(v, _)| *v)
            .map(|(_, d)| d.as_slice())
            .ok_or_else(|| Error::Graph(format!("points.shadow: view {index} was not prepared")))
    }
}

struct ShadowView {
    index: ViewIndex,
    region: UploadRegion,
}

/// The point objects as shadow casters: `points.shadow` per view and the
/// per-frame caster records in `prepare`.
pub struct PointShadows {
    scene: PointScene,
    layouts: Vec<ObjectLayout>,
    splats: Arc<Buffer>,
    splats_id: Option<BufferId>,
    settings: ShadowSettings,
    /// The views' interval test (the casters take the level of detail the view draws).
    error: SptError,
    bounds: SceneBounds,
    views: Vec<ShadowView>,
    /// Reused every frame (no allocation in steady state): the cascades
    /// being planned, the caster records, and the previous frame's draws.
    scratch_plan: Option<CascadePlan>,
    records: Vec<ShadowInstance>,
    spare: Vec<(ViewIndex, Vec<ShadowDraw>)>,
}

/// The box around every instance's bounding sphere, or None without instances.
pub fn scene_bounds(scene: &PointScene) -> Option<SceneBounds> {
    scene
        .instances
        .iter()
        .map(|inst| {
            let tree = &scene.objects[inst.object].tree;
            let centre = inst.transform.matrix().transform_point3(tree.bounds_centre.as_dvec3());
            let r = DVec3::splat(f64::from(tree.bounds_radius) * inst.transform.scale);
            SceneBounds {
                min: centre - r,
                max: centre + r,
            }
        })
        .reduce(SceneBounds::union)
}

impl PointShadows {
    /// Casters of `renderer`'s objects into the atlases of `shadows` (same
    /// settings and bounds, so the culling matches its cascades).
    pub fn new(renderer: &PointRenderer, shadows: &ShadowMaps) -> PointShadows {
        let (scene, layouts, splats) = renderer.shadow_sources();
        PointShadows {
            scene: scene.clone(),
            layouts: layouts.to_vec(),
            splats: splats.clone(),
            splats_id: None,
            settings: *shadows.settings(),
            error: renderer.spt_error(),
            bounds: shadows.bounds(),
            views: Vec::new(),
            scratch_plan: None,
            records: Vec::new(),
            spare: Vec::new(),
        }
    }

    /// The box around the instances (for [`ShadowMaps::new`]).
    pub fn bounds(renderer: &PointRenderer) -> Option<SceneBounds> {
        scene_bounds(renderer.shadow_sources().0)
    }

    fn records_per_instance(&self) -> usize {
        self.layouts
            .iter()
            .map(|l| l.clusters.as_ref().map_or(1, |c| c.clusters.len()))
            .max()
            .unwrap_or(1)
    }

    /// The caster records of one view for `plan`, and its draws.
    /// (`pixel`: the view's pixel width at unit distance, for thinning.)
    fn plan_view(
        &self,
        eye: DVec3,
        plan: &CascadePlan,
        pixel: f64,
        (records, draws): (&mut Vec<ShadowInstance>, &mut Vec<ShadowDraw>),
    ) {
        records.clear();
        draws.clear();
        if plan.count() == 0 {
            return;
        }
        for (index, inst) in self.scene.instances.iter().enumerate() {
            let object = &self.scene.objects[inst.object];
            let tree = &object.tree;
            let layout = &self.layouts[inst.object];
            let model = inst.transform.matrix();
            let scale = inst.transform.scale;
            let centre = model.transform_point3(tree.bounds_centre.as_dvec3());
            let radius = f64::from(tree.bounds_radius) * scale;
            if !plan.may_cast(centre, radius) || !keeps_instance(object, index, (eye - centre).length() / scale, pixel)
            {
                continue;
            }
            let r_lo = ((((eye - centre).length() - radius) / scale).max(0.0)) as f32;
            let model = model.as_mat4().to_cols_array();
            let mut push = |first: u32, count: usize| {
                if count == 0 {
                    return;
                }
                draws.push(ShadowDraw {
                    record: records.len() as u32,
                    count: count as u32,
                });
                records.push(ShadowInstance {
                    model,
                    params: [scale as f32, f32::from_bits(first), f32::from_bits(count as u32), 0.0],
                });
            };
            match &layout.clusters {
                None => push(layout.first, tree.prefix_len(r_lo)),
                Some(c) => {
                    for (k, cl) in c.clusters.iter().enumerate() {
                        push(layout.first + cl.first, c.cluster_prefix_len(k, r_lo));
                    }
                }
            }
        }
    }
}

/// `points.shadow` of a view: its shadow atlas in, nothing out.
impl<S: Provides<ShadowFrame> + Provides<PointShadowFrame> + 'static> Declare<S> for PointShadows {
    type Inputs<'a> = ShadowTarget;
    type Outputs = ();

    /// Declares `points.shadow` of view `index` into `target` (after
    /// `shadow.clear`; the cascades come from the frame's [`ShadowFrame`]).
    fn declare(&mut self, at: ViewGraph<'_, S>, target: ShadowTarget) -> Result<()> {
        let (ctx, graph, index, view) = (at.ctx, at.graph, at.index, at.view);
        let splats = *self
            .splats_id
            .get_or_insert_with(|| graph.import_buffer(self.splats.clone()));
        let records = (self.scene.instances.len() * self.records_per_instance()).max(1) as u64;
        let region = graph.upload_region(
            &pass_name("point shadow casters", &view.name),
            HEADER_BYTES + RECORD_BYTES * records,
        );
        let name = pass_name("points.shadow", &view.name);
        if let Some(depths) = target.depths {
            let pipeline = ComputePipeline::new(ctx, shaders::SHADOW_POINTS_COMPUTE)?;
            let table = graph.upload_region(&pass_name("point shadow draws", &view.name), 8 * records);
            declare_compute(
                graph,
                &name,
                (index, target.size),
                (splats, region, table, depths),
                pipeline,
            );
            self.views.push(ShadowView { index, region });
            return Ok(());
        }
        let pipeline = GraphicsPipeline::new(ctx, &splat_caster_desc("points.shadow"))?;
        let atlas = target.atlas;
        let mut pass = graph.pass(&name).graphics();
        let handles = [
            pass.storage_buffer(splats, BufferAccess::StorageRead(Stage::Vertex)),
            pass.upload(region, Stage::Vertex),
        ];
        pass.pipeline(&pipeline).depth(atlas, None).record(move |ctx, frame| {
            let plan = frame.prepared::<ShadowFrame>()?.view(index)?;
            let draws = frame.prepared::<PointShadowFrame>()?.view(index)?;
            if draws.is_empty() {
                return Ok(());
            }
            let handles = [ctx.handle(handles[0])?, ctx.handle(handles[1])?];
            record_cascades(ctx.cmd(), plan, |cmd, mut push| {
                cmd.bind_graphics(&pipeline);
                for d in draws {
                    push.handles = [handles[0], handles[1], d.record, 0];
                    cmd.push_constants(&push)?;
                    cmd.draw(d.count * 6, 1);
                }
                Ok(())
            })
        });
        self.views.push(ShadowView { index, region });
        Ok(())
    }
}

/// Push constants of the compute path's `points.shadow` (`Push` in
/// glsl/lighting/shadow_points.comp).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ComputeCasterPush {
    view_proj: [f32; 16],
    sun_texel: [f32; 4],
    /// Splats, shadow records, depth bits, draw table.
    handles: [u32; 4],
    /// Draws, splats, atlas side, 0.
    counts: [u32; 4],
    /// The cascade's receivers' texel box (first x, y, last x, y).
    receivers: [u32; 4],
}

/// `points.shadow` on the compute path: per cascade one dispatch over every
/// splat of the view's draws, rasterizing the splats' discs into the
/// atlas's depth bits (`glsl/lighting/shadow_points.comp`); the draw table
/// (each draw's first splat counted over the draws, and its record) is
/// written while recording, from the prepared draws.
fn declare_compute<S: Provides<ShadowFrame> + Provides<PointShadowFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (index, side): (ViewIndex, u32),
    (splats, records, table, depths): (BufferId, UploadRegion, UploadRegion, BufferId),
    pipeline: ComputePipeline,
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bindings = [
        pass.storage_buffer(splats, BufferAccess::StorageRead(compute)),
        pass.upload(records, compute),
        pass.storage_buffer(depths, BufferAccess::StorageReadWrite(compute)),
        pass.upload(table, compute),
    ];
    pass.record(move |ctx, frame| {
        let plan = frame.prepared::<ShadowFrame>()?.view(index)?;
        let draws = frame.prepared::<PointShadowFrame>()?.view(index)?;
        let mut first = 0u32;
        for (k, d) in draws.iter().enumerate() {
            ctx.write_upload_at(bindings[3], 8 * k as u64, bytemuck::cast_slice(&[first, d.record]))?;
            first = (first.checked_add(d.count))
                .ok_or_else(|| Error::invalid("points", "a view's shadow casters exceed 2³² splats"))?;
        }
        if first == 0 {
            return Ok(());
        }
        let handles = [
            ctx.handle(bindings[0])?,
            ctx.handle(bindings[1])?,
            ctx.handle(bindings[2])?,
            ctx.handle(bindings[3])?,
        ];
        for (_, receivers, push) in cascade_pushes(plan) {
            let push = ComputeCasterPush {
                view_proj: push.view_proj,
                sun_texel: push.sun_texel,
                handles,
                counts: [draws.len() as u32, first, side, 0],
                receivers,
            };
            ctx.dispatch(&pipeline, &push, [stride_groups(first, 64), 1, 1])?;
        }
        Ok(())
    });
}

impl Technique for PointShadows {
    type Prepared = PointShadowFrame;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "points.shadow"
    }

    /// Per view: the cascades (as [`ShadowMaps`] plans them), the instances
    /// that can cast into them and their prefixes, uploaded as records.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<PointShadowFrame> {
        let mut views = std::mem::take(&mut self.spare);
        views.truncate(self.views.len());
        let mut records = std::mem::take(&mut self.records);
        for (k, v) in self.views.iter().enumerate() {
            let view = frame
                .views
                .get(v.index)
                .ok_or_else(|| Error::Graph(format!("points.shadow: the frame has no view {}", v.index)))?;
            let sun = frame.lighting.sun;
            if views.len() <= k {
                views.push((v.index, Vec::new()));
            }
            let (index, draws) = &mut views[k];
            *index = v.index;
            records.clear();
            draws.clear();
            if frame.lighting.shadows == ShadowMode::Cascaded {
                let camera = view.culling_camera();
                let (aspect, bounds) = (view.culling_aspect(), self.bounds);
                let mut plan = match self.scratch_plan.take() {
                    Some(mut plan) => {
                        plan_cascades_into(&mut plan, (&camera, aspect), sun, bounds, &self.settings)?;
                        plan
                    }
                    None => plan_cascades(&camera, aspect, sun, bounds, &self.settings)?,
                };
                self.plan_view(
                    view.camera.eye,
                    &plan,
                    1.0 / view.intrinsics().fy,
                    (&mut records, draws),
                );
                plan.cascades.clear();
                self.scratch_plan = Some(plan);
            }
            let header = ShadowHeader {
                eye: view
                    .camera
                    .eye
                    .as_vec3()
                    .extend(f32::from_bits(self.error.code()))
                    .to_array(),
            };
            frame.uploads.write_pod(v.region, &header)?;
            if !records.is_empty() {
                frame
                    .uploads
                    .write_at(v.region, HEADER_BYTES, bytemuck::cast_slice(&records))?;
            }
        }
        self.records = records;
        Ok(PointShadowFrame { views })
    }

    fn recycle(&mut self, previous: PointShadowFrame) {
        self.spare = previous.views;
    }
}
