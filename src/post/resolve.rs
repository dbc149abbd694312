//! `post.resolve` (§3.3: a driving simulator needs anti-aliased images at a
//! constant frame rate): the anti-aliasing resolve of a view rendered
//! supersampled. The renderer renders the view at W'×H'
//! ([`supersampled_size`]: N samples per pixel are √N per axis, so `--msaa`
//! 1, 2, 4, 8 and the 4×4 reference's 16), and `post.resolve` maps each of
//! the view's images down to W×H by its [`ImageKind`]:
//!
//! * Filtered (radiance): a normalised filter over the output pixel's
//!   footprint in source pixels. [`ResolveFilter::Box`] (the default) weights
//!   each source pixel by the area it shares with the output pixel (with an
//!   integer factor, the plain mean of its s×s samples), so a hard edge
//!   resolves to its exact coverage fraction; [`ResolveFilter::Tent`] is a
//!   tent of radius one output pixel (softer, less aliasing of fine
//!   detail). Not luminance-weighted: Karis' 1/(1+L) weights tame fireflies
//!   of display-referred HDR, but this resolve runs on absolute radiance in
//!   cd/m² before exposure, where 1/(1+L) is about 1/L for every lit pixel
//!   and the mean would become a biased harmonic mean (edges against the sun
//!   or sky darken); exposure-aware weighting would need the exposure, which
//!   is metered after the resolve.
//! * Exact (ids, depth, distance, normals, visibility): the one source sample
//!   nearest the output pixel's centre (i + ½)·W'/W, found in integer
//!   arithmetic (ties to the larger index), so class ids are never averaged
//!   and every AOV of a pixel comes from the same sample (a nearest-depth
//!   choice would need the depth in every dispatch and would disagree with
//!   the radiance's coverage more often).
//! * Motion: that same sample, its displacement scaled by W/W' and H/H'.
//!
//! CPU twins: [`resolve_cpu`] and [`resolve_exact_cpu`]. Shader:
//! `glsl/post/resolve.comp`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

#[cfg(test)]
use super::resample::{add_weighted, ImageKind, Plane};
use super::resample::{check_images, check_size, declare_pass, ResampleImage};
use crate::error::{Error, Result};
use crate::graph::RenderGraph;
use crate::shaders;
use crate::view::pass_name;
use crate::vulkan::{ComputePipeline, Context};

/// The samples per pixel a view may be rendered with (`--msaa`): √N per axis.
pub const SAMPLES_PER_PIXEL: [u32; 5] = [1, 2, 4, 8, 16];

/// The size a view of `width`×`height` is rendered at with `samples` per
/// pixel: each side times √samples, rounded (4 and 16 give exactly 2× and
/// 4×). The renderer renders the view's camera at this size; the resolve
/// maps the whole image onto the whole output.
pub fn supersampled_size(width: u32, height: u32, samples: u32) -> Result<(u32, u32)> {
    if !SAMPLES_PER_PIXEL.contains(&samples) {
        return Err(Error::invalid(
            "msaa",
            format!("{samples} samples per pixel; must be one of {SAMPLES_PER_PIXEL:?}"),
        ));
    }
    check_size("resolve target size", (width, height))?;
    let scale = f64::from(samples).sqrt();
    let side = |n: u32| (f64::from(n) * scale).round() as u32;
    let size = (side(width), side(height));
    check_size("msaa (the supersampled size)", size)?;
    Ok(size)
}

/// The filter of Filtered images.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ResolveFilter {
    /// The output pixel's footprint, each source pixel weighted by its area in it.
    #[default]
    Box,
    /// A tent of radius one output pixel around its centre.
    Tent,
}

/// Sizes and filter of a resolve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResolveDesc {
    /// W'×H', the supersampled render.
    pub source_size: (u32, u32),
    /// W×H, the output; no side larger than the source's, nor more than 16× smaller.
    pub target_size: (u32, u32),
    pub filter: ResolveFilter,
}

impl ResolveDesc {
    fn check(&self) -> Result<()> {
        check_size("resolve source size", self.source_size)?;
        check_size("resolve target size", self.target_size)?;
        let (s, t) = (self.source_size, self.target_size);
        if s.0 < t.0 || s.1 < t.1 || s.0 > 16 * t.0 || s.1 > 16 * t.1 {
            return Err(Error::invalid(
                "resolve source size",
                format!(
                    "{}×{} for a {}×{} target; each side must be 1 to 16 times the target's",
                    s.0, s.1, t.0, t.1
                ),
            ));
        }
        Ok(())
    }

    /// Source pixels per target pixel along x and y (W'/W, H'/H).
    fn scale(&self) -> [f32; 2] {
        [
            self.source_size.0 as f32 / self.target_size.0 as f32,
            self.source_size.1 as f32 / self.target_size.1 as f32,
        ]
    }

