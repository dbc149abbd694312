//! Helpers of the point-rendering tests (`src/points/tests/render.rs`,
//! `src/points/tests/hybrid.rs`, `src/points/tests/primitives.rs`): one validated
//! frame with its point statistics and the bunny scene (the grazing
//! checkerboard is in `plane.rs`).

use crate::points::render::{PointFrameStats, SplatSettings};
use crate::points::scene::{load_point_object, PointLoadOptions, PointObject};
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::RasterPath;
use glam::DVec3;

use super::{assert_validation_clean, data, validated_context};

/// One frame of `scene` at `width`×`height` under validation, with its
/// point statistics; panics on any validation message.
pub fn render_points(
    scene: &Scene,
    camera: &Camera,
    points: SplatSettings,
    size: (u32, u32),
) -> (FrameImages, PointFrameStats) {
    render_points_on(scene, camera, (points, RasterPath::Auto), size)
}

/// As [`render_points`], on rasterizer path `raster` (the splats' compute
/// passes or the hardware rasterizer).
pub fn render_points_on(
    scene: &Scene,
    camera: &Camera,
    (points, raster): (SplatSettings, RasterPath),
    (width, height): (u32, u32),
) -> (FrameImages, PointFrameStats) {
    let (ctx, report) = validated_context();
    let out = {
        let settings = RenderSettings {
            points,
            raster,
            ..RenderSettings::new(width, height)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        let frame = renderer.render(camera).and_then(|f| renderer.read(&f)).expect("frame");
        renderer.finish().expect("finish");
        let stats = renderer.take_point_stats().expect("stats");
        (frame, *stats.last().expect("one frame of point statistics"))
    };
    drop(ctx);
    assert_validation_clean(&report);
    out
}

/// Pixels of two frames whose sRGB8 differs by more than `tolerance` in a channel.
pub fn pixels_differing(a: &FrameImages, b: &FrameImages, tolerance: u8) -> usize {
    (a.rgba8.chunks_exact(4).zip(b.rgba8.chunks_exact(4)))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > tolerance))
        .count()
}

/// The Stanford bunny sampled into 20 000 surfels (y-up: stand it up with
/// the transform `r=90,0,0`); `hybrid` keeps its triangles (§10.1.8).
pub fn bunny_object(hybrid: bool) -> PointObject {
    let options = PointLoadOptions {
        mesh_samples: 20_000,
        hybrid,
        ..PointLoadOptions::default()
    };
    load_point_object(&data("models/stanford-bunny.obj"), &options).expect("bunny")
}

/// Looking at the standing bunny from `distance` metres, slightly from above.
pub fn bunny_camera(distance: f64) -> Camera {
    Camera {
        eye: DVec3::new(0.0, -distance, 0.25 * distance + 0.1),
        target: DVec3::new(-0.02, 0.0, 0.1),
        up: DVec3::Z,
        fov_y_deg: 40.0,
        near: 0.01,
        far: 100.0,
    }
}
