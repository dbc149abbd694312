//! The Brown–Conrady lens model in OpenCV's convention and its inversion,
//! on the CPU: what `post.distortion` samples where.
//!
//! A camera ray with normalised coordinates (x, y) = (X/Z, Y/Z) is imaged at
//! x_d = x·(1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²),
//! y_d = y·(1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y, r² = x² + y²,
//! pixel (u, v) = (fx x_d + cx, fy y_d + cy), pixel (i, j)'s centre at
//! (u, v) = (i, j) (OpenCV's convention, so calibrations apply unchanged;
//! a centred principal point is ((W − 1)/2, (H − 1)/2)).

use crate::error::{Error, Result};
use crate::view::MAX_IMAGE_SIDE;

/// Largest accepted |k1|, |k2|, |k3|.
pub const MAX_RADIAL: f64 = 10.0;
/// Largest accepted |p1|, |p2|.
pub const MAX_TANGENTIAL: f64 = 1.0;

/// Pinhole intrinsics in pixels (OpenCV's convention, see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Intrinsics {
    /// Focal lengths `fx`, `fy` and the principal point at the centre of a
    /// `width`×`height` image.
    pub fn centred(fx: f64, fy: f64, width: u32, height: u32) -> Intrinsics {
        Intrinsics {
            fx,
            fy,
            cx: (f64::from(width) - 1.0) / 2.0,
            cy: (f64::from(height) - 1.0) / 2.0,
        }
    }

    fn check(&self, parameter: &str) -> Result<()> {
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
}

/// Brown–Conrady distortion coefficients (OpenCV's k1, k2, p1, p2, k3).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrownConrady {
    pub k1: f64,
    pub k2: f64,
    pub k3: f64,
    pub p1: f64,
    pub p2: f64,
}

impl BrownConrady {
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

    /// Coefficients finite and within [`MAX_RADIAL`] and [`MAX_TANGENTIAL`].
    pub fn check(&self) -> Result<()> {
        for (name, v, max) in [
            ("k1", self.k1, MAX_RADIAL),
            ("k2", self.k2, MAX_RADIAL),
            ("k3", self.k3, MAX_RADIAL),
            ("p1", self.p1, MAX_TANGENTIAL),
            ("p2", self.p2, MAX_TANGENTIAL),
        ] {
            if !v.is_finite() || v.abs() > max {
                return Err(Error::invalid(
                    format!("lens.{name}"),
                    format!("{v}; must be within ±{max}"),
                ));
            }
        }
        Ok(())
    }

    /// The coefficient whose term is largest at radius² `r2` (named in errors).
    fn dominant(&self, r2: f64) -> &'static str {
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
    fn radial_fold(&self, r_max: f64) -> Option<f64> {
        const STEPS: u32 = 4096;
        (0..=STEPS).map(|i| r_max * f64::from(i) / f64::from(STEPS)).find(|&r| {
            let r2 = r * r;
            1.0 + r2 * (3.0 * self.k1 + r2 * (5.0 * self.k2 + r2 * 7.0 * self.k3)) <= 0.0
        })
    }
}

/// The real camera: its intrinsics, lens and image size (the output).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistortedCamera {
    pub intrinsics: Intrinsics,
    pub lens: BrownConrady,
    pub width: u32,
    pub height: u32,
}

impl DistortedCamera {
    fn check(&self) -> Result<()> {
        check_side("distortion width", self.width)?;
        check_side("distortion height", self.height)?;
        self.intrinsics.check("distortion intrinsics")?;
        self.lens.check()
    }

    /// The normalised undistorted ray of every output pixel (rows top to
    /// bottom), or an error naming the coefficient when the distortion does
    /// not invert or the lens folds (not monotonic over the image).
    pub fn rays(&self) -> Result<Vec<[f64; 2]>> {
        self.check()?;
        let (w, h, k) = (self.width as usize, self.height as usize, &self.intrinsics);
        let mut rays = Vec::with_capacity(w * h);
        let mut r2_max = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                let d = [(i as f64 - k.cx) / k.fx, (j as f64 - k.cy) / k.fy];
                let r2d = d[0] * d[0] + d[1] * d[1];
                let ray = self.lens.undistort(d).ok_or_else(|| {
                    Error::invalid(
                        self.lens.dominant(r2d),
                        format!("the distortion does not invert at output pixel ({i}, {j}): the lens folds or is too strong there"),
                    )
                })?;
                let r2 = ray[0] * ray[0] + ray[1] * ray[1];
                r2_max = r2_max.max(r2);
                let jac = self.lens.jacobian(ray);
                let folds_here = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0] <= 0.0;
                let left = (i > 0).then(|| rays[rays.len() - 1]);
                let above = (j > 0).then(|| rays[rays.len() - w]);
                let not_monotonic =
                    left.is_some_and(|l: [f64; 2]| l[0] >= ray[0]) || above.is_some_and(|a: [f64; 2]| a[1] >= ray[1]);
                if folds_here || not_monotonic {
                    return Err(fold_error(self.lens.dominant(r2), (i, j)));
                }
                rays.push(ray);
            }
        }
        if let Some(r) = self.lens.radial_fold(r2_max.sqrt()) {
            return Err(fold_error(self.lens.dominant(r * r), radius_text(r)));
        }
        Ok(rays)
    }
}

