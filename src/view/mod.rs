//! Views and the frame: what a frame looks at and what its passes read.
//! Below the techniques, above the graph.
//!
//! * [`View`]: a camera and the size of the image it renders into. A frame
//!   carries a list of views; techniques prepare per view and declare their
//!   per-view passes in a loop over the views.
//! * [`SceneTargets`]: the images every technique draws into, one set per
//!   view, with their formats (pipelines take their formats from here).
//! * [`Frame`]: the frame's views, its lighting, and every technique's
//!   prepared data ([`Frame::prepared`]), which the passes' recording closures
//!   read.
//! * [`Technique`]: the prepare step every technique implements.

pub mod aov;
pub mod camera;
pub mod camera_path;
mod frame;
pub mod lighting;
mod targets;

pub use camera::{frustum_planes, Camera};
pub use frame::{Frame, FrameContext, Technique};
pub use lighting::{Exposure, Lighting, ShadowMode, SkyLightMode, SkyModel, SunPosition};
pub use targets::{LightingInputs, SceneTargets, TargetFormats, LIGHTING_CONSTANTS_BYTES};

use crate::error::{Error, Result};

/// Largest accepted image side (the device limit may be lower).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// One view of a frame: a camera and its image.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// Name, suffixed to the view's pass names when a frame has several
    /// views (empty for a single view).
    pub name: String,
    pub camera: Camera,
    /// Image size in pixels.
    pub width: u32,
    pub height: u32,
}

/// Index of a view in [`Frame::views`].
pub type ViewIndex = usize;

impl View {
    /// A view of `camera` into a `width`×`height` image.
    pub fn new(camera: Camera, width: u32, height: u32) -> View {
        View {
            name: String::new(),
            camera,
            width,
            height,
        }
    }

    /// Width / height.
    pub fn aspect(&self) -> f64 {
        f64::from(self.width) / f64::from(self.height)
    }

    /// Checks the camera and the image size.
    pub fn validate(&self) -> Result<()> {
        validate_size(self.width, self.height)?;
        self.camera.validate()
    }
}

/// Names a per-view pass: `base` for an unnamed view, `base@name` otherwise.
pub fn pass_name(base: &str, view_name: &str) -> String {
    match view_name {
        "" => base.to_string(),
        name => format!("{base}@{name}"),
    }
}

/// Checks an output size.
pub fn validate_size(width: u32, height: u32) -> Result<()> {
    for (what, v) in [("width", width), ("height", height)] {
        if v == 0 || v > MAX_IMAGE_SIDE {
            return Err(Error::invalid(what, format!("{v}; must be in 1..={MAX_IMAGE_SIDE}")));
        }
    }
    Ok(())
}
