//! Benchmark of vegetation as point trees (dissertation chapter 10, Fig.
//! 10.12): `cargo run --release --example vegetation_bench [-- --quick]
//! [--density F] [--png DIR]` (`--density`: the multiplier of the layer
//! tables' densities, as `--vegetation-density`).
//!
//! The default terrain with the built-in layer tree's plants (no rocks), at
//! 1280×720 (`--quick`: 640×360), from three views: the default camera
//! over the whole terrain, a hillside seen from 300 m, and the ground among
//! the plants. Per view: plants in view (instances drawn after frustum
//! culling and thinning), splats in the prefixes and drawn (the vertex
//! stage's count), hybrid triangles, GPU ms of the points passes and of
//! the whole frame (medians of the timestamps over the timed frames), and
//! the CPU ms of the selection. Also the time to scatter and build.

use std::time::Instant;

use alpenglow::tools::profile::median;
use alpenglow::{Camera, Context, ContextOptions, DeviceSelector, Renderer, Scene, Settings, VegetationOptions};
use glam::{DVec2, DVec3};

/// The place with the most plants within 150 m (a 150 m grid's fullest cell).
fn densest_place(scene: &Scene) -> DVec2 {
    let mut cells = std::collections::HashMap::<(i64, i64), usize>::new();
    for inst in &scene.points.instances {
        let t = inst.transform.translation;
        *cells.entry(((t.x / 150.0) as i64, (t.y / 150.0) as i64)).or_default() += 1;
    }
    let ((i, j), _) = cells.into_iter().max_by_key(|&(k, n)| (n, k)).unwrap_or(((0, 0), 0));
    DVec2::new((i as f64 + 0.5) * 150.0, (j as f64 + 0.5) * 150.0)
}

/// A camera `back` metres south-west of `at` and `up` metres above the
/// ground there, looking at the ground at `at`.
fn camera_at(scene: &Scene, at: DVec2, back: f64, up: f64) -> Camera {
    let ground = |p: DVec2| scene.ground_height(p.x, p.y).unwrap_or(0.0);
    let extent = scene.heights.extent();
    let eye_xy = (at - DVec2::splat(back * std::f64::consts::FRAC_1_SQRT_2)).clamp(DVec2::ZERO, extent);
    let target = DVec3::new(at.x, at.y, ground(at) + 2.0);
    Camera {
        eye: DVec3::new(eye_xy.x, eye_xy.y, ground(eye_xy) + up),
        target,
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.2,
        far: 30_000.0,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let png_dir = args
        .iter()
        .position(|a| a == "--png")
        .and_then(|i| args.get(i + 1))
        .cloned();
    let density: f64 = (args.iter().position(|a| a == "--density"))
        .and_then(|i| args.get(i + 1))
        .map_or(1.0, |d| d.parse().expect("--density F"));
    let (width, height) = if quick { (640, 360) } else { (1280, 720) };
    let frames = if quick { 3 } else { 8 };

    let started = Instant::now();
    let mut scene = Scene::default_terrain().expect("terrain");
    let options = VegetationOptions {
        density,
        ..VegetationOptions::default()
    };
    let report = scene.add_vegetation(&options).expect("vegetation");
    println!(
        "scatter + build: {:.2} s; {} plants ({:?}), {} candidates, {} prototypes with {} splats",
        started.elapsed().as_secs_f64(),
        report.total(),
        report.plants,
        report.candidates,
        report.prototypes,
        report.prototype_splats
    );

    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })
    .expect("context");
    println!("device: {}, {width}×{height}", ctx.info().name);
    let place = densest_place(&scene);
    let views = [
        ("default camera (whole terrain)", scene.default_camera()),
        ("hillside from 300 m", camera_at(&scene, place, 420.0, 300.0)),
        ("ground among the plants", camera_at(&scene, place, 60.0, 4.0)),
    ];
    println!("| view | plants in view | prefix splats | splats drawn | triangles | points GPU ms | frame GPU ms | selection CPU ms |");
    println!("|---|---|---|---|---|---|---|---|");
    for (k, (name, camera)) in views.iter().enumerate() {
        let mut settings = Settings::new(width, height);
        settings.readback = png_dir.is_some();
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let warmup = 2;
        let mut last = None;
        for _ in 0..warmup + frames {
            last = Some(renderer.render(camera).expect("frame"));
        }
        if let (Some(dir), Some(frame)) = (&png_dir, last) {
            let image = renderer.read(&frame).expect("read");
            let path = std::path::Path::new(dir).join(format!("vegetation-{k}.png"));
            alpenglow::files::write_png_rgba8(&path, &image.rgba8, width, height).expect("png");
        }
        let profiles = renderer.finish().expect("finish");
        let stats = renderer.take_point_stats().expect("stats");
        let timed = || profiles.iter().skip(warmup);
        let points_ms = median(timed().map(|p| {
            (p.passes.iter())
                .filter(|p| p.name.starts_with("points."))
                .map(|p| p.gpu_ms)
                .sum::<f64>()
        }));
        let frame_ms = median(timed().map(|p| p.passes.iter().map(|p| p.gpu_ms).sum::<f64>()));
        let cpu_ms = median(stats.iter().skip(warmup).map(|s| s.cpu_ms));
        let s = stats.last().expect("point statistics");
        let count = |v: Option<u64>| v.map_or("n/a".to_string(), |v| v.to_string());
        println!(
            "| {name} | {} | {} | {} | {} | {points_ms:.1} | {frame_ms:.1} | {cpu_ms:.2} |",
            s.instances_drawn,
            s.prefix_splats,
            count(s.drawn_splats),
            count(s.triangles_drawn),
        );
    }
}
