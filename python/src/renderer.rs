//! `Renderer`: one scene rendered frame after frame, settled (`render`) or
//! pipelined (`submit`, then `try_read`/`poll` or `wait`). The GIL is
//! released while the GPU works.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::camera::{Camera, Distortion, Intrinsics, Rig};
use crate::engine::{self, Engine, FrameImages, Ticket};
use crate::frames::frame_dict;
use crate::lighting::Lighting;
use crate::scene::{Context, Scene};
use crate::{arg_err, invalid, lib_err};

/// Renders one scene. Keyword settings mirror the library's settings:
/// `width`, `height` (of a single view, or the default size of a rig's
/// views), `rig` (a `Rig`: every frame renders its views, and results are
/// dicts per view name), `intrinsics` and `distortion` (of a single view),
/// `msaa` (1, 2, 4, 8, 16 samples per pixel), `terrain_detail`
/// (procedural displacement and bump mapping), `grid` (the terrain's
/// geometry-image side), `texturing` ("atlas", "direct", "classic"),
/// `raster` ("auto", the default: compute where the device can,
/// "compute": a visibility buffer in compute shaders, "hardware"),
/// `lighting` (a `Lighting`; default: the scene's), `cache_dir` (where the
/// sky-light bake is cached), `readback_slots` (frames that can be
/// submitted before the oldest unread one is lost; default 3).
#[pyclass(module = "alpenglow", frozen)]
pub struct Renderer {
    engine: Mutex<Engine>,
    rig: Option<engine::Rig>,
    names: Vec<String>,
    lighting: Mutex<engine::Lighting>,
}

fn texturing(name: &str) -> PyResult<engine::TexturingMode> {
    match name {
        "atlas" => Ok(engine::TexturingMode::Atlas),
        "direct" => Ok(engine::TexturingMode::Direct),
        "classic" => Ok(engine::TexturingMode::Classic),
        _ => Err(invalid(
            "texturing",
            format!("{name:?}; expected \"atlas\", \"direct\" or \"classic\""),
        )),
    }
}

fn raster(name: &str) -> PyResult<engine::RasterPath> {
    match name {
        "hardware" => Ok(engine::RasterPath::Hardware),
        "compute" => Ok(engine::RasterPath::Compute),
        "auto" => Ok(engine::RasterPath::Auto),
        _ => Err(invalid(
            "raster",
            format!("{name:?}; expected \"hardware\", \"compute\" or \"auto\""),
        )),
    }
}

fn poisoned() -> PyErr {
    crate::Error::new_err("the renderer is unusable: an earlier call panicked")
}

/// What `render`/`wait` return: one view's dict, or a dict per view name.
fn result<'py>(py: Python<'py>, multi: bool, views: Vec<FrameImages>) -> PyResult<Bound<'py, PyAny>> {
    if !multi {
        let view = views
            .into_iter()
            .next()
            .ok_or_else(|| crate::Error::new_err("the frame has no view"))?;
        return Ok(frame_dict(py, view)?.into_any());
    }
    let out = PyDict::new(py);
    for view in views {
        let name = view.name.clone();
        out.set_item(name, frame_dict(py, view)?)?;
    }
    Ok(out.into_any())
}

impl Renderer {
    fn engine(&self) -> PyResult<MutexGuard<'_, Engine>> {
        self.engine.lock().map_err(|_| poisoned())
    }

    /// `f` of the engine with the GIL released (other Python threads run
    /// while the GPU works).
    fn with_engine<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Engine) -> engine::Result<T> + Send,
    ) -> PyResult<engine::Result<T>> {
        py.detach(|| self.engine.lock().map(|mut e| f(&mut e)).map_err(|_| ()))
            .map_err(|()| poisoned())
    }

    /// The cameras of a frame: one `Camera` (a rig's views follow it), or
    /// a list of one `Camera` per view.
    fn cameras(&self, camera: &Bound<'_, PyAny>) -> PyResult<Vec<engine::Camera>> {
        if let Ok(c) = camera.cast::<Camera>() {
            let c = c.get().inner;
            return match &self.rig {
                Some(rig) => rig.cameras(&c).map_err(arg_err),
                None if self.names.len() == 1 => Ok(vec![c]),
                None => Err(invalid(
                    "camera",
                    format!("expected a list of {} cameras", self.names.len()),
                )),
            };
        }
        let list = camera
            .cast::<PyList>()
            .map_err(|_| invalid("camera", "expected a Camera or a list of one Camera per view"))?;
        if list.len() != self.names.len() {
            return Err(invalid(
                "camera",
                format!("{} cameras for {} views", list.len(), self.names.len()),
            ));
        }
        list.iter()
            .map(|c| {
                c.cast::<Camera>()
                    .map(|c| c.get().inner)
                    .map_err(|_| invalid("camera", "expected a list of Camera"))
            })
            .collect()
    }

    fn multi(&self) -> bool {
        self.rig.is_some() || self.names.len() > 1
    }
}

