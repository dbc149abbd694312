//! `ag_scene`: a terrain (height field) and its objects.

use std::ffi::c_char;
use std::path::PathBuf;

use crate::adapter::{self, Scene};
use crate::status::{ag_status, arg, arg_mut, guard, put, str_arg, Failure, Outcome};
use crate::types::{ag_camera, ag_heightmap_options};

/// A scene (opaque): a height field, point objects, layers.
#[allow(non_camel_case_types)]
pub struct ag_scene {
    pub(crate) scene: Scene,
}

/// Hands `scene` to C through `out`.
///
/// # Safety
/// `out` is writable (checked not NULL by the caller's earlier `put`).
unsafe fn hand_out(out: *mut *mut ag_scene, scene: Outcome<Scene>) -> Outcome<ag_status> {
    let handle = Box::into_raw(Box::new(ag_scene { scene: scene? }));
    // SAFETY: the caller guarantees `out` is writable.
    unsafe { put(out, "out", handle) }?;
    Ok(ag_status::AG_OK)
}

/// Clears `out` (NULL until a scene is made) and reads `path`.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string; `out` is NULL or writable.
unsafe fn file_path(path: *const c_char, out: *mut *mut ag_scene) -> Outcome<PathBuf> {
    // SAFETY: the caller passes NULL or a writable pointer.
    unsafe { put(out, "out", std::ptr::null_mut()) }?;
    // SAFETY: the caller passes NULL or a NUL-terminated string.
    Ok(PathBuf::from(unsafe { str_arg(path, "path") }?))
}

/// A scene from `columns`×`rows` heights in metres, row-major, row 0 at
/// y = 0, samples `spacing_x`, `spacing_y` metres apart. The heights are
/// copied. Errors (`AG_ERROR_INVALID_ARGUMENT`, naming `heights` or
/// `spacing`): fewer than 2×2 samples, NaN or infinite heights, spacing out
/// of range.
///
/// # Safety
/// `heights` is NULL or readable for `columns·rows` floats; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_from_heights(
    heights: *const f32,
    columns: u32,
    rows: u32,
    spacing_x: f64,
    spacing_y: f64,
    out: *mut *mut ag_scene,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(out, "out", std::ptr::null_mut()) }?;
        if heights.is_null() {
            return Err(Failure::null("heights"));
        }
        let count = (columns as usize)
            .checked_mul(rows as usize)
            .ok_or_else(|| Failure::invalid("heights", format!("{columns}×{rows} samples overflow")))?;
        // SAFETY: not NULL; the caller guarantees `columns·rows` readable floats.
        let slice = unsafe { std::slice::from_raw_parts(heights, count) };
        let scene = adapter::scene_from_heights(slice, columns, rows, (spacing_x, spacing_y));
        // SAFETY: `out` was checked writable above.
        unsafe { hand_out(out, scene) }
    })
}

/// A scene from a height-map file (PNG, EXR, GeoTIFF, SRTM .hgt);
/// `options` NULL: `ag_heightmap_options_default()`. Errors name the file
/// (`AG_ERROR_INPUT`) or the option.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string; `options` is NULL or valid;
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_from_file(
    path: *const c_char,
    options: *const ag_heightmap_options,
    out: *mut *mut ag_scene,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a NUL-terminated path and NULL or a writable `out`.
        let path = unsafe { file_path(path, out) }?;
        let options = match options.is_null() {
            true => crate::types::ag_heightmap_options_default(),
            // SAFETY: not NULL; the caller guarantees a valid struct.
            false => *unsafe { arg(options, "options") }?,
        };
        let spacing = match (options.spacing_x, options.spacing_y) {
            (x, y) if x == 0.0 && y == 0.0 => None,
            (x, y) => Some((x, y)),
        };
        let file_options = adapter::FileOptions {
            scale: options.scale,
            offset: options.offset,
            spacing,
            north_up: options.north_up,
        };
        // SAFETY: `out` was checked writable above.
        unsafe { hand_out(out, adapter::scene_from_file(&path, &file_options)) }
    })
}

