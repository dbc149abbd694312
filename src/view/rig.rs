//! Multi-view rigs (§3.3: driving simulators show 360° around the car on
//! several projector channels): the views one frame renders, each with its
//! own image size, intrinsics and pose, posed either in the world or
//! relative to the rig's own camera (the car).
//!
//! Rig file (TOML), one `[[view]]` table per view (1 to [`MAX_VIEWS`]):
//!
//! ```toml
//! [[view]]
//! name = "front"                 # letters, digits, '-' and '_'; unique
//! position = [1.2, 0.0, 1.4]     # metres in the rig frame: x forward, y left, z up
//! yaw_pitch_roll = [0, -5, 0]    # degrees: yaw left, pitch up, roll right-down
//! fov_y = 45                     # or fx, fy, cx, cy in pixels
//! width = 640                    # width, height, near, far: the command's by default
//! height = 480
//!
//! [[view]]
//! name = "overview"
//! eye = [100, 200, 300]          # or a world pose: eye, target, up (default 0,0,1)
//! target = [500, 500, 0]
//! fx = 500
//! fy = 500
//! cx = 300
//! cy = 200
//! k1 = -0.1                      # optional Brown–Conrady distortion: k1 k2 k3 p1 p2
//! ```
//!
//! Limits (errors otherwise): coordinates within ±[`MAX_RIG_COORDINATE`] m,
//! angles within ±[`MAX_RIG_ANGLE`]°, `0 < near < far ≤` [`MAX_RIG_FAR`] m,
//! sizes as [`super::validate_size`], names 1 to 64 characters; the file is
//! read through [`crate::io::read_input`] and must be UTF-8.

use std::path::Path;

use glam::{DMat3, DVec3};
use serde::Deserialize;

use super::lens::{Distortion, Intrinsics};
use super::{validate_size, Camera, Footprint, View};
use crate::error::{Error, Result};

/// Most views a frame renders.
pub const MAX_VIEWS: usize = 16;
/// Largest magnitude of a world `eye`/`target` coordinate or a rig-relative
/// `position` component (metres).
pub const MAX_RIG_COORDINATE: f64 = 1e7;
/// Largest magnitude of a yaw, pitch or roll (degrees).
pub const MAX_RIG_ANGLE: f64 = 360.0;
/// Largest `far` clip distance (metres); `near` is positive and below it.
pub const MAX_RIG_FAR: f64 = 1e9;

/// Where a view looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RigPose {
    /// A fixed world pose.
    World { eye: DVec3, target: DVec3, up: DVec3 },
    /// Relative to the rig's camera: `position` in metres along (forward,
    /// left, up) of the rig camera, then turned by yaw (about up, positive
    /// to the left), pitch (positive up) and roll (positive: the image's
    /// right side goes down), in degrees, applied in that order.
    Relative { position: DVec3, yaw_pitch_roll_deg: DVec3 },
}

/// How a view projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RigLens {
    /// The rig camera's vertical field of view.
    Inherit,
    /// A vertical field of view in degrees, centred, square pixels.
    FovY(f64),
    /// Pinhole intrinsics in pixels.
    Pinhole(Intrinsics),
}

/// One view of a rig.
#[derive(Clone, Debug, PartialEq)]
pub struct RigView {
    pub name: String,
    pub pose: RigPose,
    pub lens: RigLens,
    pub distortion: Option<Distortion>,
    /// Image size; None: the command's.
    pub size: Option<(u32, u32)>,
    /// Clip planes; None: the rig camera's.
    pub near: Option<f64>,
    pub far: Option<f64>,
}

/// The image a view renders into, fixed for the life of a renderer; its
/// camera comes with each frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSpec {
    /// Names the view's passes (`pass@name`) and output files; empty for
    /// a single unnamed view.
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Pinhole intrinsics; None: the camera's field of view.
    pub intrinsics: Option<Intrinsics>,
    /// Lens distortion applied after rendering.
    pub distortion: Option<Distortion>,
}

