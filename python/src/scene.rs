//! `Context` (the Vulkan device) and `Scene` (a height field and its
//! objects), and the height-map round trip `write_heightmap`.

use std::path::PathBuf;

use numpy::{PyArray2, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::engine;
use crate::{arg_err, invalid, lib_err};

/// A Vulkan instance and device. `validation=True` enables the Khronos
/// validation layers and counts their messages (`validation_messages`);
/// `device` picks a device by index or by part of its name.
#[pyclass(module = "alpenglow", frozen)]
pub struct Context {
    pub(crate) inner: engine::Context,
}

#[pymethods]
impl Context {
    #[new]
    #[pyo3(signature = (validation = false, device = None))]
    fn new(py: Python<'_>, validation: bool, device: Option<&Bound<'_, PyAny>>) -> PyResult<Context> {
        let device = match device {
            None => engine::DeviceSelector::Best,
            Some(d) => match d.extract::<usize>() {
                Ok(index) => engine::DeviceSelector::Index(index),
                Err(_) => d
                    .extract::<String>()
                    .map_err(|_| invalid("device", "expected a device index or part of its name"))?
                    .parse()
                    .map_err(arg_err)?,
            },
        };
        let options = engine::ContextOptions { validation, device };
        let inner = py.detach(|| engine::Context::new(&options)).map_err(lib_err)?;
        Ok(Context { inner })
    }

    /// The device's name.
    #[getter]
    fn device_name(&self) -> String {
        self.inner.info().name.clone()
    }

    /// Whether the validation layers are on.
    #[getter]
    fn validation(&self) -> bool {
        self.inner.validation_report().is_some()
    }

    /// The validation layers' errors and warnings so far (None without
    /// validation). Messages the library knowingly sets aside do not count.
    #[getter]
    fn validation_messages(&self) -> Option<Vec<String>> {
        self.inner.validation_report().map(|r| r.messages())
    }

    fn __repr__(&self) -> String {
        format!("Context(device={:?})", self.inner.info().name)
    }
}

/// What a scene renders: a height field (row 0 at y = 0, x along columns)
/// and its point objects (rocks, vegetation).
#[pyclass(module = "alpenglow")]
pub struct Scene {
    pub(crate) inner: engine::Scene,
}

/// A float32 array of shape (rows, cols), copied row-major; errors name
/// `parameter`.
pub(crate) fn height_array(parameter: &str, h: &Bound<'_, PyAny>) -> PyResult<(Vec<f32>, u32, u32)> {
    let array = h
        .cast::<PyUntypedArray>()
        .map_err(|_| invalid(parameter, "expected a numpy array of float32 with shape (rows, cols)"))?;
    if array.ndim() != 2 {
        return Err(invalid(
            parameter,
            format!("shape {:?}; expected (rows, cols)", array.shape()),
        ));
    }
    if !array.dtype().is_equiv_to(&numpy::dtype::<f32>(h.py())) {
        return Err(invalid(parameter, format!("dtype {}; expected float32", array.dtype())));
    }
    let (rows, cols) = (array.shape()[0], array.shape()[1]);
    let size = |n: usize| u32::try_from(n).ok().filter(|&n| n >= 2);
    let (Some(r), Some(c)) = (size(rows), size(cols)) else {
        return Err(invalid(
            parameter,
            format!("shape ({rows}, {cols}); at least 2×2 samples are needed"),
        ));
    };
    let typed = array.cast::<PyArray2<f32>>()?.readonly();
    let values: Vec<f32> = typed.as_array().iter().copied().collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(invalid(
            parameter,
            format!(
                "height at row {}, column {} is {}; heights must be finite",
                i / cols,
                i % cols,
                values[i]
            ),
        ));
    }
    Ok((values, c, r))
}

/// A spacing `(dx, dy)` or a single number for both, checked.
fn spacing_pair(spacing: &Bound<'_, PyAny>) -> PyResult<(f64, f64)> {
    let pair = match spacing.extract::<f64>() {
        Ok(d) => (d, d),
        Err(_) => spacing
            .extract::<(f64, f64)>()
            .map_err(|_| invalid("spacing", "expected dx or (dx, dy) in metres"))?,
    };
    engine::check_spacing(glam::DVec2::new(pair.0, pair.1)).map_err(|m| invalid("spacing", m))?;
    Ok(pair)
}

/// `spacing` as (dx, dy), 1 m each when it is not given.
fn spacing_or_unit(spacing: Option<&Bound<'_, PyAny>>) -> PyResult<(f64, f64)> {
    spacing.map_or(Ok((1.0, 1.0)), spacing_pair)
}

