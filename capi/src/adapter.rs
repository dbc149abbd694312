//! The only file of the C layer that names alpenglow's Rust API.
//!
//! It uses the crate's front door (`alpenglow::{Scene, Renderer, Settings,
//! Camera, …}`): the blocking `ag_renderer_render` renders a settled frame
//! and reads it (`Renderer::read_view`); the non-blocking pair goes through
//! the readback ring (`Renderer::{submit, try_read, wait}`, copying each
//! requested output of the borrowed `FrameData` straight into the caller's
//! buffer).

use std::collections::VecDeque;
use std::path::Path;

pub use alpenglow::Settings as RenderSettings;
pub use alpenglow::{Camera, Context, ContextOptions, DeviceSelector, Error, FrameImages, Renderer, Scene};

use alpenglow::glam::DVec3;
use alpenglow::{HeightmapOptions, RowOrder};

use crate::status::{Failure, Outcome};

/// How many submitted tickets are remembered for `poll`/`wait`: more than
/// the ring's most slots, so that the renderer (not this list) decides
/// when a frame was overwritten.
const REMEMBERED_FRAMES: usize = 32;

/// A height field from a caller's row-major samples (row 0 at y = 0),
/// checked: at least 2×2, `columns·rows` samples, spacing in range, every
/// height finite. Errors name `heights` or `spacing`.
pub fn scene_from_heights(heights: &[f32], columns: u32, rows: u32, spacing: (f64, f64)) -> Outcome<Scene> {
    Ok(Scene::from_heights(heights, columns, rows, spacing)?)
}

/// How a height-map file's values become metres (see `ag_heightmap_options`).
pub struct FileOptions {
    pub scale: f32,
    pub offset: f32,
    /// None: from the file's georeferencing, else 1 m.
    pub spacing: Option<(f64, f64)>,
    pub north_up: bool,
}

/// A scene from a height-map file (PNG, EXR, GeoTIFF, `.hgt`).
pub fn scene_from_file(path: &Path, options: &FileOptions) -> Outcome<Scene> {
    let options = HeightmapOptions {
        scale: options.scale,
        offset: options.offset,
        spacing: options.spacing.map(|(x, y)| alpenglow::glam::DVec2::new(x, y)),
        rows: match options.north_up {
            true => RowOrder::NorthUp,
            false => RowOrder::SouthUp,
        },
        ..HeightmapOptions::default()
    };
    Ok(Scene::from_file(path, &options)?)
}

/// A scene streamed from a height pyramid (`.hpyr`): the finest level
/// with at most `resident_side` samples a side resident, a detail window
/// of `detail_window` samples (0: none); frames wait for its tiles.
pub fn scene_from_pyramid(path: &Path, resident_side: u32, detail_window: u32) -> Outcome<Scene> {
    Ok(Scene::from_pyramid_file(path, resident_side, detail_window)?)
}

/// The ground's height at `(x, y)` as drawn (streamed scenes: from the
/// pyramid's finest level).
pub fn ground_height(scene: &Scene, x: f64, y: f64) -> Outcome<f64> {
    Ok(scene.ground_height(x, y)?)
}

/// A `size`² procedural terrain of `model` ("fbm", "multifractal",
/// "heterogeneous", "hybrid", "ridged") with `seed`, `spacing` metres apart.
pub fn scene_procedural(model: &str, seed: u32, size: u32, spacing: f64) -> Outcome<Scene> {
    Ok(Scene::procedural(model, seed, size, spacing)?)
}

/// Adds `count` procedural boulders.
pub fn add_rocks(scene: &mut Scene, count: usize) -> Outcome {
    Ok(scene.add_rocks(count)?)
}

/// A camera from plain numbers (checked when a frame is rendered).
pub fn camera(eye: [f64; 3], target: [f64; 3], up: [f64; 3], fov_y_deg: f64, near: f64, far: f64) -> Camera {
    Camera {
        eye: DVec3::from_array(eye),
        target: target.into(),
        up: up.into(),
        fov_y_deg,
        near,
        far,
    }
}

/// `(eye, target, up, fov_y_deg, near, far)` of `camera`.
pub fn camera_parts(camera: &Camera) -> ([f64; 3], [f64; 3], [f64; 3], f64, f64, f64) {
    (
        camera.eye.to_array(),
        camera.target.to_array(),
        camera.up.to_array(),
        camera.fov_y_deg,
        camera.near,
        camera.far,
    )
}

