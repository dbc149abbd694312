//! Helpers of the point-rendering tests (`tests/points_render.rs`,
//! `tests/points_hybrid.rs`, `tests/points_primitives.rs`): one validated
//! frame with its point statistics, the bunny scene, and the grazing
//! checkerboard with its analytic reference.

use alpenglow::points::build::spt::{build_spt, epsilon_from_pixels, SptOptions};
use alpenglow::points::render::{PointFrameStats, SplatMode, SplatSettings};
use alpenglow::points::scene::{load_point_object, PointLoadOptions, PointObject, PointScene, PointTransform};
use alpenglow::points::Surfel;
use alpenglow::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use glam::{DVec3, Vec3};

use super::{
    assert_validation_clean, data, dump_pngs, flip_errors, linear_to_srgb8, srgb8_to_linear, validated_context,
};

/// One frame of `scene` at `width`×`height` under validation, with its
/// point statistics; panics on any validation message.
pub fn render_points(
    scene: &Scene,
    camera: &Camera,
    points: SplatSettings,
    (width, height): (u32, u32),
) -> (FrameImages, PointFrameStats) {
    let (ctx, report) = validated_context();
    let out = {
        let settings = RenderSettings {
            points,
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

// The grazing checkerboard of `tests/points_render.rs` and
// `tests/points_primitives.rs`: a regularly sampled plane seen at a grazing
// angle, and its analytic (supersampled) reference.

/// Size of the checkerboard renders.
pub const PLANE_WIDTH: u32 = 320;
pub const PLANE_HEIGHT: u32 = 200;
/// The far field compared for Moiré: plane points beyond y = 4 m (≥ 5 m from the eye).
pub const FAR_FIELD_Y: f64 = 4.0;

/// Plane z = 0 over [0, SIDE]², surfels every SPACING, checker squares of SQUARE.
pub const SIDE: f32 = 12.0;
pub const SPACING: f32 = 0.06;
pub const SQUARE: f32 = 0.5;
pub const DARK: [u8; 3] = [40, 40, 40];
pub const LIGHT: [u8; 3] = [230, 230, 230];

pub fn checker(x: f64, y: f64) -> bool {
    ((x / SQUARE as f64).floor() as i64 + (y / SQUARE as f64).floor() as i64).rem_euclid(2) == 0
}

pub fn plane_scene(radius: f32) -> Scene {
    let n = (SIDE / SPACING) as usize;
    let mut surfels = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = Vec3::new((i as f32 + 0.5) * SPACING, (j as f32 + 0.5) * SPACING, 0.0);
            surfels.push(Surfel {
                position: p,
                normal: Vec3::Z,
                radius,
                color: if checker(p.x as f64, p.y as f64) { LIGHT } else { DARK },
                clip: Default::default(),
            });
        }
    }
    let options = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), PLANE_HEIGHT).unwrap(),
        ..SptOptions::default()
    };
    let tree = build_spt(&surfels, &options, &mut |_| {}).expect("plane tree");
    let mut points = PointScene::default();
    points.add(PointObject::new("checkerboard", tree), PointTransform::default());
    Scene::points_only(points)
}

pub fn grazing_camera() -> Camera {
    Camera {
        eye: DVec3::new(6.0, -1.0, 0.6),
        target: DVec3::new(6.0, 8.0, 0.0),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.05,
        far: 100.0,
    }
}

