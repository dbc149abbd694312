//! The one adapter between the Python bindings and the `alpenglow` crate.
//!
//! Every path into the library is imported here and nowhere else, so the
//! move to the crate's front door (`alpenglow::{Context, Scene, Renderer,
//! Settings, …}`) and to the non-blocking readback ring (`submit`,
//! `try_read`, `wait` with tickets) is an edit of this file only.
//!
//! Frames go through the renderer's readback ring: [`Engine::submit`]
//! records and submits a frame and returns its ticket; [`Engine::try_read`]
//! and [`Engine::wait`] copy the finished frame's planes out of the mapped
//! readback slot (one copy, converting f16 normals and de-interleaving the
//! ids; the `Vec`s of [`FrameImages`] become the NumPy arrays' memory).

use std::collections::VecDeque;
use std::path::Path;

pub use alpenglow::files::{check_spacing, load_heightmap, InputLimits};
use alpenglow::files::{encode_exr_height, encode_exr_samples, encode_png_rgba8, write_bytes_atomically, ExrSamples};
use alpenglow::files::{write_pyramid, FieldRows, PyramidOptions};
pub use alpenglow::files::{DEFAULT_DETAIL_WINDOW, DEFAULT_HEIGHT_STEP, DEFAULT_RESIDENT_SIDE, DEFAULT_TILE_SIDE};
pub use alpenglow::tools::solar::{parse_date, parse_time, solar_position, Clock};
pub use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, Distortion, Error, Exposure, FrameImages, HeightField,
    HeightmapOptions, Intrinsics, Lighting, ProceduralTerrain, RasterPath, Renderer, Result, Rig, RowOrder, Scene,
    Settings, ShadowMode, SkyLightMode, SkyModel, SunDisc, SunPosition, TerrainModel, TexturingMode, VegetationOptions,
    ViewSpec,
};
use alpenglow::{FrameData, Output, Ticket as RingTicket, ViewData};

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
    write_bytes_atomically(path, &bytes)
}

/// A scene streamed from the height pyramid at `path` (`.hpyr`): its
/// finest level with at most `resident_side` samples a side resident, a
/// detail window of `detail_window` samples (0: none) of a finer level
/// around the camera; frames wait for the window's tiles (deterministic).
pub fn scene_from_pyramid(path: &Path, resident_side: u32, detail_window: u32) -> Result<Scene> {
    Scene::from_pyramid_file(path, resident_side, detail_window)
}

/// Writes a height field as a tiled, compressed, checksummed pyramid
/// (what `alpenglow dem import` writes) and returns its level count.
pub fn write_height_pyramid(path: &Path, field: &HeightField, tile_side: u32, height_step: f64) -> Result<u32> {
    let options = PyramidOptions { tile_side, height_step };
    let summary = write_pyramid(path, &mut FieldRows::new(field, path), &options)?;
    Ok(summary.levels)
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
    write_bytes_atomically(path, bytes)
}

/// Submitted frames whose tickets are remembered (their readback slots were
/// reused long before).
const REMEMBERED_FRAMES: usize = 64;

/// One view of a rig (the fields of a rig file's `[[view]]` table).
#[derive(Clone, Debug, Default)]
pub struct RigViewParams {
    pub name: String,
    /// Metres along (forward, left, up) of the rig camera.
    pub position: [f64; 3],
    pub yaw_pitch_roll: [f64; 3],
    pub fov_y: Option<f64>,
    pub intrinsics: Option<Intrinsics>,
    pub distortion: Option<Distortion>,
    pub size: Option<(u32, u32)>,
    pub near: Option<f64>,
    pub far: Option<f64>,
}

