//! Importance map for geometry image warping (dissertation §7.4.2,
//! "Importance Map", eq. 7.4; `ALGORITHMS.md` §3 item 3).
//!
//! The importance `I(x, y)` of a sketch-map texel is the desired density of
//! grid points around it: a mesh cell there should be about `1/I` wide in x
//! and in y (isotropic). It combines four factors (eq. 7.4):
//!
//! ```text
//! I = max( min(I_v · S_f · S_b, I_s), floor · max I )
//! I_v = C / max(dist(eye, p), min_distance)     view distance
//! S_f = 1 inside the frustum, smoothly → 0 across a safety band outside
//! S_b = 1 for front-facing and silhouette texels, smoothly lower on back faces
//! I_s = per-texel upper bound from the surface type (smooth dunes need little)
//! ```
//!
//! Every factor can be switched off ([`ImportanceParams`]: `distance =
//! false`, or `None`). The final relative floor keeps the map strictly
//! positive, so the warp ([`crate::terrain::warp`]) never has to shrink a run
//! of texels to nothing; the back-face factor has its own floor
//! ([`Backface::floor`]). Occlusion culling, which the text mentions as a
//! further possible factor, is not implemented.

use glam::DVec3;

use crate::error::{Error, Result};

/// `smoothstep(e0, e1, x)`: 0 below `e0`, 1 above `e1`, the cubic
/// `t²(3 − 2t)` between. With `e0 == e1` a hard step at `e0`.
pub fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    if e1 <= e0 {
        return if x < e0 { 0.0 } else { 1.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// An oriented plane: the signed distance of `p` is `normal·p + offset`,
/// positive on the inner side. `normal` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal pointing to the inner side.
    pub normal: DVec3,
    /// Offset: `−normal·q` for any point `q` on the plane.
    pub offset: f64,
}

impl Plane {
    /// The plane through `point` with (not necessarily unit) inner
    /// `normal`; `None` for a zero or non-finite normal or point.
    pub fn through(point: DVec3, normal: DVec3) -> Option<Plane> {
        let normal = normal.try_normalize()?;
        let offset = -normal.dot(point);
        offset.is_finite().then_some(Plane { normal, offset })
    }

    /// Signed distance of `p`: positive inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) + self.offset
    }
}

/// The view frustum with a safety band: the factor `S_f` of eq. 7.4.
#[derive(Clone, Debug, PartialEq)]
pub struct Frustum {
    /// Bounding planes, normals pointing inwards.
    pub planes: Vec<Plane>,
    /// Width in world units (metres) of the safety band outside the planes
    /// over which `S_f` falls smoothly from 1 to 0 (0: hard cut).
    pub band: f64,
}

impl Frustum {
    /// The frustum of a pinhole camera at `eye` looking along `forward`
    /// with `up` roughly up, vertical field of view `vfov` (radians, in
    /// (0, π)) and `aspect` = width / height: four side planes through the
    /// eye plus a near plane through the eye (points behind the camera are
    /// outside). No far plane: the sketch map bounds the distance.
    pub fn perspective(eye: DVec3, forward: DVec3, up: DVec3, vfov: f64, aspect: f64, band: f64) -> Result<Frustum> {
        let bad = |m: &str| Err(Error::invalid("view frustum", m));
        if !(vfov > 0.0 && vfov < std::f64::consts::PI && aspect.is_finite() && aspect > 0.0) {
            return bad("field of view must lie in (0, π) and aspect be finite and positive");
        }
        if !(band.is_finite() && band >= 0.0 && eye.is_finite()) {
            return bad("safety band must be finite and ≥ 0, the eye finite");
        }
        let Some(f) = forward.try_normalize() else {
            return bad("forward direction is zero or not finite");
        };
        let Some(r) = f.cross(up).try_normalize() else {
            return bad("up is parallel to forward (or zero)");
        };
        let u = r.cross(f);
        let tv = (0.5 * vfov).tan();
        let th = tv * aspect;
        let normals = [f, th * f - r, th * f + r, tv * f - u, tv * f + u];
        let planes = normals
            .iter()
            .filter_map(|&n| Plane::through(eye, n))
            .collect::<Vec<_>>();
        if planes.len() != normals.len() {
            return bad("degenerate frustum plane");
        }
        Ok(Frustum { planes, band })
    }

