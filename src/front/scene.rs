//! The front door's scene constructors: a height field from a slice, a
//! file or a procedural model (the three ways a caller brings terrain).

use std::path::Path;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::io::heightmap::{check_spacing, load_heightmap, HeightField, HeightmapOptions, MAX_ABS_HEIGHT};
use crate::renderer::Scene;
use crate::terrain::procedural::{ProceduralTerrain, TerrainModel};

/// Largest grid side of [`Scene::procedural`] (and of the CLI's
/// `--terrain procedural:…,size=N`), in samples.
pub const MAX_PROCEDURAL_SIZE: u32 = 8193;

impl Scene {
    /// A scene of the height field `heights`: `columns × rows` samples in
    /// metres, row-major (row `r`, column `c` at `r·columns + c`), row 0 at
    /// y = 0 (the southern edge; +y is north), `spacing` = (dx, dy) metres
    /// between samples.
    ///
    /// Errors, naming the parameter, when `heights` does not hold
    /// `columns·rows` samples, the grid is smaller than 2×2, a height is
    /// NaN, infinite or beyond ±1000 km (`heights`), or the spacing is out
    /// of range (`spacing`).
    ///
    /// ```no_run
    /// let heights = vec![0.0_f32; 64 * 48];
    /// let scene = alpenglow::Scene::from_heights(&heights, 64, 48, (10.0, 10.0))?;
    /// # Ok::<(), alpenglow::Error>(())
    /// ```
    pub fn from_heights(heights: &[f32], columns: u32, rows: u32, spacing: (f64, f64)) -> Result<Scene> {
        if columns < 2 || rows < 2 {
            return Err(Error::invalid(
                "heights",
                format!("a {columns}×{rows} grid; at least 2×2 samples are needed"),
            ));
        }
        let expected = u64::from(columns) * u64::from(rows);
        if heights.len() as u64 != expected {
            return Err(Error::invalid(
                "heights",
                format!(
                    "{} samples for a {columns}×{rows} grid (expected {expected})",
                    heights.len()
                ),
            ));
        }
        let spacing = DVec2::new(spacing.0, spacing.1);
        check_spacing(spacing).map_err(|m| Error::invalid("spacing", m))?;
        if let Some(i) = heights
            .iter()
            .position(|v| !(v.is_finite() && v.abs() <= MAX_ABS_HEIGHT))
        {
            let (c, r) = (i % columns as usize, i / columns as usize);
            return Err(Error::invalid(
                "heights",
                format!(
                    "the height at column {c}, row {r} is {}; heights must be finite and within ±{} km",
                    heights[i],
                    MAX_ABS_HEIGHT / 1000.0
                ),
            ));
        }
        Ok(Scene::new(HeightField {
            columns,
            rows,
            spacing,
            heights: heights.to_vec(),
        }))
    }

    /// A scene of the height map at `path` (PNG, 16-bit PNG, OpenEXR,
    /// GeoTIFF, SRTM `.hgt`: every format the CLI's `--heightmap` reads),
    /// scaled, offset and spaced as `options` say. Errors name the file.
    ///
    /// ```no_run
    /// use alpenglow::{HeightmapOptions, Scene};
    /// let scene = Scene::from_file("dem.tif", &HeightmapOptions::default())?;
    /// # Ok::<(), alpenglow::Error>(())
    /// ```
    pub fn from_file(path: impl AsRef<Path>, options: &HeightmapOptions) -> Result<Scene> {
        Ok(Scene::new(load_heightmap(path.as_ref(), options)?))
    }

    /// A scene streamed from the height pyramid at `path` (`.hpyr`, from
    /// `alpenglow dem import` or [`crate::files::write_pyramid`]): its
    /// finest level with at most `resident_side` samples a side stays in
    /// memory ([`Scene::from_pyramid`]), and a detail window of
    /// `detail_window` samples (0: none) of a finer level follows the
    /// camera; frames wait for the window's tiles (deterministic; see
    /// [`Scene::set_detail_window`]). Errors name the file or the option.
    ///
    /// ```no_run
    /// let scene = alpenglow::Scene::from_pyramid_file("region.hpyr", 4096, 1024)?;
    /// let z = scene.ground_height(1200.0, 800.0)?; // from the finest level
    /// # Ok::<(), alpenglow::Error>(())
    /// ```
    pub fn from_pyramid_file(path: impl AsRef<Path>, resident_side: u32, detail_window: u32) -> Result<Scene> {
        let pyramid = crate::io::pyramid::HeightPyramid::open(path.as_ref())?;
        let mut scene = Scene::from_pyramid(&pyramid, resident_side)?;
        scene.set_detail_window(detail_window, true)?;
        Ok(scene)
    }

