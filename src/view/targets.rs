//! The images every technique of a view draws into, declared once per view
//! with their formats: pipelines take their formats from here, never from a
//! literal of their own.

use super::View;
use crate::graph::{
    Binding, BufferAccess, BufferId, ImageId, ImageInfo, PassBuilder, RenderGraph, Stage, UploadRegion,
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

/// Which heap-handle slot of the lighting constants
/// (`crate::lighting::constants::LightingFrame`) a lighting image or buffer
/// fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightingMap {
    /// `atmosphere.x`: the transmittance table.
    Transmittance,
    /// `atmosphere.y`: the multiple-scattering table.
    Multiscattering,
    /// `atmosphere.z`: the view's sky-view table.
    SkyView,
    /// `shadows.x`: the view's shadow atlas.
    ShadowAtlas,
    /// `maps.x` (unless the sky light is the reference's): the sky-light map.
    SkyLight,
    /// `maps.y`: the sun horizon map.
    Horizon,
    /// `maps.w`: the sky-light environment (a storage buffer).
    Environment,
    /// `maps.x` with the Monte Carlo reference's sky light.
    ReferenceSkyLight,
    /// `maps.z` with the Monte Carlo reference's sky light.
    ReferenceSunVisibility,
}

/// What every shading pass of a view reads for its lighting (§9): the
/// view's lighting constants (an upload region written by the view's `sky`
/// pass, which declares every lighting image and so may embed their heap
/// handles) and the images and buffers the lighting passes write (lookup
/// tables, shadow atlas, sky-light maps), which the pass must declare as
/// reads so the graph orders it after them.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingInputs {
    pub constants: UploadRegion,
    pub images: Vec<(LightingMap, ImageId)>,
    pub buffers: Vec<(LightingMap, BufferId)>,
}

/// What [`LightingInputs::read_in`] declared on a pass: the binding of the
/// lighting constants, and of each lighting image and buffer by its slot.
#[derive(Clone, Debug)]
pub struct LightingBindings {
    pub constants: Binding,
    pub maps: Vec<(LightingMap, Binding)>,
}

impl LightingInputs {
    /// Declares the reads of a pass whose shaders (at `stage`) shade with
    /// the lighting, and returns their bindings.
    pub fn read_in<P: 'static>(&self, pass: &mut PassBuilder<'_, P>, stage: Stage) -> LightingBindings {
        let constants = pass.upload(self.constants, stage);
        let mut maps = Vec::with_capacity(self.images.len() + self.buffers.len());
        for &(map, image) in &self.images {
            maps.push((map, pass.sample(image, stage)));
        }
        for &(map, buffer) in &self.buffers {
            maps.push((map, pass.storage_buffer(buffer, BufferAccess::StorageRead(stage))));
        }
        LightingBindings { constants, maps }
    }

    /// The lighting images (for passes that evaluate the sky through the
    /// constants: they read the lookup tables the constants name).
    pub fn image_ids(&self) -> Vec<ImageId> {
        self.images.iter().map(|&(_, image)| image).collect()
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
    /// What a pass that shades pixels writes, in the order the shaders
    /// take their storage handles: radiance, view depth, lighting AOVs,
    /// normal, ids.
    pub fn shaded(&self) -> [ImageId; 5] {
        [self.radiance, self.view_depth, self.visibility, self.normal, self.ids]
    }

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