#[pymethods]
impl Scene {
    /// A height field from `h`, a float32 array of shape (rows, cols) in
    /// metres; row 0 lies at y = 0, column 0 at x = 0; `spacing` is
    /// (dx, dy) in metres (or one number for both).
    #[staticmethod]
    #[pyo3(signature = (h, spacing = None))]
    fn from_heights(py: Python<'_>, h: &Bound<'_, PyAny>, spacing: Option<&Bound<'_, PyAny>>) -> PyResult<Scene> {
        let spacing = spacing_or_unit(spacing)?;
        let (values, cols, rows) = height_array("heights", h)?;
        let inner = py
            .detach(|| engine::scene_from_heights(values, cols, rows, spacing))
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(Scene { inner })
    }

    /// A height map file (16-bit PNG, EXR, GeoTIFF, SRTM .hgt), with the
    /// CLI's height-map options: `spacing` (--spacing), `height_scale`,
    /// `height_offset`, `rows` ("south-up" or "north-up"), `max_input_mb`.
    #[staticmethod]
    #[pyo3(signature = (path, spacing = None, height_scale = 1.0, height_offset = 0.0, rows = "south-up", max_input_mb = 2048))]
    fn from_file(
        py: Python<'_>,
        path: PathBuf,
        spacing: Option<&Bound<'_, PyAny>>,
        height_scale: f32,
        height_offset: f32,
        rows: &str,
        max_input_mb: u64,
    ) -> PyResult<Scene> {
        let spacing = spacing.map(spacing_pair).transpose()?;
        if !(height_scale.is_finite() && height_scale > 0.0) {
            return Err(invalid(
                "height_scale",
                format!("{height_scale}; must be finite and positive"),
            ));
        }
        if !height_offset.is_finite() {
            return Err(invalid("height_offset", format!("{height_offset}; must be finite")));
        }
        if max_input_mb == 0 {
            return Err(invalid("max_input_mb", "0; must be at least 1"));
        }
        let rows = match rows {
            "south-up" => engine::RowOrder::SouthUp,
            "north-up" => engine::RowOrder::NorthUp,
            other => {
                return Err(invalid(
                    "rows",
                    format!("{other:?}; expected \"south-up\" or \"north-up\""),
                ))
            }
        };
        let options = engine::HeightmapOptions {
            scale: height_scale,
            offset: height_offset,
            spacing: spacing.map(|(x, y)| glam::DVec2::new(x, y)),
            rows,
            limits: engine::InputLimits::with_max_file_mib(max_input_mb),
        };
        let field = py.detach(|| engine::load_heightmap(&path, &options)).map_err(lib_err)?;
        Ok(Scene {
            inner: engine::Scene::new(field),
        })
    }

    /// A scene streamed from a height pyramid (`.hpyr`, written by
    /// `alpenglow dem import` or `write_pyramid`): its finest level with at
    /// most `resident_side` samples a side stays in memory, and a detail
    /// window of `detail_window` samples (0: none) of a finer level follows
    /// the camera; frames wait for the window's tiles, so they are
    /// deterministic. `ground_height` answers from the finest level.
    #[staticmethod]
    #[pyo3(signature = (path, resident_side = engine::DEFAULT_RESIDENT_SIDE, detail_window = engine::DEFAULT_DETAIL_WINDOW))]
    fn from_pyramid(py: Python<'_>, path: PathBuf, resident_side: u32, detail_window: u32) -> PyResult<Scene> {
        let inner = py
            .detach(|| engine::scene_from_pyramid(&path, resident_side, detail_window))
            .map_err(lib_err)?;
        Ok(Scene { inner })
    }

    /// A procedural terrain: `model` one of "fbm", "multifractal",
    /// "heterogeneous", "hybrid", "ridged" (the CLI's `--terrain
    /// procedural:MODEL` with its default parameters), `size`×`size`
    /// samples `spacing` metres apart.
    #[staticmethod]
    #[pyo3(signature = (model = "ridged", seed = 1, size = 513, spacing = 20.0))]
    fn procedural(py: Python<'_>, model: &str, seed: u64, size: u32, spacing: f64) -> PyResult<Scene> {
        engine::check_spacing(glam::DVec2::splat(spacing)).map_err(|m| invalid("spacing", m))?;
        let inner = py
            .detach(|| engine::scene_procedural(model, seed, size, spacing))
            .map_err(arg_err)?;
        Ok(Scene { inner })
    }

