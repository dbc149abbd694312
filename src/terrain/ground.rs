//! The ground as drawn, on the CPU: a height query for placing a car or a
//! camera on the surface the GPU draws (issue 14), not on the bare cubic
//! B-spline, which the procedural detail moves by metres (dissertation
//! §7.4.2 "Warp and Zoom", §7.4.3 "Procedural Detail"; `ALGORITHMS.md` §3
//! items 5–6).
//!
//! # What the GPU draws
//!
//! `terrain.warp` (`glsl/terrain/warp.comp`) writes every vertex of the
//! geometry image at `z = B(x, y) + D(x, y; 0, o)`: `B` the cubic B-spline
//! of the sketch atlas ([`crate::surface::bspline`]) and `D` the detail
//! octaves of `glsl/include/terrain_detail.glsl`,
//!
//! ```text
//! D(p; o_lo, o_hi) = Σ_{k=1..8} (w(o_hi, k) − w(o_lo, k)) · A·d0·2^(−k·H) · N(p·2^k/d0 + k·(37.13, 11.71))
//! w(o, k)          = clamp(o − (k − 1), 0, 1)
//! ```
//!
//! with `N` the wavelet noise tile ([`crate::surface::wavelet_noise`]), `d0`
//! the atlas spacing (the finer of `dx`, `dy`), and `A`, `H` and the tile's
//! seed from [`TerrainSettings`]. `o` is the vertex's *split octave*
//! ([`split_octave`]): `log2(d0 / d) − SPLIT_BIAS` clamped to `[0, 8]`, `d`
//! the longest 3D distance to its four grid neighbours. So the geometric
//! detail fades with the grid's spacing, i.e. with the view's LOD; the
//! octaves above `o` go into per-pixel bump mapping (shading only). Between
//! vertices the surface is the triangulated grid.
//!
//! # What the query returns
//!
//! [`Ground::height`] is the **finest level**, `o = 8`: every detail octave,
//! the surface the drawn one converges to as the grid refines. A vertex of
//! split octave `o` lies within [`Ground::omitted_detail_bound`]`(o)` of it
//! (every octave above `o` at the tile's largest value); between vertices
//! the linear interpolation adds its own error. On the Jacksboro DEM
//! (`d0` = 74.4 m) with the default settings (`A` = 0.15, `H` = 0.9, 512²
//! grid) the grid next to a camera 2–30 m above the ground is 1.7–3.5 m
//! wide, so even there `o` is only 4–5 (octaves 5–8, 0.49 … 0.08 m in
//! amplitude, are bump-mapped): 3 m above the ground, the drawn ground
//! within 30 m differs from [`Ground::height`] by 0.15 m rms, 0.43 m at
//! most (`src/terrain/tests/ground.rs`; the vertices' bound there is 1.9 m). A coarse
//! far view (`o` → 0) differs by about 1.5 m rms, at most
//! [`Ground::omitted_detail_bound`]`(0)` (26 m, a loose bound).
//!
//! What *is* drawn, exactly: [`Ground::surface`] at a given `o` is a vertex
//! of that split octave, [`Ground::vertex`] one invocation of
//! `terrain.warp`, and [`DrawnSurface`] the whole triangulated mesh of a
//! view, from the same warp the renderer uploads; `src/terrain/tests/ground.rs` checks
//! that it matches the GPU's depth to within 1 cm.

use glam::{DVec2, DVec3, DVec4};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::surface::bspline::{sample_bspline, sample_bspline_gradient};
use crate::surface::wavelet_noise::NOISE_TILE;
use crate::surface::wavelet_noise::{evaluate_gradient, noise_tile};
use crate::terrain::geometry_image::{TerrainSettings, MAX_DETAIL_OCTAVES, SPLIT_BIAS};
use crate::terrain::zoom::zoom_xy;

/// Per-octave shift of the noise lattice (times the octave number), as in
/// `detail_octaves` of `glsl/include/terrain_detail.glsl`.
pub const OCTAVE_SHIFT: DVec2 = DVec2::new(37.13, 11.71);

