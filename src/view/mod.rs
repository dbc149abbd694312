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
//! * [`Technique`]: the prepare step every technique implements, with what
//!   it needs of the others' prepared data.

pub mod aov;
pub mod camera;
pub mod camera_path;
mod frame;
pub mod lens;
pub mod lighting;
pub mod rig;
mod targets;

pub use camera::{frustum_planes, Camera};
pub(crate) use frame::frame_slots;
pub use frame::{declare_views, per_view, Declare, Frame, FrameContext, Provides, Technique};
pub use lens::Intrinsics;
pub use lighting::{Exposure, FrameLighting, Lighting, LightingSetup, ShadowMode, SkyLightMode, SkyModel, SunPosition};
pub use targets::{LightingBindings, LightingMap, SceneTargets, TargetFormats};

use glam::{DMat4, Mat4, Vec3};

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
    /// Pinhole intrinsics in pixels; None: the camera's vertical field of
    /// view, centred, square pixels.
    pub intrinsics: Option<Intrinsics>,
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
            intrinsics: None,
        }
    }

    /// Width / height.
    pub fn aspect(&self) -> f64 {
        f64::from(self.width) / f64::from(self.height)
    }

    /// The view's intrinsics: explicit ones, or those of the camera's
    /// vertical field of view.
    pub fn intrinsics(&self) -> Intrinsics {
        self.intrinsics
            .unwrap_or_else(|| Intrinsics::from_fov_y(self.camera.fov_y_deg, self.width, self.height))
    }

    /// The camera whose symmetric frustum (with [`View::culling_aspect`])
    /// encloses the view's: CPU LOD, culling and shadow cascades plan with
    /// it; the GPU projects with [`View::view_proj`]. The camera itself
    /// without explicit intrinsics.
    pub fn culling_camera(&self) -> Camera {
        match self.intrinsics {
            None => self.camera,
            Some(k) => Camera {
                fov_y_deg: k.enclosing_fov(self.width, self.height).0,
                ..self.camera
            },
        }
    }

    /// Aspect ratio (tan of the half field of view across over down) of
    /// [`View::culling_camera`].
    pub fn culling_aspect(&self) -> f64 {
        match self.intrinsics {
            None => self.aspect(),
            Some(k) => k.enclosing_fov(self.width, self.height).1,
        }
    }

    /// World → Vulkan clip space (depth 0..1, row 0 at the top), in f64.
    pub fn view_proj_f64(&self) -> DMat4 {
        match self.intrinsics {
            None => self.camera.view_proj_f64(self.aspect()),
            Some(k) => {
                let c = &self.camera;
                k.projection(self.width, self.height, c.near, c.far) * DMat4::look_at_rh(c.eye, c.target, c.up)
            }
        }
    }

    /// [`View::view_proj_f64`] rounded to f32.
    pub fn view_proj(&self) -> Mat4 {
        self.view_proj_f64().as_mat4()
    }

    /// `(right, up, forward)` such that the view ray through NDC (x, y)
    /// (y down) is `forward + x·right − y·up` (not normalised): the camera
    /// axes scaled by the image plane's half-extents at depth 1 and the
    /// forward axis shifted by the principal point.
    pub fn ray_basis(&self) -> (Vec3, Vec3, Vec3) {
        let k = self.intrinsics();
        let c = &self.camera;
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let right = c.right() * (0.5 * w / k.fx);
        let up = c.image_up() * (0.5 * h / k.fy);
        let (ox, oy) = k.principal_ndc(self.width, self.height);
        let forward = c.forward() - ox * right + oy * up;
        (right.as_vec3(), up.as_vec3(), forward.as_vec3())
    }

    /// The angle one pixel spans at the optical axis (radians, vertical).
    pub fn pixel_angle(&self) -> f64 {
        1.0 / self.intrinsics().fy
    }

    /// Checks the camera, the image size and the intrinsics.
    pub fn validate(&self) -> Result<()> {
        validate_size(self.width, self.height)?;
        self.camera.validate()?;
        match &self.intrinsics {
            Some(k) => k.validate(self.width, self.height),
            None => Ok(()),
        }
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