/// Per pixel: None where the ray misses the plane (or hits within `margin`
/// of its border, or before y = `min_y`), else the checker albedo averaged
/// over `n`×`n` samples.
pub fn analytic_plane(camera: &Camera, n: usize, margin: f64, min_y: f64) -> Vec<Option<f32>> {
    let aspect = PLANE_WIDTH as f64 / PLANE_HEIGHT as f64;
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let (f, r, u) = (camera.forward(), camera.right(), camera.image_up());
    let albedo = |c: [u8; 3]| srgb8_to_linear(c[0]);
    let hit = |px: f64, py: f64| -> Option<(f64, f64)> {
        let x = (px / PLANE_WIDTH as f64 * 2.0 - 1.0) * tan * aspect;
        let y = (1.0 - py / PLANE_HEIGHT as f64 * 2.0) * tan;
        let d = f + r * x + u * y;
        if d.z >= 0.0 {
            return None;
        }
        let t = -camera.eye.z / d.z;
        let p = camera.eye + d * t;
        (p.x > margin && p.x < SIDE as f64 - margin && p.y > margin && p.y < SIDE as f64 - margin).then_some((p.x, p.y))
    };
    let mut out = Vec::with_capacity((PLANE_WIDTH * PLANE_HEIGHT) as usize);
    for py in 0..PLANE_HEIGHT {
        for px in 0..PLANE_WIDTH {
            let centre = hit(px as f64 + 0.5, py as f64 + 0.5).filter(|&(_, y)| y >= min_y);
            out.push(centre.map(|_| {
                let mut sum = 0.0;
                let mut count = 0;
                for sy in 0..n {
                    for sx in 0..n {
                        let q = hit(
                            px as f64 + (sx as f64 + 0.5) / n as f64,
                            py as f64 + (sy as f64 + 0.5) / n as f64,
                        );
                        if let Some((x, y)) = q {
                            sum += albedo(if checker(x, y) { LIGHT } else { DARK });
                            count += 1;
                        }
                    }
                }
                sum / count.max(1) as f32
            }));
        }
    }
    out
}

/// Mean FLIP of the rendered albedo against `reference` over the pixels where it is Some.
pub fn plane_flip(frame: &FrameImages, reference: &[Option<f32>]) -> f32 {
    let test: Vec<u8> = frame
        .hdr
        .chunks_exact(4)
        .flat_map(|p| {
            let g = linear_to_srgb8(p[1]);
            [g, g, g, 255]
        })
        .collect();
    let expected: Vec<u8> = reference
        .iter()
        .zip(test.chunks_exact(4))
        .flat_map(|(r, t)| match r {
            Some(v) => {
                let g = linear_to_srgb8(*v);
                [g, g, g, 255]
            }
            None => [t[0], t[1], t[2], 255],
        })
        .collect();
    dump_pngs(&[("test", &test), ("ref", &expected)], PLANE_WIDTH, PLANE_HEIGHT);
    let errors = flip_errors(&expected, &test, PLANE_WIDTH, PLANE_HEIGHT);
    let (sum, n) = errors
        .iter()
        .zip(reference)
        .filter(|(_, r)| r.is_some())
        .fold((0.0, 0), |(s, n), (e, _)| (s + e, n + 1));
    sum / n as f32
}

pub fn unlit(mode: SplatMode) -> SplatSettings {
    SplatSettings {
        mode,
        shaded: false,
        ..SplatSettings::default()
    }
}

pub fn holes(frame: &FrameImages, covered: &[Option<f32>]) -> usize {
    let w = frame.weight.as_ref().expect("W channel");
    w.iter()
        .zip(covered)
        .filter(|(w, c)| c.is_some() && (**w <= 0.0 || w.is_nan()))
        .count()
}

/// Mean FLIP of the checkerboard sampled once per pixel at the pixel centre
/// (aliased) against `reference`: the scale of aliasing.
pub fn point_sampled_flip(camera: &Camera, reference: &[Option<f32>], like: &FrameImages) -> f32 {
    let point_sampled = analytic_plane(camera, 1, 0.1, FAR_FIELD_Y);
    let fake = FrameImages {
        hdr: point_sampled
            .iter()
            .flat_map(|v| {
                let g = v.unwrap_or(0.0);
                [g, g, g, 1.0]
            })
            .collect(),
        ..like.clone()
    };
    plane_flip(&fake, reference)
}
