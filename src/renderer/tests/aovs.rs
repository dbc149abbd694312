//! The simulator AOVs (`src/view/aov.rs`) on the GPU, under validation and
//! synchronization validation, each against an independent reference:
//!
//! * `distance` against `Z` and the pixel's ray computed here in f64
//!   (distance = Z / cos(angle to the forward axis)), +inf exactly on sky;
//! * `motion` of the second frame of a moving camera against the motion
//!   re-projected here from `Z` and the two poses, and the surface it points
//!   to against the first frame's depth (a static scene looks the same from
//!   both ends of the vector); 0 on the first frame;
//! * `class`: 0 exactly where `Z` is +inf; terrain 10 + a layer of the tree;
//!   the atlas's dominant layers against the per-pixel reference (direct
//!   texturing), and those against the CPU twin of the layer tree; classic
//!   texturing's four surface types;
//! * rocks and scans: class 2 and 3 with their instance ids exactly where
//!   their splats are (W > 0), in every splat mode (opaque, EWA, single
//!   pass), over terrain and alone;
//! * normals: unit length and facing the camera on every surface, 0 for sky;
//! * `Renderer::reset_motion` makes the next frame's motion 0.

use crate::points::build::spt::{epsilon_from_pixels, SptOptions};
use crate::points::render::{SplatMode, SplatSettings};
use crate::points::scene::{scatter_rocks, PointClass, PointObject, PointScene, PointTransform};
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::dominant::dominant_layer;
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::procedural::ProceduralTerrain;
use crate::terrain::shading::CLASSIC_LAYERS;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::texturing::page_table::PageTable;
use crate::texturing::reference::ReferenceSurface;
use crate::view::aov::{CLASS_LAYER_BASE, CLASS_ROCK, CLASS_SCAN, CLASS_SKY};
use glam::{DVec2, DVec3, DVec4};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 100;

/// Renders `cameras` one frame each (`settle`: until every texture tile is
/// resident) and reads every frame back, with the last frame's texture page
/// table.
fn render(
    scene: &Scene,
    settings: RenderSettings,
    cameras: &[Camera],
    settle: bool,
) -> (Vec<FrameImages>, Option<PageTable>) {
    let (ctx, report) = validated_context();
    let frames = {
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        let frames = cameras
            .iter()
            .map(|c| {
                let outcome = match settle {
                    true => renderer.render_settled(c, 16),
                    false => renderer.render(c),
                };
                outcome.and_then(|f| renderer.read(&f)).expect("frame")
            })
            .collect();
        renderer.finish().expect("finish");
        (frames, renderer.texture_page_table().expect("page table"))
    };
    drop(ctx);
    assert_validation_clean(&report);
    frames
}

/// The ray through the centre of pixel (x, y), scaled to ray·forward = 1.
fn ray(camera: &Camera, x: u32, y: u32) -> DVec3 {
    let aspect = f64::from(WIDTH) / f64::from(HEIGHT);
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let ndc_x = (f64::from(x) + 0.5) / f64::from(WIDTH) * 2.0 - 1.0;
    let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(HEIGHT) * 2.0;
    camera.forward() + camera.right() * (ndc_x * tan * aspect) + camera.image_up() * (ndc_y * tan)
}

/// Every pixel as (index, x, y).
fn pixels() -> impl Iterator<Item = (usize, u32, u32)> {
    (0..HEIGHT).flat_map(|y| (0..WIDTH).map(move |x| ((y * WIDTH + x) as usize, x, y)))
}

/// Checks distance against Z and the ray; returns the number of sky pixels.
fn check_distance(frame: &FrameImages, camera: &Camera) -> usize {
    let mut sky = 0;
    for (i, x, y) in pixels() {
        let (z, d) = (frame.depth[i], frame.distance[i]);
        if z == f32::INFINITY {
            assert_eq!(d, f32::INFINITY, "pixel ({x}, {y}): sky distance {d}");
            sky += 1;
            continue;
        }
        // cos of the angle to the forward axis is 1 / |ray|.
        let expected = f64::from(z) * ray(camera, x, y).length();
        assert!(
            (f64::from(d) - expected).abs() <= 1e-5 * expected,
            "pixel ({x}, {y}): distance {d}, Z / cos = {expected}"
        );
    }
    sky
}