impl ViewSpec {
    /// An unnamed `width`×`height` view projecting with its camera's field of view.
    pub fn new(width: u32, height: u32) -> ViewSpec {
        ViewSpec {
            name: String::new(),
            width,
            height,
            intrinsics: None,
            distortion: None,
        }
    }

    /// The view of this image through `camera`.
    pub fn view(&self, camera: Camera) -> View {
        View {
            name: self.name.clone(),
            camera,
            width: self.width,
            height: self.height,
            intrinsics: self.intrinsics,
        }
    }

    /// The angle (radians at the axis) one pixel of this view spans, the
    /// finer of its two sides ([`View::pixel_footprint`]), seen with
    /// `fov_y_deg` when it has no intrinsics.
    pub fn pixel_footprint(&self, fov_y_deg: f64) -> f64 {
        match self.intrinsics {
            None => Footprint::pixel_footprint_for(fov_y_deg.to_radians(), self.height),
            Some(k) => 1.0 / k.fx.max(k.fy),
        }
    }

    /// Checks the size, the intrinsics and the distortion.
    pub fn validate(&self) -> Result<()> {
        validate_size(self.width, self.height)?;
        if let Some(k) = &self.intrinsics {
            k.validate(self.width, self.height)?;
        }
        if let Some(d) = &self.distortion {
            d.validate()?;
        }
        Ok(())
    }
}

/// Checks a list of views: 1 to [`MAX_VIEWS`], each valid, names unique
/// and usable in file names (several views must all be named).
pub fn validate_views(views: &[ViewSpec]) -> Result<()> {
    if views.is_empty() || views.len() > MAX_VIEWS {
        return Err(Error::invalid(
            "views",
            format!("{} views; a frame renders 1 to {MAX_VIEWS}", views.len()),
        ));
    }
    for (i, v) in views.iter().enumerate() {
        v.validate()?;
        if views.len() > 1 || !v.name.is_empty() {
            check_name(&v.name)?;
        }
        if views[..i].iter().any(|w| w.name == v.name) {
            return Err(Error::invalid("view.name", format!("'{}' is used twice", v.name)));
        }
    }
    Ok(())
}

fn check_name(name: &str) -> Result<()> {
    let ok =
        !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    match ok {
        true => Ok(()),
        false => Err(Error::invalid(
            "view.name",
            format!("'{name}'; use 1 to 64 letters, digits, '-' or '_'"),
        )),
    }
}

/// Views rendered together in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    pub views: Vec<RigView>,
}

impl Rig {
    /// The 360° ring around a car: six 60° horizontal views (4:3, yaw 0°,
    /// 60°, … counter-clockwise from the front) at the rig camera, each
    /// `width` wide.
    pub fn ring6(width: u32) -> Rig {
        let names = ["front", "front_left", "rear_left", "rear", "rear_right", "front_right"];
        // In u64: any u32 width (the size checks of `specs` refuse a wrong one).
        let height = (u64::from(width) * 3 / 4).max(1) as u32;
        // 60° across at 4:3: tan(fov_y/2) = tan(30°)·3/4.
        let fov_y = 2.0 * (30f64.to_radians().tan() * 0.75).atan().to_degrees();
        let views = names
            .iter()
            .enumerate()
            .map(|(k, name)| RigView {
                name: name.to_string(),
                pose: RigPose::Relative {
                    position: DVec3::ZERO,
                    yaw_pitch_roll_deg: DVec3::new(60.0 * k as f64, 0.0, 0.0),
                },
                lens: RigLens::FovY(fov_y),
                distortion: None,
                size: Some((width, height)),
                near: None,
                far: None,
            })
            .collect();
        Rig { views }
    }

