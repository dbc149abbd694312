//! The detail window on the host: which level and tiles it takes, its
//! heights against the pyramid's level (the B-spline of `level_field`, an
//! independent read of the same file), the blend's continuity and exact
//! gradient, coarser-until-finer, and the cache's bound along a drive.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use super::*;
use crate::io::pyramid::{write_pyramid, FieldRows, PyramidOptions};

/// 1025² samples 1 m apart: a broad slope and hills the resident level
/// holds, ripples 6 m long it cannot (they vanish below level 2).
pub(crate) fn rippled_field() -> HeightField {
    HeightField::from_fn(1025, 1025, DVec2::ONE, |c, r| {
        let (x, y) = (f64::from(c), f64::from(r));
        let hills = 40.0 * (x / 170.0).sin() * (y / 230.0).cos() + 0.05 * x;
        let ripples = 1.5 * (x * std::f64::consts::TAU / 6.0).sin() * (y * std::f64::consts::TAU / 7.0).cos();
        (hills + ripples) as f32
    })
}

/// `field` written as a pyramid with 64² tiles.
pub(crate) fn write_test_pyramid(field: &HeightField, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-detail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let options = PyramidOptions {
        tile_side: 64,
        ..PyramidOptions::default()
    };
    write_pyramid(&path, &mut FieldRows::new(field, Path::new("ripples")), &options).unwrap();
    path
}

struct Fixture {
    pyramid: HeightPyramid,
    resident: HeightField,
    window: DetailWindow,
}

/// The rippled pyramid, level 3 (129²) resident, a 256² window.
fn fixture(name: &str, wait: bool) -> Fixture {
    let path = write_test_pyramid(&rippled_field(), name);
    let pyramid = HeightPyramid::open(&path).unwrap();
    let level = pyramid.level_within(129);
    assert_eq!(level, 3);
    let resident = pyramid.level_field(level).unwrap();
    let source = DetailSource {
        path,
        resident_level: level,
        window: 256,
        wait,
    };
    let window = DetailWindow::open(&source).unwrap().unwrap();
    Fixture {
        pyramid,
        resident,
        window,
    }
}

fn eye(f: &Fixture, x: f64, y: f64, above: f64) -> DVec3 {
    DVec3::new(x, y, sample_bspline(&f.resident, x, y) + above)
}

#[test]
fn the_level_follows_the_eye_height_and_the_tiles_the_eye() {
    let f = fixture("plan.hpyr", true);
    let ground = |x, y| sample_bspline(&f.resident, x, y);
    // 256 samples span 32 eye heights: level 0 up to 8 m, level 1 to 16 m.
    let at = |x: f64, y: f64, above: f64| f.window.plan(DVec3::new(x, y, ground(x, y) + above), ground(x, y));
    assert_eq!(at(500.0, 500.0, 5.0).unwrap().level, 0);
    assert_eq!(at(500.0, 500.0, 12.0).unwrap().level, 1);
    assert_eq!(at(500.0, 500.0, 30.0).unwrap().level, 2);
    assert_eq!(at(500.0, 500.0, 100.0), None, "no level finer than 3 spans 3.2 km");
    // Centred on the nearest tile corner (8 at 500 m), clamped into the level.
    let r = at(500.0, 500.0, 5.0).unwrap();
    assert_eq!((r.x0, r.x1, r.y0, r.y1), (6, 10, 6, 10));
    let r = at(10.0, 1020.0, 5.0).unwrap();
    assert_eq!((r.x0, r.x1, r.y0, r.y1), (0, 4, 13, 17));
}