    /// The frustum with every plane moved `slack` metres outwards: it
    /// contains the frustum of every translate of the camera by at most
    /// `slack` (a plane through the moved eye with the same normal is at
    /// most that far from the original).
    pub fn widened(mut self, slack: f64) -> Frustum {
        for plane in &mut self.planes {
            plane.offset += slack;
        }
        self
    }

    /// `S_f(p)`: 1 inside all planes; outside, `1 − smoothstep(0, band, d)`
    /// for the largest outside distance `d` (so 0 beyond the band).
    pub fn factor(&self, p: DVec3) -> f64 {
        let outside = self
            .planes
            .iter()
            .map(|pl| -pl.signed_distance(p))
            .fold(0.0_f64, f64::max);
        1.0 - smoothstep(0.0, self.band, outside)
    }

    /// Whether `p` is inside every plane (`S_f = 1` without the band).
    pub fn contains(&self, p: DVec3) -> bool {
        self.planes.iter().all(|pl| pl.signed_distance(p) >= 0.0)
    }
}

/// The back-face factor `S_b` of eq. 7.4 as a function of `cos θ = n·v`
/// (unit normal `n`, unit direction `v` to the eye).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Backface {
    /// Over how much `−cos θ` the factor falls from 1 (silhouette,
    /// `cos θ = 0`) to `floor`; in (0, 1].
    pub falloff: f64,
    /// Value for clearly back-facing texels, in (0, 1]. Kept positive:
    /// back faces are not drawn but still join visible front faces, and a
    /// zero would let the warp collapse whole slopes.
    pub floor: f64,
}

impl Default for Backface {
    /// Falloff 0.3 (back faces steeper than ≈17° away from the silhouette
    /// get the floor), floor 0.1.
    fn default() -> Self {
        Self {
            falloff: 0.3,
            floor: 0.1,
        }
    }
}

impl Backface {
    /// `S_b`: 1 for `cos θ ≥ 0` (front-facing and silhouette), then
    /// smoothly down to `floor` at `cos θ = −falloff`.
    pub fn factor(&self, cos_theta: f64) -> f64 {
        if cos_theta >= 0.0 {
            return 1.0;
        }
        let s = smoothstep(0.0, self.falloff, -cos_theta);
        self.floor + (1.0 - self.floor) * (1.0 - s)
    }
}

/// Parameters of [`importance_map`]. `None` (or `distance = false`)
/// switches a factor off.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportanceParams {
    /// `C` in `I_v = C / dist`: desired grid points per unit length at
    /// distance 1 (finite, > 0). Only ratios matter to the warp; `C`
    /// matters against the surface bound `I_s`.
    pub c: f64,
    /// Use the view-distance factor `I_v`; `false`: `I_v = C` everywhere.
    pub distance: bool,
    /// Distances below this (world units, ≥ 0) count as this, so a texel
    /// under the eye gets a finite importance.
    pub min_distance: f64,
    /// Frustum factor `S_f`.
    pub frustum: Option<Frustum>,
    /// Back-face factor `S_b`.
    pub backface: Option<Backface>,
    /// Per-texel upper bound `I_s` (n·n values, row-major).
    pub surface_bound: Option<Vec<f64>>,
    /// Relative floor in (0, 1]: the result is at least `floor · max I`
    /// (and 1 everywhere if every texel is 0 or invalid).
    pub floor: f64,
}

impl Default for ImportanceParams {
    /// `C = 1`, distance factor on with `min_distance = 1`, no frustum, no
    /// back-face factor, no surface bound, floor `1e-3`.
    fn default() -> Self {
        Self {
            c: 1.0,
            distance: true,
            min_distance: 1.0,
            frustum: None,
            backface: None,
            surface_bound: None,
            floor: 1e-3,
        }
    }
}

/// Checks that `geometry` holds `n·n ≥ 4` texels.
pub(crate) fn check_grid(what: &str, len: usize, n: usize) -> Result<()> {
    if n < 2 || n.checked_mul(n) != Some(len) {
        return Err(Error::invalid(
            what,
            format!("{len} texels for a {n}×{n} grid (need n ≥ 2 and n·n texels)"),
        ));
    }
    Ok(())
}