/// Weight of octave `k` in the range up to octave `o` (`octave_weight` in
/// `terrain_detail.glsl`): octaves `≤ ⌊o⌋` fully, octave `⌊o⌋ + 1` by the
/// fraction of `o`.
pub fn octave_weight(o: f64, k: u32) -> f64 {
    (o - f64::from(k) + 1.0).clamp(0.0, 1.0)
}

/// Split octave of a vertex whose longest 3D distance to its four grid
/// neighbours is `distance` (metres), with atlas spacing `d0` (§7.4.3;
/// step 3 of `glsl/terrain/warp.comp`).
pub fn split_octave(d0: f64, distance: f64) -> f64 {
    ((d0 / distance.max(1e-6)).log2() - f64::from(SPLIT_BIAS)).clamp(0.0, f64::from(MAX_DETAIL_OCTAVES))
}

/// The drawn terrain's surface functions: the atlas's B-spline plus the
/// detail octaves of a [`TerrainSettings`].
pub struct Ground<'a> {
    field: &'a HeightField,
    tile: Vec<f32>,
    /// Atlas spacing `d0`, rounded to `f32` as the GPU receives it.
    d0: f64,
    amplitude: f64,
    roughness: f64,
    detail: bool,
    /// Largest |texel| of the tile: a bound of |N| (its weights are
    /// non-negative and sum to one).
    noise_max: f64,
}

