//! Ground queries on a streamed field (issue 31 item 1: "ground queries …
//! work on streamed fields"; §7.4.4 keeps the large atlas out of memory).
//!
//! A scene made from a height pyramid holds one coarse level resident; the
//! detail window ([`super::DetailWindow`]) draws a finer level near the
//! camera, and where it is drawn its real samples replace the procedural
//! detail octaves coarser than their spacing (`glsl/terrain/warp.comp`:
//! octaves from `o_window = log2(d0 / s)` up, `s` the level's spacing,
//! `d0` the resident spacing). A query answered from the resident level
//! would put a car on the resident B-spline plus noise, metres away from
//! the real ground the window draws under it.
//!
//! [`StreamedGround`] answers from the pyramid's **finest level**, the
//! surface the drawn one converges to as the camera comes down (as
//! [`Ground::height`] is the finest level of the procedural detail):
//!
//! ```text
//! h(x, y) = B_0(x, y) + D(x, y; o_0, 8),   o_0 = max(log2(d0 / s_0), 0)
//! ```
//!
//! `B_0` the cubic B-spline of level 0 (the same taps and clamping as
//! [`crate::surface::bspline::sample_bspline`]), `D` the detail octaves of
//! [`Ground::detail`]. The samples come tile by tile from the file through
//! a small least-recently-used cache ([`TileCache`], [`QUERY_CACHE_TILES`]
//! tiles), so memory does not grow with the field and queries near each
//! other read each tile once. It is the query's own reader: nothing is
//! shared with the renderer's window or its reader thread.

use glam::{DVec2, DVec3};

use super::DetailSource;
use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::io::pyramid::stream::TileCache;
use crate::io::pyramid::{HeightPyramid, TileKey};
use crate::surface::bspline::{bspline_axis, cubic_bspline_derivative_weights, cubic_bspline_weights};
use crate::terrain::geometry_image::{TerrainSettings, MAX_DETAIL_OCTAVES};
use crate::terrain::ground::Ground;

/// Tiles the query cache holds: the 4×4 taps of one query touch at most
/// four tiles; 16 keep a neighbourhood of queries (a car's wheels, a path)
/// from reading a tile twice.
pub const QUERY_CACHE_TILES: usize = 16;

/// The ground of a streamed scene on the CPU (module docs).
pub struct StreamedGround<'a> {
    /// The resident level's ground: the extent check and the detail octaves
    /// (their `d0` is the resident spacing, as on the GPU).
    resident: Ground<'a>,
    pyramid: HeightPyramid,
    /// Samples a side and spacing of level 0.
    size: (u32, u32),
    spacing: DVec2,
    /// The first procedural octave the finest level leaves to the noise.
    first_octave: f64,
    cache: TileCache,
}

impl<'a> StreamedGround<'a> {
    /// The ground of the scene whose resident level is `resident`, streamed
    /// from `source`'s pyramid, drawn with `settings`. Errors name the file
    /// (unreadable, not a pyramid) or the setting.
    pub fn open(resident: &'a HeightField, settings: &TerrainSettings, source: &DetailSource) -> Result<Self> {
        let resident = Ground::new(resident, settings)?;
        let pyramid = HeightPyramid::open(&source.path)?;
        let spacing = pyramid.level_spacing(0);
        let positive = spacing.min_element() > 0.0;
        if !positive {
            return Err(Error::input(&source.path, "level 0 has no positive spacing"));
        }
        let first_octave = (resident.atlas_spacing() / spacing.min_element()).log2().max(0.0);
        Ok(StreamedGround {
            resident,
            size: pyramid.level_size(0),
            spacing,
            pyramid,
            first_octave,
            cache: TileCache::new(QUERY_CACHE_TILES),
        })
    }

    /// Ground height (metres) at world `(x, y)`: level 0's B-spline with
    /// the octaves finer than its spacing (module docs). Errors name the
    /// point outside the terrain, or the file and tile that could not be read.
    pub fn height(&mut self, x: f64, y: f64) -> Result<f64> {
        self.resident.height(x, y)?;
        Ok(self.surface(DVec2::new(x, y))?.0)
    }

