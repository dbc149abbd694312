//! What `post.distortion` samples where, on the CPU: the real camera's
//! rays through the lens model of [`crate::view::lens`] (Brown–Conrady in
//! OpenCV's convention, [`Distortion`], inverted by Newton iterations), the
//! undistorted render that covers them and the source map.

use crate::error::{Error, Result};
use crate::view::lens::{Distortion, Intrinsics};
use crate::view::MAX_IMAGE_SIDE;

/// The real camera: its intrinsics, lens and image size (the output).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistortedCamera {
    pub intrinsics: Intrinsics,
    pub lens: Distortion,
    pub width: u32,
    pub height: u32,
}

impl DistortedCamera {
    fn check(&self) -> Result<()> {
        check_side("distortion width", self.width)?;
        check_side("distortion height", self.height)?;
        self.intrinsics.check_finite("distortion intrinsics")?;
        self.lens.check_as("lens")
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
    source.intrinsics.check_finite("distortion source")?;
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
