//! The terrain's compute path (issue 28, [`crate::terrain::visibility`])
//! against the hardware path it replaces, on the Jacksboro DEM under
//! validation and synchronization validation: the same views rendered by
//! both must agree to a mean FLIP of at most [`MAX_MEAN_FLIP`] and in view
//! depth to 1e-4 relative on at least [`MIN_DEPTH_AGREEMENT`] of the pixels
//! both cover (silhouettes may pick the other of two triangles), and cover
//! the same pixels but for [`MAX_COVERAGE_DIFFERENCE`] of them.

use crate::points::build::spt::{epsilon_from_pixels, SptOptions};
use crate::points::scene::scatter_rocks;
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::technique::HARDWARE_CASTERS;
use crate::terrain::visibility::RasterPath;
use crate::test_support::{assert_validation_clean, dump_pngs, jacksboro_field, mean_flip, validated_context};
use crate::view::aov::CLASS_ROCK;
use crate::view::rig::ViewSpec;
use crate::view::{Lighting, SunPosition};
use glam::DVec3;

const WIDTH: u32 = 192;
const HEIGHT: u32 = 108;
/// Mean FLIP of the compute path against the hardware path (issue 28's bound).
const MAX_MEAN_FLIP: f32 = 0.02;
/// Share of the pixels both paths cover whose view depths agree to 1e-4.
const MIN_DEPTH_AGREEMENT: f64 = 0.99;
/// Share of the pixels only one path covers.
const MAX_COVERAGE_DIFFERENCE: f64 = 0.002;

/// The terrain tests' views, and the valley view with a near plane of
/// 0.5 m (triangles crossing it take the homogeneous path).
fn cameras(scene: &Scene) -> Vec<(&'static str, Camera)> {
    let mut cameras = super::terrain::views(scene);
    let valley = cameras[2].1;
    cameras.push(("near-plane", Camera { near: 0.5, ..valley }));
    cameras
}

