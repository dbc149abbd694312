//! The CPU half of geometry image warping per frame (dissertation §7.4,
//! Fig. 7.8; `ALGORITHMS.md` §3 items 2–4): sketch map → importance map →
//! warp. Its result, the warping function `Φ` sampled on the sketch grid, is
//! what the GPU's warp-and-zoom pass ([`crate::terrain::geometry_image`])
//! interpolates up to the output grid.
//!
//! # World-anchored plans (§7.4.3, §7.4.5: swimming)
//!
//! The importance of eq. 7.4 is `C / dist` from the eye: scale-free, so a
//! plan made for every frame's own eye slides every vertex over the surface
//! at about the camera's speed, and the interpolation error under each
//! pixel changes all the time ("the vertices of the warped grid slide over
//! the surface as the camera moves"). With [`LodSettings::snap`] `> 0` the
//! plan is made for the eye snapped to a world grid of spacing `G` (the
//! camera translated by the snap offset, its orientation kept) and made
//! again only when the snapped eye changes: between such replans the mesh
//! is world-static and does not swim at all; at a replan every vertex
//! jumps once. Sliding over a distance `S` costs about `S / cell` times
//! the peak-to-peak interpolation error per pixel, the jump at most that
//! error once, so a grid coarser than the far field's cells (where the
//! swimming is, at distant silhouettes) cuts the mean per-frame change by
//! about `cell / G` (`docs/PERFORMANCE.md`, "Swimming"). The real eye is
//! somewhere in the grid cell around the planned one (a cube of side `G`,
//! up to `reach = G·√3/2` away): the sketch region grows by `reach` on
//! every side and the frustum factor's planes move `reach` outwards, so
//! everything the real camera sees stays covered. The distance term
//! near the real eye is then off by up to `reach` (its `min_distance` of
//! one sketch texel limits that).
//!
//! # Height-adaptive grid
//!
//! A grid of one whole-terrain sketch texel ([`ANCHORED_SNAP`]; 80 m on the
//! default terrain, 250 m on the Jacksboro DEM) is right for a flying eye
//! but not for one walking 2 m above the ground: planned for an eye up to
//! `0.87 G` away (possibly under the ground, the eye's height is snapped
//! too), the mesh under it is coarser and can rise above the real eye. So
//! [`LodSettings::snap`] is the coarsest grid, halved until `G` is at most
//! [`HEIGHT_FACTOR`] × the eye's height above the ground under it
//! ([`LodSettings::anchor`]): a walking eye gets a grid of a few metres,
//! almost the per-frame plan of the text (and about its swimming), a
//! flying eye the anchored plan. The level of the grid keeps to the last
//! frame's while the height allows it and is less than four times that
//! grid (hysteresis: changing the level replans). Measured in
//! `docs/PERFORMANCE.md` ("Swimming"); on by default ([`DEFAULT_SNAP`]),
//! `--lod-snap 0` plans for every frame's eye. Only translation is
//! anchored: a camera that turns, or changes its field of view, is planned
//! again every frame.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::surface::bspline::sample_bspline;
use crate::terrain::importance::{importance_map, smoothstep, Backface, Frustum, ImportanceParams};
use crate::terrain::sketch_map::{SketchAlignment, SketchMap, DEFAULT_SKETCH_SIDE};
use crate::terrain::warp::{bilinear, density_ratio, warp_into, PassOrder, WarpOptions, WarpResult};
use crate::view::Camera;

/// How the output grid is placed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LodMode {
    /// Warped by the importance map (§7.4).
    #[default]
    Warped,
    /// A regular grid over the sketch map with the same vertex count (for
    /// comparison).
    Uniform,
}

/// Which factors of the importance map (eq. 7.4) are on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImportanceFactors {
    pub distance: bool,
    pub frustum: bool,
    pub backface: bool,
    pub surface: bool,
}

impl Default for ImportanceFactors {
    fn default() -> Self {
        Self {
            distance: true,
            frustum: true,
            backface: true,
            surface: true,
        }
    }
}

/// Per-texel scalar carried to the vertices for the debug views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugScalar {
    #[default]
    None,
    /// The importance map, divided by its maximum.
    Importance,
    /// Obtained over demanded sample density (Fig. 7.12).
    DensityRatio,
}

