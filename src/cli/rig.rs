//! Camera models and multi-view rigs on the command line: `--pose`,
//! `--rotation`, `--intrinsics`, `--distortion` for the command's camera,
//! `--rig FILE.toml` or `--rig-preset ring6` for several views posed
//! relative to it, and output paths with a `{view}` pattern.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use glam::{DMat4, DQuat};

use alpenglow::{Camera, Distortion, Intrinsics, Rig, ViewSpec};

/// The placeholder of a view's name in output paths.
pub const VIEW_PATTERN: &str = "{view}";

#[derive(Args, Debug, Clone, Default)]
#[command(next_help_heading = "Camera")]
pub struct CameraArgs {
    /// Camera pose: a 4×4 camera→world matrix, 16 comma-separated numbers
    /// row by row (OpenGL camera axes: x right, y up, looking down −z).
    #[arg(long, value_parser = parse_pose, allow_hyphen_values = true, conflicts_with_all = ["eye", "target", "rotation"], value_name = "M00,M01,...,M33")]
    pub pose: Option<DMat4>,
    /// Camera orientation as a unit quaternion X,Y,Z,W (camera→world, the
    /// --pose axes), placed at --eye.
    #[arg(long, value_parser = parse_quaternion, allow_hyphen_values = true, requires = "eye", conflicts_with = "target", value_name = "X,Y,Z,W")]
    pub rotation: Option<DQuat>,
    /// Pinhole intrinsics FX,FY,CX,CY in pixels (instead of --fov-y):
    /// off-centre principal points and non-square pixels.
    #[arg(long, value_parser = parse_intrinsics, allow_hyphen_values = true, value_name = "FX,FY,CX,CY")]
    pub intrinsics: Option<Intrinsics>,
    /// Brown–Conrady lens distortion K1,K2,K3,P1,P2 (OpenCV convention),
    /// applied by resampling the rendered image.
    #[arg(long, value_parser = parse_distortion, allow_hyphen_values = true, value_name = "K1,K2,K3,P1,P2")]
    pub distortion: Option<Distortion>,
    /// Several views per frame (TOML [[view]] tables, see the README), posed
    /// relative to the command's camera; --out and --exr then need `{view}`.
    #[arg(long, conflicts_with_all = ["rig_preset", "intrinsics", "distortion"], value_name = "FILE")]
    pub rig: Option<PathBuf>,
    /// A built-in rig: ring6 (six 60° views around the camera, 4:3, --width wide).
    #[arg(long = "rig-preset", value_enum, conflicts_with_all = ["intrinsics", "distortion"], value_name = "PRESET")]
    pub rig_preset: Option<RigPreset>,
    /// Anti-aliasing: samples per pixel, 1, 2, 4, 8 or 16 (supersampled
    /// render, each side ×√N, resolved with exact AOVs).
    #[arg(long, default_value_t = 1, value_name = "SAMPLES", value_parser = clap::value_parser!(u32).range(0..))]
    pub msaa: u32,
    /// Motion blur: the shutter's open time in seconds (0: off), along the
    /// motion AOV from frame to frame.
    #[arg(long, default_value_t = 0.0, value_name = "SECONDS")]
    pub shutter: f32,
    /// Frames per second of the sequence (`fly`, and the motion that the
    /// shutter time is a part of).
    #[arg(long, default_value_t = 30.0, value_name = "HZ")]
    pub fps: f32,
}

/// Built-in rigs.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RigPreset {
    /// Six 60° horizontal views around the car (yaw 0°, 60°, …, counter-clockwise).
    Ring6,
}

impl CameraArgs {
    /// The rig of the arguments, if any.
    pub fn rig(&self, width: u32) -> Result<Option<Rig>> {
        Ok(match (&self.rig, self.rig_preset) {
            (Some(path), _) => Some(Rig::load(path)?),
            (None, Some(RigPreset::Ring6)) => Some(Rig::ring6(width)),
            (None, None) => None,
        })
    }

