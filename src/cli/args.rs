//! Command-line arguments (the stable contract of the README).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use glam::DVec3;

/// alpenglow: a Vulkan renderer for large outdoor scenes.
#[derive(Parser, Debug)]
#[command(name = "alpenglow", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one frame of a scene (the built-in default scene without input files).
    Render(RenderArgs),
    /// Render N frames and report the median GPU time per pass and per frame.
    Bench(BenchArgs),
    /// Print the Vulkan device, driver and the features in use.
    Info(DeviceArgs),
}

#[derive(Args, Debug, Clone)]
pub struct DeviceArgs {
    /// Enable the Khronos validation layers (and synchronization validation);
    /// exit non-zero if any validation error or warning was reported.
    #[arg(long)]
    pub validation: bool,
    /// Vulkan device by index or name substring (default: discrete, integrated, then CPU).
    #[arg(long, env = "ALPENGLOW_DEVICE")]
    pub device: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Camera position X,Y,Z in metres (default: framing the whole terrain).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<DVec3>,
    /// Point looked at, X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<DVec3>,
    /// Up direction X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    pub up: DVec3,
    /// Vertical field of view in degrees.
    #[arg(long = "fov-y", default_value_t = 50.0)]
    pub fov_y: f64,
    /// Near plane distance in metres (default: from the terrain size).
    #[arg(long)]
    pub near: Option<f64>,
    /// Far plane distance in metres (default: from the terrain size).
    #[arg(long)]
    pub far: Option<f64>,
    /// Height field: 16-bit PNG (value·scale + offset) or EXR (first channel, metres·scale + offset).
    #[arg(long)]
    pub heightmap: Option<PathBuf>,
    /// Metres per height sample: DX or DX,DY.
    #[arg(long, value_parser = parse_spacing, default_value = "1")]
    pub spacing: (f64, f64),
    /// Multiplier of height-map values.
    #[arg(long = "height-scale", default_value_t = 1.0, allow_hyphen_values = true)]
    pub height_scale: f32,
    /// Added to height-map values after scaling, metres.
    #[arg(long = "height-offset", default_value_t = 0.0, allow_hyphen_values = true)]
    pub height_offset: f32,
    #[command(flatten)]
    pub device: DeviceArgs,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Tone-mapped sRGB PNG.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// OpenEXR: linear R,G,B,A and Z (view-space depth, +inf where nothing was hit).
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Per-pass timings as JSON (name, GPU ms, CPU ms; frame totals).
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Chrome trace (opens in Perfetto).
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Frames to time (after warm-up).
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// Frames rendered first and not timed.
    #[arg(long, default_value_t = 5)]
    pub warmup: u32,
    /// Write the summary as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Chrome trace of the timed frames.
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

fn parse_numbers(s: &str, what: &str) -> Result<Vec<f64>, String> {
    s.split(',')
        .map(|p| {
            let v: f64 = p.trim().parse().map_err(|_| format!("'{s}' is not {what}"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("'{s}' has a non-finite number"))
            }
        })
        .collect()
}

fn parse_vec3(s: &str) -> Result<DVec3, String> {
    match parse_numbers(s, "X,Y,Z")?.as_slice() {
        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not X,Y,Z (three comma-separated numbers)")),
    }
}

fn parse_spacing(s: &str) -> Result<(f64, f64), String> {
    let v = parse_numbers(s, "DX[,DY]")?;
    let (dx, dy) = match v.as_slice() {
        [d] => (*d, *d),
        [dx, dy] => (*dx, *dy),
        _ => return Err(format!("'{s}' is not DX or DX,DY")),
    };
    if dx > 0.0 && dy > 0.0 {
        Ok((dx, dy))
    } else {
        Err(format!("'{s}': spacing must be positive"))
    }
}
