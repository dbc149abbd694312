//! What is drawn: a height field, point objects and a sun. The built-in
//! default scene is a procedural ridged-multifractal terrain (§6.1) with
//! procedural rocks (§6.1.4) and plants (chapter 10, Fig. 10.12) scattered
//! over it, under a low afternoon sun.

use glam::{DVec2, DVec3, Vec3};

use crate::budget::{Footprint, MemoryLimits};
use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::io::pyramid::HeightPyramid;
use crate::points::build::plants::scatter::{scatter, ScatterRule};
use crate::points::build::spt::{epsilon_from_pixels, SptOptions};
#[cfg(test)]
use crate::points::scene::PointInstance;
use crate::points::scene::{scatter_rocks, PointScene};
use crate::points::vegetation::{plant_scene, VegetationOptions, VegetationReport};
use crate::surface::layers::vegetation::subtree_shares;
use crate::terrain::detail::{DetailSource, StreamedGround, DEFAULT_DETAIL_WINDOW, MAX_DETAIL_WINDOW};
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::ground::Ground;
use crate::terrain::procedural::ProceduralTerrain;
use crate::texturing::reference::ReferenceSurface;
use crate::view::camera::Camera;
use crate::view::{Lighting, SunPosition};

/// Rocks of the default scene: distinct shapes, surfels per shape, instances.
pub const DEFAULT_ROCKS: (usize, usize, usize) = (4, 4000, 300);

/// Host bytes of the point instance itself: the instance (72 B) twice (a
/// growing vector doubles) and the per-frame selection entry (16 B).
#[cfg(test)]
pub const INSTANCE_HOST_BYTES: u64 = 2 * std::mem::size_of::<PointInstance>() as u64 + 16;

/// Host bytes per point instance (boulder or plant) at the peak of a
/// render, measured: 10⁶ boulders raised the peak resident memory of a
/// 64×48 render on lavapipe by 1.83 GB. Beyond [`INSTANCE_HOST_BYTES`] this
/// is the renderer's copy of the scene, the per-view draw and shadow-caster
/// records ([`super::footprint::instances_footprint`]: a 96 B
/// `GpuInstance` per frame in flight, and the casters' records) in
/// host-visible upload memory, and the selection's per-frame lists. On a
/// CPU device all of it is host memory; on a GPU the upload regions still
/// live in host-visible memory.
pub const INSTANCE_PEAK_BYTES: u64 = 1900;

/// What `count` boulders need ([`Scene::add_rocks`]): [`INSTANCE_PEAK_BYTES`]
/// each; the few rock shapes are small and fixed.
pub fn rocks_footprint(count: usize) -> Footprint {
    Footprint::per_item(count as u64, INSTANCE_PEAK_BYTES, 0)
}

/// Most plants the vegetation rules may ask for over a terrain before the
/// cap ([`VegetationOptions::max_plants`]) thins them: 10¹². Beyond it the
/// thinning ratio and the counts reported lose their meaning (a density
/// multiplier of 10³⁰⁰ reported saturated counts, 10³⁰⁸ an infinite
/// expectation and no plants at all).
pub const MAX_EXPECTED_PLANTS: f64 = 1e12;

/// Checks what the vegetation `rules` ask for over a terrain of `extent`
/// metres: at most [`MAX_EXPECTED_PLANTS`] before the cap (the error names
/// `vegetation.density`, the CLI's `--vegetation-density`), and the plants
/// the cap keeps within the host's memory (`vegetation.max_plants`).
fn check_plant_count(rules: &[ScatterRule], extent: DVec2, options: &VegetationOptions) -> Result<()> {
    let expected: f64 = rules.iter().map(|r| r.density * extent.x * extent.y).sum();
    if !(expected.is_finite() && expected <= MAX_EXPECTED_PLANTS) {
        return Err(Error::invalid(
            "vegetation.density",
            format!(
                "{:e} asks for about {expected:.3e} plants over the {:.0} m × {:.0} m terrain; at most {MAX_EXPECTED_PLANTS:e} (the cap then keeps {})",
                options.density, extent.x, extent.y, options.max_plants
            ),
        ));
    }
    let plants = (expected.ceil() as usize).min(options.max_plants);
    // Per kept plant: its instance and the scatter's placements (up to
    // `CANDIDATES_PER_PLANT` accepted before the cap, 48 B each).
    let per_plant = INSTANCE_PEAK_BYTES + 4 * 48;
    MemoryLimits::host_only().check(
        "vegetation.max_plants",
        &format!("{plants} plants"),
        Footprint::per_item(plants as u64, per_plant, 0),
    )
}