/// A scene streamed from a height pyramid (`.hpyr`, written by
/// `alpenglow dem import`): its finest level with at most `resident_side`
/// samples a side (2..=16384; 4096 is the CLI's default) stays in memory,
/// and a detail window of `detail_window` samples (0: none, at most 8192;
/// 1024 is the default) of a finer level follows the camera. Frames wait
/// for the window's tiles (deterministic). Errors name the file
/// (`AG_ERROR_INPUT`) or the option (`AG_ERROR_INVALID_ARGUMENT`).
///
/// # Safety
/// `path` is NULL or a NUL-terminated string; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_from_pyramid(
    path: *const c_char,
    resident_side: u32,
    detail_window: u32,
    out: *mut *mut ag_scene,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a NUL-terminated path and NULL or a writable `out`.
        let path = unsafe { file_path(path, out) }?;
        let scene = adapter::scene_from_pyramid(&path, resident_side, detail_window);
        // SAFETY: `out` was checked writable above.
        unsafe { hand_out(out, scene) }
    })
}

/// The height (metres) of the ground at world `(x, y)` as drawn, with
/// every procedural detail octave: where to put a car's wheels. On a scene
/// from `ag_scene_from_pyramid` with a detail window, from the pyramid's
/// finest level, read tile by tile. Each call takes a few milliseconds.
/// Errors (`AG_ERROR_INVALID_ARGUMENT`) name a point outside the terrain.
///
/// # Safety
/// `scene` is NULL or a live scene; `height` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_ground_height(scene: *const ag_scene, x: f64, y: f64, height: *mut f64) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(height, "height", f64::NAN) }?;
        // SAFETY: the caller passes NULL or a live handle.
        let scene = unsafe { arg(scene, "scene") }?;
        let value = adapter::ground_height(&scene.scene, x, y)?;
        // SAFETY: checked writable above.
        unsafe { put(height, "height", value) }?;
        Ok(ag_status::AG_OK)
    })
}

/// A `size`×`size` procedural terrain: `model` is "fbm", "multifractal",
/// "heterogeneous", "hybrid" or "ridged", samples `spacing` metres apart.
///
/// # Safety
/// `model` is NULL or a NUL-terminated string; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_procedural(
    model: *const c_char,
    seed: u32,
    size: u32,
    spacing: f64,
    out: *mut *mut ag_scene,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(out, "out", std::ptr::null_mut()) }?;
        // SAFETY: the caller passes NULL or a NUL-terminated string.
        let model = unsafe { str_arg(model, "model") }?;
        // SAFETY: `out` was checked writable above.
        unsafe { hand_out(out, adapter::scene_procedural(model, seed, size, spacing)) }
    })
}

/// Scatters `count` procedural boulders over the terrain. Errors before
/// building anything when they do not fit the host's memory.
///
/// # Safety
/// `scene` is NULL or a live scene not used by another thread.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_add_rocks(scene: *mut ag_scene, count: u32) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live, unshared handle.
        let scene = unsafe { arg_mut(scene, "scene") }?;
        adapter::add_rocks(&mut scene.scene, count as usize)?;
        Ok(ag_status::AG_OK)
    })
}

/// A camera that shows the whole terrain: from beyond its southern edge,
/// above the highest point, looking at the centre.
///
/// # Safety
/// `scene` is NULL or a live scene; `camera` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_default_camera(scene: *const ag_scene, camera: *mut ag_camera) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live handle.
        let scene = unsafe { arg(scene, "scene") }?;
        let value = ag_camera::from_rust(&adapter::default_camera(&scene.scene));
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(camera, "camera", value) }?;
        Ok(ag_status::AG_OK)
    })
}

/// Destroys `scene` (NULL: nothing to do). Renderers built from it keep
/// what they need.
///
/// # Safety
/// `scene` is NULL or a scene from this API not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn ag_scene_destroy(scene: *mut ag_scene) {
    if !scene.is_null() {
        // SAFETY: a live handle from Box::into_raw, owned by the caller until now.
        let scene = unsafe { Box::from_raw(scene) };
        // Dropping a scene is plain memory; a panic here must still not unwind into C.
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || drop(scene)));
    }
}
