//! The viewer's fly camera: a position, a heading (yaw about +Z, pitch
//! above the horizon) and a speed. WASD move in the view's horizontal
//! frame, E/Q (or Space/C) up and down, Shift runs 4× faster; the mouse
//! turns it while a button is held; the wheel scales the speed.

use glam::DVec3;

use alpenglow::Camera;

/// Degrees of turn per pixel of mouse motion.
const TURN_DEG_PER_PIXEL: f64 = 0.15;
/// Speed factor per wheel notch.
const WHEEL_FACTOR: f64 = 1.25;
/// Pitch limit (degrees): the view never looks straight up or down.
const MAX_PITCH_DEG: f64 = 89.0;

/// Which ways the camera is being moved (the keys held).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    pub forward: f64,
    pub right: f64,
    pub up: f64,
    pub fast: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub eye: DVec3,
    /// Heading: degrees counter-clockwise from +X about +Z.
    pub yaw_deg: f64,
    /// Degrees above the horizon.
    pub pitch_deg: f64,
    /// Metres per second.
    pub speed: f64,
    /// What the camera keeps of the starting one (fov, near, far).
    lens: Camera,
}

impl FlyCamera {
    /// The fly camera looking where `camera` looks, at a speed that
    /// crosses the eye–target distance in 10 s.
    pub fn new(camera: Camera) -> FlyCamera {
        let dir = (camera.target - camera.eye).normalize_or_zero();
        let dir = if dir == DVec3::ZERO { DVec3::X } else { dir };
        FlyCamera {
            eye: camera.eye,
            yaw_deg: dir.y.atan2(dir.x).to_degrees(),
            pitch_deg: dir
                .z
                .clamp(-1.0, 1.0)
                .asin()
                .to_degrees()
                .clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG),
            speed: (camera.eye.distance(camera.target) / 10.0).max(1.0),
            lens: camera,
        }
    }

    /// The unit view direction.
    pub fn forward(&self) -> DVec3 {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        DVec3::new(yaw.cos() * pitch.cos(), yaw.sin() * pitch.cos(), pitch.sin())
    }

    /// The camera to render: eye, a target 1 km ahead (far enough that
    /// `--eye`/`--target` printed with 3 decimals reproduce the direction),
    /// +Z up, the starting lens.
    pub fn camera(&self) -> Camera {
        Camera {
            eye: self.eye,
            target: self.eye + self.forward() * 1000.0,
            up: DVec3::Z,
            ..self.lens
        }
    }

    /// Moves for `dt` seconds.
    pub fn advance(&mut self, motion: Motion, dt: f64) {
        let yaw = self.yaw_deg.to_radians();
        let ahead = DVec3::new(yaw.cos(), yaw.sin(), 0.0);
        let right = DVec3::new(yaw.sin(), -yaw.cos(), 0.0);
        let step = self.speed * dt * if motion.fast { 4.0 } else { 1.0 };
        self.eye += (ahead * motion.forward + right * motion.right + DVec3::Z * motion.up) * step;
    }

    /// Turns by a mouse motion of (`dx`, `dy`) pixels (right and down).
    pub fn turn(&mut self, dx: f64, dy: f64) {
        self.yaw_deg = (self.yaw_deg - dx * TURN_DEG_PER_PIXEL).rem_euclid(360.0);
        self.pitch_deg = (self.pitch_deg - dy * TURN_DEG_PER_PIXEL).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
    }

    /// Scales the speed by `notches` of the wheel (up: faster).
    pub fn scroll(&mut self, notches: f64) {
        self.speed = (self.speed * WHEEL_FACTOR.powf(notches)).clamp(0.01, 1e6);
    }

    /// The camera as `render` options.
    pub fn options(&self) -> String {
        let c = self.camera();
        format!(
            "--eye {:.3},{:.3},{:.3} --target {:.3},{:.3},{:.3}",
            c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 100.0),
            target: DVec3::new(100.0, 0.0, 100.0),
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 1.0,
            far: 1e5,
        }
    }

    #[test]
    fn starts_looking_where_the_camera_looks() {
        let fly = FlyCamera::new(start());
        assert!((fly.forward() - DVec3::X).length() < 1e-12);
        assert_eq!(fly.speed, 10.0);
        let c = fly.camera();
        assert_eq!((c.eye, c.fov_y_deg, c.near, c.far), (start().eye, 50.0, 1.0, 1e5));
    }

    #[test]
    fn moves_and_turns() {
        let mut fly = FlyCamera::new(start());
        let forward = Motion {
            forward: 1.0,
            ..Motion::default()
        };
        fly.advance(forward, 2.0);
        assert!((fly.eye - DVec3::new(20.0, 0.0, 100.0)).length() < 1e-9);
        let strafe = Motion {
            right: 1.0,
            fast: true,
            ..Motion::default()
        };
        fly.advance(strafe, 0.5);
        assert!((fly.eye - DVec3::new(20.0, -20.0, 100.0)).length() < 1e-9);
        // 600 px right turns 90° clockwise (seen from above): looking -Y.
        fly.turn(600.0, 0.0);
        assert!((fly.forward() - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-9);
        fly.turn(0.0, 1e6);
        assert_eq!(fly.pitch_deg, -MAX_PITCH_DEG);
        fly.scroll(2.0);
        assert!((fly.speed - 15.625).abs() < 1e-9);
    }
}
