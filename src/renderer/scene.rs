//! What is drawn: a height field, point objects and a sun. The built-in
//! default scene is a procedural ridged-multifractal terrain (§6.1) with
//! procedural rocks (§6.1.4) and plants (chapter 10, Fig. 10.12) scattered
//! over it, under a low afternoon sun.

use glam::{DVec2, DVec3, Vec3};

use crate::error::Result;
use crate::io::heightmap::HeightField;
use crate::points::build::plants::scatter::{scatter, ScatterRule};
use crate::points::build::spt::{epsilon_from_pixels, SptOptions};
use crate::points::scene::{scatter_rocks, PointScene};
use crate::points::vegetation::{plant_scene, VegetationOptions, VegetationReport};
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::ground::Ground;
use crate::terrain::procedural::ProceduralTerrain;
use crate::texturing::layers::vegetation::subtree_shares;
use crate::texturing::reference::ReferenceSurface;
use crate::view::camera::Camera;
use crate::view::{Lighting, SunPosition};

/// Rocks of the default scene: distinct shapes, surfels per shape, instances.
pub const DEFAULT_ROCKS: (usize, usize, usize) = (4, 4000, 300);

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
    pub layers: crate::texturing::layers::LayerTree,
    /// Extra input maps of the layer tree (rainfall, radiation, temperature;
    /// [`crate::texturing::layers::INPUT_NAMES`]), registered to the height
    /// field: each grid spans the terrain rectangle corner to corner, at any
    /// resolution (its spacing is ignored); values in the units the layers'
    /// hats use.
    pub input_maps: [Option<HeightField>; 3],
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
    pub fn add_rocks(&mut self, count: usize) -> Result<()> {
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
    /// chapter 10 point trees; [`crate::points::vegetation`]): scattered
    /// over the terrain where their layer shows, as the CPU twin of the
    /// layer evaluation ([`ReferenceSurface`], full detail, the default
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

    /// A scene of `heights` with the default sun and no point objects.
    pub fn new(heights: HeightField) -> Scene {
        Scene {
            heights,
            draw_terrain: true,
            points: PointScene::default(),
            sun_direction: Vec3::new(-0.55, 0.45, 0.42).normalize(),
            layers: crate::texturing::layers::LayerTree::default_tree(),
            input_maps: [None, None, None],
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
    /// procedural detail at the finest level ([`crate::terrain::ground`]
    /// says how far a drawn view may differ). Errors, naming the point,
    /// outside the terrain. Each call builds the noise tile (a few
    /// milliseconds; a query on a built [`Ground`] takes about a
    /// microsecond): for many queries or other settings use [`Scene::ground`].
    pub fn ground_height(&self, x: f64, y: f64) -> Result<f64> {
        self.ground(&TerrainSettings::default())?.height(x, y)
    }

    /// Unit upward normal of [`Scene::ground_height`]'s surface at `(x, y)`.
    pub fn ground_normal(&self, x: f64, y: f64) -> Result<DVec3> {
        self.ground(&TerrainSettings::default())?.normal(x, y)
    }

    /// The ground as drawn with `terrain` (the renderer's
    /// [`crate::renderer::RenderSettings::terrain`]), for repeated queries.
    pub fn ground(&self, terrain: &TerrainSettings) -> Result<Ground<'_>> {
        Ground::new(&self.heights, terrain)
    }

    /// A camera that shows the whole terrain: from beyond its southern edge,
    /// above the highest point, looking at the centre
    /// ([`Camera::overview`]: valid for every legal height field).
    pub fn default_camera(&self) -> Camera {
        let (lo, hi) = self.height_range();
        Camera::overview(self.heights.extent(), f64::from(lo), f64::from(hi))
    }
}
