//! Golden-image tests: frames compared with stored PNGs by FLIP: the
//! default scene (with its rocks) and the real Jacksboro DEM from three
//! viewpoints (high and oblique, low and grazing, along a valley), all with
//! the warped terrain and its procedural detail (§7.4) coloured from the
//! texture atlas (§8.2; frames rendered until every tile is ready), the
//! default scene also with the classic surface types (§7.4.3); and the
//! Stanford bunny as a sequential point tree with opaque, EWA and
//! single-pass EWA splats (§10.1–10.2, §10.4).
//!
//! Every scene with terrain renders in both rasterizer paths (issue 28:
//! the hardware rasterizer, the text's, and the compute path's visibility
//! buffer), each checked against the golden, and the two against each
//! other: mean FLIP ≤ 0.02 and the view depth within 1e-4 relative on at
//! least 99.5 % of the pixels both hit.
//!
//! Threshold: mean FLIP ≤ [`MEAN_FLIP_THRESHOLD`] (0.02; override with
//! `ALPENGLOW_FLIP_THRESHOLD`). On the lavapipe that made the goldens the
//! error is 0; other drivers rasterize, interpolate and round transcendental
//! functions differently, which measured well below 0.02 in mean FLIP for
//! these smooth terrain scenes, while a one-pass regression (a missing sky,
//! a wrong normal, a flipped image) gives 0.1 or more.
//!
//! Refresh the goldens after an intended change:
//! `ALPENGLOW_UPDATE_GOLDENS=1 cargo test --test golden`, then look at the
//! new PNGs in `tests/golden/` before committing them. A failing test writes
//! the frame and the FLIP heat map to `target/golden-failures/`.

mod common;

use alpenglow::files::{load_point_object, write_png_rgba8};
use alpenglow::glam::DVec3;
use alpenglow::{
    Camera, FrameImages, Lighting, PointLoadOptions, PointScene, PointTransform, RasterPath, Renderer, Scene, Settings,
    SplatMode, SplatSettings, SunPosition, TexturingMode,
};
use common::{
    assert_validation_clean, data, failure_dir, golden_dir, jacksboro_field, jacksboro_valley_camera, mean_flip,
    validated_context,
};

const MEAN_FLIP_THRESHOLD: f32 = 0.02;
const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;

fn threshold() -> f32 {
    std::env::var("ALPENGLOW_FLIP_THRESHOLD")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(MEAN_FLIP_THRESHOLD)
}

/// Frames a golden render may take until every texture tile is ready.
const SETTLE_FRAMES: u32 = 16;

fn check_golden(name: &str, scene: &Scene, camera: &Camera) {
    check_golden_with(name, scene, camera, SplatSettings::default(), TexturingMode::default());
}

/// The fraction of the pixels where both frames hit a surface whose view
/// depths agree within [`DEPTH_TOLERANCE`] relative must be at least this
/// (the rest: silhouettes, where the two rasterizers' sample positions
/// meet a ridge's edge differently).
const DEPTH_AGREEMENT: f64 = 0.995;
const DEPTH_TOLERANCE: f32 = 1e-4;

/// Checks `scene` through `camera` against golden `name` in both terrain
/// rasterizer paths (issue 28: the compute path's images match the
/// hardware path's), and the two paths against each other: mean FLIP and
/// view depth. Scenes without terrain render once.
fn check_golden_with(name: &str, scene: &Scene, camera: &Camera, points: SplatSettings, texturing: TexturingMode) {
    let (ctx, report) = validated_context();
    let ewa_points = !scene.points.objects.is_empty() && points.mode == SplatMode::Ewa;
    let paths: &[RasterPath] = match scene.draw_terrain || ewa_points {
        true => &[RasterPath::Hardware, RasterPath::Compute],
        false => &[RasterPath::Auto],
    };
    let frames: Vec<FrameImages> = (paths.iter())
        .map(|&raster| {
            let mut settings = Settings::new(WIDTH, HEIGHT);
            settings.points = points;
            settings.texturing = texturing;
            settings.raster = raster;
            let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
            let frame = (renderer.render_settled(camera, SETTLE_FRAMES))
                .and_then(|f| renderer.read(&f))
                .expect("frame");
            renderer.finish().expect("finish");
            frame
        })
        .collect();
    drop(ctx);
    assert_validation_clean(&report);

    let golden_path = golden_dir().join(format!("{name}.png"));
    if std::env::var_os("ALPENGLOW_UPDATE_GOLDENS").is_some() {
        // The goldens are the first path's: the hardware rasterizer, the text's.
        write_png_rgba8(&golden_path, &frames[0].rgba8, WIDTH, HEIGHT).expect("write golden");
        eprintln!("updated {}", golden_path.display());
        return;
    }
    let golden = image::open(&golden_path)
        .unwrap_or_else(|e| {
            panic!(
                "cannot read golden {}: {e} (create it with ALPENGLOW_UPDATE_GOLDENS=1 cargo test --test golden)",
                golden_path.display()
            )
        })
        .to_rgba8();
    assert_eq!(golden.dimensions(), (WIDTH, HEIGHT), "golden {name} has another size");
    for (frame, raster) in frames.iter().zip(paths) {
        compare(&format!("{name} ({})", raster.name()), golden.as_raw(), frame);
    }
    if let [hardware, compute] = &frames[..] {
        compare(&format!("{name}: compute against hardware"), &hardware.rgba8, compute);
        let both: Vec<(f32, f32)> = (hardware.depth.iter().zip(&compute.depth))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|(&a, &b)| (a, b))
            .collect();
        let agreeing = both
            .iter()
            .filter(|(a, b)| (a - b).abs() <= DEPTH_TOLERANCE * a.abs())
            .count();
        let agreement = agreeing as f64 / both.len().max(1) as f64;
        eprintln!(
            "{name}: view depth within {DEPTH_TOLERANCE} relative on {agreement:.5} of {} pixels",
            both.len()
        );
        assert!(
            both.len() > 1000 && agreement >= DEPTH_AGREEMENT,
            "{name}: the paths' view depths agree within {DEPTH_TOLERANCE} relative on {agreement:.5} of the {} \
             pixels both hit (at least {DEPTH_AGREEMENT})",
            both.len()
        );
    }
}

