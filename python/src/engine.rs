//! The one adapter between the Python bindings and the `alpenglow` crate.
//!
//! Every path into the library is imported here and nowhere else, so the
//! move to the crate's front door (`alpenglow::{Context, Scene, Renderer,
//! Settings, …}`) and to the non-blocking readback ring (`submit`,
//! `try_read`, `wait` with tickets) is an edit of this file only.
//!
//! Today the frames are rendered with the blocking `Renderer::render_views`
//! and read with `Renderer::read_views`: [`Engine::submit`] records and
//! submits a frame and returns its ticket; [`Engine::wait`] waits for the
//! GPU and copies the frame out of the mapped readback buffers (one copy:
//! the `Vec`s of [`FrameImages`] become the NumPy arrays' memory).

use std::collections::VecDeque;
use std::path::Path;

pub use alpenglow::io::heightmap::{check_spacing, load_heightmap, HeightField, HeightmapOptions, RowOrder};
pub use alpenglow::io::limits::InputLimits;
pub use alpenglow::lighting::solar::{parse_date, parse_time, solar_position, Clock};
pub use alpenglow::points::vegetation::VegetationOptions;
pub use alpenglow::renderer::{Camera, FrameImages, RenderSettings as Settings, Renderer, Rig, Scene, ViewSpec};
pub use alpenglow::terrain::procedural::{ProceduralTerrain, TerrainModel};
pub use alpenglow::texturing::gpu_layout::TexturingMode;
pub use alpenglow::view::lens::Distortion;
pub use alpenglow::view::rig::{RigLens, RigPose, RigView};
pub use alpenglow::view::{Exposure, Intrinsics, Lighting, ShadowMode, SkyLightMode, SkyModel, SunPosition};
pub use alpenglow::vulkan::{Context, ContextOptions, DeviceSelector};
pub use alpenglow::{Error, Result};

use alpenglow::graph::FrameOutcome;
use alpenglow::io::image_out::{encode_exr_height, encode_exr_samples, encode_png_rgba8, ExrSamples};

/// Frames rendered in a row, at most, while the texture atlas settles
/// (the CLI's bound).
pub const MAX_SETTLE_FRAMES: u32 = 64;

/// A height field of `columns`×`rows` samples, row 0 at y = 0, as a
/// scene; `heights` is checked (finite, within the library's range) and
/// its errors name `heights`.
pub fn scene_from_heights(heights: Vec<f32>, columns: u32, rows: u32, spacing: (f64, f64)) -> Result<Scene> {
    let field = HeightField {
        columns,
        rows,
        spacing: glam::DVec2::new(spacing.0, spacing.1),
        heights,
    };
    field.validate(Path::new("heights"))?;
    Ok(Scene::new(field))
}

/// A procedural terrain (`model`: fbm, multifractal, heterogeneous,
/// hybrid or ridged with the library's default parameters) of
/// `size`×`size` samples `spacing` metres apart.
pub fn scene_procedural(model: &str, seed: u64, size: u32, spacing: f64) -> Result<Scene> {
    let model = TerrainModel::from_name(model).ok_or_else(|| {
        let names: Vec<&str> = TerrainModel::ALL.iter().map(|m| m.name()).collect();
        Error::invalid("model", format!("{model:?}; expected one of {}", names.join(", ")))
    })?;
    let terrain = ProceduralTerrain {
        model,
        seed,
        ..ProceduralTerrain::default()
    };
    let field = terrain.try_generate(size, size, glam::DVec2::splat(spacing))?;
    Ok(Scene::new(field))
}

/// Writes `heights` (`columns`×`rows`, row 0 first) as a one-channel
/// float EXR height map that [`load_heightmap`] reads back exactly
/// (south-up rows), atomically.
pub fn write_heightmap(path: &Path, heights: &[f32], columns: u32, rows: u32) -> Result<()> {
    let bytes = encode_exr_height(heights, columns, rows)?;
    alpenglow::io::atomic::write_bytes_atomically(path, &bytes)
}

