//! Camera paths for the `fly` command: keyframes read from a TOML file, or
//! an orbit around a point.
//!
//! A keyframe file is a list of `[[keyframe]]` tables, each with a `time`
//! in seconds and an `eye` and a `target` position in world metres:
//!
//! ```toml
//! [[keyframe]]
//! time = 0.0
//! eye = [5120.0, -1200.0, 1400.0]
//! target = [5120.0, 5120.0, 200.0]
//!
//! [[keyframe]]
//! time = 4.0
//! eye = [9000.0, 2000.0, 1100.0]
//! target = [5120.0, 5120.0, 200.0]
//! ```
//!
//! At least two and at most [`MAX_KEYFRAMES`] keyframes, times in
//! `0..=`[`MAX_KEYFRAME_TIME`] seconds and strictly increasing, positions
//! finite with three components within ±[`MAX_KEYFRAME_COORDINATE`] metres,
//! eye ≠ target; any other key is an error.
//! Field of view, near/far planes and the up vector come from a base
//! [`Camera`].
//!
//! Between keyframes, eye and target each follow a **centripetal**
//! Catmull–Rom spline (α = ½, Yuksel et al. 2011), which passes through
//! every keyframe and, unlike the uniform spline, never forms cusps or
//! loops within a segment when keyframes are unevenly spaced. Time maps
//! linearly onto each segment, so the speed may change at a keyframe when
//! neighbouring segments differ in length or duration. The end keyframes
//! are duplicated as phantom neighbours, which gives the path zero velocity
//! at its first and last keyframe (it eases in and out); outside the
//! keyframe times the camera holds the end keyframes.

use std::f64::consts::TAU;
use std::path::Path;

use glam::{DVec2, DVec3};
use serde::Deserialize;

use super::camera::{self, Camera, MAX_COORDINATE};
use crate::error::{Error, Result};

/// Latest keyframe time (seconds); times lie in `0..=MAX_KEYFRAME_TIME`, so
/// a path's duration is finite (±1e308 once overflowed it to infinity).
pub const MAX_KEYFRAME_TIME: f64 = 1e6;
/// Largest magnitude of a keyframe eye or target coordinate (metres).
pub const MAX_KEYFRAME_COORDINATE: f64 = 1e7;
/// Most keyframes in a path.
pub const MAX_KEYFRAMES: usize = 10_000;

/// Smallest ratio of an orbit's radius to the eye's distance from the
/// centre (the sine of the angle between the view and the vertical):
/// steeper orbits look straight down, along the default up vector.
pub const MIN_ORBIT_SLOPE: f64 = 1e-4;

/// A camera position at a time (seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    pub time: f64,
    pub eye: DVec3,
    pub target: DVec3,
}

/// The usual start of an orbit (the CLI's): −90°, i.e. south of the centre
/// looking north, like [`crate::renderer::Scene::default_camera`].
pub const DEFAULT_START_ANGLE_DEG: f64 = -90.0;

/// The eye circles `centre` at `radius` (in the xy plane) and at height
/// `centre.z + height`, always looking at `centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub centre: DVec3,
    /// Horizontal distance from the centre, metres (> 0).
    pub radius: f64,
    /// Eye z above `centre.z`, metres.
    pub height: f64,
    /// Full turns over the path; positive is counter-clockwise seen from above.
    pub turns: f64,
    /// Where the eye starts, degrees counter-clockwise from +X
    /// (0: east of the centre, −90: south of it).
    pub start_angle_deg: f64,
}

impl Orbit {
    /// The automatic orbit of a terrain spanning `[0, extent.x]×[0,
    /// extent.y]×[lo, hi]`: one turn from the south around its centre at
    /// 60 % of its half-size, 0.08 of its size above the highest point.
    /// Valid ([`Orbit::validate`]) for the box of every legal height field:
    /// centre, radius and height are kept within half of
    /// `MAX_COORDINATE` (a larger terrain is circled in part), and the
    /// radius is at least a fifth of the height (a terrain far higher than
    /// wide is circled, not looked at from straight above), and the eye
    /// stays apart from the centre at the centre's magnitude.
    pub fn around(extent: DVec2, lo: f64, hi: f64) -> Orbit {
        let size = extent.x.max(extent.y);
        let limit = 0.5 * MAX_COORDINATE;
        let centre = DVec3::new(extent.x * 0.5, extent.y * 0.5, lo).min(DVec3::splat(limit));
        let height = (hi - lo + size * 0.08).min(limit);
        let radius = (size * 0.3).min(limit).max(height * 0.2);
        // Far enough from the centre to tell them apart at its magnitude.
        let grow = (2e-8 * centre.abs().max_element().max(1.0) / radius.hypot(height)).max(1.0);
        Orbit {
            centre,
            radius: radius * grow,
            height: height * grow,
            turns: 1.0,
            start_angle_deg: DEFAULT_START_ANGLE_DEG,
        }
    }