/// Settings of the CPU stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    /// Sketch map side in texels (default 128).
    pub sketch_side: usize,
    pub mode: LodMode,
    pub factors: ImportanceFactors,
    pub alignment: SketchAlignment,
    /// Spacing of the coarsest world grid the plan's eye is snapped to, in
    /// sketch texels of a map over the whole terrain (`extent / (side −
    /// 1)`), halved for an eye near the ground; 0: the plan follows the eye
    /// every frame (the text). See the module documentation.
    pub snap: f64,
}

/// Default [`LodSettings::snap`]: the anchored plan with a grid of one
/// whole-terrain sketch texel at most, finer for an eye near the ground
/// ([`HEIGHT_FACTOR`]; module documentation).
pub const DEFAULT_SNAP: f64 = ANCHORED_SNAP;
/// The coarsest snap that cuts the swimming 5–8× and keeps the density of
/// Fig. 7.12 (`docs/PERFORMANCE.md`, "Swimming"): one whole-terrain
/// sketch texel.
pub const ANCHORED_SNAP: f64 = 1.0;
/// The snap grid is at most this many times the eye's height above the
/// ground ([`LodSettings::anchor`]): snapping moves the eye's height by at
/// most `G / 2`, so the planned eye is no lower than the ground under the
/// real one, and the near field of an eye near the ground is planned
/// within about its height of the real eye (measured against 1 and 4 in
/// `docs/PERFORMANCE.md`, "Swimming").
pub const HEIGHT_FACTOR: f64 = 2.0;
/// Most halvings of the coarsest snap grid for a low eye; an eye lower
/// still is planned every frame (a grid of 1/2¹⁶ of a sketch texel, a few
/// millimetres, anchors nothing).
pub const MAX_SNAP_LEVEL: u32 = 16;
/// Largest [`LodSettings::snap`] (a grid that coarse anchors the plan to
/// one point of the terrain).
pub const MAX_SNAP: f64 = 1024.0;

impl Default for LodSettings {
    fn default() -> Self {
        Self {
            sketch_side: DEFAULT_SKETCH_SIDE,
            mode: LodMode::Warped,
            factors: ImportanceFactors::default(),
            alignment: SketchAlignment::View,
            snap: DEFAULT_SNAP,
        }
    }
}

/// The grid a plan's eye is snapped to ([`LodSettings::anchor`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    /// The camera the plan is made for: the real one moved so that its eye
    /// sits on the grid (the real one itself without snapping).
    pub camera: Camera,
    /// The grid's spacing `G` in metres (0: no snapping).
    pub spacing: f64,
    /// How many times the coarsest grid ([`LodSettings::snap`]) was halved
    /// for the eye's height above the ground (None: no snapping).
    pub level: Option<u32>,
}

impl Anchor {
    /// Half the grid spacing: the real eye is in the cube of this half-size
    /// around the planned one.
    pub fn cell(&self) -> f64 {
        0.5 * self.spacing
    }
}

impl LodSettings {
    /// The grid the plan's eye snaps to for `camera` and the camera moved
    /// onto it (module documentation, "Height-adaptive grid"): the coarsest
    /// grid of [`LodSettings::snap`] sketch texels, halved until it is at
    /// most [`HEIGHT_FACTOR`] × the eye's height above the B-spline ground
    /// under it; `previous`, the level of the last frame's grid, is kept
    /// while that grid is neither too coarse for the height nor four times
    /// finer than it allows (hysteresis: a height that hovers about a
    /// threshold does not replan every frame). No snapping with a snap of 0,
    /// an eye at or under the ground, or a grid finer than
    /// [`MAX_SNAP_LEVEL`] halvings.
    pub fn anchor(&self, field: &HeightField, camera: &Camera, previous: Option<u32>) -> Result<Anchor> {
        if !(self.snap.is_finite() && (0.0..=MAX_SNAP).contains(&self.snap)) {
            return Err(Error::invalid(
                "terrain.lod.snap",
                format!("{} sketch texels (must be in 0..={MAX_SNAP})", self.snap),
            ));
        }
        let unsnapped = Anchor {
            camera: *camera,
            spacing: 0.0,
            level: None,
        };
        if self.snap == 0.0 {
            return Ok(unsnapped);
        }
        let coarsest = self.snap * field.extent().max_element() / (self.sketch_side.max(2) - 1) as f64;
        let height = camera.eye.z - sample_bspline(field, camera.eye.x, camera.eye.y);
        let allowed = HEIGHT_FACTOR * height;
        if !(allowed > 0.0 && allowed.is_finite()) {
            return Ok(unsnapped);
        }
        let grid = |level: u32| coarsest / f64::from(1u32 << level.min(31));
        let keep =
            previous.filter(|&p| p <= MAX_SNAP_LEVEL && grid(p) <= allowed && (p == 0 || grid(p) > 0.25 * allowed));
        let level = match keep {
            Some(p) => p,
            None => (coarsest / allowed).log2().ceil().max(0.0) as u32,
        };
        if level > MAX_SNAP_LEVEL {
            return Ok(unsnapped);
        }
        let spacing = grid(level);
        let eye = (camera.eye / spacing).round() * spacing;
        let moved = Camera {
            eye,
            target: camera.target + (eye - camera.eye),
            ..*camera
        };
        Ok(Anchor {
            camera: moved,
            spacing,
            level: Some(level),
        })
    }
}

