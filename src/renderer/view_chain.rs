//! What a view's output is made from (composition of the simulator camera
//! passes, §3.3): the techniques render the view's *render spec* — larger
//! by the anti-aliasing factor, and through the undistorted pinhole that
//! covers a distorted lens — and the view's post chain resamples that into
//! the output: `post.resolve` (supersampling, [`crate::post::resolve`]),
//! `post.distortion` (Brown–Conrady, [`crate::post::distortion`]), then
//! `post.motion_blur` on the radiance ([`crate::post::motion_blur`]).

use crate::error::{Error, Result};
use crate::graph::RenderGraph;
use crate::post::distortion::{self, DistortedCamera, LensDistortion};
use crate::post::motion_blur::{MotionBlur, MotionBlurImages, MotionBlurSettings};
use crate::post::resample::{ImageKind, ResampleImage};
use crate::post::resolve::{supersampled_size, Resolve, ResolveDesc, ResolveFilter};
use crate::view::rig::ViewSpec;
use crate::view::{pass_name, SceneTargets};
use crate::vulkan::Context;

/// One view's chain from what is rendered to what is output.
pub(super) struct ViewChain {
    /// The output image.
    pub output: ViewSpec,
    /// What the techniques render.
    pub render: ViewSpec,
    /// The undistorted image the resolve makes (the distortion's source).
    source: (u32, u32),
    distortion: Option<LensDistortion>,
}

/// The distorted camera of `output` and the undistorted render it is
/// resampled from (None without distortion): errors when the view has no
/// pinhole intrinsics or its distortion folds within the image. CPU only,
/// so front ends can check a view before any device work
/// ([`check_view`]).
fn distortion_source(output: &ViewSpec) -> Result<Option<(DistortedCamera, distortion::SourceView)>> {
    let Some(d) = output.distortion else { return Ok(None) };
    let k = output.intrinsics.ok_or_else(|| {
        Error::invalid(
            "distortion",
            format!(
                "view '{}' needs pinhole intrinsics with its lens distortion",
                output.name
            ),
        )
    })?;
    let camera = DistortedCamera {
        intrinsics: k,
        lens: d,
        width: output.width,
        height: output.height,
    };
    let source = distortion::source_intrinsics(&camera)?;
    Ok(Some((camera, source)))
}

/// Checks that `view` can be rendered as specified ([`ViewSpec::validate`]
/// and its lens distortion), without a device.
pub fn check_view(view: &ViewSpec) -> Result<()> {
    view.validate()?;
    distortion_source(view).map(|_| ())
}

impl ViewChain {
    /// The chain of `output` with `samples` samples per pixel (1: none).
    pub fn new(ctx: &Context, output: &ViewSpec, samples: u32) -> Result<ViewChain> {
        let (mut size, mut intrinsics) = ((output.width, output.height), output.intrinsics);
        let distortion = match distortion_source(output)? {
            None => None,
            Some((camera, source)) => {
                size = (source.width, source.height);
                intrinsics = Some(source.intrinsics);
                Some(LensDistortion::new(ctx, &camera, &source)?)
            }
        };
        let source = size;
        if samples != 1 {
            size = supersampled_size(size.0, size.1, samples)?;
            intrinsics = intrinsics.map(|k| k.scaled(source, size.0, size.1));
        }
        let render = ViewSpec {
            name: output.name.clone(),
            width: size.0,
            height: size.1,
            intrinsics,
            distortion: None,
        };
        render.validate()?;
        Ok(ViewChain {
            output: output.clone(),
            render,
            source,
            distortion,
        })
    }

    /// Declares the view's post chain from `rendered` (the render spec's
    /// targets) and returns the targets the exposure, tone mapping and
    /// readback use (`rendered` itself when there is nothing to do).
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        rendered: &SceneTargets,
        (resolve, blur): (&Resolve, Option<(&MotionBlur, MotionBlurSettings)>),
    ) -> Result<SceneTargets> {
        let name = &self.output.name;
        let stage = |what: &str| match name.as_str() {
            "" => what.to_string(),
            n => format!("{n}.{what}"),
        };
        let weight = rendered.weight.is_some();
        // The lighting inputs stay the rendered targets'.
        let lit = &rendered.lighting;
        let mut current = rendered.clone();
        if self.source != (self.render.width, self.render.height) {
            let next = SceneTargets::declare_named(graph, &stage("resolved"), self.source, weight, lit.clone());
            let desc = ResolveDesc {
                source_size: (current.width, current.height),
                target_size: self.source,
                filter: ResolveFilter::Box,
            };
            resolve.declare(graph, name, &desc, &resampled(&current, &next))?;
            current = next;
        }
        if let Some(lens) = &self.distortion {
            let size = (self.output.width, self.output.height);
            let next = SceneTargets::declare_named(graph, &stage("distorted"), size, weight, lit.clone());
            lens.declare(graph, name, &resampled(&current, &next))?;
            current = next;
        }
        if let Some((blur, settings)) = blur {
            let formats = current.formats;
            let output = graph.create_image(
                &pass_name("motion-blurred radiance", name),
                crate::graph::ImageInfo::new(current.width, current.height, formats.radiance),
            );
            let images = MotionBlurImages {
                width: current.width,
                height: current.height,
                radiance: current.radiance,
                depth: current.view_depth,
                motion: current.motion,
                output,
            };
            blur.declare(graph, name, &images, &settings)?;
            current.radiance = output;
        }
        Ok(current)
    }
}

/// Every image of `from` resampled into `to`, by its kind: radiance and
/// lighting visibility filtered, depth, normal, ids, distance and splat
/// weight exact (the one sample nearest the pixel's centre), motion
/// exact and rescaled into the target's pixels.
fn resampled(from: &SceneTargets, to: &SceneTargets) -> Vec<ResampleImage> {
    let f = from.formats;
    let mut images = vec![
        ResampleImage::new(from.radiance, to.radiance, f.radiance, ImageKind::Filtered),
        ResampleImage::new(from.visibility, to.visibility, f.visibility, ImageKind::Filtered),
        ResampleImage::new(from.view_depth, to.view_depth, f.view_depth, ImageKind::Exact),
        ResampleImage::new(from.normal, to.normal, f.normal, ImageKind::Exact),
        ResampleImage::new(from.ids, to.ids, f.ids, ImageKind::Exact),
        ResampleImage::new(from.distance, to.distance, f.distance, ImageKind::Exact),
        ResampleImage::new(from.motion, to.motion, f.motion, ImageKind::Motion),
    ];
    if let (Some(a), Some(b)) = (from.weight, to.weight) {
        images.push(ResampleImage::new(a, b, f.weight, ImageKind::Exact));
    }
    images
}