    /// Eye position at normalised time `t` (clamped to [0, 1]).
    pub fn eye_at(&self, t: f64) -> DVec3 {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let angle = self.start_angle_deg.to_radians() + TAU * self.turns * t;
        self.centre + DVec3::new(self.radius * angle.cos(), self.radius * angle.sin(), self.height)
    }

    /// Checks that all numbers are finite, the radius is positive, and
    /// every camera on the orbit is valid ([`Camera::validate`] with up
    /// +Z): the eye within ±`MAX_COORDINATE`, not straight above the
    /// centre (radius at least `MIN_ORBIT_SLOPE` of the distance) and not
    /// on it.
    pub fn validate(&self) -> Result<()> {
        let finite = self.centre.is_finite()
            && [self.radius, self.height, self.turns, self.start_angle_deg]
                .iter()
                .all(|v| v.is_finite());
        if !finite {
            return Err(Error::invalid("orbit", "all numbers must be finite"));
        }
        if self.radius <= 0.0 {
            return Err(Error::invalid(
                "orbit",
                format!("radius {} must be positive", self.radius),
            ));
        }
        // The cameras of the orbit, checked here so that their problems are
        // reported as the orbit's (not as an eye the user never gave).
        let reach = self.centre.truncate().abs().max_element() + self.radius;
        let (top, centre) = ((self.centre.z + self.height).abs(), self.centre.abs().max_element());
        if reach > MAX_COORDINATE || top > MAX_COORDINATE || centre > MAX_COORDINATE {
            return Err(Error::invalid(
                "orbit",
                format!(
                    "centre {}, radius {} and height {} take the eye beyond ±{MAX_COORDINATE:e} m, \
                     the largest coordinate a camera may have",
                    camera::short_vec(self.centre),
                    camera::short(self.radius),
                    camera::short(self.height)
                ),
            ));
        }
        let distance = self.radius.hypot(self.height);
        if self.radius < MIN_ORBIT_SLOPE * distance {
            return Err(Error::invalid(
                "orbit",
                format!(
                    "radius {} is too small for height {}: the eye would look straight down",
                    camera::short(self.radius),
                    camera::short(self.height)
                ),
            ));
        }
        if distance < 1e-8 * centre.max(1.0) {
            return Err(Error::invalid(
                "orbit",
                format!(
                    "radius {} and height {} are too small for a centre {} m from the origin: \
                     the eye would sit on the centre",
                    camera::short(self.radius),
                    camera::short(self.height),
                    camera::short(centre)
                ),
            ));
        }
        Ok(())
    }
}

/// How the camera moves over a flythrough.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPath {
    /// Catmull–Rom through keyframes (see the module documentation); time in
    /// the keyframes' seconds.
    Keyframes(Vec<Keyframe>),
    /// A circle around a point; time normalised to [0, 1].
    Orbit(Orbit),
}

