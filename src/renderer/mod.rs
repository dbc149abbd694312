//! The renderer: composition only. It builds the frame graph of a scene
//! once from the techniques (each declares its passes per view), then
//! renders frames of it, headless, into HDR radiance, view-space depth and
//! tone-mapped sRGB. A frame renders 1 to 16 views ([`ViewSpec`], a
//! multi-view rig, §3.3) in one submission: they share the scene's
//! persistent state (texture atlas, sky-light bake, point trees); each has
//! its own targets, geometry image, point selection and shadow cascades, and
//! its passes are named `pass@view`. A frame is *prepare, then record*: every technique's
//! `prepare` does its CPU work for the frame's views (profile stages
//! `prepare.terrain`, `prepare.texturing`, `prepare.points`), then the baked
//! graph records the passes, which only read what was prepared.
//!
//! Frame graph of the default scene:
//! `sky` (graphics) → `terrain.warp` (compute: warp and zoom into the
//! vertex buffer, §7.4) → `texturing.*` (compute: the dirty atlas tiles,
//! §8.2) → `terrain.draw` (graphics, reads the vertex buffer) → the points
//! passes (`points.visibility` → `points.accumulate` → `points.normalize`
//! for EWA splats, `points.single_pass.*` for single-pass splats (§10.4), or
//! `points.opaque`; see [`crate::points::render`]) →
//! `aovs` (full screen: distance and motion from view depth,
//! [`crate::post::aovs`]) → `tonemap` (compute) → `readback` (transfer).

pub mod footprint;
mod frame_data;
mod lighting;
mod outputs;
mod present;
mod readback;
mod ring;
pub mod scene;
mod view_chain;
mod wiring;

pub use crate::view::rig::{Rig, ViewSpec, MAX_VIEWS};
pub use crate::view::{validate_size, Camera, MAX_IMAGE_SIDE};
pub use frame_data::{FrameData, Plane, ViewData};
pub use outputs::{Element, Output, Outputs};
pub use readback::FrameImages;
pub use ring::Ticket;
pub use scene::Scene;

use readback::Readback;
pub use view_chain::check_view;
use view_chain::ViewChain;
use wiring::{declare_outputs, Wiring};

use crate::error::{Error, Result};
use crate::graph::{BakedGraph, CpuStage, FrameOutcome, RenderGraph};
use crate::lighting::shadows::{ShadowFrame, ShadowSettings};
use crate::lighting::technique::{PreparedLighting, SceneLighting};
use crate::points::render::shadow::PointShadowFrame;
use crate::points::render::{PointFrameStats, PointRenderer, PointsFrame, SplatSettings};
use crate::post::aovs::{Aovs, AovsFrame};
use crate::post::motion_blur::MotionBlurSettings;
use crate::post::overlay::{Overlay, OverlayPrepared};
use crate::post::present::{declare_present, PresentFrame, PresentedImage};
use crate::profile::FrameProfile;
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::visibility::RasterPath;
use crate::terrain::{Terrain, TerrainFrame};
use crate::texturing::generation::{TextureAtlas, TextureFrame, TextureFrameStats, TextureStreaming};
use crate::texturing::page_table::PageTable;
use crate::view::rig::validate_views;
use crate::view::{frame_slots, Frame, FrameLighting, Lighting, View};
use crate::vulkan::{Context, FrameRing, FRAMES_IN_FLIGHT};

/// The default [`RenderSettings::readback_slots`]: one frame being read,
/// one in flight and one being recorded.
pub const DEFAULT_READBACK_SLOTS: usize = 3;
/// The most [`RenderSettings::readback_slots`].
pub const MAX_READBACK_SLOTS: usize = 16;