/// A terrain scene.
#[derive(Clone, Debug)]
pub struct Scene {
    pub heights: HeightField,
    /// Whether the terrain is drawn (false: point objects against the sky).
    pub draw_terrain: bool,
    /// Point objects (sequential point trees) and their instances.
    pub points: PointScene,
    /// Unit direction towards the sun.
    pub sun_direction: Vec3,
    /// The surface-layer tree of §8.2 (atlas and direct texturing).
    pub layers: crate::surface::layers::LayerTree,
    /// Extra input maps of the layer tree (rainfall, radiation, temperature;
    /// [`crate::surface::layers::INPUT_NAMES`]), registered to the height
    /// field: each grid spans the terrain rectangle corner to corner, at any
    /// resolution (its spacing is ignored); values in the units the layers'
    /// hats use.
    pub input_maps: [Option<HeightField>; 3],
    /// Where detail finer than `heights` streams from near the camera
    /// (a height pyramid's finer levels, [`crate::terrain::detail`]).
    pub detail: Option<DetailSource>,
}

impl Scene {
    /// The default scene: 513² samples of the default procedural terrain at
    /// 20 m spacing (10.24 km square), with [`DEFAULT_ROCKS`] boulders and
    /// the plants of the built-in layer tree ([`Scene::add_vegetation`]).
    pub fn default_procedural() -> Result<Scene> {
        let mut scene = Scene::default_terrain()?;
        scene.add_rocks(DEFAULT_ROCKS.2)?;
        scene.add_vegetation(&VegetationOptions::default())?;
        Ok(scene)
    }

    /// The default terrain without rocks.
    pub fn default_terrain() -> Result<Scene> {
        let heights = ProceduralTerrain::default().try_generate(513, 513, DVec2::splat(20.0))?;
        Ok(Scene::new(heights))
    }