#[test]
fn window_heights_are_the_levels_bspline_blended_without_a_seam() {
    let mut f = fixture("heights.hpyr", true);
    let e = eye(&f, 480.0, 530.0, 4.0);
    let uploads = f.window.update(e, &f.resident).unwrap();
    assert_eq!(uploads.len(), 16);
    let active = f.window.active().unwrap();
    assert_eq!(Some(active), f.window.wanted());
    let fine = f.pyramid.level_field(0).unwrap();
    // Inside (band and support away from the edges): level 0 itself.
    let (x0, x1) = (f64::from(active.x0 * 64), f64::from(active.x1 * 64));
    let mut worst = 0.0f64;
    for k in 0..200 {
        let x = x0 + 40.0 + (x1 - x0 - 80.0) * f64::from(k) / 199.0;
        let y = f64::from(active.y0 * 64) + 40.0 + 1.7 * f64::from(k % 97);
        let (h, grad) = f.window.height(&f.resident, x, y);
        worst = worst.max((h - sample_bspline(&fine, x, y)).abs());
        assert!(
            (grad - sample_bspline_gradient(&fine, x, y)).length() < 1e-6,
            "gradient at {x}, {y}"
        );
    }
    assert!(worst < 1e-6, "{worst}");
    // Outside the window: the resident level.
    let (h, _) = f.window.height(&f.resident, x0 - 5.0, 530.0);
    assert_eq!(h, sample_bspline(&f.resident, x0 - 5.0, 530.0));
    // Across the band: continuous (steps no larger than the ripples allow
    // between 0.05 m apart), the gradient the derivative of the heights.
    let mut previous = f.window.height(&f.resident, x0 - 10.0, 530.0).0;
    let mut x = x0 - 10.0;
    while x < x0 + 50.0 {
        let (h, grad) = f.window.height(&f.resident, x, 530.0);
        assert!((h - previous).abs() < 0.15, "a step of {} m at x = {x}", h - previous);
        let d = 1e-4;
        let numeric =
            (f.window.height(&f.resident, x + d, 530.0).0 - f.window.height(&f.resident, x - d, 530.0).0) / (2.0 * d);
        assert!(
            (numeric - grad.x).abs() < 1e-3 * (1.0 + grad.x.abs()),
            "x = {x}: {numeric} vs {}",
            grad.x
        );
        previous = h;
        x += 0.05;
    }
}

#[test]
fn coarser_tiles_are_drawn_until_finer_ones_arrive() {
    let mut f = fixture("arrive.hpyr", true);
    f.window.update(eye(&f, 480.0, 530.0, 4.0), &f.resident).unwrap();
    let first = f.window.active().unwrap();
    f.window.wait = false;
    // One tile east: the new column may not have arrived yet; what is
    // drawn meanwhile is the old window's share of the new one, or all of it.
    f.window.update(eye(&f, 544.0, 530.0, 4.0), &f.resident).unwrap();
    let wanted = f.window.wanted().unwrap();
    assert_eq!(wanted.x0, first.x0 + 1);
    let shared = first.intersect(wanted).unwrap();
    let active = f.window.active().unwrap();
    assert!(active == shared || active == wanted, "{active:?}");
    // A new level: nothing of the old one is drawn until its tiles arrive.
    f.window.wait = true;
    f.window.update(eye(&f, 544.0, 530.0, 12.0), &f.resident).unwrap();
    assert_eq!(f.window.active().unwrap().level, 1);
}

#[test]
fn the_host_cache_stays_within_its_bound_along_a_drive() {
    let mut f = fixture("drive.hpyr", false);
    let (_, capacity) = f.window.cache_tiles();
    assert_eq!(capacity, CACHE_WINDOWS * 16);
    let mut uploaded = 0;
    let mut most_pending = 0;
    for step in 0..120 {
        let t = f64::from(step) / 119.0;
        let e = eye(&f, 60.0 + 900.0 * t, 100.0 + 800.0 * t * t, 4.0 + 20.0 * t);
        let uploads = f.window.update(e, &f.resident).unwrap().len();
        assert!(uploads <= UPLOAD_BUDGET_TILES, "step {step}: {uploads} tiles uploaded");
        uploaded += uploads;
        let (tiles, capacity) = f.window.cache_tiles();
        assert!(
            tiles <= capacity,
            "step {step}: {tiles} tiles cached, at most {capacity}"
        );
        most_pending = most_pending.max(f.window.stream.pending());
        if let (Some(a), Some(w)) = (f.window.active(), f.window.wanted()) {
            assert!(a.intersect(w) == Some(a), "step {step}: {a:?} outside {w:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    assert!(most_pending <= capacity);
    assert!(uploaded >= 16, "{uploaded} tiles uploaded along the drive");
    // Standing still, the budgeted frames fill the whole window, nearest
    // tiles first.
    let e = eye(&f, 960.0, 900.0, 24.0);
    let mut frames = 0;
    while f.window.active() != f.window.wanted() || frames == 0 {
        let uploads = f.window.update(e, &f.resident).unwrap();
        assert!(uploads.len() <= UPLOAD_BUDGET_TILES);
        frames += 1;
        assert!(frames < 200, "the window never filled");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    assert!(f.window.active().is_some());
    // The mirror never holds more than the window's image.
    assert_eq!(f.window.mirror.len(), 256 * 256);
}