/// The renderer's settings from the C settings' values.
/// `readback_slots` 0 keeps the library's default ring size.
pub fn render_settings(
    width: u32,
    height: u32,
    msaa: u32,
    terrain_detail: bool,
    readback_slots: u32,
) -> RenderSettings {
    let mut settings = RenderSettings::new(width, height);
    if readback_slots != 0 {
        settings.readback_slots = readback_slots as usize;
    }
    settings.msaa = msaa;
    settings.terrain.detail = terrain_detail;
    settings
}

/// The outputs a frame hands to C, in `ag_output` order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    Rgba8,
    Hdr,
    Depth,
    Distance,
    Normal,
    Class,
    Instance,
    Motion,
}

impl Output {
    pub const ALL: [Output; 8] = [
        Output::Rgba8,
        Output::Hdr,
        Output::Depth,
        Output::Distance,
        Output::Normal,
        Output::Class,
        Output::Instance,
        Output::Motion,
    ];

    /// Bytes per pixel in the caller's buffer.
    pub fn pixel_bytes(self) -> usize {
        match self {
            Output::Rgba8 | Output::Depth | Output::Distance | Output::Class | Output::Instance => 4,
            Output::Motion => 8,
            Output::Normal => 12,
            Output::Hdr => 16,
        }
    }

    /// The library's output.
    pub fn library(self) -> alpenglow::Output {
        match self {
            Output::Rgba8 => alpenglow::Output::Rgba8,
            Output::Hdr => alpenglow::Output::Hdr,
            Output::Depth => alpenglow::Output::Depth,
            Output::Distance => alpenglow::Output::Distance,
            Output::Normal => alpenglow::Output::Normal,
            Output::Class => alpenglow::Output::Class,
            Output::Instance => alpenglow::Output::Instance,
            Output::Motion => alpenglow::Output::Motion,
        }
    }

    /// The name of the output's field in `ag_frame_buffers`.
    pub fn field(self) -> &'static str {
        match self {
            Output::Rgba8 => "rgba8",
            Output::Hdr => "hdr",
            Output::Depth => "depth",
            Output::Distance => "distance",
            Output::Normal => "normal",
            Output::Class => "class_id",
            Output::Instance => "instance_id",
            Output::Motion => "motion",
        }
    }
}

/// One read frame's view, as bytes per output.
pub struct ViewImages(FrameImages);

impl ViewImages {
    /// The bytes of `output`, `pixel_bytes` per pixel, row 0 at the top.
    pub fn bytes(&self, output: Output) -> &[u8] {
        let images = &self.0;
        match output {
            Output::Rgba8 => &images.rgba8,
            Output::Hdr => bytemuck::cast_slice(&images.hdr),
            Output::Depth => bytemuck::cast_slice(&images.depth),
            Output::Distance => bytemuck::cast_slice(&images.distance),
            Output::Normal => bytemuck::cast_slice(&images.normal),
            Output::Class => bytemuck::cast_slice(&images.class),
            Output::Instance => bytemuck::cast_slice(&images.instance),
            Output::Motion => bytemuck::cast_slice(&images.motion),
        }
    }
}

/// Where one view's outputs go: per output, in [`Output::ALL`] order, the
/// caller's bytes (at least its size, checked by the caller) or None.
pub type Destinations<'a> = [Option<&'a mut [u8]>; 8];

/// A renderer and the tickets of the frames submitted to it.
pub struct FramePipe {
    renderer: Renderer,
    /// (C ticket, the renderer's ticket), oldest first; the renderer decides
    /// whether a ticket's frame is still readable.
    submitted: VecDeque<(u64, alpenglow::Ticket)>,
}

impl FramePipe {
    pub fn new(ctx: &Context, scene: &Scene, settings: RenderSettings) -> Outcome<FramePipe> {
        Ok(FramePipe {
            renderer: Renderer::new(ctx, scene, settings)?,
            submitted: VecDeque::new(),
        })
    }

    /// `(width, height)` of every view, in order.
    pub fn view_sizes(&self) -> Vec<(u32, u32)> {
        self.renderer.views().iter().map(|v| (v.width, v.height)).collect()
    }

