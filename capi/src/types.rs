//! The plain C structs and constants of the ABI: camera, settings, output
//! buffers, options. Opaque handles are in their own modules.

use std::ffi::{c_char, c_void};

use crate::adapter::{self, Output};
use crate::status::{Failure, Outcome};

/// Version of the C ABI: bumped whenever a struct's layout or a function's
/// signature changes incompatibly.
pub const AG_ABI_VERSION: u32 = 2;

/// Which output of a frame (`ag_renderer_output_bytes`). Values of `ag_output`.
#[allow(non_camel_case_types)]
pub type ag_output = u32;
/// Tone-mapped sRGB, 4 × uint8 per pixel.
pub const AG_OUTPUT_RGBA8: ag_output = 0;
/// Linear HDR radiance, 4 × float per pixel (alpha 1).
pub const AG_OUTPUT_HDR: ag_output = 1;
/// View-space depth along the camera's forward axis in metres, float; +inf for sky.
pub const AG_OUTPUT_DEPTH: ag_output = 2;
/// Euclidean distance from the eye along the pixel's ray in metres, float; +inf for sky.
pub const AG_OUTPUT_DISTANCE: ag_output = 3;
/// World-space shading normal, 3 × float per pixel (0 for sky).
pub const AG_OUTPUT_NORMAL: ag_output = 4;
/// Semantic class, uint32 per pixel (sky 0, terrain 1 or 10 + its surface
/// layer, rock 2, other point objects 3, vegetation 4).
pub const AG_OUTPUT_CLASS: ag_output = 5;
/// Point instance id, uint32 per pixel (1-based; 0 for terrain and sky).
pub const AG_OUTPUT_INSTANCE: ag_output = 6;
/// Motion from the previous frame in pixels, 2 × float per pixel (+x right, +y down).
pub const AG_OUTPUT_MOTION: ag_output = 7;

/// The [`Output`] of a C value.
pub(crate) fn output(value: ag_output) -> Outcome<Output> {
    (Output::ALL.get(value as usize).copied())
        .ok_or_else(|| Failure::invalid("output", format!("{value}; expected 0 to {}", Output::ALL.len() - 1)))
}

/// Which rasterizer draws the terrain and the EWA splats (`ag_settings.raster`). Values of `ag_raster`.
#[allow(non_camel_case_types)]
pub type ag_raster = u32;
/// The hardware rasterizer.
pub const AG_RASTER_HARDWARE: ag_raster = 0;
/// Compute shaders into a visibility buffer, then one shading pass per
/// pixel; needs the device feature shaderBufferInt64Atomics.
pub const AG_RASTER_COMPUTE: ag_raster = 1;
/// Compute where the device has the feature, else hardware (the default).
pub const AG_RASTER_AUTO: ag_raster = 2;

/// The library's rasterizer of a C value.
pub(crate) fn raster(value: ag_raster) -> Outcome<alpenglow::RasterPath> {
    match value {
        AG_RASTER_HARDWARE => Ok(alpenglow::RasterPath::Hardware),
        AG_RASTER_COMPUTE => Ok(alpenglow::RasterPath::Compute),
        AG_RASTER_AUTO => Ok(alpenglow::RasterPath::Auto),
        _ => Err(Failure::invalid(
            "raster",
            format!("{value}; expected 0 (hardware), 1 (compute) or 2 (auto)"),
        )),
    }
}

/// A pinhole camera looking from `eye` at `target`, world coordinates in
/// metres with z up. Checked when a frame is rendered: finite values,
/// eye ≠ target, `up` not parallel to the view direction,
/// 0 < `fov_y_deg` < 180, 0 < `near` < `far`.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ag_camera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    /// Vertical field of view in degrees.
    pub fov_y_deg: f64,
    pub near: f64,
    pub far: f64,
}

impl ag_camera {
    pub(crate) fn to_rust(self) -> adapter::Camera {
        adapter::camera(self.eye, self.target, self.up, self.fov_y_deg, self.near, self.far)
    }