/// `v` for a message: exponent notation when huge (`1e308`, not 309 digits).
fn short(v: f64) -> String {
    if v.abs() >= 1e16 {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// What is wrong with keyframe `k` (following `prev`), if anything.
fn keyframe_problem(prev: Option<&Keyframe>, k: &Keyframe) -> Option<String> {
    if !(0.0..=MAX_KEYFRAME_TIME).contains(&k.time) {
        return Some(format!("time {} is not in 0..={MAX_KEYFRAME_TIME} s", short(k.time)));
    }
    if let Some(p) = prev {
        if k.time <= p.time {
            return Some(format!(
                "time {} is not after the previous keyframe's {}; times must strictly increase",
                k.time, p.time
            ));
        }
    }
    if !k.eye.is_finite() || !k.target.is_finite() {
        return Some("eye and target must be finite".into());
    }
    for (what, p) in [("eye", k.eye), ("target", k.target)] {
        if p.abs().max_element() > MAX_KEYFRAME_COORDINATE {
            return Some(format!(
                "{what} ({}, {}, {}) exceeds ±{MAX_KEYFRAME_COORDINATE} m",
                short(p.x),
                short(p.y),
                short(p.z)
            ));
        }
    }
    if k.eye.distance(k.target) <= 1e-9 * k.eye.length().max(1.0) {
        return Some("eye equals target; there is no view direction".into());
    }
    None
}

impl CameraPath {
    /// Checks the path: for keyframes what [`load_keyframes`] checks, for an
    /// orbit [`Orbit::validate`].
    pub fn validate(&self) -> Result<()> {
        match self {
            CameraPath::Keyframes(keys) => {
                if keys.len() < 2 {
                    return Err(Error::invalid(
                        "camera path",
                        format!("needs at least 2 keyframes, has {}", keys.len()),
                    ));
                }
                for (i, k) in keys.iter().enumerate() {
                    if let Some(problem) = keyframe_problem(i.checked_sub(1).map(|j| &keys[j]), k) {
                        return Err(Error::invalid("camera path", format!("keyframe {}: {problem}", i + 1)));
                    }
                }
                Ok(())
            }
            CameraPath::Orbit(orbit) => orbit.validate(),
        }
    }

    /// Time of the path's first camera: the first keyframe's time, 0 for an
    /// orbit.
    pub fn start_time(&self) -> f64 {
        match self {
            CameraPath::Keyframes(keys) => keys.first().map_or(0.0, |k| k.time),
            CameraPath::Orbit(_) => 0.0,
        }
    }

    /// Length of the path: last minus first keyframe time (seconds), 1.0 for
    /// an orbit.
    pub fn duration(&self) -> f64 {
        match self {
            CameraPath::Keyframes(keys) => match (keys.first(), keys.last()) {
                (Some(a), Some(b)) => b.time - a.time,
                _ => 0.0,
            },
            CameraPath::Orbit(_) => 1.0,
        }
    }

    /// `base` moved to time `t` of the path (clamped to the path's time
    /// range; NaN means the start). Keyframe times are absolute: the path
    /// runs from [`CameraPath::start_time`] for [`CameraPath::duration`].
    /// A keyframe path with no keyframes returns `base` unchanged. The
    /// result passes [`Camera::validate`] when the path passes
    /// [`CameraPath::validate`], `base` does, and the view direction neither
    /// vanishes nor becomes parallel to `base.up` along the way.
    pub fn camera_at(&self, t: f64, base: &Camera) -> Camera {
        let (eye, target) = match self {
            CameraPath::Keyframes(keys) => match interpolate(keys, t) {
                Some(pose) => pose,
                None => return *base,
            },
            CameraPath::Orbit(orbit) => (orbit.eye_at(t), orbit.centre),
        };
        Camera { eye, target, ..*base }
    }

    /// `frames` cameras evenly spaced over the whole path, both ends
    /// included; one frame gives just the start, zero none. Allocates all of
    /// them: for long paths use [`CameraPath::sample_at`].
    pub fn sample(&self, frames: u32, base: &Camera) -> Vec<Camera> {
        (0..frames).map(|i| self.sample_at(i, frames, base)).collect()
    }

    /// Camera `i` of [`CameraPath::sample`]`(frames, base)`, computed alone
    /// (a path of any length in constant memory).
    pub fn sample_at(&self, i: u32, frames: u32, base: &Camera) -> Camera {
        let (start, duration) = (self.start_time(), self.duration());
        let t = if i + 1 == frames && frames > 1 {
            start + duration
        } else if frames > 1 {
            start + duration * f64::from(i) / f64::from(frames - 1)
        } else {
            start
        };
        self.camera_at(t, base)
    }
}

/// Cubic Hermite curve from `p1` (tangent `m1`) to `p2` (tangent `m2`),
/// `u` in [0, 1]; exactly `p1` at 0 and `p2` at 1.
fn hermite(p1: DVec3, m1: DVec3, p2: DVec3, m2: DVec3, u: f64) -> DVec3 {
    let (u2, u3) = (u * u, u * u * u);
    p1 * (2.0 * u3 - 3.0 * u2 + 1.0) + m1 * (u3 - 2.0 * u2 + u) + p2 * (3.0 * u2 - 2.0 * u3) + m2 * (u3 - u2)
}

/// Centripetal Catmull–Rom segment from `p1` to `p2` with neighbours `p0`
/// and `p3`, in Hermite form: knot intervals are `|Δp|^½` (floored so
/// coincident points, e.g. a fixed target, stay finite) and the tangents
/// those of the non-uniform spline, scaled to the segment.
fn catmull_rom(p0: DVec3, p1: DVec3, p2: DVec3, p3: DVec3, u: f64) -> DVec3 {
    let knot = |a: DVec3, b: DVec3| a.distance(b).sqrt().max(1e-12);
    let (d0, d1, d2) = (knot(p0, p1), knot(p1, p2), knot(p2, p3));
    let m1 = ((p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1) * d1;
    let m2 = ((p2 - p1) / d1 - (p3 - p1) / (d1 + d2) + (p3 - p2) / d2) * d1;
    hermite(p1, m1, p2, m2, u)
}

/// Eye and target at time `t`; `None` without keyframes.
fn interpolate(keys: &[Keyframe], t: f64) -> Option<(DVec3, DVec3)> {
    let (first, last) = (keys.first()?, keys.last()?);
    if t.is_nan() || t <= first.time {
        return Some((first.eye, first.target));
    }
    if t >= last.time {
        return Some((last.eye, last.target));
    }
    // keys[i].time <= t < keys[i + 1].time (times increase on valid paths;
    // the clamps keep invalid ones in bounds).
    let i = keys.partition_point(|k| k.time <= t).clamp(1, keys.len() - 1) - 1;
    let (a, b) = (&keys[i], &keys[i + 1]);
    let before = &keys[i.saturating_sub(1)];
    let after = &keys[(i + 2).min(keys.len() - 1)];
    let span = b.time - a.time;
    let u = if span > 0.0 {
        ((t - a.time) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some((
        catmull_rom(before.eye, a.eye, b.eye, after.eye, u),
        catmull_rom(before.target, a.target, b.target, after.target, u),
    ))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyframeFile {
    #[serde(default)]
    keyframe: Vec<RawKeyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawKeyframe {
    time: toml::Spanned<f64>,
    eye: toml::Spanned<Vec<f64>>,
    target: toml::Spanned<Vec<f64>>,
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Parses keyframe-file `text`; errors name `origin` (see [`load_keyframes`]).
pub fn parse_keyframes(text: &str, origin: &Path) -> Result<CameraPath> {
    let file: KeyframeFile = toml::from_str(text).map_err(|e| {
        let message = e.message().trim().replace('\n', "; ");
        match e.span() {
            Some(span) => Error::input(origin, format!("line {}: {message}", line_of(text, span.start))),
            None => Error::input(origin, message),
        }
    })?;
    if file.keyframe.len() > MAX_KEYFRAMES {
        return Err(Error::input(
            origin,
            format!(
                "{} [[keyframe]] tables, more than the limit of {MAX_KEYFRAMES}",
                file.keyframe.len()
            ),
        ));
    }
    if file.keyframe.len() < 2 {
        return Err(Error::input(
            origin,
            format!("needs at least 2 [[keyframe]] tables, found {}", file.keyframe.len()),
        ));
    }
    let mut keys: Vec<Keyframe> = Vec::with_capacity(file.keyframe.len());
    for (i, raw) in file.keyframe.iter().enumerate() {
        let at = |span: std::ops::Range<usize>| format!("keyframe {} (line {})", i + 1, line_of(text, span.start));
        let vector = |v: &toml::Spanned<Vec<f64>>, name: &str| match v.get_ref().as_slice() {
            &[x, y, z] => Ok(DVec3::new(x, y, z)),
            other => Err(Error::input(
                origin,
                format!(
                    "{}: {name} has {} components; expected [x, y, z]",
                    at(v.span()),
                    other.len()
                ),
            )),
        };
        let k = Keyframe {
            time: *raw.time.get_ref(),
            eye: vector(&raw.eye, "eye")?,
            target: vector(&raw.target, "target")?,
        };
        if let Some(problem) = keyframe_problem(keys.last(), &k) {
            return Err(Error::input(origin, format!("{}: {problem}", at(raw.time.span()))));
        }
        keys.push(k);
    }
    Ok(CameraPath::Keyframes(keys))
}

/// Reads a keyframe TOML file (format in the module documentation). Errors
/// are one line naming the file, and the line for syntax errors and bad
/// keyframes.
pub fn load_keyframes(path: &Path) -> Result<CameraPath> {
    let bytes = crate::io::read_input(path)?;
    let text = String::from_utf8(bytes).map_err(|_| Error::input(path, "not UTF-8 text"))?;
    parse_keyframes(&text, path)
}

#[cfg(test)]
mod tests;