    /// Unit upward normal of [`StreamedGround::height`]'s surface, from its
    /// analytic gradient.
    pub fn normal(&mut self, x: f64, y: f64) -> Result<DVec3> {
        self.resident.height(x, y)?;
        let (_, g) = self.surface(DVec2::new(x, y))?;
        Ok(DVec3::new(-g.x, -g.y, 1.0).normalize())
    }

    /// Tiles the cache holds now (at most [`QUERY_CACHE_TILES`]).
    pub fn cached_tiles(&self) -> usize {
        self.cache.len()
    }

    /// Height and gradient at `xy` (inside the terrain).
    fn surface(&mut self, xy: DVec2) -> Result<(f64, DVec2)> {
        let (cx, tx, inside_x) = bspline_axis(xy.x, self.spacing.x, self.size.0);
        let (ry, ty, inside_y) = bspline_axis(xy.y, self.spacing.y, self.size.1);
        let (wx, wy) = (cubic_bspline_weights(tx), cubic_bspline_weights(ty));
        let (dx, dy) = (
            cubic_bspline_derivative_weights(tx),
            cubic_bspline_derivative_weights(ty),
        );
        let (mut h, mut gx, mut gy) = (0.0, 0.0, 0.0);
        for j in 0..4 {
            for i in 0..4 {
                let v = f64::from(self.sample(cx[i], ry[j])?);
                h += wx[i] * wy[j] * v;
                gx += dx[i] * wy[j] * v;
                gy += wx[i] * dy[j] * v;
            }
        }
        // Outside an axis the B-spline is constant along it (as sample_bspline_gradient).
        let grad = DVec2::new(
            if inside_x { gx / self.spacing.x } else { 0.0 },
            if inside_y { gy / self.spacing.y } else { 0.0 },
        );
        let (dh, dg) = self
            .resident
            .detail(xy, self.first_octave, f64::from(MAX_DETAIL_OCTAVES));
        Ok((h + dh, grad + dg))
    }

