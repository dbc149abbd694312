//! Benchmark of single-pass splatting with a fuzzy depth test (dissertation
//! §10.4) against the three-pass mode (§10.2), on the hardware rasterizer
//! and in compute (issue 29), in the same run:
//! `cargo run --release -p alpenglow-bench --bin splat_modes_bench [-- --quick] [--instances N]`.
//!
//! `--frames N` times N frames (3 with `--quick`, else 8).
//! `--compute-only` leaves out the hardware rasterizer's row (the ratios are
//! then against the compute three passes, the first row).
//!
//! `--instances N` draws N copies of the leaves (sharing one splat list) on
//! a grid 0.3 m apart, N ≥ 10 for 10⁶ splats and N ≥ 100 for 10⁷, from a
//! distant view only (pulled back to see the grid).
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
    RasterPath, Renderer, Scene, Settings, SplatBackend, SplatMode, SplatSettings,
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

fn measure(
    ctx: &Context,
    (scene, camera): (&Scene, &Camera),
    (points, raster): (SplatSettings, RasterPath),
    frames: usize,
) -> Measured {
    let mut settings = Settings::new(SIDE, SIDE);
    settings.points = points;
    settings.raster = raster;
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

/// One row of the tables: a splat mode on a rasterizer path.
struct Mode {
    name: &'static str,
    mode: SplatMode,
    raster: RasterPath,
    backend: SplatBackend,
}

/// The modes the device can run: three-pass EWA on the hardware
/// rasterizer (the reference) and in compute, single-pass in compute and
/// with the interlock backend.
fn modes(ctx: &Context) -> Vec<Mode> {
    let compute = ctx.has_feature("shaderBufferInt64Atomics");
    let interlock = ctx.has_feature("fragmentShaderPixelInterlock");
    let mode = |name, mode, raster, backend| Mode {
        name,
        mode,
        raster,
        backend,
    };
    let all = [
        (
            mode(
                "three-pass EWA, hardware",
                SplatMode::Ewa,
                RasterPath::Hardware,
                SplatBackend::Compute,
            ),
            true,
        ),
        (
            mode(
                "three-pass EWA, compute",
                SplatMode::Ewa,
                RasterPath::Compute,
                SplatBackend::Compute,
            ),
            compute,
        ),
        (
            mode(
                "single-pass, compute",
                SplatMode::SinglePass,
                RasterPath::Auto,
                SplatBackend::Compute,
            ),
            true,
        ),
        (
            mode(
                "single-pass, interlock",
                SplatMode::SinglePass,
                RasterPath::Auto,
                SplatBackend::Interlock,
            ),
            interlock,
        ),
    ];
    all.into_iter()
        .filter(|(_, offered)| *offered)
        .map(|(m, _)| m)
        .collect()
}

/// `count` instances of object 0 of `points` on a grid 0.3 m apart (x
/// across the view, y away from it), the first where the single bunny stands.
fn instances(points: &mut PointScene, count: usize) -> usize {
    let side = (count as f64).sqrt().ceil() as usize;
    for k in 1..count {
        let (i, j) = ((k % side) as f64, (k / side) as f64);
        let x = (i - (side as f64 - 1.0) / 2.0) * 0.3;
        let transform = PointTransform::parse(&format!("t={x},{},0;r=90,0,0", j * 0.3)).unwrap();
        points.add_instance(0, transform).expect("instance");
    }
    side
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let compute_only = args.iter().any(|a| a == "--compute-only");
    let count: usize = (args.iter().position(|a| a == "--instances"))
        .and_then(|i| args.get(i + 1))
        .map(|n| n.parse().expect("--instances N"))
        .unwrap_or(1)
        .max(1);
    let frames: usize = (args.iter().position(|a| a == "--frames"))
        .and_then(|i| args.get(i + 1))
        .map(|n| n.parse().expect("--frames N"))
        .unwrap_or(if quick { 3 } else { 8 })
        .max(1);
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })
    .expect("Vulkan context");
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_info);
    println!(
        "64-bit buffer atomics: {}, fragment shader interlock: {}",
        ctx.has_feature("shaderBufferInt64Atomics"),
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
    let splats = leaves.tree.nodes.len();
    points.add(leaves, PointTransform::parse("r=90,0,0").unwrap());
    let side = instances(&mut points, count);
    let scene = Scene::points_only(points);
    println!(
        "{count} × {splats} leaves as a flat list ({} splats), {SIDE}² window, two-sided, {frames} timed frames",
        count * splats
    );
    let views: &[(&str, f64)] = match count {
        1 => &[("distant", 2.0), ("close", 0.25)],
        _ => &[("distant", 2.0 * (side as f64 / 3.0).max(1.0))],
    };
    let mut modes = modes(&ctx);
    if compute_only {
        modes.retain(|m| m.raster != RasterPath::Hardware);
    }
    let reference_name = modes.first().map_or("", |m| m.name);
    for &(view, distance) in views {
        let camera = camera_at(distance);
        println!("\n{view} view ({distance} m):");
        println!("| mode | splats drawn | GPU ms, median (best) | M splats/s, median (best) | × {reference_name}, median (best) | FLIP vs {reference_name} |");
        println!("|---|---|---|---|---|---|");
        let mut reference: Option<(Measured, [f64; 2])> = None;
        let mut breakdown = Vec::new();
        for m in &modes {
            let settings = SplatSettings {
                mode: m.mode,
                backend: m.backend,
                two_sided: true,
                ..SplatSettings::default()
            };
            let measured = measure(&ctx, (&scene, &camera), (settings, m.raster), frames);
            let rates = [measured.gpu_ms, measured.best_ms].map(|ms| measured.drawn as f64 / ms / 1e3);
            let (speedup, flip) = match &reference {
                Some((r, r_rates)) => (
                    [rates[0] / r_rates[0], rates[1] / r_rates[1]],
                    mean_flip(&r.rgba8, &measured.rgba8),
                ),
                None => ([1.0; 2], 0.0),
            };
            println!(
                "| {} | {} | {:.1} ({:.1}) | {:.2} ({:.2}) | {:.2} ({:.2}) | {flip:.4} |",
                m.name, measured.drawn, measured.gpu_ms, measured.best_ms, rates[0], rates[1], speedup[0], speedup[1]
            );
            let passes: Vec<String> = measured.passes.iter().map(|(n, ms)| format!("{n} {ms:.1}")).collect();
            let tiles = match measured.tiles {
                (0, _) => String::new(),
                (longest, dropped) => format!(" (longest tile list {longest}, {dropped} entries dropped)"),
            };
            breakdown.push(format!("  {}: {}{tiles}", m.name, passes.join(", ")));
            if reference.is_none() {
                reference = Some((measured, rates));
            }
        }
        println!("GPU ms per pass:\n{}", breakdown.join("\n"));
    }
}
