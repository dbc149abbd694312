//! `post.distortion` (§3.3: the cameras of a driving simulator; the images
//! a real camera would see): Brown–Conrady lens distortion (OpenCV's model
//! and convention, [`crate::view::lens::Distortion`]) as a resampling pass. The renderer renders the
//! view with the undistorted pinhole camera of [`source_intrinsics`]; the
//! pass makes every output pixel of the real camera from the render at the
//! pixel's ray, found once on the CPU by inverting the distortion (damped
//! Newton iterations, [`crate::view::lens::Distortion::undistort`]) and uploaded as a buffer
//! of source positions ([`SourceMap`]). Per image by its [`ImageKind`]:
//! Filtered bilinear, Exact the nearest texel, Motion the nearest texel with
//! its displacement carried into output pixels by the mapping's derivative
//! (F·J_D·F'⁻¹). Lenses that do not invert or fold over the image are
//! errors naming the coefficient. CPU twins: [`distortion_cpu`],
//! [`distortion_exact_cpu`]. Shader: `glsl/post/distortion.comp`.

pub mod lens;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

pub use lens::{source_intrinsics, source_map, DistortedCamera, SourceMap, SourceView};

#[cfg(test)]
use super::resample::{bilinear, ImageKind, Plane};
use super::resample::{check_images, declare_pass, ResampleImage};
#[cfg(test)]
use crate::error::Error;
use crate::error::Result;
use crate::graph::RenderGraph;
use crate::shaders;
use crate::view::pass_name;
use crate::vulkan::{Buffer, BufferUsageFlags, ComputePipeline, Context};

/// Push constants of `post.distortion` (`glsl/post/distortion.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct DistortionPush {
    /// Source (sampled), target (storage), map buffer, format code.
    handles: [u32; 4],
    /// Source width, height; target width, height.
    size: [u32; 4],
    /// Kind; pad.
    mode: [u32; 4],
    /// k1, k2, k3, p1.
    radial: [f32; 4],
    /// p2; pad.
    tangential: [f32; 4],
    /// fx', fy' of the source; pad.
    focal: [f32; 4],
    /// cx', cy' of the source; pad.
    centre: [f32; 4],
    /// fx/fx', fx/fy', fy/fx', fy/fy'.
    ratios: [f32; 4],
}

/// The lens parameters the shader (and its twin) use for motion, in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MotionLens {
    radial: [f32; 4],
    p2: f32,
    focal: [f32; 2],
    centre: [f32; 2],
    /// F·J·F'⁻¹ is J with its entries scaled by these (exactly 1 without
    /// distortion, so the identity carries motion bit for bit).
    ratios: [f32; 4],
}

impl MotionLens {
    fn new(camera: &DistortedCamera, source: &SourceView) -> MotionLens {
        let (l, k, s) = (camera.lens, camera.intrinsics, source.intrinsics);
        MotionLens {
            radial: [l.k1 as f32, l.k2 as f32, l.k3 as f32, l.p1 as f32],
            p2: l.p2 as f32,
            focal: [s.fx as f32, s.fy as f32],
            centre: [s.cx as f32, s.cy as f32],
            ratios: [k.fx / s.fx, k.fx / s.fy, k.fy / s.fx, k.fy / s.fy].map(|r| r as f32),
        }
    }

    /// The displacement `m` (source pixels) at source position `q`, in
    /// output pixels: the twin of `carry_motion` in the shader.
    #[cfg(test)]
    fn carry(&self, m: [f32; 2], q: [f32; 2]) -> [f32; 2] {
        let [k1, k2, k3, p1] = self.radial;
        let p2 = self.p2;
        let x = (q[0] - self.centre[0]) / self.focal[0];
        let y = (q[1] - self.centre[1]) / self.focal[1];
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        let slope = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3);
        let jxx = radial + 2.0 * x * x * slope + 2.0 * p1 * y + 6.0 * p2 * x;
        let jxy = 2.0 * x * y * slope + 2.0 * p1 * x + 2.0 * p2 * y;
        let jyy = radial + 2.0 * y * y * slope + 6.0 * p1 * y + 2.0 * p2 * x;
        let r = self.ratios;
        [
            jxx * r[0] * m[0] + jxy * r[1] * m[1],
            jxy * r[2] * m[0] + jyy * r[3] * m[1],
        ]
    }
}

/// Lens distortion of one camera: the source map (on the GPU and the CPU)
/// and a pipeline; one `post.distortion` pass per view of that camera.
pub struct LensDistortion {
    pipeline: Arc<ComputePipeline>,
    buffer: Arc<Buffer>,
    cpu: LensDistortionCpu,
}

