//! Swimming of the warped terrain mesh, measured (dissertation §7.4.3,
//! §7.4.5: "the vertices of the warped grid slide over the surface as the
//! camera moves").
//!
//! # The metric
//!
//! A camera moves slowly along a path of `K` frames ([`camera_path`]); frame
//! `k` plans its own mesh `M_k` (the LOD of [`crate::terrain::lod`], warped
//! or uniform). Swimming is the change of the image that is due to the mesh
//! alone, not to the camera: each consecutive pair is drawn **with the same
//! camera** `C_{k+1}`, once with `M_k` and once with `M_{k+1}`, and per pixel
//!
//! ```text
//! depth swimming  s_d(p) = |D(M_{k+1}, C_{k+1}; p) − D(M_k, C_{k+1}; p)| / R(C_{k+1}; p)
//! colour swimming s_c(p) = |L(M_{k+1}, C_{k+1}; p) − L(M_k, C_{k+1}; p)|
//! ```
//!
//! `D` is the drawn view depth (along the camera's forward axis), `R` the
//! view depth of the true surface by CPU ray casting
//! ([`crate::terrain::raycast`]), `L` the shaded luminance in `[0, 1]`
//! (Lambert, [`SUN`], ambient [`AMBIENT`], vertex normals interpolated as
//! `terrain.draw` does). A pixel counts when the ray cast hits the terrain
//! (static ground; the scene has nothing else) and both meshes cover it;
//! [`Swimming`] holds the means over all counted pixels of all `K − 1`
//! pairs; [`Swimming::worst_depth`] and [`Swimming::worst_colour`] the
//! largest mean of a single pair (the pop of a world-anchored plan's
//! replan, [`crate::terrain::lod`]). A world-static mesh swims 0 exactly, whatever the camera does; so
//! does the ray-cast reference itself (its surface never changes). The
//! accuracy [`Swimming::error`], the mean `|D(M_k, C_k) − R(C_k)| / R(C_k)`
//! over all `K` frames, is reported alongside: a remedy must not buy
//! stillness with a mesh that lags behind the view.
//!
//! # Why on the CPU
//!
//! The drawn surface is computed, not rendered: `terrain.warp` is a twin of
//! [`crate::terrain::zoom::zoom_positions`] (the same bilinear `Φ`, the same
//! cubic B-spline; `src/terrain/tests/terrain.rs` checks the GPU's depth
//! against the ray cast, `src/terrain/tests/ground.rs` the CPU mesh against
//! the GPU's depth to 1 cm), and [`rasterize`] draws it with the grid's
//! triangles. That makes the metric exact (no driver, no rounding to a depth
//! format), deterministic, fast enough for a test in a debug build, and lets
//! one camera draw two frames' meshes, which the renderer cannot (its LOD
//! always follows the frame's own camera). The procedural detail is off
//! (`--no-terrain-detail`): the reference is the B-spline the ray cast
//! knows; the detail octaves fade with the split octave and so follow the
//! same vertices.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::surface::bspline::sample_bspline_gradient;
use crate::terrain::raycast::Raycaster;
use crate::terrain::zoom::zoom_positions;
use crate::view::{Camera, View};

/// Direction to the sun of the metric's shading (unit; 54° elevation).
pub const SUN: DVec3 = DVec3::new(-0.541_675, -0.225_698, 0.809_758);
/// Ambient term of the metric's shading.
pub const AMBIENT: f64 = 0.2;

/// `frames` cameras from `start`, each moved by `step` (metres, along the
/// horizontal forward axis and to the right) from the one before; the view
/// direction stays the same.
pub fn camera_path(start: Camera, step: DVec2, frames: usize) -> Vec<Camera> {
    let forward = start.forward().truncate().try_normalize().unwrap_or(DVec2::Y);
    let right = DVec2::new(forward.y, -forward.x);
    (0..frames)
        .map(|k| {
            let d = (k as f64 * (step.x * forward + step.y * right)).extend(0.0);
            Camera {
                eye: start.eye + d,
                target: start.target + d,
                ..start
            }
        })
        .collect()
}

/// A drawn terrain mesh on the CPU: a `side×side` grid of world vertices
/// with unit normals, triangulated as
/// [`crate::terrain::geometry_image::grid_indices`].
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub side: usize,
    pub positions: Vec<DVec3>,
    pub normals: Vec<DVec3>,
}

impl Mesh {
    /// The mesh `terrain.warp` makes of `warped` (an `n×n` warped sketch
    /// map, [`crate::terrain::lod::LodFrame`]'s `warp.positions`) at
    /// `side×side` vertices without detail: heights and normals of the
    /// B-spline at the zoomed positions.
    pub fn from_warp(field: &HeightField, warped: &[DVec3], n: usize, side: usize) -> Result<Mesh> {
        let positions = zoom_positions(field, warped, n, side)?;
        Ok(Mesh::new(field, side, positions))
    }

