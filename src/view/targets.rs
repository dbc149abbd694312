//! The images every technique of a view draws into, declared once per view
//! with their formats: pipelines take their formats from here, never from a
//! literal of their own.

use super::View;
use crate::graph::{ImageId, ImageInfo, RenderGraph};
use crate::vulkan::Format;

/// Formats of the scene targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TargetFormats {
    /// Linear HDR radiance.
    pub radiance: Format,
    /// View-space depth along the camera's forward axis (metres).
    pub view_depth: Format,
    /// The depth buffer.
    pub depth: Format,
    /// W: the accumulated EWA splat weight.
    pub weight: Format,
    /// Tone-mapped sRGB.
    pub display: Format,
    /// The points passes' float accumulation targets (colour·w, w; normal·w, depth·w).
    pub accumulation: Format,
}

impl Default for TargetFormats {
    fn default() -> Self {
        TargetFormats {
            radiance: Format::R32G32B32A32_SFLOAT,
            view_depth: Format::R32_SFLOAT,
            depth: Format::D32_SFLOAT,
            weight: Format::R32_SFLOAT,
            display: Format::R8G8B8A8_UNORM,
            accumulation: Format::R32G32B32A32_SFLOAT,
        }
    }
}

/// One view's render targets (transient images of the frame graph).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneTargets {
    pub width: u32,
    pub height: u32,
    pub formats: TargetFormats,
    /// Linear HDR radiance (`formats.radiance`).
    pub radiance: ImageId,
    /// View-space depth, +inf for sky (`formats.view_depth`).
    pub view_depth: ImageId,
    /// Depth buffer (`formats.depth`).
    pub depth: ImageId,
    /// W of the points passes (`formats.weight`); None without points.
    pub weight: Option<ImageId>,
    /// Tone-mapped sRGB (`formats.display`).
    pub display: ImageId,
}

impl SceneTargets {
    /// Declares the targets of `view` (and W when `weight`).
    pub fn declare<P: 'static>(graph: &mut RenderGraph<P>, view: &View, weight: bool) -> SceneTargets {
        let formats = TargetFormats::default();
        let (w, h) = (view.width, view.height);
        let name = |what: &str| super::pass_name(what, &view.name);
        let mut image = |what: &str, format| graph.create_image(&name(what), ImageInfo::new(w, h, format));
        SceneTargets {
            width: w,
            height: h,
            formats,
            radiance: image("hdr radiance", formats.radiance),
            view_depth: image("view depth", formats.view_depth),
            depth: image("depth buffer", formats.depth),
            display: image("srgb", formats.display),
            weight: weight.then(|| image("splat weight", formats.weight)),
        }
    }
}
