//! The affine EWA kernel against the perspective-accurate one (dissertation
//! §10.2, Figs. 10.15–10.17: the text compares perspective-accurate splatting
//! with the affine approximation of Zwicker et al. 2001), on the checkerboard
//! plane (surfels every 6 cm, radius 6 cm) and its 16×16 supersampled analytic
//! reference, under validation:
//!
//! * the eye 4 cm above the plane, looking along it: the splats near the eye
//!   are large against their distance (radius / distance up to ≈ 0.5) and seen
//!   at grazing angles, where the Jacobian at the splat centre is a poor
//!   stand-in for the projection: affine EWA smears them into ellipses far
//!   larger and more distorted than their true outlines; it still leaves no
//!   holes (the screen-space low-pass filter keeps every footprint ≥ a pixel),
//!   but its mean FLIP is far above the perspective-accurate kernel's
//!   ([`CLOSE_FLIP_MARGIN`], [`CLOSE_FLIP_PERSPECTIVE`]);
//! * face-on, and at the render tests' grazing view 60 cm above the plane
//!   (radius / distance ≤ 0.05), the projection is nearly affine over a splat
//!   and both kernels give about the same image ([`FAR_FLIP_TOLERANCE`]); the
//!   hardware path and single-pass splatting draw the affine kernel too (one
//!   shared set-up), without holes.
//!
//! Opaque discs with radius = half the cell diagonal (Fig. 10.17) leave no
//! gaps with either kernel here: on a regular plane the affine outlines'
//! errors (larger on the far side, smaller on the near side) cancel to first
//! order where neighbours meet, so the text's holes need larger splats than
//! this plane's.

use crate::points::render::{SplatKernel, SplatMode, SplatSettings};
use crate::renderer::{Camera, FrameImages, Scene};
use crate::test_support::plane::{
    analytic_plane, grazing_camera, holes, plane_flip, plane_scene, unlit, HEIGHT, SPACING, WIDTH,
};
use crate::test_support::points::render_points_on;
use crate::RasterPath;
use glam::DVec3;

/// Perspective-accurate EWA's mean FLIP with the eye 4 cm above the plane
/// (measured 0.167 on lavapipe: the reconstruction's blur over a sample
/// spacing, which covers many pixels this close).
const CLOSE_FLIP_PERSPECTIVE: f32 = 0.20;
/// How far affine EWA's mean FLIP lies above the perspective-accurate one's
/// with the eye 4 cm above the plane (measured 0.419 against 0.167).
const CLOSE_FLIP_MARGIN: f32 = 0.15;
/// The largest difference of the two kernels' mean FLIP face-on and at the
/// 60 cm grazing view (measured 0.1731 and 0.1731; 0.1673 and 0.1656).
const FAR_FLIP_TOLERANCE: f32 = 0.01;

fn settings(mode: SplatMode, kernel: SplatKernel) -> SplatSettings {
    SplatSettings { kernel, ..unlit(mode) }
}

fn render(scene: &Scene, camera: &Camera, settings: SplatSettings, raster: RasterPath) -> FrameImages {
    let (frame, stats) = render_points_on(scene, camera, (settings, raster), (WIDTH, HEIGHT));
    eprintln!(
        "{} {} ({}): {}",
        settings.kernel.name(),
        settings.mode.name(),
        raster.name(),
        stats.summary()
    );
    frame
}

/// Mean FLIP of EWA with each kernel (compute path) against the supersampled
/// plane seen by `camera`; `holes_allowed` says which kernels must leave no
/// W = 0 pixel where the plane is seen.
fn kernel_flips(camera: &Camera, holes_allowed: [bool; 2]) -> [f32; 2] {
    let covered = analytic_plane(camera, 1, 0.1, 0.0);
    let reference = analytic_plane(camera, 16, 0.1, 0.0);
    let scene = plane_scene(SPACING);
    let mut k = 0;
    SplatKernel::ALL.map(|kernel| {
        let frame = render(&scene, camera, settings(SplatMode::Ewa, kernel), RasterPath::Compute);
        let gaps = holes(&frame, &covered);
        eprintln!("{}: {gaps} holes", kernel.name());
        assert!(
            holes_allowed[k] || gaps == 0,
            "{}: {gaps} W = 0 pixels inside the plane",
            kernel.name()
        );
        k += 1;
        plane_flip(&frame, &reference)
    })
}

#[test]
fn affine_ewa_distorts_splats_near_the_eye_at_grazing_angles() {
    let camera = Camera {
        eye: DVec3::new(6.05, -0.02, 0.04),
        target: DVec3::new(6.05, 1.0, 0.0),
        near: 0.002,
        ..grazing_camera()
    };
    // Perspective-accurate EWA culls the splats within 0.6° of edge-on
    // (MIN_COS_VIEW in splat_setup.glsl): beyond ≈ 4 m, at the horizon, a
    // few pixels stay empty this low; affine's taller far footprints cover them.
    let [perspective, affine] = kernel_flips(&camera, [true, false]);
    eprintln!("eye 4 cm above the plane, mean FLIP: perspective {perspective:.4}, affine {affine:.4}");
    assert!(
        perspective <= CLOSE_FLIP_PERSPECTIVE,
        "perspective-accurate EWA mean FLIP {perspective} > {CLOSE_FLIP_PERSPECTIVE}"
    );
    assert!(
        affine >= perspective + CLOSE_FLIP_MARGIN,
        "affine EWA mean FLIP {affine} not ≥ perspective-accurate {perspective} + {CLOSE_FLIP_MARGIN}"
    );
}

#[test]
fn affine_and_perspective_accurate_ewa_agree_face_on_and_far_away() {
    let face_on = Camera {
        eye: DVec3::new(6.0, 6.0, 3.0),
        target: DVec3::new(6.0, 6.0, 0.0),
        up: DVec3::Y,
        ..grazing_camera()
    };
    for (name, camera) in [("face-on", face_on), ("grazing, 60 cm", grazing_camera())] {
        let [perspective, affine] = kernel_flips(&camera, [false, false]);
        eprintln!("{name}: mean FLIP perspective {perspective:.4}, affine {affine:.4}");
        assert!(
            (affine - perspective).abs() <= FAR_FLIP_TOLERANCE,
            "{name}: affine {affine} and perspective-accurate {perspective} differ by more than {FAR_FLIP_TOLERANCE}"
        );
    }

    // One shared set-up: the hardware path's three passes and single-pass
    // splatting draw the affine kernel as well.
    let camera = grazing_camera();
    let covered = analytic_plane(&camera, 1, 0.1, 0.0);
    let scene = plane_scene(SPACING);
    for (mode, raster) in [
        (SplatMode::Ewa, RasterPath::Hardware),
        (SplatMode::SinglePass, RasterPath::Compute),
    ] {
        let frame = render(&scene, &camera, settings(mode, SplatKernel::Affine), raster);
        let gaps = holes(&frame, &covered);
        assert_eq!(gaps, 0, "affine {} ({}): {gaps} holes", mode.name(), raster.name());
    }
}