/// The pixel position (x right, y down) of homogeneous world point `p` in `camera`.
fn project(camera: &Camera, p: DVec4) -> Option<(f64, f64)> {
    let clip = camera.view_proj_f64(f64::from(WIDTH) / f64::from(HEIGHT)) * p;
    (clip.w > 0.0).then(|| {
        (
            (clip.x / clip.w * 0.5 + 0.5) * f64::from(WIDTH),
            (clip.y / clip.w * 0.5 + 0.5) * f64::from(HEIGHT),
        )
    })
}

#[test]
fn distance_and_motion_follow_depth_and_the_poses() {
    for raster in crate::test_support::RASTER_PATHS {
        distance_and_motion_follow_depth_and_the_poses_in(raster);
    }
}

fn distance_and_motion_follow_depth_and_the_poses_in(raster: crate::RasterPath) {
    let scene = Scene::default_terrain().expect("scene");
    let before = scene.default_camera();
    let after = Camera {
        eye: before.eye + DVec3::new(90.0, 60.0, -40.0),
        target: before.target + DVec3::new(500.0, 0.0, 30.0),
        ..before
    };
    let settings = RenderSettings {
        raster,
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    let (frames, _) = render(&scene, settings, &[before, after], false);
    assert!(frames[0].motion.iter().all(|&m| m == 0.0), "the first frame has motion");
    for (frame, camera) in frames.iter().zip([&before, &after]) {
        let sky = check_distance(frame, camera);
        assert!(sky > 100 && sky < frame.depth.len() - 100, "{sky} sky pixels");
    }

    // The motion of the second frame, re-projected here from Z and the poses.
    let frame = &frames[1];
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    let (mut depth_errors, mut still_errors) = (Vec::new(), Vec::new());
    for (i, x, y) in pixels() {
        let z = f64::from(frame.depth[i]);
        let r = ray(&after, x, y);
        let point = match z.is_finite() {
            true => (after.eye + r * z).extend(1.0),
            false => r.extend(0.0),
        };
        let Some(p) = project(&before, point) else { continue };
        let expected = (f64::from(x) + 0.5 - p.0, f64::from(y) + 0.5 - p.1);
        let m = (f64::from(frame.motion[2 * i]), f64::from(frame.motion[2 * i + 1]));
        worst = worst.max((m.0 - expected.0).abs()).max((m.1 - expected.1).abs());
        largest = largest.max(m.0.hypot(m.1));
        // The surface the vector points to, in the first frame's depth.
        let (px, py) = (p.0.floor() as i64, p.1.floor() as i64);
        if z.is_finite() && px >= 0 && py >= 0 && px < i64::from(WIDTH) && py < i64::from(HEIGHT) {
            let seen = f64::from(frames[0].depth[(py * i64::from(WIDTH) + px) as usize]);
            let expected_depth = (point.truncate() - before.eye).dot(before.forward());
            // Control: the first frame's depth at the same pixel (no motion).
            let still = f64::from(frames[0].depth[i]);
            depth_errors.push((seen - expected_depth).abs() / expected_depth);
            still_errors.push((still - expected_depth).abs() / expected_depth);
        }
    }
    let quantile = |v: &mut Vec<f64>, q: f64| {
        v.sort_by(f64::total_cmp);
        v[((v.len() - 1) as f64 * q) as usize]
    };
    let (median, p90) = (quantile(&mut depth_errors, 0.5), quantile(&mut depth_errors, 0.9));
    let still = quantile(&mut still_errors, 0.5);
    eprintln!(
        "motion: largest {largest:.2} px, worst difference from the CPU {worst:.5} px; first-frame depth \
         at the previous position: {} pixels, relative error median {median:.5}, 90th percentile {p90:.5} \
         (at the same pixel: median {still:.5})",
        depth_errors.len(),
    );
    assert!(
        largest > 10.0,
        "the camera moved, yet the largest motion is {largest} px"
    );
    assert!(worst < 0.02, "motion differs from the CPU's by {worst} px");
    assert!(
        depth_errors.len() > 5000,
        "{} pixels seen in both frames",
        depth_errors.len()
    );
    assert!(
        median < 0.01 && p90 < 0.03 && median < 0.2 * still,
        "motion does not track surfaces"
    );
}

/// Checks the normals of geometry pixels (`geometry(i)`): unit length,
/// facing the camera (all but `tolerance` of them); 0 elsewhere.
fn check_normals(name: &str, frame: &FrameImages, camera: &Camera, geometry: impl Fn(usize) -> bool, tolerance: f64) {
    let (mut surfaces, mut away) = (0usize, 0usize);
    for (i, x, y) in pixels() {
        let n = DVec3::new(
            f64::from(frame.normal[3 * i]),
            f64::from(frame.normal[3 * i + 1]),
            f64::from(frame.normal[3 * i + 2]),
        );
        if !geometry(i) {
            assert_eq!(n, DVec3::ZERO, "{name}: pixel ({x}, {y}) has a normal but no surface");
            continue;
        }
        surfaces += 1;
        assert!(
            (n.length() - 1.0).abs() < 2e-3,
            "{name}: pixel ({x}, {y}): |n| = {}",
            n.length()
        );
        away += usize::from(n.dot(ray(camera, x, y)) >= 0.0);
    }
    eprintln!("{name}: {away} of {surfaces} normals face away from the camera");
    assert!(
        surfaces > 0 && (away as f64) <= tolerance * surfaces as f64,
        "{name}: {away} normals face away"
    );
}

/// The classes of a terrain frame: 0 exactly where Z is +inf, the instance
/// 0 everywhere; the terrain's classes (minus the layer base) per pixel.
fn terrain_layers(name: &str, frame: &FrameImages) -> Vec<Option<u32>> {
    assert!(
        frame.instance.iter().all(|&i| i == 0),
        "{name}: an instance id without points"
    );
    pixels()
        .map(|(i, x, y)| {
            let (class, z) = (frame.class[i], frame.depth[i]);
            assert_eq!(
                class == CLASS_SKY,
                z == f32::INFINITY,
                "{name}: pixel ({x}, {y}) class {class}, Z {z}"
            );
            (class != CLASS_SKY).then(|| {
                assert!(
                    class >= CLASS_LAYER_BASE,
                    "{name}: terrain pixel ({x}, {y}) of class {class}"
                );
                class - CLASS_LAYER_BASE
            })
        })
        .collect()
}

/// The share of terrain pixels whose layers agree, of those both have.
fn agreement(a: &[Option<u32>], b: &[Option<u32>]) -> f64 {
    let pairs: Vec<(u32, u32)> = a.iter().zip(b).filter_map(|(a, b)| Some(((*a)?, (*b)?))).collect();
    pairs.iter().filter(|(a, b)| a == b).count() as f64 / pairs.len().max(1) as f64
}

/// The dominant layer of the CPU twin (`ReferenceSurface`) at each
/// terrain pixel of `frame`: evaluated where the atlas texel the pixel reads
/// is (`table`: with the texel's spacing as the noise's band limit), or
/// without a table at the pixel's point with its footprint (direct texturing).
fn cpu_layers(scene: &Scene, camera: &Camera, frame: &FrameImages, table: Option<&PageTable>) -> Vec<Option<u32>> {
    let noise_seed = TerrainSettings::default().noise_seed;
    let reference = ReferenceSurface::new(&scene.heights, &scene.layers, &scene.input_maps, noise_seed).expect("cpu");
    let footprint = 2.0 * (0.5 * camera.fov_y_deg.to_radians()).tan() / f64::from(HEIGHT);
    let extent = scene.heights.extent();
    pixels()
        .map(|(i, x, y)| {
            let z = f64::from(frame.depth[i]);
            if !z.is_finite() {
                return None;
            }
            let p = camera.eye + ray(camera, x, y) * z;
            let (xy, footprint) = match table {
                None => (p.truncate(), z * footprint),
                Some(table) => {
                    let e = table.lookup(p.truncate(), extent)?;
                    let (min, size) = (
                        DVec2::from(e.node_min.map(f64::from)),
                        DVec2::from(e.node_size.map(f64::from)),
                    );
                    let spacing = size / f64::from(e.inner_texels);
                    let texel = ((p.truncate() - min) / spacing).floor();
                    (min + (texel + 0.5) * spacing, spacing.max_element())
                }
            };
            let surface = reference.evaluate(xy, footprint);
            Some(dominant_layer(&surface.coverage).expect("a layer") as u32)
        })
        .collect()
}

#[test]
fn terrain_classes_are_the_dominant_layers_and_normals_face_the_camera() {
    for raster in crate::test_support::RASTER_PATHS {
        terrain_classes_are_the_dominant_layers_and_normals_face_the_camera_in(raster);
    }
}

fn terrain_classes_are_the_dominant_layers_and_normals_face_the_camera_in(raster: crate::RasterPath) {
    let scene = Scene::default_terrain().expect("scene");
    let camera = scene.default_camera();
    let layer_count = scene.layers.layers.len() as u32;
    let mut found = Vec::new();
    for (name, texturing) in [
        ("atlas", TexturingMode::Atlas),
        ("direct", TexturingMode::Direct),
        ("classic", TexturingMode::Classic),
    ] {
        let settings = RenderSettings {
            texturing,
            raster,
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let (frames, table) = render(&scene, settings, &[camera], true);
        let frame = &frames[0];
        check_normals(name, frame, &camera, |i| frame.depth[i].is_finite(), 0.01);
        let layers = terrain_layers(name, frame);
        let mut distinct: Vec<u32> = layers.iter().flatten().copied().collect();
        distinct.sort_unstable();
        distinct.dedup();
        let allowed: Vec<u32> = match texturing {
            TexturingMode::Classic => CLASSIC_LAYERS.iter().map(|&(_, k)| k).collect(),
            _ => (0..layer_count).collect(),
        };
        assert!(
            distinct.iter().all(|l| allowed.contains(l)),
            "{name}: layers {distinct:?}"
        );
        assert!(distinct.len() >= 2, "{name}: a single layer {distinct:?}");
        if texturing != TexturingMode::Classic {
            // The GPU's dominant layer against the CPU twin's where the GPU evaluated the tree.
            let cpu = cpu_layers(&scene, &camera, frame, table.as_ref());
            let agree = agreement(&layers, &cpu);
            eprintln!("{name}: layers {distinct:?}, {agree:.4} of the terrain pixels agree with the CPU twin");
            assert!(
                agree > 0.97,
                "{name}: only {agree} of the dominant layers agree with the CPU"
            );
        }
        found.push(layers);
    }
    // The atlas's tiles are finer than the pixels far away, so their
    // band-limited noise keeps layers the pixel's footprint averages away.
    eprintln!(
        "atlas and direct agree on {:.4} of the pixels",
        agreement(&found[0], &found[1])
    );
}

/// A procedural rock (§6.1.4) of about `size` metres across.
fn rock(size: f64) -> (PointObject, f64) {
    let flat = Scene::points_only(PointScene::default()).heights;
    let spt = SptOptions {
        epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), HEIGHT).expect("epsilon"),
        ..SptOptions::default()
    };
    let rocks = scatter_rocks(&flat, 1, 3000, 1, (1.0, 1.0), 5, &spt).expect("rock");
    let object = rocks.objects[0].clone();
    assert_eq!(object.class, PointClass::Rock);
    let scale = size / (2.0 * f64::from(object.tree.bounds_radius));
    (object, scale)
}