/// The rig of `views`, checked the way a rig file is (its text is one:
/// the front door builds rigs from files).
pub fn rig_from_views(views: &[RigViewParams]) -> Result<Rig> {
    use std::fmt::Write;
    let mut text = String::new();
    let num = |v: f64| -> Result<String> {
        match v.is_finite() {
            true => Ok(format!("{v:?}")),
            false => Err(Error::invalid("view", format!("{v}; numbers must be finite"))),
        }
    };
    for v in views {
        let mut line = |key: &str, value: String| {
            let _ = writeln!(text, "{key} = {value}");
        };
        line("[[view]]\nname", format!("{:?}", v.name));
        let triple =
            |a: [f64; 3]| -> Result<String> { Ok(format!("[{}, {}, {}]", num(a[0])?, num(a[1])?, num(a[2])?)) };
        line("position", triple(v.position)?);
        line("yaw_pitch_roll", triple(v.yaw_pitch_roll)?);
        if let Some(f) = v.fov_y {
            line("fov_y", num(f)?);
        }
        if let Some(k) = v.intrinsics {
            for (key, value) in [("fx", k.fx), ("fy", k.fy), ("cx", k.cx), ("cy", k.cy)] {
                line(key, num(value)?);
            }
        }
        if let Some(d) = v.distortion {
            for (key, value) in [("k1", d.k1), ("k2", d.k2), ("k3", d.k3), ("p1", d.p1), ("p2", d.p2)] {
                line(key, num(value)?);
            }
        }
        if let Some((w, h)) = v.size {
            line("width", w.to_string());
            line("height", h.to_string());
        }
        if let Some(n) = v.near {
            line("near", num(n)?);
        }
        if let Some(f) = v.far {
            line("far", num(f)?);
        }
    }
    let rig = Rig::parse(&text, Path::new("rig"))?;
    rig.specs((1, 1))?;
    Ok(rig)
}

/// A submitted frame's handle.
pub type Ticket = u64;

/// A renderer with the frames it has submitted but not yet handed out.
pub struct Engine {
    renderer: Renderer,
    /// The latest submitted frames (more than any readback ring keeps).
    pending: VecDeque<(Ticket, RingTicket)>,
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

    /// Submits one frame of `cameras` (one per view) without waiting for
    /// the GPU; read it with [`Engine::try_read`] or [`Engine::wait`]
    /// before `readback_slots` more frames are submitted.
    pub fn submit(&mut self, cameras: &[Camera]) -> Result<Ticket> {
        let frame = self.renderer.submit(cameras)?;
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        if self.pending.len() == REMEMBERED_FRAMES {
            self.pending.pop_front();
        }
        self.pending.push_back((ticket, frame));
        Ok(ticket)
    }

    fn ring_ticket(&self, ticket: Ticket) -> Result<RingTicket> {
        let (_, frame) = *self.pending.iter().find(|(t, _)| *t == ticket).ok_or_else(|| {
            Error::invalid(
                "ticket",
                format!("{ticket} is not a frame of this renderer (or too old to remember)"),
            )
        })?;
        Ok(frame)
    }

    /// The views of `ticket` once the GPU is done, or an error when the
    /// ticket is unknown or its readback slot was reused by later frames
    /// (never stale data). A ticket may be read again until then.
    pub fn wait(&mut self, ticket: Ticket) -> Result<Vec<FrameImages>> {
        let frame = self.ring_ticket(ticket)?;
        owned(&self.renderer.wait(frame)?)
    }

    /// [`Engine::wait`], or `None` while the GPU is still busy with the
    /// frame (never blocks).
    pub fn try_read(&mut self, ticket: Ticket) -> Result<Option<Vec<FrameImages>>> {
        let frame = self.ring_ticket(ticket)?;
        self.renderer.try_read(frame)?.map(|data| owned(&data)).transpose()
    }

    /// Drains the GPU (the profiles are dropped).
    pub fn finish(&mut self) -> Result<()> {
        self.renderer.finish().map(drop)
    }
}

/// A frame's views copied out of the readback slot (the one copy).
fn owned(data: &FrameData<'_>) -> Result<Vec<FrameImages>> {
    data.views().map(|view| owned_view(&view)).collect()
}

fn owned_view(view: &ViewData<'_>) -> Result<FrameImages> {
    let pixels = view.width() as usize * view.height() as usize;
    let floats = |output: Output| -> Result<Vec<f32>> {
        let mut values = vec![0.0; pixels * output.channels()];
        view.plane(output)?.copy_into_f32(&mut values)?;
        Ok(values)
    };
    let ids = |output: Output| -> Result<Vec<u32>> {
        let mut values = vec![0; pixels];
        view.plane(output)?.copy_into_u32(&mut values)?;
        Ok(values)
    };
    let mut rgba8 = vec![0; pixels * 4];
    view.copy_into(Output::Rgba8, &mut rgba8)?;
    Ok(FrameImages {
        name: view.name().to_string(),
        width: view.width(),
        height: view.height(),
        rgba8,
        hdr: floats(Output::Hdr)?,
        depth: floats(Output::Depth)?,
        weight: match view.outputs().contains(Output::Weight) {
            true => Some(floats(Output::Weight)?),
            false => None,
        },
        visibility: floats(Output::Visibility)?,
        normal: floats(Output::Normal)?,
        class: ids(Output::Class)?,
        instance: ids(Output::Instance)?,
        motion: floats(Output::Motion)?,
        distance: floats(Output::Distance)?,
    })
}