/// Output size (or the views of a rig), whether frames are read back to
/// the host, and every technique's settings.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct RenderSettings {
    /// The image size of a single view (ignored when `views` is set).
    pub width: u32,
    pub height: u32,
    /// The views every frame renders (1 to [`MAX_VIEWS`]); empty: one
    /// unnamed `width`×`height` view.
    pub views: Vec<ViewSpec>,
    /// Anti-aliasing: samples per pixel (1, 2, 4, 8 or 16), rendered as a
    /// supersampled image (each side ×√samples) and resolved.
    pub msaa: u32,
    /// Motion blur (§3.3) along the motion AOV; None: off.
    pub motion_blur: Option<MotionBlurSettings>,
    /// Copy the view's images ([`RenderSettings::outputs`]) to host memory
    /// every frame.
    pub readback: bool,
    /// Which outputs are copied (default: all); the copies of the others
    /// are skipped.
    pub outputs: Outputs,
    /// Readback slots (1 to [`MAX_READBACK_SLOTS`], default 3): frame `k`
    /// is read back into slot `k % readback_slots`, so a frame can be read
    /// until `readback_slots` more frames were submitted
    /// ([`Renderer::submit`], [`Renderer::try_read`]).
    pub readback_slots: usize,
    pub terrain: TerrainSettings,
    /// How point objects are splatted.
    pub points: SplatSettings,
    /// How the terrain is coloured (§7.4.3 surface types or the §8.2 layer tree).
    pub texturing: TexturingMode,
    /// Tile streaming of [`TexturingMode::Atlas`].
    pub texture_streaming: TextureStreaming,
    /// Which rasterizer draws the terrain and the EWA splats (`--raster`):
    /// the hardware's, or compute shaders ([`RasterPath`]).
    pub raster: RasterPath,
    /// The sun's cascaded shadow maps.
    pub shadows: ShadowSettings,
    /// Where the sky-light bake is cached (None: baked every time). Optional:
    /// a cache that cannot be read or written is logged (`log::warn`) and
    /// the renderer is built without it.
    pub cache_dir: Option<std::path::PathBuf>,
    /// The lighting of the first frames (None: [`Scene::default_lighting`]);
    /// change it between frames with [`Renderer::set_lighting`].
    pub lighting: Option<Lighting>,
    /// The format of the swapchain frames are presented to
    /// ([`RenderSettings::present_to`], [`Renderer::present`]); None: headless.
    pub(crate) present: Option<crate::vulkan::Format>,
}

impl RenderSettings {
    /// `width`×`height` with readback and the default terrain settings.
    pub fn new(width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            views: Vec::new(),
            msaa: 1,
            motion_blur: None,
            readback: true,
            outputs: Outputs::ALL,
            readback_slots: DEFAULT_READBACK_SLOTS,
            terrain: TerrainSettings::default(),
            points: SplatSettings::default(),
            texturing: TexturingMode::default(),
            texture_streaming: TextureStreaming::for_image(width, height),
            raster: RasterPath::default(),
            shadows: ShadowSettings {
                atlas_size: 2048,
                ..ShadowSettings::default()
            },
            cache_dir: None,
            lighting: None,
            present: None,
        }
    }

    /// Settings for the views `views` (their atlas sized for all of them).
    pub fn for_views(views: Vec<ViewSpec>) -> RenderSettings {
        let sizes: Vec<(u32, u32)> = views.iter().map(|v| (v.width, v.height)).collect();
        let (w, h) = sizes.first().copied().unwrap_or((1, 1));
        RenderSettings {
            texture_streaming: TextureStreaming::for_views(&sizes),
            views,
            ..RenderSettings::new(w, h)
        }
    }

    /// The views a frame renders.
    pub fn view_specs(&self) -> Vec<ViewSpec> {
        match self.views.is_empty() {
            true => vec![ViewSpec::new(self.width, self.height)],
            false => self.views.clone(),
        }
    }
}

frame_slots! {
    /// What the renderer's techniques prepare each frame, one slot each:
    /// what a pass body reads with `frame.prepared::<T>()`.
    pub(crate) struct Slots {
        shadows: ShadowFrame,
        point_shadows: PointShadowFrame,
        lighting: PreparedLighting,
        terrain: TerrainFrame,
        texturing: TextureFrame,
        points: PointsFrame,
        aovs: AovsFrame,
        present: PresentFrame,
        overlay: OverlayPrepared,
    }
}

/// A renderer's frame.
pub(crate) type RenderFrame = Frame<Slots>;

/// The techniques of a scene, each with its persistent state.
/// (The sky and tone mapping prepare nothing: their passes own their pipelines.)
struct Techniques {
    lighting: SceneLighting,
    shadows: Option<lighting::SunShadows>,
    terrain: Option<Terrain>,
    atlas: Option<TextureAtlas>,
    points: Option<PointRenderer>,
    aovs: Aovs,
    /// Over the presented frame (a renderer that presents).
    overlay: Option<Overlay>,
}