/// What a plan depends on: the same key gives the same plan.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlanKey {
    camera: Camera,
    /// The snap grid's spacing (the region's margin depends on it).
    spacing: f64,
    aspect: f64,
    settings: LodSettings,
    debug: DebugScalar,
    /// The field's sample counts and spacing.
    field: (u32, u32, DVec2),
}

/// The result of one frame's CPU stage.
#[derive(Clone, Debug, Default)]
pub struct LodFrame {
    pub sketch: Option<SketchMap>,
    /// Empty for a uniform grid without a debug view that needs it.
    pub importance: Vec<f64>,
    pub warp: WarpResult,
    /// Per sketch texel `(Φx, Φy, debug scalar, 0)`, what the GPU reads.
    pub upload: Vec<[f32; 4]>,
    /// What the current plan was made for (None: no plan yet).
    key: Option<PlanKey>,
    /// The level of the last frame's snap grid ([`LodSettings::anchor`]).
    snap_level: Option<u32>,
}

/// The per-type upper bound `I_s` of eq. 7.4. Surface type here is the
/// local roughness of the sketch map: the deviation of a texel's height
/// from the mean of its four neighbours, relative to the texel size (0 on
/// planes and smooth slopes). Smooth ground gets at most 20 % of the map's
/// largest view-distance importance `max I_v`, rough ground is effectively
/// unbounded; texels outside the terrain get 0 (lifted to the importance
/// floor).
fn surface_bound(sketch: &SketchMap, max_distance_importance: f64) -> Vec<f64> {
    let n = sketch.n;
    let g = &sketch.geometry;
    let texel = (sketch.region.side_s.length() / (n - 1) as f64)
        .min(sketch.region.side_t.length() / (n - 1) as f64)
        .max(1e-9);
    (0..n * n)
        .map(|k| {
            if sketch.outside[k] {
                return 0.0;
            }
            let (r, c) = (k / n, k % n);
            let h = |r: usize, c: usize| g[r * n + c].z;
            let mean = 0.25
                * (h(r, c.saturating_sub(1))
                    + h(r, (c + 1).min(n - 1))
                    + h(r.saturating_sub(1), c)
                    + h((r + 1).min(n - 1), c));
            let roughness = (h(r, c) - mean).abs() / texel;
            max_distance_importance * (0.2 + 0.8 * smoothstep(0.0, 0.05, roughness))
        })
        .collect()
}

