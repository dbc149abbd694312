//! Soak run (issue 15, part 5): many frames of a `fly` orbit over the
//! default scene with texture streaming forced to evict (the smallest atlas
//! there is, shrunk further to 256² textures, and a budget of 4 tiles a
//! frame), reporting whether memory or frame times drift. The geometry is
//! kept light for CPU Vulkan (a 128² terrain grid, a 512² shadow atlas):
//! what is soaked is the per-frame work and its bookkeeping, not fill rate.
//!
//! `cargo run --release --example soak -- [--frames N] [--width W] [--height H]`
//! (default 10,000 frames of 160×100). Not part of `cargo test`.
//!
//! Reported: resident memory (VmRSS of /proc/self/status, sampled every
//! 100 frames: first, last, largest, and the slope of a least-squares line
//! in KiB per 1000 frames), GPU memory allocated through gpu-allocator
//! (`Context::allocated_bytes`) at the first and last sample, texture tiles
//! generated and evicted, and the wall time per frame (submission, with any
//! wait for a free frame slot): median of the first and last 1000 frames
//! and p99. Profiles and texture statistics are taken every 100 frames, so
//! the renderer keeps none of them.

use std::time::Instant;

use alpenglow::tools::profile::{median, quantile, summarize};
use alpenglow::{
    CameraPath, Context, ContextOptions, DeviceSelector, FrameProfile, Orbit, Renderer, Scene, Settings,
    ShadowSettings, TerrainSettings, TextureStreaming,
};
use glam::DVec3;

/// Frames between memory samples (and profile collection).
const SAMPLE_EVERY: u32 = 100;
/// Frames at each end compared for drift.
const WINDOW: usize = 1000;

struct Args {
    frames: u32,
    width: u32,
    height: u32,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        frames: 10_000,
        width: 160,
        height: 100,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().ok_or_else(|| format!("{flag}: missing value"))?;
        let number = value
            .parse::<u32>()
            .ok()
            .filter(|&v| v >= 1)
            .ok_or_else(|| format!("{flag}: {value:?} is not a whole number from 1 to {}", u32::MAX))?;
        match flag.as_str() {
            "--frames" => args.frames = number,
            "--width" => args.width = number,
            "--height" => args.height = number,
            _ => return Err(format!("unknown argument {flag:?} (use --frames, --width, --height)")),
        }
    }
    Ok(args)
}