impl<'a> Ground<'a> {
    /// The ground of `field` drawn with `settings` (detail on or off,
    /// amplitude, `H`, noise seed). Errors name the setting or the field.
    pub fn new(field: &'a HeightField, settings: &TerrainSettings) -> Result<Ground<'a>> {
        settings.validate()?;
        let spacing_ok = field.spacing.is_finite() && field.spacing.min_element() > 0.0;
        let samples = (field.columns as usize).checked_mul(field.rows as usize);
        if !spacing_ok || field.columns < 2 || field.rows < 2 || samples != Some(field.heights.len()) {
            return Err(Error::invalid(
                "height field",
                format!(
                    "{}×{} samples, {} heights, spacing {}×{} m: need at least 2×2 samples, one height each and a positive spacing",
                    field.columns, field.rows, field.heights.len(), field.spacing.x, field.spacing.y
                ),
            ));
        }
        let tile = noise_tile(settings.noise_seed, NOISE_TILE)?;
        let noise_max = tile.iter().fold(0.0f64, |m, &v| m.max(f64::from(v).abs()));
        Ok(Ground {
            field,
            tile,
            d0: f64::from(field.spacing.min_element() as f32),
            amplitude: f64::from(settings.detail_amplitude),
            roughness: f64::from(settings.detail_h),
            detail: settings.detail,
            noise_max,
        })
    }

    /// The height field.
    pub fn field(&self) -> &HeightField {
        self.field
    }

    /// Sketch-atlas spacing `d0` (metres).
    pub fn atlas_spacing(&self) -> f64 {
        self.d0
    }

    /// Bound of the noise: the tile's largest |texel| (its evaluation
    /// weights are non-negative and sum to one).
    pub fn noise_bound(&self) -> f64 {
        self.noise_max
    }

    /// Amplitude of detail octave `k` (metres), `A·d0·2^(−k·H)`; 0 with the
    /// detail off.
    pub fn octave_amplitude(&self, k: u32) -> f64 {
        match self.detail {
            true => self.amplitude * self.d0 * (-f64::from(k) * self.roughness).exp2(),
            false => 0.0,
        }
    }

    /// Ground height (metres) at world `(x, y)` at the finest level: the
    /// B-spline with every detail octave (module docs: how far a drawn
    /// view may differ). Errors, naming the coordinates, outside the
    /// terrain rectangle `[0, (columns−1)·dx] × [0, (rows−1)·dy]`.
    pub fn height(&self, x: f64, y: f64) -> Result<f64> {
        let xy = self.inside(x, y)?;
        Ok(self.surface(xy, f64::from(MAX_DETAIL_OCTAVES)).0)
    }

    /// Unit upward normal of [`Ground::height`]'s surface at `(x, y)`, from
    /// its analytic gradient. (The GPU's vertex normals are the same
    /// analytic gradient with the detail octaves up to the vertex's split
    /// octave; the finer ones are bump-mapped in `terrain.draw`.)
    pub fn normal(&self, x: f64, y: f64) -> Result<DVec3> {
        let xy = self.inside(x, y)?;
        let (_, g) = self.surface(xy, f64::from(MAX_DETAIL_OCTAVES));
        Ok(DVec3::new(-g.x, -g.y, 1.0).normalize())
    }

    /// `(x, y)` if it lies on the terrain, else the one-line error.
    fn inside(&self, x: f64, y: f64) -> Result<DVec2> {
        let extent = self.field.extent();
        if (0.0..=extent.x).contains(&x) && (0.0..=extent.y).contains(&y) {
            return Ok(DVec2::new(x, y));
        }
        Err(Error::invalid(
            "ground position",
            format!(
                "({x}, {y}) m lies outside the terrain [0, {}] × [0, {}] m",
                extent.x, extent.y
            ),
        ))
    }

    /// Height and world gradient of a vertex of split octave `split` at
    /// `xy` (no range check: outside the terrain the B-spline continues its
    /// edge, as on the GPU): `B(xy) + D(xy; 0, split)`.
    pub fn surface(&self, xy: DVec2, split: f64) -> (f64, DVec2) {
        let h = sample_bspline(self.field, xy.x, xy.y);
        let g = sample_bspline_gradient(self.field, xy.x, xy.y);
        let (dh, dg) = self.detail(xy, 0.0, split);
        (h + dh, g + dg)
    }

    /// `detail_octaves` of `terrain_detail.glsl`: the octaves weighted by
    /// `w(o_hi, k) − w(o_lo, k)`, height (metres) and world gradient; zero
    /// with the detail off.
    pub fn detail(&self, xy: DVec2, o_lo: f64, o_hi: f64) -> (f64, DVec2) {
        let (mut h, mut grad) = (0.0, DVec2::ZERO);
        if !self.detail {
            return (h, grad);
        }
        let last = (o_hi.ceil().max(0.0) as u32).min(MAX_DETAIL_OCTAVES);
        for k in 1..=last {
            let w = octave_weight(o_hi, k) - octave_weight(o_lo, k);
            if w <= 0.0 {
                continue;
            }
            let freq = f64::from(k).exp2() / self.d0;
            let p = xy * freq + OCTAVE_SHIFT * f64::from(k);
            let (n, g) = evaluate_gradient(&self.tile, NOISE_TILE, p.x, p.y);
            let a = w * self.octave_amplitude(k);
            h += a * n;
            grad += a * g * freq;
        }
        (h, grad)
    }

    /// Largest difference between a vertex of split octave `split` and the
    /// finest level [`Ground::height`] at the same point: every octave above
    /// `split`, by its weight, at the tile's largest |value|.
    pub fn omitted_detail_bound(&self, split: f64) -> f64 {
        (1..=MAX_DETAIL_OCTAVES)
            .map(|k| (1.0 - octave_weight(split, k)) * self.octave_amplitude(k) * self.noise_max)
            .sum()
    }

    /// Vertex `(i, j)` of the `side×side` geometry image that
    /// `terrain.warp` computes from `warped` (the view's `n×n` warped
    /// sketch map, [`crate::terrain::lod::LodFrame`]'s `warp.positions`):
    /// `(x, y, z, split octave)`, steps 1–4 of `glsl/terrain/warp.comp`.
    pub fn vertex(&self, warped: &[DVec3], n: usize, side: usize, i: usize, j: usize) -> DVec4 {
        let extent = self.field.extent();
        let p = zoom_xy(warped, n, side, extent, i, j);
        let grad = sample_bspline_gradient(self.field, p.x, p.y);
        let last = side - 1;
        let neighbours = [
            ((i + 1).min(last), j),
            (i.saturating_sub(1), j),
            (i, (j + 1).min(last)),
            (i, j.saturating_sub(1)),
        ];
        let d2 = neighbours
            .iter()
            .map(|&(a, b)| {
                let dxy = zoom_xy(warped, n, side, extent, a, b) - p;
                dxy.length_squared() + grad.dot(dxy).powi(2)
            })
            .fold(0.0, f64::max);
        let split = split_octave(self.d0, d2.sqrt());
        p.extend(self.surface(p, split).0).extend(split)
    }
}

/// A point of the drawn mesh: its height and the triangle it lies in.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg(test)]
pub struct DrawnPoint {
    /// Height of the triangulated surface (metres).
    pub height: f64,
    /// Smallest split octave of the triangle's vertices.
    pub split_min: f64,
    /// Longest horizontal edge of the triangle (metres).
    pub edge: f64,
}

/// The triangulated mesh a view draws: the `side×side` geometry image of
/// `terrain.warp` over a warped sketch map, with the grid's triangles
/// ([`crate::terrain::geometry_image::grid_indices`]).
#[cfg(test)]
pub struct DrawnSurface<'g, 'a> {
    ground: &'g Ground<'a>,
    warped: &'g [DVec3],
    n: usize,
    side: usize,
    /// Per sketch cell, the bounding box (min x, min y, max x, max y) of
    /// its four warped corners: where its output vertices lie.
    cells: Vec<[f64; 4]>,
}

#[cfg(test)]
impl<'g, 'a> DrawnSurface<'g, 'a> {
    /// The mesh of `warped` (`n×n`, `n ≥ 2`) zoomed to `side×side`
    /// vertices (`side ≥ 2`).
    #[cfg(test)]
    pub fn new(ground: &'g Ground<'a>, warped: &'g [DVec3], n: usize, side: usize) -> Result<Self> {
        if n < 2 || warped.len() != n * n || side < 2 {
            return Err(Error::invalid(
                "drawn surface",
                format!("{} warped texels for n = {n}, output side {side}", warped.len()),
            ));
        }
        let mut cells = Vec::with_capacity((n - 1) * (n - 1));
        for r in 0..n - 1 {
            for c in 0..n - 1 {
                let corners = [(r, c), (r, c + 1), (r + 1, c), (r + 1, c + 1)].map(|(r, c)| warped[r * n + c]);
                let lo = corners.iter().fold(DVec2::INFINITY, |m, p| m.min(p.truncate()));
                let hi = corners.iter().fold(DVec2::NEG_INFINITY, |m, p| m.max(p.truncate()));
                cells.push([lo.x, lo.y, hi.x, hi.y]);
            }
        }
        Ok(DrawnSurface {
            ground,
            warped,
            n,
            side,
            cells,
        })
    }

