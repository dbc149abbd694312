//! The renderer: builds the frame graph of a scene once, then renders views
//! of it, headless, into HDR radiance, view-space depth and tone-mapped sRGB.
//!
//! Frame graph of the default scene:
//! `sky` (graphics) → `terrain.warp` (compute: CPU warp of the sketch map,
//! then warp and zoom on the GPU into the vertex buffer, §7.4) →
//! `terrain.draw` (graphics, reads the vertex buffer) → the points passes
//! (`points.visibility` → `points.accumulate` → `points.normalize` for EWA
//! splats, or `points.opaque`; see [`crate::points::render`]) → `tonemap`
//! (compute) → `readback` (transfer).

pub mod scene;

use std::sync::Arc;

use glam::Vec3;

pub use crate::view::{Camera, FrameParams};
pub use scene::Scene;

use crate::error::{Error, Result};
use crate::graph::{Access, BakedGraph, FrameOutcome, ImageInfo, RenderGraph};
use crate::lighting::sky::add_sky_pass;
use crate::points::render::{add_point_passes, PointFrameStats, PointPasses, SplatSettings, SplatTargets};
use crate::profile::FrameProfile;
use crate::terrain::geometry_image::{GeometryImage, TerrainSettings};
use crate::terrain::shading::{add_draw_pass, TerrainTexturing};
use crate::texturing::generation::{AtlasResources, TextureFrameStats, TextureStreaming};
use crate::texturing::gpu_layout::TexturingMode;
use crate::texturing::page_table::PageTable;
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, Context, Format, FrameRing, MemoryLocation, FRAMES_IN_FLIGHT,
};

/// Largest accepted image side (the device limit may be lower).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Output size, whether frames are read back to the host, and the
/// terrain's LOD and detail settings.
#[derive(Clone, Copy, Debug)]
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
}

struct Readback {
    hdr: Vec<Arc<Buffer>>,
    depth: Vec<Arc<Buffer>>,
    ldr: Vec<Arc<Buffer>>,
    weight: Option<Vec<Arc<Buffer>>>,
}

/// Renders one scene, frame after frame.
pub struct Renderer {
    ctx: Context,
    frames: FrameRing,
    graph: BakedGraph<FrameParams>,
    settings: RenderSettings,
    readback: Option<Readback>,
    scene_sun: Vec3,
    snow_line: f32,
    /// Frames rendered so far.
    frames_rendered: u64,
    /// Point passes' statistics (None without points).
    points: Option<PointPasses>,
    /// The texture atlas's statistics (None unless texturing from the atlas).
    atlas: Option<AtlasResources>,
    /// Kept alive for the graph's imported resources.
    _terrain: Option<GeometryImage>,
}

