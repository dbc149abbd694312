//! A driving simulator's frame loop (issue 14, part 8): a car drives over
//! the real Jacksboro DEM (`tests/data/jacksboro-fault.png`) at 25 m/s in
//! fixed steps of 1/30 s, the driver's eye 1.7 m above the ground query
//! ([`alpenglow::Ground`]: the terrain as drawn, with its
//! procedural detail, §7.4.3), looking along the path; every step renders
//! through [`Renderer`].
//!
//! `cargo run --release --example drive -- [--steps N] [--width W] [--height H] [--views 6|1] [--raster PATH] [--pyramid FILE|procedural:SIDE]`
//! (default: a `ring6` rig of 320×240 views, 300 steps). `--pyramid`
//! drives across a streamed region instead (issue 31 item 1): a height
//! pyramid (`alpenglow dem import`), or a procedural one of SIDE² 1 m
//! samples written to the temporary directory first; 4096² resident, a
//! 1024² detail window that frames do not wait for, the ground query from
//! the finest level ([`alpenglow::StreamedGround`]), the path from the
//! region's centre. Prints the median, p99 and largest
//! frame time per step: wall-clock (CPU: ground query, prepare, record,
//! submit, and any wait for a free frame slot) and GPU (the sum of the
//! frame's pass timestamps from [`Renderer::finish`]).

use std::time::Instant;

use std::path::PathBuf;

use alpenglow::files::{load_heightmap, write_ridge_region, DEFAULT_DETAIL_WINDOW, DEFAULT_RESIDENT_SIDE};
use alpenglow::glam::{DVec2, DVec3};
use alpenglow::tools::profile::{median, quantile, summarize};
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, HeightmapOptions, RasterPath, Renderer, Rig, Scene, Settings,
    ViewSpec,
};

/// Car speed (m/s) and the fixed step (s).
const SPEED: f64 = 25.0;
const DT: f64 = 1.0 / 30.0;
/// The driver's eye above the ground (metres).
const EYE_HEIGHT: f64 = 1.7;
/// Where the path starts (in the valley of the Jacksboro fault) and its
/// mean heading (radians from +x: up the valley, to the north-east).
const START: DVec2 = DVec2::new(13600.0, 9600.0);
const HEADING: f64 = 1.18;

/// Steps left out of the steady-state figures.
const WARM_UP: usize = 10;

struct Args {
    steps: usize,
    width: u32,
    height: u32,
    /// 6: the `ring6` rig (each view --width wide, 4:3); 1: one view.
    views: u32,
    /// The terrain's rasterizer (`--raster hardware|compute|auto`).
    raster: RasterPath,
    /// `--pyramid FILE|procedural:SIDE`: a streamed region.
    pyramid: Option<String>,
}

/// `--steps N --width W --height H`; errors name the argument.
fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        steps: 300,
        width: 320,
        height: 200,
        views: 6,
        raster: RasterPath::Hardware,
        pyramid: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().ok_or_else(|| format!("{flag}: missing value"))?;
        let number = |min: u64| match value.parse::<u64>() {
            Ok(v) if v >= min => Ok(v),
            _ => Err(format!("{flag}: {value:?} is not a whole number ≥ {min}")),
        };
        match flag.as_str() {
            "--steps" => args.steps = number(1)? as usize,
            "--views" => match number(1)? {
                1 => args.views = 1,
                6 => args.views = 6,
                _ => return Err(format!("{flag}: {value} is not 1 or 6 (ring6)")),
            },
            "--raster" => {
                args.raster = match value.as_str() {
                    "hardware" => RasterPath::Hardware,
                    "compute" => RasterPath::Compute,
                    "auto" => RasterPath::Auto,
                    _ => return Err(format!("{flag}: {value:?} is not hardware, compute or auto")),
                }
            }
            "--pyramid" => args.pyramid = Some(value),
            "--width" => {
                args.width = number(1)?
                    .try_into()
                    .map_err(|_| format!("{flag}: {value} is too large"))?
            }
            "--height" => {
                args.height = number(1)?
                    .try_into()
                    .map_err(|_| format!("{flag}: {value} is too large"))?
            }
            _ => {
                return Err(format!(
                    "unknown argument {flag:?} (use --steps, --width, --height, --views, --raster, --pyramid)"
                ))
            }
        }
    }
    Ok(args)
}

