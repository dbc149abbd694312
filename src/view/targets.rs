//! The images every technique of a view draws into, declared once per view
//! with their formats: pipelines take their formats from here, never from a
//! literal of their own.

use super::View;
use crate::graph::{
    BufferAccess, BufferId, ImageAccess, ImageId, ImageInfo, PassBuilder, RenderGraph, Stage, UploadRegion,
};
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
    /// The lighting AOVs: sun visibility, sky visibility.
    pub visibility: Format,
    /// The simulator AOVs ([`super::aov`]): world-space shading normal (xyz, w = 1 on
    /// geometry, 0 for sky).
    pub normal: Format,
    /// Semantic class and instance id.
    pub ids: Format,
    /// Screen-space motion from the previous frame (pixels).
    pub motion: Format,
    /// Euclidean distance from the eye (metres).
    pub distance: Format,
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
            visibility: Format::R32G32_SFLOAT,
            normal: Format::R16G16B16A16_SFLOAT,
            ids: Format::R32G32_UINT,
            motion: Format::R32G32_SFLOAT,
            distance: Format::R32_SFLOAT,
        }
    }
}

/// What every shading pass of a view reads for its lighting (§9): the
/// view's lighting constants (an upload region the lighting technique writes
/// in its prepare step) and the images and buffers the lighting passes
/// write (lookup tables, shadow atlas, sky-light maps), which the pass must
/// declare as reads so the graph orders it after them.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingInputs {
    pub constants: UploadRegion,
    pub images: Vec<ImageId>,
    pub buffers: Vec<BufferId>,
}

impl LightingInputs {
    /// Declares the reads of a pass whose shaders (at `stage`) shade with
    /// the lighting.
    pub fn read_in<'g, P: 'static>(&self, mut builder: PassBuilder<'g, P>, stage: Stage) -> PassBuilder<'g, P> {
        builder = builder.read(self.constants, BufferAccess::StorageRead(stage));
        for &image in &self.images {
            builder = builder.read(image, ImageAccess::Sampled(stage));
        }
        for &buffer in &self.buffers {
            builder = builder.read(buffer, BufferAccess::StorageRead(stage));
        }
        builder
    }
}

/// One view's render targets (transient images of the frame graph).
#[derive(Clone, Debug, PartialEq)]
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
    /// The lighting AOVs (`formats.visibility`): sun visibility (0 = in
    /// shadow, 1 = lit) and sky visibility (1 = open sky); 1, 1 for sky.
    pub visibility: ImageId,
    /// World-space shading normal (`formats.normal`): written by `sky` (0),
    /// `terrain.draw` and the points passes.
    pub normal: ImageId,
    /// Class and instance id (`formats.ids`; [`super::aov`]): written by
    /// `sky` (0, 0), `terrain.draw` and the points pass where one surfel wins.
    pub ids: ImageId,
    /// Motion in pixels from the previous frame (`formats.motion`), written by `aovs`.
    pub motion: ImageId,
    /// Distance from the eye, +inf for sky (`formats.distance`), written by `aovs`.
    pub distance: ImageId,
    /// The view's lighting.
    pub lighting: LightingInputs,
}

impl SceneTargets {
    /// Declares the targets of `view` (and W when `weight`), lit by the
    /// lighting constants in `lighting` (the lighting technique declares
    /// that region, sized by its own type).
    pub fn declare<P: 'static>(
        graph: &mut RenderGraph<P>,
        view: &View,
        weight: bool,
        lighting: UploadRegion,
    ) -> SceneTargets {
        let lighting = LightingInputs {
            constants: lighting,
            images: Vec::new(),
            buffers: Vec::new(),
        };
        SceneTargets::declare_named(graph, &view.name, (view.width, view.height), weight, lighting)
    }

    /// Declares `width`×`height` targets whose images are named after
    /// `view_name` (the targets a view's post-processing resamples into),
    /// lit by `lighting`.
    pub fn declare_named<P: 'static>(
        graph: &mut RenderGraph<P>,
        view_name: &str,
        (w, h): (u32, u32),
        weight: bool,
        lighting: LightingInputs,
    ) -> SceneTargets {
        let formats = TargetFormats::default();
        let name = |what: &str| super::pass_name(what, view_name);
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
            visibility: image("lighting visibility", formats.visibility),
            normal: image("world normal", formats.normal),
            ids: image("class and instance", formats.ids),
            motion: image("motion", formats.motion),
            distance: image("distance", formats.distance),
            lighting,
        }
    }
}