    /// The views a frame renders: the rig's, or one view of `size`.
    pub fn view_specs(&self, rig: Option<&Rig>, size: (u32, u32), fov_y: f64) -> Result<Vec<ViewSpec>> {
        Ok(match rig {
            Some(rig) => {
                let mut specs = rig.specs(size)?;
                // A distorted view that inherits the field of view: the
                // intrinsics of --fov-y at its size.
                for spec in specs
                    .iter_mut()
                    .filter(|s| s.distortion.is_some() && s.intrinsics.is_none())
                {
                    spec.intrinsics = Some(Intrinsics::from_fov_y(fov_y, spec.width, spec.height));
                }
                // A rig file's views are checked here, so that their errors
                // name the file and the view, not --distortion.
                for spec in &specs {
                    alpenglow::check_view(spec).map_err(|e| match (&self.rig, &e) {
                        (Some(path), alpenglow::Error::InvalidArgument { message, .. }) => {
                            anyhow::anyhow!("{}: view '{}': {message}", path.display(), spec.name)
                        }
                        _ => anyhow::Error::from(e),
                    })?;
                }
                specs
            }
            None => {
                // A distorted lens needs fixed intrinsics: those of --fov-y by default.
                let intrinsics = match (self.intrinsics, self.distortion) {
                    (None, Some(_)) => Some(Intrinsics::from_fov_y(fov_y, size.0, size.1)),
                    (k, _) => k,
                };
                let spec = ViewSpec {
                    intrinsics,
                    distortion: self.distortion,
                    ..ViewSpec::new(size.0, size.1)
                };
                spec.validate()?;
                vec![spec]
            }
        })
    }

    /// The motion blur of --shutter and --fps (None for a shutter of 0).
    pub fn motion_blur(&self) -> Result<Option<alpenglow::MotionBlurSettings>> {
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 1000.0) {
            bail!("invalid --fps {}: must be in (0, 1000]", self.fps);
        }
        if self.shutter == 0.0 {
            return Ok(None);
        }
        let settings = alpenglow::MotionBlurSettings {
            shutter_s: self.shutter,
            frame_interval_s: 1.0 / self.fps,
            ..Default::default()
        };
        settings.check()?;
        Ok(Some(settings))
    }

    /// `camera` placed by --pose or --eye with --rotation.
    pub fn place(&self, camera: Camera) -> Result<Camera> {
        let (fov, near, far) = (camera.fov_y_deg, camera.near, camera.far);
        Ok(match (self.pose, self.rotation) {
            // The pose's errors are the pose's (its translation is the eye).
            (Some(pose), _) => Camera::from_pose(pose, fov, near, far).map_err(|e| match e {
                alpenglow::Error::InvalidArgument { parameter, message }
                    if ["camera.eye", "camera.target", "camera.up"].contains(&parameter.as_str()) =>
                {
                    anyhow::anyhow!("invalid --pose: {message}")
                }
                e => e.into(),
            })?,
            (None, Some(rotation)) => Camera::from_position_rotation(camera.eye, rotation, fov, near, far)?,
            (None, None) => camera,
        })
    }
}

/// The cameras of a frame: the rig's views around `camera`, or `camera`.
pub fn frame_cameras(rig: Option<&Rig>, camera: &Camera) -> Result<Vec<Camera>> {
    Ok(match rig {
        Some(rig) => rig.cameras(camera)?,
        None => vec![*camera],
    })
}

/// Checks an output path against the views: several views need `{view}`
/// in it (one file per view), and `{view}` needs named views (a rig's; the
/// command's own camera has no name, and `{view}` would expand to nothing).
pub fn check_pattern(path: &Option<PathBuf>, flag: &str, views: &[ViewSpec]) -> Result<()> {
    let Some(path) = path else { return Ok(()) };
    let has = path.to_string_lossy().contains(VIEW_PATTERN);
    if has && views.iter().any(|v| v.name.is_empty()) {
        bail!(
            "{flag} {}: {VIEW_PATTERN} is the name of a rig's view, and without --rig or --rig-preset \
             there is none; remove it from the path",
            path.display()
        );
    }
    if views.len() > 1 && !has {
        bail!(
            "{flag} {}: a rig of {} views writes one file per view; put {VIEW_PATTERN} in the path",
            path.display(),
            views.len()
        );
    }
    Ok(())
}