/// Renders one scene, frame after frame. `Send`: a simulator may hand it to
/// its render thread.
pub struct Renderer {
    ctx: Context,
    frames: FrameRing,
    graph: BakedGraph<RenderFrame>,
    /// The output images.
    views: Vec<ViewSpec>,
    /// What the techniques render for each (supersampled, undistorted).
    render_specs: Vec<ViewSpec>,
    /// Per view, when reading back (empty: nothing is read back).
    readback: Vec<Readback>,
    /// The readback ring's size.
    readback_slots: usize,
    /// Identifies the renderer's tickets.
    id: u64,
    /// The last frame and its CPU stages, reused by the next.
    frame: Option<RenderFrame>,
    stages: Vec<CpuStage>,
    /// The lighting of the next frames, validated when set.
    lighting: FrameLighting,
    /// Frames rendered so far.
    frames_rendered: u64,
    techniques: Techniques,
    /// The swapchain image the frame ends in, and the view it shows
    /// ([`Renderer::present`]); None: headless.
    presented: Option<crate::graph::ImageId>,
    shown: usize,
    presented_image: PresentedImage,
}

impl Renderer {
    /// Uploads the scene, declares every technique's passes for the view
    /// and bakes the frame graph.
    pub fn new(ctx: &Context, scene: &Scene, settings: RenderSettings) -> Result<Renderer> {
        Renderer::with_progress(ctx, scene, settings, &mut |_| {})
    }

    /// [`Renderer::new`], reporting the sky-light bake's progress (0..1).
    pub fn with_progress(
        ctx: &Context,
        scene: &Scene,
        settings: RenderSettings,
        progress: &mut dyn FnMut(f32),
    ) -> Result<Renderer> {
        // Before anything is uploaded: a field whose samples do not fill its
        // grid would be read out of bounds.
        scene
            .heights
            .validate(std::path::Path::new("the scene's height field"))?;
        let specs = settings.view_specs();
        validate_views(&specs)?;
        let max = ctx.max_image_dimension();
        if let Some(v) = specs.iter().find(|v| v.width > max || v.height > max) {
            return Err(Error::invalid(
                "image size",
                format!("{}×{} exceeds the device limit of {max} per side", v.width, v.height),
            ));
        }
        // The memory model before any image, buffer or upload: the views
        // (size × samples × views), the height field and the instances.
        let limits = ctx.memory_limits();
        let points_present = !scene.points.is_empty();
        let slots = settings.readback_slots;
        if !(1..=MAX_READBACK_SLOTS).contains(&slots) {
            return Err(Error::invalid(
                "readback_slots",
                format!("{slots}; it must be 1 to {MAX_READBACK_SLOTS}"),
            ));
        }
        let readback_slots = settings.readback.then_some(slots);
        footprint::check_views(&limits, &specs, settings.msaa, points_present, readback_slots)?;
        let field = (scene.heights.columns, scene.heights.rows);
        footprint::check_scene(&limits, field, scene.points.instances.len(), specs.len())?;
        let mut graph = RenderGraph::new();
        let chains: Vec<ViewChain> = (specs.iter())
            .map(|s| ViewChain::new(ctx, s, settings.msaa))
            .collect::<Result<_>>()?;
        // The views the graph is declared for; every frame brings their cameras.
        let views: Vec<View> = (chains.iter()).map(|c| c.render.view(scene.default_camera())).collect();
        let lighting = FrameLighting::new(settings.lighting.unwrap_or_else(|| scene.default_lighting()))?;
        let wiring = Wiring {
            ctx,
            scene,
            settings: &settings,
            views: &views,
        };
        let (mut techniques, targets) = wiring.declare(&mut graph, &chains, lighting.setup(), progress)?;
        let outputs = match settings.readback {
            true => settings.outputs,
            false => Outputs::NONE,
        };
        let (readback, displays) = declare_outputs(
            ctx,
            &mut graph,
            (&views, &targets, &chains),
            &settings,
            (outputs, slots),
        )?;
        let presented = match settings.present {
            Some(format) => {
                let window = declare_present(ctx, &mut graph, &displays, format)?;
                let mut overlay = Overlay::new(ctx, format)?;
                overlay.declare(&mut graph, window);
                techniques.overlay = Some(overlay);
                Some(window)
            }
            None => None,
        };
        let graph = graph.bake(ctx)?;
        Ok(Renderer {
            ctx: ctx.clone(),
            frames: FrameRing::new(ctx)?,
            graph,
            readback,
            readback_slots: slots,
            id: ring::renderer_id(),
            frame: None,
            stages: Vec::new(),
            views: specs,
            render_specs: chains.into_iter().map(|c| c.render).collect(),
            lighting,
            frames_rendered: 0,
            techniques,
            presented,
            shown: 0,
            presented_image: PresentedImage::Color,
        })
    }