    /// The drawn surface above world `xy`; None where the mesh does not
    /// reach (outside the view's sketch region).
    #[cfg(test)]
    pub fn at(&self, xy: DVec2) -> Option<DrawnPoint> {
        let m = self.n - 1;
        let scale = m as f64 / (self.side - 1) as f64;
        let slack = 1e-6 * (1.0 + xy.abs().max_element());
        let range = |c: usize| {
            let lo = ((c as f64 / scale).floor() as usize).saturating_sub(1);
            let hi = (((c + 1) as f64 / scale).ceil() as usize + 1).min(self.side - 1);
            lo..hi
        };
        for (k, b) in self.cells.iter().enumerate() {
            if xy.x < b[0] - slack || xy.y < b[1] - slack || xy.x > b[2] + slack || xy.y > b[3] + slack {
                continue;
            }
            let (r, c) = (k / m, k % m);
            for j in range(r) {
                for i in range(c) {
                    if let Some(p) = self.in_quad(xy, i, j) {
                        return Some(p);
                    }
                }
            }
        }
        None
    }

    /// The point above `xy` if it lies in one of the two triangles of grid
    /// quad `(i, j)` (`grid_indices`' split: `(i, j), (i+1, j), (i, j+1)`
    /// and `(i+1, j), (i+1, j+1), (i, j+1)`).
    #[cfg(test)]
    fn in_quad(&self, xy: DVec2, i: usize, j: usize) -> Option<DrawnPoint> {
        let extent = self.ground.field.extent();
        let at = |a: usize, b: usize| zoom_xy(self.warped, self.n, self.side, extent, a, b);
        let triangles = [
            [(i, j), (i + 1, j), (i, j + 1)],
            [(i + 1, j), (i + 1, j + 1), (i, j + 1)],
        ];
        for t in triangles {
            let [a, b, c] = t.map(|(p, q)| at(p, q));
            let area = (b - a).perp_dot(c - a);
            if area.abs() <= 1e-12 * (1.0 + a.length_squared()) {
                continue;
            }
            let l1 = (c - b).perp_dot(xy - b) / area;
            let l2 = (a - c).perp_dot(xy - c) / area;
            let l3 = 1.0 - l1 - l2;
            let eps = -1e-9;
            if l1 < eps || l2 < eps || l3 < eps {
                continue;
            }
            let v = t.map(|(p, q)| self.ground.vertex(self.warped, self.n, self.side, p, q));
            let edge = [(a, b), (b, c), (c, a)]
                .iter()
                .map(|(p, q)| p.distance(*q))
                .fold(0.0, f64::max);
            return Some(DrawnPoint {
                height: l1 * v[0].z + l2 * v[1].z + l3 * v[2].z,
                split_min: v.iter().map(|v| v.w).fold(f64::INFINITY, f64::min),
                edge,
            });
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::wavelet_noise::evaluate;
    use crate::terrain::procedural::ProceduralTerrain;

    fn field() -> HeightField {
        ProceduralTerrain::default().generate(65, 49, DVec2::new(20.0, 25.0))
    }

    /// The finest level against a direct evaluation of the formula in the
    /// module docs: B-spline plus every octave, each from the noise tile's
    /// plain evaluation (not the gradient path the twin uses).
    #[test]
    fn height_is_the_bspline_plus_every_octave() {
        let field = field();
        let settings = TerrainSettings::default();
        let ground = Ground::new(&field, &settings).unwrap();
        let tile = noise_tile(settings.noise_seed, NOISE_TILE).unwrap();
        let d0 = 20.0f32 as f64;
        let (amp, h) = (f64::from(settings.detail_amplitude), f64::from(settings.detail_h));
        let mut largest = 0.0f64;
        for (x, y) in [
            (0.0, 0.0),
            (317.25, 811.5),
            (1279.9, 1200.0),
            (640.0, 13.7),
            (1000.1, 599.9),
        ] {
            let mut expected = sample_bspline(&field, x, y);
            for k in 1..=8 {
                let f = f64::from(k).exp2() / d0;
                let n = evaluate(
                    &tile,
                    NOISE_TILE,
                    x * f + 37.13 * f64::from(k),
                    y * f + 11.71 * f64::from(k),
                );
                expected += amp * d0 * (-f64::from(k) * h).exp2() * n;
            }
            let got = ground.height(x, y).unwrap();
            assert!((got - expected).abs() < 1e-9, "({x}, {y}): {got} vs {expected}");
            largest = largest.max((expected - sample_bspline(&field, x, y)).abs());
        }
        assert!(largest > 0.1, "the detail must move the surface ({largest} m)");
        // Without detail it is the bare B-spline.
        let bare = Ground::new(
            &field,
            &TerrainSettings {
                detail: false,
                ..settings
            },
        )
        .unwrap();
        assert_eq!(
            bare.height(317.25, 811.5).unwrap(),
            sample_bspline(&field, 317.25, 811.5)
        );
    }

    #[test]
    fn gradient_and_normal_match_finite_differences() {
        let field = field();
        let ground = Ground::new(&field, &TerrainSettings::default()).unwrap();
        for (x, y, split) in [(400.3, 300.7, 8.0), (901.0, 777.7, 3.4), (55.5, 1100.1, 0.6)] {
            let (_, g) = ground.surface(DVec2::new(x, y), split);
            // Small steps: the quadratic B-spline's second derivative jumps at
            // its knots, which central differences across a knot feel.
            let e = 1e-6;
            let f = |dx: f64, dy: f64| ground.surface(DVec2::new(x + dx, y + dy), split).0;
            let fd = DVec2::new(f(e, 0.0) - f(-e, 0.0), f(0.0, e) - f(0.0, -e)) / (2.0 * e);
            assert!((g - fd).length() < 1e-4 * (1.0 + fd.length()), "{g} vs {fd}");
        }
        let (_, g) = ground.surface(DVec2::new(400.3, 300.7), 8.0);
        let n = ground.normal(400.3, 300.7).unwrap();
        assert!((n.length() - 1.0).abs() < 1e-12 && (n.x / n.z + g.x).abs() < 1e-12);
    }

    #[test]
    fn split_weights_and_bounds() {
        assert_eq!(octave_weight(4.25, 4), 1.0);
        assert_eq!(octave_weight(4.25, 5), 0.25);
        assert_eq!(octave_weight(4.25, 6), 0.0);
        assert_eq!(split_octave(64.0, 2.0), 5.0 - 0.5);
        assert_eq!(split_octave(64.0, 1e-9), 8.0);
        assert_eq!(split_octave(1.0, 64.0), 0.0);
        let field = field();
        let ground = Ground::new(&field, &TerrainSettings::default()).unwrap();
        assert_eq!(ground.omitted_detail_bound(8.0), 0.0);
        // The difference between a split-3.5 vertex and the finest level
        // stays within the bound, and the bound is not vacuous.
        let bound = ground.omitted_detail_bound(3.5);
        let mut largest = 0.0f64;
        for k in 0..400 {
            let xy = DVec2::new(3.17 * f64::from(k), 2.71 * f64::from(k));
            let d = (ground.surface(xy, 3.5).0 - ground.surface(xy, 8.0).0).abs();
            assert!(d <= bound, "{d} > {bound}");
            largest = largest.max(d);
        }
        assert!(largest > 0.2 * bound, "{largest} vs {bound}");
    }

    #[test]
    fn outside_the_terrain_is_an_error_naming_the_point() {
        let field = field();
        let ground = Ground::new(&field, &TerrainSettings::default()).unwrap();
        let e = ground.height(-0.5, 10.0).unwrap_err().to_string();
        assert!(e.contains("(-0.5, 10)") && !e.contains('\n'), "{e}");
        assert!(ground.height(10.0, 1200.5).is_err());
        assert!(ground.normal(f64::NAN, 1.0).is_err());
        assert!(ground.height(1280.0, 1200.0).is_ok());
        let bad = HeightField {
            heights: vec![0.0; 3],
            ..field.clone()
        };
        assert!(Ground::new(&bad, &TerrainSettings::default()).is_err());
    }

    /// An identity warp: the drawn surface is the regular grid, its
    /// vertices the twin at their split octave, and between them the
    /// triangles interpolate linearly.
    #[test]
    fn drawn_surface_of_a_regular_grid() {
        let field = field();
        let ground = Ground::new(&field, &TerrainSettings::default()).unwrap();
        let n = 5;
        let warped: Vec<DVec3> = (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * 80.0, (k / n) as f64 * 60.0, 0.0))
            .collect();
        let side = 17;
        let surface = DrawnSurface::new(&ground, &warped, n, side).unwrap();
        // Vertex (3, 5) sits at (60, 75); its neighbours 20 m and 15 m away.
        let v = ground.vertex(&warped, n, side, 3, 5);
        let d = (DVec2::new(20.0, 0.0).length_squared()
            + sample_bspline_gradient(&field, 60.0, 75.0).x.powi(2) * 400.0)
            .max(225.0 + sample_bspline_gradient(&field, 60.0, 75.0).y.powi(2) * 225.0)
            .sqrt();
        assert_eq!(v.truncate().truncate(), DVec2::new(60.0, 75.0));
        assert!(
            (v.w - split_octave(20.0, d)).abs() < 1e-6,
            "{} vs {}",
            v.w,
            split_octave(20.0, d)
        );
        assert!((v.z - ground.surface(DVec2::new(60.0, 75.0), v.w).0).abs() < 1e-9);
        let at = surface.at(DVec2::new(60.0, 75.0)).unwrap();
        assert!((at.height - v.z).abs() < 1e-9);
        // Inside the lower triangle of quad (3, 5): (60,75), (80,75), (60,90).
        let (a, b, c) = (
            v,
            ground.vertex(&warped, n, side, 4, 5),
            ground.vertex(&warped, n, side, 3, 6),
        );
        let p = surface.at(DVec2::new(65.0, 80.0)).unwrap();
        let lin = a.z + 0.25 * (b.z - a.z) + (1.0 / 3.0) * (c.z - a.z);
        assert!((p.height - lin).abs() < 1e-9, "{} vs {lin}", p.height);
        assert_eq!(p.edge, 25.0);
        assert!(surface.at(DVec2::new(-5.0, 10.0)).is_none());
        assert!(DrawnSurface::new(&ground, &warped, 4, side).is_err());
    }
}
