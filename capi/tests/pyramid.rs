//! Streamed regions from C: `ag_scene_from_pyramid` opens a height pyramid
//! (a coarse level resident, a detail window of a finer one) and
//! `ag_scene_ground_height` answers from its finest level; bad paths,
//! options and points are error codes with one-line messages.

use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

use alpenglow::files::{write_pyramid, FieldRows, PyramidOptions};
use alpenglow::HeightField;
use alpenglow_c::*;

fn last_error() -> String {
    // SAFETY: ag_last_error never returns NULL; the string lives until the next failure.
    unsafe { CStr::from_ptr(ag_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// 257² samples 1 m apart: broad hills, and ripples 6–7 m long that the
/// coarser levels lose.
fn rippled() -> HeightField {
    HeightField::from_fn(257, 257, alpenglow::glam::DVec2::ONE, |c, r| {
        let (x, y) = (f64::from(c), f64::from(r));
        let ripples = 1.5 * (x * std::f64::consts::TAU / 6.0).sin() * (y * std::f64::consts::TAU / 7.0).cos();
        (50.0 + 20.0 * (x / 60.0).sin() + ripples) as f32
    })
}

fn pyramid(field: &HeightField) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-c-pyramid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ripples.hpyr");
    let options = PyramidOptions {
        tile_side: 32,
        ..PyramidOptions::default()
    };
    write_pyramid(&path, &mut FieldRows::new(field, Path::new("ripples")), &options).unwrap();
    path
}

fn open(path: &Path, resident_side: u32, detail_window: u32) -> (ag_status, *mut ag_scene) {
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    let mut scene = null_mut();
    // SAFETY: NUL-terminated path, writable out.
    let status = unsafe { ag_scene_from_pyramid(c_path.as_ptr(), resident_side, detail_window, &mut scene) };
    (status, scene)
}

fn ground(scene: *const ag_scene, x: f64, y: f64) -> (ag_status, f64) {
    let mut h = 0.0;
    // SAFETY: a live scene, a writable height.
    let status = unsafe { ag_scene_ground_height(scene, x, y, &mut h) };
    (status, h)
}

#[test]
fn a_streamed_scene_answers_ground_heights_from_its_finest_level() {
    let field = rippled();
    let path = pyramid(&field);
    let (status, streamed) = open(&path, 33, 64);
    assert_eq!(status, ag_status::AG_OK, "{}", last_error());
    let (status, resident) = open(&path, 33, 0);
    assert_eq!(status, ag_status::AG_OK, "{}", last_error());
    let (mut off_streamed, mut off_resident) = (0.0, 0.0);
    for k in 0..50u32 {
        let (c, r) = (2 + (k * 37) % 252, 2 + (k * 91) % 252);
        // The B-spline at a sample: the [1, 4, 1] / 6 average along each axis.
        let w = [1.0, 4.0, 1.0].map(|v| v / 6.0);
        let mut knot = 0.0;
        for (j, wj) in w.iter().enumerate() {
            for (i, wi) in w.iter().enumerate() {
                knot += wi * wj * f64::from(field.height(c + i as u32 - 1, r + j as u32 - 1));
            }
        }
        let (status, h) = ground(streamed, f64::from(c), f64::from(r));
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        off_streamed += (h - knot).abs() / 50.0;
        let (_, h) = ground(resident, f64::from(c), f64::from(r));
        off_resident += (h - knot).abs() / 50.0;
    }
    // The streamed answer holds the ripples (only octaves finer than 1 m differ).
    assert!(
        off_streamed < 0.06 && off_resident > 10.0 * off_streamed,
        "{off_streamed} {off_resident}"
    );
    let (status, h) = ground(streamed, -4.0, 10.0);
    assert_eq!(status, ag_status::AG_ERROR_INVALID_ARGUMENT);
    assert!(h.is_nan());
    assert!(last_error().contains("ground position"), "{}", last_error());
    // SAFETY: a live scene; NULL height is checked.
    let status = unsafe { ag_scene_ground_height(streamed, 1.0, 1.0, null_mut()) };
    assert_eq!(status, ag_status::AG_ERROR_NULL_POINTER);
    // SAFETY: both scenes are live and destroyed once.
    unsafe {
        ag_scene_destroy(streamed);
        ag_scene_destroy(resident);
    }
}

#[test]
fn bad_pyramids_and_options_are_one_line_errors() {
    let path = pyramid(&rippled());
    let missing = path.with_file_name("missing.hpyr");
    let refused = |(status, scene): (ag_status, *mut ag_scene), code: ag_status, word: &str| {
        assert_eq!(status, code, "{}", last_error());
        assert!(scene.is_null() && last_error().contains(word), "{}", last_error());
    };
    refused(open(&missing, 33, 64), ag_status::AG_ERROR_INPUT, "missing.hpyr");
    refused(
        open(&path, 1, 64),
        ag_status::AG_ERROR_INVALID_ARGUMENT,
        "resident side",
    );
    refused(
        open(&path, 33, 100_000),
        ag_status::AG_ERROR_INVALID_ARGUMENT,
        "detail window",
    );
    let mut out = null_mut();
    // SAFETY: NULL path is checked.
    let status = unsafe { ag_scene_from_pyramid(null(), 33, 64, &mut out) };
    assert_eq!(status, ag_status::AG_ERROR_NULL_POINTER);
    assert!(!last_error().contains('\n'));
}