    /// The lighting of the next frames.
    pub fn lighting(&self) -> &Lighting {
        self.lighting.lighting()
    }

    /// Sets the lighting of the next frames (sun, sky model, exposure,
    /// shadows, sky light): checked here, so a bad value fails before any
    /// frame is recorded. The renderer must have been built with the parts
    /// the lighting uses (see [`RenderSettings::lighting`]).
    pub fn set_lighting(&mut self, lighting: Lighting) -> Result<()> {
        self.lighting = FrameLighting::new(lighting)?;
        Ok(())
    }

    /// Forgets the previous frame's cameras: the next frame's motion AOV is
    /// 0 (a cut, or a camera that jumped).
    pub fn reset_motion(&mut self) {
        self.techniques.aovs.reset();
    }

    /// The context the renderer draws with.
    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// Keeps the profiles of at most `frames` frames (at least 1; default
    /// `DEFAULT_PROFILE_HISTORY`) until
    /// [`Renderer::finish`] takes them: older ones are dropped and their
    /// memory reused, so frames allocate nothing for their profiles once
    /// the history is full.
    pub fn set_profile_history(&mut self, frames: usize) {
        self.graph.set_profile_history(frames);
    }

    /// Wraps every pass in a pipeline-statistics query from the next frame
    /// on (vertex, fragment and compute invocations…: each profile pass's
    /// [`PassTiming::pipeline_stats`](crate::tools::profile::PassTiming));
    /// an error naming the feature when the device lacks
    /// `pipelineStatisticsQuery`.
    pub fn set_pipeline_stats(&mut self, on: bool) -> Result<()> {
        self.graph.set_pipeline_stats(&self.ctx, on)
    }

    /// Pass names in execution order.
    pub fn pass_names(&self) -> Vec<String> {
        self.graph.pass_names()
    }

    /// The views every frame renders.
    pub fn views(&self) -> &[ViewSpec] {
        &self.views
    }

    /// Prepares, records and submits a frame of `camera` (a renderer of
    /// one view).
    pub fn render(&mut self, camera: &Camera) -> Result<FrameOutcome> {
        self.render_views(std::slice::from_ref(camera))
    }

    /// Prepares, records and submits a frame of every view, view `k`
    /// through `cameras[k]`, in one submission.
    pub fn render_views(&mut self, cameras: &[Camera]) -> Result<FrameOutcome> {
        if cameras.len() != self.views.len() {
            return Err(Error::invalid(
                "cameras",
                format!("{} cameras for {} views", cameras.len(), self.views.len()),
            ));
        }
        for (spec, camera) in self.render_specs.iter().zip(cameras) {
            view_of(spec, camera).validate()?;
        }
        if self.presented.is_some() && !self.graph.present_bound() {
            return Err(Error::invalid(
                "frame",
                "the renderer presents to a window (Settings::present_to): render with Renderer::present",
            ));
        }
        // The slot's previous frame must be done before prepare writes its uploads.
        let index = self.frames.wait_for_next()?;
        // The frame (views, prepared data) and its stages are reused frame
        // after frame: steady-state frames allocate nothing.
        let mut frame = match self.frame.take() {
            Some(mut frame) => {
                frame.reset(index, self.lighting);
                for (view, camera) in frame.views.iter_mut().zip(cameras) {
                    view.camera = *camera;
                }
                frame
            }
            None => {
                let views = (self.render_specs.iter().zip(cameras))
                    .map(|(s, c)| s.view(*c))
                    .collect();
                Frame::new(index, views, self.lighting)
            }
        };
        let mut stages = std::mem::take(&mut self.stages);
        stages.clear();
        let result = self.prepare_and_execute(&mut frame, &mut stages);
        (self.frame, self.stages) = (Some(frame), stages);
        let outcome = result?;
        self.frames_rendered = outcome.frame + 1;
        Ok(outcome)
    }