fn render(scene: &Scene, cameras: &[(&str, Camera)], raster: RasterPath) -> Vec<FrameImages> {
    let settings = RenderSettings {
        raster,
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    let frames: Vec<Vec<Camera>> = cameras.iter().map(|&(_, c)| vec![c]).collect();
    render_with(scene, &frames, settings)
}

/// Each frame of `frames` (a camera per view) rendered and read back, the
/// views of every frame in a row.
pub(super) fn render_with(scene: &Scene, frames: &[Vec<Camera>], settings: RenderSettings) -> Vec<FrameImages> {
    let (ctx, report) = validated_context();
    let raster = settings.raster;
    let frames = {
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        assert_eq!(renderer.raster_path(), raster);
        let frames = (frames.iter())
            .flat_map(|cameras| {
                let frame = renderer.render_views(cameras).expect("frame");
                renderer.read_views(&frame).expect("read")
            })
            .collect();
        renderer.finish().expect("finish");
        frames
    };
    drop(ctx);
    assert_validation_clean(&report);
    frames
}

#[test]
fn compute_path_matches_the_hardware_path() {
    let scene = Scene::new(jacksboro_field());
    let cameras = cameras(&scene);
    let hardware = render(&scene, &cameras, RasterPath::Hardware);
    let compute = render(&scene, &cameras, RasterPath::Compute);
    compare(&cameras, &hardware, &compute);
}

/// The compute path's shadow casters (`terrain.shadow` in compute, culled
/// per cascade, copied into the atlas) against the hardware's on frames
/// otherwise equal (both on the compute path), under a low sun that puts
/// a good share of the terrain in shadow: the sun visibility AOV agrees to
/// 0.1 on at least [`MIN_SUN_AGREEMENT`] of the terrain's pixels.
#[test]
fn compute_shadow_casters_match_the_hardware_casters() {
    let scene = Scene::new(jacksboro_field());
    let cameras = cameras(&scene);
    let settings = RenderSettings {
        raster: RasterPath::Compute,
        lighting: Some(Lighting {
            sun: SunPosition::Angles {
                elevation_deg: 8.0,
                azimuth_deg: 120.0,
            },
            ..Lighting::default()
        }),
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    let frames: Vec<Vec<Camera>> = cameras.iter().map(|&(_, c)| vec![c]).collect();
    HARDWARE_CASTERS.set(true);
    let hardware = render_with(&scene, &frames, settings.clone());
    HARDWARE_CASTERS.set(false);
    let compute = render_with(&scene, &frames, settings);
    let (mut terrain, mut shadowed, mut agree) = (0usize, 0usize, 0usize);
    for (((name, _), h), c) in cameras.iter().zip(&hardware).zip(&compute) {
        dump_pngs(
            &[
                (&format!("{name}-hardware-casters"), &h.rgba8),
                (&format!("{name}-compute-casters"), &c.rgba8),
            ],
            WIDTH,
            HEIGHT,
        );
        let mut view_agree = (0usize, 0usize);
        for (k, depth) in h.depth.iter().enumerate() {
            if !depth.is_finite() {
                continue;
            }
            let (sun_h, sun_c) = (h.visibility[2 * k], c.visibility[2 * k]);
            view_agree.0 += 1;
            view_agree.1 += usize::from((sun_h - sun_c).abs() <= 0.1);
            shadowed += usize::from(sun_h < 0.5);
        }
        eprintln!(
            "{name}: sun visibility agrees on {} of {} pixels",
            view_agree.1, view_agree.0
        );
        terrain += view_agree.0;
        agree += view_agree.1;
    }
    let share = |n: usize| n as f64 / terrain.max(1) as f64;
    assert!(
        share(shadowed) >= 0.05,
        "only {:.3} of the terrain in shadow",
        share(shadowed)
    );
    assert!(
        share(agree) >= MIN_SUN_AGREEMENT,
        "sun visibility agrees on {:.4}",
        share(agree)
    );
}

/// Share of the terrain's pixels whose sun visibility agrees to 0.1 with
/// the compute casters and the hardware's.
const MIN_SUN_AGREEMENT: f64 = 0.99;

/// The point objects' compute casters (`points.shadow` in compute, into the
/// atlas's depth bits with the terrain's) against the hardware casters:
/// rocks under a low sun, the sun visibility of every pixel agrees to 0.1
/// on at least [`MIN_SUN_AGREEMENT`] of them, and the rocks' shadows are
/// there (without the rocks, the compute frame loses sun on fewer pixels).
#[test]
fn compute_point_casters_match_the_hardware_casters() {
    let spt = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), HEIGHT).expect("epsilon"),
        ..SptOptions::default()
    };
    let bare = Scene::new(jacksboro_field());
    let mut scene = bare.clone();
    scene.points = scatter_rocks(&scene.heights, 2, 2000, 400, (30.0, 80.0), 7, &spt).expect("rocks");
    let frames = [vec![cameras(&scene)[4].1]];
    let settings = RenderSettings {
        raster: RasterPath::Compute,
        lighting: Some(Lighting {
            sun: SunPosition::Angles {
                elevation_deg: 10.0,
                azimuth_deg: 200.0,
            },
            ..Lighting::default()
        }),
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    HARDWARE_CASTERS.set(true);
    let hardware = render_with(&scene, &frames, settings.clone());
    HARDWARE_CASTERS.set(false);
    let compute = render_with(&scene, &frames, settings.clone());
    let without = render_with(&bare, &frames, settings);
    let sun = |f: &FrameImages, k: usize| f.visibility[2 * k];
    let (h, c, w) = (&hardware[0], &compute[0], &without[0]);
    dump_pngs(
        &[
            ("rocks-hardware-casters", &h.rgba8),
            ("rocks-compute-casters", &c.rgba8),
        ],
        WIDTH,
        HEIGHT,
    );
    let seen: Vec<usize> = (0..h.depth.len()).filter(|&k| h.depth[k].is_finite()).collect();
    let agree = seen.iter().filter(|&&k| (sun(h, k) - sun(c, k)).abs() <= 0.1).count();
    let rock_shadow = |f: &FrameImages| seen.iter().filter(|&&k| sun(w, k) - sun(f, k) > 0.5).count();
    let share = agree as f64 / seen.len().max(1) as f64;
    eprintln!(
        "sun visibility agrees on {agree} of {} pixels; rock shadows: {} pixels (compute), {} (hardware)",
        seen.len(),
        rock_shadow(c),
        rock_shadow(h)
    );
    assert!(share >= MIN_SUN_AGREEMENT, "sun visibility agrees on {share:.4}");
    // Measured on lavapipe: 32 pixels in both (0 if the point casters wrote nothing).
    assert!(rock_shadow(c) >= 20, "the rocks shadow {} pixels", rock_shadow(c));
    assert!(
        rock_shadow(c).abs_diff(rock_shadow(h)) * 5 <= rock_shadow(h),
        "rock shadows: {} pixels (compute) against {} (hardware)",
        rock_shadow(c),
        rock_shadow(h)
    );
}