/// The importance map of eq. 7.4 on `sketch` for `camera`, with the
/// factors `f` on, for any eye in the cube of half-size `cell` around
/// `camera.eye`: the frustum factor's planes move out by the cube's reach
/// `√3·cell` ([`Frustum::widened`]); distances are measured from
/// `camera.eye` (measuring them to the cube, so that the ground near any
/// eye in it gets the full near-field density, spreads that density over
/// the cube and made the mesh less accurate, not more).
pub(crate) fn sketch_importance(
    sketch: &SketchMap,
    camera: &Camera,
    (aspect, cell): (f64, f64),
    f: ImportanceFactors,
) -> Result<Vec<f64>> {
    let slack = 3f64.sqrt() * cell;
    let n = sketch.n;
    let texel = (sketch.region.side_s.length().max(sketch.region.side_t.length()) / (n - 1) as f64).max(1e-6);
    let frustum = if f.frustum {
        Some(
            Frustum::perspective(
                camera.eye,
                camera.forward(),
                camera.up,
                camera.fov_y_deg.to_radians(),
                aspect,
                2.0 * texel,
            )?
            .widened(slack),
        )
    } else {
        None
    };
    let mut params = ImportanceParams {
        min_distance: texel,
        distance: f.distance,
        frustum,
        backface: f.backface.then(Backface::default),
        ..Default::default()
    };
    if f.surface {
        // The largest view-distance importance over the map: the scale of the bound.
        let max = if f.distance {
            let nearest = sketch
                .geometry
                .iter()
                .map(|p| p.distance(camera.eye))
                .fold(f64::INFINITY, f64::min);
            params.c / nearest.max(params.min_distance)
        } else {
            params.c
        };
        params.surface_bound = Some(surface_bound(sketch, max));
    }
    importance_map(&sketch.geometry, n, camera.eye, &params)
}

impl LodFrame {
    /// Forgets what the current plan was made for: the next
    /// [`LodFrame::plan`] plans again (benchmarks of the CPU stage).
    pub fn invalidate(&mut self) {
        self.key = None;
    }

    /// Runs sketch map, importance map and warp for `camera` into `self`
    /// (buffers reused from frame to frame); with [`LodSettings::snap`] for
    /// the anchored camera, and nothing at all while that and the other
    /// inputs are those of the current plan (module documentation).
    pub fn plan(
        &mut self,
        field: &HeightField,
        camera: &Camera,
        aspect: f64,
        settings: &LodSettings,
        debug: DebugScalar,
    ) -> Result<()> {
        let n = settings.sketch_side;
        if !(4..=1024).contains(&n) {
            return Err(Error::invalid("sketch map size", format!("{n} (must be 4..=1024)")));
        }
        let anchor = settings.anchor(field, camera, self.snap_level)?;
        self.snap_level = anchor.level;
        let (anchored, cell) = (anchor.camera, anchor.cell());
        let key = PlanKey {
            camera: anchored,
            spacing: anchor.spacing,
            aspect,
            settings: *settings,
            debug,
            field: (field.columns, field.rows, field.spacing),
        };
        if self.key == Some(key) {
            return Ok(());
        }
        self.key = None;
        let camera = &anchored;
        let reach = 3f64.sqrt() * cell;
        let sketch = SketchMap::for_view_with_margin(field, camera, aspect, (settings.alignment, reach), n)?;
        // A uniform grid needs the importance map only for the debug views.
        let importance = if settings.mode == LodMode::Warped || debug != DebugScalar::None {
            sketch_importance(&sketch, camera, (aspect, cell), settings.factors)?
        } else {
            Vec::new()
        };
        if settings.mode == LodMode::Uniform {
            self.warp.positions.clone_from(&sketch.geometry);
        } else {
            let order = match settings.alignment {
                SketchAlignment::View => PassOrder::RowsFirst,
                SketchAlignment::Axes => PassOrder::for_view(camera.forward()),
            };
            let options = WarpOptions {
                order,
                ..Default::default()
            };
            warp_into(&sketch.geometry, &importance, n, options, &mut self.warp)?;
        }
        let scalar: Vec<f64> = match debug {
            DebugScalar::None => Vec::new(),
            DebugScalar::Importance => {
                let max = importance.iter().copied().fold(0.0, f64::max).max(1e-30);
                // Importance at the warped positions: bilinear in the sketch frame.
                let at = |p: &DVec3| bilinear(&importance, n, sketch.region.grid_coord(p.truncate(), n));
                self.warp.positions.iter().map(|p| at(p) / max).collect()
            }
            DebugScalar::DensityRatio => {
                density_ratio(&self.warp.positions, &sketch.geometry, &importance, n)?.combined
            }
        };
        self.upload.clear();
        self.upload.extend(self.warp.positions.iter().enumerate().map(|(k, p)| {
            [
                p.x as f32,
                p.y as f32,
                scalar.get(k).copied().unwrap_or(0.0) as f32,
                0.0,
            ]
        }));
        self.importance = importance;
        self.sketch = Some(sketch);
        self.key = Some(key);
        Ok(())
    }
}