    /// Every technique's prepare, then the graph records and submits `frame`.
    /// The order is the data's: the lighting needs the shadows' cascades
    /// (its constants carry them), so it takes what their prepare returned.
    fn prepare_and_execute(&mut self, frame: &mut RenderFrame, stages: &mut Vec<CpuStage>) -> Result<FrameOutcome> {
        let mut uploads = self.graph.uploads(frame.index);
        let t = &mut self.techniques;
        let mut shadows = None;
        if let Some(s) = &mut t.shadows {
            shadows = Some(frame.prepare(&mut s.maps, (), &mut uploads, stages)?);
            if let Some(points) = &mut s.points {
                frame.prepare_into(points, (), &mut uploads, stages)?;
            }
        }
        frame.prepare_into(&mut t.lighting, shadows.as_ref(), &mut uploads, stages)?;
        if let Some(shadows) = shadows {
            frame.insert(shadows);
        }
        if let Some(terrain) = &mut t.terrain {
            frame.prepare_into(terrain, (), &mut uploads, stages)?;
        }
        if let Some(atlas) = &mut t.atlas {
            atlas.observe_profiles(self.graph.profiles());
            // The atlas's base surface is the terrain's, window included.
            let window = frame
                .prepared::<TerrainFrame>()
                .map_or(Default::default(), |t| t.detail.push);
            frame.prepare_into(atlas, window, &mut uploads, stages)?;
        }
        if let Some(points) = &mut t.points {
            frame.prepare_into(points, (), &mut uploads, stages)?;
        }
        frame.prepare_into(&mut t.aovs, (), &mut uploads, stages)?;
        if self.presented.is_some() {
            frame.insert(PresentFrame {
                view: self.shown,
                image: self.presented_image,
            });
        }
        if let Some(overlay) = &mut t.overlay {
            frame.prepare_into(overlay, (), &mut uploads, stages)?;
        }
        self.graph.execute(&mut self.frames, frame, stages)
    }

    /// Renders `camera` until every texture tile the view needs is ready
    /// and returns that frame. The atlas generates at most its tile budget
    /// per frame (not its GPU time budget: these frames are not shown), at
    /// least one tile, and coarsens what does not fit, so a still view
    /// always settles; errors only if `max_frames` frames in a row bring no
    /// tile closer. Same as [`Renderer::render`] without the atlas.
    pub fn render_settled(&mut self, camera: &Camera, max_frames: u32) -> Result<FrameOutcome> {
        self.render_views_settled(std::slice::from_ref(camera), max_frames)
    }

    /// [`Renderer::render_settled`] of every view.
    pub fn render_views_settled(&mut self, cameras: &[Camera], max_frames: u32) -> Result<FrameOutcome> {
        if let Some(atlas) = &mut self.techniques.atlas {
            atlas.set_paced(false);
        }
        let settled = self.render_until_settled(cameras, max_frames.max(1));
        if let Some(atlas) = &mut self.techniques.atlas {
            atlas.set_paced(true);
        }
        settled
    }

    fn render_until_settled(&mut self, cameras: &[Camera], max_frames: u32) -> Result<FrameOutcome> {
        let (mut fewest, mut stalled) = (usize::MAX, 0);
        loop {
            let outcome = self.render_views(cameras)?;
            let missing = self.techniques.atlas.as_ref().map_or(0, |a| a.last_deferred());
            if missing == 0 {
                return Ok(outcome);
            }
            (fewest, stalled) = if missing < fewest {
                (missing, 0)
            } else {
                (fewest, stalled + 1)
            };
            if stalled >= max_frames {
                return Err(Error::invalid(
                    "texture atlas",
                    format!("{missing} tiles still missing after {max_frames} frames without progress"),
                ));
            }
        }
    }

    /// Waits for `frame` and copies the first view's images out of the
    /// readback buffers. Call before rendering
    /// [`RenderSettings::readback_slots`] more frames.
    pub fn read(&mut self, frame: &FrameOutcome) -> Result<FrameImages> {
        self.read_view(frame, 0)
    }

    /// [`Renderer::read`] of view `view`.
    pub fn read_view(&mut self, frame: &FrameOutcome, view: usize) -> Result<FrameImages> {
        if self.readback.is_empty() {
            return Err(Error::invalid("readback", "the renderer was created without readback"));
        }
        let rb = (self.readback.get(view))
            .ok_or_else(|| Error::invalid("view", format!("{view}; the renderer has {} views", self.views.len())))?;
        let slots = self.readback_slots as u64;
        if self.frames_rendered > frame.frame + slots {
            return Err(Error::invalid(
                "readback",
                format!(
                    "frame {} was overwritten: read a frame before rendering {slots} more (readback_slots)",
                    frame.frame
                ),
            ));
        }
        self.ctx.wait(frame.timeline)?;
        rb.read((frame.frame % slots) as usize)
    }

