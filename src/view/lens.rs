//! Camera models beyond the vertical field of view: pinhole intrinsics in
//! pixels (off-centre principal points and non-square pixels, as projector
//! channels and calibrated simulator cameras need) and the projection they
//! give, in Vulkan's conventions (depth 0..1, image row 0 at the top); the
//! Brown–Conrady lens model in OpenCV's convention and its inversion (what
//! `post.distortion` resamples with, [`crate::post::distortion`]).
//!
//! A camera ray with normalised coordinates (x, y) = (X/Z, Y/Z) is imaged at
//! x_d = x·(1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²),
//! y_d = y·(1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y, r² = x² + y²,
//! pixel (u, v) = (fx x_d + cx, fy y_d + cy), pixel (i, j)'s centre at
//! (u, v) = (i, j) (OpenCV's convention, so calibrations apply unchanged;
//! a centred principal point is ((W − 1)/2, (H − 1)/2)).

use glam::{DMat4, DVec4};

use crate::error::{Error, Result};

/// Pinhole intrinsics of an image, in pixels (OpenCV's K and convention):
/// a camera-space point (x right, y down, z forward) lands at pixel
/// `(fx·x/z + cx, fy·y/z + cy)`, where pixel (i, j)'s centre is at (i, j)
/// (so the centre of a W×H image is ((W − 1)/2, (H − 1)/2)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Intrinsics {
    /// The intrinsics of a centred pinhole with vertical field of view
    /// `fov_y_deg` and square pixels.
    pub fn from_fov_y(fov_y_deg: f64, width: u32, height: u32) -> Intrinsics {
        let fy = 0.5 * f64::from(height) / (0.5 * fov_y_deg.to_radians()).tan();
        Intrinsics::centred(fy, fy, width, height)
    }

    /// Focal lengths `fx`, `fy` and the principal point at the centre of a
    /// `width`×`height` image.
    pub fn centred(fx: f64, fy: f64, width: u32, height: u32) -> Intrinsics {
        Intrinsics {
            fx,
            fy,
            cx: 0.5 * f64::from(width) - 0.5,
            cy: 0.5 * f64::from(height) - 0.5,
        }
    }

    /// Checks only that the focal lengths are finite and positive and the
    /// principal point finite; errors name `parameter.fx` and so on.
    pub fn check_finite(&self, parameter: &str) -> Result<()> {
        for (name, v, positive) in [
            ("fx", self.fx, true),
            ("fy", self.fy, true),
            ("cx", self.cx, false),
            ("cy", self.cy, false),
        ] {
            if !v.is_finite() || (positive && v <= 0.0) {
                let need = if positive { "positive and finite" } else { "finite" };
                return Err(Error::invalid(
                    format!("{parameter}.{name}"),
                    format!("{v}; must be {need}"),
                ));
            }
        }
        Ok(())
    }

    /// Checks that the intrinsics describe a forward-looking pinhole whose
    /// frustum stays within 179° on each axis and whose principal point is
    /// within a few image sizes of the image.
    pub fn validate(&self, width: u32, height: u32) -> Result<()> {
        let (w, h) = (f64::from(width), f64::from(height));
        for (name, v) in [("fx", self.fx), ("fy", self.fy)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("camera.{name}"),
                    format!("{v} pixels; must be finite and > 0"),
                ));
            }
        }
        for (name, v, side) in [("cx", self.cx, w), ("cy", self.cy, h)] {
            if !(v.is_finite() && v.abs() <= 4.0 * side.max(1.0) + side) {
                return Err(Error::invalid(
                    format!("camera.{name}"),
                    format!("{v} pixels; must be finite and within 4 image sizes of the {side}-pixel image"),
                ));
            }
        }
        let (tx, ty) = self.half_tangents(width, height);
        let limit = (89.5f64).to_radians().tan();
        if tx.0.max(tx.1) > limit || ty.0.max(ty.1) > limit {
            return Err(Error::invalid(
                "camera.fx/camera.fy",
                format!(
                    "fx {} and fy {} with cx {}, cy {} open the view beyond 179°",
                    self.fx, self.fy, self.cx, self.cy
                ),
            ));
        }
        Ok(())
    }

    /// Tangents of the frustum's half-angles: ((left, right), (top, bottom)),
    /// each the distance from the optical axis at depth 1 (negative when the
    /// principal point lies outside the image).
    pub fn half_tangents(&self, width: u32, height: u32) -> ((f64, f64), (f64, f64)) {
        let (w, h) = (f64::from(width), f64::from(height));
        let (cx, cy) = (self.cx + 0.5, self.cy + 0.5);
        ((cx / self.fx, (w - cx) / self.fx), (cy / self.fy, (h - cy) / self.fy))
    }

    /// The symmetric frustum enclosing this one: (vertical field of view in
    /// degrees, aspect = tan(fov_x/2) / tan(fov_y/2)). CPU culling and LOD
    /// use it; the GPU projects with the exact, off-axis one.
    pub fn enclosing_fov(&self, width: u32, height: u32) -> (f64, f64) {
        let ((l, r), (t, b)) = self.half_tangents(width, height);
        let tan_x = l.abs().max(r.abs()).max(1e-9);
        let tan_y = t.abs().max(b.abs()).max(1e-9);
        (2.0 * tan_y.atan().to_degrees(), tan_x / tan_y)
    }

    /// The principal point in normalised device coordinates (x right, y down).
    pub fn principal_ndc(&self, width: u32, height: u32) -> (f64, f64) {
        let (w, h) = (f64::from(width), f64::from(height));
        (2.0 * (self.cx + 0.5) / w - 1.0, 2.0 * (self.cy + 0.5) / h - 1.0)
    }

    /// These intrinsics for the image scaled to `width`×`height` from
    /// `from` (the same rays through the same image area).
    pub fn scaled(&self, from: (u32, u32), width: u32, height: u32) -> Intrinsics {
        let sx = f64::from(width) / f64::from(from.0);
        let sy = f64::from(height) / f64::from(from.1);
        Intrinsics {
            fx: self.fx * sx,
            fy: self.fy * sy,
            cx: (self.cx + 0.5) * sx - 0.5,
            cy: (self.cy + 0.5) * sy - 0.5,
        }
    }

    /// View space (right-handed, looking down −z, y up) → Vulkan clip space
    /// of a `width`×`height` image: x right, y down (row 0 at the top),
    /// reversed depth, 1 at `near` and 0 at `far` (`view::depth`).
    pub fn projection(&self, width: u32, height: u32, near: f64, far: f64) -> DMat4 {
        let (w, h) = (f64::from(width), f64::from(height));
        // With d = −z the view-space depth: ndc.x = (2fx/w)·x/d + (2cx/w − 1),
        // ndc.y (down) = (2fy/h)·(−y)/d + (2cy/h − 1).
        let (ox, oy) = self.principal_ndc(width, height);
        let (a, b) = super::depth::depth_row(near, far);
        DMat4::from_cols(
            DVec4::new(2.0 * self.fx / w, 0.0, 0.0, 0.0),
            DVec4::new(0.0, -2.0 * self.fy / h, 0.0, 0.0),
            DVec4::new(-ox, -oy, a, -1.0),
            DVec4::new(0.0, 0.0, b, 0.0),
        )
    }
}