/// Places `object` with scale `scale` so that its bounding sphere's centre is at `at`.
fn place(points: &mut PointScene, object: PointObject, scale: f64, at: DVec3) {
    let centre = object.tree.bounds_centre.as_dvec3() * scale;
    let transform = PointTransform {
        translation: at - centre,
        scale,
        ..PointTransform::default()
    };
    points.add(object, transform);
}

/// Checks the ids of a frame with point objects: where W > 0 exactly the
/// pairs of `expected` (class, instance), each on some pixels; elsewhere
/// the terrain's or the sky's (instance 0).
fn check_point_ids(name: &str, frame: &FrameImages, expected: &[(u32, u32)]) {
    let weight = frame.weight.as_ref().expect("W");
    let mut counts = vec![0usize; expected.len()];
    for (i, x, y) in pixels() {
        let ids = (frame.class[i], frame.instance[i]);
        if weight[i] > 0.0 {
            let k = expected.iter().position(|e| *e == ids);
            let k = k.unwrap_or_else(|| panic!("{name}: splat pixel ({x}, {y}) has ids {ids:?}"));
            counts[k] += 1;
        } else {
            assert!(
                ids.1 == 0 && ids.0 != CLASS_ROCK && ids.0 != CLASS_SCAN,
                "{name}: pixel ({x}, {y}) without splats has ids {ids:?}"
            );
        }
    }
    eprintln!("{name}: pixels per (class, instance) {expected:?}: {counts:?}");
    assert!(counts.iter().all(|&n| n > 50), "{name}: {counts:?}");
}

