//! `bench`: a still view rendered after warm-up frames, timed per pass
//! (median, p95, p99), with device memory and (`--pipeline-stats`) each
//! pass's pipeline statistics.

use std::process::ExitCode;

use anyhow::{anyhow, Result};
use serde_json::{json, Value};

use alpenglow::tools::budget::format_bytes;
use alpenglow::tools::profile::{chrome_trace, median, summarize, FrameSummary, PassSummary};
use alpenglow::{DeviceInfo, DeviceMemoryUse, FrameProfile, TextureSummary};

use super::args::BenchArgs;
use super::outputs::Outputs;
use super::renderdoc::{self, FrameCapture};
use super::{
    camera, check_frames, check_validation, context, lighting, load_scene, render_settings, rig, views,
    MAX_SETTLE_FRAMES,
};

/// What the timed frames of a bench run produced.
struct Run {
    timed: Vec<FrameProfile>,
    intervals: Vec<f64>,
    point_stats: Vec<alpenglow::PointFrameStats>,
    texture_stats: Vec<alpenglow::TextureFrameStats>,
    raster: alpenglow::RasterPath,
    memory: DeviceMemoryUse,
}

pub(super) fn bench(args: BenchArgs) -> Result<ExitCode> {
    let mut outputs = Outputs::default();
    outputs.add(args.profile.as_deref(), "--profile")?;
    outputs.add(args.trace.as_deref(), "--trace")?;
    check_frames(args.frames, args.warmup)?;
    let (rig, specs) = views(&args.scene)?;
    let mut scene = load_scene(&args.scene)?;
    // Frames along a path never wait for the detail window's tiles.
    scene.set_detail_window(args.scene.terrain.detail_window, false)?;
    let cameras = rig::frame_cameras(rig.as_ref(), &camera(&args.scene, &scene)?)?;
    // The frames after the settling ones: warm-up, then timed.
    let mut capture = FrameCapture::new(&args.renderdoc, u64::from(args.warmup) + u64::from(args.frames))?;
    let ctx = context(&args.scene.device)?;
    let report = ctx.validation_report();
    let device = ctx.info().clone();
    let run = {
        let settings = render_settings(&args.scene, &scene, &specs, false)?;
        let mut renderer = lighting::renderer(&ctx, &scene, settings)?;
        run_frames(&ctx, &mut renderer, &cameras, &args, &mut capture)?
    };
    drop(ctx);
    check_validation(report)?;
    let (passes, frame) = summarize(&run.timed);
    let sizes: Vec<String> = specs.iter().map(|v| format!("{}x{}", v.width, v.height)).collect();
    print_summary(&device, &sizes.join("+"), &run, &passes, &frame);
    let textures = report_textures(&run.texture_stats, &run.timed);
    if args.profile.is_some() {
        let mut value = json!({
            "textures": textures,
            "device": device,
            "raster": run.raster.name(),
            "width": args.scene.width,
            "height": args.scene.height,
            "views": specs.iter().map(|v| json!({"name": v.name, "width": v.width, "height": v.height})).collect::<Vec<_>>(),
            "points": run.point_stats,
        });
        extend(&mut value, frame_json(&run, &frame, &passes));
        let text = serde_json::to_string_pretty(&value)?;
        outputs.stage(args.profile.as_deref(), || Ok(text.into_bytes()))?;
    }
    outputs.stage(args.trace.as_deref(), || {
        Ok(chrome_trace(&device.name, &run.timed)?.into_bytes())
    })?;
    renderdoc::report(capture)?;
    outputs.commit()?;
    Ok(ExitCode::SUCCESS)
}

/// Renders the settling, warm-up and timed frames; keeps what the timed
/// ones produced.
fn run_frames(
    ctx: &alpenglow::Context,
    renderer: &mut alpenglow::Renderer,
    cameras: &[alpenglow::Camera],
    args: &BenchArgs,
    capture: &mut Option<FrameCapture>,
) -> Result<Run> {
    let raster = renderer.raster_path();
    renderer.set_pipeline_stats(args.pipeline_stats)?;
    // Every frame's profile is reported (the history is bounded by default).
    renderer.set_profile_history((args.warmup + args.frames + MAX_SETTLE_FRAMES) as usize);
    // A still view: first every texture tile (untimed), then warm-up and timed frames.
    let settle_frames = renderer.render_views_settled(cameras, MAX_SETTLE_FRAMES)?.frame + 1;
    let mut intervals = Vec::new();
    let mut last = std::time::Instant::now();
    for i in 0..args.warmup + args.frames {
        renderdoc::frame(capture, i.into(), || Ok(renderer.render_views(cameras)?))?;
        if i >= args.warmup {
            intervals.push(last.elapsed().as_secs_f64() * 1e3);
        }
        last = std::time::Instant::now();
    }
    let profiles = renderer.finish()?;
    let memory = ctx.memory_use();
    let untimed = (settle_frames + u64::from(args.warmup)) as usize;
    let timed: Vec<FrameProfile> = profiles.into_iter().skip(untimed).collect();
    if timed.is_empty() {
        return Err(anyhow!("no frame timings were collected"));
    }
    Ok(Run {
        timed,
        intervals,
        point_stats: renderer.take_point_stats()?.into_iter().skip(untimed).collect(),
        texture_stats: renderer.take_texture_stats()?.into_iter().skip(untimed).collect(),
        raster,
        memory,
    })
}

