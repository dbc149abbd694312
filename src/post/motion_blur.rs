//! `post.motion_blur` (§3.3: "mainly motion blur is important" for the
//! perception of speed in a driving simulator): velocity-based,
//! deterministic motion blur of a view's radiance, a simplified form of
//! McGuire et al. 2012, "A reconstruction filter for plausible motion blur".
//!
//! Per pixel X with blur vector v_X = motion·shutter/dt (the motion AOV in
//! pixels, previous → current frame; clamped to `max_length_px`), N fixed
//! stratified samples Y = X + t·v_X, t = (i + ½)/N − ½ (no jitter: frames
//! are deterministic), each the bilinear footprint of four texels T, each
//! texel weighted by its bilinear weight times its own depth test (so no
//! colour crosses a depth edge by interpolation). With d = |t|·|v_X| the
//! distance of Y from X:
//!
//! * behind = clamp((z_T − z_X)/(0.05·z_X), 0, 1) where z_T > z_X (relative
//!   soft depth comparison: view depth spans metres to kilometres; +inf sky);
//! * reach = clamp(|v_T|/2 + 1 − d, 0, 1): T's own blur covers X;
//! * w = bilinear weight · (behind + (1 − behind)·reach).
//!
//! A sample behind X counts fully (X is blurred over it, so it shows
//! through); a sample in front of or level with X only as far as its own
//! blur reaches X, so a sharp foreground is not smeared over a moving
//! background. Uniform motion at one depth weights all samples equally: a
//! box blur of length |v|, as a camera shutter gives.
//!
//! Simplified from McGuire et al.: no tile maximum and neighbourhood
//! maximum velocity (samples follow the pixel's own velocity, so a moving
//! object's blur does not spread past its silhouette over a static
//! background; in a driving simulator the camera's motion moves every
//! pixel), cylinder-like reach instead of cone weights (no 1/|v| energy
//! terms: a uniform region blurs to the exact box), the centre pixel not
//! given a separate weight, no jitter. The result is the weighted mean;
//! zero motion leaves the pixel bit for bit. Shader:
//! `glsl/post/motion_blur.comp`; CPU twin [`motion_blur_cpu`].

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::resample::check_size;
#[cfg(test)]
use super::resample::{add_weighted, Plane};
use crate::error::{Error, Result};
use crate::graph::{ImageAccess, ImageId, RenderGraph, Stage};
use crate::shaders;
use crate::view::pass_name;
use crate::vulkan::{ComputePipeline, Context};

/// The relative depth difference over which a sample goes from "level with"
/// to "behind" the pixel.
pub const SOFT_DEPTH: f32 = 0.05;

/// Shutter, frame interval and sampling of the blur.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionBlurSettings {
    /// Exposure time in seconds (`--shutter`); 0 turns the blur off.
    pub shutter_s: f32,
    /// Time between frames in seconds (the motion AOV spans one interval).
    pub frame_interval_s: f32,
    /// Samples per pixel along the blur, 1 to 64.
    pub samples: u32,
    /// Longest blur in pixels (longer blur vectors are shortened).
    pub max_length_px: f32,
}

impl Default for MotionBlurSettings {
    /// A half-open shutter (180°) at 60 Hz, 16 samples, at most 64 pixels.
    fn default() -> Self {
        MotionBlurSettings {
            shutter_s: 1.0 / 120.0,
            frame_interval_s: 1.0 / 60.0,
            samples: 16,
            max_length_px: 64.0,
        }
    }
}

impl MotionBlurSettings {
    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<()> {
        if !(self.frame_interval_s.is_finite() && self.frame_interval_s > 0.0) {
            return Err(Error::invalid(
                "motion_blur.frame_interval_s",
                format!("{}; must be positive", self.frame_interval_s),
            ));
        }
        if !(self.shutter_s >= 0.0 && self.shutter_s <= self.frame_interval_s) {
            return Err(Error::invalid(
                "shutter",
                format!(
                    "{} s; must be from 0 to the frame interval ({} s)",
                    self.shutter_s, self.frame_interval_s
                ),
            ));
        }
        if !(1..=64).contains(&self.samples) {
            return Err(Error::invalid(
                "motion_blur.samples",
                format!("{}; must be in 1..=64", self.samples),
            ));
        }
        if !(self.max_length_px.is_finite() && self.max_length_px >= 0.0) {
            return Err(Error::invalid(
                "motion_blur.max_length_px",
                format!("{}; must be finite and not negative", self.max_length_px),
            ));
        }
        Ok(())
    }

    /// Blur per pixel of motion: shutter / frame interval.
    fn factor(&self) -> f32 {
        self.shutter_s / self.frame_interval_s
    }
}

