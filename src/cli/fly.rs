//! `alpenglow fly`: a camera path rendered to a PNG sequence (and with
//! `--exr` an EXR sequence with every channel, motion relative to the
//! path's previous frame) with a progress bar, and the per-frame times. The vertex count of the warped
//! terrain is constant (§7.4), so frame times should barely vary.
//!
//! Frames go into a hidden staging sibling of the output directory
//! (`.DIR.partial-PID-N`), renamed into place together with `--json` and
//! `--trace` when every frame was written (one output transaction,
//! `alpenglow::files::OutputTransaction`): on any error no partial
//! sequence is left behind, and a run that was killed leaves a staging
//! folder that the next run in that directory removes.
//!
//! The path's cameras are computed one frame at a time
//! (`CameraPath::sample_at`), so memory does not grow with `--frames`
//! beyond the per-frame timings (at most `MAX_FRAMES` frames).
//!
//! "wall per frame" is, for every frame alike (the first included), the
//! CPU time to submit it plus, with `--out-dir`, to read it back and write
//! its files; start-up (device, scene, renderer) is not part of it.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use super::lighting;
use anyhow::{bail, Context as _, Result};
use indicatif::{ProgressBar, ProgressStyle};

use alpenglow::files::{load_keyframes, write_png_rgba8};
use alpenglow::tools::profile::{chrome_trace, median, summarize};
use alpenglow::{Camera, CameraPath, FrameImages, FrameProfile, Orbit, Rig, Scene, TextureFrameStats};

use super::args::FlyArgs;
use super::renderdoc::{self, FrameCapture};
use super::{
    camera, check_frames, check_validation, context, load_scene, render_settings, report_textures, rig, views, Outputs,
};

/// The default path: one turn around the terrain's centre at 60 % of its
/// half-size, above the highest point ([`Orbit::around`]).
fn default_orbit(scene: &Scene) -> Orbit {
    let (lo, hi) = scene.height_range();
    Orbit::around(scene.heights.extent(), f64::from(lo), f64::from(hi))
}

/// The cameras of frame `i` of `frames` along `path` (a rig's views each).
/// The path sets eye and target: when they make an invalid camera (eye on
/// the target, a view along the up vector), the error names the path's
/// option `source` (`--path FILE`, `--orbit`), not --eye or --target.
fn frame_cameras(
    path: &CameraPath,
    source: &str,
    rig: Option<&Rig>,
    base: &Camera,
    i: u32,
    frames: u32,
) -> Result<Vec<Camera>> {
    let c = path.sample_at(i, frames, base);
    c.validate().map_err(|e| {
        let message = match &e {
            alpenglow::Error::InvalidArgument { message, .. } => message.clone(),
            other => other.to_string(),
        };
        match e.parameter() {
            Some("camera.eye" | "camera.target" | "camera") => anyhow::anyhow!("{source}: frame {i}: {message}"),
            Some("camera.up") => anyhow::anyhow!("{source}: frame {i}: {message} (--up, default 0,0,1)"),
            _ => anyhow::Error::from(e).context(format!("camera path frame {i}")),
        }
    })?;
    rig::frame_cameras(rig, &c).with_context(|| format!("camera path frame {i}"))
}

/// Frame `index` of the view `view` (a rig's views each get a folder).
fn frame_path(dir: &Path, view: &str, index: usize, extension: &str) -> PathBuf {
    dir.join(view).join(format!("frame_{index:05}.{extension}"))
}

fn stats(values: &[f64]) -> (f64, f64, f64) {
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(0.0, f64::max);
    (min, median(values.iter().copied()), max)
}