/// The car on its path: the heading swings ±0.35 rad around [`HEADING`]
/// over 600 m of path; the position is the integral of that unit-speed
/// heading over the path length `s`.
struct Car {
    s: f64,
    xy: DVec2,
}

impl Car {
    fn heading_at(s: f64) -> f64 {
        HEADING + 0.35 * (std::f64::consts::TAU / 600.0 * s).sin()
    }

    fn heading(&self) -> f64 {
        Car::heading_at(self.s)
    }

    /// Drives `ds` metres on (Simpson's rule: far below a millimetre of
    /// error per step).
    fn advance(&mut self, ds: f64) {
        let direction = |s: f64| DVec2::from_angle(Car::heading_at(s));
        let s = self.s;
        self.xy += ds / 6.0 * (direction(s) + 4.0 * direction(s + 0.5 * ds) + direction(s + ds));
        self.s += ds;
    }
}

/// The car's camera: the driver's eye `EYE_HEIGHT` above the ground
/// height `ground` at `xy`, looking along `heading`, 3° down.
fn car_camera(ground: f64, xy: DVec2, heading: f64) -> Camera {
    let eye = xy.extend(ground + EYE_HEIGHT);
    let pitch = 3f64.to_radians();
    let forward = DVec2::from_angle(heading).extend(0.0) * pitch.cos() - DVec3::Z * pitch.sin();
    Camera {
        eye,
        target: eye + forward,
        up: DVec3::Z,
        fov_y_deg: 60.0,
        near: 0.1,
        far: 100_000.0,
    }
}

/// A procedural height pyramid of `side`² samples 1 m apart
/// ([`write_ridge_region`]), written once into the temporary directory.
fn procedural_pyramid(side: u32) -> alpenglow::Result<PathBuf> {
    let path = std::env::temp_dir().join(format!("alpenglow-drive-{side}.hpyr"));
    if !path.exists() {
        write_ridge_region(&path, side)?;
    }
    Ok(path)
}

/// The scene, where the car starts, and the region's name.
fn load_scene(args: &Args) -> alpenglow::Result<(Scene, DVec2, String)> {
    let Some(pyramid) = &args.pyramid else {
        let dem = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/jacksboro-fault.png");
        let heights = load_heightmap(
            &dem,
            &HeightmapOptions {
                scale: 1.0,
                offset: 0.0,
                spacing: Some(DVec2::new(74.4, 92.6)),
                ..Default::default()
            },
        )?;
        return Ok((Scene::new(heights), START, "the Jacksboro DEM".into()));
    };
    let path = match pyramid.strip_prefix("procedural:") {
        Some(side) => {
            let side = side.parse().ok().filter(|s| (2..=65536).contains(s)).ok_or_else(|| {
                alpenglow::Error::invalid("--pyramid", format!("{side:?} is not a side in 2..=65536"))
            })?;
            procedural_pyramid(side)?
        }
        None => PathBuf::from(pyramid),
    };
    let mut scene = Scene::from_pyramid_file(&path, DEFAULT_RESIDENT_SIDE, DEFAULT_DETAIL_WINDOW)?;
    // Frames along the path never wait for the window's tiles.
    scene.set_detail_window(DEFAULT_DETAIL_WINDOW, false)?;
    let centre = scene.heights.extent() / 2.0;
    Ok((scene, centre, path.display().to_string()))
}

/// One row of the table: median, p99, largest and first value (ms).
fn row(name: &str, values: &[f64]) {
    println!(
        "| {name:<26} | {:>8.2} | {:>8.2} | {:>8.2} | {:>8.2} |",
        median(values.iter().copied()),
        quantile(values, 0.99),
        values.iter().copied().fold(f64::NAN, f64::max),
        values.first().copied().unwrap_or(f64::NAN)
    );
}