/// The images of one view the blur reads and writes, all `width`×`height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionBlurImages {
    pub width: u32,
    pub height: u32,
    /// Linear radiance, RGBA32F (read sampled).
    pub radiance: ImageId,
    /// View depth, R32F, +inf for sky (read sampled).
    pub depth: ImageId,
    /// Motion, R32G32F, pixels previous → current (read sampled).
    pub motion: ImageId,
    /// The blurred radiance, RGBA32F (written as a storage image).
    pub output: ImageId,
}

/// Push constants of `post.motion_blur` (`glsl/post/motion_blur.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MotionBlurPush {
    /// Sampled: radiance, depth, motion; storage: output.
    handles: [u32; 4],
    /// Width, height, samples; pad.
    size: [u32; 4],
    /// Shutter / frame interval, maximum length, soft depth extent; pad.
    params: [f32; 4],
}

/// Motion blur: a pipeline, and one `post.motion_blur` pass per view.
pub struct MotionBlur {
    pipeline: Arc<ComputePipeline>,
}

impl MotionBlur {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<MotionBlur> {
        Ok(MotionBlur {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::POST_MOTION_BLUR)?),
        })
    }

    /// Declares `post.motion_blur` (`post.motion_blur@view` for a named
    /// view): reads `images`' radiance, depth and motion, writes its output.
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        view_name: &str,
        images: &MotionBlurImages,
        settings: &MotionBlurSettings,
    ) -> Result<()> {
        settings.check()?;
        check_size("motion_blur size", (images.width, images.height))?;
        let read = [images.radiance, images.depth, images.motion];
        if read.contains(&images.output) {
            return Err(Error::invalid(
                "motion_blur output",
                "it is also one of the images the blur reads",
            ));
        }
        let pipeline = self.pipeline.clone();
        let i = *images;
        let params = [settings.factor(), settings.max_length_px, SOFT_DEPTH, 0.0];
        let samples = settings.samples;
        let mut pass = graph.pass(&pass_name("post.motion_blur", view_name));
        let [radiance, depth, motion] = read.map(|image| pass.sample(image, Stage::Compute));
        let output = pass.storage_image(i.output, ImageAccess::StorageWrite(Stage::Compute));
        pass.record(move |ctx, _| {
            let push = MotionBlurPush {
                handles: [
                    ctx.handle(radiance)?,
                    ctx.handle(depth)?,
                    ctx.handle(motion)?,
                    ctx.handle(output)?,
                ],
                size: [i.width, i.height, samples, 0],
                params,
            };
            ctx.dispatch(&pipeline, &push, [i.width.div_ceil(8), i.height.div_ceil(8), 1])
        });
        Ok(())
    }
}

