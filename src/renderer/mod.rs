//! The renderer: composition only. It builds the frame graph of a scene
//! once from the techniques (each declares its passes per view), then
//! renders views of it, headless, into HDR radiance, view-space depth and
//! tone-mapped sRGB. A frame is *prepare, then record*: every technique's
//! `prepare` does its CPU work for the frame's views (profile stages
//! `prepare.terrain`, `prepare.texturing`, `prepare.points`), then the baked
//! graph records the passes, which only read what was prepared.
//!
//! Frame graph of the default scene:
//! `sky` (graphics) → `terrain.warp` (compute: warp and zoom into the
//! vertex buffer, §7.4) → `texturing.*` (compute: the dirty atlas tiles,
//! §8.2) → `terrain.draw` (graphics, reads the vertex buffer) → the points
//! passes (`points.visibility` → `points.accumulate` → `points.normalize`
//! for EWA splats, or `points.opaque`; see [`crate::points::render`]) →
//! `aovs` (full screen: distance and motion from view depth,
//! [`crate::post::aovs`]) → `tonemap` (compute) → `readback` (transfer).

mod aov_readback;
mod lighting;
pub mod scene;

use std::sync::Arc;

pub use crate::view::{validate_size, Camera, MAX_IMAGE_SIDE};
pub use scene::Scene;

use crate::error::{Error, Result};
use crate::graph::{BakedGraph, FrameOutcome, RenderGraph};
use crate::lighting::shadows::ShadowSettings;
use crate::lighting::sky::Sky;
use crate::lighting::technique::SceneLighting;
use crate::points::render::{PointFrameStats, PointRenderer, SplatSettings};
use crate::post::aovs::Aovs;
use crate::post::exposure::ExposureMeter;
use crate::post::tonemap::Tonemap;
use crate::profile::FrameProfile;
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::{Terrain, TerrainTexturing};
use crate::texturing::generation::{TextureAtlas, TextureFrameStats, TextureStreaming};
use crate::texturing::gpu_layout::TexturingMode;
use crate::texturing::page_table::PageTable;
use crate::view::{Frame, Lighting, SceneTargets, View};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, FrameRing, MemoryLocation, FRAMES_IN_FLIGHT};

/// Output size, whether frames are read back to the host, and the
/// terrain's LOD and detail settings.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Copy HDR, depth and sRGB images to host memory every frame.
    pub readback: bool,
    pub terrain: TerrainSettings,
    /// How point objects are splatted.
    pub points: SplatSettings,
    /// How the terrain is coloured (§7.4.3 surface types or the §8.2 layer tree).
    pub texturing: TexturingMode,
    /// Tile streaming of [`TexturingMode::Atlas`].
    pub texture_streaming: TextureStreaming,
    /// The sun's cascaded shadow maps.
    pub shadows: ShadowSettings,
    /// Where the sky-light bake is cached (None: baked every time).
    pub cache_dir: Option<std::path::PathBuf>,
    /// The lighting of the first frames (None: [`Scene::default_lighting`]);
    /// change it between frames with [`Renderer::set_lighting`].
    pub lighting: Option<Lighting>,
}

impl RenderSettings {
    /// `width`×`height` with readback and the default terrain settings.
    pub fn new(width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            readback: true,
            terrain: TerrainSettings::default(),
            points: SplatSettings::default(),
            texturing: TexturingMode::default(),
            texture_streaming: TextureStreaming::for_image(width, height),
            shadows: ShadowSettings {
                atlas_size: 2048,
                ..ShadowSettings::default()
            },
            cache_dir: None,
            lighting: None,
        }
    }
}