/// Fails when `frame` differs from `reference` (sRGB8) by more than the
/// mean FLIP threshold; writes the frame and the heat map first.
fn compare(label: &str, reference: &[u8], frame: &FrameImages) {
    let (mean, heatmap) = mean_flip(reference, &frame.rgba8, WIDTH, HEIGHT);
    if mean > threshold() {
        let dir = failure_dir();
        let file = label.replace([' ', ':', '(', ')'], "_");
        let _ = write_png_rgba8(&dir.join(format!("{file}.actual.png")), &frame.rgba8, WIDTH, HEIGHT);
        let rgba: Vec<u8> = heatmap.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
        let _ = write_png_rgba8(&dir.join(format!("{file}.flip.png")), &rgba, WIDTH, HEIGHT);
        panic!(
            "{label}: mean FLIP {mean:.4} > {:.4}; see {}",
            threshold(),
            dir.display()
        );
    }
    eprintln!("{label}: mean FLIP {mean:.5}");
}

#[test]
fn default_scene_matches_golden() {
    let scene = Scene::default_procedural().expect("default scene");
    check_golden("default-scene", &scene, &scene.default_camera());
}

/// The default scene with the §7.4.3 surface types instead of the atlas.
#[test]
fn default_scene_classic_texturing_matches_golden() {
    let scene = Scene::default_procedural().expect("default scene");
    let camera = scene.default_camera();
    check_golden_with(
        "default-scene-classic",
        &scene,
        &camera,
        SplatSettings::default(),
        TexturingMode::Classic,
    );
}

/// The Jacksboro DEM seen high and oblique: the default camera, from
/// beyond the southern edge and above the highest point.
#[test]
fn real_dem_high_oblique_view_matches_golden() {
    let scene = Scene::new(jacksboro_field());
    check_golden("jacksboro-high-oblique", &scene, &scene.default_camera());
}

/// Low and grazing: 80 m above a ridge, looking across the terrain just
/// below the horizon (large depth range, strong warping).
#[test]
fn real_dem_low_grazing_view_matches_golden() {
    let scene = Scene::new(jacksboro_field());
    let camera = Camera {
        eye: DVec3::new(2000.0, 3000.0, 1150.0),
        target: DVec3::new(20000.0, 20000.0, 600.0),
        up: DVec3::Z,
        fov_y_deg: 45.0,
        near: 10.0,
        far: 100000.0,
    };
    check_golden("jacksboro-grazing", &scene, &camera);
}

/// Along the valley of the Jacksboro fault, from its south-western part
/// towards the north-east, a few hundred metres above the valley floor.
#[test]
fn real_dem_along_valley_view_matches_golden() {
    let scene = Scene::new(jacksboro_field());
    check_golden("jacksboro-valley", &scene, &jacksboro_valley_camera());
}

fn bunny_scene() -> Scene {
    let options = PointLoadOptions {
        mesh_samples: 30_000,
        ..PointLoadOptions::default()
    };
    let bunny = load_point_object(&data("models/stanford-bunny.obj"), &options).expect("bunny");
    let mut points = PointScene::default();
    // The model is y-up; stand it up in the z-up world.
    points.add(bunny, PointTransform::parse("r=90,0,0").expect("transform"));
    let mut scene = Scene::points_only(points);
    // Sun from behind the camera's left shoulder: the seen side is lit.
    let sun = SunPosition::Angles {
        elevation_deg: 40.0,
        azimuth_deg: 200.0,
    };
    scene.sun_direction = Lighting {
        sun,
        ..scene.default_lighting()
    }
    .sun_direction();
    scene
}

fn bunny_camera() -> Camera {
    Camera {
        eye: DVec3::new(0.12, -0.3, 0.17),
        target: DVec3::new(-0.02, 0.0, 0.09),
        up: DVec3::Z,
        fov_y_deg: 45.0,
        near: 0.01,
        far: 100.0,
    }
}

#[test]
fn bunny_ewa_matches_golden() {
    let settings = SplatSettings {
        mode: SplatMode::Ewa,
        ..SplatSettings::default()
    };
    check_golden_with(
        "bunny-ewa",
        &bunny_scene(),
        &bunny_camera(),
        settings,
        TexturingMode::default(),
    );
}

#[test]
fn bunny_opaque_matches_golden() {
    let settings = SplatSettings {
        mode: SplatMode::Opaque,
        ..SplatSettings::default()
    };
    check_golden_with(
        "bunny-opaque",
        &bunny_scene(),
        &bunny_camera(),
        settings,
        TexturingMode::default(),
    );
}

/// Single-pass splatting (§10.4): merges at fuzzy boundaries follow the
/// GPU's invocation order, which may differ between runs; the mean FLIP
/// threshold covers it.
#[test]
fn bunny_single_pass_matches_golden() {
    let settings = SplatSettings {
        mode: SplatMode::SinglePass,
        ..SplatSettings::default()
    };
    check_golden_with(
        "bunny-single-pass",
        &bunny_scene(),
        &bunny_camera(),
        settings,
        TexturingMode::default(),
    );
}