/// Resident memory of this process in KiB (Linux; None elsewhere).
fn rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Slope of the least-squares line through `(x, y)` points.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Streaming that must evict: the minimal atlas with 256² textures (a few
/// slots per tile size) and 4 tiles generated per frame.
fn evicting_streaming(width: u32, height: u32) -> alpenglow::Result<TextureStreaming> {
    let mut streaming = TextureStreaming::for_views_within(&[(width, height)], TextureStreaming::min_atlas_bytes())?;
    streaming.atlas.size = 256;
    streaming.atlas.max_tile = streaming.atlas.max_tile.min(256);
    let streaming = streaming.with_tile_budget(4)?;
    streaming.validate()?;
    Ok(streaming)
}

struct Sample {
    frame: u32,
    rss_kib: u64,
    gpu_bytes: u64,
}

fn run(args: &Args) -> alpenglow::Result<()> {
    let scene = Scene::default_terrain()?;
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    let mut settings = Settings::new(args.width, args.height);
    settings.readback = false;
    settings.texture_streaming = evicting_streaming(args.width, args.height)?;
    settings.terrain = TerrainSettings {
        grid_side: 128,
        ..TerrainSettings::default()
    };
    settings.shadows = ShadowSettings {
        atlas_size: 512,
        ..ShadowSettings::default()
    };
    let atlas_kib = settings.texture_streaming.atlas_bytes() / 1024;
    let mut renderer = Renderer::new(&ctx, &scene, settings)?;
    // Five turns low over the terrain: every part is seen, left and seen again.
    let extent = scene.heights.extent();
    let (lo, hi) = scene.height_range();
    let path = CameraPath::Orbit(Orbit {
        centre: DVec3::new(extent.x * 0.5, extent.y * 0.5, f64::from(lo)),
        radius: extent.x.max(extent.y) * 0.25,
        height: f64::from(hi - lo) * 1.2,
        turns: 5.0,
        start_angle_deg: 0.0,
    });
    path.validate()?;
    let base = scene.default_camera();
    let mut wall = Vec::with_capacity(args.frames as usize);
    let mut samples = Vec::new();
    let (mut generated, mut evicted) = (0usize, 0usize);
    let mut last_profiles: Vec<FrameProfile> = Vec::new();
    let started = Instant::now();
    for i in 0..args.frames {
        let camera = path.sample_at(i, args.frames, &base);
        let t = Instant::now();
        renderer.render_views(&[camera])?;
        wall.push(t.elapsed().as_secs_f64() * 1e3);
        if (i + 1) % SAMPLE_EVERY == 0 || i + 1 == args.frames {
            last_profiles = renderer.finish()?;
            for s in renderer.take_texture_stats()? {
                generated += s.tiles.generated;
                evicted += s.tiles.evicted;
            }
            samples.push(Sample {
                frame: i + 1,
                rss_kib: rss_kib().unwrap_or(0),
                gpu_bytes: ctx.allocated_bytes(),
            });
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    report(args, &wall, &samples, (generated, evicted), atlas_kib, seconds, &ctx);
    let (mut passes, _) = summarize(&last_profiles);
    passes.sort_by(|a, b| b.median_gpu_ms.total_cmp(&a.median_gpu_ms));
    let costliest: Vec<String> = passes
        .iter()
        .take(4)
        .map(|p| format!("{} {:.2}", p.name, p.median_gpu_ms))
        .collect();
    println!(
        "costliest passes of the last {} frames (median GPU ms): {}",
        last_profiles.len(),
        costliest.join(", ")
    );
    Ok(())
}

fn report(
    args: &Args,
    wall: &[f64],
    samples: &[Sample],
    (generated, evicted): (usize, usize),
    atlas_kib: u64,
    seconds: f64,
    ctx: &Context,
) {
    let info = ctx.info();
    println!(
        "soak: {} frames of {}×{} on {} ({}), {:.1} frames/s ({seconds:.0} s)",
        args.frames,
        args.width,
        args.height,
        info.name,
        info.driver_info,
        f64::from(args.frames) / seconds
    );
    println!("textures: atlas {atlas_kib} KiB, {generated} tiles generated, {evicted} evicted");
    let (first, last) = (&samples[0], &samples[samples.len() - 1]);
    let max = samples.iter().map(|s| s.rss_kib).max().unwrap_or(0);
    let points: Vec<(f64, f64)> = samples.iter().map(|s| (f64::from(s.frame), s.rss_kib as f64)).collect();
    let per_1000 = if points.len() > 1 {
        slope(&points) * 1000.0
    } else {
        f64::NAN
    };
    println!(
        "RSS: {} KiB at frame {}, {} KiB at frame {}, max {max} KiB; slope {per_1000:+.1} KiB per 1000 frames",
        first.rss_kib, first.frame, last.rss_kib, last.frame
    );
    println!(
        "GPU allocated: {} KiB at frame {}, {} KiB at frame {}",
        first.gpu_bytes / 1024,
        first.frame,
        last.gpu_bytes / 1024,
        last.frame
    );
    let window = WINDOW.min(wall.len() / 2).max(1);
    let head = median(wall[..window].iter().copied());
    let tail = median(wall[wall.len() - window..].iter().copied());
    println!(
        "wall per frame (ms): median of the first {window} {head:.3}, of the last {window} {tail:.3} ({:+.1} %), p99 {:.3}, max {:.3}",
        (tail / head - 1.0) * 100.0,
        quantile(wall, 0.99),
        wall.iter().copied().fold(0.0, f64::max)
    );
}

fn main() {
    let outcome = parse_args().and_then(|args| run(&args).map_err(|e| e.to_string()));
    if let Err(e) = outcome {
        eprintln!("soak: {e}");
        std::process::exit(2);
    }
}