    /// The images of the views; `size` is the default image size.
    pub fn specs(&self, size: (u32, u32)) -> Result<Vec<ViewSpec>> {
        let specs: Vec<ViewSpec> = self
            .views
            .iter()
            .map(|v| {
                let (width, height) = v.size.unwrap_or(size);
                ViewSpec {
                    name: v.name.clone(),
                    width,
                    height,
                    intrinsics: match (v.lens, v.distortion) {
                        (RigLens::Pinhole(k), _) => Some(k),
                        // A distorted lens needs fixed intrinsics.
                        (RigLens::FovY(f), Some(_)) => Some(Intrinsics::from_fov_y(f, width, height)),
                        _ => None,
                    },
                    distortion: v.distortion,
                }
            })
            .collect();
        validate_views(&specs)?;
        Ok(specs)
    }

    /// The cameras of the views for the rig camera `rig` (its pose, field
    /// of view and clip planes are the defaults).
    pub fn cameras(&self, rig: &Camera) -> Result<Vec<Camera>> {
        rig.validate()?;
        let frame = DMat3::from_cols(rig.forward(), -rig.right(), rig.image_up());
        self.views
            .iter()
            .map(|v| {
                let (eye, target, up) = match v.pose {
                    RigPose::World { eye, target, up } => (eye, target, up),
                    RigPose::Relative {
                        position,
                        yaw_pitch_roll_deg: a,
                    } => {
                        let turn = DMat3::from_rotation_z(a.x.to_radians())
                            * DMat3::from_rotation_y(-a.y.to_radians())
                            * DMat3::from_rotation_x(a.z.to_radians());
                        let eye = rig.eye + frame * position;
                        (eye, eye + frame * (turn * DVec3::X), frame * (turn * DVec3::Z))
                    }
                };
                let camera = Camera {
                    eye,
                    target,
                    up,
                    fov_y_deg: match v.lens {
                        RigLens::FovY(f) => f,
                        _ => rig.fov_y_deg,
                    },
                    near: v.near.unwrap_or(rig.near),
                    far: v.far.unwrap_or(rig.far),
                };
                camera
                    .validate()
                    .map_err(|e| Error::invalid(format!("view {}", v.name), e.to_string()))?;
                Ok(camera)
            })
            .collect()
    }