    /// Renders `cameras` until the texture atlas settled (at most
    /// `settle_frames` frames without progress) and reads the first `views` views.
    pub fn render_blocking(
        &mut self,
        cameras: &[Camera],
        settle_frames: u32,
        views: usize,
    ) -> Outcome<Vec<ViewImages>> {
        let frame = self.renderer.render_views_settled(cameras, settle_frames)?;
        (0..views)
            .map(|k| Ok(ViewImages(self.renderer.read_view(&frame, k)?)))
            .collect()
    }

    /// Submits a frame of `cameras` into the readback ring; its ticket (never 0).
    pub fn submit(&mut self, cameras: &[Camera]) -> Outcome<u64> {
        let ticket = self.renderer.submit(cameras)?;
        let id = ticket.frame() + 1;
        if self.submitted.len() == REMEMBERED_FRAMES {
            self.submitted.pop_front();
        }
        self.submitted.push_back((id, ticket));
        Ok(id)
    }

    /// Copies the frame of `ticket` into `destinations` (one per view) if
    /// the GPU is done with it (true), else leaves them alone (false); never blocks.
    pub fn try_read(&mut self, ticket: u64, destinations: &mut [Destinations]) -> Outcome<bool> {
        let ticket = self.ticket(ticket)?;
        match self.renderer.try_read(ticket)? {
            Some(frame) => copy_frame(&frame, destinations).map(|()| true),
            None => Ok(false),
        }
    }

    /// Waits for the frame of `ticket` and copies it into `destinations`.
    pub fn wait(&mut self, ticket: u64, destinations: &mut [Destinations]) -> Outcome {
        let ticket = self.ticket(ticket)?;
        let frame = self.renderer.wait(ticket)?;
        copy_frame(&frame, destinations)
    }

    fn ticket(&self, ticket: u64) -> Outcome<alpenglow::Ticket> {
        (self.submitted.iter())
            .find(|(id, _)| *id == ticket)
            .map(|(_, t)| *t)
            .ok_or_else(|| {
                Failure::invalid(
                    "ticket",
                    format!("{ticket} was not submitted to this renderer or is too old to read"),
                )
            })
    }
}

/// Copies view `k` of `frame` into `destinations[k]`, converting as the
/// ring's `copy_into` does (f16 normals to f32, ids de-interleaved).
fn copy_frame(frame: &alpenglow::FrameData<'_>, destinations: &mut [Destinations]) -> Outcome {
    for (k, destination) in destinations.iter_mut().enumerate() {
        let view = frame.view(k)?;
        for (output, dst) in Output::ALL.into_iter().zip(destination.iter_mut()) {
            if let Some(dst) = dst {
                let bytes = view.width() as usize * view.height() as usize * output.pixel_bytes();
                let dst = dst.get_mut(..bytes).ok_or_else(|| {
                    Failure::new(
                        crate::ag_status::AG_ERROR_INTERNAL,
                        "a destination shorter than checked",
                    )
                })?;
                view.copy_into(output.library(), dst)?;
            }
        }
    }
    Ok(())
}

/// A context with `validation` on the device `device` ("NAME" or "INDEX";
/// None: the best one).
pub fn context(validation: bool, device: Option<&str>) -> Outcome<Context> {
    let device = match device {
        Some(text) => text
            .parse::<DeviceSelector>()
            .map_err(|e| Failure::invalid("device", e))?,
        None => DeviceSelector::default(),
    };
    Ok(Context::new(&ContextOptions { validation, device })?)
}

/// Validation messages so far (None: the context has no validation).
pub fn validation_messages(ctx: &Context) -> Option<(u64, Vec<String>)> {
    ctx.validation_report().map(|r| (r.total(), r.messages()))
}

/// Destroys `ctx` (the device goes once no renderer holds it) and returns
/// the validation messages counted by then.
pub fn destroy_context(ctx: Context) -> Option<(u64, Vec<String>)> {
    let report = ctx.validation_report();
    drop(ctx);
    report.map(|r| (r.total(), r.messages()))
}

/// The scene's default camera.
pub fn default_camera(scene: &Scene) -> Camera {
    scene.default_camera()
}

/// The name of the context's device.
pub fn device_name(ctx: &Context) -> String {
    ctx.info().name.clone()
}