    /// The mesh of world `positions` (`side×side`, heights given), normals
    /// from the B-spline of `field`.
    pub fn new(field: &HeightField, side: usize, positions: Vec<DVec3>) -> Mesh {
        let normals = positions
            .iter()
            .map(|p| {
                let g = sample_bspline_gradient(field, p.x, p.y);
                DVec3::new(-g.x, -g.y, 1.0).normalize()
            })
            .collect();
        Mesh {
            side,
            positions,
            normals,
        }
    }
}

/// A CPU-drawn image: per pixel (row-major, row 0 at the top) the view
/// depth (`+∞` where nothing is drawn) and the shaded luminance.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    pub width: u32,
    pub height: u32,
    pub depth: Vec<f64>,
    pub luminance: Vec<f64>,
}

/// Luminance of a unit normal under [`SUN`] with [`AMBIENT`].
pub fn shade(normal: DVec3) -> f64 {
    AMBIENT + (1.0 - AMBIENT) * normal.dot(SUN).max(0.0)
}

/// Draws `mesh` as `view` sees it: every triangle wholly in front of the
/// near plane, depth-tested, sampled at pixel centres (a pixel on a shared
/// edge may take either triangle), depth and normal interpolated
/// perspective-correctly (the normal then renormalised and shaded).
/// Triangles that cross the near plane are left out (the GPU clips them;
/// their pixels then count for no metric).
pub fn rasterize(mesh: &Mesh, view: &View) -> Raster {
    let (w, h) = (view.width as usize, view.height as usize);
    let mut out = Raster {
        width: view.width,
        height: view.height,
        depth: vec![f64::INFINITY; w * h],
        luminance: vec![0.0; w * h],
    };
    let (eye, forward) = (view.camera.eye, view.camera.forward());
    let view_proj = view.view_proj_f64();
    // Per vertex: pixel position, 1/depth; None behind the near plane.
    let screen: Vec<Option<(DVec2, f64)>> = (mesh.positions.iter())
        .map(|&p| {
            let depth = (p - eye).dot(forward);
            if depth <= view.camera.near {
                return None;
            }
            let clip = view_proj * p.extend(1.0);
            let ndc = clip.truncate().truncate() / clip.w;
            let px = DVec2::new((ndc.x * 0.5 + 0.5) * w as f64, (ndc.y * 0.5 + 0.5) * h as f64);
            Some((px, 1.0 / depth))
        })
        .collect();
    let side = mesh.side;
    let mut normal_at = vec![DVec3::ZERO; w * h];
    for j in 0..side.saturating_sub(1) {
        for i in 0..side - 1 {
            let k = j * side + i;
            for t in [[k, k + 1, k + side], [k + 1, k + side + 1, k + side]] {
                triangle(&screen, t, (w, h), |pixel, b| {
                    let inv = b[0] + b[1] + b[2];
                    let depth = 1.0 / inv;
                    if depth < out.depth[pixel] {
                        out.depth[pixel] = depth;
                        let n = t.iter().zip(b).map(|(&v, bv)| mesh.normals[v] * bv).sum::<DVec3>();
                        normal_at[pixel] = n;
                    }
                });
            }
        }
    }
    for (l, n) in out.luminance.iter_mut().zip(&normal_at) {
        *l = n.try_normalize().map_or(0.0, shade);
    }
    out
}

/// Calls `pixel(index, weights)` for every pixel centre inside triangle `t`
/// of `screen`: `weights` are the screen-space barycentrics times the
/// vertices' `1/depth` (their sum is `1/depth` at the pixel).
fn triangle(
    screen: &[Option<(DVec2, f64)>],
    t: [usize; 3],
    (w, h): (usize, usize),
    mut pixel: impl FnMut(usize, [f64; 3]),
) {
    let (Some(a), Some(b), Some(c)) = (screen[t[0]], screen[t[1]], screen[t[2]]) else {
        return;
    };
    let area = (b.0 - a.0).perp_dot(c.0 - a.0);
    if area.abs() < 1e-12 {
        return;
    }
    let lo = a.0.min(b.0).min(c.0);
    let hi = a.0.max(b.0).max(c.0);
    let x0 = (lo.x - 0.5).ceil().max(0.0);
    let y0 = (lo.y - 0.5).ceil().max(0.0);
    let x1 = (hi.x - 0.5).floor().min(w as f64 - 1.0);
    let y1 = (hi.y - 0.5).floor().min(h as f64 - 1.0);
    if x0 > x1 || y0 > y1 {
        return;
    }
    for y in y0 as usize..=y1 as usize {
        for x in x0 as usize..=x1 as usize {
            let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let l0 = (c.0 - b.0).perp_dot(p - b.0) / area;
            let l1 = (a.0 - c.0).perp_dot(p - c.0) / area;
            let l2 = 1.0 - l0 - l1;
            if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                continue;
            }
            pixel(y * w + x, [l0 * a.1, l1 * b.1, l2 * c.1]);
        }
    }
}