/// Checks an output size.
pub fn validate_size(width: u32, height: u32) -> Result<()> {
    for (what, v) in [("--width", width), ("--height", height)] {
        if v == 0 || v > MAX_IMAGE_SIDE {
            return Err(Error::invalid(what, format!("{v}; must be in 1..={MAX_IMAGE_SIDE}")));
        }
    }
    Ok(())
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

impl Renderer {
    /// Uploads the scene and bakes its frame graph.
    pub fn new(ctx: &Context, scene: &Scene, settings: RenderSettings) -> Result<Renderer> {
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
        let hdr = graph.create_image("hdr radiance", ImageInfo::new(w, h, Format::R32G32B32A32_SFLOAT));
        let view_depth = graph.create_image("view depth", ImageInfo::new(w, h, Format::R32_SFLOAT));
        let depth = graph.create_image("depth buffer", ImageInfo::new(w, h, Format::D32_SFLOAT));
        let ldr = graph.create_image("srgb", ImageInfo::new(w, h, Format::R8G8B8A8_UNORM));

        add_sky_pass(ctx, &mut graph, hdr, view_depth)?;
        let (terrain, atlas) = if scene.draw_terrain {
            let terrain = GeometryImage::new(ctx, Arc::new(scene.heights.clone()), settings.terrain)?;
            let terrain_resources = terrain.add_warp_pass(ctx, &mut graph)?;
            let atlas = add_draw_pass(
                ctx,
                &mut graph,
                &terrain,
                terrain_resources,
                (hdr, view_depth, depth),
                h,
                &TerrainTexturing {
                    mode: settings.texturing,
                    layers: &scene.layers,
                    streaming: settings.texture_streaming,
                    input_maps: &scene.input_maps,
                },
            )?;
            (Some(terrain), atlas)
        } else {
            (None, None)
        };
        let (points, weight) = if scene.points.is_empty() {
            (None, None)
        } else {
            let weight = graph.create_image("splat weight", ImageInfo::new(w, h, Format::R32_SFLOAT));
            let targets = SplatTargets {
                radiance: hdr,
                view_depth,
                depth,
                weight,
                clear_depth: !scene.draw_terrain,
            };
            let passes = add_point_passes(ctx, &mut graph, &scene.points, settings.points, targets, (w, h))?;
            (Some(passes), Some(weight))
        };
        crate::post::tonemap::add_tonemap_pass(ctx, &mut graph, hdr, ldr, (w, h))?;

        let pixels = w as u64 * h as u64;
        let readback = if settings.readback {
            let rb = Readback {
                hdr: host_buffers(ctx, "hdr", pixels * 16)?,
                depth: host_buffers(ctx, "depth", pixels * 4)?,
                ldr: host_buffers(ctx, "srgb", pixels * 4)?,
                weight: match weight {
                    Some(_) => Some(host_buffers(ctx, "splat weight", pixels * 4)?),
                    None => None,
                },
            };
            let mut copies = vec![
                (hdr, graph.import_buffers_per_frame(rb.hdr.clone())),
                (view_depth, graph.import_buffers_per_frame(rb.depth.clone())),
                (ldr, graph.import_buffers_per_frame(rb.ldr.clone())),
            ];
            if let (Some(image), Some(buffers)) = (weight, &rb.weight) {
                copies.push((image, graph.import_buffers_per_frame(buffers.clone())));
            }
            let mut pass = graph.pass("readback").transfer();
            for &(image, buffer) in &copies {
                pass = pass.read(image, Access::TransferSrc).write(buffer, Access::TransferDst);
            }
            let recorded = copies.clone();
            pass.record(move |pass, _| {
                let pairs = recorded
                    .iter()
                    .map(|&(i, b)| Ok((pass.image(i)?, pass.buffer(b)?)))
                    .collect::<Result<Vec<_>>>()?;
                for (image, buffer) in pairs {
                    pass.cmd().copy_image_to_buffer(image, buffer);
                }
                Ok(())
            });
            for &(_, buffer) in &copies {
                graph.read_back(buffer);
            }
            Some(rb)
        } else {
            graph.keep(ldr);
            None
        };
        let graph = graph.bake(ctx)?;
        let (lo, hi) = scene.height_range();
        Ok(Renderer {
            ctx: ctx.clone(),
            frames: FrameRing::new(ctx)?,
            graph,
            settings,
            readback,
            scene_sun: scene.sun_direction,
            snow_line: lo + (hi - lo) * 0.8,
            frames_rendered: 0,
            points,
            atlas,
            _terrain: terrain,
        })
    }

    /// The context the renderer draws with.
    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// Pass names in execution order.
    pub fn pass_names(&self) -> Vec<String> {
        self.graph.pass_names()
    }

    /// Records and submits a frame of `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<FrameOutcome> {
        camera.validate()?;
        let params = FrameParams {
            camera: *camera,
            aspect: self.settings.width as f64 / self.settings.height as f64,
            sun: self.scene_sun,
            exposure: 1.0,
            snow_line: self.snow_line,
        };
        let outcome = self.graph.execute(&mut self.frames, &params)?;
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
            match &self.atlas {
                Some(atlas) if atlas.last_deferred()? > 0 => continue,
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
        })
    }

    /// Waits for `frame` and copies the colour atlas textures (sRGB-encoded
    /// RGBA8, `atlas size²` texels each, in texture order) out of their
    /// readback buffers; needs [`TextureStreaming::readback`]. Same
    /// frames-in-flight rule as [`Renderer::read`].
    pub fn read_texture_atlas(&mut self, frame: &FrameOutcome) -> Result<Vec<Vec<u8>>> {
        let buffers = (self.atlas.as_ref().and_then(|a| a.readback.as_ref()))
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
        match &self.atlas {
            Some(a) => a.take_stats(),
            None => Ok(Vec::new()),
        }
    }

    /// The texture page table of the last recorded frame (which atlas tile
    /// colours which part of the terrain); None unless texturing from the atlas.
    pub fn texture_page_table(&self) -> Result<Option<PageTable>> {
        self.atlas.as_ref().map(AtlasResources::page_table).transpose()
    }

    /// Point statistics of the frames completed so far and not yet taken
    /// (complete after [`Renderer::finish`]); empty without point objects.
    pub fn take_point_stats(&mut self) -> Result<Vec<PointFrameStats>> {
        self.graph.finish(&mut self.frames)?;
        match &self.points {
            Some(p) => p.take_stats(),
            None => Ok(Vec::new()),
        }
    }
}
