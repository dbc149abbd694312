//! The sketch map of geometry image warping (dissertation §7.4.2, Fig. 7.8;
//! `ALGORITHMS.md` §3 item 2): the square region enclosing the view
//! frustum, clipped to the terrain, resampled from the sketch atlas (the
//! whole height field) to a small fixed grid of `(x, y, h)` texels.
//!
//! # The region
//!
//! The frustum is cut at the distance of the farthest corner of the
//! terrain's bounding box (nothing beyond can be seen), its eight corners
//! and the eye are projected onto the ground plane, and the region is the
//! smallest square that encloses them in the map's frame, then clipped to
//! the terrain's bounding rectangle in that frame.
//!
//! The frame is aligned with the view ([`SketchAlignment::View`], the
//! default): rows run across the view, columns along it. The separable warp
//! adapts its first pass per line and shares the second across lines
//! ([`crate::terrain::warp`]), so this orientation lets the first pass
//! follow the lateral frustum edges for every view direction; with an
//! axis-aligned map ([`SketchAlignment::Axes`], the text's choice) diagonal
//! views lose about a fifth of the texels within the wanted density band
//! (`src/terrain/tests/warp.rs`). A rotated frame's clipped rectangle may still reach
//! beyond the terrain at its corners: those texels get zero importance
//! through the surface bound ([`SketchMap::outside`]) and the GPU clamps
//! warped positions onto the terrain, so such samples collapse onto its
//! edge and form only zero-area triangles there.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::surface::bspline::sample_bspline;
use crate::view::Camera;

/// Default sketch map side (texels), as in the text.
pub const DEFAULT_SKETCH_SIDE: usize = 128;

/// Orientation of the sketch map's frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SketchAlignment {
    /// Rows across the view direction, columns along it.
    #[default]
    View,
    /// Rows along world x, columns along world y (the text's choice).
    Axes,
}

/// An oriented rectangle on the ground: texel `(c, r)` of an `n×n` map
/// sits at `origin + c/(n−1)·side_s + r/(n−1)·side_t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SketchRegion {
    pub origin: DVec2,
    /// Whole side along the rows (texel column index grows along it).
    pub side_s: DVec2,
    /// Whole side along the columns (row index grows along it).
    pub side_t: DVec2,
}

impl SketchRegion {
    /// World xy of the normalised map coordinate `(s, t) ∈ [0, 1]²`.
    pub fn at(&self, s: f64, t: f64) -> DVec2 {
        self.origin + s * self.side_s + t * self.side_t
    }

    /// Grid coordinate (column, row) of world `xy` on an `n×n` map of this
    /// region (the sides are orthogonal).
    pub fn grid_coord(&self, xy: DVec2, n: usize) -> DVec2 {
        let d = xy - self.origin;
        let m = (n - 1) as f64;
        let (ls, lt) = (
            self.side_s.length_squared().max(1e-30),
            self.side_t.length_squared().max(1e-30),
        );
        DVec2::new(d.dot(self.side_s) / ls, d.dot(self.side_t) / lt) * m
    }

    /// The region of `camera` (aspect = width / height) over `field`.
    pub fn for_view(field: &HeightField, camera: &Camera, aspect: f64, alignment: SketchAlignment) -> Result<Self> {
        Self::for_view_with_margin(field, camera, aspect, alignment, 0.0)
    }

