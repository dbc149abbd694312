//! `alpenglow._alpenglow`: the native module of the Python package
//! `alpenglow` (see `python/README.md`). Everything it needs from the
//! library goes through [`engine`], the one adapter file.
//!
//! Errors: an invalid argument raises `ValueError` whose message names the
//! parameter; anything else the library refuses raises `alpenglow.Error`
//! with the library's one-line message. Nothing panics across the FFI.

mod camera;
mod engine;
mod frames;
mod lighting;
mod renderer;
mod scene;

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

create_exception!(
    alpenglow,
    Error,
    PyException,
    "An error of the alpenglow library (its one-line message): a file it cannot read or write, a device it cannot use, a frame it cannot render."
);

/// `alpenglow.Error` with the library's message.
pub(crate) fn lib_err(e: engine::Error) -> PyErr {
    Error::new_err(e.to_string())
}

/// An error of checking a caller's arguments: `ValueError` when the library
/// names an invalid parameter, else `alpenglow.Error`.
pub(crate) fn arg_err(e: engine::Error) -> PyErr {
    match e.parameter() {
        Some(_) => PyValueError::new_err(e.to_string()),
        None => lib_err(e),
    }
}

/// `ValueError("invalid {parameter}: {message}")`, the library's wording.
pub(crate) fn invalid(parameter: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("invalid {parameter}: {message}"))
}

#[pymodule]
fn _alpenglow(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add("MAX_SETTLE_FRAMES", engine::MAX_SETTLE_FRAMES)?;
    m.add_class::<scene::Context>()?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<camera::Camera>()?;
    m.add_class::<camera::Intrinsics>()?;
    m.add_class::<camera::Distortion>()?;
    m.add_class::<camera::View>()?;
    m.add_class::<camera::Rig>()?;
    m.add_class::<lighting::Lighting>()?;
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(frames::write_png, m)?)?;
    m.add_function(wrap_pyfunction!(frames::write_exr, m)?)?;
    m.add_function(wrap_pyfunction!(frames::encode_png, m)?)?;
    m.add_function(wrap_pyfunction!(frames::encode_exr, m)?)?;
    m.add_function(wrap_pyfunction!(scene::write_heightmap, m)?)?;
    m.add_function(wrap_pyfunction!(scene::write_pyramid, m)?)?;
    Ok(())
}