/// Brown–Conrady lens distortion (OpenCV's k1, k2, k3, p1, p2 and
/// convention, see the module) on normalised coordinates
/// `x = (u − cx)/fx`, `y = (v − cy)/fy`. The renderer draws an undistorted
/// image and resamples it (`post.distortion`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Distortion {
    pub k1: f64,
    pub k2: f64,
    pub k3: f64,
    pub p1: f64,
    pub p2: f64,
}

/// Largest accepted |k1|, |k2|, |k3|.
pub const MAX_RADIAL: f64 = 10.0;
/// Largest accepted |p1|, |p2|.
pub const MAX_TANGENTIAL: f64 = 1.0;

impl Distortion {
    /// The distorted normalised coordinates of the ray (x, y).
    pub fn distort(&self, [x, y]: [f64; 2]) -> [f64; 2] {
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        [
            x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x),
            y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y,
        ]
    }

    /// The Jacobian ∂(x_d, y_d)/∂(x, y), rows x_d and y_d.
    pub fn jacobian(&self, [x, y]: [f64; 2]) -> [[f64; 2]; 2] {
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        let slope = self.k1 + r2 * (2.0 * self.k2 + r2 * 3.0 * self.k3);
        let off = 2.0 * x * y * slope + 2.0 * self.p1 * x + 2.0 * self.p2 * y;
        [
            [
                radial + 2.0 * x * x * slope + 2.0 * self.p1 * y + 6.0 * self.p2 * x,
                off,
            ],
            [
                off,
                radial + 2.0 * y * y * slope + 6.0 * self.p1 * y + 2.0 * self.p2 * x,
            ],
        ]
    }

    /// The ray (x, y) imaged at (x_d, y_d): damped Newton iterations from
    /// (x_d, y_d); None when they do not converge (to 1e-12) in 100 steps or
    /// meet a Jacobian that is not positive.
    pub fn undistort(&self, target: [f64; 2]) -> Option<[f64; 2]> {
        let residual = |p: [f64; 2]| {
            let d = self.distort(p);
            [d[0] - target[0], d[1] - target[1]]
        };
        let size = |e: [f64; 2]| e[0].abs().max(e[1].abs());
        let tolerance = 1e-12 * (1.0 + size(target));
        let (mut p, mut e) = (target, residual(target));
        for _ in 0..100 {
            let error = size(e);
            if error.is_nan() {
                return None;
            }
            if error <= tolerance {
                return Some(p);
            }
            let j = self.jacobian(p);
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if det.is_nan() || det <= 0.0 {
                return None;
            }
            let step = [
                (j[1][1] * e[0] - j[0][1] * e[1]) / det,
                (j[0][0] * e[1] - j[1][0] * e[0]) / det,
            ];
            let mut lambda = 1.0;
            loop {
                let q = [p[0] - lambda * step[0], p[1] - lambda * step[1]];
                let eq = residual(q);
                if size(eq) < size(e) {
                    (p, e) = (q, eq);
                    break;
                }
                lambda *= 0.5;
                if lambda < 1e-9 {
                    return None;
                }
            }
        }
        None
    }

    /// Checks that every coefficient is finite and within `MAX_RADIAL`
    /// (k) or `MAX_TANGENTIAL` (p); errors name `distortion.k1` and so on.
    pub fn validate(&self) -> Result<()> {
        self.check_as("distortion")
    }

    /// [`Distortion::validate`] with errors naming `parameter.k1` and so on.
    pub fn check_as(&self, parameter: &str) -> Result<()> {
        let coefficients = [
            ("k1", self.k1, MAX_RADIAL),
            ("k2", self.k2, MAX_RADIAL),
            ("k3", self.k3, MAX_RADIAL),
            ("p1", self.p1, MAX_TANGENTIAL),
            ("p2", self.p2, MAX_TANGENTIAL),
        ];
        for (name, v, max) in coefficients {
            if !(v.is_finite() && v.abs() <= max) {
                return Err(Error::invalid(
                    format!("{parameter}.{name}"),
                    format!("{v}; must be finite with |{name}| ≤ {max}"),
                ));
            }
        }
        Ok(())
    }

    /// The coefficient whose term is largest at radius² `r2` (named in
    /// errors as `lens.k1` and so on).
    pub fn dominant(&self, r2: f64) -> &'static str {
        let terms = [
            ("lens.k1", (self.k1 * r2).abs()),
            ("lens.k2", (self.k2 * r2 * r2).abs()),
            ("lens.k3", (self.k3 * r2 * r2 * r2).abs()),
            ("lens.p1", (3.0 * self.p1 * r2).abs()),
            ("lens.p2", (3.0 * self.p2 * r2).abs()),
        ];
        terms.iter().fold(terms[0], |a, &b| if b.1 > a.1 { b } else { a }).0
    }

    /// The first radius in [0, `r_max`] where the radial mapping
    /// r·(1 + k1 r² + k2 r⁴ + k3 r⁶) stops increasing (the lens folds).
    pub fn radial_fold(&self, r_max: f64) -> Option<f64> {
        const STEPS: u32 = 4096;
        (0..=STEPS).map(|i| r_max * f64::from(i) / f64::from(STEPS)).find(|&r| {
            let r2 = r * r;
            1.0 + r2 * (3.0 * self.k1 + r2 * (5.0 * self.k2 + r2 * 7.0 * self.k3)) <= 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_intrinsics_give_the_cameras_projection() {
        let (w, h) = (640, 360);
        let k = Intrinsics::from_fov_y(50.0, w, h);
        let mut expected = DMat4::perspective_rh(50f64.to_radians(), 640.0 / 360.0, 0.5, 900.0);
        crate::view::depth::set_reversed_depth(&mut expected, 0.5, 900.0);
        expected.y_axis.y = -expected.y_axis.y;
        let got = k.projection(w, h, 0.5, 900.0);
        assert!(got.abs_diff_eq(expected, 1e-12), "{got:?} vs {expected:?}");
        assert!((k.enclosing_fov(w, h).0 - 50.0).abs() < 1e-9);
    }

    #[test]
    fn a_point_projects_to_its_opencv_pixel() {
        let (w, h) = (320, 200);
        let k = Intrinsics {
            fx: 300.0,
            fy: 260.0,
            cx: 100.0,
            cy: 120.0,
        };
        // OpenCV camera (x right, y down, z forward) = view space (x, −y, −z).
        let (x, y, z) = (1.5, -0.7, 4.0);
        let clip = k.projection(w, h, 0.1, 100.0) * DVec4::new(x, -y, -z, 1.0);
        let ndc = clip.truncate() / clip.w;
        // Pixel centres at integers: continuous position − ½.
        let pixel = ((ndc.x + 1.0) * 0.5 * 320.0 - 0.5, (ndc.y + 1.0) * 0.5 * 200.0 - 0.5);
        let expected = (300.0 * x / z + 100.0, 260.0 * y / z + 120.0);
        assert!((pixel.0 - expected.0).abs() < 1e-9 && (pixel.1 - expected.1).abs() < 1e-9);
        assert!(ndc.z > 0.0 && ndc.z < 1.0);
    }

    #[test]
    fn absurd_intrinsics_name_their_parameter() {
        let ok = Intrinsics::from_fov_y(60.0, 320, 200);
        assert!(ok.validate(320, 200).is_ok());
        let bad = Intrinsics { fx: 0.0, ..ok };
        assert_eq!(bad.validate(320, 200).unwrap_err().parameter(), Some("camera.fx"));
        let bad = Intrinsics { cy: f64::NAN, ..ok };
        assert_eq!(bad.validate(320, 200).unwrap_err().parameter(), Some("camera.cy"));
        let wide = Intrinsics { fx: 0.1, ..ok };
        assert!(wide.validate(320, 200).is_err());
    }
}
