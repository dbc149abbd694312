//! Benchmark of point rendering (dissertation §10.1.7, §10.2, §10.3):
//! `cargo run --release --example splat_bench [-- --quick]`.
//!
//! 1. Splats per second of each splat mode (opaque, three-pass EWA) and
//!    primitive (point, quad by vertex pulling, instanced quad), as in
//!    Table 10.3: the bunny sampled into ~100k surfels, every leaf drawn
//!    (a flat list: no level of detail), framed in a 512² window.
//! 2. The sequential point tree against drawing every leaf, at several
//!    distances: splats in the prefix, splats drawn, GPU time.
//! 3. CPU time of the per-frame selection per object instance: the default
//!    scene's 300 rock instances.
//! 4. Hybrid point–polygon rendering (§10.1.8) against points only, at
//!    several distances: splats and triangles drawn, GPU time
//!    (`-- --hybrid` runs only this part).
//!
//! GPU times are the medians of the points passes' timestamps over the timed
//! frames; splats/s = splats drawn (the vertex stage's count) / that time.

use alpenglow::points::build::spt::{epsilon_from_pixels, SequentialPointTree, ROOT_R_MAX};
use alpenglow::points::render::{SplatMode, SplatPrimitive, SplatSettings};
use alpenglow::points::scene::{load_point_object, PointLoadOptions, PointObject, PointScene, PointTransform};
use alpenglow::profile::median;
use alpenglow::renderer::{Camera, RenderSettings, Renderer, Scene};
use alpenglow::vulkan::{Context, ContextOptions, DeviceSelector};
use glam::DVec3;

const SIDE: u32 = 512;

struct Measured {
    gpu_ms: f64,
    prefix: u64,
    drawn: u64,
    triangles: u64,
    cpu_ms: f64,
}

fn measure(ctx: &Context, scene: &Scene, camera: &Camera, points: SplatSettings, frames: usize) -> Measured {
    let settings = RenderSettings {
        readback: false,
        points,
        ..RenderSettings::new(SIDE, SIDE)
    };
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let warmup = 2;
    for _ in 0..warmup + frames {
        renderer.render(camera).expect("frame");
    }
    let profiles = renderer.finish().expect("finish");
    let stats = renderer.take_point_stats().expect("stats");
    let gpu_ms = median(profiles.iter().skip(warmup).map(|p| {
        p.passes
            .iter()
            .filter(|p| p.name.starts_with("points."))
            .map(|p| p.gpu_ms)
            .sum::<f64>()
    }));
    let last = stats.last().expect("point statistics");
    Measured {
        gpu_ms,
        prefix: last.prefix_splats,
        drawn: last.drawn_splats.unwrap_or(0),
        triangles: last.triangles_drawn.unwrap_or(0),
        cpu_ms: median(stats.iter().skip(warmup).map(|s| s.cpu_ms)),
    }
}

/// The leaves of `tree` as a flat list drawn at every distance.
fn all_leaves(tree: &SequentialPointTree) -> SequentialPointTree {
    let mut flat = tree.clone();
    flat.nodes.retain(|n| n.is_leaf);
    for n in &mut flat.nodes {
        n.r_min = 0.0;
        n.r_max = ROOT_R_MAX;
    }
    flat
}

fn single(object: PointObject) -> Scene {
    let mut points = PointScene::default();
    points.add(object, PointTransform::parse("r=90,0,0").unwrap());
    Scene::points_only(points)
}