#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (ctx, scene, width = 640, height = 360, *, rig = None, intrinsics = None, distortion = None, msaa = 1, terrain_detail = true, grid = None, texturing = "atlas", raster = "auto", lighting = None, cache_dir = None, readback_slots = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        ctx: &Context,
        scene: &Scene,
        width: u32,
        height: u32,
        rig: Option<Rig>,
        intrinsics: Option<Intrinsics>,
        distortion: Option<Distortion>,
        msaa: u32,
        terrain_detail: bool,
        grid: Option<u32>,
        texturing: &str,
        raster: &str,
        lighting: Option<Lighting>,
        cache_dir: Option<PathBuf>,
        readback_slots: Option<usize>,
    ) -> PyResult<Renderer> {
        let rig = rig.map(|r| r.inner);
        let specs = match &rig {
            Some(_) if intrinsics.is_some() || distortion.is_some() => {
                return Err(invalid("intrinsics", "a rig's views carry their own lenses"))
            }
            Some(r) => r.specs((width, height)).map_err(arg_err)?,
            None => {
                let mut spec = engine::ViewSpec::new(width, height);
                spec.intrinsics = intrinsics.map(|k| k.inner);
                spec.distortion = distortion.map(|d| d.inner);
                if spec.distortion.is_some() && spec.intrinsics.is_none() {
                    return Err(invalid("distortion", "needs intrinsics"));
                }
                spec.validate().map_err(arg_err)?;
                vec![spec]
            }
        };
        let names = specs.iter().map(|s| s.name.clone()).collect();
        let mut settings = engine::Settings::for_views(specs);
        settings.msaa = msaa;
        settings.terrain.detail = terrain_detail;
        if let Some(g) = grid {
            settings.terrain.grid_side = g;
        }
        settings.terrain.validate().map_err(arg_err)?;
        settings.texturing = self::texturing(texturing)?;
        settings.raster = self::raster(raster)?;
        settings.lighting = lighting.map(|l| l.inner);
        settings.cache_dir = cache_dir;
        if let Some(n) = readback_slots {
            settings.readback_slots = n;
        }
        let light = settings.lighting.unwrap_or_else(|| scene.inner.default_lighting());
        let (ctx, scene) = (&ctx.inner, &scene.inner);
        let engine = py.detach(|| Engine::new(ctx, scene, settings)).map_err(arg_err)?;
        Ok(Renderer {
            engine: Mutex::new(engine),
            rig,
            names,
            lighting: Mutex::new(light),
        })
    }

    /// Renders `camera` (a `Camera`, or one per view) until the texture
    /// atlas settled and returns the frame: a dict of arrays (see the
    /// package documentation), or with a rig a dict of them per view name.
    fn render<'py>(&self, py: Python<'py>, camera: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let cameras = self.cameras(camera)?;
        let views = self.with_engine(py, |e| e.render_settled(&cameras))?.map_err(lib_err)?;
        result(py, self.multi(), views)
    }

    /// Submits one frame of `camera` without waiting for the GPU (a
    /// simulator's frame: the texture atlas streams at its pace) and
    /// returns its ticket for `try_read`, `poll` or `wait`.
    fn submit(&self, py: Python<'_>, camera: &Bound<'_, PyAny>) -> PyResult<Ticket> {
        let cameras = self.cameras(camera)?;
        self.with_engine(py, |e| e.submit(&cameras))?.map_err(lib_err)
    }

    /// The frame of `ticket` once the GPU finished it. Errors
    /// (`alpenglow.Error`) for an unknown ticket or one whose readback slot
    /// later frames reused (never stale data).
    fn wait<'py>(&self, py: Python<'py>, ticket: Ticket) -> PyResult<Bound<'py, PyAny>> {
        let views = self.with_engine(py, |e| e.wait(ticket))?.map_err(lib_err)?;
        result(py, self.multi(), views)
    }

    /// The frame of `ticket`, or None while the GPU is still at work.
    fn try_read<'py>(&self, py: Python<'py>, ticket: Ticket) -> PyResult<Option<Bound<'py, PyAny>>> {
        let views = self.with_engine(py, |e| e.try_read(ticket))?.map_err(lib_err)?;
        views.map(|v| result(py, self.multi(), v)).transpose()
    }

    /// Same as `try_read`.
    fn poll<'py>(&self, py: Python<'py>, ticket: Ticket) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.try_read(py, ticket)
    }

    /// The lighting of the next frames.
    #[getter]
    fn lighting(&self) -> PyResult<Lighting> {
        let inner = *self
            .lighting
            .lock()
            .map_err(|_| crate::Error::new_err("the renderer is unusable"))?;
        Ok(Lighting { inner })
    }

    /// Changes the lighting from the next frame on (time of day, sky, …).
    #[setter]
    fn set_lighting(&self, py: Python<'_>, lighting: Lighting) -> PyResult<()> {
        let inner = lighting.inner;
        self.with_engine(py, |e| e.set_lighting(inner))?.map_err(arg_err)?;
        if let Ok(mut l) = self.lighting.lock() {
            *l = inner;
        }
        Ok(())
    }

    /// The views' names, in order ("" for a single unnamed view).
    #[getter]
    fn views(&self) -> Vec<String> {
        self.names.clone()
    }

    /// The render graph's pass names (`pass@view`).
    #[getter]
    fn pass_names(&self) -> PyResult<Vec<String>> {
        Ok(self.engine()?.renderer().pass_names())
    }

    /// Waits until the GPU finished every submitted frame.
    fn finish(&self, py: Python<'_>) -> PyResult<()> {
        self.with_engine(py, |e| e.finish())?.map_err(lib_err)
    }

    fn __repr__(&self) -> String {
        format!("Renderer(views={:?})", self.names)
    }
}
