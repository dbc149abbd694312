//! The pinhole camera of the CLI contract: world right-handed, +Z up,
//! vertical field of view, image row 0 at the top.

use glam::{DMat4, DQuat, DVec2, DVec3, DVec4, Mat4};

use crate::error::{Error, Result};

/// The largest coordinate of a camera's eye or target, metres (10⁸ m: the
/// Earth is 1.3·10⁷ m across; beyond it f32 positions lose whole kilometres).
pub const MAX_COORDINATE: f64 = 1e8;
/// The smallest near-plane distance, metres (1 µm).
pub const MIN_NEAR: f64 = 1e-6;
/// The farthest far-plane distance, metres.
pub const MAX_FAR: f64 = 1e9;
/// The largest far / near ratio the 32-bit depth buffer resolves.
pub const MAX_DEPTH_RATIO: f64 = 1e10;
/// The steepest view of [`Camera::overview`], degrees below the horizontal.
pub const MAX_OVERVIEW_ELEVATION_DEG: f64 = 80.0;

/// `x` in few characters: plain between 10⁻³ and 10⁷, else in scientific
/// notation (`1e300`, not three hundred digits).
pub fn short(x: f64) -> String {
    if x == 0.0 || (1e-3..1e7).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A vector as `X,Y,Z` with [`short`] components.
pub(crate) fn short_vec(v: DVec3) -> String {
    format!("{},{},{}", short(v.x), short(v.y), short(v.z))
}

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
    /// Checks that the camera describes a view: finite values, eye and
    /// target within ±`MAX_COORDINATE` metres, eye ≠ target, up not zero
    /// or parallel to the view direction, 0 < fov < 180, and
    /// `MIN_NEAR` ≤ near < far ≤ `MAX_FAR` with far / near ≤
    /// `MAX_DEPTH_RATIO` (the depth buffer's precision).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("camera.eye", self.eye),
            ("camera.target", self.target),
            ("camera.up", self.up),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(name, format!("{} must be finite numbers", short_vec(v))));
            }
        }
        for (name, v) in [("camera.eye", self.eye), ("camera.target", self.target)] {
            if v.abs().max_element() > MAX_COORDINATE {
                return Err(Error::invalid(
                    name,
                    format!(
                        "{} is beyond ±{MAX_COORDINATE:e} m, the largest coordinate a camera may have",
                        short_vec(v)
                    ),
                ));
            }
        }
        let dir = self.target - self.eye;
        if dir.length() <= 1e-9 * self.eye.length().max(1.0) {
            return Err(Error::invalid(
                "camera",
                "eye equals target; there is no view direction",
            ));
        }
        let Some(up) = self.up.try_normalize() else {
            return Err(Error::invalid("camera.up", "up is zero"));
        };
        if dir.normalize().cross(up).length() < 1e-6 {
            return Err(Error::invalid("camera.up", "up is parallel to the view direction"));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::invalid(
                "camera.fov_y_deg",
                format!("{} degrees; must be in (0, 180)", self.fov_y_deg),
            ));
        }
        // The GPU's projection holds 1/tan(fov/2) in 32 bits: below about
        // 1e-36° it is infinite (the CLI property test's `--fov-y 1e-300`).
        if !((1.0 / (0.5 * self.fov_y_deg.to_radians()).tan()) as f32).is_finite() {
            return Err(Error::invalid(
                "camera.fov_y_deg",
                format!(
                    "{} degrees is too narrow for the GPU's 32-bit projection",
                    self.fov_y_deg
                ),
            ));
        }
        let far_ok = self.far.is_finite() || self.far == f64::INFINITY;
        if !(self.near > 0.0 && self.near.is_finite() && self.far > self.near && far_ok) {
            return Err(Error::invalid(
                "camera.near/camera.far",
                format!(
                    "near {} and far {}; need 0 < near < far, near finite (far may be inf: an infinite far plane)",
                    self.near, self.far
                ),
            ));
        }
        if self.near < MIN_NEAR {
            return Err(Error::invalid(
                "camera.near",
                format!("{} m is below the smallest near plane, {MIN_NEAR} m", short(self.near)),
            ));
        }
        if self.far > MAX_FAR && self.far.is_finite() {
            return Err(Error::invalid(
                "camera.far",
                format!("{} m is beyond the farthest far plane, {MAX_FAR:e} m", short(self.far)),
            ));
        }
        if self.far / self.near > MAX_DEPTH_RATIO && self.far.is_finite() {
            return Err(Error::invalid(
                "camera.near/camera.far",
                format!(
                    "far / near = {:.3e} exceeds {MAX_DEPTH_RATIO:e}, beyond the depth buffer's precision; raise near or lower far",
                    self.far / self.near
                ),
            ));
        }
        Ok(())
    }

    /// The automatic camera of a terrain spanning `[0, extent.x]×[0,
    /// extent.y]×[lo, hi]`: from beyond its southern edge, above the highest
    /// point, looking at the centre, with clip planes that hold the whole
    /// terrain. Valid ([`Camera::validate`]) for the box of every legal
    /// height field (sides of at least a millimetre, heights within
    /// ±10⁶ m; `crate::io::heightmap`), however thin, flat, steep or large:
    ///
    /// * the view is at most `MAX_OVERVIEW_ELEVATION_DEG` from the
    ///   horizontal, so a terrain far higher than wide is seen from the side,
    ///   not straight down along `up`;
    /// * the eye is at least 10⁻⁸ of the target's distance from the origin
    ///   away from the target, so the two differ at their magnitude;
    /// * eye and target are clamped to ±`MAX_COORDINATE` (a terrain
    ///   larger than that is shown in part);
    /// * near is at most half the eye's distance to the terrain (a
    ///   millimetre terrain is not clipped away), far reaches its farthest
    ///   corner, both within `MIN_NEAR`, `MAX_FAR` and
    ///   `MAX_DEPTH_RATIO`.
    ///
    /// For ordinary terrains (wider than high, within the limits) this is
    /// the camera of earlier versions unchanged.
    pub fn overview(extent: DVec2, lo: f64, hi: f64) -> Camera {
        let size = extent.x.max(extent.y);
        let relief = hi - lo;
        let mut target = DVec3::new(extent.x * 0.5, extent.y * 0.5, lo + relief * 0.3);
        let mut eye = DVec3::new(extent.x * 0.5, -extent.y * 0.12, hi + relief * 0.6 + size * 0.08);
        // Not steeper than the limit: move back south.
        let (run, rise) = (target.y - eye.y, eye.z - target.z);
        let max_slope = MAX_OVERVIEW_ELEVATION_DEG.to_radians().tan();
        if rise > run * max_slope {
            eye.y = target.y - rise / max_slope;
        }
        // Far enough from the target to tell them apart at its magnitude
        // (a millimetre terrain a thousand kilometres up).
        let offset = eye - target;
        let min_distance = 1e-8 * target.length().max(1.0);
        if offset.length() < min_distance {
            eye = target + offset * (min_distance / offset.length());
        }
        let limit = DVec3::splat(MAX_COORDINATE);
        // eye.y < 0 < target.y before and after clamping: never equal.
        (eye, target) = (eye.clamp(-limit, limit), target.clamp(-limit, limit));
        let (box_min, box_max) = (DVec3::new(0.0, 0.0, lo), extent.extend(hi));
        let nearest = eye.distance(eye.clamp(box_min, box_max));
        let farthest = (0..8)
            .map(|k| {
                let corner = DVec3::new(
                    if k & 1 == 0 { box_min.x } else { box_max.x },
                    if k & 2 == 0 { box_min.y } else { box_max.y },
                    if k & 4 == 0 { box_min.z } else { box_max.z },
                );
                eye.distance(corner)
            })
            .fold(0.0, f64::max);
        // Ten times the larger of the terrain's size and its height range
        // (the eye stands above the highest point, and a small steep field
        // would otherwise lie beyond the far plane), and past the farthest corner.
        let far = (size.max(relief) * 10.0).max(farthest * 1.5).min(MAX_FAR);
        let near = (size * 1e-4).max(0.1).min(0.5 * nearest);
        let near = near.max(MIN_NEAR).max(far / MAX_DEPTH_RATIO).min(0.5 * far);
        Camera {
            eye,
            target,
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near,
            far,
        }
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

    /// World → clip transform for Vulkan (reversed depth, 1 at `near` and 0
    /// at `far`: `view::depth`; y flipped so image row 0 is the
    /// top). Computed in f64, rounded once.
    pub fn view_proj(&self, aspect: f64) -> Mat4 {
        self.view_proj_f64(aspect).as_mat4()
    }

    /// [`Camera::view_proj`] in f64.
    pub fn view_proj_f64(&self, aspect: f64) -> DMat4 {
        let view = DMat4::look_at_rh(self.eye, self.target, self.up);
        // The depth row is replaced: any finite far plane will do here.
        let mut proj = DMat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, self.near, 2.0 * self.near);
        super::depth::set_reversed_depth(&mut proj, self.near, self.far);
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

    /// A field of view whose 32-bit projection is infinite is refused by
    /// name; the narrowest representable one is legal.
    #[test]
    fn fields_of_view_too_narrow_for_f32_are_refused() {
        for fov in [1e-300, 1e-40] {
            let e = Camera {
                fov_y_deg: fov,
                ..camera()
            }
            .validate()
            .unwrap_err();
            assert_eq!(e.parameter(), Some("camera.fov_y_deg"), "{e}");
        }
        assert!(Camera {
            fov_y_deg: 1e-30,
            ..camera()
        }
        .validate()
        .is_ok());
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

    /// Absurd magnitudes name the real problem, not "eye equals target"
    /// or "up is parallel" (issue 15's probe).
    #[test]
    fn absurd_magnitudes_name_the_parameter_and_the_limit() {
        let fails = |edit: &dyn Fn(&mut Camera)| {
            let mut c = camera();
            edit(&mut c);
            c.validate().unwrap_err()
        };
        let e = fails(&|c| c.eye = DVec3::new(1e300, 0.0, 0.0));
        assert_eq!(e.parameter(), Some("camera.eye"));
        assert!(e.to_string().contains("1e300,0,0 is beyond ±1e8 m"), "{e}");
        assert_eq!(fails(&|c| c.target.z = -1e9).parameter(), Some("camera.target"));
        assert_eq!(
            fails(&|c| c.up = DVec3::new(1e-320, 0.0, 0.0)).to_string(),
            "invalid camera.up: up is zero"
        );
        assert_eq!(fails(&|c| c.near = 1e-300).parameter(), Some("camera.near"));
        assert_eq!(fails(&|c| c.far = 1e300).parameter(), Some("camera.far"));
        let e = fails(&|c| {
            c.near = 1e-5;
            c.far = 1e6;
        });
        assert!(e.to_string().contains("depth buffer"), "{e}");
        // The limits themselves are legal.
        let mut c = camera();
        c.eye = DVec3::new(MAX_COORDINATE, 0.0, 10.0);
        c.target = DVec3::new(MAX_COORDINATE - 100.0, 0.0, 10.0);
        assert!(c.validate().is_ok());
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(12.5), "12.5");
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

    /// The automatic camera is valid for the box of every legal height
    /// field: millimetre squares, strips ten million times longer than
    /// wide, terrains kilometres beyond the coordinate limit, flat and
    /// 2000 km high ones. Where the limits allow, near stops short of the
    /// terrain and far reaches its farthest corner.
    #[test]
    fn the_overview_is_valid_for_every_legal_terrain() {
        let sides = [1e-3, 30.0, 61_410.0, 2.048e8, 32_767.0 * 1e5];
        let heights = [
            (0.0, 0.0),
            (0.0, 100.0),
            (-1e6, 1e6),
            (1e6, 1e6),
            (-1e6, -1e6),
            (-3.5, 0.25),
        ];
        for x in sides {
            for y in sides {
                for (lo, hi) in heights {
                    let extent = DVec2::new(x, y);
                    let c = Camera::overview(extent, lo, hi);
                    let what = format!("{extent} × {lo}..{hi}: {c:?}");
                    c.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
                    let forward = c.forward();
                    let steepness = (-forward.z).asin().to_degrees();
                    assert!(steepness <= MAX_OVERVIEW_ELEVATION_DEG + 1e-6, "{what}: {steepness}°");
                    if c.eye.abs().max_element() < MAX_COORDINATE && extent.max_element() < MAX_COORDINATE {
                        let (lo3, hi3) = (DVec3::new(0.0, 0.0, lo), extent.extend(hi));
                        assert!(
                            c.near < c.eye.distance(c.eye.clamp(lo3, hi3)),
                            "{what}: near clips the terrain"
                        );
                        let far = c.eye.distance(lo3).max(c.eye.distance(hi3));
                        assert!(c.far >= far.min(MAX_FAR), "{what}: far stops short of the terrain");
                    }
                }
            }
        }
    }

    /// Ordinary terrains keep the automatic camera of earlier versions.
    #[test]
    fn the_overview_of_an_ordinary_terrain_is_unchanged() {
        for (extent, lo, hi) in [
            (DVec2::new(10_240.0, 10_240.0), 12.0, 900.0),
            (DVec2::new(5_000.0, 8_000.0), -40.0, 2_500.0),
        ] {
            let size: f64 = extent.max_element();
            let old = Camera {
                eye: DVec3::new(extent.x * 0.5, -extent.y * 0.12, hi + (hi - lo) * 0.6 + size * 0.08),
                target: DVec3::new(extent.x * 0.5, extent.y * 0.5, lo + (hi - lo) * 0.3),
                up: DVec3::Z,
                fov_y_deg: 50.0,
                near: (size * 1e-4).max(0.1),
                far: size.max(hi - lo) * 10.0,
            };
            assert_eq!(Camera::overview(extent, lo, hi), old);
        }
    }
}