pub fn fly(args: FlyArgs) -> Result<ExitCode> {
    let mut outputs = Outputs::default();
    outputs.add(args.profile.as_deref(), "--profile")?;
    outputs.add(args.trace.as_deref(), "--trace")?;
    check_frames(args.frames, 0)?;
    if args.exr && args.out_dir.is_none() {
        bail!("--exr needs --out-dir DIR (the EXR frames go beside the PNG frames)");
    }
    if let Some(dir) = &args.out_dir {
        outputs.add_dir(dir, "--out-dir")?;
    }
    let (rig, specs) = views(&args.scene)?;
    let mut scene = load_scene(&args.scene)?;
    // Frames along a path never wait for the detail window's tiles.
    scene.set_detail_window(args.scene.terrain.detail_window, false)?;
    let base = camera(&args.scene, &scene)?;
    let (path, source) = match (&args.path, args.orbit) {
        (Some(file), _) => (load_keyframes(file)?, format!("--path {}", file.display())),
        (None, Some(orbit)) => (CameraPath::Orbit(orbit), "--orbit".to_string()),
        (None, None) => (
            CameraPath::Orbit(default_orbit(&scene)),
            "the automatic orbit".to_string(),
        ),
    };
    path.validate()?;
    // Every camera checked before start-up, none kept.
    for i in 0..args.frames {
        frame_cameras(&path, &source, rig.as_ref(), &base, i, args.frames)?;
    }

    // Before the Vulkan instance (a loaded RenderDoc hooks it) and any output.
    let mut capture = FrameCapture::new(&args.renderdoc, args.frames.into())?;

    let staging = match &args.out_dir {
        Some(dir) => Some(outputs.stage_dir(dir)?),
        None => None,
    };
    if let Some(dir) = &staging {
        for view in specs.iter().filter(|v| !v.name.is_empty()) {
            std::fs::create_dir(dir.join(&view.name)).with_context(|| format!("cannot create {}", dir.display()))?;
        }
    }

    let ctx = context(&args.scene.device)?;
    let report = ctx.validation_report();
    let device = ctx.info().name.clone();
    let mut wall = vec![Duration::ZERO; args.frames as usize];
    let texture_stats;
    let raster;
    let profiles = {
        let settings = render_settings(&args.scene, &scene, &specs, staging.is_some())?;
        let mut renderer = lighting::renderer(&ctx, &scene, settings)?;
        raster = renderer.raster_path().name();
        // Every frame's profile is reported (the history is bounded by default).
        renderer.set_profile_history(args.frames as usize);
        let bar = ProgressBar::new(u64::from(args.frames));
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} frames {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let write = |views: &[FrameImages], index: usize| -> Result<()> {
            if let Some(dir) = &staging {
                for images in views {
                    let path = |extension| frame_path(dir, &images.name, index, extension);
                    write_png_rgba8(&path("png"), &images.rgba8, images.width, images.height)?;
                    if args.exr {
                        let bytes = super::exr::encode_frame_exr(images)?;
                        alpenglow::files::write_bytes_atomically(&path("exr"), &bytes)?;
                    }
                }
            }
            Ok(())
        };
        // A frame is read back and written while the next one renders; its
        // wall time is its submission plus its read-back and writes.
        let mut pending = None;
        for i in 0..args.frames {
            let cams = frame_cameras(&path, &source, rig.as_ref(), &base, i, args.frames)?;
            let start = Instant::now();
            let outcome = renderdoc::frame(&mut capture, i.into(), || Ok(renderer.render_views(&cams)?))?;
            wall[i as usize] += start.elapsed();
            if let Some((index, frame)) = pending.take() {
                let start = Instant::now();
                write(&renderer.read_views(&frame)?, index)?;
                wall[index] += start.elapsed();
            }
            if staging.is_some() {
                pending = Some((i as usize, outcome));
            }
            bar.inc(1);
        }
        if let Some((index, frame)) = pending.take() {
            let start = Instant::now();
            write(&renderer.read_views(&frame)?, index)?;
            wall[index] += start.elapsed();
        }
        bar.finish_and_clear();
        let profiles = renderer.finish()?;
        texture_stats = renderer.take_texture_stats()?;
        profiles
    };
    drop(ctx);
    check_validation(report)?;
    let run = FlyRun {
        device: &device,
        raster,
        profiles: &profiles,
        wall: &wall,
        writes: staging.is_some(),
    };
    report_fly(&args, &run, &texture_stats, &mut outputs)?;
    renderdoc::report(capture)?;
    outputs.commit()?;
    if let Some(dir) = &args.out_dir {
        println!("  {} frames written to {}", args.frames, dir.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// What a flythrough measured: the device, each frame's profile and wall
/// time, and whether frames were written.
struct FlyRun<'a> {
    device: &'a str,
    /// The terrain's rasterizer.
    raster: &'static str,
    profiles: &'a [FrameProfile],
    wall: &'a [Duration],
    writes: bool,
}

/// Prints the flythrough's GPU, wall and CPU warp times and stages the
/// `--profile` and `--trace` files.
fn report_fly(
    args: &FlyArgs,
    run: &FlyRun<'_>,
    texture_stats: &[TextureFrameStats],
    outputs: &mut Outputs,
) -> Result<()> {
    let (device, profiles, wall) = (run.device, run.profiles, run.wall);
    let wall_ms: Vec<f64> = wall.iter().map(|d| d.as_secs_f64() * 1e3).collect();

    let gpu: Vec<f64> = profiles.iter().map(|p| p.gpu_ms).collect();
    let cpu_warp: Vec<f64> = profiles
        .iter()
        .filter_map(|p| {
            p.passes
                .iter()
                .find(|q| q.name.starts_with("terrain.warp"))
                .map(|q| q.cpu_ms)
        })
        .collect();
    let (gmin, gmed, gmax) = stats(&gpu);
    let (wmin, wmed, wmax) = stats(&wall_ms);
    let (cmin, cmed, cmax) = stats(&cpu_warp);
    println!(
        "{device}: {} frames, {}x{}",
        profiles.len(),
        args.scene.width,
        args.scene.height
    );
    println!("  GPU frame time   min {gmin:.3}  median {gmed:.3}  max {gmax:.3} ms");
    println!(
        "  wall per frame   min {wmin:.3}  median {wmed:.3}  max {wmax:.3} ms, first {:.3} ms \
         (each frame's submission{}, start-up excluded)",
        wall_ms[0],
        if run.writes { " + read-back + file writes" } else { "" }
    );
    println!("  CPU warp         min {cmin:.3}  median {cmed:.3}  max {cmax:.3} ms");
    let textures = report_textures(texture_stats, profiles);

    if args.profile.is_some() {
        let (passes, frame) = summarize(profiles);
        let value = serde_json::json!({
            "device": run.device,
            "raster": run.raster,
            "frames": profiles.len(),
            "gpu_ms": {"min": gmin, "median": gmed, "max": gmax, "per_frame": gpu},
            "wall_ms": {"min": wmin, "median": wmed, "max": wmax, "first": wall_ms[0]},
            "cpu_warp_ms": {"min": cmin, "median": cmed, "max": cmax},
            "median_frame_gpu_ms": frame.median_gpu_ms,
            "passes": passes,
            "textures": textures.as_ref().map(|t| serde_json::json!({"summary": t, "per_frame": texture_stats})),
        });
        let text = serde_json::to_string_pretty(&value)?;
        outputs.stage(args.profile.as_deref(), || Ok(text.into_bytes()))?;
    }
    outputs.stage(args.trace.as_deref(), || {
        Ok(chrome_trace(run.device, profiles)?.into_bytes())
    })?;
    Ok(())
}