/// Rocks on the terrain, half hidden behind it, in a two-view rig with
/// direct texturing: the points depth-test against the compute path's
/// depth buffer (`terrain.depth`) as against `terrain.draw`'s.
#[test]
fn points_and_rig_views_occlude_alike_in_both_paths() {
    let field = jacksboro_field();
    let spt = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), HEIGHT).expect("epsilon"),
        ..SptOptions::default()
    };
    let mut scene = Scene::new(field);
    scene.points = scatter_rocks(&scene.heights, 2, 2000, 400, (30.0, 80.0), 7, &spt).expect("rocks");
    let base = cameras(&scene)[4].1;
    let right = Camera {
        eye: base.eye + DVec3::new(400.0, -300.0, 0.0),
        ..base
    };
    let views: Vec<ViewSpec> = ["left", "right"]
        .iter()
        .map(|name| ViewSpec {
            name: name.to_string(),
            ..ViewSpec::new(WIDTH, HEIGHT)
        })
        .collect();
    let frames = [vec![base, right]];
    let settings = |raster| RenderSettings {
        raster,
        texturing: TexturingMode::Direct,
        ..RenderSettings::for_views(views.clone())
    };
    let hardware = render_with(&scene, &frames, settings(RasterPath::Hardware));
    let compute = render_with(&scene, &frames, settings(RasterPath::Compute));
    assert_eq!(hardware.len(), 2, "two views");
    let names = [("rig-left", base), ("rig-right", right)];
    compare(&names, &hardware, &compute);
    let rocks = |f: &FrameImages| f.class.iter().filter(|&&c| c == CLASS_ROCK).count();
    assert!(rocks(&compute[0]) > 20, "{} rock pixels", rocks(&compute[0]));
}

