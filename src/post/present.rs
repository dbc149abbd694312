//! Presentation to a window (`alpenglow view`): `present.clear` fills the
//! swapchain image with the letterbox colour, `present.aov` (per view, only
//! when an AOV is shown: its debug view, `glsl/post/present_aov.comp`)
//! turns one of the view's AOVs into display colours, `present.blit`
//! scales the shown view's display image (tone-mapped sRGB, `tonemap`) or
//! AOV into the largest rectangle of its aspect ratio centred in it. The swapchain image
//! is imported into the graph ([`RenderGraph::import_presented`]), so the
//! graph derives the transitions to and from the presentation layout like
//! any other barrier. Which view is shown is prepared per frame
//! ([`PresentFrame`]), so the graph is baked once for every view.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::graph::{ImageAccess, ImageId, ImageInfo, RenderGraph, Stage};
use crate::shaders;
use crate::view::{pass_name, Frame, Provides, SceneTargets};
use crate::vulkan::{ComputePipeline, Context, Format};

/// The colour around a letterboxed view (linear 0..1, the swapchain's
/// UNORM bytes are written as they are).
const LETTERBOX: [f32; 4] = [0.06, 0.06, 0.07, 1.0];

/// Which image of the shown view is presented: its colour, or one of its
/// AOVs as a debug view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum PresentedImage {
    /// The tone-mapped frame.
    #[default]
    Color,
    /// View depth, log scale: near white, 100 km black, sky blue.
    Depth,
    /// World normal as n·0.5 + 0.5.
    Normal,
    /// Semantic class, a colour per class.
    Class,
    /// Instance id, a colour per instance.
    Instance,
    /// Motion: hue by direction, brightness by length (16 px full).
    Motion,
    /// Sun visibility (0 black: in shadow).
    SunVisibility,
    /// Sky visibility (1 white: open sky).
    SkyVisibility,
}

impl PresentedImage {
    /// Every presented image, in menu order.
    pub const ALL: [PresentedImage; 8] = [
        PresentedImage::Color,
        PresentedImage::Depth,
        PresentedImage::Normal,
        PresentedImage::Class,
        PresentedImage::Instance,
        PresentedImage::Motion,
        PresentedImage::SunVisibility,
        PresentedImage::SkyVisibility,
    ];

    /// A short name (the viewer's switch).
    pub fn name(self) -> &'static str {
        match self {
            PresentedImage::Color => "color",
            PresentedImage::Depth => "depth",
            PresentedImage::Normal => "normal",
            PresentedImage::Class => "class",
            PresentedImage::Instance => "instance",
            PresentedImage::Motion => "motion",
            PresentedImage::SunVisibility => "sun vis.",
            PresentedImage::SkyVisibility => "sky vis.",
        }
    }

    /// The AOV image of `targets` it shows and the shader's kind (None:
    /// the colour).
    fn source(self, t: &SceneTargets) -> Option<(ImageId, u32)> {
        Some(match self {
            PresentedImage::Color => return None,
            PresentedImage::Depth => (t.view_depth, 1),
            PresentedImage::Normal => (t.normal, 2),
            PresentedImage::Class => (t.ids, 3),
            PresentedImage::Instance => (t.ids, 4),
            PresentedImage::Motion => (t.motion, 5),
            PresentedImage::SunVisibility => (t.visibility, 6),
            PresentedImage::SkyVisibility => (t.visibility, 7),
        })
    }
}

/// What the present passes show this frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct PresentFrame {
    /// The view shown (index into the frame's views).
    pub view: usize,
    pub image: PresentedImage,
}

/// Push constants of `present.aov` (`glsl/post/present_aov.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct AovPush {
    handles: [u32; 4],
    size: [u32; 4],
}

/// The largest rectangle (x, y, width, height) of aspect `source`
/// centred in `target`, at least 1×1.
pub fn letterbox(source: (u32, u32), target: (u32, u32)) -> [u32; 4] {
    let (sw, sh) = (source.0.max(1) as u64, source.1.max(1) as u64);
    let (tw, th) = (target.0.max(1) as u64, target.1.max(1) as u64);
    let (w, h) = match sw * th >= tw * sh {
        true => (tw, (tw * sh / sw).max(1)),
        false => ((th * sw / sh).max(1), th),
    };
    [((tw - w) / 2) as u32, ((th - h) / 2) as u32, w as u32, h as u32]
}