/// A rendered frame in host memory. Row 0 is the top of the image.
#[derive(Clone, Debug)]
pub struct FrameImages {
    pub width: u32,
    pub height: u32,
    /// Tone-mapped sRGB, 4 bytes per pixel.
    pub rgba8: Vec<u8>,
    /// Linear HDR radiance, 4 floats per pixel (alpha 1 everywhere).
    pub hdr: Vec<f32>,
    /// View-space depth along the camera's forward axis, metres; +inf for sky.
    pub depth: Vec<f32>,
    /// W: the accumulated EWA splat weight before normalisation (opaque
    /// splats: 1), 0 where no splat reached; None for scenes without points.
    pub weight: Option<Vec<f32>>,
    /// The lighting AOVs, 2 floats per pixel: sun visibility (0 = in
    /// shadow, 1 = lit; the filtered shadow term) and sky visibility (the
    /// ambient-occlusion term, 1 = open sky); (1, 1) for sky pixels.
    pub visibility: Vec<f32>,
    /// The simulator AOVs (`crate::view::aov`): world-space shading normal,
    /// 3 floats per pixel (0 for sky).
    pub normal: Vec<f32>,
    /// Semantic class per pixel (sky 0, terrain 1 or 10 + its dominant
    /// surface layer, rock 2, other point objects 3).
    pub class: Vec<u32>,
    /// Point instance id per pixel (1-based; 0 for terrain and sky).
    pub instance: Vec<u32>,
    /// Motion from the previous frame in pixels, 2 floats per pixel (this
    /// frame's position minus the previous one's; +x right, +y down; 0 on
    /// the first frame).
    pub motion: Vec<f32>,
    /// Euclidean distance from the eye along the pixel's ray, metres; +inf for sky.
    pub distance: Vec<f32>,
}

impl FrameImages {
    /// One AOV channel of [`FrameImages::visibility`]: 0 sun, 1 sky.
    pub fn visibility_channel(&self, k: usize) -> Vec<f32> {
        self.visibility.iter().skip(k).step_by(2).copied().collect()
    }
}

struct Readback {
    hdr: Vec<Arc<Buffer>>,
    depth: Vec<Arc<Buffer>>,
    ldr: Vec<Arc<Buffer>>,
    weight: Option<Vec<Arc<Buffer>>>,
    visibility: Vec<Arc<Buffer>>,
    aovs: aov_readback::AovReadback,
}

/// The techniques of a scene, each with its persistent state.
/// (The sky and tone mapping prepare nothing: their passes own their pipelines.)
struct Techniques {
    lighting: SceneLighting,
    shadows: Option<lighting::SunShadows>,
    terrain: Option<Terrain>,
    atlas: Option<TextureAtlas>,
    points: Option<PointRenderer>,
    aovs: Aovs,
}

/// Renders one scene, frame after frame. `Send`: a simulator may hand it to
/// its render thread.
pub struct Renderer {
    ctx: Context,
    frames: FrameRing,
    graph: BakedGraph<Frame>,
    settings: RenderSettings,
    readback: Option<Readback>,
    lighting: Lighting,
    /// Frames rendered so far.
    frames_rendered: u64,
    techniques: Techniques,
}

/// One readback buffer per frame slot.
fn host_buffers(ctx: &Context, name: &str, size: u64) -> Result<Vec<Arc<Buffer>>> {
    Buffer::per_frame(
        ctx,
        BufferDesc {
            name: format!("{name} readback"),
            size,
            usage: BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuToCpu,
        },
    )
}

