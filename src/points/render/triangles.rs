//! The triangles of hybrid point–polygon objects (dissertation §10.1.8) in
//! the points passes: one buffer of every hybrid object's sorted triangle
//! list, and per pass a pipeline (`glsl/points/hybrid.vert` with the pass's
//! fragment stage) that draws each instance's CPU prefix by vertex pulling.
//! The vertex stage does the exact test `r < s/ε`; the CPU prefix comes from
//! [`super::selection::plan_frame_into`].

use std::sync::Arc;

use bytemuck::Pod;

use super::gpu_layout::{pack_triangles, GpuTriangle};
use super::passes::SplatPush;
use super::selection::FramePlan;
use crate::error::{Error, Result};
use crate::points::scene::PointScene;
use crate::vulkan::{Buffer, BufferUsageFlags, CommandRecorder, Context, GraphicsPipeline};

/// The hybrid triangles of a scene on the GPU.
pub(super) struct TriangleBuffer {
    pub buffer: Arc<Buffer>,
    /// Per object: index of its first triangle (0 for objects without).
    pub firsts: Vec<u32>,
}

impl TriangleBuffer {
    /// Uploads the triangles of `scene`'s hybrid objects; None when it has none.
    pub fn upload(ctx: &Context, scene: &PointScene) -> Result<Option<TriangleBuffer>> {
        if scene.objects.iter().all(|o| o.hybrid.is_none()) {
            return Ok(None);
        }
        let mut triangles: Vec<GpuTriangle> = Vec::new();
        let mut firsts = Vec::with_capacity(scene.objects.len());
        for object in &scene.objects {
            // Bounded by the check below: firsts never exceed the total.
            firsts.push(triangles.len() as u32);
            if let Some(hybrid) = &object.hybrid {
                triangles.extend(pack_triangles(hybrid, object.tree.epsilon));
            }
        }
        if triangles.is_empty() {
            return Ok(None);
        }
        if triangles.len() > (u32::MAX / 3) as usize {
            return Err(Error::invalid(
                "points",
                format!("{} hybrid triangles exceed the limit", triangles.len()),
            ));
        }
        let buffer = Arc::new(Buffer::with_data(
            ctx,
            "hybrid triangles",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&triangles),
        )?);
        Ok(Some(TriangleBuffer { buffer, firsts }))
    }
}

/// Records one triangle draw per planned hybrid instance with `pipeline`;
/// `push` is the pass's push constants, `triangles` the triangle buffer's
/// handle (it takes the splats' place).
pub(super) fn draw_triangles(
    cmd: &mut CommandRecorder,
    pipeline: &GraphicsPipeline,
    plan: &FramePlan,
    push: SplatPush,
    triangles: u32,
) -> Result<()> {
    draw_triangles_with(cmd, pipeline, plan, (push, |p| p), triangles)
}

/// As [`draw_triangles`] with push constants `P` that begin with the splat
/// passes' block (`splat` reaches it).
pub(super) fn draw_triangles_with<P: Pod>(
    cmd: &mut CommandRecorder,
    pipeline: &GraphicsPipeline,
    plan: &FramePlan,
    (mut push, splat): (P, fn(&mut P) -> &mut SplatPush),
    triangles: u32,
) -> Result<()> {
    if plan.triangle_draws.is_empty() {
        return Ok(());
    }
    cmd.bind_graphics(pipeline);
    splat(&mut push).splats = triangles;
    for d in &plan.triangle_draws {
        splat(&mut push).record = d.record;
        cmd.push_constants(&push)?;
        cmd.draw(d.count * 3, 1);
    }
    Ok(())
}