    pub(crate) fn from_rust(camera: &adapter::Camera) -> ag_camera {
        let (eye, target, up, fov_y_deg, near, far) = adapter::camera_parts(camera);
        ag_camera {
            eye,
            target,
            up,
            fov_y_deg,
            near,
            far,
        }
    }
}

/// How a renderer renders. Start from `ag_settings_default()` and change
/// fields: later ABI versions only add fields at the end.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ag_settings {
    /// Image size in pixels (1 to 16384 each).
    pub width: u32,
    pub height: u32,
    /// Anti-aliasing samples per pixel: 1, 2, 4, 8 or 16.
    pub msaa: u32,
    /// Procedural terrain detail (displacement and bump mapping) on or off.
    pub terrain_detail: bool,
    /// `ag_renderer_render`: how many frames in a row may bring no texture
    /// tile closer before it gives up (the atlas settles in a few frames).
    pub settle_frames: u32,
    /// Frames that may be submitted and not yet read: the readback ring's
    /// slots, 1 to 16; 0: the library's default (3). A ticket can be read
    /// until this many later frames were submitted.
    pub readback_slots: u32,
    /// Which rasterizer draws the terrain and the EWA splats: `AG_RASTER_*` (ABI 2).
    pub raster: ag_raster,
}

/// The default settings: 640×360, no anti-aliasing, terrain detail on,
/// 64 settle frames, the default readback ring.
#[no_mangle]
pub extern "C" fn ag_settings_default() -> ag_settings {
    ag_settings {
        width: 640,
        height: 360,
        msaa: 1,
        terrain_detail: true,
        settle_frames: 64,
        readback_slots: 0,
        raster: AG_RASTER_AUTO,
    }
}

/// How to create a context.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct ag_context_options {
    /// Enable the Khronos validation layers (with synchronization validation).
    pub validation: bool,
    /// The device: a name fragment (case-insensitive) or an index of
    /// `vkEnumeratePhysicalDevices`, NUL-terminated; NULL: the best device.
    pub device: *const c_char,
}

/// How a height-map file's raw values become metres.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ag_heightmap_options {
    /// Multiplies each raw value (PNG: the integer; EXR: the stored float). > 0.
    pub scale: f32,
    /// Added after scaling, in metres.
    pub offset: f32,
    /// Metres between samples in x and y; both 0: from the file's
    /// georeferencing (GeoTIFF, .hgt), else 1 m.
    pub spacing_x: f64,
    pub spacing_y: f64,
    /// Image row 0 is the northern edge (most GIS rasters); false: row 0 is y = 0.
    pub north_up: bool,
}

/// Scale 1, offset 0, spacing from the file, rows kept (row 0 at y = 0).
#[no_mangle]
pub extern "C" fn ag_heightmap_options_default() -> ag_heightmap_options {
    ag_heightmap_options {
        scale: 1.0,
        offset: 0.0,
        spacing_x: 0.0,
        spacing_y: 0.0,
        north_up: false,
    }
}

/// A caller-owned buffer: `data` NULL means "not wanted".
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct ag_buffer {
    pub data: *mut c_void,
    /// Size of `data` in bytes: at least `ag_renderer_output_bytes` of its output.
    pub bytes: usize,
}

/// Where to copy one view's outputs. Each field may be `{NULL, 0}` to skip
/// that output. Row 0 is the top of the image; pixels are row-major.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct ag_frame_buffers {
    pub rgba8: ag_buffer,
    pub hdr: ag_buffer,
    pub depth: ag_buffer,
    pub distance: ag_buffer,
    pub normal: ag_buffer,
    pub class_id: ag_buffer,
    pub instance_id: ag_buffer,
    pub motion: ag_buffer,
}

impl ag_frame_buffers {
    /// The buffer of `output`.
    pub(crate) fn get(&self, output: Output) -> ag_buffer {
        match output {
            Output::Rgba8 => self.rgba8,
            Output::Hdr => self.hdr,
            Output::Depth => self.depth,
            Output::Distance => self.distance,
            Output::Normal => self.normal,
            Output::Class => self.class_id,
            Output::Instance => self.instance_id,
            Output::Motion => self.motion,
        }
    }
}
