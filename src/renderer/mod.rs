//! The renderer: builds the frame graph of a scene once, then renders views
//! of it, headless, into HDR radiance, view-space depth and tone-mapped sRGB.
//!
//! Frame graph of the default scene:
//! `sky` (graphics) → `terrain.warp` (compute: CPU warp of the sketch map,
//! then warp and zoom on the GPU into the vertex buffer, §7.4) →
//! `terrain.draw` (graphics, reads the vertex buffer) → `tonemap` (compute)
//! → `readback` (transfer).

pub mod camera;
pub mod camera_path;
pub mod scene;
pub mod tonemap;

use std::sync::Arc;

use glam::Vec3;

pub use camera::Camera;
pub use scene::Scene;

use crate::error::{Error, Result};
use crate::graph::{Access, BakedGraph, FrameOutcome, ImageInfo, RenderGraph};
use crate::lighting::sky::add_sky_pass;
use crate::profile::FrameProfile;
use crate::terrain::geometry_image::{GeometryImage, TerrainSettings};
use crate::terrain::shading::add_draw_pass;
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, Context, Format, FrameRing, MemoryLocation, FRAMES_IN_FLIGHT,
};

/// Largest accepted image side (the device limit may be lower).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// What every pass of a frame may read: the view and the lighting.
#[derive(Clone, Copy, Debug)]
pub struct FrameParams {
    pub camera: Camera,
    /// Width / height.
    pub aspect: f64,
    /// Unit direction towards the sun.
    pub sun: Vec3,
    /// Multiplier applied to radiance before tone mapping.
    pub exposure: f32,
    /// Altitude (m) above which flat ground is snow-covered.
    pub snow_line: f32,
}

/// Output size, whether frames are read back to the host, and the
/// terrain's LOD and detail settings.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Copy HDR, depth and sRGB images to host memory every frame.
    pub readback: bool,
    pub terrain: TerrainSettings,
}

impl RenderSettings {
    /// `width`×`height` with readback and the default terrain settings.
    pub fn new(width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            readback: true,
            terrain: TerrainSettings::default(),
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
}

struct Readback {
    hdr: Vec<Arc<Buffer>>,
    depth: Vec<Arc<Buffer>>,
    ldr: Vec<Arc<Buffer>>,
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
    /// Kept alive for the graph's imported resources.
    _terrain: GeometryImage,
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

fn host_buffers(ctx: &Context, name: &str, size: u64) -> Result<Vec<Arc<Buffer>>> {
    (0..FRAMES_IN_FLIGHT)
        .map(|i| {
            Buffer::new(
                ctx,
                BufferDesc {
                    name: format!("{name} readback {i}"),
                    size,
                    usage: BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuToCpu,
                },
            )
            .map(Arc::new)
        })
        .collect()
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
        let terrain = GeometryImage::new(ctx, Arc::new(scene.heights.clone()), settings.terrain)?;
        let mut graph = RenderGraph::new();
        let hdr = graph.create_image("hdr radiance", ImageInfo::new(w, h, Format::R32G32B32A32_SFLOAT));
        let view_depth = graph.create_image("view depth", ImageInfo::new(w, h, Format::R32_SFLOAT));
        let depth = graph.create_image("depth buffer", ImageInfo::new(w, h, Format::D32_SFLOAT));
        let ldr = graph.create_image("srgb", ImageInfo::new(w, h, Format::R8G8B8A8_UNORM));

        add_sky_pass(ctx, &mut graph, hdr, view_depth)?;
        let terrain_resources = terrain.add_warp_pass(ctx, &mut graph)?;
        add_draw_pass(
            ctx,
            &mut graph,
            &terrain,
            terrain_resources,
            (hdr, view_depth, depth),
            h,
        )?;
        tonemap::add_tonemap_pass(ctx, &mut graph, hdr, ldr, (w, h))?;

        let pixels = w as u64 * h as u64;
        let readback = if settings.readback {
            let rb = Readback {
                hdr: host_buffers(ctx, "hdr", pixels * 16)?,
                depth: host_buffers(ctx, "depth", pixels * 4)?,
                ldr: host_buffers(ctx, "srgb", pixels * 4)?,
            };
            let hdr_rb = graph.import_buffers_per_frame(rb.hdr.clone());
            let depth_rb = graph.import_buffers_per_frame(rb.depth.clone());
            let ldr_rb = graph.import_buffers_per_frame(rb.ldr.clone());
            graph
                .pass("readback")
                .transfer()
                .read(hdr, Access::TransferSrc)
                .read(view_depth, Access::TransferSrc)
                .read(ldr, Access::TransferSrc)
                .write(hdr_rb, Access::TransferDst)
                .write(depth_rb, Access::TransferDst)
                .write(ldr_rb, Access::TransferDst)
                .record(move |pass, _| {
                    let copies = [(hdr, hdr_rb), (view_depth, depth_rb), (ldr, ldr_rb)];
                    let pairs = copies
                        .iter()
                        .map(|&(i, b)| Ok((pass.image(i)?, pass.buffer(b)?)))
                        .collect::<Result<Vec<_>>>()?;
                    for (image, buffer) in pairs {
                        pass.cmd().copy_image_to_buffer(image, buffer);
                    }
                    Ok(())
                });
            for r in [hdr_rb, depth_rb, ldr_rb] {
                graph.read_back(r);
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
        })
    }

    /// Waits for all frames and returns the timings of those not yet taken.
    pub fn finish(&mut self) -> Result<Vec<FrameProfile>> {
        self.graph.finish(&mut self.frames)?;
        Ok(self.graph.take_profiles())
    }
}
