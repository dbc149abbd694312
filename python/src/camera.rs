//! Cameras, pinhole intrinsics, lens distortion, the views of a rig and
//! rigs.

use std::path::PathBuf;

use glam::{DMat4, DVec3};
use numpy::{PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::engine;
use crate::{arg_err, invalid, lib_err};

/// `obj` (a sequence or array) as a float64 array of `shape`, row-major.
fn floats(parameter: &str, obj: &Bound<'_, PyAny>, shape: &[usize]) -> PyResult<Vec<f64>> {
    let np = obj.py().import("numpy")?;
    let what = || {
        format!(
            "expected {} numbers of shape {shape:?}",
            shape.iter().product::<usize>()
        )
    };
    let array = np
        .call_method1("asarray", (obj, "float64"))
        .map_err(|_| invalid(parameter, what()))?;
    let array = array
        .cast::<PyArrayDyn<f64>>()
        .map_err(|_| invalid(parameter, what()))?;
    if array.shape() != shape {
        return Err(invalid(parameter, format!("shape {:?}; {}", array.shape(), what())));
    }
    let values: Vec<f64> = array.readonly().as_array().iter().copied().collect();
    if values.iter().any(|v| !v.is_finite()) {
        return Err(invalid(parameter, "every number must be finite"));
    }
    Ok(values)
}

/// A point or direction `(x, y, z)`.
pub(crate) fn vec3(parameter: &str, obj: &Bound<'_, PyAny>) -> PyResult<DVec3> {
    let v = floats(parameter, obj, &[3])?;
    Ok(DVec3::new(v[0], v[1], v[2]))
}

/// A perspective camera: eye, target, up (+Z is up in the world), vertical
/// field of view in degrees, near and far clip distances in metres.
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct Camera {
    pub(crate) inner: engine::Camera,
}

impl Camera {
    fn checked(inner: engine::Camera) -> PyResult<Camera> {
        inner.validate().map_err(arg_err)?;
        Ok(Camera { inner })
    }
}

#[pymethods]
impl Camera {
    /// A camera at `eye` looking at `target`.
    #[staticmethod]
    #[pyo3(signature = (eye, target, up = None, fov_y = 60.0, near = 1.0, far = 1e5))]
    fn look_at(
        eye: &Bound<'_, PyAny>,
        target: &Bound<'_, PyAny>,
        up: Option<&Bound<'_, PyAny>>,
        fov_y: f64,
        near: f64,
        far: f64,
    ) -> PyResult<Camera> {
        let up = match up {
            Some(u) => vec3("up", u)?,
            None => DVec3::Z,
        };
        Camera::checked(engine::Camera {
            eye: vec3("eye", eye)?,
            target: vec3("target", target)?,
            up,
            fov_y_deg: fov_y,
            near,
            far,
        })
    }

    /// A camera at `pose`, a 4×4 camera-to-world matrix (row-major as NumPy
    /// prints it; the OpenGL/glTF convention: x right, y up, looking down
    /// −z; scale ignored).
    #[staticmethod]
    #[pyo3(signature = (pose, fov_y = 60.0, near = 1.0, far = 1e5))]
    fn from_pose(pose: &Bound<'_, PyAny>, fov_y: f64, near: f64, far: f64) -> PyResult<Camera> {
        let rows = floats("pose", pose, &[4, 4])?;
        let m = DMat4::from_cols_slice(&rows).transpose();
        let inner = engine::Camera::from_pose(m, fov_y, near, far).map_err(arg_err)?;
        Ok(Camera { inner })
    }

    /// The camera-to-world pose, float64 (4, 4), row-major.
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = self.inner.pose().transpose().to_cols_array().to_vec();
        numpy::PyArray1::from_vec(py, rows).reshape([4, 4])
    }

    #[getter]
    fn eye(&self) -> (f64, f64, f64) {
        self.inner.eye.into()
    }

    #[getter]
    fn target(&self) -> (f64, f64, f64) {
        self.inner.target.into()
    }

    #[getter]
    fn up(&self) -> (f64, f64, f64) {
        self.inner.up.into()
    }

    #[getter]
    fn fov_y(&self) -> f64 {
        self.inner.fov_y_deg
    }

    #[getter]
    fn near(&self) -> f64 {
        self.inner.near
    }

    #[getter]
    fn far(&self) -> f64 {
        self.inner.far
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "Camera.look_at(eye={:?}, target={:?}, up={:?}, fov_y={}, near={}, far={})",
            <(f64, f64, f64)>::from(c.eye),
            <(f64, f64, f64)>::from(c.target),
            <(f64, f64, f64)>::from(c.up),
            c.fov_y_deg,
            c.near,
            c.far
        )
    }
}

/// Pinhole intrinsics in pixels: focal lengths `fx`, `fy` and principal
/// point `cx`, `cy` (pixel centres at integers: a centred principal point
/// is ((W − 1)/2, (H − 1)/2)).
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct Intrinsics {
    pub(crate) inner: engine::Intrinsics,
}

#[pymethods]
impl Intrinsics {
    #[new]
    fn new(fx: f64, fy: f64, cx: f64, cy: f64) -> Intrinsics {
        Intrinsics {
            inner: engine::Intrinsics { fx, fy, cx, cy },
        }
    }

    /// A centred pinhole with vertical field of view `fov_y` (degrees).
    #[staticmethod]
    fn from_fov_y(fov_y: f64, width: u32, height: u32) -> Intrinsics {
        Intrinsics {
            inner: engine::Intrinsics::from_fov_y(fov_y, width, height),
        }
    }

