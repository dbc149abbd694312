//! The ground query against what the GPU draws (issue 14, part 7;
//! dissertation §7.4.2–7.4.3, [`crate::terrain::ground`]), on the real
//! Jacksboro DEM with the default terrain settings.
//!
//! 1. A low camera (3 m above the ground) looks down at it; every pixel
//!    within 30 m is turned back into a world point from the rendered
//!    view-space depth (along the camera's forward axis, rays built like
//!    `Camera::ray_basis`). Those points must lie on the CPU twin of the
//!    view's mesh ([`DrawnSurface`]: the same warp, vertices, split
//!    octaves, detail and triangles) within 1 cm — what remains is `f32`
//!    rounding of world coordinates near 15 km (about 1 mm) and of the
//!    noise lookups. The same twin without detail (the bare B-spline mesh)
//!    misses by metres: the check can fail.
//! 2. The same points against [`Ground::height`], the finest level: the
//!    grid next to the camera (2–3 m) carries the detail octaves only up to
//!    its split octave (about 4.1 here), octaves 5–8 are bump-mapped. So
//!    the budget is statistical: an RMS of twice what the omitted octaves
//!    give at the vertices (the linear interpolation across the triangles
//!    adds about as much again), and a largest difference within the
//!    vertices' bound ([`Ground::omitted_detail_bound`]: every omitted
//!    octave at the tile's largest value). The bare B-spline breaks it.
//! 3. 300 random cameras 2 m above [`Ground::height`] are never under the
//!    drawn surface (the CPU twin of each view's mesh at the eye); 2 m
//!    above the bare B-spline, some are.
//!
//! 4. Straight down over the Rocky Mountain DEM, the warped grid's shading
//!    normals match a uniform grid's (the independent reference: no per-line
//!    warp, no shear): vertex normals are the surface's analytic ones, so
//!    the sheared quads of per-line warps no longer misread rough ground
//!    (central differences across them left rows of specks, up to ~40°).
//!
//! Validation and synchronization validation are on throughout.

use crate::io::heightmap::{load_heightmap, HeightmapOptions, RowOrder};
use crate::random::SplitMix64;
use crate::renderer::{Camera, RenderSettings, Renderer, Scene};
use crate::surface::bspline::sample_bspline;
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::ground::{octave_weight, DrawnSurface, Ground};
use crate::terrain::lod::{DebugScalar, LodFrame, LodMode};
use crate::test_support::{assert_validation_clean, data, jacksboro_field, validated_context};
use glam::{DVec2, DVec3};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 100;
/// Pixels whose ground point lies within this horizontal distance of the eye.
const NEAR: f64 = 30.0;

fn aspect() -> f64 {
    f64::from(WIDTH) / f64::from(HEIGHT)
}

/// At `eye`, looking along `heading` (radians from +x), `pitch` below the
/// horizon.
fn camera_at(eye: DVec3, heading: f64, pitch: f64) -> Camera {
    let forward = DVec3::new(heading.cos() * pitch.cos(), heading.sin() * pitch.cos(), -pitch.sin());
    Camera {
        eye,
        target: eye + 10.0 * forward,
        up: DVec3::Z,
        fov_y_deg: 60.0,
        near: 0.05,
        far: 100_000.0,
    }
}

/// The view's warped sketch map as the GPU receives it (`f32`).
fn warp_of(scene: &Scene, camera: &Camera, terrain: &TerrainSettings) -> Vec<DVec3> {
    let mut frame = LodFrame::default();
    frame
        .plan(&scene.heights, camera, aspect(), &terrain.lod, DebugScalar::None)
        .expect("LOD plan");
    frame.warp.positions.iter().map(|p| p.as_vec3().as_dvec3()).collect()
}

/// World points of the rendered pixels within [`NEAR`] of the eye.
fn rendered_points(camera: &Camera, depth: &[f32]) -> Vec<DVec3> {
    let tan_y = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let (right, up, forward) = (
        camera.right() * tan_y * aspect(),
        camera.image_up() * tan_y,
        camera.forward(),
    );
    let mut points = Vec::new();
    for j in 0..HEIGHT {
        for i in 0..WIDTH {
            let d = f64::from(depth[(j * WIDTH + i) as usize]);
            let sx = 2.0 * (f64::from(i) + 0.5) / f64::from(WIDTH) - 1.0;
            let sy = 1.0 - 2.0 * (f64::from(j) + 0.5) / f64::from(HEIGHT);
            // forward·dir = 1: the depth is the ray parameter.
            let p = camera.eye + d * (forward + sx * right + sy * up);
            if d.is_finite() && p.truncate().distance(camera.eye.truncate()) <= NEAR {
                points.push(p);
            }
        }
    }
    points
}

/// Standard deviation of the evaluated wavelet noise (0.210–0.215 over
/// 64 seeds: `crate::surface::wavelet_noise::TILE_STD`'s docs).
const NOISE_STD: f64 = 0.215;

