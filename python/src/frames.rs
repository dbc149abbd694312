//! Frames as dicts of NumPy arrays, and the library's PNG and EXR writers
//! of them (byte for byte the CLI's `--out` and `--exr` files).

use std::path::PathBuf;

use numpy::{Element, PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::engine::{self, ExrPlane, FrameImages};
use crate::{invalid, lib_err};

/// `values` (moved, not copied: NumPy owns the `Vec`) as an array of `shape`.
fn array<'py, T: Element>(py: Python<'py>, values: Vec<T>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, values).reshape(shape)?.into_any())
}

/// One view's images as a dict: "rgba8" (H,W,4) uint8, "hdr" (H,W,4),
/// "depth" and "distance" (H,W) with inf for sky, "normal" (H,W,3),
/// "motion" (H,W,2), "visibility" (H,W,2: sun, sky) float32, "class" and
/// "instance" (H,W) uint32, and "weight" (H,W) float32 for scenes with
/// points.
pub(crate) fn frame_dict(py: Python<'_>, images: FrameImages) -> PyResult<Bound<'_, PyDict>> {
    let (h, w) = (images.height as usize, images.width as usize);
    let d = PyDict::new(py);
    d.set_item("rgba8", array(py, images.rgba8, &[h, w, 4])?)?;
    d.set_item("hdr", array(py, images.hdr, &[h, w, 4])?)?;
    d.set_item("depth", array(py, images.depth, &[h, w])?)?;
    d.set_item("distance", array(py, images.distance, &[h, w])?)?;
    d.set_item("normal", array(py, images.normal, &[h, w, 3])?)?;
    d.set_item("class", array(py, images.class, &[h, w])?)?;
    d.set_item("instance", array(py, images.instance, &[h, w])?)?;
    d.set_item("motion", array(py, images.motion, &[h, w, 2])?)?;
    d.set_item("visibility", array(py, images.visibility, &[h, w, 2])?)?;
    if let Some(weight) = images.weight {
        d.set_item("weight", array(py, weight, &[h, w])?)?;
    }
    Ok(d)
}

/// Row-major values and their image size (rows, columns).
type Plane<T> = (Vec<T>, (usize, usize));

/// `frame[key]` as a `T` array of shape (H, W, channels) (channels 1: (H, W)),
/// copied row-major; None when absent and not `required`.
fn plane<T: Element + Copy>(
    frame: &Bound<'_, PyDict>,
    key: &str,
    channels: usize,
    size: Option<(usize, usize)>,
    required: bool,
) -> PyResult<Option<Plane<T>>> {
    let Some(value) = frame.get_item(key)? else {
        return match required {
            true => Err(invalid("frame", format!("no {key:?} array"))),
            false => Ok(None),
        };
    };
    let parameter = format!("frame[{key:?}]");
    let want = std::any::type_name::<T>();
    let a = value
        .cast::<PyArrayDyn<T>>()
        .map_err(|_| invalid(&parameter, format!("expected a numpy array of {want}")))?;
    let shape = a.shape().to_vec();
    let ok = match channels {
        1 => shape.len() == 2,
        n => shape.len() == 3 && shape[2] == n,
    };
    let hw = (shape.first().copied().unwrap_or(0), shape.get(1).copied().unwrap_or(0));
    if !ok || size.is_some_and(|s| s != hw) || hw.0 == 0 || hw.1 == 0 {
        return Err(invalid(&parameter, format!("shape {shape:?} does not fit the frame")));
    }
    let values = a.readonly().as_array().iter().copied().collect();
    Ok(Some((values, hw)))
}

/// Every `n`-th value of `values` from the `k`-th.
fn channel(values: &[f32], n: usize, k: usize) -> Vec<f32> {
    values.iter().skip(k).step_by(n).copied().collect()
}

/// The EXR of a frame dict (the CLI's channels and order).
fn exr_bytes<'py>(frame: &Bound<'py, PyDict>) -> PyResult<(Vec<u8>, Python<'py>)> {
    let py = frame.py();
    let (hdr, size) = plane::<f32>(frame, "hdr", 4, None, true)?.ok_or_else(|| invalid("frame", "no hdr"))?;
    let s = Some(size);
    let (depth, _) = plane::<f32>(frame, "depth", 1, s, true)?.ok_or_else(|| invalid("frame", "no depth"))?;
    let mut planes: Vec<(&str, ExrPlane)> = Vec::new();
    if let Some((v, _)) = plane::<f32>(frame, "visibility", 2, s, false)? {
        planes.push(("sun_visibility", ExrPlane::F32(channel(&v, 2, 0))));
        planes.push(("sky_visibility", ExrPlane::F32(channel(&v, 2, 1))));
    }
    if let Some((v, _)) = plane::<f32>(frame, "distance", 1, s, false)? {
        planes.push(("distance", ExrPlane::F32(v)));
    }
    if let Some((v, _)) = plane::<f32>(frame, "normal", 3, s, false)? {
        for (k, name) in ["N.X", "N.Y", "N.Z"].into_iter().enumerate() {
            planes.push((name, ExrPlane::F32(channel(&v, 3, k))));
        }
    }
    for key in ["class", "instance"] {
        if let Some((v, _)) = plane::<u32>(frame, key, 1, s, false)? {
            planes.push((key, ExrPlane::U32(v)));
        }
    }
    if let Some((v, _)) = plane::<f32>(frame, "motion", 2, s, false)? {
        planes.push(("motion.X", ExrPlane::F32(channel(&v, 2, 0))));
        planes.push(("motion.Y", ExrPlane::F32(channel(&v, 2, 1))));
    }
    if let Some((v, _)) = plane::<f32>(frame, "weight", 1, s, false)? {
        planes.push(("W", ExrPlane::F32(v)));
    }
    let wh = (size.1 as u32, size.0 as u32);
    let bytes = py
        .detach(|| engine::encode_exr(wh, &hdr, &depth, &planes))
        .map_err(lib_err)?;
    Ok((bytes, py))
}