    /// [`Renderer::read`] of every view, in order.
    pub fn read_views(&mut self, frame: &FrameOutcome) -> Result<Vec<FrameImages>> {
        (0..self.views.len()).map(|k| self.read_view(frame, k)).collect()
    }

    /// Waits for `frame` and copies the colour atlas textures (sRGB-encoded
    /// RGBA8, `atlas size²` texels each, in texture order) out of their
    /// readback buffers; needs [`TextureStreaming::readback`]. Same
    /// frames-in-flight rule as [`Renderer::read`].
    pub fn read_texture_atlas(&mut self, frame: &FrameOutcome) -> Result<Vec<Vec<u8>>> {
        let buffers = (self.techniques.atlas.as_ref().and_then(|a| a.readback()))
            .ok_or_else(|| Error::invalid("texture atlas readback", "the renderer was created without it"))?;
        if self.frames_rendered > frame.frame + FRAMES_IN_FLIGHT as u64 {
            return Err(Error::invalid(
                "texture atlas readback",
                format!("frame {} was overwritten", frame.frame),
            ));
        }
        self.ctx.wait(frame.timeline)?;
        let slot = frame.frame as usize % FRAMES_IN_FLIGHT;
        buffers.iter().map(|b| Ok(b[slot].mapped()?.to_vec())).collect()
    }

    /// Waits for all frames and returns the timings of those not yet taken.
    pub fn finish(&mut self) -> Result<Vec<FrameProfile>> {
        self.graph.finish(&mut self.frames)?;
        if let Some(atlas) = &mut self.techniques.atlas {
            atlas.observe_profiles(self.graph.profiles());
        }
        Ok(self.graph.take_profiles())
    }

    /// The timings of the frames the GPU has completed and not yet taken,
    /// without waiting (a live viewer's per-frame profile).
    pub fn take_profiles(&mut self) -> Vec<FrameProfile> {
        self.graph.take_profiles()
    }

    /// Texture atlas statistics of the frames recorded so far and not yet
    /// taken (their GPU times are the `texturing.*` passes of
    /// [`Renderer::finish`]'s profiles); empty unless texturing from the atlas.
    pub fn take_texture_stats(&mut self) -> Result<Vec<TextureFrameStats>> {
        Ok(match &mut self.techniques.atlas {
            Some(a) => a.take_stats(),
            None => Vec::new(),
        })
    }

    /// The rasterizer the frame is drawn with ([`RenderSettings::raster`]
    /// resolved on this device): compute when the terrain or the EWA splats
    /// are drawn by compute passes, else hardware.
    pub fn raster_path(&self) -> RasterPath {
        let terrain = (self.techniques.terrain.as_ref()).map(|t| t.raster_path());
        let points = (self.techniques.points.as_ref()).map(|p| match p.draws_in_compute() {
            true => RasterPath::Compute,
            false => RasterPath::Hardware,
        });
        match (terrain, points) {
            (Some(RasterPath::Compute), _) | (_, Some(RasterPath::Compute)) => RasterPath::Compute,
            _ => RasterPath::Hardware,
        }
    }

    /// The texture page table of the last recorded frame (which atlas tile
    /// colours which part of the terrain); None unless texturing from the atlas.
    pub fn texture_page_table(&self) -> Result<Option<PageTable>> {
        Ok(self.techniques.atlas.as_ref().map(|a| a.page_table().clone()))
    }

    /// Point statistics of the frames the GPU has completed, without
    /// waiting (a live viewer's); empty without point objects.
    pub fn take_completed_point_stats(&mut self) -> Result<Vec<PointFrameStats>> {
        match &mut self.techniques.points {
            Some(p) => p.take_stats(),
            None => Ok(Vec::new()),
        }
    }

    /// Point statistics of the frames completed so far and not yet taken
    /// (complete after [`Renderer::finish`]); empty without point objects.
    pub fn take_point_stats(&mut self) -> Result<Vec<PointFrameStats>> {
        self.graph.finish(&mut self.frames)?;
        match &mut self.techniques.points {
            Some(p) => p.take_stats(),
            None => Ok(Vec::new()),
        }
    }
}

/// The view `spec` renders through `camera`, without allocating (the
/// name stays empty: only the size and intrinsics are checked with it).
fn view_of(spec: &ViewSpec, camera: &Camera) -> View {
    View {
        name: String::new(),
        camera: *camera,
        width: spec.width,
        height: spec.height,
        intrinsics: spec.intrinsics,
    }
}

#[cfg(test)]
mod tests;
