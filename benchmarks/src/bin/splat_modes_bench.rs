//! Benchmark of single-pass splatting with a fuzzy depth test (dissertation
//! §10.4) against the three-pass mode (§10.2), in the same run:
//! `cargo run --release -p alpenglow-bench --bin splat_modes_bench [-- --quick]`.
//!
//! The bunny sampled into ~100k surfels, every leaf drawn (a flat list, two
//! sided: every splat goes through the EWA set-up), in a 512² window, from a
//! distant view (splats about a pixel) and a close one (splats of tens of
//! pixels), as the text's measurement (GeForce 6800 GT: 17.8 vs 9.9 and
//! 11.1 vs 6.0 M splats/s). Per mode: splats drawn (the GPU's count), the
//! median GPU time of the splatting passes' timestamps over the timed frames
//! (every `points.*` pass but the sun's shadow casters `points.shadow`, the
//! same for both modes) and the shortest (the least disturbed on a shared
//! machine),
//! M splats/s, the time of each pass, and the image quality: mean FLIP of the
//! single-pass image against the three-pass one (same frame, tone-mapped).

use alpenglow::files::load_point_object;
use alpenglow::tools::profile::median;
use alpenglow::tools::spt::epsilon_from_pixels;
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, PointLoadOptions, PointObject, PointScene, PointTransform,
    Renderer, Scene, Settings, SplatBackend, SplatMode, SplatSettings,
};

use alpenglow_bench::points::{all_leaves, camera_at};

const SIDE: u32 = 512;

struct Measured {
    /// Median GPU time of the splatting passes, ms.
    gpu_ms: f64,
    /// Their shortest time over the timed frames, ms: the least disturbed
    /// by other work on a shared machine.
    best_ms: f64,
    /// Median GPU time per points pass, ms, in submission order.
    passes: Vec<(String, f64)>,
    drawn: u64,
    /// Single pass, compute backend: the longest tile list and the tile
    /// entries dropped for want of capacity (0 in the other modes).
    tiles: (u64, u64),
    /// The last frame, tone-mapped sRGB.
    rgba8: Vec<u8>,
}

fn measure(ctx: &Context, scene: &Scene, camera: &Camera, points: SplatSettings, frames: usize) -> Measured {
    let mut settings = Settings::new(SIDE, SIDE);
    settings.points = points;
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let warmup = 2;
    for _ in 0..warmup + frames - 1 {
        renderer.render(camera).expect("frame");
    }
    let last = renderer.render(camera).expect("frame");
    let rgba8 = renderer.read(&last).expect("read back").rgba8;
    let profiles = renderer.finish().expect("finish");
    let stats = renderer.take_point_stats().expect("stats");
    let timed = || profiles.iter().skip(warmup);
    let points_passes = |p: &alpenglow::FrameProfile| {
        p.passes
            .iter()
            .filter(|p| p.name.starts_with("points.") && !p.name.starts_with("points.shadow"))
            .map(|p| (p.name.clone(), p.gpu_ms))
            .collect::<Vec<_>>()
    };
    let names: Vec<String> = timed()
        .next()
        .map(|p| points_passes(p).into_iter().map(|(n, _)| n).collect())
        .unwrap_or_default();
    let passes = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let ms = median(timed().filter_map(|p| points_passes(p).get(i).map(|(_, ms)| *ms)));
            (name.clone(), ms)
        })
        .collect();
    let totals: Vec<f64> = timed()
        .map(|p| points_passes(p).iter().map(|(_, ms)| ms).sum::<f64>())
        .collect();
    Measured {
        gpu_ms: median(totals.iter().copied()),
        best_ms: totals.iter().copied().fold(f64::INFINITY, f64::min),
        passes,
        drawn: stats.last().and_then(|s| s.drawn_splats).unwrap_or(0),
        tiles: stats.last().map_or((0, 0), |s| {
            (s.longest_tile_list.unwrap_or(0), s.tile_entries_dropped.unwrap_or(0))
        }),
        rgba8,
    }
}