/// The RGBA8 pixels of `image`: a frame dict (its "rgba8") or a uint8
/// array (H, W, 4).
fn rgba8(image: &Bound<'_, PyAny>) -> PyResult<(Vec<u8>, (u32, u32))> {
    let (values, (h, w)) = match image.cast::<PyDict>() {
        Ok(frame) => plane::<u8>(frame, "rgba8", 4, None, true)?,
        Err(_) => {
            let d = PyDict::new(image.py());
            d.set_item("rgba8", image)?;
            plane::<u8>(&d, "rgba8", 4, None, true)?
        }
    }
    .ok_or_else(|| invalid("image", "no rgba8 array"))?;
    Ok((values, (w as u32, h as u32)))
}

fn png_bytes(image: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    let (pixels, (w, h)) = rgba8(image)?;
    image.py().detach(|| engine::encode_png(&pixels, w, h)).map_err(lib_err)
}

/// The PNG of `image` (a frame dict or a uint8 (H, W, 4) array), as bytes.
#[pyfunction]
pub fn encode_png<'py>(image: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = png_bytes(image)?;
    Ok(PyBytes::new(image.py(), &bytes))
}

/// Writes the PNG of `image` (a frame dict or a uint8 (H, W, 4) array)
/// atomically: the CLI's `--out` file.
#[pyfunction]
pub fn write_png(path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let bytes = png_bytes(image)?;
    image.py().detach(|| engine::write_file(&path, &bytes)).map_err(lib_err)
}

/// The OpenEXR file of a frame dict (RGBA from "hdr", Z from "depth", and
/// the AOVs present), as bytes.
#[pyfunction]
pub fn encode_exr<'py>(frame: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyBytes>> {
    let (bytes, py) = exr_bytes(frame)?;
    Ok(PyBytes::new(py, &bytes))
}

/// Writes the OpenEXR file of a frame dict atomically: the CLI's `--exr`
/// file (RGBA, Z, sun_visibility, sky_visibility, distance, N.X/Y/Z,
/// class, instance, motion.X/Y, W).
#[pyfunction]
pub fn write_exr(path: PathBuf, frame: &Bound<'_, PyDict>) -> PyResult<()> {
    let (bytes, py) = exr_bytes(frame)?;
    py.detach(|| engine::write_file(&path, &bytes)).map_err(lib_err)
}