/// View depth of the true surface per pixel centre of `view` (`+∞` where
/// the ray misses the terrain).
pub fn reference_depth(caster: &Raycaster<'_>, view: &View) -> Vec<f64> {
    let (right, up, forward) = view.ray_basis();
    let (right, up, forward) = (right.as_dvec3(), up.as_dvec3(), forward.as_dvec3());
    let (w, h) = (view.width as usize, view.height as usize);
    // The ray's parameter is its view depth when its forward part is the
    // unit forward axis (no principal point offset).
    let axis = view.camera.forward();
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let ndc = DVec2::new(
                2.0 * (x as f64 + 0.5) / w as f64 - 1.0,
                2.0 * (y as f64 + 0.5) / h as f64 - 1.0,
            );
            let dir = forward + ndc.x * right - ndc.y * up;
            let t = caster.raycast(view.camera.eye, dir, view.camera.far);
            out.push(t.map_or(f64::INFINITY, |t| t * dir.dot(axis)));
        }
    }
    out
}

/// The swimming of one path (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Swimming {
    /// Mean relative depth change between consecutive meshes seen by one camera.
    pub depth: f64,
    /// Mean absolute luminance change (luminance in `[0, 1]`).
    pub colour: f64,
    /// Mean relative depth error of each frame's mesh against the ray cast.
    pub error: f64,
    /// Pixels counted for `depth` and `colour`, over all pairs.
    pub pixels: usize,
    /// The largest mean relative depth change of a single pair (the pop
    /// of a replan where the others do not change).
    pub worst_depth: f64,
    /// The largest mean luminance change of a single pair.
    pub worst_colour: f64,
}

/// Measures the swimming along `cameras` (at least two) at `width×height`:
/// `mesh(k, camera)` plans frame `k`'s mesh (in order, once per frame).
pub fn measure(
    field: &HeightField,
    cameras: &[Camera],
    (width, height): (u32, u32),
    mut mesh: impl FnMut(usize, &Camera) -> Result<Mesh>,
) -> Result<Swimming> {
    if cameras.len() < 2 || width == 0 || height == 0 {
        return Err(Error::invalid(
            "swimming path",
            format!(
                "{} cameras at {width}×{height} (need at least two and a non-empty image)",
                cameras.len()
            ),
        ));
    }
    let caster = Raycaster::new(field)?;
    let mut sums = Swimming::default();
    let (mut error_sum, mut error_pixels) = (0.0, 0usize);
    let mut previous: Option<Mesh> = None;
    for (k, camera) in cameras.iter().enumerate() {
        let current = mesh(k, camera)?;
        let view = View::new(*camera, width, height);
        let reference = reference_depth(&caster, &view);
        let now = rasterize(&current, &view);
        for (&d, &r) in now.depth.iter().zip(&reference) {
            if d.is_finite() && r.is_finite() {
                error_sum += (d - r).abs() / r;
                error_pixels += 1;
            }
        }
        // An unchanged mesh draws the same image: no need to draw it twice.
        let before = match &previous {
            Some(m) if *m == current => Some(now.clone()),
            Some(m) => Some(rasterize(m, &view)),
            None => None,
        };
        if let Some(before) = before {
            let (mut depth, mut colour, mut pixels) = (0.0, 0.0, 0usize);
            for (p, &r) in reference.iter().enumerate() {
                let (a, b) = (before.depth[p], now.depth[p]);
                if a.is_finite() && b.is_finite() && r.is_finite() {
                    depth += (b - a).abs() / r;
                    colour += (now.luminance[p] - before.luminance[p]).abs();
                    pixels += 1;
                }
            }
            let n = pixels.max(1) as f64;
            sums.worst_depth = sums.worst_depth.max(depth / n);
            sums.worst_colour = sums.worst_colour.max(colour / n);
            sums.depth += depth;
            sums.colour += colour;
            sums.pixels += pixels;
        }
        previous = Some(current);
    }
    let pixels = sums.pixels.max(1) as f64;
    Ok(Swimming {
        depth: sums.depth / pixels,
        colour: sums.colour / pixels,
        error: error_sum / error_pixels.max(1) as f64,
        ..sums
    })
}