/// Unit surface normals of an `n×n` geometry image (texels `(x, y, h)`,
/// row-major): `P_s × P_t` from central differences (one-sided at the
/// border), oriented to `+z`; `(0, 0, 1)` where degenerate.
pub fn grid_normals(geometry: &[DVec3], n: usize) -> Result<Vec<DVec3>> {
    check_grid("geometry image", geometry.len(), n)?;
    let at = |r: usize, c: usize| geometry[r * n + c];
    let mut out = Vec::with_capacity(n * n);
    for r in 0..n {
        let (r0, r1) = (r.saturating_sub(1), (r + 1).min(n - 1));
        for c in 0..n {
            let (c0, c1) = (c.saturating_sub(1), (c + 1).min(n - 1));
            let ps = at(r, c1) - at(r, c0);
            let pt = at(r1, c) - at(r0, c);
            let nrm = ps.cross(pt).try_normalize().unwrap_or(DVec3::Z);
            out.push(if nrm.z < 0.0 { -nrm } else { nrm });
        }
    }
    Ok(out)
}

/// The importance map of an `n×n` sketch map (eq. 7.4; §7.4.2;
/// `ALGORITHMS.md` §3 item 3): one value per texel, row-major, every value
/// finite and > 0.
///
/// `geometry` holds the texels' world positions `(x, y, h)`. Normals for
/// `S_b` come from `grid_normals`. Non-finite intermediate values count
/// as 0 and are then lifted to the floor. Errors on a wrong texel count,
/// a surface bound of the wrong length, non-finite `eye`, or parameters out
/// of range; never panics.
pub fn importance_map(geometry: &[DVec3], n: usize, eye: DVec3, params: &ImportanceParams) -> Result<Vec<f64>> {
    check_grid("geometry image", geometry.len(), n)?;
    let bad = |what: &str, m: String| Err(Error::invalid(format!("importance {what}"), m));
    if !(params.c.is_finite() && params.c > 0.0) {
        return bad("constant C", format!("{} (must be finite and > 0)", params.c));
    }
    if !(params.min_distance.is_finite() && params.min_distance >= 0.0) {
        return bad(
            "min_distance",
            format!("{} (must be finite and ≥ 0)", params.min_distance),
        );
    }
    if !(params.floor > 0.0 && params.floor <= 1.0) {
        return bad("floor", format!("{} (must lie in (0, 1])", params.floor));
    }
    if !eye.is_finite() {
        return bad("eye", format!("{eye} is not finite"));
    }
    if let Some(b) = &params.backface {
        if !(b.falloff > 0.0 && b.falloff <= 1.0 && b.floor > 0.0 && b.floor <= 1.0) {
            return bad(
                "back-face factor",
                format!("falloff {} / floor {} (each must lie in (0, 1])", b.falloff, b.floor),
            );
        }
    }
    if let Some(f) = &params.frustum {
        if !(f.band.is_finite() && f.band >= 0.0) {
            return bad("frustum band", format!("{} (must be finite and ≥ 0)", f.band));
        }
    }
    if let Some(s) = &params.surface_bound {
        if s.len() != geometry.len() {
            return bad(
                "surface bound",
                format!("{} values for {} texels", s.len(), geometry.len()),
            );
        }
    }
    let normals = match params.backface {
        Some(_) => grid_normals(geometry, n)?,
        None => Vec::new(),
    };
    let mut out: Vec<f64> = geometry
        .iter()
        .enumerate()
        .map(|(k, &p)| {
            let to_eye = eye - p;
            let dist = to_eye.length();
            let mut i = if params.distance {
                params.c / dist.max(params.min_distance)
            } else {
                params.c
            };
            if let Some(f) = &params.frustum {
                i *= f.factor(p);
            }
            if let Some(b) = &params.backface {
                let cos = to_eye.try_normalize().map_or(1.0, |v| normals[k].dot(v));
                i *= b.factor(cos);
            }
            if let Some(s) = &params.surface_bound {
                // `f64::min` would ignore a NaN bound; treat it as 0 instead.
                i = if s[k] >= i { i } else { s[k] };
            }
            if i.is_finite() && i > 0.0 {
                i
            } else {
                0.0
            }
        })
        .collect();
    let max = out.iter().copied().fold(0.0_f64, f64::max);
    let floor = if max > 0.0 { params.floor * max } else { 1.0 };
    for v in &mut out {
        *v = v.max(floor);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(n: usize, spacing: f64) -> Vec<DVec3> {
        (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * spacing, (k / n) as f64 * spacing, 0.0))
            .collect()
    }

    #[test]
    fn smoothstep_ends_and_hard_step() {
        assert_eq!(smoothstep(0.0, 2.0, -1.0), 0.0);
        assert_eq!(smoothstep(0.0, 2.0, 1.0), 0.5);
        assert_eq!(smoothstep(0.0, 2.0, 3.0), 1.0);
        assert_eq!(smoothstep(1.0, 1.0, 0.5), 0.0);
        assert_eq!(smoothstep(1.0, 1.0, 1.0), 1.0);
    }

    #[test]
    fn frustum_inside_band_outside() {
        let f = Frustum::perspective(DVec3::ZERO, DVec3::Y, DVec3::Z, 1.0, 1.0, 10.0).unwrap();
        assert!(f.contains(DVec3::new(0.0, 100.0, 0.0)));
        assert_eq!(f.factor(DVec3::new(0.0, 100.0, 0.0)), 1.0);
        // Behind the eye, 5 m: half-way through the band.
        assert!((f.factor(DVec3::new(0.0, -5.0, 0.0)) - 0.5).abs() < 1e-12);
        assert_eq!(f.factor(DVec3::new(0.0, -50.0, 0.0)), 0.0);
        // Far to the right of the side plane.
        assert_eq!(f.factor(DVec3::new(1000.0, 100.0, 0.0)), 0.0);
        assert!(Frustum::perspective(DVec3::ZERO, DVec3::Z, DVec3::Z, 1.0, 1.0, 1.0).is_err());
        assert!(Frustum::perspective(DVec3::ZERO, DVec3::Y, DVec3::Z, 4.0, 1.0, 1.0).is_err());
    }

    #[test]
    fn backface_is_one_in_front_and_floored_behind() {
        let b = Backface::default();
        assert_eq!(b.factor(0.7), 1.0);
        assert_eq!(b.factor(0.0), 1.0);
        assert!(b.factor(-0.15) < 1.0 && b.factor(-0.15) > b.floor);
        assert_eq!(b.factor(-0.9), b.floor);
    }

    #[test]
    fn distance_importance_falls_with_distance() {
        let g = flat(8, 10.0);
        let i = importance_map(&g, 8, DVec3::new(0.0, 0.0, 10.0), &ImportanceParams::default()).unwrap();
        assert!((i[0] - 0.1).abs() < 1e-12);
        assert!(i[1] > i[2] && i[8] > i[16] && i[63] < i[9]);
    }

    #[test]
    fn switches_bound_and_floor() {
        let g = flat(4, 1.0);
        let eye = DVec3::new(0.0, 0.0, 1.0);
        let off = ImportanceParams {
            distance: false,
            c: 3.0,
            ..Default::default()
        };
        assert!(importance_map(&g, 4, eye, &off).unwrap().iter().all(|&v| v == 3.0));
        let mut bound = vec![10.0; 16];
        bound[5] = 0.5;
        bound[6] = 0.0;
        let p = ImportanceParams {
            surface_bound: Some(bound),
            ..off.clone()
        };
        let i = importance_map(&g, 4, eye, &p).unwrap();
        assert_eq!(i[5], 0.5);
        assert_eq!(i[6], 3.0 * 1e-3, "a zero bound is lifted to the floor");
        assert!(importance_map(&g, 5, eye, &p).is_err());
        assert!(importance_map(&g, 4, DVec3::NAN, &off).is_err());
        let short = ImportanceParams {
            surface_bound: Some(vec![1.0; 3]),
            ..off
        };
        assert!(importance_map(&g, 4, eye, &short).is_err());
    }

    #[test]
    fn back_slope_gets_less_importance() {
        // A roof: rising to x = 4, falling after; eye far on the −x side.
        let n = 9;
        let g: Vec<DVec3> = (0..n * n)
            .map(|k| {
                let (c, r) = ((k % n) as f64, (k / n) as f64);
                DVec3::new(c, r, 4.0 - (c - 4.0).abs())
            })
            .collect();
        let p = ImportanceParams {
            distance: false,
            backface: Some(Backface::default()),
            ..Default::default()
        };
        let i = importance_map(&g, n, DVec3::new(-100.0, 4.0, 2.0), &p).unwrap();
        assert_eq!(i[4 * n + 1], 1.0, "front slope");
        assert!((i[4 * n + 7] - 0.1).abs() < 1e-12, "back slope gets the floor");
    }
}
