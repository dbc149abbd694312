//! `aovs`: the simulator AOVs that follow from a view's depth and its
//! cameras (`crate::view::aov`), one full-screen pass per view after every
//! pass that writes view depth. The scene is static, so the surface point
//! seen through pixel p is `X = eye + ray(p)·depth` (ray through the pixel
//! centre with `ray·forward = 1`, depth along the forward axis, the ray
//! basis of `sky`), and
//!
//! * `distance = |ray|·depth`: Euclidean metres from the eye, +inf for sky;
//! * `motion = p − project(previous view_proj, X)`: where the same surface
//!   point was in the previous frame, in pixels (+x right, +y down); sky
//!   pixels project the direction at infinity (`(ray, 0)`), so only the
//!   rotation moves them; 0 on a view's first frame, for a camera that did
//!   not move, and where the point was behind the previous camera.
//!
//! The technique keeps each view's previous world → clip transform across
//! frames in `prepare` and uploads the per-view constants: the ray basis
//! and the previous transform composed with a translation to this frame's
//! eye, in f64 and rounded once, so `X − eye` (metres, not kilometres)
//! enters the shader. A compute pass, one invocation a pixel (issue 28:
//! full-screen work as compute). Shader: `glsl/post/aovs.comp`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DMat4;

use crate::error::{Error, Result};
use crate::graph::{ImageAccess, Stage, UploadRegion};
use crate::shaders;
use crate::view::{pass_name, Declare, FrameContext, SceneTargets, Technique, View, ViewGraph, ViewIndex};
use crate::vulkan::{ComputePipeline, Context};

/// Per-view constants of `aovs` (`AovConstants` in glsl/post/aovs.frag).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct AovConstants {
    /// Camera right · tan(fov_x / 2).
    pub right: [f32; 4],
    /// Image up · tan(fov_y / 2).
    pub up: [f32; 4],
    /// Unit forward axis.
    pub forward: [f32; 4],
    /// The previous frame's world → clip after a translation by this
    /// frame's eye (column-major): maps `X − eye` to the previous clip space.
    pub previous: [f32; 16],
    /// Width, height, 1 when there is a previous frame (else motion is 0), 0.
    pub size: [f32; 4],
}

/// Bytes of [`AovConstants`].
pub const AOV_CONSTANTS_BYTES: u64 = std::mem::size_of::<AovConstants>() as u64;

/// The constants of a `width`×`height` view of `camera` whose previous
/// frame had the world → clip transform `previous` (None: its first frame;
/// the same transform as this frame's: a still camera, motion exactly 0).
pub fn aov_constants(view: &View, previous: Option<DMat4>) -> AovConstants {
    let (camera, width, height) = (&view.camera, view.width, view.height);
    let previous = previous.filter(|&p| p != view.view_proj_f64());
    let (right, up, forward) = view.ray_basis();
    let relative = previous.map_or(DMat4::IDENTITY, |p| p * DMat4::from_translation(camera.eye));
    AovConstants {
        right: right.extend(0.0).to_array(),
        up: up.extend(0.0).to_array(),
        forward: forward.extend(0.0).to_array(),
        previous: relative.as_mat4().to_cols_array(),
        size: [width as f32, height as f32, previous.map_or(0.0, |_| 1.0), 0.0],
    }
}

/// Push constants of `aovs`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct AovPush {
    /// Sampled handle of the view depth.
    depth: u32,
    /// Storage handle of the view's constants.
    constants: u32,
    /// Storage handles of motion and distance.
    motion: u32,
    distance: u32,
    /// The targets' size.
    width: u32,
    height: u32,
    _pad: [u32; 2],
}

/// One view's `aovs` pass: its index and constants.
#[derive(Clone, Copy, Debug)]
struct AovView {
    index: ViewIndex,
    constants: UploadRegion,
}

/// What the `aovs` passes read this frame: which views have motion (a
/// previous frame).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AovsFrame {
    pub with_motion: Vec<bool>,
}

/// The depth-derived AOVs: a pipeline, one pass per view, and each view's
/// previous camera transform.
pub struct Aovs {
    pipeline: Arc<ComputePipeline>,
    views: Vec<AovView>,
    previous: Vec<Option<DMat4>>,
    /// The previous frame's prepared data, reused ([`Technique::recycle`]).
    spare: Vec<bool>,
}

impl Aovs {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<Aovs> {
        Ok(Aovs {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::AOVS)?),
            views: Vec::new(),
            previous: Vec::new(),
            spare: Vec::new(),
        })
    }

    /// Forgets every view's previous camera: the next frame's motion is 0
    /// (a cut, or a camera that jumped).
    pub fn reset(&mut self) {
        self.previous.iter_mut().for_each(|p| *p = None);
    }
}