/// Declares `present.clear`, each view's `present.aov` and `present.blit`
/// of `views` (each view's name and post-processed targets) into a
/// swapchain image of `format`; returns it (bind an acquired image to it
/// before each frame).
pub fn declare_present<S>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    views: &[(String, SceneTargets)],
    format: Format,
) -> Result<ImageId>
where
    S: Provides<PresentFrame> + 'static,
{
    let window = graph.import_presented("swapchain", format);
    graph
        .pass("present.clear")
        .transfer()
        .write(window, ImageAccess::TransferDst)
        .record(move |ctx, _| {
            let image = ctx.image(window)?;
            ctx.cmd().clear_color_image(image, LETTERBOX);
            Ok(())
        });
    let pipeline = Arc::new(ComputePipeline::new(ctx, shaders::PRESENT_AOV)?);
    let mut sources = Vec::new();
    for (k, (name, targets)) in views.iter().enumerate() {
        let aov = declare_aov(graph, (k, name, targets), pipeline.clone());
        sources.push((targets.display, aov));
    }
    let mut blit = graph.pass("present.blit").transfer();
    for &(display, aov) in &sources {
        blit = blit
            .read(display, ImageAccess::TransferSrc)
            .read(aov, ImageAccess::TransferSrc);
    }
    blit.write(window, ImageAccess::TransferDst)
        .record(move |ctx, frame: &Frame<S>| {
            let shown = frame.prepared::<PresentFrame>()?;
            let &(display, aov) = (sources.get(shown.view)).ok_or_else(|| {
                Error::invalid("shown view", format!("{}; the frame has {}", shown.view, sources.len()))
            })?;
            let source = match shown.image {
                PresentedImage::Color => display,
                _ => aov,
            };
            let (src, dst) = (ctx.image(source)?, ctx.image(window)?);
            let (s, d) = (src.desc(), dst.desc());
            let rect = letterbox((s.width, s.height), (d.width, d.height));
            ctx.cmd().blit_image(src, dst, rect);
            Ok(())
        });
    Ok(window)
}

/// `present.aov` of view `index`: its shown AOV in display colours, into
/// the image returned (only while that view shows an AOV).
fn declare_aov<S>(
    graph: &mut RenderGraph<Frame<S>>,
    (index, name, targets): (usize, &str, &SceneTargets),
    pipeline: Arc<ComputePipeline>,
) -> ImageId
where
    S: Provides<PresentFrame> + 'static,
{
    let (width, height) = (targets.width, targets.height);
    let shown = graph.create_image(
        &pass_name("aov display", name),
        ImageInfo::new(width, height, Format::R8G8B8A8_UNORM),
    );
    let mut pass = graph.pass(&pass_name("present.aov", name));
    let output = pass.storage_image(shown, ImageAccess::StorageWrite(Stage::Compute));
    let mut bindings = Vec::new();
    for image in PresentedImage::ALL {
        if let Some((source, kind)) = image.source(targets) {
            bindings.push((image, pass.sample(source, Stage::Compute), kind));
        }
    }
    pass.record(move |ctx, frame: &Frame<S>| {
        let p = frame.prepared::<PresentFrame>()?;
        let Some(&(_, source, kind)) = bindings.iter().find(|(image, ..)| *image == p.image) else {
            return Ok(());
        };
        if p.view != index {
            return Ok(());
        }
        let push = AovPush {
            handles: [ctx.handle(source)?, ctx.handle(output)?, kind, 0],
            size: [width, height, 0, 0],
        };
        ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
    });
    shown
}

#[cfg(test)]
mod tests {
    use super::letterbox;

    #[test]
    fn letterbox_keeps_the_aspect_ratio_and_centres() {
        assert_eq!(letterbox((320, 200), (320, 200)), [0, 0, 320, 200]);
        // Wider window: bars left and right.
        assert_eq!(letterbox((320, 200), (640, 200)), [160, 0, 320, 200]);
        // Taller window: bars above and below.
        assert_eq!(letterbox((320, 200), (320, 400)), [0, 100, 320, 200]);
        assert_eq!(letterbox((1280, 720), (800, 800)), [0, 175, 800, 450]);
        assert_eq!(letterbox((100, 1), (1, 1)), [0, 0, 1, 1]);
    }
}
