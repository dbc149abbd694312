//! The pinhole camera of the CLI contract: world right-handed, +Z up,
//! vertical field of view, image row 0 at the top.

use glam::{DMat4, DQuat, DVec3, DVec4, Mat4};

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

    /// A camera at `pose` (camera → world, in the OpenGL/glTF camera
    /// convention: x right, y up, looking down −z; scale is ignored).
    pub fn from_pose(pose: DMat4, fov_y_deg: f64, near: f64, far: f64) -> Result<Camera> {
        if !pose.is_finite() {
            return Err(Error::invalid("camera.pose", "the matrix has a non-finite entry"));
        }
        let eye = pose.w_axis.truncate();
        let forward = -pose.z_axis.truncate();
        let up = pose.y_axis.truncate();
        if forward.length() < 1e-12 || up.length() < 1e-12 || forward.normalize().cross(up.normalize()).length() < 1e-6
        {
            return Err(Error::invalid(
                "camera.pose",
                "its y and z axes are zero or parallel; not a rotation",
            ));
        }
        let camera = Camera {
            eye,
            target: eye + forward.normalize(),
            up: up.normalize(),
            fov_y_deg,
            near,
            far,
        };
        camera.validate()?;
        Ok(camera)
    }

    /// A camera at `position` turned by `rotation` (camera → world, the
    /// [`Camera::from_pose`] convention: the identity looks down −z).
    pub fn from_position_rotation(
        position: DVec3,
        rotation: DQuat,
        fov_y_deg: f64,
        near: f64,
        far: f64,
    ) -> Result<Camera> {
        if !rotation.is_finite() || rotation.length() < 1e-9 {
            return Err(Error::invalid(
                "camera.rotation",
                "the quaternion is zero or not finite",
            ));
        }
        let pose = DMat4::from_rotation_translation(rotation.normalize(), position);
        Camera::from_pose(pose, fov_y_deg, near, far)
    }

    /// The camera → world pose ([`Camera::from_pose`] convention).
    pub fn pose(&self) -> DMat4 {
        let (r, u, f) = (self.right(), self.image_up(), self.forward());
        DMat4::from_cols(r.extend(0.0), u.extend(0.0), (-f).extend(0.0), self.eye.extend(1.0))
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
    fn a_pose_round_trips() {
        let c = Camera {
            up: DVec3::new(0.1, 0.0, 1.0),
            ..camera()
        };
        let back = Camera::from_pose(c.pose(), c.fov_y_deg, c.near, c.far).unwrap();
        assert!(back.eye.abs_diff_eq(c.eye, 1e-12));
        assert!(back.forward().abs_diff_eq(c.forward(), 1e-12));
        assert!(back.image_up().abs_diff_eq(c.image_up(), 1e-12));
        // The identity rotation looks down −z with +y up in the image.
        let q = Camera::from_position_rotation(DVec3::ZERO, DQuat::IDENTITY, 60.0, 0.1, 10.0).unwrap();
        assert!(q.forward().abs_diff_eq(-DVec3::Z, 1e-12) && q.image_up().abs_diff_eq(DVec3::Y, 1e-12));
        // Rotating by 90° about +x looks along +y with +z up.
        let q = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let c = Camera::from_position_rotation(DVec3::ONE, q, 60.0, 0.1, 10.0).unwrap();
        assert!(c.forward().abs_diff_eq(DVec3::Y, 1e-12) && c.image_up().abs_diff_eq(DVec3::Z, 1e-12));
        assert_eq!(
            Camera::from_pose(DMat4::ZERO, 60.0, 0.1, 10.0).unwrap_err().parameter(),
            Some("camera.pose")
        );
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