/// The CPU twin of `post.motion_blur` (what the GPU must match to f32
/// rounding): radiance, depth (x) and motion (x, y) as float planes of one size.
#[cfg(test)]
pub fn motion_blur_cpu(
    radiance: &Plane<[f32; 4]>,
    depth: &Plane<[f32; 4]>,
    motion: &Plane<[f32; 4]>,
    settings: &MotionBlurSettings,
) -> Result<Plane<[f32; 4]>> {
    settings.check()?;
    radiance.check("motion_blur radiance")?;
    depth.check("motion_blur depth")?;
    motion.check("motion_blur motion")?;
    let (w, h) = (radiance.width, radiance.height);
    if (depth.width, depth.height) != (w, h) || (motion.width, motion.height) != (w, h) {
        return Err(Error::invalid(
            "motion_blur size",
            "radiance, depth and motion differ in size",
        ));
    }
    let (factor, max_length) = (settings.factor(), settings.max_length_px);
    let blur_of = |x: i64, y: i64| {
        let m = motion.at(x, y);
        let v = [m[0] * factor, m[1] * factor];
        let len = (v[0] * v[0] + v[1] * v[1]).sqrt();
        if len > max_length {
            let s = max_length / len;
            [v[0] * s, v[1] * s]
        } else {
            v
        }
    };
    let length = |v: [f32; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
    let n = settings.samples;
    Ok(Plane::from_fn(w, h, |px, py| {
        let (x, y) = (i64::from(px), i64::from(py));
        let centre = radiance.at(x, y);
        let v = blur_of(x, y);
        let len = length(v);
        if len == 0.0 {
            return centre;
        }
        let zx = depth.at(x, y)[0];
        let (mut sum, mut total) = ([0.0f32; 4], 0.0f32);
        for i in 0..n {
            let t = (i as f32 + 0.5) / n as f32 - 0.5;
            let p = [
                (px as f32 + 0.5 + t * v[0]).clamp(0.5, w as f32 - 0.5),
                (py as f32 + 0.5 + t * v[1]).clamp(0.5, h as f32 - 0.5),
            ];
            let d = t.abs() * len;
            let q = [p[0] - 0.5, p[1] - 0.5];
            let f = [q[0].floor(), q[1].floor()];
            let s = [q[0] - f[0], q[1] - f[1]];
            for dy in 0..2 {
                for dx in 0..2 {
                    let b = if dx == 0 { 1.0 - s[0] } else { s[0] } * if dy == 0 { 1.0 - s[1] } else { s[1] };
                    if b > 0.0 {
                        let (tx, ty) = (f[0] as i64 + dx, f[1] as i64 + dy);
                        let zy = depth.at(tx, ty)[0];
                        let behind = if zy > zx {
                            ((zy - zx) / (SOFT_DEPTH * zx)).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        let reach = (0.5 * length(blur_of(tx, ty)) + 1.0 - d).clamp(0.0, 1.0);
                        let weight = b * (behind + (1.0 - behind) * reach);
                        if weight > 0.0 {
                            add_weighted(&mut sum, weight, radiance.at(tx, ty));
                            total += weight;
                        }
                    }
                }
            }
        }
        if total > 0.0 {
            sum.map(|s| s / total)
        } else {
            centre
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(w: u32, h: u32, v: [f32; 4]) -> Plane<[f32; 4]> {
        Plane::from_fn(w, h, |_, _| v)
    }

    #[test]
    fn settings_errors_name_the_setting() {
        let base = MotionBlurSettings::default();
        for (s, name) in [
            (MotionBlurSettings { shutter_s: 0.1, ..base }, "shutter"),
            (
                MotionBlurSettings {
                    shutter_s: -0.001,
                    ..base
                },
                "shutter",
            ),
            (
                MotionBlurSettings {
                    frame_interval_s: 0.0,
                    ..base
                },
                "frame_interval_s",
            ),
            (MotionBlurSettings { samples: 0, ..base }, "samples"),
            (
                MotionBlurSettings {
                    max_length_px: f32::NAN,
                    ..base
                },
                "max_length_px",
            ),
        ] {
            let e = s.check().unwrap_err().to_string();
            assert!(e.contains(name) && !e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn the_twin_refuses_planes_of_other_sizes() {
        let (a, b) = (flat(4, 3, [1.0; 4]), flat(3, 4, [1.0; 4]));
        let e = motion_blur_cpu(&a, &a, &b, &MotionBlurSettings::default()).unwrap_err();
        assert!(e.to_string().contains("motion_blur size"), "{e}");
        let hollow = Plane {
            texels: Vec::new(),
            ..a.clone()
        };
        assert!(motion_blur_cpu(&hollow, &a, &a, &MotionBlurSettings::default()).is_err());
    }

    #[test]
    fn a_closed_shutter_or_no_motion_leaves_the_image() {
        let radiance = Plane::from_fn(9, 5, |x, y| [x as f32 * 0.37, y as f32, 1.0 / (1.0 + x as f32), 1.0]);
        let depth = flat(9, 5, [10.0, 0.0, 0.0, 1.0]);
        let moving = flat(9, 5, [6.0, 1.0, 0.0, 1.0]);
        let closed = MotionBlurSettings {
            shutter_s: 0.0,
            ..Default::default()
        };
        assert_eq!(motion_blur_cpu(&radiance, &depth, &moving, &closed).unwrap(), radiance);
        let still = flat(9, 5, [0.0; 4]);
        let open = MotionBlurSettings::default();
        assert_eq!(motion_blur_cpu(&radiance, &depth, &still, &open).unwrap(), radiance);
    }

    #[test]
    fn the_blur_is_clamped_to_its_longest() {
        let radiance = Plane::from_fn(200, 1, |x, _| [if x < 100 { 0.0 } else { 1.0 }, 0.0, 0.0, 1.0]);
        let depth = flat(200, 1, [10.0, 0.0, 0.0, 1.0]);
        let fast = flat(200, 1, [400.0, 0.0, 0.0, 0.0]);
        let settings = MotionBlurSettings {
            shutter_s: 1.0,
            frame_interval_s: 1.0,
            samples: 16,
            max_length_px: 16.0,
        };
        // 16 pixels, not 400: the step spreads 8 pixels either way.
        let out = motion_blur_cpu(&radiance, &depth, &fast, &settings).unwrap();
        assert_eq!(out.at(90, 0)[0], 0.0);
        assert_eq!(out.at(109, 0)[0], 1.0);
        assert!(out.at(99, 0)[0] > 0.3 && out.at(100, 0)[0] < 0.7);
    }
}