#[test]
fn rocks_and_scans_have_their_class_and_instance_in_every_splat_mode() {
    let (object, scale) = rock(1.0);
    let mut points = PointScene::default();
    place(&mut points, object.clone(), scale, DVec3::new(-0.7, 0.0, 0.0));
    let scan = PointObject {
        class: PointClass::Scan,
        ..object
    };
    place(&mut points, scan, scale, DVec3::new(0.7, 0.0, 0.0));
    let scene = Scene::points_only(points);
    let camera = Camera {
        eye: DVec3::new(0.0, -3.5, 1.0),
        target: DVec3::ZERO,
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.01,
        far: 100.0,
    };
    for mode in [SplatMode::Ewa, SplatMode::Opaque, SplatMode::SinglePass] {
        let settings = RenderSettings {
            points: SplatSettings {
                mode,
                ..SplatSettings::default()
            },
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let frame = &render(&scene, settings, &[camera], false).0[0];
        let name = format!("points alone, {}", mode.name());
        check_point_ids(&name, frame, &[(CLASS_ROCK, 1), (CLASS_SCAN, 2)]);
        let weight = frame.weight.as_ref().expect("W");
        check_normals(&name, frame, &camera, |i| weight[i] > 0.0, 0.02);
        check_distance(frame, &camera);
    }
}

#[test]
fn a_rock_on_the_terrain_keeps_its_ids_where_it_is_seen() {
    let field = ProceduralTerrain::default()
        .try_generate(65, 65, DVec2::splat(40.0))
        .expect("terrain");
    let mut scene = Scene::new(field);
    let (object, scale) = rock(60.0);
    let ground = crate::surface::bspline::sample_bspline(&scene.heights, 1280.0, 1280.0);
    place(
        &mut scene.points,
        object,
        scale,
        DVec3::new(1280.0, 1280.0, ground + 10.0),
    );
    let camera = Camera {
        eye: DVec3::new(1280.0, 1050.0, ground + 90.0),
        target: DVec3::new(1280.0, 1280.0, ground + 10.0),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.5,
        far: 20000.0,
    };
    let frame = &render(&scene, RenderSettings::new(WIDTH, HEIGHT), &[camera], true).0[0];
    check_point_ids("rock on terrain", frame, &[(CLASS_ROCK, 1)]);
    let terrain = pixels().filter(|&(i, _, _)| frame.class[i] >= CLASS_LAYER_BASE).count();
    assert!(terrain > 1000, "{terrain} terrain pixels");
    check_normals("rock on terrain", frame, &camera, |i| frame.depth[i].is_finite(), 0.02);
}

#[test]
fn a_reset_forgets_the_previous_camera() {
    let field = ProceduralTerrain::default()
        .try_generate(65, 65, DVec2::splat(40.0))
        .expect("terrain");
    let scene = Scene::new(field);
    let first = scene.default_camera();
    let second = Camera {
        eye: first.eye + DVec3::new(150.0, 0.0, 0.0),
        ..first
    };
    let (ctx, report) = validated_context();
    {
        let mut renderer = Renderer::new(&ctx, &scene, RenderSettings::new(WIDTH, HEIGHT)).expect("renderer");
        let mut motion = |camera: &Camera, reset: bool| {
            if reset {
                renderer.reset_motion();
            }
            let frame = renderer.render(camera).and_then(|f| renderer.read(&f)).expect("frame");
            frame.motion.iter().fold(0.0f32, |m, v| m.max(v.abs()))
        };
        assert_eq!(motion(&first, false), 0.0, "first frame");
        assert!(motion(&second, false) > 1.0, "the camera moved");
        assert_eq!(motion(&first, true), 0.0, "after a reset");
        renderer.finish().expect("finish");
    }
    drop(ctx);
    assert_validation_clean(&report);
}