    /// [`SketchRegion::for_view`] with the enclosing square grown by
    /// `margin` metres on every side before the clip to the terrain: the
    /// region of a world-anchored plan ([`crate::terrain::lod::LodSettings::snap`])
    /// then covers every eye within `margin` of the planning camera's.
    pub fn for_view_with_margin(
        field: &HeightField,
        camera: &Camera,
        aspect: f64,
        alignment: SketchAlignment,
        margin: f64,
    ) -> Result<Self> {
        camera.validate()?;
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(Error::invalid(
                "sketch map margin",
                format!("{margin} (must be finite and ≥ 0)"),
            ));
        }
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(Error::invalid(
                "aspect ratio",
                format!("{aspect} (must be finite and > 0)"),
            ));
        }
        let extent = field.extent();
        let (lo, hi) = field.min_max();
        let (lo, hi) = (f64::from(lo), f64::from(hi));
        // Axes of the frame: `t` along the view on the ground, `s` to its right.
        let forward = camera.forward();
        let t_axis = match alignment {
            SketchAlignment::Axes => DVec2::Y,
            SketchAlignment::View => forward
                .truncate()
                .try_normalize()
                .filter(|_| forward.truncate().length() > 1e-3)
                .or_else(|| camera.image_up().truncate().try_normalize())
                .unwrap_or(DVec2::Y),
        };
        let s_axis = DVec2::new(t_axis.y, -t_axis.x);
        let to_frame = |p: DVec2| DVec2::new(p.dot(s_axis), p.dot(t_axis));

        // The frustum cut at the farthest terrain corner.
        let eye = camera.eye;
        let box_corners = (0..8).map(|k| {
            DVec3::new(
                if k & 1 == 0 { 0.0 } else { extent.x },
                if k & 2 == 0 { 0.0 } else { extent.y },
                if k & 4 == 0 { lo } else { hi },
            )
        });
        let reach = box_corners.map(|c| c.distance(eye)).fold(0.0, f64::max);
        let far = camera.far.min(reach.max(camera.near * 2.0));
        let (right, up) = (camera.right(), camera.image_up());
        let tv = (0.5 * camera.fov_y_deg.to_radians()).tan();
        let th = tv * aspect;
        let mut min = to_frame(eye.truncate());
        let mut max = min;
        for d in [camera.near, far] {
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                let p = eye + d * (forward + sx * th * right + sy * tv * up);
                let q = to_frame(p.truncate());
                min = min.min(q);
                max = max.max(q);
            }
        }
        // Enclosing square, then clipped to the terrain's rectangle.
        let centre = 0.5 * (min + max);
        let half = 0.5 * (max - min).max_element() + margin;
        let (mut smin, mut smax) = (centre - half, centre + half);
        let terrain = [
            DVec2::ZERO,
            DVec2::new(extent.x, 0.0),
            DVec2::new(0.0, extent.y),
            extent,
        ]
        .map(to_frame);
        let tmin = terrain.iter().fold(DVec2::splat(f64::INFINITY), |a, &b| a.min(b));
        let tmax = terrain.iter().fold(DVec2::splat(f64::NEG_INFINITY), |a, &b| a.max(b));
        smin = smin.max(tmin);
        smax = smax.min(tmax);
        // A view that misses the terrain: a sliver at the nearest terrain edge
        // (still a valid, if invisible, mesh). A sliver is at least a
        // thousandth of the terrain's length, but never wider than the
        // terrain itself in that direction: on a strip more than a thousand
        // times longer than wide the whole width is the sliver.
        let min_side = 1e-3 * extent.max_element();
        for k in 0..2 {
            let side = min_side.min(tmax[k] - tmin[k]);
            if smax[k] - smin[k] < side {
                let c = (0.5 * (smin[k] + smax[k])).clamp(tmin[k], tmax[k] - side);
                smin[k] = c;
                smax[k] = c + side;
            }
        }
        let side = smax - smin;
        let region = SketchRegion {
            origin: smin.x * s_axis + smin.y * t_axis,
            side_s: side.x * s_axis,
            side_t: side.y * t_axis,
        };
        if !(region.origin.is_finite() && region.side_s.is_finite() && region.side_t.is_finite()) {
            return Err(Error::invalid("sketch map", "the view gives a non-finite region"));
        }
        Ok(region)
    }
}

/// An `n×n` sketch map: the region's texels with heights from the atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct SketchMap {
    pub n: usize,
    pub region: SketchRegion,
    /// World `(x, y, h)` per texel, row-major; heights are the cubic
    /// B-spline of the atlas (`sample_bspline`), clamped at its edges.
    pub geometry: Vec<DVec3>,
    /// Texels outside the terrain's rectangle (possible at the corners of a
    /// view-aligned region).
    pub outside: Vec<bool>,
}

