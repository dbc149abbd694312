//! Views and the frame: what a frame looks at and what its passes read.
//! Below the techniques, above the graph.
//!
//! * [`View`]: a camera and the size of the image it renders into. A frame
//!   carries a list of views; techniques prepare per view and declare their
//!   per-view passes in a loop over the views. The view is read one way by
//!   every technique: [`View::view_proj`] (the projection, with intrinsics),
//!   [`View::frustum`] (its exact planes), [`View::culling_camera`] (the
//!   symmetric frustum enclosing it, for planners that need a camera),
//!   [`View::pixel_footprint`] (the size of a pixel at 1 m) and
//!   [`View::footprint`] (all a tile or LOD planner measures). Motion reads
//!   the previous frame's [`View::view_proj_f64`].
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
pub mod deferred;
pub mod depth;
mod frame;
pub mod lens;
pub mod lighting;
pub mod rig;
mod targets;

pub use camera::{frustum_planes, Camera};
pub(crate) use frame::frame_slots;
pub use frame::{declare_views, per_view, Declare, Frame, FrameContext, Provides, Technique, ViewGraph};
pub use lens::Intrinsics;
pub use lighting::{
    Exposure, FrameLighting, Lighting, LightingSetup, ShadowMode, SkyLightMode, SkyModel, SunDisc, SunPosition,
};
pub use targets::{LightingBindings, LightingMap, SceneTargets, TargetFormats};

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

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

    /// The world planes of the view's exact frustum (off-axis with
    /// intrinsics), `(n, d)` with `n·x + d ≥ 0` inside.
    pub fn frustum(&self) -> [DVec4; 6] {
        frustum_planes(self.view_proj_f64())
    }

    /// The size of one pixel at 1 m along the optical axis (metres, or
    /// radians at the axis), the finer of its two sides: `1/max(fx, fy)`;
    /// `2·tan(fov_y/2)/height` without intrinsics. Texture tiles and the
    /// per-pixel filtering of the surface take their detail from it.
    pub fn pixel_footprint(&self) -> f64 {
        let spec = rig::ViewSpec {
            intrinsics: self.intrinsics,
            ..rig::ViewSpec::new(self.width, self.height)
        };
        spec.pixel_footprint(self.camera.fov_y_deg)
    }

    /// What a planner measures of the view: its eye, its pixel footprint
    /// and its exact frustum.
    pub fn footprint(&self) -> Footprint {
        Footprint {
            eye: self.camera.eye,
            pixel_footprint: self.pixel_footprint(),
            frustum: Some(self.frustum()),
        }
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

/// What a planner (the texture quadtree) measures of a view
/// ([`View::footprint`]): how much detail it needs where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Eye position in world metres.
    pub eye: DVec3,
    /// Size of one pixel at 1 m ([`View::pixel_footprint`]).
    pub pixel_footprint: f64,
    /// World planes `(n, d)` with `n·x + d ≥ 0` inside; `None`: no culling.
    pub frustum: Option<[DVec4; 6]>,
}

impl Footprint {
    /// The pixel footprint `2·tan(fov_y/2)/rows` of a centred pinhole with
    /// vertical field of view `fov_y` (radians), square pixels and `rows`
    /// image rows.
    pub fn pixel_footprint_for(fov_y: f64, rows: u32) -> f64 {
        2.0 * (fov_y / 2.0).tan() / f64::from(rows.max(1))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(100.0, 200.0, 50.0),
            target: DVec3::new(900.0, 700.0, 0.0),
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 1.0,
            far: 10000.0,
        }
    }

    /// Whether the world point `p` lies inside every plane of `planes`.
    fn inside(planes: &[DVec4; 6], p: DVec3) -> bool {
        planes.iter().all(|q| q.truncate().dot(p) + q.w >= -1e-9)
    }

    /// The world point at depth `depth` on the ray through pixel (u, v)
    /// (OpenCV's convention) of `view`.
    fn through_pixel(view: &View, (u, v): (f64, f64), depth: f64) -> DVec3 {
        let k = view.intrinsics();
        let c = &view.camera;
        let (x, y) = ((u - k.cx) / k.fx, (v - k.cy) / k.fy);
        c.eye + depth * (c.forward() + x * c.right() - y * c.image_up())
    }

    #[test]
    fn a_view_by_field_of_view_reads_as_its_camera() {
        let view = View::new(camera(), 320, 200);
        let c = view.camera;
        let footprint = view.footprint();
        assert_eq!(footprint.eye, c.eye);
        assert_eq!(
            footprint.pixel_footprint,
            2.0 * (c.fov_y_deg.to_radians() / 2.0).tan() / 200.0
        );
        assert_eq!(footprint.frustum, Some(frustum_planes(c.view_proj_f64(1.6))));
        assert!((view.pixel_footprint() * view.intrinsics().fy - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_view_by_intrinsics_reads_its_own_frustum_and_footprint() {
        // Telephoto: the footprint of fx, fy, not of the camera's 50°.
        let tele = View {
            intrinsics: Some(Intrinsics {
                fx: 1600.0,
                fy: 1500.0,
                cx: 120.0,
                cy: 80.0,
            }),
            ..View::new(camera(), 240, 160)
        };
        assert_eq!(tele.pixel_footprint(), 1.0 / 1600.0);
        // Off-axis: the image sees 14°–40° right of the optical axis, which
        // the camera's symmetric 50° frustum (±35° across) does not enclose.
        let off = View {
            intrinsics: Some(Intrinsics {
                fx: 400.0,
                fy: 400.0,
                cx: -100.0,
                cy: -60.0,
            }),
            ..View::new(camera(), 240, 160)
        };
        let symmetric = frustum_planes(off.camera.view_proj_f64(off.aspect()));
        let planes = off.footprint().frustum.expect("a frustum");
        for depth in [10.0, 500.0, 5000.0] {
            for corner in [(-0.49, -0.49), (239.49, -0.49), (-0.49, 159.49), (239.49, 159.49)] {
                assert!(
                    inside(&planes, through_pixel(&off, corner, depth)),
                    "{corner:?} at {depth}"
                );
            }
            // Left of the image (on the optical axis) and beyond its right edge.
            assert!(!inside(&planes, through_pixel(&off, (-20.0, 80.0), depth)));
            assert!(!inside(&planes, through_pixel(&off, (260.0, 80.0), depth)));
        }
        assert!(!inside(&symmetric, through_pixel(&off, (239.0, 80.0), 500.0)));
    }
}