/// The PNG of an sRGB RGBA8 image (the CLI's encoder).
pub fn encode_png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    encode_png_rgba8(rgba, width, height)
}

/// One extra channel of a frame's EXR.
pub enum ExrPlane {
    F32(Vec<f32>),
    /// Exact integer ids (`UINT` channels).
    U32(Vec<u32>),
}

/// The OpenEXR file of a frame: linear `R,G,B,A` (`hdr`), `Z` (`depth`)
/// and the extra channels in order (the CLI's `--exr` writer).
pub fn encode_exr(size: (u32, u32), hdr: &[f32], depth: &[f32], planes: &[(&str, ExrPlane)]) -> Result<Vec<u8>> {
    let extra: Vec<(&str, ExrSamples<'_>)> = planes
        .iter()
        .map(|(name, plane)| match plane {
            ExrPlane::F32(v) => (*name, ExrSamples::F32(v)),
            ExrPlane::U32(v) => (*name, ExrSamples::U32(v)),
        })
        .collect();
    encode_exr_samples(size, (hdr, depth), &extra)
}

/// Writes `bytes` to `path` atomically (a temporary file renamed over it).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    alpenglow::io::atomic::write_bytes_atomically(path, bytes)
}

/// Submitted frames whose tickets are remembered (their readback slots were
/// reused long before).
const REMEMBERED_FRAMES: usize = 64;

/// A submitted frame's handle.
pub type Ticket = u64;

/// A renderer with the frames it has submitted but not yet handed out.
pub struct Engine {
    renderer: Renderer,
    /// The latest submitted frames (more than any readback ring keeps).
    pending: VecDeque<(Ticket, FrameOutcome)>,
    next_ticket: Ticket,
}

impl Engine {
    pub fn new(ctx: &Context, scene: &Scene, settings: Settings) -> Result<Engine> {
        Ok(Engine {
            renderer: Renderer::new(ctx, scene, settings)?,
            pending: VecDeque::with_capacity(REMEMBERED_FRAMES),
            next_ticket: 1,
        })
    }

    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    pub fn set_lighting(&mut self, lighting: Lighting) -> Result<()> {
        self.renderer.set_lighting(lighting)
    }

    /// Renders `cameras` (one per view) until the texture atlas settled and
    /// reads every view.
    pub fn render_settled(&mut self, cameras: &[Camera]) -> Result<Vec<FrameImages>> {
        let frame = self.renderer.render_views_settled(cameras, MAX_SETTLE_FRAMES)?;
        self.renderer.read_views(&frame)
    }

    /// Submits one frame of `cameras` (one per view); read it with
    /// [`Engine::wait`] before several more frames are submitted.
    pub fn submit(&mut self, cameras: &[Camera]) -> Result<Ticket> {
        let frame = self.renderer.render_views(cameras)?;
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        if self.pending.len() == REMEMBERED_FRAMES {
            self.pending.pop_front();
        }
        self.pending.push_back((ticket, frame));
        Ok(ticket)
    }

    /// The views of `ticket` once the GPU is done (blocking today), or an
    /// error when the ticket is unknown or its readback slot was reused by
    /// later frames (never stale data). A ticket may be read again until then.
    pub fn wait(&mut self, ticket: Ticket) -> Result<Vec<FrameImages>> {
        let (_, frame) = *self.pending.iter().find(|(t, _)| *t == ticket).ok_or_else(|| {
            Error::invalid(
                "ticket",
                format!("{ticket} is not a frame of this renderer (or too old to remember)"),
            )
        })?;
        self.renderer.read_views(&frame)
    }

    /// [`Engine::wait`], or `None` while the GPU is still busy with the
    /// frame. Today's renderer has no non-blocking query: this waits.
    pub fn try_read(&mut self, ticket: Ticket) -> Result<Option<Vec<FrameImages>>> {
        self.wait(ticket).map(Some)
    }

    /// Drains the GPU (the profiles are dropped).
    pub fn finish(&mut self) -> Result<()> {
        self.renderer.finish().map(drop)
    }
}
