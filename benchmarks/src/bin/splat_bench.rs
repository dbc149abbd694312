//! Benchmark of point rendering (dissertation §10.1.7, §10.2, §10.3):
//! `cargo run --release -p alpenglow-bench --bin splat_bench [-- --quick]`.
//!
//! 1. Table 10.3: frames and splats per second of each primitive in the
//!    three passes of EWA splatting (and in the opaque mode), the text's set
//!    (point primitives with the EWA set-up, quadruplicated and instanced
//!    object-space quads with the kernel in a texture) beside alpenglow's own
//!    (EWA quads by vertex pulling, instanced EWA quads, EWA points), with
//!    the text's fps: the bunny sampled into N ≈ 101 685 surfels like the
//!    text's, every leaf drawn (a flat list: no level of detail), a close
//!    view covering a 512² window.
//! 2. The sequential point tree against drawing every leaf, at several
//!    distances: splats in the prefix, splats drawn, GPU time; and the SPT
//!    rate (splats sent and drawn per second) of a field of 64 bunnies at
//!    2.7–6.5 m, opaque points as in the text (§10.1.7: ~60 M points/s on a
//!    Radeon 9700, ~80 M on a GeForce 6800 GT) and EWA quads, and EWA
//!    splats in compute (issue 29). Every other table draws on the hardware
//!    rasterizer (the primitives are its).
//! 3. CPU time of the per-frame selection per object instance: the default
//!    scene's 300 rock instances.
//! 4. Hybrid point–polygon rendering (§10.1.8) against points only, at
//!    several distances: splats and triangles drawn, GPU time
//!    (`-- --hybrid` runs only this part).
//!
//! `-- --primitives` runs only part 1 and the SPT rate; `-- --kernels` only
//! part 5; `-- --spt-error` only part 6.
//! 5. The perspective-accurate kernel against the affine EWA approximation
//!    (§10.2, Figs. 10.15–10.17): part 1's close view of every leaf, EWA
//!    quads, on the hardware rasterizer and the compute path.
//! 6. The isotropic SPT error against the view-dependent one (§10.1.4,
//!    §10.1.7): the bunny's tree at several distances and the field of 64
//!    bunnies, EWA quads on both paths: splats passing the interval test,
//!    drawn, GPU time.
//!
//! GPU times are the medians of the points passes' timestamps over the timed
//! frames (the passes that draw the view: visibility, accumulation and
//! normalisation, or opaque; not `points.shadow`, the sun's shadow map);
//! splats/s = splats drawn (the vertex stage's count) / that time.

use alpenglow::bench::{PointInstance, QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT};
use alpenglow::files::load_point_object;
use alpenglow::tools::profile::median;
use alpenglow::tools::spt::epsilon_from_pixels;
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, PointLoadOptions, PointObject, PointScene, PointTransform,
    RasterPath, Renderer, Scene, Settings, SplatKernel, SplatMode, SplatPrimitive, SplatSettings, SptError,
};

use alpenglow_bench::points::{all_leaves, camera_at};
use glam::DVec3;

const SIDE: u32 = 512;
/// Surfels sampled from the bunny mesh (each a leaf): the text's N = 101 685.
const MESH_SAMPLES: usize = 101_685;
/// Table 10.3 (GeForce 6800 GT, N = 101 685, 512²): fps of the text's primitives.
const TEXT_FPS: [(SplatPrimitive, &str, f64); 3] = [
    (
        SplatPrimitive::Point,
        "Perspective Accurate Splatting (point primitives)",
        50.0,
    ),
    (SplatPrimitive::ObjectQuad, "Quadruplication", 97.8),
    (SplatPrimitive::ObjectInstanced, "Instancing", 29.7),
];

struct Measured {
    gpu_ms: f64,
    /// The fastest timed frame's GPU ms (the least disturbed by other work
    /// on a shared machine).
    best_ms: f64,
    prefix: u64,
    passed: u64,
    drawn: u64,
    triangles: u64,
    cpu_ms: f64,
}