    /// A scene of a procedural terrain: `model` (one of
    /// [`TerrainModel::ALL`]'s names: `fbm`, `multifractal`,
    /// `heterogeneous`, `hybrid`, `ridged`) with `seed` and the other
    /// parameters at [`ProceduralTerrain::default`], sampled on a
    /// `size × size` grid (2..=[`MAX_PROCEDURAL_SIZE`]) `spacing` metres
    /// apart. For every parameter, build a [`ProceduralTerrain`] and call
    /// [`Scene::from_terrain`].
    ///
    /// ```no_run
    /// let scene = alpenglow::Scene::procedural("ridged", 7, 513, 20.0)?;
    /// # Ok::<(), alpenglow::Error>(())
    /// ```
    pub fn procedural(model: &str, seed: u32, size: u32, spacing: f64) -> Result<Scene> {
        let model = TerrainModel::from_name(model).ok_or_else(|| {
            let names = TerrainModel::ALL.map(TerrainModel::name).join(", ");
            Error::invalid("model", format!("unknown model '{model}' (models: {names})"))
        })?;
        let terrain = ProceduralTerrain {
            model,
            seed: u64::from(seed),
            ..ProceduralTerrain::default()
        };
        Scene::from_terrain(&terrain, (size, size), (spacing, spacing))
    }

    /// A scene of `terrain` sampled on a `columns × rows` grid
    /// (`size`, each side 2..=[`MAX_PROCEDURAL_SIZE`]) with `spacing` =
    /// (dx, dy) metres between samples. Errors name the bad parameter.
    pub fn from_terrain(terrain: &ProceduralTerrain, size: (u32, u32), spacing: (f64, f64)) -> Result<Scene> {
        terrain.validate()?;
        for v in [size.0, size.1] {
            if !(2..=MAX_PROCEDURAL_SIZE).contains(&v) {
                return Err(Error::invalid(
                    "size",
                    format!("{v} samples (must be in 2..={MAX_PROCEDURAL_SIZE})"),
                ));
            }
        }
        let spacing = DVec2::new(spacing.0, spacing.1);
        check_spacing(spacing).map_err(|m| Error::invalid("spacing", m))?;
        Ok(Scene::new(terrain.try_generate(size.0, size.1, spacing)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(e: Error) -> String {
        e.to_string()
    }

    #[test]
    fn from_heights_keeps_row_zero_at_y_zero() {
        let heights: Vec<f32> = (0..6).map(|i| i as f32).collect();
        let scene = Scene::from_heights(&heights, 3, 2, (2.0, 5.0)).unwrap();
        assert_eq!((scene.heights.columns, scene.heights.rows), (3, 2));
        assert_eq!(scene.heights.height(2, 0), 2.0);
        assert_eq!(scene.heights.height(0, 1), 3.0);
        assert_eq!(scene.heights.spacing, DVec2::new(2.0, 5.0));
    }

    #[test]
    fn from_heights_refuses_bad_input_naming_the_parameter() {
        let mut heights = vec![0.0_f32; 6];
        heights[4] = f32::NAN;
        let e = message(Scene::from_heights(&heights, 3, 2, (1.0, 1.0)).unwrap_err());
        assert!(e.contains("heights") && e.contains("column 1, row 1"), "{e}");
        heights[4] = f32::INFINITY;
        assert!(message(Scene::from_heights(&heights, 3, 2, (1.0, 1.0)).unwrap_err()).contains("heights"));
        let e = message(Scene::from_heights(&[0.0; 5], 3, 2, (1.0, 1.0)).unwrap_err());
        assert!(e.contains("heights") && e.contains("expected 6"), "{e}");
        let e = message(Scene::from_heights(&[0.0; 2], 2, 1, (1.0, 1.0)).unwrap_err());
        assert!(e.contains("2×2"), "{e}");
        let e = message(Scene::from_heights(&[0.0; 4], 2, 2, (0.0, 1.0)).unwrap_err());
        assert!(e.contains("spacing"), "{e}");
    }

    #[test]
    fn procedural_names_the_model_and_size() {
        let e = message(Scene::procedural("perlin", 1, 9, 10.0).unwrap_err());
        assert!(e.contains("model") && e.contains("ridged"), "{e}");
        let e = message(Scene::procedural("fbm", 1, 1, 10.0).unwrap_err());
        assert!(e.contains("size"), "{e}");
        let e = message(Scene::procedural("fbm", 1, 9, f64::NAN).unwrap_err());
        assert!(e.contains("spacing"), "{e}");
        let scene = Scene::procedural("fbm", 3, 9, 10.0).unwrap();
        assert_eq!((scene.heights.columns, scene.heights.rows), (9, 9));
    }
}