/// `path` for view `name` (`{view}` replaced).
pub fn view_path(path: &Path, name: &str) -> PathBuf {
    PathBuf::from(path.to_string_lossy().replace(VIEW_PATTERN, name))
}

/// `path` of every view, for the output checks.
pub fn view_paths(path: &Option<PathBuf>, views: &[ViewSpec]) -> Vec<Option<PathBuf>> {
    match path {
        Some(p) => views.iter().map(|v| Some(view_path(p, &v.name))).collect(),
        None => vec![None; views.len()],
    }
}

fn numbers<const N: usize>(s: &str, what: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| format!("'{s}' is not {what}")))
        .collect::<Result<_, _>>()?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!("'{s}' has a non-finite number"));
    }
    v.try_into()
        .map_err(|v: Vec<f64>| format!("'{s}' has {} numbers; expected {what}", v.len()))
}

fn parse_pose(s: &str) -> Result<DMat4, String> {
    let m = numbers::<16>(s, "16 numbers (a 4×4 matrix, row by row)")?;
    let pose = DMat4::from_cols_array(&m).transpose();
    if pose.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(format!("'{s}': the last row must be 0,0,0,1"));
    }
    Ok(pose)
}

fn parse_quaternion(s: &str) -> Result<DQuat, String> {
    let [x, y, z, w] = numbers::<4>(s, "X,Y,Z,W")?;
    let q = DQuat::from_xyzw(x, y, z, w);
    if (q.length() - 1.0).abs() > 1e-3 {
        return Err(format!("'{s}' is not a unit quaternion (length {:.4})", q.length()));
    }
    Ok(q.normalize())
}

fn parse_intrinsics(s: &str) -> Result<Intrinsics, String> {
    let [fx, fy, cx, cy] = numbers::<4>(s, "FX,FY,CX,CY")?;
    Ok(Intrinsics { fx, fy, cx, cy })
}

fn parse_distortion(s: &str) -> Result<Distortion, String> {
    let [k1, k2, k3, p1, p2] = numbers::<5>(s, "K1,K2,K3,P1,P2")?;
    let d = Distortion { k1, k2, k3, p1, p2 };
    d.validate().map_err(|e| format!("'{s}': {e}"))?;
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_parse_row_by_row() {
        let pose = parse_pose("1,0,0,10, 0,0,-1,20, 0,1,0,30, 0,0,0,1").unwrap();
        assert_eq!(pose.w_axis.truncate(), glam::DVec3::new(10.0, 20.0, 30.0));
        // Camera y (up) is world z; camera −z (forward) is world y.
        assert_eq!(pose.y_axis.truncate(), glam::DVec3::Z);
        assert_eq!(-pose.z_axis.truncate(), glam::DVec3::Y);
        assert!(parse_pose("1,0,0").is_err());
        assert!(parse_pose("1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1").is_err());
        assert!(parse_quaternion("0,0,0,2").is_err());
        assert!(parse_distortion("0,0,0,0,5").unwrap_err().contains("p2"));
    }

    #[test]
    fn rig_outputs_need_the_view_pattern() {
        let rig = Rig::ring6(64);
        let views = rig.specs((64, 48)).unwrap();
        assert!(check_pattern(&Some("out.png".into()), "--out", &views).is_err());
        assert!(check_pattern(&Some("out/{view}.png".into()), "--out", &views).is_ok());
        // Without a rig there is no view name for {view} to expand to.
        let single = [ViewSpec::new(64, 48)];
        let e = check_pattern(&Some("o_{view}.png".into()), "--exr", &single).unwrap_err();
        assert!(e.to_string().starts_with("--exr o_{view}.png: "), "{e}");
        assert!(check_pattern(&Some("o.png".into()), "--out", &single).is_ok());
        assert_eq!(
            view_path(Path::new("o/{view}.png"), "rear"),
            PathBuf::from("o/rear.png")
        );
    }
}