/// The frame, interval, memory and pass entries of the bench JSON.
fn frame_json(run: &Run, frame: &FrameSummary, passes: &[PassSummary]) -> Value {
    let interval_max = run.intervals.iter().copied().fold(0.0, f64::max);
    json!({
        "frames": frame.frames,
        "median_frame_gpu_ms": frame.median_gpu_ms,
        "p95_frame_gpu_ms": frame.p95_gpu_ms,
        "p99_frame_gpu_ms": frame.p99_gpu_ms,
        "median_frame_cpu_ms": frame.median_cpu_ms,
        "p95_frame_cpu_ms": frame.p95_cpu_ms,
        "p99_frame_cpu_ms": frame.p99_cpu_ms,
        "median_frame_interval_ms": median(run.intervals.iter().copied()),
        "max_frame_interval_ms": interval_max,
        "device_memory": run.memory,
        "passes": passes,
    })
}

/// Adds the entries of object `more` to object `value`.
fn extend(value: &mut Value, more: Value) {
    if let (Some(v), Value::Object(m)) = (value.as_object_mut(), more) {
        v.extend(m);
    }
}

/// Prints the frame, interval, memory, pass and point lines.
fn print_summary(device: &DeviceInfo, sizes: &str, run: &Run, passes: &[PassSummary], frame: &FrameSummary) {
    println!(
        "{} ({}, {}), {sizes}, {} frames: median frame {:.3} ms GPU (p95 {:.3}, p99 {:.3}), {:.3} ms CPU (p95 {:.3}, p99 {:.3})",
        device.name,
        device.device_type,
        device.driver_info,
        frame.frames,
        frame.median_gpu_ms,
        frame.p95_gpu_ms,
        frame.p99_gpu_ms,
        frame.median_cpu_ms,
        frame.p95_cpu_ms,
        frame.p99_cpu_ms,
    );
    let interval_median = median(run.intervals.iter().copied());
    let interval_max = run.intervals.iter().copied().fold(0.0, f64::max);
    println!("  frame interval   median {interval_median:>8.3} ms wall (max {interval_max:.3}), 2 frames in flight");
    println!("  {}", memory_line(&run.memory));
    for p in passes {
        println!(
            "  {:<16} median {:>8.3} ms GPU (p95 {:.3}, p99 {:.3}, min {:.3}, max {:.3}), {:.3} ms CPU (p99 {:.3})",
            p.name,
            p.median_gpu_ms,
            p.p95_gpu_ms,
            p.p99_gpu_ms,
            p.min_gpu_ms,
            p.max_gpu_ms,
            p.median_cpu_ms,
            p.p99_cpu_ms
        );
        if let Some(stats) = &p.pipeline_stats {
            println!("  {:<16} pipeline statistics (median): {}", p.name, stats.line());
        }
    }
    if let Some(stats) = run.point_stats.last() {
        println!("  {}", stats.summary());
        let cpu = median(run.point_stats.iter().map(|s| s.cpu_ms));
        println!(
            "  points CPU selection median {cpu:.3} ms per frame ({:.4} ms per instance)",
            cpu / stats.instances.max(1) as f64
        );
    }
}

/// `device memory 12.0 MiB allocated (16.0 MiB reserved), heaps 20.0 MiB of 4.0 GiB budget`.
fn memory_line(m: &DeviceMemoryUse) -> String {
    let heaps = match (m.heap_usage_bytes, m.heap_budget_bytes) {
        (Some(usage), Some(budget)) => format!(
            ", device-local heaps {} in use of {} budget (VK_EXT_memory_budget)",
            format_bytes(usage),
            format_bytes(budget)
        ),
        _ => String::new(),
    };
    format!(
        "device memory    {} allocated ({} reserved){heaps}",
        format_bytes(m.allocated_bytes),
        format_bytes(m.reserved_bytes)
    )
}

/// Prints the texture streaming summary of `stats` with the GPU times of
/// `profiles`; None (and nothing printed) without the atlas.
pub(crate) fn report_textures(
    stats: &[alpenglow::TextureFrameStats],
    profiles: &[FrameProfile],
) -> Option<TextureSummary> {
    let summary = (!stats.is_empty()).then(|| TextureSummary::new(stats, profiles))?;
    println!("  {}", summary.line());
    if let Some(line) = summary.per_pass_line() {
        println!("  {line}");
    }
    Some(summary)
}