    #[getter]
    fn fx(&self) -> f64 {
        self.inner.fx
    }

    #[getter]
    fn fy(&self) -> f64 {
        self.inner.fy
    }

    #[getter]
    fn cx(&self) -> f64 {
        self.inner.cx
    }

    #[getter]
    fn cy(&self) -> f64 {
        self.inner.cy
    }

    fn __repr__(&self) -> String {
        let k = &self.inner;
        format!("Intrinsics(fx={}, fy={}, cx={}, cy={})", k.fx, k.fy, k.cx, k.cy)
    }
}

/// Brown–Conrady lens distortion (radial k1, k2, k3; tangential p1, p2),
/// applied after rendering.
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct Distortion {
    pub(crate) inner: engine::Distortion,
}

#[pymethods]
impl Distortion {
    #[new]
    #[pyo3(signature = (k1 = 0.0, k2 = 0.0, k3 = 0.0, p1 = 0.0, p2 = 0.0))]
    fn new(k1: f64, k2: f64, k3: f64, p1: f64, p2: f64) -> PyResult<Distortion> {
        let inner = engine::Distortion { k1, k2, k3, p1, p2 };
        inner.validate().map_err(arg_err)?;
        Ok(Distortion { inner })
    }

    fn __repr__(&self) -> String {
        let d = &self.inner;
        format!(
            "Distortion(k1={}, k2={}, k3={}, p1={}, p2={})",
            d.k1, d.k2, d.k3, d.p1, d.p2
        )
    }
}

/// One view of a rig, relative to the rig's camera: `position` in metres
/// along (forward, left, up), turned by `yaw` (left positive), `pitch` (up
/// positive) and `roll` in degrees; its own `fov_y` or `intrinsics` (else
/// the rig camera's field of view), `distortion`, image size and clip
/// distances (else the renderer's).
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct View {
    pub(crate) inner: engine::RigView,
}

#[pymethods]
impl View {
    #[new]
    #[pyo3(signature = (name, *, position = None, yaw = 0.0, pitch = 0.0, roll = 0.0, fov_y = None, intrinsics = None, distortion = None, width = None, height = None, near = None, far = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        name: String,
        position: Option<&Bound<'_, PyAny>>,
        yaw: f64,
        pitch: f64,
        roll: f64,
        fov_y: Option<f64>,
        intrinsics: Option<Intrinsics>,
        distortion: Option<Distortion>,
        width: Option<u32>,
        height: Option<u32>,
        near: Option<f64>,
        far: Option<f64>,
    ) -> PyResult<View> {
        let position = position
            .map(|p| vec3("position", p))
            .transpose()?
            .unwrap_or(DVec3::ZERO);
        let lens = match (fov_y, intrinsics) {
            (Some(_), Some(_)) => return Err(invalid("fov_y", "give fov_y or intrinsics, not both")),
            (Some(f), None) => engine::RigLens::FovY(f),
            (None, Some(k)) => engine::RigLens::Pinhole(k.inner),
            (None, None) => engine::RigLens::Inherit,
        };
        let size = match (width, height) {
            (Some(w), Some(h)) => Some((w, h)),
            (None, None) => None,
            _ => return Err(invalid("width", "give width and height together")),
        };
        let view = engine::RigView {
            name,
            pose: engine::RigPose::Relative {
                position,
                yaw_pitch_roll_deg: DVec3::new(yaw, pitch, roll),
            },
            lens,
            distortion: distortion.map(|d| d.inner),
            size,
            near,
            far,
        };
        // Checks the name, size, lens and distortion the way a rig file's are.
        engine::Rig {
            views: vec![view.clone()],
        }
        .specs((1, 1))
        .map_err(arg_err)?;
        Ok(View { inner: view })
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    fn __repr__(&self) -> String {
        format!("View({:?})", self.inner.name)
    }
}

/// A camera rig: 1 to 16 named views rendered together each frame.
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct Rig {
    pub(crate) inner: engine::Rig,
}

#[pymethods]
impl Rig {
    #[new]
    fn new(views: Vec<View>) -> PyResult<Rig> {
        let inner = engine::Rig {
            views: views.into_iter().map(|v| v.inner).collect(),
        };
        inner.specs((1, 1)).map_err(arg_err)?;
        Ok(Rig { inner })
    }

    /// Six 60° views around a car (front, front_left, rear_left, rear,
    /// rear_right, front_right), each `width` wide, 4:3.
    #[staticmethod]
    fn ring6(width: u32) -> PyResult<Rig> {
        let inner = engine::Rig::ring6(width);
        inner.specs((1, 1)).map_err(arg_err)?;
        Ok(Rig { inner })
    }

    /// A rig file (TOML, the CLI's `--rig`).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Rig> {
        let inner = py.detach(|| engine::Rig::load(&path)).map_err(lib_err)?;
        Ok(Rig { inner })
    }

    /// The views' names, in order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner.views.iter().map(|v| v.name.clone()).collect()
    }

    /// The cameras of the views for the rig camera `camera`.
    fn cameras(&self, camera: &Camera) -> PyResult<Vec<Camera>> {
        let cameras = self.inner.cameras(&camera.inner).map_err(arg_err)?;
        Ok(cameras.into_iter().map(|inner| Camera { inner }).collect())
    }

    fn __len__(&self) -> usize {
        self.inner.views.len()
    }

    fn __repr__(&self) -> String {
        format!("Rig({:?})", self.names())
    }
}