/// RMS of the detail octaves a vertex of split octave `split` leaves out
/// (independent octaves, each `NOISE_STD` times its weight and amplitude).
fn omitted_rms(ground: &Ground, split: f64) -> f64 {
    let sum: f64 = (1..=8u32)
        .map(|k| ((1.0 - octave_weight(split, k)) * ground.octave_amplitude(k)).powi(2))
        .sum();
    NOISE_STD * sum.sqrt()
}

#[test]
fn rendered_ground_lies_on_the_twin_and_near_the_query() {
    let scene = Scene::new(jacksboro_field());
    let terrain = TerrainSettings::default();
    let ground = scene.ground(&terrain).expect("ground");
    let eye = DVec3::new(
        15000.0,
        12000.0,
        ground.height(15000.0, 12000.0).expect("on the terrain") + 3.0,
    );
    let camera = camera_at(eye, 1.2, 40f64.to_radians());
    let (ctx, report) = validated_context();
    let depth = {
        let settings = RenderSettings {
            terrain,
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let frame = renderer.render(&camera).and_then(|f| renderer.read(&f)).expect("frame");
        renderer.finish().expect("finish");
        frame.depth
    };
    drop(ctx);
    assert_validation_clean(&report);

    let warped = warp_of(&scene, &camera, &terrain);
    let (n, side) = (terrain.lod.sketch_side, terrain.grid_side as usize);
    let drawn = DrawnSurface::new(&ground, &warped, n, side).expect("twin");
    let bare_ground = scene
        .ground(&TerrainSettings {
            detail: false,
            ..terrain
        })
        .expect("bare ground");
    let bare = DrawnSurface::new(&bare_ground, &warped, n, side).expect("bare twin");
    let points = rendered_points(&camera, &depth);
    assert!(points.len() > 2000, "only {} pixels near the camera", points.len());
    let (mut twin_max, mut bare_max, mut split_min, mut edge_max) = (0.0f64, 0.0f64, f64::INFINITY, 0.0f64);
    let (mut fine_sq, mut fine_max, mut spline_sq, mut spline_max) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for p in &points {
        let at = drawn.at(p.truncate()).expect("the mesh covers every rendered point");
        twin_max = twin_max.max((p.z - at.height).abs());
        bare_max = bare_max.max((p.z - bare.at(p.truncate()).expect("bare mesh").height).abs());
        (split_min, edge_max) = (split_min.min(at.split_min), edge_max.max(at.edge));
        let fine = (p.z - ground.height(p.x, p.y).expect("on the terrain")).abs();
        let spline = (p.z - sample_bspline(&scene.heights, p.x, p.y)).abs();
        (fine_sq, fine_max) = (fine_sq + fine * fine, fine_max.max(fine));
        (spline_sq, spline_max) = (spline_sq + spline * spline, spline_max.max(spline));
    }
    let count = points.len() as f64;
    let (fine_rms, spline_rms) = ((fine_sq / count).sqrt(), (spline_sq / count).sqrt());
    // The query's tolerance near the camera: twice the RMS the omitted
    // octaves give at the vertices (the linear interpolation across the
    // triangles adds about as much again), and for the largest difference
    // the vertices' bound (every omitted octave at the tile's largest value).
    let (rms_budget, max_budget) = (
        2.0 * omitted_rms(&ground, split_min),
        ground.omitted_detail_bound(split_min),
    );
    println!(
        "{} points within {NEAR} m: |z − twin| max {twin_max:.4} m, bare-B-spline twin {bare_max:.3} m; split octave ≥ {split_min:.2}, longest edge {edge_max:.2} m",
        points.len(),
    );
    println!(
        "|z − ground_height| rms {fine_rms:.3} m (budget {rms_budget:.3}), max {fine_max:.3} m (budget {max_budget:.3}); |z − B-spline| rms {spline_rms:.3} m, max {spline_max:.3} m",
    );
    assert!(twin_max <= 0.01, "rendered ground {twin_max} m off its CPU twin");
    assert!(bare_max > 0.1, "the bare B-spline twin should miss ({bare_max} m)");
    assert!(
        fine_rms <= rms_budget && fine_max <= max_budget,
        "ground_height is off the drawn ground"
    );
    assert!(spline_rms > rms_budget, "the bare B-spline should break the budget");
}

#[test]
fn cameras_above_the_query_are_above_the_drawn_ground() {
    let scene = Scene::new(jacksboro_field());
    let terrain = TerrainSettings::default();
    let ground = scene.ground(&terrain).expect("ground");
    let extent = scene.heights.extent();
    let mut rng = SplitMix64(14);
    let (mut under_query, mut under_spline, mut clearance) = (0, 0, f64::INFINITY);
    // The drawn ground under the eye of a camera 2 m above `base`, and its eye height.
    let drawn_under = |xy: DVec2, base: f64, heading: f64| {
        let camera = camera_at(xy.extend(base + 2.0), heading, 10f64.to_radians());
        let warped = warp_of(&scene, &camera, &terrain);
        let drawn = DrawnSurface::new(&ground, &warped, terrain.lod.sketch_side, terrain.grid_side as usize)
            .expect("twin")
            .at(xy)
            .expect("the view's mesh covers its eye");
        (drawn.height, camera.eye.z)
    };
    for _ in 0..300 {
        let xy = DVec2::new(rng.next_f64(), rng.next_f64()) * (extent - 1000.0) + 500.0;
        let heading = rng.next_f64() * std::f64::consts::TAU;
        let (drawn, eye) = drawn_under(xy, ground.height(xy.x, xy.y).expect("on the terrain"), heading);
        clearance = clearance.min(eye - drawn);
        under_query += usize::from(eye <= drawn);
        let (drawn, eye) = drawn_under(xy, sample_bspline(&scene.heights, xy.x, xy.y), heading);
        under_spline += usize::from(eye <= drawn);
    }
    println!(
        "300 cameras: 2 m above ground_height, {under_query} under the drawn ground (smallest clearance {clearance:.2} m); 2 m above the B-spline, {under_spline}"
    );
    assert_eq!(under_query, 0);
    assert!(
        under_spline > 0,
        "the bare B-spline should put some cameras underground"
    );
}

#[test]
fn ground_queries_off_the_terrain_are_one_line_errors() {
    let scene = Scene::new(jacksboro_field());
    let extent = scene.heights.extent();
    let e = scene.ground_height(extent.x + 1.0, 100.0).unwrap_err().to_string();
    assert!(
        e.contains(&format!("({}, 100)", extent.x + 1.0)) && !e.contains('\n'),
        "{e}"
    );
    assert!(scene.ground_normal(-1.0, 0.0).is_err());
    let n = scene.ground_normal(15000.0, 12000.0).expect("normal");
    assert!(n.z > 0.0 && (n.length() - 1.0).abs() < 1e-12);
}

/// Angle in degrees between the world normals of two renders at pixel `i`
/// (None where either shows no terrain).
fn normal_angle(a: &[f32], b: &[f32], i: usize) -> Option<f64> {
    let v = |n: &[f32]| DVec3::new(f64::from(n[3 * i]), f64::from(n[3 * i + 1]), f64::from(n[3 * i + 2]));
    let (p, q) = (v(a), v(b));
    (p.length() > 0.5 && q.length() > 0.5)
        .then(|| p.normalize().dot(q.normalize()).clamp(-1.0, 1.0).acos().to_degrees())
}

#[test]
fn warped_grid_shades_like_a_uniform_grid_from_straight_above() {
    let options = HeightmapOptions {
        spacing: Some(DVec2::new(233.6, 234.3)),
        rows: RowOrder::NorthUp,
        ..Default::default()
    };
    let scene = Scene::new(load_heightmap(&data("real-world/rmnp-dem.png"), &options).expect("DEM"));
    let extent = scene.heights.extent();
    let centre = DVec3::new(extent.x / 2.0, extent.y / 2.0, 3300.0);
    let distance = 0.49 * extent.y / 10f64.to_radians().tan();
    let camera = Camera {
        eye: centre + DVec3::Z * distance,
        target: centre,
        up: DVec3::Y,
        fov_y_deg: 20.0,
        near: distance - 4000.0,
        far: distance + 4000.0,
    };
    let (width, height) = (160, 198);
    let (ctx, report) = validated_context();
    let render = |mode: LodMode| {
        let mut settings = RenderSettings::new(width, height);
        settings.terrain.lod.mode = mode;
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let frame = renderer.render(&camera).and_then(|f| renderer.read(&f)).expect("frame");
        renderer.finish().expect("finish");
        frame.normal
    };
    let (warped, uniform) = (render(LodMode::Warped), render(LodMode::Uniform));
    drop(ctx);
    assert_validation_clean(&report);
    let mut angles: Vec<f64> = (0..(width * height) as usize)
        .filter_map(|i| normal_angle(&warped, &uniform, i))
        .collect();
    assert!(
        angles.len() > (width * height) as usize * 9 / 10,
        "terrain fills the view"
    );
    angles.sort_by(f64::total_cmp);
    let quantile = |q: f64| angles[((angles.len() - 1) as f64 * q) as usize];
    let (median, p999, max) = (quantile(0.5), quantile(0.999), angles[angles.len() - 1]);
    println!("warped vs uniform shading normals: median {median:.2}°, 99.9 % {p999:.2}°, max {max:.2}°");
    assert!(
        median < 2.0 && p999 < 12.0 && max < 25.0,
        "warped normals off the uniform grid's: {median:.2}° / {p999:.2}° / {max:.2}°"
    );
}