    /// Scatters `count` procedural boulders over the terrain.
    fn add_rocks(&mut self, py: Python<'_>, count: usize) -> PyResult<()> {
        let scene = &mut self.inner;
        py.detach(|| scene.add_rocks(count)).map_err(arg_err)
    }

    /// Plants the vegetation of the scene's layer tree; `density`
    /// multiplies every layer's density. Returns the number of plants.
    #[pyo3(signature = (density = 1.0, seed = 1))]
    fn add_vegetation(&mut self, py: Python<'_>, density: f64, seed: u64) -> PyResult<usize> {
        if !(density.is_finite() && density >= 0.0) {
            return Err(invalid("density", format!("{density}; must be finite and ≥ 0")));
        }
        let options = engine::VegetationOptions {
            density,
            seed,
            ..engine::VegetationOptions::default()
        };
        let scene = &mut self.inner;
        let before = scene.points.instances.len();
        py.detach(|| scene.add_vegetation(&options)).map_err(arg_err)?;
        Ok(self.inner.points.instances.len() - before)
    }

    /// The heights, float32 (rows, cols), row 0 at y = 0 (a copy).
    #[getter]
    fn heights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let f = &self.inner.heights;
        let shape = [f.rows as usize, f.columns as usize];
        numpy::PyArray1::from_vec(py, f.heights.clone()).reshape(shape)
    }

    /// Metres between samples, (dx, dy).
    #[getter]
    fn spacing(&self) -> (f64, f64) {
        (self.inner.heights.spacing.x, self.inner.heights.spacing.y)
    }

    /// The terrain's size in metres, (x, y).
    #[getter]
    fn extent(&self) -> (f64, f64) {
        let e = self.inner.heights.extent();
        (e.x, e.y)
    }

    /// The lowest and highest height, metres.
    #[getter]
    fn height_range(&self) -> (f32, f32) {
        self.inner.height_range()
    }

    /// Point objects (rocks, plants) in the scene.
    #[getter]
    fn point_instances(&self) -> usize {
        self.inner.points.instances.len()
    }

    /// The terrain's height at (x, y), metres.
    fn ground_height(&self, x: f64, y: f64) -> PyResult<f64> {
        self.inner.ground_height(x, y).map_err(arg_err)
    }

    /// A camera showing the whole terrain (the CLI's default camera).
    fn default_camera(&self) -> crate::camera::Camera {
        crate::camera::Camera {
            inner: self.inner.default_camera(),
        }
    }

    fn __repr__(&self) -> String {
        let f = &self.inner.heights;
        format!(
            "Scene({}×{} samples, spacing ({}, {}) m, {} point instances)",
            f.columns,
            f.rows,
            f.spacing.x,
            f.spacing.y,
            self.inner.points.instances.len()
        )
    }
}

/// Writes `h` (float32 (rows, cols), row 0 at y = 0) as a float EXR height
/// map that `Scene.from_file(path, spacing=…)` reads back exactly.
#[pyfunction]
pub fn write_heightmap(py: Python<'_>, path: PathBuf, h: &Bound<'_, PyAny>) -> PyResult<()> {
    let (values, cols, rows) = height_array("heights", h)?;
    py.detach(|| engine::write_heightmap(&path, &values, cols, rows))
        .map_err(lib_err)
}

/// Writes `h` (float32 (rows, cols), row 0 at y = 0, `spacing` (dx, dy) or
/// one number) as a height pyramid that `Scene.from_pyramid(path)` streams:
/// tiles of `tile_side` samples, heights quantised to `height_step` metres.
/// Returns the number of levels.
#[pyfunction]
#[pyo3(signature = (path, h, spacing = None, tile_side = engine::DEFAULT_TILE_SIDE, height_step = engine::DEFAULT_HEIGHT_STEP))]
pub fn write_pyramid(
    py: Python<'_>,
    path: PathBuf,
    h: &Bound<'_, PyAny>,
    spacing: Option<&Bound<'_, PyAny>>,
    tile_side: u32,
    height_step: f64,
) -> PyResult<u32> {
    let spacing = spacing_or_unit(spacing)?;
    let (values, cols, rows) = height_array("heights", h)?;
    let scene = py
        .detach(|| engine::scene_from_heights(values, cols, rows, spacing))
        .map_err(arg_err)?;
    py.detach(|| engine::write_height_pyramid(&path, &scene.heights, tile_side, height_step))
        .map_err(arg_err)
}