/// With the splats on the compute path too, the frame shades once: the
/// points test against the terrain's visibility keys and `terrain.shade`
/// comes after their `points.accumulate` and resolves their sums (issue
/// 29): no `terrain.depth`, no `points.normalize`. The hardware path
/// keeps both of its passes.
#[test]
fn terrain_shade_resolves_the_splats_on_the_compute_path() {
    let mut scene = Scene::new(jacksboro_field());
    let spt = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), HEIGHT).expect("epsilon"),
        ..SptOptions::default()
    };
    scene.points = scatter_rocks(&scene.heights, 2, 200, 400, (30.0, 80.0), 7, &spt).expect("rocks");
    let (ctx, report) = validated_context();
    for raster in [RasterPath::Compute, RasterPath::Hardware] {
        let settings = RenderSettings {
            raster,
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let names = renderer.pass_names();
        let at = |pass: &str| names.iter().position(|n| n == pass);
        let compute = raster == RasterPath::Compute;
        assert!(at("terrain.depth").is_none(), "{raster:?}: {names:?}");
        assert_eq!(at("points.normalize").is_some(), !compute, "{raster:?}: {names:?}");
        if compute {
            let (accumulate, shade) = (at("points.accumulate"), at("terrain.shade"));
            assert!(accumulate.is_some() && shade > accumulate, "{names:?}");
            assert!(at("points.clear") > at("terrain.raster_big"), "{names:?}");
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// Asserts the bounds of the module docs on each view's pair of frames.
fn compare(cameras: &[(&str, Camera)], hardware: &[FrameImages], compute: &[FrameImages]) {
    for (((name, _), h), c) in cameras.iter().zip(hardware).zip(compute) {
        dump_pngs(
            &[
                (&format!("{name}-hardware"), &h.rgba8),
                (&format!("{name}-compute"), &c.rgba8),
            ],
            WIDTH,
            HEIGHT,
        );
        let flip = mean_flip(&h.rgba8, &c.rgba8, WIDTH, HEIGHT).0;
        let (mut both, mut agree, mut one) = (0usize, 0usize, 0usize);
        for (&dh, &dc) in h.depth.iter().zip(&c.depth) {
            match (dh.is_finite(), dc.is_finite()) {
                (true, true) => {
                    both += 1;
                    agree += usize::from((dh - dc).abs() <= 1e-4 * dh.abs());
                }
                (false, false) => {}
                _ => one += 1,
            }
        }
        let pixels = h.depth.len() as f64;
        let agreement = agree as f64 / both.max(1) as f64;
        eprintln!(
            "{name}: mean FLIP {flip:.4}, depth agreement {agreement:.4} of {both} pixels, {one} covered by one path only"
        );
        assert!(both > 0, "{name}: no terrain");
        assert!(flip <= MAX_MEAN_FLIP, "{name}: mean FLIP {flip:.4}");
        assert!(
            agreement >= MIN_DEPTH_AGREEMENT,
            "{name}: depth agrees on {agreement:.4}"
        );
        assert!(
            one as f64 / pixels <= MAX_COVERAGE_DIFFERENCE,
            "{name}: {one} pixels covered by one path"
        );
    }
}

/// A CPU twin of `terrain.raster`'s coverage test
/// (`glsl/include/terrain_visibility.glsl`: fixed point with 8 sub-pixel
/// bits, edge functions, the tie rule): which pixel centres of a
/// `width`×`height` image the screen triangle `v` covers.
fn twin_coverage(v: [[f32; 2]; 3], (width, height): (i64, i64)) -> Vec<(i64, i64)> {
    let fixed = |p: [f32; 2]| [(p[0] * 256.0).round() as i64, (p[1] * 256.0).round() as i64];
    let edge = |a: [i64; 2], b: [i64; 2], p: [i64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let bias = |a: [i64; 2], b: [i64; 2]| {
        let d = [b[0] - a[0], b[1] - a[1]];
        if d[1] < 0 || (d[1] == 0 && d[0] > 0) {
            0
        } else {
            -1
        }
    };
    let (a, mut b, mut c) = (fixed(v[0]), fixed(v[1]), fixed(v[2]));
    let area = edge(a, b, c);
    if area == 0 {
        return Vec::new();
    }
    if area < 0 {
        std::mem::swap(&mut b, &mut c);
    }
    let biases = [bias(b, c), bias(c, a), bias(a, b)];
    let mut covered = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let p = [x * 256 + 128, y * 256 + 128];
            let e = [edge(b, c, p), edge(c, a, p), edge(a, b, p)];
            if e.iter().zip(&biases).all(|(e, b)| e + b >= 0) {
                covered.push((x, y));
            }
        }
    }
    covered
}

/// The tie rule is watertight: a jittered grid of triangles (both diagonal
/// directions, both windings, vertices and edges exactly on pixel centres
/// among them) covering the whole image covers every pixel centre exactly
/// once.
#[test]
fn the_coverage_rule_covers_every_pixel_of_a_tessellation_once() {
    let (width, height) = (48i64, 32i64);
    let (columns, rows) = (13usize, 9usize);
    let mut state = 0x9e37_79b9u32;
    let mut jitter = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state % 1000) as f32 / 1000.0 - 0.5
    };
    // Vertices 4 px apart from -2 px, jittered by up to ±1.2 px; every third
    // one snapped to a pixel centre or a pixel-centre column.
    let mut vertices = vec![[0.0f32; 2]; columns * rows];
    for r in 0..rows {
        for c in 0..columns {
            let inner = c > 0 && r > 0 && c + 1 < columns && r + 1 < rows;
            let mut p = [c as f32 * 4.5 - 2.0, r as f32 * 4.5 - 2.0];
            if inner {
                p[0] += 2.4 * jitter();
                p[1] += 2.4 * jitter();
                match (r * columns + c) % 3 {
                    0 => p = [p[0].floor() + 0.5, p[1].floor() + 0.5],
                    1 => p[0] = p[0].floor() + 0.5,
                    _ => {}
                }
            }
            vertices[r * columns + c] = p;
        }
    }
    let mut counts = vec![0u32; (width * height) as usize];
    for r in 0..rows - 1 {
        for c in 0..columns - 1 {
            let i = |dc: usize, dr: usize| vertices[(r + dr) * columns + c + dc];
            let quad = [i(0, 0), i(1, 0), i(0, 1), i(1, 1)];
            let triangles = match (r + c) % 2 {
                0 => [[quad[0], quad[1], quad[2]], [quad[1], quad[3], quad[2]]],
                _ => [[quad[0], quad[1], quad[3]], [quad[0], quad[2], quad[3]]],
            };
            for (k, mut t) in triangles.into_iter().enumerate() {
                if (r + k) % 2 == 0 {
                    t.swap(1, 2);
                }
                for (x, y) in twin_coverage(t, (width, height)) {
                    counts[(y * width + x) as usize] += 1;
                }
            }
        }
    }
    let wrong: Vec<_> = (counts.iter().enumerate())
        .filter(|(_, &n)| n != 1)
        .map(|(p, &n)| (p as i64 % width, p as i64 / width, n))
        .collect();
    assert!(
        wrong.is_empty(),
        "pixels not covered exactly once (x, y, times): {wrong:?}"
    );
}

