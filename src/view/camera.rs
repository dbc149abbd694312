//! The pinhole camera of the CLI contract: world right-handed, +Z up,
//! vertical field of view, image row 0 at the top.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

use crate::error::{Error, Result};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f64,
    pub near: f64,
    pub far: f64,
}

impl Camera {
    /// Checks that the camera describes a view: finite values, eye ≠ target,
    /// up not parallel to the view direction, 0 < fov < 180, 0 < near < far.
    pub fn validate(&self) -> Result<()> {
        let finite = |v: DVec3| v.is_finite();
        if !finite(self.eye) || !finite(self.target) || !finite(self.up) {
            return Err(Error::invalid("camera", "eye, target and up must be finite numbers"));
        }
        let dir = self.target - self.eye;
        if dir.length() <= 1e-9 * self.eye.length().max(1.0) {
            return Err(Error::invalid(
                "camera",
                "eye equals target; there is no view direction",
            ));
        }
        if self.up.length() == 0.0 || dir.normalize().cross(self.up.normalize()).length() < 1e-6 {
            return Err(Error::invalid("camera", "up is zero or parallel to the view direction"));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::invalid(
                "camera.fov_y_deg",
                format!("{} degrees; must be in (0, 180)", self.fov_y_deg),
            ));
        }
        if !(self.near > 0.0 && self.near.is_finite() && self.far > self.near && self.far.is_finite()) {
            return Err(Error::invalid(
                "camera.near/camera.far",
                format!(
                    "near {} and far {}; need 0 < near < far, both finite",
                    self.near, self.far
                ),
            ));
        }
        Ok(())
    }

    /// Unit forward axis (view-space depth is measured along it).
    pub fn forward(&self) -> DVec3 {
        (self.target - self.eye).normalize()
    }

    /// Unit right axis.
    pub fn right(&self) -> DVec3 {
        self.forward().cross(self.up).normalize()
    }

    /// Unit up axis of the image (orthogonal to forward).
    pub fn image_up(&self) -> DVec3 {
        self.right().cross(self.forward())
    }

    /// World → clip transform for Vulkan (depth 0..1, y flipped so image row 0
    /// is the top). Computed in f64, rounded once.
    pub fn view_proj(&self, aspect: f64) -> Mat4 {
        self.view_proj_f64(aspect).as_mat4()
    }

    /// [`Camera::view_proj`] in f64.
    pub fn view_proj_f64(&self, aspect: f64) -> DMat4 {
        let view = DMat4::look_at_rh(self.eye, self.target, self.up);
        let mut proj = DMat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, self.near, self.far);
        proj.y_axis.y = -proj.y_axis.y;
        proj * view
    }

    /// Right and up axes scaled by the half-extents of the image plane at
    /// distance 1 (for reconstructing view rays).
    pub fn ray_basis(&self, aspect: f64) -> (Vec3, Vec3, Vec3) {
        let tan_y = (self.fov_y_deg.to_radians() * 0.5).tan();
        (
            (self.right() * tan_y * aspect).as_vec3(),
            (self.image_up() * tan_y).as_vec3(),
            self.forward().as_vec3(),
        )
    }
}

/// The world-space planes of the frustum of `view_proj` (Vulkan clip space,
/// depth 0..1), as (n, d) with n·x + d ≥ 0 inside.
pub fn frustum_planes(view_proj: DMat4) -> [DVec4; 6] {
    let m = view_proj.transpose();
    let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| p / p.truncate().length().max(1e-300))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 10.0),
            target: DVec3::new(100.0, 0.0, 10.0),
            up: DVec3::Z,
            fov_y_deg: 60.0,
            near: 1.0,
            far: 1000.0,
        }
    }

    #[test]
    fn bad_cameras_are_rejected() {
        assert!(camera().validate().is_ok());
        let mut c = camera();
        c.target = c.eye;
        assert!(c.validate().unwrap_err().to_string().contains("eye equals target"));
        let mut c = camera();
        c.up = DVec3::X;
        assert!(c.validate().is_err());
        let mut c = camera();
        c.fov_y_deg = 180.0;
        assert_eq!(c.validate().unwrap_err().parameter(), Some("camera.fov_y_deg"));
        let mut c = camera();
        c.near = 0.0;
        assert_eq!(c.validate().unwrap_err().parameter(), Some("camera.near/camera.far"));
        let mut c = camera();
        c.eye.x = f64::NAN;
        assert!(c.validate().is_err());
    }

    #[test]
    fn up_in_the_world_is_up_in_the_image() {
        let c = camera();
        let vp = c.view_proj(1.0);
        let above = vp * glam::Vec4::new(100.0, 0.0, 30.0, 1.0);
        let below = vp * glam::Vec4::new(100.0, 0.0, -10.0, 1.0);
        // Vulkan NDC y grows downwards: a point above the horizon has smaller y.
        assert!(above.y / above.w < 0.0 && below.y / below.w > 0.0);
        let right = vp * glam::Vec4::new(100.0, -20.0, 10.0, 1.0);
        assert!(
            right.x / right.w > 0.0,
            "-Y is to the right when looking along +X with +Z up"
        );
    }
}