/// `aovs` of a view: its targets in, nothing out.
impl<S: 'static> Declare<S> for Aovs {
    type Inputs<'a> = &'a SceneTargets;
    type Outputs = ();

    /// Declares `aovs` for view `index`: reads its view depth, writes its
    /// motion and distance.
    fn declare(&mut self, at: ViewGraph<'_, S>, targets: &SceneTargets) -> Result<()> {
        let ViewGraph { graph, index, view, .. } = at;
        let constants = graph.upload_region(&pass_name("aov constants", &view.name), AOV_CONSTANTS_BYTES);
        let pipeline = self.pipeline.clone();
        let compute = Stage::Compute;
        let mut pass = graph.pass(&pass_name("aovs", &view.name));
        let depth = pass.sample(targets.view_depth, compute);
        let constants_binding = pass.upload(constants, compute);
        let motion = pass.storage_image(targets.motion, ImageAccess::StorageWrite(compute));
        let distance = pass.storage_image(targets.distance, ImageAccess::StorageWrite(compute));
        let (width, height) = (targets.width, targets.height);
        pass.record(move |ctx, _| {
            let push = AovPush {
                depth: ctx.handle(depth)?,
                constants: ctx.handle(constants_binding)?,
                motion: ctx.handle(motion)?,
                distance: ctx.handle(distance)?,
                width,
                height,
                _pad: [0; 2],
            };
            ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
        });
        self.views.push(AovView { index, constants });
        self.previous.push(None);
        Ok(())
    }
}

impl Technique for Aovs {
    type Prepared = AovsFrame;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "aovs"
    }

    /// Per view: the constants from this frame's camera and the previous
    /// frame's transform, then this frame's transform kept for the next.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<AovsFrame> {
        let mut with_motion = std::mem::take(&mut self.spare);
        with_motion.clear();
        for (view, previous) in self.views.iter().zip(&mut self.previous) {
            let v = frame
                .views
                .get(view.index)
                .ok_or_else(|| Error::Graph(format!("aovs: the frame has no view {}", view.index)))?;
            let constants = aov_constants(v, *previous);
            frame.uploads.write_pod(view.constants, &constants)?;
            with_motion.push(previous.is_some());
            *previous = Some(v.view_proj_f64());
        }
        Ok(AovsFrame { with_motion })
    }

    fn recycle(&mut self, previous: AovsFrame) {
        self.spare = previous.with_motion;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::Camera;
    use glam::{DVec3, DVec4};

    fn camera(eye: DVec3) -> Camera {
        Camera {
            eye,
            target: DVec3::new(5000.0, 5000.0, 100.0),
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 1.0,
            far: 50000.0,
        }
    }

    /// The shader's arithmetic on the constants (f32 as there), for one pixel.
    fn motion_of(c: &AovConstants, pixel: (f32, f32), depth: f32) -> (f32, f32) {
        let v = |a: [f32; 4]| glam::Vec3::new(a[0], a[1], a[2]);
        let (w, h) = (c.size[0], c.size[1]);
        let ndc = (pixel.0 / w * 2.0 - 1.0, pixel.1 / h * 2.0 - 1.0);
        let ray = v(c.forward) + ndc.0 * v(c.right) - ndc.1 * v(c.up);
        let clip = glam::Mat4::from_cols_array(&c.previous) * (ray * depth).extend(1.0);
        let before = ((clip.x / clip.w * 0.5 + 0.5) * w, (clip.y / clip.w * 0.5 + 0.5) * h);
        (pixel.0 - before.0, pixel.1 - before.1)
    }

    #[test]
    fn motion_is_the_pixel_minus_the_previous_projection() {
        let (w, h) = (320u32, 200u32);
        let (now, before) = (
            camera(DVec3::new(100.0, -300.0, 900.0)),
            camera(DVec3::new(80.0, -310.0, 905.0)),
        );
        let aspect = f64::from(w) / f64::from(h);
        let c = aov_constants(&View::new(now, w, h), Some(before.view_proj_f64(aspect)));
        assert_eq!(c.size[2], 1.0);
        // A world point seen by both cameras: its pixels in each, in f64.
        let x = DVec3::new(3000.0, 4200.0, 150.0);
        let pixel = |cam: &Camera| {
            let clip = cam.view_proj_f64(aspect) * DVec4::new(x.x, x.y, x.z, 1.0);
            (
                (clip.x / clip.w * 0.5 + 0.5) * f64::from(w),
                (clip.y / clip.w * 0.5 + 0.5) * f64::from(h),
            )
        };
        let (p, q) = (pixel(&now), pixel(&before));
        let depth = (x - now.eye).dot(now.forward());
        let m = motion_of(&c, (p.0 as f32, p.1 as f32), depth as f32);
        assert!(
            (f64::from(m.0) - (p.0 - q.0)).abs() < 1e-2,
            "{m:?} vs {:?}",
            (p.0 - q.0, p.1 - q.1)
        );
        assert!(
            (f64::from(m.1) - (p.1 - q.1)).abs() < 1e-2,
            "{m:?} vs {:?}",
            (p.0 - q.0, p.1 - q.1)
        );
        // The same camera twice: no motion at all.
        assert_eq!(
            aov_constants(&View::new(now, w, h), Some(now.view_proj_f64(aspect))).size[2],
            0.0
        );
        assert_eq!(aov_constants(&View::new(now, w, h), None).size[2], 0.0);
    }
}