fn measure(ctx: &Context, scene: &Scene, camera: &Camera, points: SplatSettings, frames: usize) -> Measured {
    measure_on(ctx, (scene, camera), (points, RasterPath::Hardware), frames)
}

/// As [`measure`] on rasterizer path `raster` (the primitives are the
/// hardware rasterizer's: every table but the SPT rate's compute row draws there).
fn measure_on(
    ctx: &Context,
    (scene, camera): (&Scene, &Camera),
    (points, raster): (SplatSettings, RasterPath),
    frames: usize,
) -> Measured {
    let mut settings = Settings::new(SIDE, SIDE);
    settings.readback = false;
    settings.points = points;
    settings.raster = raster;
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let warmup = 2;
    for _ in 0..warmup + frames {
        renderer.render(camera).expect("frame");
    }
    let profiles = renderer.finish().expect("finish");
    let stats = renderer.take_point_stats().expect("stats");
    let per_frame: Vec<f64> = (profiles.iter().skip(warmup))
        .map(|p| {
            p.passes
                .iter()
                .filter(|p| p.name.starts_with("points.") && !p.name.starts_with("points.shadow"))
                .map(|p| p.gpu_ms)
                .sum::<f64>()
        })
        .collect();
    let gpu_ms = median(per_frame.iter().copied());
    let best_ms = per_frame.iter().copied().fold(f64::INFINITY, f64::min);
    let last = stats.last().expect("point statistics");
    Measured {
        gpu_ms,
        best_ms,
        prefix: last.prefix_splats,
        passed: last.interval_passed.unwrap_or(0),
        drawn: last.drawn_splats.unwrap_or(0),
        triangles: last.triangles_drawn.unwrap_or(0),
        cpu_ms: median(stats.iter().skip(warmup).map(|s| s.cpu_ms)),
    }
}

fn single(object: PointObject) -> Scene {
    let mut points = PointScene::default();
    points.add(object, PointTransform::parse("r=90,0,0").unwrap());
    Scene::points_only(points)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let hybrid_only = std::env::args().any(|a| a == "--hybrid");
    let primitives_only = std::env::args().any(|a| a == "--primitives");
    let kernels_only = std::env::args().any(|a| a == "--kernels");
    let spt_error_only = std::env::args().any(|a| a == "--spt-error");
    let frames = if quick { 3 } else { 10 };
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })
    .expect("Vulkan context");
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_info);
    let spt = alpenglow::tools::spt::SptOptions {
        epsilon: epsilon_from_pixels(1.0, 40f32.to_radians(), SIDE).unwrap(),
        ..Default::default()
    };
    let options = PointLoadOptions {
        mesh_samples: MESH_SAMPLES,
        spt,
        ..PointLoadOptions::default()
    };
    let models = alpenglow_bench::repo_root().join("tests/data/models");
    if hybrid_only {
        hybrid_against_points(&ctx, &options, &models, frames);
        return;
    }
    let bunny = load_point_object(&models.join("stanford-bunny.obj"), &options).expect("bunny");
    let leaves = PointObject::new("bunny leaves", all_leaves(&bunny.tree));
    let flat = single(leaves);
    let close = camera_at(0.25);

    if kernels_only {
        kernels(&ctx, &flat, &close, frames);
        return;
    }
    if spt_error_only {
        spt_errors(&ctx, &bunny, frames);
        return;
    }
    table_10_3(&ctx, &flat, &close, frames);
    if primitives_only {
        spt_rate(&ctx, &bunny, frames);
        return;
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

    spt_rate(&ctx, &tree_scene.points.objects[0], frames);

    println!("\n3. CPU selection per frame, default scene (300 rock instances):");
    let mut scene = Scene::default_terrain().expect("default terrain");
    scene.add_rocks(alpenglow::DEFAULT_ROCKS.2).expect("rocks");
    let m = measure(&ctx, &scene, &scene.default_camera(), SplatSettings::default(), frames);
    println!(
        "median {:.3} ms per frame, {:.2} µs per instance",
        m.cpu_ms,
        m.cpu_ms * 1e3 / scene.points.instances.len() as f64
    );
    hybrid_against_points(&ctx, &options, &models, frames);
    kernels(&ctx, &flat, &close, frames);
    spt_errors(&ctx, &tree_scene.points.objects[0], frames);
}