fn camera_at(distance: f64) -> Camera {
    Camera {
        eye: DVec3::new(0.0, -distance, 0.1 + 0.2 * distance),
        target: DVec3::new(-0.02, 0.0, 0.09),
        up: DVec3::Z,
        fov_y_deg: 40.0,
        near: 0.01,
        far: 1000.0,
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let hybrid_only = std::env::args().any(|a| a == "--hybrid");
    let frames = if quick { 3 } else { 10 };
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })
    .expect("Vulkan context");
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_info);
    let spt = alpenglow::points::build::spt::SptOptions {
        epsilon: epsilon_from_pixels(1.0, 40f32.to_radians(), SIDE).unwrap(),
        ..Default::default()
    };
    let options = PointLoadOptions {
        mesh_samples: 100_000,
        spt,
        ..PointLoadOptions::default()
    };
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/models");
    if hybrid_only {
        hybrid_against_points(&ctx, &options, &models, frames);
        return;
    }
    let bunny = load_point_object(&models.join("stanford-bunny.obj"), &options).expect("bunny");
    let leaves = PointObject::new("bunny leaves", all_leaves(&bunny.tree));
    let flat = single(leaves);
    let close = camera_at(0.25);

    println!(
        "\n1. {} leaves as a flat list, {SIDE}² window, two-sided (every splat drawn):",
        flat.points.total_splats()
    );
    println!("| mode | primitive | splats drawn | GPU ms (points passes) | M splats/s |");
    println!("|---|---|---|---|---|");
    for mode in SplatMode::ALL {
        for primitive in SplatPrimitive::ALL {
            let settings = SplatSettings {
                mode,
                primitive,
                two_sided: true,
                ..SplatSettings::default()
            };
            let m = measure(&ctx, &flat, &close, settings, frames);
            println!(
                "| {} | {} | {} | {:.1} | {:.2} |",
                mode.name(),
                primitive.name(),
                m.drawn,
                m.gpu_ms,
                m.drawn as f64 / m.gpu_ms / 1e3
            );
        }
    }

    println!(
        "\n2. Sequential point tree ({} nodes) against every leaf, EWA quads:",
        bunny.tree.nodes.len()
    );
    println!("| eye distance (m) | SPT prefix | SPT drawn | SPT GPU ms | leaves drawn | leaves GPU ms |");
    println!("|---|---|---|---|---|---|");
    let tree_scene = single(bunny);
    for distance in [0.25, 0.5, 1.0, 2.0, 4.0] {
        let camera = camera_at(distance);
        let settings = SplatSettings::default();
        let s = measure(&ctx, &tree_scene, &camera, settings, frames);
        let l = measure(&ctx, &flat, &camera, settings, frames);
        println!(
            "| {distance} | {} | {} | {:.1} | {} | {:.1} |",
            s.prefix, s.drawn, s.gpu_ms, l.drawn, l.gpu_ms
        );
    }

    println!("\n3. CPU selection per frame, default scene (300 rock instances):");
    let mut scene = Scene::default_terrain().expect("default terrain");
    scene
        .add_rocks(alpenglow::renderer::scene::DEFAULT_ROCKS.2)
        .expect("rocks");
    let m = measure(&ctx, &scene, &scene.default_camera(), SplatSettings::default(), frames);
    println!(
        "median {:.3} ms per frame, {:.2} µs per instance",
        m.cpu_ms,
        m.cpu_ms * 1e3 / scene.points.instances.len() as f64
    );
    hybrid_against_points(&ctx, &options, &models, frames);
}

/// Part 4: each model with and without its triangles (EWA quads).
fn hybrid_against_points(ctx: &Context, options: &PointLoadOptions, models: &std::path::Path, frames: usize) {
    // The teapot scaled to about the bunny's size.
    for (file, transform) in [("stanford-bunny.obj", "r=90,0,0"), ("teapot.obj", "r=90,0,0;s=0.05")] {
        let load = |hybrid| {
            let options = PointLoadOptions {
                hybrid,
                ..options.clone()
            };
            let object = load_point_object(&models.join(file), &options).expect("model");
            let mut points = PointScene::default();
            points.add(object, PointTransform::parse(transform).unwrap());
            Scene::points_only(points)
        };
        let (points, hybrid) = (load(false), load(true));
        println!(
            "\n4. Hybrid point–polygon against points only, {file} ({} triangles, {} nodes; {} nodes in the hybrid list), EWA quads:",
            hybrid.points.objects[0].triangle_count(),
            points.points.total_splats(),
            hybrid.points.total_splats()
        );
        println!(
            "| eye distance (m) | points: splats drawn | GPU ms | hybrid: splats drawn | triangles drawn | GPU ms |"
        );
        println!("|---|---|---|---|---|---|");
        for distance in [0.25, 0.5, 1.0, 2.0, 4.0] {
            let camera = camera_at(distance);
            let p = measure(ctx, &points, &camera, SplatSettings::default(), frames);
            let h = measure(ctx, &hybrid, &camera, SplatSettings::default(), frames);
            println!(
                "| {distance} | {} | {:.1} | {} | {} | {:.1} |",
                p.drawn, p.gpu_ms, h.drawn, h.triangles, h.gpu_ms
            );
        }
    }
}
