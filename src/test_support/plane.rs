//! The checkerboard plane of the point-rendering tests (`src/points/tests/render.rs`,
//! `src/points/tests/primitives.rs`, `src/points/tests/single_pass.rs`): a regularly sampled plane seen at a
//! grazing angle, its analytic (supersampled) reference, the mean FLIP of a
//! render against it, and its holes (W = 0 where the plane is seen).

use crate::points::build::clip::ClipLines;
use crate::points::build::spt::{build_spt, epsilon_from_pixels, SptOptions};
use crate::points::render::{SplatMode, SplatSettings};
use crate::points::scene::{PointObject, PointScene, PointTransform};
use crate::points::Surfel;
use crate::renderer::{Camera, FrameImages, Scene};
use glam::{DVec3, Vec3};

use super::{dump_pngs, flip_errors, linear_to_srgb8, srgb8_to_linear};

/// The image size of the plane tests.
pub const WIDTH: u32 = 320;
pub const HEIGHT: u32 = 200;
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
    plane_scene_clipped(radius, |_| Some(ClipLines::NONE))
}

/// The plane with the surfels `clip` keeps (Some) and their clip lines.
pub fn plane_scene_clipped(radius: f32, clip: impl Fn(Vec3) -> Option<ClipLines>) -> Scene {
    let n = (SIDE / SPACING) as usize;
    let mut surfels = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = Vec3::new((i as f32 + 0.5) * SPACING, (j as f32 + 0.5) * SPACING, 0.0);
            if let Some(clip) = clip(p) {
                surfels.push(Surfel {
                    position: p,
                    normal: Vec3::Z,
                    radius,
                    color: if checker(p.x as f64, p.y as f64) { LIGHT } else { DARK },
                    clip,
                });
            }
        }
    }
    let options = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), HEIGHT).unwrap(),
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
    let aspect = WIDTH as f64 / HEIGHT as f64;
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let (f, r, u) = (camera.forward(), camera.right(), camera.image_up());
    let albedo = |c: [u8; 3]| srgb8_to_linear(c[0]);
    let hit = |px: f64, py: f64| -> Option<(f64, f64)> {
        let x = (px / WIDTH as f64 * 2.0 - 1.0) * tan * aspect;
        let y = (1.0 - py / HEIGHT as f64 * 2.0) * tan;
        let d = f + r * x + u * y;
        if d.z >= 0.0 {
            return None;
        }
        let t = -camera.eye.z / d.z;
        let p = camera.eye + d * t;
        (p.x > margin && p.x < SIDE as f64 - margin && p.y > margin && p.y < SIDE as f64 - margin).then_some((p.x, p.y))
    };
    let mut out = Vec::with_capacity((WIDTH * HEIGHT) as usize);
    for py in 0..HEIGHT {
        for px in 0..WIDTH {
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
    dump_pngs(&[("test", &test), ("ref", &expected)], WIDTH, HEIGHT);
    let errors = flip_errors(&expected, &test, WIDTH, HEIGHT);
    let (sum, n) = errors
        .iter()
        .zip(reference)
        .filter(|(_, r)| r.is_some())
        .fold((0.0, 0), |(s, n), (e, _)| (s + e, n + 1));
    sum / n as f32
}

/// Settings of `mode` writing the splats' albedo (no shading).
pub fn unlit(mode: SplatMode) -> SplatSettings {
    SplatSettings {
        mode,
        shaded: false,
        ..SplatSettings::default()
    }
}

/// Pixels where `covered` is Some but W is 0 (or NaN).
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