    /// Scatters `count` procedural boulders (§6.1.4; [`DEFAULT_ROCKS`]
    /// shapes and samples, 1–40 m) over the terrain, as instances of a few
    /// trees built for a one-pixel error at 50° and 720 rows.
    ///
    /// Errors, before anything is built, when `count` boulders do not fit
    /// the host's memory (`rocks_footprint`); the parameter is `rocks`.
    pub fn add_rocks(&mut self, count: usize) -> Result<()> {
        MemoryLimits::host_only().check("rocks", &format!("{count} boulders"), rocks_footprint(count))?;
        let spt = SptOptions {
            epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), 720)?,
            ..SptOptions::default()
        };
        let (shapes, samples, _) = DEFAULT_ROCKS;
        let rocks = scatter_rocks(&self.heights, shapes, samples, count, (3.0, 16.0), 0xA1BE, &spt)?;
        self.points.append(rocks);
        Ok(())
    }

    /// Plants of the layer tree's `vegetation` tables (§8.2 layers,
    /// chapter 10 point trees; `crate::points::vegetation`): scattered
    /// over the terrain where their layer shows, as the CPU twin of the
    /// layer evaluation (`ReferenceSurface`, full detail, the default
    /// terrain noise seed) says, standing on [`Scene::ground`] with the
    /// default terrain settings. Set the layers and input maps first.
    /// Warns when the cap thinned them.
    pub fn add_vegetation(&mut self, options: &VegetationOptions) -> Result<VegetationReport> {
        options.validate()?;
        let rules: Vec<ScatterRule> = (self.layers.layers.iter().enumerate())
            .flat_map(|(source, flat)| {
                flat.layer.vegetation.iter().map(move |v| ScatterRule {
                    model: v.model,
                    density: v.density * options.density,
                    scale: v.scale,
                    source,
                })
            })
            .collect();
        if rules.is_empty() {
            return Ok(VegetationReport::default());
        }
        check_plant_count(&rules, self.heights.extent(), options)?;
        let terrain = TerrainSettings::default();
        let reference = ReferenceSurface::new(&self.heights, &self.layers, &self.input_maps, terrain.noise_seed)?;
        let shares = |xy| Ok(subtree_shares(&self.layers, &reference.evaluate(xy, 0.0).coverage));
        let placed = scatter(&rules, self.heights.extent(), options.seed, options.max_plants, &shares)?;
        if placed.thinned > 0 {
            log::warn!(
                "vegetation: {} of about {} plants left out (at most {}; lower the density)",
                placed.thinned,
                placed.thinned + placed.placements.len(),
                options.max_plants
            );
        }
        let ground = self.ground(&terrain)?;
        let (plants, report) = plant_scene(&rules, &placed, &mut |xy| ground.height(xy.x, xy.y), options)?;
        self.points.append(plants);
        Ok(report)
    }

    /// The default lighting of the scene: its sun, a snow line at 80 % of
    /// its height range, the rest [`Lighting::default`].
    pub fn default_lighting(&self) -> Lighting {
        let (lo, hi) = self.height_range();
        Lighting {
            sun: SunPosition::Direction(self.sun_direction),
            snow_line: lo + (hi - lo) * 0.8,
            ..Lighting::default()
        }
    }

    /// A scene of the height pyramid `pyramid`: its finest level with at
    /// most `max_side` samples a side ([`HeightPyramid::level_within`])
    /// becomes the terrain's sketch atlas in memory (§7.4.4: "a large
    /// sketch atlas in main memory"), so memory is bounded by `max_side`,
    /// not by the field (a 65536² field at `max_side` 4096 holds level 4,
    /// 4097², over the field's whole extent).
    pub fn from_pyramid(pyramid: &HeightPyramid, max_side: u32) -> Result<Scene> {
        if !(2..=16384).contains(&max_side) {
            return Err(Error::invalid(
                "resident side",
                format!("{max_side} samples (must be within 2..=16384)"),
            ));
        }
        let level = pyramid.level_within(max_side);
        let field = pyramid.level_field(level)?;
        log::info!(
            "{}: level {level} of {} ({}×{} samples, {:.2}×{:.2} m) resident",
            pyramid.path().display(),
            pyramid.levels(),
            field.columns,
            field.rows,
            field.spacing.x,
            field.spacing.y
        );
        field.validate(pyramid.path())?;
        let detail = DetailSource {
            path: pyramid.path().to_path_buf(),
            resident_level: level,
            window: DEFAULT_DETAIL_WINDOW,
            wait: true,
        };
        Ok(Scene {
            detail: Some(detail),
            ..Scene::new(field)
        })
    }

    /// Sets the detail window of a scene from a height pyramid
    /// ([`crate::terrain::detail`]): `side` samples a side (0: none, at
    /// most [`MAX_DETAIL_WINDOW`], rounded up to whole tiles); `wait`: frames wait
    /// for its tiles (deterministic), else they draw the resident level
    /// until the tiles arrive. Nothing for other scenes.
    pub fn set_detail_window(&mut self, side: u32, wait: bool) -> Result<()> {
        if side > MAX_DETAIL_WINDOW {
            return Err(Error::invalid(
                "detail window",
                format!("{side} samples (at most {MAX_DETAIL_WINDOW})"),
            ));
        }
        if let Some(detail) = &mut self.detail {
            detail.window = side;
            detail.wait = wait;
        }
        Ok(())
    }

    /// A scene of `heights` with the default sun and no point objects.
    pub fn new(heights: HeightField) -> Scene {
        Scene {
            heights,
            draw_terrain: true,
            points: PointScene::default(),
            sun_direction: Vec3::new(-0.55, 0.45, 0.42).normalize(),
            layers: crate::surface::layers::LayerTree::default_tree(),
            input_maps: [None, None, None],
            detail: None,
        }
    }

    /// Point objects against the sky, without terrain (a flat 2×2 field
    /// stands in for the height field).
    pub fn points_only(points: PointScene) -> Scene {
        let heights = HeightField {
            columns: 2,
            rows: 2,
            spacing: DVec2::ONE,
            heights: vec![0.0; 4],
        };
        Scene {
            draw_terrain: false,
            points,
            ..Scene::new(heights)
        }
    }

    /// Height range in metres.
    pub fn height_range(&self) -> (f32, f32) {
        self.heights.min_max()
    }

    /// Height (metres) of the ground at world `(x, y)` as the terrain is
    /// drawn with the default [`TerrainSettings`]: the B-spline with its
    /// procedural detail at the finest level (`crate::terrain::ground`
    /// says how far a drawn view may differ). On a scene streamed from a
    /// height pyramid with a detail window, the B-spline of the pyramid's
    /// finest level, whose real samples replace the octaves they cover
    /// ([`Scene::streamed_ground`]). Errors, naming the point, outside the
    /// terrain. Each call builds the noise tile (a few milliseconds; a
    /// query on a built [`Ground`] takes about a microsecond): for many
    /// queries or other settings use [`Scene::ground`] or
    /// [`Scene::streamed_ground`].
    pub fn ground_height(&self, x: f64, y: f64) -> Result<f64> {
        let terrain = TerrainSettings::default();
        match self.streamed_ground(&terrain)? {
            Some(mut streamed) => streamed.height(x, y),
            None => self.ground(&terrain)?.height(x, y),
        }
    }

    /// Unit upward normal of [`Scene::ground_height`]'s surface at `(x, y)`.
    pub fn ground_normal(&self, x: f64, y: f64) -> Result<DVec3> {
        let terrain = TerrainSettings::default();
        match self.streamed_ground(&terrain)? {
            Some(mut streamed) => streamed.normal(x, y),
            None => self.ground(&terrain)?.normal(x, y),
        }
    }

    /// The ground of the resident field as drawn with `terrain` (the
    /// renderer's [`crate::renderer::RenderSettings::terrain`]), for
    /// repeated queries. Where the scene streams detail
    /// ([`Scene::streamed_ground`] is `Some`), the drawn ground near the
    /// camera is that one.
    pub fn ground(&self, terrain: &TerrainSettings) -> Result<Ground<'_>> {
        Ground::new(&self.heights, terrain)
    }

    /// The ground of a scene streamed from a height pyramid with a detail
    /// window (issue 31 item 1): the pyramid's finest level read tile by
    /// tile through a small cache, with the detail octaves finer than its
    /// spacing ([`StreamedGround`]). `None` for other scenes, for a window
    /// of 0, or when the resident level is already the finest.
    pub fn streamed_ground(&self, terrain: &TerrainSettings) -> Result<Option<StreamedGround<'_>>> {
        match &self.detail {
            Some(source) if source.window > 0 && source.resident_level > 0 => {
                StreamedGround::open(&self.heights, terrain, source).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// A camera that shows the whole terrain: from beyond its southern edge,
    /// above the highest point, looking at the centre
    /// ([`Camera::overview`]: valid for every legal height field).
    pub fn default_camera(&self) -> Camera {
        let (lo, hi) = self.height_range();
        Camera::overview(self.heights.extent(), f64::from(lo), f64::from(hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_scene() -> Scene {
        Scene::new(HeightField::from_fn(33, 33, DVec2::splat(10.0), |c, r| (c + r) as f32))
    }

    #[test]
    fn boulders_are_bounded_before_they_are_built() {
        // The instance is 72 B; a boulder about 1.9 kB at a render's peak,
        // so 10⁸ of them about 177 GiB.
        assert_eq!(INSTANCE_HOST_BYTES, 2 * 72 + 16);
        const { assert!(INSTANCE_PEAK_BYTES > INSTANCE_HOST_BYTES + 2 * 96) };
        assert_eq!(rocks_footprint(100_000_000).host, 190_000_000_000);
        let mut scene = small_scene();
        let e = scene.add_rocks(usize::MAX / 256).unwrap_err();
        assert_eq!(e.parameter(), Some("rocks"));
        assert!(e.to_string().contains("boulders need about"), "{e}");
        assert!(scene.points.is_empty());
        scene.add_rocks(3).unwrap();
        assert_eq!(scene.points.instances.len(), 3);
    }

    #[test]
    fn absurd_vegetation_densities_are_refused_by_name() {
        for density in [1e300, 1e308, f64::MAX] {
            let mut scene = small_scene();
            let options = VegetationOptions {
                density,
                ..VegetationOptions::default()
            };
            let e = scene.add_vegetation(&options).unwrap_err();
            assert_eq!(e.parameter(), Some("vegetation.density"), "{e}");
            assert!(e.to_string().contains("plants over the 320 m × 320 m terrain"), "{e}");
            assert!(scene.points.is_empty());
        }
    }
}