    /// Parses rig-file `text` (format in the module documentation); errors
    /// name `origin`, the view and the key.
    pub fn parse(text: &str, origin: &Path) -> Result<Rig> {
        // Before the TOML parser builds every table: count the headers.
        let headers = text.lines().filter(|l| l.trim_start().starts_with("[[view")).count();
        if headers > MAX_VIEWS {
            return Err(Error::input(
                origin,
                format!("{headers} [[view]] tables; a rig has 1 to {MAX_VIEWS}"),
            ));
        }
        let file: RigFile = toml::from_str(text).map_err(|e| {
            let message = e.message().trim().replace('\n', "; ");
            match e.span() {
                Some(span) => Error::input(origin, format!("line {}: {message}", line_of(text, span.start))),
                None => Error::input(origin, message),
            }
        })?;
        if file.view.is_empty() || file.view.len() > MAX_VIEWS {
            return Err(Error::input(
                origin,
                format!("{} [[view]] tables; a rig has 1 to {MAX_VIEWS}", file.view.len()),
            ));
        }
        let views = file
            .view
            .into_iter()
            .enumerate()
            .map(|(i, raw)| {
                let label = match &raw.name {
                    Some(n) if !n.is_empty() => format!("view '{n}'"),
                    _ => format!("view {}", i + 1),
                };
                raw.into_view()
                    .map_err(|e| Error::input(origin, format!("{label}: {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        let rig = Rig { views };
        rig.specs((1, 1)).map_err(|e| Error::input(origin, e.to_string()))?;
        Ok(rig)
    }

    /// Reads a rig file.
    pub fn load(path: &Path) -> Result<Rig> {
        let bytes = crate::io::read_input(path)?;
        let text = String::from_utf8(bytes).map_err(|_| Error::input(path, "not UTF-8 text"))?;
        Rig::parse(&text, path)
    }
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFile {
    #[serde(default)]
    view: Vec<RawView>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawView {
    name: Option<String>,
    eye: Option<[f64; 3]>,
    target: Option<[f64; 3]>,
    up: Option<[f64; 3]>,
    position: Option<[f64; 3]>,
    yaw_pitch_roll: Option<[f64; 3]>,
    fov_y: Option<f64>,
    fx: Option<f64>,
    fy: Option<f64>,
    cx: Option<f64>,
    cy: Option<f64>,
    k1: Option<f64>,
    k2: Option<f64>,
    k3: Option<f64>,
    p1: Option<f64>,
    p2: Option<f64>,
    width: Option<u32>,
    height: Option<u32>,
    near: Option<f64>,
    far: Option<f64>,
}

/// Checks the pose and clip numbers of a raw view against the limits above.
fn check_numbers(v: &RawView) -> std::result::Result<(), String> {
    let vectors = [
        ("eye", v.eye, MAX_RIG_COORDINATE),
        ("target", v.target, MAX_RIG_COORDINATE),
        ("up", v.up, f64::MAX),
        ("position", v.position, MAX_RIG_COORDINATE),
        ("yaw_pitch_roll", v.yaw_pitch_roll, MAX_RIG_ANGLE),
    ];
    for (what, value, limit) in vectors {
        let Some(a) = value else { continue };
        if !a.iter().all(|x| x.is_finite()) {
            return Err(format!("{what} {a:?} is not finite"));
        }
        if a.iter().any(|x| x.abs() > limit) {
            return Err(format!("{what} {a:?} exceeds ±{limit}"));
        }
    }
    if v.up.is_some_and(|u| u == [0.0; 3]) {
        return Err("up is zero".into());
    }
    if let (Some(e), Some(t)) = (v.eye, v.target) {
        if e == t {
            return Err("eye equals target; there is no view direction".into());
        }
    }
    for (what, value) in [("near", v.near), ("far", v.far)] {
        if let Some(x) = value {
            if !(x > 0.0 && x <= MAX_RIG_FAR) {
                return Err(format!("{what} {x} is not in (0, {MAX_RIG_FAR}] m"));
            }
        }
    }
    if let (Some(near), Some(far)) = (v.near, v.far) {
        if near >= far {
            return Err(format!("near {near} is not below far {far}"));
        }
    }
    Ok(())
}

impl RawView {
    fn into_view(self) -> std::result::Result<RigView, String> {
        check_numbers(&self)?;
        let name = self.name.ok_or("has no name")?;
        // Every view of a rig file is named, even a lone one: its name
        // makes the output file names (`{view}`).
        check_name(&name).map_err(|_| format!("name '{name}': use 1 to 64 letters, digits, '-' or '_'"))?;
        let v3 = |a: [f64; 3]| DVec3::from_array(a);
        let pose = match (self.eye, self.target, self.position, self.yaw_pitch_roll) {
            (Some(eye), Some(target), None, None) => RigPose::World {
                eye: v3(eye),
                target: v3(target),
                up: v3(self.up.unwrap_or([0.0, 0.0, 1.0])),
            },
            (None, None, position, angles) if self.up.is_none() => RigPose::Relative {
                position: v3(position.unwrap_or([0.0; 3])),
                yaw_pitch_roll_deg: v3(angles.unwrap_or([0.0; 3])),
            },
            _ => return Err("give either eye and target (and up), or position and yaw_pitch_roll".into()),
        };
        let pinhole = [self.fx, self.fy, self.cx, self.cy];
        let lens = match (self.fov_y, pinhole) {
            (None, [None, None, None, None]) => RigLens::Inherit,
            (Some(f), [None, None, None, None]) => RigLens::FovY(f),
            (None, [Some(fx), Some(fy), Some(cx), Some(cy)]) => RigLens::Pinhole(Intrinsics { fx, fy, cx, cy }),
            _ => return Err("give either fov_y or all of fx, fy, cx, cy".into()),
        };
        let k = [self.k1, self.k2, self.k3, self.p1, self.p2];
        let distortion = k.iter().any(Option::is_some).then(|| {
            let [k1, k2, k3, p1, p2] = k.map(|c| c.unwrap_or(0.0));
            Distortion { k1, k2, k3, p1, p2 }
        });
        let size = match (self.width, self.height) {
            (Some(w), Some(h)) => Some((w, h)),
            (None, None) => None,
            _ => return Err("give both width and height, or neither".into()),
        };
        if let Some(f) = self.fov_y {
            if !(f > 0.0 && f < 180.0) {
                return Err(format!("fov_y {f}; must be in (0, 180) degrees"));
            }
        }
        Ok(RigView {
            name,
            pose,
            lens,
            distortion,
            size,
            near: self.near,
            far: self.far,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig_camera() -> Camera {
        Camera {
            eye: DVec3::new(100.0, 200.0, 30.0),
            target: DVec3::new(100.0, 300.0, 30.0),
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 0.5,
            far: 5000.0,
        }
    }

    #[test]
    fn ring6_looks_all_around() {
        let rig = Rig::ring6(320);
        let specs = rig.specs((640, 360)).unwrap();
        assert!(specs.iter().all(|s| (s.width, s.height) == (320, 240)));
        let cameras = rig.cameras(&rig_camera()).unwrap();
        // The rig looks along +y, so left is −x.
        assert!(cameras[0].forward().abs_diff_eq(DVec3::Y, 1e-12));
        let left = cameras[1].forward();
        assert!(left.x < 0.0 && (left.angle_between(DVec3::Y).to_degrees() - 60.0).abs() < 1e-9);
        assert!(cameras[3].forward().abs_diff_eq(-DVec3::Y, 1e-12));
        // 60° across each: tan(fov_x/2) = tan(30°).
        let c = &cameras[2];
        let tan_x = (0.5 * c.fov_y_deg.to_radians()).tan() * 320.0 / 240.0;
        assert!((tan_x - 30f64.to_radians().tan()).abs() < 1e-12);
        assert!(cameras
            .iter()
            .all(|c| c.eye == rig_camera().eye && c.image_up().abs_diff_eq(DVec3::Z, 1e-12)));
    }

    /// Any width gives a ring (3/4 of u32::MAX fits a u32); one beyond the
    /// image limits is refused by `specs`, naming the width, not a panic
    /// on overflow.
    #[test]
    fn ring6_of_any_width_is_checked_not_overflowed() {
        for width in [0, 1, 16_384, 16_385, u32::MAX / 3 + 1, u32::MAX] {
            let rig = Rig::ring6(width);
            let (w, h) = rig.views[0].size.unwrap();
            assert_eq!((w, u64::from(h)), (width, (u64::from(width) * 3 / 4).max(1)));
            if !(1..=16_384).contains(&width) {
                let e = rig.specs((64, 48)).unwrap_err();
                assert_eq!(e.parameter(), Some("width"), "{e}");
            }
        }
    }

    #[test]
    fn relative_poses_follow_the_rig() {
        let text = r#"
            [[view]]
            name = "up_right"
            position = [2, -1, 0.5]
            yaw_pitch_roll = [-90, 30, 0]
            [[view]]
            name = "rolled"
            yaw_pitch_roll = [0, 0, 90]
            [[view]]
            name = "world"
            eye = [0, 0, 10]
            target = [10, 0, 10]
            fx = 200
            fy = 210
            cx = 150
            cy = 100
            width = 300
            height = 200
        "#;
        let rig = Rig::parse(text, Path::new("rig.toml")).unwrap();
        let cams = rig.cameras(&rig_camera()).unwrap();
        // Forward +y, left −x, up +z: position (2, −1, 0.5) is 2 along y, 1 along +x.
        assert!(cams[0].eye.abs_diff_eq(DVec3::new(101.0, 202.0, 30.5), 1e-12));
        // Yaw −90° turns right (+x), pitch 30° up.
        let f = cams[0].forward();
        assert!(f.abs_diff_eq(
            DVec3::new(30f64.to_radians().cos(), 0.0, 30f64.to_radians().sin()),
            1e-12
        ));
        // Roll 90°: the image's up is the rig's right (+x).
        assert!(cams[1].image_up().abs_diff_eq(DVec3::X, 1e-12));
        let specs = rig.specs((640, 360)).unwrap();
        assert_eq!((specs[0].width, specs[2].width, specs[2].height), (640, 300, 200));
        assert_eq!(specs[2].intrinsics.unwrap().fy, 210.0);
    }

    #[test]
    fn bad_rigs_are_one_line_errors_naming_the_view() {
        let bad = [
            ("", "0 [[view]] tables"),
            ("[[view]]\nfov_y = 40", "has no name"),
            (
                "[[view]]\nname = \"a\"\neye = [0,0,1]\nposition = [0,0,0]",
                "either eye and target",
            ),
            ("[[view]]\nname = \"a\"\nfx = 100", "either fov_y or all of"),
            ("[[view]]\nname = \"a\"\nfov_y = 200", "fov_y 200"),
            ("[[view]]\nname = \"a b\"", "view 'a b': name 'a b'"),
            // A lone view named "" (accepted before: its files had no name).
            ("[[view]]\nname = \"\"", "view 1: name ''"),
            ("[[view]]\nname = \"a\"\n[[view]]\nname = \"\"", "view 2: name ''"),
            ("[[view]]\nname = \"a\\u001b[2J\"", "name 'a\\u{1b}[2J'"),
            ("[[view]]\nname = \"a\"\n[[view]]\nname = \"a\"", "used twice"),
            ("[[view]]\nname = \"a\"\nwidth = 0\nheight = 10", "width"),
            ("[[view]]\nname = \"a\"\nspeed = 3", "unknown field"),
            ("[[view]]\nname = \"a\"\nk1 = 1e9", "k1"),
            (
                "[[view]]\nname = \"a\"\nposition = [3e38, 0, 0]",
                "position [3e38, 0.0, 0.0] exceeds",
            ),
            (
                "[[view]]\nname = \"a\"\nyaw_pitch_roll = [1e300, 0, 0]",
                "yaw_pitch_roll",
            ),
            ("[[view]]\nname = \"a\"\neye = [0,0,1e8]\ntarget = [0,0,0]", "eye"),
            (
                "[[view]]\nname = \"a\"\neye = [0,0,1]\ntarget = [0,0,1]",
                "eye equals target",
            ),
            (
                "[[view]]\nname = \"a\"\neye = [0,0,1]\ntarget = [1,0,1]\nup = [0,0,0]",
                "up is zero",
            ),
            ("[[view]]\nname = \"a\"\nnear = -1", "near -1 is not in"),
            ("[[view]]\nname = \"a\"\nfar = inf", "far inf is not in"),
            (
                "[[view]]\nname = \"a\"\nnear = 10\nfar = 5",
                "near 10 is not below far 5",
            ),
            ("[[view]]\nname = \"a\"\nfov_y = nan", "fov_y NaN"),
            ("[[view]]\nname = \"a\"\nwidth = 99999\nheight = 10", "width"),
            (&"[[view]]\nname = \"v\"\n".repeat(40), "40 [[view]] tables"),
        ];
        for (text, expected) in bad {
            let e = Rig::parse(text, Path::new("cams.toml")).unwrap_err().to_string();
            assert!(e.contains("cams.toml") && e.contains(expected), "{text:?}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