fn mean_flip(reference: &[u8], test: &[u8]) -> f32 {
    let rgb = |rgba: &[u8]| -> Vec<u8> { rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let a = nv_flip::FlipImageRgb8::with_data(SIDE, SIDE, &rgb(reference));
    let b = nv_flip::FlipImageRgb8::with_data(SIDE, SIDE, &rgb(test));
    let error = nv_flip::flip(a, b, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&error).mean()
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let frames = if quick { 3 } else { 8 };
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })
    .expect("Vulkan context");
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_info);
    println!(
        "fragment shader interlock: {}",
        ctx.has_feature("fragmentShaderPixelInterlock")
    );
    let options = PointLoadOptions {
        mesh_samples: 100_000,
        spt: alpenglow::tools::spt::SptOptions {
            epsilon: epsilon_from_pixels(1.0, 40f32.to_radians(), SIDE).unwrap(),
            ..Default::default()
        },
        ..PointLoadOptions::default()
    };
    let models = alpenglow_bench::repo_root().join("tests/data/models");
    let bunny = load_point_object(&models.join("stanford-bunny.obj"), &options).expect("bunny");
    let mut points = PointScene::default();
    let leaves = PointObject::new("bunny leaves", all_leaves(&bunny.tree));
    points.add(leaves, PointTransform::parse("r=90,0,0").unwrap());
    let scene = Scene::points_only(points);
    println!(
        "{} leaves as a flat list, {SIDE}² window, two-sided, {frames} timed frames",
        scene.points.total_splats()
    );

    let mut modes = vec![
        ("three-pass EWA", SplatMode::Ewa, SplatBackend::Compute),
        (
            "single-pass, tiles (compute)",
            SplatMode::SinglePass,
            SplatBackend::Compute,
        ),
    ];
    if ctx.has_feature("fragmentShaderPixelInterlock") && ctx.has_feature("fragmentStoresAndAtomics") {
        modes.push(("single-pass, interlock", SplatMode::SinglePass, SplatBackend::Interlock));
    }
    for (view, distance) in [("distant", 2.0), ("close", 0.25)] {
        let camera = camera_at(distance);
        println!("\n{view} view ({distance} m):");
        println!("| mode | splats drawn | GPU ms, median (best) | M splats/s, median (best) | × three-pass, median (best) | FLIP vs three-pass |");
        println!("|---|---|---|---|---|---|");
        let mut reference: Option<(Measured, [f64; 2])> = None;
        let mut breakdown = Vec::new();
        for &(name, mode, backend) in &modes {
            let settings = SplatSettings {
                mode,
                backend,
                two_sided: true,
                ..SplatSettings::default()
            };
            let m = measure(&ctx, &scene, &camera, settings, frames);
            let rates = [m.gpu_ms, m.best_ms].map(|ms| m.drawn as f64 / ms / 1e3);
            let (speedup, flip) = match &reference {
                Some((r, r_rates)) => (
                    [rates[0] / r_rates[0], rates[1] / r_rates[1]],
                    mean_flip(&r.rgba8, &m.rgba8),
                ),
                None => ([1.0; 2], 0.0),
            };
            println!(
                "| {name} | {} | {:.1} ({:.1}) | {:.2} ({:.2}) | {:.2} ({:.2}) | {flip:.4} |",
                m.drawn, m.gpu_ms, m.best_ms, rates[0], rates[1], speedup[0], speedup[1]
            );
            let passes: Vec<String> = m.passes.iter().map(|(n, ms)| format!("{n} {ms:.1}")).collect();
            let tiles = match m.tiles {
                (0, _) => String::new(),
                (longest, dropped) => format!(" (longest tile list {longest}, {dropped} entries dropped)"),
            };
            breakdown.push(format!("  {name}: {}{tiles}", passes.join(", ")));
            if reference.is_none() {
                reference = Some((m, rates));
            }
        }
        println!("GPU ms per pass:\n{}", breakdown.join("\n"));
    }
}