    /// The factors of a motion image's x and y (W/W', H/H').
    fn motion_factors(&self) -> [f32; 2] {
        [
            self.target_size.0 as f32 / self.source_size.0 as f32,
            self.target_size.1 as f32 / self.source_size.1 as f32,
        ]
    }
}

/// Push constants of `post.resolve` (`glsl/post/resolve.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ResolvePush {
    /// Source (sampled), target (storage), format code, kind.
    handles: [u32; 4],
    /// Source width, height; target width, height.
    size: [u32; 4],
    /// Scale x, y; filter (0 box, 1 tent); pad.
    params: [f32; 4],
    /// Motion factors x, y; pad.
    motion: [f32; 4],
}

/// The resolve: a pipeline, and one `post.resolve` pass per view.
pub struct Resolve {
    pipeline: Arc<ComputePipeline>,
}

impl Resolve {
    /// Builds the pipeline.
    pub fn new(ctx: &Context) -> Result<Resolve> {
        Ok(Resolve {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::POST_RESOLVE)?),
        })
    }

    /// Declares `post.resolve` (`post.resolve@view` for a named view): every
    /// image's source (W'×H', read sampled) into its target (W×H, written as
    /// a storage image), one dispatch per image.
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        view_name: &str,
        desc: &ResolveDesc,
        images: &[ResampleImage],
    ) -> Result<()> {
        desc.check()?;
        let checked = check_images("post.resolve", images)?;
        let (s, t) = (desc.source_size, desc.target_size);
        let (scale, motion) = (desc.scale(), desc.motion_factors());
        let filter = match desc.filter {
            ResolveFilter::Box => 0.0,
            ResolveFilter::Tent => 1.0,
        };
        let name = pass_name("post.resolve", view_name);
        declare_pass(
            graph,
            &name,
            self.pipeline.clone(),
            checked,
            &[],
            t,
            move |image, h, _| {
                Ok(ResolvePush {
                    handles: [h[0], h[1], image.format, image.kind],
                    size: [s.0, s.1, t.0, t.1],
                    params: [scale[0], scale[1], filter, 0.0],
                    motion: [motion[0], motion[1], 0.0, 0.0],
                })
            },
        );
        Ok(())
    }
}

/// The first and last source texel of target pixel `i` along one axis
/// (`s` source pixels per target pixel, `n` source texels).
#[cfg(test)]
fn taps(i: u32, s: f32, n: u32, filter: ResolveFilter) -> (i64, i64) {
    let (first, last) = match filter {
        ResolveFilter::Tent => {
            let c = (i as f32 + 0.5) * s;
            ((c - s - 0.5).ceil() as i64, (c + s - 0.5).floor() as i64)
        }
        ResolveFilter::Box => ((i as f32 * s).floor() as i64, ((i + 1) as f32 * s).ceil() as i64 - 1),
    };
    (first.max(0), last.min(i64::from(n) - 1))
}

/// The weight of source texel `k` for target pixel `i` along one axis.
#[cfg(test)]
fn weight(k: i64, i: u32, s: f32, filter: ResolveFilter) -> f32 {
    match filter {
        ResolveFilter::Tent => {
            let c = (i as f32 + 0.5) * s;
            (1.0 - (k as f32 + 0.5 - c).abs() / s).max(0.0)
        }
        ResolveFilter::Box => {
            let (a, b) = (i as f32 * s, (i + 1) as f32 * s);
            (((k + 1) as f32).min(b) - (k as f32).max(a)).max(0.0)
        }
    }
}

/// The source texel whose centre is nearest target pixel `i`'s centre
/// along an axis of `target` → `source` texels (ties to the larger index).
#[cfg(test)]
pub fn nearest_source_texel(i: u32, target: u32, source: u32) -> u32 {
    (((2 * u64::from(i) + 1) * u64::from(source)) / (2 * u64::from(target))) as u32
}

/// The CPU twin of `post.resolve` for a float image of `kind` (what the GPU
/// must match to f32 rounding); errors as [`Resolve::declare`]'s.
#[cfg(test)]
pub fn resolve_cpu(
    source: &Plane<[f32; 4]>,
    target_size: (u32, u32),
    kind: ImageKind,
    filter: ResolveFilter,
) -> Result<Plane<[f32; 4]>> {
    let desc = ResolveDesc {
        source_size: (source.width, source.height),
        target_size,
        filter,
    };
    desc.check()?;
    source.check("resolve source")?;
    let (scale, motion) = (desc.scale(), desc.motion_factors());
    let mut plane = match kind {
        ImageKind::Exact | ImageKind::Motion => resolve_exact_cpu(source, target_size)?,
        ImageKind::Filtered => Plane::from_fn(target_size.0, target_size.1, |i, j| {
            let (xs, ys) = (
                taps(i, scale[0], source.width, filter),
                taps(j, scale[1], source.height, filter),
            );
            let (mut sum, mut total) = ([0.0f32; 4], 0.0f32);
            for y in ys.0..=ys.1 {
                let wy = weight(y, j, scale[1], filter);
                for x in xs.0..=xs.1 {
                    let w = weight(x, i, scale[0], filter) * wy;
                    if w > 0.0 {
                        add_weighted(&mut sum, w, source.at(x, y));
                        total += w;
                    }
                }
            }
            sum.map(|s| s / total)
        }),
    };
    if kind == ImageKind::Motion {
        for m in &mut plane.texels {
            m[0] *= motion[0];
            m[1] *= motion[1];
        }
    }
    Ok(plane)
}

