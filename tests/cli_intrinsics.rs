//! A view given by pinhole intrinsics is textured as finely by the atlas as
//! the same view given by `--fov-y` (issue 27, seam 4): the atlas plans its
//! tiles with the view's own frustum and pixel footprint
//! (`View::footprint`), not with the camera's symmetric field of view.
//!
//! Each case renders the real Jacksboro DEM (`tests/data/README.md`) under
//! validation with the atlas and with `--texturing direct` (the atlas's
//! reference, the same layers evaluated per pixel) and measures the mean
//! FLIP between the two; a view by intrinsics must be no worse than the
//! same view by `--fov-y`, within [`MARGIN`].
//!
//! Measured (lavapipe, debug build), mean FLIP atlas vs direct:
//!
//! | view | by `--fov-y` | by intrinsics, before | after |
//! |---|---|---|---|
//! | telephoto 1600,1600,120,80 | 0.0089 | 0.0225 | 0.0090 |
//! | off-axis 400,400,-100,-60 | 0.0211 | 0.0284 | 0.0183 |
//!
//! ("before": the atlas planning with `--fov-y`'s default 50° symmetric
//! frustum and footprint, as before the fix.) With `ALPENGLOW_DUMP=DIR` the
//! renders are kept in `DIR`.

mod common;

use std::path::Path;

use alpenglow::glam::DVec3;
use common::cli::{assert_success, fresh_dir, run};
use common::{data, mean_flip};

/// How much worse than by `--fov-y` a view by intrinsics may be: the two
/// are not the same pixels (the telephoto's principal point is half a
/// pixel off centre; the off-axis view is compared with a centred view
/// turned to its middle ray), and tile selection measures distances from
/// the eye, which fits an off-axis image's far side less well. Before the
/// fix both cases fail by more than twice this.
const MARGIN: f32 = 0.002;

const WIDTH: u32 = 240;
const HEIGHT: u32 = 160;

/// The valley camera of `tests/common` (`jacksboro_valley_camera`).
const EYE: DVec3 = DVec3::new(13600.0, 9600.0, 750.0);
const TARGET: DVec3 = DVec3::new(18500.0, 21500.0, 350.0);

fn vec3(v: DVec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// Renders the DEM at 240×160 with `camera` options and `--texturing mode`
/// into `dir/name-mode.png`; returns its RGBA8 pixels.
fn render(dir: &Path, name: &str, camera: &[String], mode: &str) -> Vec<u8> {
    let dem = data("jacksboro-fault.png");
    let png = dir.join(format!("{name}-{mode}.png"));
    let (w, h) = (WIDTH.to_string(), HEIGHT.to_string());
    let mut args: Vec<&str> = vec![
        "render",
        "--validation",
        "--heightmap",
        dem.to_str().unwrap(),
        "--spacing",
        "74.4,92.6",
        "--rocks",
        "0",
        "--width",
        &w,
        "--height",
        &h,
        "--near",
        "5",
        "--far",
        "100000",
        "--texturing",
        mode,
        "--out",
        png.to_str().unwrap(),
    ];
    args.extend(camera.iter().map(String::as_str));
    assert_success(&format!("render {name} --texturing {mode}"), &run(&args));
    let image = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
    assert_eq!((image.width(), image.height()), (WIDTH, HEIGHT));
    image.to_rgba8().into_raw()
}

/// Mean FLIP of the atlas render against the direct one.
fn atlas_error(dir: &Path, name: &str, camera: &[String]) -> f32 {
    let direct = render(dir, name, camera, "direct");
    let atlas = render(dir, name, camera, "atlas");
    mean_flip(&direct, &atlas, WIDTH, HEIGHT).0
}

/// `--eye`, `--target` and what else a case says.
fn camera(target: DVec3, rest: &[&str]) -> Vec<String> {
    let mut args = vec!["--eye".into(), vec3(EYE), "--target".into(), vec3(target)];
    args.extend(rest.iter().map(|s| s.to_string()));
    args
}

/// The vertical field of view in degrees of focal length `f` pixels over
/// the image's rows.
fn fov_y(f: f64) -> String {
    (2.0 * (0.5 * f64::from(HEIGHT) / f).atan()).to_degrees().to_string()
}

#[test]
fn intrinsics_views_are_textured_as_finely_as_fov_views() {
    let dir = match std::env::var("ALPENGLOW_DUMP") {
        Ok(d) => Path::new(&d).to_path_buf(),
        Err(_) => fresh_dir("intrinsics-atlas"),
    };
    // Telephoto, principal point at the centre (as a new user would type it).
    let tele = atlas_error(
        &dir,
        "tele-intrinsics",
        &camera(TARGET, &["--intrinsics", "1600,1600,120,80"]),
    );
    let tele_fov = atlas_error(&dir, "tele-fov", &camera(TARGET, &["--fov-y", &fov_y(1600.0)]));
    // Off-axis: the principal point 220 px left of and 140 px above the
    // image centre, so the image sees 14°–40° right of the optical axis
    // and 9°–28° below it (outside the camera's 50° symmetric frustum).
    let off = atlas_error(
        &dir,
        "off-intrinsics",
        &camera(TARGET, &["--intrinsics", "400,400,-100,-60"]),
    );
    // The same focal length, centred, turned to the off-axis image's middle
    // ray (pixel (119.5, 79.5): x = 219.5/400 right, y = 139.5/400 down).
    let forward = (TARGET - EYE).normalize();
    let right = forward.cross(DVec3::Z).normalize();
    let up = right.cross(forward);
    let middle = EYE + 1000.0 * (forward + (219.5 / 400.0) * right - (139.5 / 400.0) * up);
    let off_fov = atlas_error(&dir, "off-fov", &camera(middle, &["--fov-y", &fov_y(400.0)]));
    eprintln!(
        "mean FLIP atlas vs direct: telephoto {tele} (by --fov-y {tele_fov}), off-axis {off} (by --fov-y {off_fov})"
    );
    assert!(
        tele <= tele_fov + MARGIN,
        "telephoto by intrinsics: atlas vs direct mean FLIP {tele}, by --fov-y {tele_fov}"
    );
    assert!(
        off <= off_fov + MARGIN,
        "off-axis by intrinsics: atlas vs direct mean FLIP {off}, by --fov-y {off_fov}"
    );
    if std::env::var("ALPENGLOW_DUMP").is_err() {
        let _ = std::fs::remove_dir_all(&dir);
    }
}