fn radius_text(r: f64) -> String {
    format!("radius {r:.4}")
}

fn fold_error(coefficient: &str, at: impl std::fmt::Debug) -> Error {
    Error::invalid(
        coefficient,
        format!("the lens folds at {at:?} (its mapping is not monotonic over the image)"),
    )
}

fn check_side(parameter: &str, v: u32) -> Result<()> {
    if v == 0 || v > MAX_IMAGE_SIDE {
        return Err(Error::invalid(
            parameter,
            format!("{v}; must be in 1..={MAX_IMAGE_SIDE}"),
        ));
    }
    Ok(())
}

/// The undistorted pinhole render `post.distortion` samples: intrinsics
/// (OpenCV's convention) and size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceView {
    pub intrinsics: Intrinsics,
    pub width: u32,
    pub height: u32,
}

impl SourceView {
    /// The vertical field of view of the render in degrees (for the
    /// project's cameras: square pixels and a centred principal point, as
    /// [`source_intrinsics`] gives when the output has square pixels).
    pub fn fov_y_deg(&self) -> f64 {
        (2.0 * (f64::from(self.height) / (2.0 * self.intrinsics.fy)).atan()).to_degrees()
    }
}

/// The undistorted render the output of `camera` needs: every ray of an
/// output pixel centre inside it (nearest and bilinear samples need nothing
/// beyond the texel centres), at no less than the output's pixel density
/// anywhere (the mapping output → source pixels stretches every direction by
/// at least 1: fx' = s·fx, fy' = s·fy with s the largest singular value of
/// F·J_D·F⁻¹ over the image, F = diag(fx, fy)), principal point centred.
/// Zero coefficients and a centred principal point give the output's own
/// intrinsics and size (the pass is then the identity).
pub fn source_intrinsics(camera: &DistortedCamera) -> Result<SourceView> {
    let rays = camera.rays()?;
    let k = camera.intrinsics;
    let (a, c) = (k.fx / k.fy, k.fy / k.fx);
    let mut scale = 0.0f64;
    let mut extent = [0.0f64; 2];
    for &ray in &rays {
        let j = camera.lens.jacobian(ray);
        // F·J·F⁻¹ and its largest singular value.
        let m = [[j[0][0], j[0][1] * a], [j[1][0] * c, j[1][1]]];
        let p = m[0][0] * m[0][0] + m[1][0] * m[1][0];
        let q = m[0][1] * m[0][1] + m[1][1] * m[1][1];
        let r = m[0][0] * m[0][1] + m[1][0] * m[1][1];
        let largest = (p + q) / 2.0 + (((p - q) / 2.0).powi(2) + r * r).sqrt();
        scale = scale.max(largest.sqrt());
        extent = [extent[0].max(ray[0].abs()), extent[1].max(ray[1].abs())];
    }
    let (fx, fy) = (scale * k.fx, scale * k.fy);
    let side = |half: f64| (2.0 * half + 1.0 - 1e-9).ceil();
    let (w, h) = (side(fx * extent[0]), side(fy * extent[1]));
    if w > f64::from(MAX_IMAGE_SIDE) || h > f64::from(MAX_IMAGE_SIDE) {
        return Err(Error::invalid(
            "lens",
            format!("its undistorted render would be {w}×{h}, more than {MAX_IMAGE_SIDE} a side"),
        ));
    }
    let (width, height) = (w as u32, h as u32);
    Ok(SourceView {
        intrinsics: Intrinsics::centred(fx, fy, width, height),
        width,
        height,
    })
}

/// Where `post.distortion` samples the source for each output pixel (source
/// texel coordinates, texel k's centre at k; rows top to bottom).
#[derive(Clone, Debug, PartialEq)]
pub struct SourceMap {
    pub width: u32,
    pub height: u32,
    pub positions: Vec<[f32; 2]>,
}

/// The source map of `camera` rendered from `source`; an error naming the
/// source view when it does not contain every ray the output needs.
pub fn source_map(camera: &DistortedCamera, source: &SourceView) -> Result<SourceMap> {
    source.intrinsics.check("distortion source")?;
    check_side("distortion source width", source.width)?;
    check_side("distortion source height", source.height)?;
    let k = source.intrinsics;
    let (max_u, max_v) = (f64::from(source.width) - 0.5, f64::from(source.height) - 0.5);
    let rays = camera.rays()?;
    let mut positions = Vec::with_capacity(rays.len());
    for (n, ray) in rays.iter().enumerate() {
        let (u, v) = (k.fx * ray[0] + k.cx, k.fy * ray[1] + k.cy);
        if !(-0.5..=max_u).contains(&u) || !(-0.5..=max_v).contains(&v) {
            let (i, j) = (n % camera.width as usize, n / camera.width as usize);
            return Err(Error::invalid(
                "distortion source",
                format!(
                    "the {}×{} render does not contain the ray of output pixel ({i}, {j}) (at {u:.1}, {v:.1}); use source_intrinsics",
                    source.width, source.height
                ),
            ));
        }
        positions.push([u as f32, v as f32]);
    }
    Ok(SourceMap {
        width: camera.width,
        height: camera.height,
        positions,
    })
}