fn run(args: &Args) -> alpenglow::Result<()> {
    let (scene, start, region) = load_scene(args)?;
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    let rig = (args.views == 6).then(|| Rig::ring6(args.width));
    let specs = match &rig {
        Some(rig) => rig.specs((args.width, args.height))?,
        None => vec![ViewSpec::new(args.width, args.height)],
    };
    let mut settings = Settings::for_views(specs.clone());
    settings.readback = false;
    settings.raster = args.raster;
    let resident_ground = scene.ground(&settings.terrain)?;
    let mut streamed_ground = scene.streamed_ground(&settings.terrain)?;
    let mut ground = |xy: DVec2| match streamed_ground.as_mut() {
        Some(streamed) => streamed.height(xy.x, xy.y),
        None => resident_ground.height(xy.x, xy.y),
    };
    let started = Instant::now();
    let mut renderer = Renderer::new(&ctx, &scene, settings)?;
    let setup = started.elapsed().as_secs_f64();
    let mut wall = Vec::with_capacity(args.steps);
    let frames_per_step = 1;
    let mut car = Car { s: 0.0, xy: start };
    for _ in 0..args.steps {
        let t = Instant::now();
        let camera = car_camera(ground(car.xy)?, car.xy, car.heading());
        let cameras = match &rig {
            Some(rig) => rig.cameras(&camera)?,
            None => vec![camera],
        };
        // Every view in one submission.
        renderer.render_views(&cameras)?;
        wall.push(t.elapsed().as_secs_f64() * 1e3);
        car.advance(SPEED * DT);
    }
    let profiles = renderer.finish()?;
    let gpu: Vec<f64> = profiles
        .chunks(frames_per_step)
        .map(|step| step.iter().flat_map(|f| &f.passes).map(|p| p.gpu_ms).sum())
        .collect();
    let cpu: Vec<f64> = profiles
        .chunks(frames_per_step)
        .map(|step| step.iter().map(|f| f.cpu_ms).sum())
        .collect();
    let info = ctx.info();
    println!(
        "drive: {} steps of 1/30 s at {SPEED} m/s ({:.0} m over {region}), {} view(s) of {}×{}, {} ({})",
        args.steps,
        SPEED * DT * args.steps as f64,
        specs.len(),
        specs[0].width,
        specs[0].height,
        info.name,
        info.driver_info
    );
    println!("renderer set-up (sky-light bake included): {setup:.2} s\n");
    println!("| per step (ms)              |   median |      p99 |      max |    first |");
    println!("|----------------------------|----------|----------|----------|----------|");
    row("wall (CPU)", &wall);
    row("  prepare, record, submit", &cpu);
    row("GPU (sum of passes)", &gpu);
    // The steady state: after the first WARM_UP steps (the atlas's first
    // tiles, pipeline and cache warm-up; the time budget needs timings).
    let steady = |v: &[f64]| v.get(WARM_UP..).unwrap_or(&[]).to_vec();
    println!("| after the first {WARM_UP} steps      |          |          |          |          |");
    row("wall (CPU)", &steady(&wall));
    row("  prepare, record, submit", &steady(&cpu));
    row("GPU (sum of passes)", &steady(&gpu));
    let spread = |v: &[f64]| quantile(v, 0.99) / median(v.iter().copied());
    println!(
        "\np99/median after the first {WARM_UP} steps: wall {:.2}, GPU {:.2}",
        spread(&steady(&wall)),
        spread(&steady(&gpu))
    );
    // The CPU stages of a step (prepare per technique).
    let mut stages: Vec<(String, Vec<f64>)> = Vec::new();
    for f in profiles.iter().skip(WARM_UP) {
        for s in &f.prepare {
            match stages.iter_mut().find(|(n, _)| *n == s.name) {
                Some((_, v)) => v.push(s.cpu_ms),
                None => stages.push((s.name.clone(), vec![s.cpu_ms])),
            }
        }
    }
    println!("\nCPU stages after the first {WARM_UP} steps (ms): median, p99, max");
    for (name, v) in &stages {
        let max = v.iter().copied().fold(f64::NAN, f64::max);
        println!(
            "  {name:<32} {:>8.2} {:>8.2} {max:>8.2}",
            median(v.iter().copied()),
            quantile(v, 0.99)
        );
    }
    let (mut passes, _) = summarize(&profiles);
    passes.sort_by(|a, b| b.median_gpu_ms.total_cmp(&a.median_gpu_ms));
    println!("\ncostliest passes (GPU ms per frame): median, max");
    for p in passes.iter().take(6) {
        println!("  {:<32} {:>8.2} {:>8.2}", p.name, p.median_gpu_ms, p.max_gpu_ms);
    }
    Ok(())
}

fn main() {
    let outcome = parse_args().and_then(|args| run(&args).map_err(|e| e.to_string()));
    if let Err(e) = outcome {
        eprintln!("drive: {e}");
        std::process::exit(2);
    }
}