/// Declares `readback`: the view's images into per-frame host buffers.
fn declare_readback(ctx: &Context, graph: &mut RenderGraph<Frame>, targets: &SceneTargets) -> Result<Readback> {
    let pixels = u64::from(targets.width) * u64::from(targets.height);
    let mut copies = Vec::new();
    let rb = Readback {
        aovs: aov_readback::AovReadback::declare(ctx, graph, targets, &mut copies)?,
        hdr: host_buffers(ctx, "hdr", pixels * 16)?,
        depth: host_buffers(ctx, "depth", pixels * 4)?,
        ldr: host_buffers(ctx, "srgb", pixels * 4)?,
        visibility: host_buffers(ctx, "lighting visibility", pixels * 8)?,
        weight: match targets.weight {
            Some(_) => Some(host_buffers(ctx, "splat weight", pixels * 4)?),
            None => None,
        },
    };
    copies.extend([
        (targets.radiance, graph.import_buffers_per_frame(rb.hdr.clone())),
        (targets.view_depth, graph.import_buffers_per_frame(rb.depth.clone())),
        (targets.display, graph.import_buffers_per_frame(rb.ldr.clone())),
        (
            targets.visibility,
            graph.import_buffers_per_frame(rb.visibility.clone()),
        ),
    ]);
    if let (Some(image), Some(buffers)) = (targets.weight, &rb.weight) {
        copies.push((image, graph.import_buffers_per_frame(buffers.clone())));
    }
    graph.read_back_images("readback", copies);
    Ok(rb)
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
        validate_size(settings.width, settings.height)?;
        let (w, h) = (settings.width, settings.height);
        let max = ctx.max_image_dimension();
        if w > max || h > max {
            return Err(Error::invalid(
                "image size",
                format!("{w}×{h} exceeds the device limit of {max} per side"),
            ));
        }
        let mut graph = RenderGraph::new();
        // The view the graph is declared for; every frame brings its camera.
        let view = View::new(scene.default_camera(), w, h);
        let lighting = settings.lighting.unwrap_or_else(|| scene.default_lighting());
        lighting.validate()?;
        let mut targets = SceneTargets::declare(&mut graph, &view, !scene.points.is_empty());
        let mut scene_lighting = lighting::scene_lighting(scene, &targets);
        lighting::declare_atmosphere(ctx, &mut graph, (&view, &lighting), (&mut targets, &mut scene_lighting))?;
        if scene.draw_terrain {
            lighting::declare_sky_light(
                ctx,
                &mut graph,
                (scene, &lighting),
                (&mut targets, &mut scene_lighting),
                settings.cache_dir.as_deref(),
                progress,
            )?;
        }
        let sky = Sky::new(ctx, &targets.formats)?;
        sky.declare(&mut graph, (0, &view), &targets);
        let mut terrain = match scene.draw_terrain {
            true => Some(warped_terrain(ctx, &mut graph, scene, &settings, &view)?),
            false => None,
        };
        let mut points = match scene.points.is_empty() {
            true => None,
            false => Some(PointRenderer::new(ctx, &scene.points, settings.points)?),
        };
        // The atlas's generation passes before the shadow casters: validation
        // layers before 1.3.268 count their dispatches as writing every buffer
        // of the heap, the geometry image included, so the casters' barrier
        // must come after them.
        let atlas = match (&terrain, settings.texturing) {
            (Some(terrain), TexturingMode::Atlas) => Some(TextureAtlas::declare(
                ctx,
                &mut graph,
                terrain.generation_inputs(&scene.layers),
                settings.texture_streaming,
            )?),
            _ => None,
        };
        let shadows = lighting::declare_shadows(
            ctx,
            &mut graph,
            (&view, &mut targets),
            (terrain.as_ref(), points.as_ref()),
            settings.shadows,
        )?;
        if let Some(terrain) = &mut terrain {
            terrain.declare_draw(
                ctx,
                &mut graph,
                (0, &view),
                &targets,
                atlas.as_ref().map(|a| a.bindings()),
            )?;
        }
        if let Some(points) = &mut points {
            points.declare(ctx, &mut graph, (0, &view), &targets, !scene.draw_terrain)?;
        }
        let mut aovs = Aovs::new(ctx, &targets.formats)?;
        aovs.declare(&mut graph, (0, &view), &targets);
        let exposure = ExposureMeter::new(ctx)?.declare(&mut graph, &view, &targets);
        Tonemap::new(ctx)?.declare(&mut graph, &view, &targets, exposure);
        let readback = match settings.readback {
            true => Some(declare_readback(ctx, &mut graph, &targets)?),
            false => {
                graph.keep(targets.display);
                None
            }
        };
        let graph = graph.bake(ctx)?;
        Ok(Renderer {
            ctx: ctx.clone(),
            frames: FrameRing::new(ctx)?,
            graph,
            settings,
            readback,
            lighting,
            frames_rendered: 0,
            techniques: Techniques {
                lighting: scene_lighting,
                shadows,
                terrain,
                atlas,
                points,
                aovs,
            },
        })
    }

    /// The lighting of the next frames.
    pub fn lighting(&self) -> &Lighting {
        &self.lighting
    }

    /// Sets the lighting of the next frames (sun, sky model, exposure,
    /// shadows, sky light): checked here, so a bad value fails before any
    /// frame is recorded. The renderer must have been built with the parts
    /// the lighting uses (see [`RenderSettings::lighting`]).
    pub fn set_lighting(&mut self, lighting: Lighting) -> Result<()> {
        lighting.validate()?;
        self.lighting = lighting;
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

    /// Pass names in execution order.
    pub fn pass_names(&self) -> Vec<String> {
        self.graph.pass_names()
    }

    /// Prepares, records and submits a frame of `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<FrameOutcome> {
        camera.validate()?;
        let view = View::new(*camera, self.settings.width, self.settings.height);
        // The slot's previous frame must be done before prepare writes its uploads.
        let index = self.frames.wait_for_next()?;
        let mut frame = Frame::new(index, vec![view], self.lighting);
        let mut stages = Vec::new();
        let mut uploads = self.graph.uploads(index);
        let t = &mut self.techniques;
        if let Some(shadows) = &mut t.shadows {
            frame.prepare(&mut shadows.maps, &mut uploads, &mut stages)?;
            if let Some(points) = &mut shadows.points {
                frame.prepare(points, &mut uploads, &mut stages)?;
            }
        }
        // After the shadows: the constants carry their cascades.
        frame.prepare(&mut t.lighting, &mut uploads, &mut stages)?;
        if let Some(terrain) = &mut t.terrain {
            frame.prepare(terrain, &mut uploads, &mut stages)?;
        }
        if let Some(atlas) = &mut t.atlas {
            frame.prepare(atlas, &mut uploads, &mut stages)?;
        }
        if let Some(points) = &mut t.points {
            frame.prepare(points, &mut uploads, &mut stages)?;
        }
        frame.prepare(&mut t.aovs, &mut uploads, &mut stages)?;
        let outcome = self.graph.execute(&mut self.frames, &frame, &stages)?;
        self.frames_rendered = outcome.frame + 1;
        Ok(outcome)
    }

    /// Renders `camera` until every texture tile the view needs is ready
    /// (the atlas generates at most its budget per frame) and returns that
    /// frame; at most `max_frames` frames, then errors. Same as
    /// [`Renderer::render`] without the atlas.
    pub fn render_settled(&mut self, camera: &Camera, max_frames: u32) -> Result<FrameOutcome> {
        for _ in 0..max_frames.max(1) {
            let outcome = self.render(camera)?;
            match &self.techniques.atlas {
                Some(atlas) if atlas.last_deferred() > 0 => continue,
                _ => return Ok(outcome),
            }
        }
        Err(Error::invalid(
            "texture atlas",
            format!("tiles still missing after {max_frames} frames: raise the tile budget or the atlas size"),
        ))
    }

    /// Waits for `frame` and copies its images out of the readback buffers.
    /// Call before rendering [`FRAMES_IN_FLIGHT`] more frames.
    pub fn read(&mut self, frame: &FrameOutcome) -> Result<FrameImages> {
        let rb = self
            .readback
            .as_ref()
            .ok_or_else(|| Error::invalid("readback", "the renderer was created without readback"))?;
        if self.frames_rendered > frame.frame + FRAMES_IN_FLIGHT as u64 {
            return Err(Error::invalid(
                "readback",
                format!(
                    "frame {} was overwritten: read a frame before rendering {FRAMES_IN_FLIGHT} more",
                    frame.frame
                ),
            ));
        }
        self.ctx.wait(frame.timeline)?;
        let slot = frame.frame as usize % FRAMES_IN_FLIGHT;
        let floats = |b: &Buffer| -> Result<Vec<f32>> { Ok(bytemuck::pod_collect_to_vec(b.mapped()?)) };
        let aovs = rb.aovs.read(slot)?;
        Ok(FrameImages {
            width: self.settings.width,
            height: self.settings.height,
            rgba8: rb.ldr[slot].mapped()?.to_vec(),
            hdr: floats(&rb.hdr[slot])?,
            depth: floats(&rb.depth[slot])?,
            weight: match &rb.weight {
                Some(w) => Some(floats(&w[slot])?),
                None => None,
            },
            visibility: floats(&rb.visibility[slot])?,
            normal: aovs.normal,
            class: aovs.class,
            instance: aovs.instance,
            motion: aovs.motion,
            distance: aovs.distance,
        })
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
        Ok(self.graph.take_profiles())
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

    /// The texture page table of the last recorded frame (which atlas tile
    /// colours which part of the terrain); None unless texturing from the atlas.
    pub fn texture_page_table(&self) -> Result<Option<PageTable>> {
        Ok(self.techniques.atlas.as_ref().map(|a| a.page_table().clone()))
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

/// The terrain of `scene` with its `terrain.warp` declared.
fn warped_terrain(
    ctx: &Context,
    graph: &mut RenderGraph<Frame>,
    scene: &Scene,
    settings: &RenderSettings,
    view: &View,
) -> Result<Terrain> {
    let texturing = TerrainTexturing {
        mode: settings.texturing,
        layers: &scene.layers,
        input_maps: &scene.input_maps,
    };
    let field = Arc::new(scene.heights.clone());
    let mut terrain = Terrain::new(ctx, graph, field, settings.terrain, &texturing)?;
    terrain.declare_warp(ctx, graph, (0, view))?;
    Ok(terrain)
}