    /// Sample `(c, r)` of level 0 (inside it), through the cache.
    fn sample(&mut self, c: u32, r: u32) -> Result<f32> {
        let t = self.pyramid.tile_side();
        let key = TileKey {
            level: 0,
            x: c / t,
            y: r / t,
        };
        if let Some(tile) = self.cache.get(key) {
            return Ok(tile.heights[((r % t) * tile.width + c % t) as usize]);
        }
        let tile = self.pyramid.read_tile(key)?;
        let v = tile.heights[((r % t) * tile.width + c % t) as usize];
        self.cache.insert(tile);
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::super::tests::{rippled_field, write_test_pyramid};
    use super::*;
    use crate::renderer::Scene;
    use crate::surface::bspline::sample_bspline;

    /// The rippled pyramid (1 m samples, ripples 6–7 m long) with level 3
    /// (8 m) resident and a 256² window.
    fn streamed_scene(name: &str) -> (Scene, HeightField) {
        let path = write_test_pyramid(&rippled_field(), name);
        let pyramid = HeightPyramid::open(&path).unwrap();
        let mut scene = Scene::from_pyramid(&pyramid, 129).unwrap();
        scene.set_detail_window(256, true).unwrap();
        (scene, pyramid.level_field(0).unwrap())
    }

    /// Points spread over the field, away from nothing in particular.
    fn points() -> impl Iterator<Item = DVec2> {
        (0..300).map(|k| {
            let k = f64::from(k);
            DVec2::new((k * 0.618_034).fract() * 1024.0, (k * 0.414_214).fract() * 1024.0)
        })
    }

    #[test]
    fn streamed_heights_are_the_finest_levels_bspline_with_the_octaves_it_leaves() {
        let (scene, level0) = streamed_scene("ground-query.hpyr");
        let terrain = TerrainSettings::default();
        let mut streamed = scene.streamed_ground(&terrain).unwrap().expect("a streamed scene");
        let resident = scene.ground(&terrain).unwrap();
        // Resident spacing 8 m, level 0 1 m: the window replaces octaves 1–3.
        let first = (resident.atlas_spacing() / 1.0).log2();
        assert!((first - 3.0).abs() < 1e-6, "{first}");
        let (mut worst, mut off_streamed, mut off_resident) = (0.0f64, 0.0, 0.0);
        for p in points() {
            // Independent: the whole level read at once and the crate's B-spline.
            let truth = sample_bspline(&level0, p.x, p.y);
            let expected = truth + resident.detail(p, first, f64::from(MAX_DETAIL_OCTAVES)).0;
            let h = streamed.height(p.x, p.y).unwrap();
            worst = worst.max((h - expected).abs());
            off_streamed += (h - truth).abs() / 300.0;
            off_resident += (resident.height(p.x, p.y).unwrap() - truth).abs() / 300.0;
            assert!(streamed.cached_tiles() <= QUERY_CACHE_TILES);
        }
        println!(
            "streamed query: |h − expected| ≤ {worst:.2e} m; mean |h − B_0| streamed {off_streamed:.3} m, resident {off_resident:.3} m"
        );
        assert!(worst < 1e-6, "{worst}");
        // The real ripples (1.5 m) are in the streamed answer, not the resident one.
        assert!(
            off_streamed < 0.05 && off_resident > 10.0 * off_streamed,
            "{off_streamed} {off_resident}"
        );
        // The scene's one-off queries take the streamed ground.
        let p = DVec2::new(300.5, 411.25);
        assert_eq!(
            scene.ground_height(p.x, p.y).unwrap(),
            streamed.height(p.x, p.y).unwrap()
        );
    }

    #[test]
    fn streamed_normals_follow_the_heights_and_errors_name_the_point_or_the_tile() {
        let (mut scene, _) = streamed_scene("ground-normal.hpyr");
        let mut streamed = scene.streamed_ground(&TerrainSettings::default()).unwrap().unwrap();
        for p in points().skip(1).take(40) {
            let e = 1e-5;
            let dx = (streamed.height(p.x + e, p.y).unwrap() - streamed.height(p.x - e, p.y).unwrap()) / (2.0 * e);
            let dy = (streamed.height(p.x, p.y + e).unwrap() - streamed.height(p.x, p.y - e).unwrap()) / (2.0 * e);
            let expected = DVec3::new(-dx, -dy, 1.0).normalize();
            let n = streamed.normal(p.x, p.y).unwrap();
            assert!((n - expected).length() < 1e-4, "{p}: {n} vs {expected}");
        }
        let err = streamed.height(-3.0, 10.0).unwrap_err().to_string();
        assert!(err.contains("(-3, 10)") && err.lines().count() == 1, "{err}");
        // Without a window the drawn ground is the resident one.
        scene.set_detail_window(0, true).unwrap();
        assert!(scene.streamed_ground(&TerrainSettings::default()).unwrap().is_none());
        let resident = scene
            .ground(&TerrainSettings::default())
            .unwrap()
            .height(10.0, 20.0)
            .unwrap();
        assert_eq!(scene.ground_height(10.0, 20.0).unwrap(), resident);
        // A corrupt tile of level 0 is a one-line error naming the file and the tile.
        let path = scene.detail.as_ref().unwrap().path.clone();
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[100] ^= 0x40; // inside the first tile (level 0, tile (0, 0))
        let bad = path.with_file_name("ground-corrupt.hpyr");
        std::fs::write(&bad, &bytes).unwrap();
        scene.detail.as_mut().unwrap().path = bad;
        scene.set_detail_window(256, true).unwrap();
        let err = scene.ground_height(5.0, 5.0).unwrap_err().to_string();
        assert!(
            err.contains("ground-corrupt.hpyr") && err.contains("tile (0, 0) of level 0") && err.lines().count() == 1,
            "{err}"
        );
    }
}