/// Part 6: the isotropic and the view-dependent SPT error (§10.1.4, §10.1.7).
fn spt_errors(ctx: &Context, bunny: &PointObject, frames: usize) {
    println!("\n6. SPT error, {SIDE}² window, EWA quads, back faces culled:");
    println!("| scene | path | error | splats in prefixes | pass the interval test | drawn | GPU ms median (best) |");
    println!("|---|---|---|---|---|---|---|");
    let mut views: Vec<(String, Scene, Camera)> = [0.25, 1.0, 4.0]
        .map(|d| (format!("bunny at {d} m"), single(bunny.clone()), camera_at(d)))
        .into();
    let (field, field_camera) = bunny_field(bunny);
    views.push(("64 bunnies, 2.7–6.5 m".into(), field, field_camera));
    let mut paths = vec![RasterPath::Hardware];
    if ctx.has_feature("shaderBufferInt64Atomics") {
        paths.push(RasterPath::Compute);
    }
    for (name, scene, camera) in &views {
        for &raster in &paths {
            for error in SptError::ALL {
                let settings = SplatSettings {
                    error,
                    ..SplatSettings::default()
                };
                let m = measure_on(ctx, (scene, camera), (settings, raster), frames);
                let counts = [m.prefix, m.passed, m.drawn].map(|c| c.to_string()).join(" | ");
                let timing = format!("{:.1} ({:.1})", m.gpu_ms, m.best_ms);
                println!(
                    "| {name} | {} | {} | {counts} | {timing} |",
                    raster.name(),
                    error.name()
                );
            }
        }
    }
}

/// Part 5: the two splat kernels (§10.2) on both rasterizer paths.
fn kernels(ctx: &Context, flat: &Scene, close: &Camera, frames: usize) {
    println!("\n5. Splat kernels, {SIDE}² window, every leaf, EWA quads, two-sided:");
    println!("| path | kernel | splats drawn | GPU ms median (best) |");
    println!("|---|---|---|---|");
    for raster in [RasterPath::Hardware, RasterPath::Compute] {
        for kernel in SplatKernel::ALL {
            let settings = SplatSettings {
                kernel,
                two_sided: true,
                ..SplatSettings::default()
            };
            let m = measure_on(ctx, (flat, close), (settings, raster), frames);
            println!(
                "| {} | {} | {} | {:.1} ({:.1}) |",
                raster.name(),
                kernel.name(),
                m.drawn,
                m.gpu_ms,
                m.best_ms
            );
        }
    }
}

/// Part 1: Table 10.3, the text's primitive set and alpenglow's, in both modes.
fn table_10_3(ctx: &Context, flat: &Scene, close: &Camera, frames: usize) {
    let n = flat.points.total_splats();
    println!("\n1. Table 10.3: {n} leaves as a flat list, {SIDE}² window, two-sided (every splat drawn):");
    println!("| mode | set | primitive | splats drawn | GPU ms median (best) | fps median (best) | M splats/s median (best) | text fps (GeForce 6800 GT) |");
    println!("|---|---|---|---|---|---|---|---|");
    let rows = [
        ("text", SplatPrimitive::Point),
        ("text", SplatPrimitive::ObjectQuad),
        ("text", SplatPrimitive::ObjectInstanced),
        ("alpenglow", SplatPrimitive::Quad),
        ("alpenglow", SplatPrimitive::Instanced),
    ];
    for mode in [SplatMode::Ewa, SplatMode::Opaque] {
        for (set, primitive) in rows {
            let settings = SplatSettings {
                mode,
                primitive,
                two_sided: true,
                ..SplatSettings::default()
            };
            let m = measure(ctx, flat, close, settings, frames);
            let text = TEXT_FPS
                .iter()
                .find(|(p, _, _)| *p == primitive && mode == SplatMode::Ewa && set == "text")
                .map_or("–".to_string(), |(_, name, fps)| format!("{fps} ({name})"));
            println!(
                "| {} | {set} | {} | {} | {:.1} ({:.1}) | {:.2} ({:.2}) | {:.2} ({:.2}) | {text} |",
                mode.name(),
                primitive.name(),
                m.drawn,
                m.gpu_ms,
                m.best_ms,
                1e3 / m.gpu_ms,
                1e3 / m.best_ms,
                m.drawn as f64 / m.gpu_ms / 1e3,
                m.drawn as f64 / m.best_ms / 1e3
            );
        }
    }
    println!(
        "quadruplication: {QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT} bytes per splat on top of the 64-byte splat record ({:.1} MB for {n} splats)",
        (QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT * n as u64) as f64 / 1e6
    );
}