/// The twin can fail: without the tie rule (every edge inclusive) the same
/// tessellation covers some centre twice.
#[test]
fn an_inclusive_rule_would_double_cover_shared_edges() {
    // Two triangles sharing the vertical edge x = 2.5 through pixel centres.
    let left = [[0.0, 0.0], [2.5, 0.0], [2.5, 4.0]];
    let right = [[2.5, 0.0], [5.0, 0.0], [2.5, 4.0]];
    let both = |t| twin_coverage(t, (5, 4));
    let (l, r) = (both(left), both(right));
    let shared: Vec<_> = l.iter().filter(|p| r.contains(p)).collect();
    assert!(shared.is_empty(), "{shared:?} covered twice");
    // The centres on the shared edge, (2, y), belong to exactly one side.
    for y in 0..4 {
        assert!(l.contains(&(2, y)) != r.contains(&(2, y)), "centre (2, {y})");
    }
}

/// On the GPU: a field seen from straight above fills the image, every
/// pixel covered by the compute path (a crack between two grid triangles
/// would show the sky).
#[test]
fn a_field_from_above_has_no_crack_in_the_compute_path() {
    let field = crate::io::heightmap::HeightField::from_fn(33, 33, glam::DVec2::splat(100.0), |c, r| {
        (10.0 * ((c as f64) * 0.7).sin() * ((r as f64) * 0.5).cos()) as f32
    });
    let scene = Scene::new(field);
    let camera = Camera {
        eye: DVec3::new(1600.0, 1600.0, 1500.0),
        target: DVec3::new(1600.0, 1600.0, 0.0),
        up: DVec3::Y,
        ..scene.default_camera()
    };
    let frame = &render(&scene, &[("above", camera)], RasterPath::Compute)[0];
    let holes: Vec<_> = (frame.depth.iter().enumerate())
        .filter(|(_, d)| !d.is_finite())
        .map(|(p, _)| (p as u32 % WIDTH, p as u32 / WIDTH))
        .collect();
    assert!(
        holes.is_empty(),
        "{} pixels without terrain: {:?}",
        holes.len(),
        &holes[..holes.len().min(20)]
    );
}
