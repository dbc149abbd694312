//! The CPU half of geometry image warping per frame (dissertation §7.4,
//! Fig. 7.8; `ALGORITHMS.md` §3 items 2–4): sketch map → importance map →
//! warp. Its result, the warping function `Φ` sampled on the sketch grid, is
//! what the GPU's warp-and-zoom pass ([`crate::terrain::geometry_image`])
//! interpolates up to the output grid.

use glam::DVec3;

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
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
}

impl Default for LodSettings {
    fn default() -> Self {
        Self {
            sketch_side: DEFAULT_SKETCH_SIDE,
            mode: LodMode::Warped,
            factors: ImportanceFactors::default(),
            alignment: SketchAlignment::View,
        }
    }
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
/// factors `f` on.
fn sketch_importance(sketch: &SketchMap, camera: &Camera, aspect: f64, f: ImportanceFactors) -> Result<Vec<f64>> {
    let n = sketch.n;
    let texel = (sketch.region.side_s.length().max(sketch.region.side_t.length()) / (n - 1) as f64).max(1e-6);
    let frustum = if f.frustum {
        Some(Frustum::perspective(
            camera.eye,
            camera.forward(),
            camera.up,
            camera.fov_y_deg.to_radians(),
            aspect,
            2.0 * texel,
        )?)
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
    /// Runs sketch map, importance map and warp for `camera` into `self`
    /// (buffers reused from frame to frame).
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
        let sketch = SketchMap::for_view(field, camera, aspect, settings.alignment, n)?;
        // A uniform grid needs the importance map only for the debug views.
        let importance = if settings.mode == LodMode::Warped || debug != DebugScalar::None {
            sketch_importance(&sketch, camera, aspect, settings.factors)?
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
        Ok(())
    }
}