/// Part 2b: the SPT rate of a field of 8×8 bunnies 0.5 m apart seen from
/// 2.5 m before its front row, 1.2 m up (the text's set-up: opaque point
/// primitives, §10.1.7; and EWA quads): splats sent (prefixes) and drawn per
/// second.
fn spt_rate(ctx: &Context, bunny: &PointObject, frames: usize) {
    let (scene, camera) = bunny_field(bunny);
    println!("\nSPT rate: 64 bunny instances at 2.7–6.5 m, {SIDE}² window, back faces culled:");
    println!(
        "| mode | primitive | shaded | splats sent (prefixes) | splats drawn | GPU ms median (best) | M splats/s sent | M splats/s drawn median (best) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    // Opaque unlit points are the text's "single-colored point primitives";
    // the last row: EWA splats in compute (issue 29), where the device can.
    let mut rows = vec![
        (SplatMode::Opaque, SplatPrimitive::Point, false, RasterPath::Hardware),
        (SplatMode::Opaque, SplatPrimitive::Point, true, RasterPath::Hardware),
        (SplatMode::Ewa, SplatPrimitive::Quad, true, RasterPath::Hardware),
        (SplatMode::Ewa, SplatPrimitive::ObjectQuad, true, RasterPath::Hardware),
    ];
    if ctx.has_feature("shaderBufferInt64Atomics") {
        rows.push((SplatMode::Ewa, SplatPrimitive::Quad, true, RasterPath::Compute));
    }
    for (mode, primitive, shaded, raster) in rows {
        let settings = SplatSettings {
            mode,
            primitive,
            shaded,
            ..SplatSettings::default()
        };
        let m = measure_on(ctx, (&scene, &camera), (settings, raster), frames);
        let primitive = match raster {
            RasterPath::Compute => "compute",
            _ => primitive.name(),
        };
        println!(
            "| {} | {} | {} | {} | {} | {:.1} ({:.1}) | {:.2} | {:.2} ({:.2}) |",
            mode.name(),
            primitive,
            if shaded { "yes" } else { "no" },
            m.prefix,
            m.drawn,
            m.gpu_ms,
            m.best_ms,
            m.prefix as f64 / m.gpu_ms / 1e3,
            m.drawn as f64 / m.gpu_ms / 1e3,
            m.drawn as f64 / m.best_ms / 1e3
        );
    }
}

/// 64 standing instances of `bunny` on an 8 × 8 grid 0.5 m apart, and a
/// camera that sees them at 2.7–6.5 m.
fn bunny_field(bunny: &PointObject) -> (Scene, Camera) {
    let standing = PointTransform::parse("r=90,0,0").unwrap();
    let mut points = PointScene {
        objects: vec![bunny.clone()],
        ..PointScene::default()
    };
    for j in 0..8 {
        for i in 0..8 {
            let translation = DVec3::new(0.5 * (i as f64 - 3.5), 0.5 * j as f64, 0.0);
            let transform = PointTransform {
                translation,
                ..standing
            };
            points.instances.push(PointInstance { object: 0, transform });
        }
    }
    let camera = Camera {
        eye: DVec3::new(0.0, -2.5, 1.2),
        target: DVec3::new(0.0, 1.75, 0.0),
        ..camera_at(1.0)
    };
    (Scene::points_only(points), camera)
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