/// The CPU twin of `post.resolve` for an Exact image of any texel type.
#[cfg(test)]
pub fn resolve_exact_cpu<T: Copy>(source: &Plane<T>, (width, height): (u32, u32)) -> Result<Plane<T>> {
    ResolveDesc {
        source_size: (source.width, source.height),
        target_size: (width, height),
        filter: ResolveFilter::Box,
    }
    .check()?;
    source.check("resolve source")?;
    Ok(Plane::from_fn(width, height, |i, j| {
        source.at(
            i64::from(nearest_source_texel(i, width, source.width)),
            i64::from(nearest_source_texel(j, height, source.height)),
        )
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_per_pixel_map_to_square_root_scales() {
        assert_eq!(supersampled_size(320, 200, 1).unwrap(), (320, 200));
        assert_eq!(supersampled_size(320, 200, 2).unwrap(), (453, 283));
        assert_eq!(supersampled_size(320, 200, 4).unwrap(), (640, 400));
        assert_eq!(supersampled_size(320, 200, 8).unwrap(), (905, 566));
        assert_eq!(supersampled_size(320, 200, 16).unwrap(), (1280, 800));
        let e = supersampled_size(320, 200, 3).unwrap_err().to_string();
        assert!(e.contains("msaa") && !e.contains('\n'), "{e}");
        assert!(supersampled_size(16384, 10, 4).is_err());
    }

    #[test]
    fn box_weights_partition_the_footprint_and_tents_are_centred() {
        for s in [1.0f32, 2.0, 2.0f32.sqrt(), 8.0f32.sqrt(), 4.0] {
            for i in [3u32, 7, 20] {
                let (a, b) = taps(i, s, 1000, ResolveFilter::Box);
                let total: f32 = (a..=b).map(|k| weight(k, i, s, ResolveFilter::Box)).sum();
                assert!((total - s).abs() < 1e-5, "box s={s} i={i}: {total}");
                let (a, b) = taps(i, s, 1000, ResolveFilter::Tent);
                let c = (i as f32 + 0.5) * s;
                let w = |k| weight(k, i, s, ResolveFilter::Tent);
                let centroid = (a..=b).map(|k| w(k) * (k as f32 + 0.5 - c)).sum::<f32>() / (a..=b).map(w).sum::<f32>();
                // Centred for integer factors; otherwise off by a fraction of a source pixel.
                let bound = if s.fract() == 0.0 { 1e-6 } else { 0.05 };
                assert!(centroid.abs() < bound, "tent s={s} i={i}: {centroid}");
            }
        }
    }

    #[test]
    fn the_nearest_texel_is_the_one_under_the_centre() {
        // 2×: target pixel 3's centre is at 7.0, between texels 6 and 7: the larger.
        assert_eq!(nearest_source_texel(3, 10, 20), 7);
        assert_eq!(nearest_source_texel(0, 10, 40), 2);
        assert_eq!(nearest_source_texel(9, 10, 14), 13);
        assert_eq!(nearest_source_texel(4, 7, 7), 4);
    }

    #[test]
    fn twins_refuse_bad_planes() {
        let short = Plane {
            width: 4,
            height: 4,
            texels: vec![[0.0f32; 4]; 15],
        };
        let e = resolve_cpu(&short, (2, 2), ImageKind::Filtered, ResolveFilter::Box).unwrap_err();
        assert!(e.to_string().contains("resolve source"), "{e}");
        let empty: Plane<[u32; 4]> = Plane::from_fn(0, 3, |_, _| [0; 4]);
        assert!(resolve_exact_cpu(&empty, (1, 1)).is_err());
    }

    #[test]
    fn bad_sizes_are_errors_naming_the_size() {
        let desc = |source_size, target_size| ResolveDesc {
            source_size,
            target_size,
            filter: ResolveFilter::Box,
        };
        for (d, name) in [
            (desc((10, 10), (20, 10)), "resolve source size"),
            (desc((400, 10), (20, 10)), "resolve source size"),
            (desc((10, 0), (10, 10)), "resolve source size"),
            (desc((10, 10), (0, 10)), "resolve target size"),
        ] {
            let e = d.check().unwrap_err().to_string();
            assert!(e.contains(name) && !e.contains('\n'), "{e}");
        }
    }
}