impl SketchMap {
    /// Resamples `field` over `region` to `n×n` texels (`n ≥ 2`).
    pub fn resample(field: &HeightField, region: SketchRegion, n: usize) -> Result<SketchMap> {
        if !(2..=4096).contains(&n) {
            return Err(Error::invalid("sketch map size", format!("{n} (must be 2..=4096)")));
        }
        let extent = field.extent();
        let m = (n - 1) as f64;
        let slack = 1e-9 * extent.max_element();
        let mut geometry = Vec::with_capacity(n * n);
        let mut outside = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                let p = region.at(c as f64 / m, r as f64 / m);
                let out = p.x < -slack || p.y < -slack || p.x > extent.x + slack || p.y > extent.y + slack;
                let q = p.clamp(DVec2::ZERO, extent);
                geometry.push(DVec3::new(p.x, p.y, sample_bspline(field, q.x, q.y)));
                outside.push(out);
            }
        }
        Ok(SketchMap {
            n,
            region,
            geometry,
            outside,
        })
    }

    /// The sketch map of a view: [`SketchRegion::for_view`] then
    /// [`SketchMap::resample`].
    pub fn for_view(
        field: &HeightField,
        camera: &Camera,
        aspect: f64,
        alignment: SketchAlignment,
        n: usize,
    ) -> Result<SketchMap> {
        SketchMap::resample(field, SketchRegion::for_view(field, camera, aspect, alignment)?, n)
    }

    /// [`SketchMap::for_view`] over [`SketchRegion::for_view_with_margin`].
    pub fn for_view_with_margin(
        field: &HeightField,
        camera: &Camera,
        aspect: f64,
        (alignment, margin): (SketchAlignment, f64),
        n: usize,
    ) -> Result<SketchMap> {
        let region = SketchRegion::for_view_with_margin(field, camera, aspect, alignment, margin)?;
        SketchMap::resample(field, region, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::procedural::ProceduralTerrain;

    fn field() -> HeightField {
        ProceduralTerrain::default().generate(65, 65, DVec2::splat(100.0))
    }

    fn camera(eye: DVec3, target: DVec3) -> Camera {
        Camera {
            eye,
            target,
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 1.0,
            far: 100_000.0,
        }
    }

    /// Every terrain point that the camera sees (inside the frustum) lies in
    /// the region, for both alignments.
    #[test]
    fn region_encloses_the_visible_terrain() {
        let f = field();
        let cams = [
            camera(DVec3::new(3200.0, -500.0, 900.0), DVec3::new(3200.0, 3200.0, 100.0)),
            camera(DVec3::new(300.0, 300.0, 700.0), DVec3::new(4000.0, 5000.0, 0.0)),
            camera(DVec3::new(3000.0, 3000.0, 3000.0), DVec3::new(3010.0, 3000.0, 0.0)),
        ];
        for cam in cams {
            for alignment in [SketchAlignment::View, SketchAlignment::Axes] {
                let region = SketchRegion::for_view(&f, &cam, 16.0 / 9.0, alignment).unwrap();
                let frustum = crate::terrain::importance::Frustum::perspective(
                    cam.eye,
                    cam.forward(),
                    cam.up,
                    cam.fov_y_deg.to_radians(),
                    16.0 / 9.0,
                    0.0,
                )
                .unwrap();
                let s_len2 = region.side_s.length_squared();
                let t_len2 = region.side_t.length_squared();
                for r in 0..65 {
                    for c in 0..65 {
                        let p = DVec3::new(c as f64 * 100.0, r as f64 * 100.0, f64::from(f.height(c, r)));
                        if !frustum.contains(p) {
                            continue;
                        }
                        let d = p.truncate() - region.origin;
                        let (s, t) = (d.dot(region.side_s) / s_len2, d.dot(region.side_t) / t_len2);
                        assert!(
                            (-1e-9..=1.0 + 1e-9).contains(&s) && (-1e-9..=1.0 + 1e-9).contains(&t),
                            "{alignment:?}: visible point {p} at ({s}, {t}) outside the region"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn view_aligned_columns_run_along_the_view() {
        let f = field();
        let cam = camera(DVec3::new(300.0, 300.0, 700.0), DVec3::new(4000.0, 4000.0, 0.0));
        let region = SketchRegion::for_view(&f, &cam, 1.5, SketchAlignment::View).unwrap();
        let along = region.side_t.normalize();
        assert!(along.dot(cam.forward().truncate().normalize()) > 0.999);
        let map = SketchMap::resample(&f, region, 16).unwrap();
        assert_eq!(map.geometry.len(), 256);
        assert!(map.geometry.iter().all(|p| p.is_finite()));
    }

    #[test]
    fn axis_aligned_region_is_clipped_to_the_terrain() {
        let f = field();
        let cam = camera(DVec3::new(3200.0, -500.0, 900.0), DVec3::new(3200.0, 3200.0, 100.0));
        let map = SketchMap::for_view(&f, &cam, 16.0 / 9.0, SketchAlignment::Axes, 8).unwrap();
        assert!(map.outside.iter().all(|&o| !o));
        let e = f.extent();
        for p in &map.geometry {
            assert!(p.x >= -1e-6 && p.y >= -1e-6 && p.x <= e.x + 1e-6 && p.y <= e.y + 1e-6);
        }
    }

    /// A strip far more than a thousand times longer than wide (lengthwise
    /// in x or in y, by its samples or its spacing): every view gives a region of
    /// positive, finite sides within the strip's width, seen or missed,
    /// for both alignments (the sliver of a missed view used to be wider
    /// than the strip, and its `clamp` bounds crossed).
    #[test]
    fn strips_give_regions_within_their_width() {
        let strips = [
            (2048, 2, DVec2::splat(30.0)),
            (2, 2048, DVec2::splat(30.0)),
            (4000, 3, DVec2::ONE),
            (2, 9000, DVec2::splat(0.001)),
            // Square in samples, a strip by its spacing (`--spacing 1,2000`).
            (65, 65, DVec2::new(1.0, 2000.0)),
        ];
        for (columns, rows, spacing) in strips {
            let f = HeightField::from_fn(columns, rows, spacing, |c, r| ((c + 3 * r) % 7) as f32);
            let e = f.extent();
            let centre = (0.5 * e).extend(0.0);
            let size = e.max_element();
            let cams = [
                // Along the strip, across it, straight down, and away from it.
                camera(centre - DVec3::new(0.6 * e.x, 0.6 * e.y, -0.1 * size), centre),
                camera(centre + DVec3::new(0.3 * size, -0.3 * size, 0.2 * size), centre),
                camera(centre + DVec3::new(0.0, 1e-3 * size, 0.1 * size), centre),
                camera(
                    centre + DVec3::new(2.0 * size, 0.0, 10.0),
                    centre + DVec3::new(3.0 * size, 0.0, 0.0),
                ),
            ];
            for cam in cams {
                let cam = Camera {
                    near: 1e-3 * size,
                    far: 100.0 * size,
                    ..cam
                };
                for alignment in [SketchAlignment::View, SketchAlignment::Axes] {
                    let what = format!("{columns}x{rows} at {spacing} m, {alignment:?}, eye {}", cam.eye);
                    let region = SketchRegion::for_view(&f, &cam, 4.0 / 3.0, alignment).expect(&what);
                    let (s, t) = (region.side_s.length(), region.side_t.length());
                    assert!(
                        s > 0.0 && t > 0.0 && s.is_finite() && t.is_finite(),
                        "{what}: sides {s}, {t}"
                    );
                    let map = SketchMap::resample(&f, region, 8).expect(&what);
                    assert!(map.geometry.iter().all(|p| p.is_finite()), "{what}");
                    if alignment == SketchAlignment::Axes {
                        let slack = 1e-9 * size;
                        for p in &map.geometry {
                            assert!(
                                p.x >= -slack && p.y >= -slack && p.x <= e.x + slack && p.y <= e.y + slack,
                                "{what}: texel {p} off the strip {e}"
                            );
                        }
                    }
                }
            }
        }
    }
}