impl LensDistortion {
    /// Inverts the distortion of `camera` for every output pixel into the
    /// render `source` (usually [`source_intrinsics`] of `camera`) and
    /// uploads the map; errors name the coefficient or the source view.
    pub fn new(ctx: &Context, camera: &DistortedCamera, source: &SourceView) -> Result<LensDistortion> {
        let cpu = LensDistortionCpu::new(camera, source)?;
        let buffer = Buffer::with_data(
            ctx,
            "post.distortion source map",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&cpu.map.positions),
        )?;
        Ok(LensDistortion {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::POST_DISTORTION)?),
            buffer: Arc::new(buffer),
            cpu,
        })
    }

    /// The CPU side: the real camera (the output), the undistorted render the
    /// pass samples, and the source position of every output pixel.
    pub fn cpu(&self) -> &LensDistortionCpu {
        &self.cpu
    }

    /// Declares `post.distortion` (`post.distortion@view` for a named view):
    /// every image's source (the undistorted render, `cpu().source`'s size,
    /// read sampled) into its target (`cpu().camera`'s size, written as a
    /// storage image), one dispatch per image.
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        view_name: &str,
        images: &[ResampleImage],
    ) -> Result<()> {
        let checked = check_images("post.distortion", images)?;
        let map = graph.import_buffer(self.buffer.clone());
        let (camera, source) = (&self.cpu.camera, &self.cpu.source);
        let lens = MotionLens::new(camera, source);
        let size = [source.width, source.height, camera.width, camera.height];
        let target = (camera.width, camera.height);
        let name = pass_name("post.distortion", view_name);
        declare_pass(
            graph,
            &name,
            self.pipeline.clone(),
            checked,
            &[map],
            target,
            move |image, h, buffers| {
                Ok(DistortionPush {
                    handles: [h[0], h[1], buffers[0], image.format],
                    size,
                    mode: [image.kind, 0, 0, 0],
                    radial: lens.radial,
                    tangential: [lens.p2, 0.0, 0.0, 0.0],
                    focal: [lens.focal[0], lens.focal[1], 0.0, 0.0],
                    centre: [lens.centre[0], lens.centre[1], 0.0, 0.0],
                    ratios: lens.ratios,
                })
            },
        );
        Ok(())
    }
}

/// The nearest texel to source position `q`.
#[cfg(test)]
fn nearest(q: [f32; 2]) -> (i64, i64) {
    ((q[0] + 0.5).floor() as i64, (q[1] + 0.5).floor() as i64)
}

/// The CPU twin of `post.distortion` for a float image of `kind`, sampled
/// where `distortion`'s map says (what the GPU must match to f32 rounding).
#[cfg(test)]
pub fn distortion_cpu(
    distortion: &LensDistortionCpu,
    source: &Plane<[f32; 4]>,
    kind: ImageKind,
) -> Result<Plane<[f32; 4]>> {
    let map = &distortion.map;
    check_planes(map, source)?;
    let lens = MotionLens::new(&distortion.camera, &distortion.source);
    Ok(Plane::from_fn(map.width, map.height, |i, j| {
        let q = map.positions[(j * map.width + i) as usize];
        let (x, y) = nearest(q);
        match kind {
            ImageKind::Filtered => bilinear(source, q),
            ImageKind::Exact => source.at(x, y),
            ImageKind::Motion => {
                let m = source.at(x, y);
                let [mx, my] = lens.carry([m[0], m[1]], q);
                [mx, my, m[2], m[3]]
            }
        }
    }))
}

/// A map with a position per pixel, a source with a texel per pixel.
#[cfg(test)]
fn check_planes<T: Copy>(map: &SourceMap, source: &Plane<T>) -> Result<()> {
    source.check("distortion source")?;
    if map.positions.len() != map.width as usize * map.height as usize {
        return Err(Error::invalid(
            "distortion map",
            format!("{} positions for {}×{}", map.positions.len(), map.width, map.height),
        ));
    }
    Ok(())
}

/// The CPU twin of `post.distortion` for an Exact image of any texel type.
#[cfg(test)]
pub fn distortion_exact_cpu<T: Copy>(map: &SourceMap, source: &Plane<T>) -> Result<Plane<T>> {
    check_planes(map, source)?;
    Ok(Plane::from_fn(map.width, map.height, |i, j| {
        let (x, y) = nearest(map.positions[(j * map.width + i) as usize]);
        source.at(x, y)
    }))
}

/// What the CPU twin needs of a lens distortion (no GPU).
#[derive(Clone, Debug, PartialEq)]
pub struct LensDistortionCpu {
    pub camera: DistortedCamera,
    pub source: SourceView,
    pub map: SourceMap,
}

impl LensDistortionCpu {
    /// The map of `camera` rendered from `source`.
    pub fn new(camera: &DistortedCamera, source: &SourceView) -> Result<LensDistortionCpu> {
        Ok(LensDistortionCpu {
            camera: *camera,
            source: *source,
            map: source_map(camera, source)?,
        })
    }
}

#[cfg(test)]
mod tests;
