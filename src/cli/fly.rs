//! `alpenglow fly`: a camera path rendered to a PNG sequence (and with
//! `--exr` an EXR sequence with every channel, motion relative to the
//! path's previous frame) with a progress bar, and the per-frame times. The vertex count of the warped
//! terrain is constant (§7.4), so frame times should barely vary.
//!
//! Frames go into a temporary sibling of the output directory, renamed into
//! place when every frame was written: on any error no partial sequence is
//! left behind.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::lighting;
use anyhow::{bail, Context as _, Result};
use indicatif::{ProgressBar, ProgressStyle};

use alpenglow::io::image_out::write_png_rgba8;
use alpenglow::profile::{median, summarize, write_chrome_trace};
use alpenglow::renderer::{FrameImages, Scene};
use alpenglow::view::camera_path::{load_keyframes, CameraPath, Orbit, DEFAULT_START_ANGLE_DEG};

use super::args::FlyArgs;
use super::{
    camera, check_output_path, check_validation, context, load_scene, render_settings, report_textures, rig, views,
    OutputSet,
};

/// The default path: one turn around the terrain's centre at 60 % of its
/// half-size, 0.4 of its size above the highest point.
fn default_orbit(scene: &Scene) -> Orbit {
    let extent = scene.heights.extent();
    let (lo, hi) = scene.height_range();
    let size = extent.x.max(extent.y);
    Orbit {
        centre: glam::DVec3::new(extent.x * 0.5, extent.y * 0.5, f64::from(lo)),
        radius: size * 0.3,
        height: f64::from(hi - lo) + size * 0.08,
        turns: 1.0,
        start_angle_deg: DEFAULT_START_ANGLE_DEG,
    }
}

/// A sibling of `dir` to write into first.
fn staging_dir(dir: &Path) -> PathBuf {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// Removes the staging directory unless disarmed.
struct StagingGuard(Option<PathBuf>);

impl Drop for StagingGuard {
    fn drop(&mut self) {
        if let Some(dir) = self.0.take() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
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
    check_output_path(&args.json, "JSON")?;
    check_output_path(&args.trace, "trace")?;
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if args.exr && args.out_dir.is_none() {
        bail!("--exr needs --out-dir DIR (the EXR frames go beside the PNG frames)");
    }
    if let Some(dir) = &args.out_dir {
        if dir.exists() && (!dir.is_dir() || std::fs::read_dir(dir)?.next().is_some()) {
            bail!("--out-dir {} exists and is not an empty directory", dir.display());
        }
        if !dir.exists() {
            check_output_path(&Some(dir.clone()), "frame directory")?;
        }
    }
    let (rig, specs) = views(&args.scene)?;
    let scene = load_scene(&args.scene)?;
    let base = camera(&args.scene, &scene)?;
    let path = match (&args.path, args.orbit) {
        (Some(file), _) => load_keyframes(file)?,
        (None, Some(orbit)) => CameraPath::Orbit(orbit),
        (None, None) => CameraPath::Orbit(default_orbit(&scene)),
    };
    path.validate()?;
    let cameras = path.sample(args.frames, &base);
    let mut frames = Vec::with_capacity(cameras.len());
    for (i, c) in cameras.iter().enumerate() {
        c.validate().with_context(|| format!("camera path frame {i}"))?;
        frames.push(rig::frame_cameras(rig.as_ref(), c).with_context(|| format!("camera path frame {i}"))?);
    }

    let staging = args.out_dir.as_ref().map(|d| staging_dir(d));
    let mut guard = StagingGuard(None);
    if let Some(dir) = &staging {
        std::fs::create_dir(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        guard.0 = Some(dir.clone());
        for view in specs.iter().filter(|v| !v.name.is_empty()) {
            std::fs::create_dir(dir.join(&view.name)).with_context(|| format!("cannot create {}", dir.display()))?;
        }
    }

    let ctx = context(&args.scene.device)?;
    let report = ctx.validation_report();
    let device = ctx.info().name.clone();
    let mut wall_ms = Vec::with_capacity(cameras.len());
    let texture_stats;
    let profiles = {
        let settings = render_settings(&args.scene, &scene, &specs, staging.is_some())?;
        let mut renderer = lighting::renderer(&ctx, &scene, settings)?;
        let bar = ProgressBar::new(cameras.len() as u64);
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
                        super::exr::write_frame_exr(&path("exr"), images)?;
                    }
                }
            }
            Ok(())
        };
        let mut pending = None;
        let mut last = std::time::Instant::now();
        for (i, cams) in frames.iter().enumerate() {
            let outcome = renderer.render_views(cams)?;
            if let Some((index, frame)) = pending.take() {
                let images = renderer.read_views(&frame)?;
                write(&images, index)?;
            }
            if staging.is_some() {
                pending = Some((i, outcome));
            }
            wall_ms.push(last.elapsed().as_secs_f64() * 1e3);
            last = std::time::Instant::now();
            bar.inc(1);
        }
        if let Some((index, frame)) = pending.take() {
            let images = renderer.read_views(&frame)?;
            write(&images, index)?;
        }
        bar.finish_and_clear();
        let profiles = renderer.finish()?;
        texture_stats = renderer.take_texture_stats()?;
        profiles
    };
    drop(ctx);
    check_validation(report)?;

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
    println!("  wall per frame   min {wmin:.3}  median {wmed:.3}  max {wmax:.3} ms");
    println!("  CPU warp         min {cmin:.3}  median {cmed:.3}  max {cmax:.3} ms");
    let textures = report_textures(&texture_stats, &profiles);

    let mut outputs = OutputSet::default();
    if args.json.is_some() {
        let (passes, frame) = summarize(&profiles);
        let value = serde_json::json!({
            "device": device,
            "frames": profiles.len(),
            "gpu_ms": {"min": gmin, "median": gmed, "max": gmax, "per_frame": gpu},
            "wall_ms": {"min": wmin, "median": wmed, "max": wmax},
            "cpu_warp_ms": {"min": cmin, "median": cmed, "max": cmax},
            "median_frame_gpu_ms": frame.median_gpu_ms,
            "passes": passes,
            "textures": textures.as_ref().map(|t| serde_json::json!({"summary": t, "per_frame": texture_stats})),
        });
        let text = serde_json::to_string_pretty(&value)?;
        outputs.write(&args.json, |p| {
            alpenglow::io::atomic::write_bytes_atomically(p, text.as_bytes())
        })?;
    }
    outputs.write(&args.trace, |p| write_chrome_trace(p, &device, &profiles))?;
    if let (Some(dir), Some(staged)) = (&args.out_dir, &staging) {
        if dir.is_dir() {
            std::fs::remove_dir(dir).with_context(|| format!("cannot replace {}", dir.display()))?;
        }
        std::fs::rename(staged, dir).with_context(|| format!("cannot move frames into {}", dir.display()))?;
        guard.0 = None;
        println!("  {} frames written to {}", cameras.len(), dir.display());
    }
    outputs.commit();
    Ok(ExitCode::SUCCESS)
}
