//! Views: what a frame looks at. Below the techniques, above the graph:
//! the camera, camera paths, and the per-frame parameters every pass reads.

pub mod camera;
pub mod camera_path;

use glam::Vec3;

pub use camera::{frustum_planes, Camera};

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
