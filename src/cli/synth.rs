//! `alpenglow synth fill`, `synth grow` and `synth transition`: height-field
//! synthesis by non-parametric sampling (dissertation §7.3;
//! `alpenglow::tools::synth`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use alpenglow::files::{encode_exr_height, encode_png_gray16, load_heightmap, load_heightmap_with_voids};
use alpenglow::tools::budget::MemoryLimits;
use alpenglow::tools::synth::{
    band_of, check_fields, check_free_growth, check_hole_fill, plan_free_growth, plan_hole_fill, plan_transition, Axis,
    CpuSearch, FillParams, GpuSearch, Growth, GrowthCost, SearchDevice, TransitionParams, FREE_GROWTH,
};
use alpenglow::{Context, HeightField, HeightmapOptions, RowOrder};
use anyhow::{bail, Result};
use clap::{Args, Subcommand, ValueEnum};
use glam::DVec2;

use crate::cli::args::{parse_hours, parse_spacing, RowsArg};
use crate::cli::outputs::Outputs;
use crate::cli::progress;
use crate::cli::terrain_spec::{TerrainSpec, PREFIX};

#[derive(Subcommand, Debug)]
pub enum SynthCommand {
    /// Fill holes of a DEM by pixel growing (§7.3): the samples marked by
    /// --mask, or without it the voids of the input (NaN, no-data).
    Fill(FillArgs),
    /// Grow a new height field of a given size from an exemplar alone
    /// (§7.3, Fig. 7.1): pixel growing from one window of the exemplar.
    Grow(FreeArgs),
    /// Join two height fields of the same size across a grown band (§7.3.3).
    Transition(TransitionArgs),
}

/// How height-map files are read (and PNG outputs written).
#[derive(Args, Debug)]
#[command(next_help_heading = "Height maps")]
pub struct HeightArgs {
    /// Metres between height samples: DX, or DX,DY (default: a GeoTIFF's or
    /// .hgt's georeferencing, else 1 with a warning).
    #[arg(long, value_parser = parse_spacing, value_name = "DX[,DY]")]
    pub spacing: Option<(f64, f64)>,
    /// Multiplier of height-map values (to metres); a PNG or EXR output is
    /// written back with the same mapping.
    #[arg(long = "height-scale", default_value_t = 1.0, value_parser = crate::cli::args::parse_height_scale, value_name = "FACTOR")]
    pub height_scale: f32,
    /// Added to height-map values after scaling, in metres (also used for
    /// the output).
    #[arg(long = "height-offset", default_value_t = 0.0, value_parser = crate::cli::args::parse_height_offset, value_name = "METRES")]
    pub height_offset: f32,
    /// Where a PNG, EXR or plain TIFF's first row lies (south-up: rows
    /// kept; north-up: flipped); the output keeps the input's orientation.
    #[arg(long, value_enum, default_value = "south-up", value_name = "ORDER")]
    pub rows: RowsArg,
    /// Largest input file in MiB.
    #[arg(long = "max-input-mb", default_value_t = 2048, value_name = "MIB", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_input_mb: u64,
}

/// The neighbourhood search.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchArg {
    /// Compute passes on the Vulkan device.
    Gpu,
    /// The CPU twin (same rule, same result).
    Cpu,
}

/// Parameters of pixel growing.
#[derive(Args, Debug)]
#[command(next_help_heading = "Synthesis")]
pub struct GrowArgs {
    /// Window side n in samples, odd (default: fill 7, transition 11).
    #[arg(long, value_name = "SAMPLES")]
    pub window: Option<u32>,
    /// Weight λ of the slope channels against the height channel (both
    /// normalised); inf: slopes only, no height criterion (Fig. 7.4).
    #[arg(long, default_value_t = 0.25, value_name = "WEIGHT")]
    pub lambda: f32,
    /// Tolerance ε: candidates within (1+ε) of the best match (default: fill 0.1, transition 0.5).
    #[arg(long, value_name = "TOLERANCE")]
    pub epsilon: Option<f32>,
    /// Seed of the candidate subsample and the random choice.
    #[arg(long, default_value_t = 1, value_name = "SEED")]
    pub seed: u32,
    /// Most samples searched together in one wave (1: the text's
    /// sequential order; default: fill and transition 256, grow 1).
    #[arg(long, value_name = "SAMPLES")]
    pub batch: Option<usize>,
    /// Most candidate windows (those nearest the unknown samples first).
    #[arg(long, default_value_t = 16384, value_name = "COUNT")]
    pub candidates: usize,
    /// Neighbourhood search.
    #[arg(long, value_enum, default_value = "gpu", value_name = "DEVICE")]
    pub search: SearchArg,
    /// Longest estimated run accepted, in hours: a growth estimated to
    /// take longer is refused before it starts (README, "Height-field synthesis").
    #[arg(long = "max-hours", default_value_t = alpenglow::tools::budget::DEFAULT_MAX_HOURS, value_name = "HOURS", value_parser = parse_hours)]
    pub max_hours: f64,
    #[command(flatten)]
    pub device: crate::cli::args::DeviceArgs,
}

impl GrowArgs {
    fn params(&self, defaults: FillParams) -> FillParams {
        FillParams {
            window: self.window.unwrap_or(defaults.window),
            lambda: self.lambda,
            epsilon: self.epsilon.unwrap_or(defaults.epsilon),
            seed: self.seed,
            batch: self.batch.unwrap_or(defaults.batch),
            candidates: self.candidates,
        }
    }
}

#[derive(Args, Debug)]
pub struct FillArgs {
    /// The DEM: PNG, EXR, GeoTIFF or SRTM .hgt.
    #[arg(long, value_name = "FILE")]
    pub input: PathBuf,
    /// Greyscale PNG (or any height map) of the input's size: non-zero
    /// samples are unknown (besides the input's voids).
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// The filled DEM: .png (16-bit, the input's scale and offset) or .exr (float).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[command(flatten)]
    pub grow: GrowArgs,
    #[command(flatten)]
    pub heights: HeightArgs,
}

#[derive(Args, Debug)]
pub struct FreeArgs {
    /// The exemplar height field: PNG, EXR, GeoTIFF or SRTM .hgt (no voids).
    #[arg(long, value_name = "FILE")]
    pub exemplar: PathBuf,
    /// The grown field: .png (16-bit, the exemplar's scale and offset) or .exr (float).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Size of the new field in samples: COLUMNSxROWS, or N for N×N.
    #[arg(long, value_parser = parse_size, value_name = "COLUMNSxROWS")]
    pub size: (u32, u32),
    #[command(flatten)]
    pub grow: GrowArgs,
    #[command(flatten)]
    pub heights: HeightArgs,
}

/// `COLUMNSxROWS` or `N` of `--size`.
fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' is not N or COLUMNSxROWS"))
    };
    match s.split_once(['x', 'X', '×']) {
        Some((c, r)) => Ok((side(c)?, side(r)?)),
        None => side(s).map(|n| (n, n)),
    }
}

/// The axis of `--axis`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisArg {
    /// A west, B east, a band of columns.
    X,
    /// A south, B north, a band of rows.
    Y,
}

#[derive(Args, Debug)]
pub struct TransitionArgs {
    /// Height field A (a file or procedural:MODEL[,KEY=VALUE...]).
    #[arg(value_name = "A")]
    pub a: String,
    /// Height field B, the same size and spacing as A.
    #[arg(value_name = "B")]
    pub b: String,
    /// The joined field: .png (16-bit, --height-scale and --height-offset) or .exr (float).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Width of the grown band in metres, centred between A and B.
    #[arg(long, value_name = "METRES")]
    pub band: f64,
    /// Axis across which A and B are joined.
    #[arg(long, value_enum, default_value = "x", value_name = "AXIS")]
    pub axis: AxisArg,
    /// Radius in samples of the Gaussian blur of the grown band (σ = R/2; 0: none).
    #[arg(long, default_value_t = 2, value_name = "SAMPLES")]
    pub blur: u32,
    /// Also write K intermediate steps of the growth (Fig. 7.6) beside --out,
    /// as STEM-step-I.EXT (I = 1..K, the band 1/(K+1), …, K/(K+1) grown;
    /// its ungrown samples the smooth ramp, no blur).
    #[arg(long, default_value_t = 0, value_name = "K", value_parser = clap::value_parser!(u32).range(0..=16))]
    pub steps: u32,
    #[command(flatten)]
    pub grow: GrowArgs,
    #[command(flatten)]
    pub heights: HeightArgs,
}

/// Runs `synth fill` or `synth transition`.
pub fn synth(command: SynthCommand) -> Result<ExitCode> {
    match command {
        SynthCommand::Fill(args) => fill(args),
        SynthCommand::Grow(args) => grow_free(args),
        SynthCommand::Transition(args) => transition(args),
    }
}

pub(crate) fn heightmap_options(args: &HeightArgs) -> HeightmapOptions {
    HeightmapOptions {
        scale: args.height_scale,
        offset: args.height_offset,
        spacing: args.spacing.map(|(dx, dy)| DVec2::new(dx, dy)),
        rows: match args.rows {
            RowsArg::NorthUp => RowOrder::NorthUp,
            RowsArg::SouthUp => RowOrder::SouthUp,
        },
        limits: alpenglow::files::InputLimits::with_max_file_mib(args.max_input_mb),
    }
}

/// Reserves `out` after checking its extension.
fn reserve_output(out: &Path) -> Result<Outputs> {
    let ext = out.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        bail!("--out {}: the output must end in .png (16-bit) or .exr", out.display());
    }
    let mut outputs = Outputs::default();
    outputs.add(Some(out), "--out")?;
    Ok(outputs)
}

/// The unknown samples of `fill`: the input's voids and the mask's non-zero samples.
fn load_fill_input(args: &FillArgs) -> Result<(HeightField, Vec<bool>)> {
    let opts = heightmap_options(&args.heights);
    let (field, mut unknown) = load_heightmap_with_voids(&args.input, &opts)?;
    if let Some(path) = &args.mask {
        let mask_opts = HeightmapOptions {
            scale: 1.0,
            offset: 0.0,
            spacing: Some(DVec2::ONE),
            ..opts
        };
        let mask = load_heightmap(path, &mask_opts)?;
        if (mask.columns, mask.rows) != (field.columns, field.rows) {
            bail!(
                "--mask {}: the mask is {}×{} samples, the input {} is {}×{}",
                path.display(),
                mask.columns,
                mask.rows,
                args.input.display(),
                field.columns,
                field.rows
            );
        }
        for (u, &m) in unknown.iter_mut().zip(&mask.heights) {
            *u |= m != 0.0;
        }
    }
    Ok((field, unknown))
}

/// An error of the library's `mask` (the unknown samples) in the words of
/// what made them: `--mask FILE` where one was given, else the input's voids.
fn unknown_error(e: alpenglow::Error, args: &FillArgs) -> anyhow::Error {
    match (&e, e.parameter()) {
        (alpenglow::Error::InvalidArgument { message, .. }, Some("mask")) => match &args.mask {
            Some(mask) => anyhow::anyhow!("--mask {}: {message}", mask.display()),
            None => anyhow::anyhow!(
                "{}: {message} (without --mask the unknown samples are the input's voids, its no-data samples)",
                args.input.display()
            ),
        },
        _ => e.into(),
    }
}

fn fill(args: FillArgs) -> Result<ExitCode> {
    let outputs = reserve_output(&args.out)?;
    let (field, unknown) = load_fill_input(&args)?;
    let params = args.grow.params(FillParams::default());
    check_hole_fill(&field, &unknown, &params).map_err(|e| unknown_error(e, &args))?;
    let total = unknown.iter().filter(|&&u| u).count();
    let cost = GrowthCost::fill(field.columns, field.rows, total as u64, &params);
    let search = prepare_search(&cost, &args.grow, &format!("--input {}", args.input.display()))?;
    let growth = progress::phase("planning the growth", || plan_hole_fill(&field, &unknown, &params))
        .map_err(|e| unknown_error(e, &args))?;
    if total == 0 {
        log::warn!(
            "{}: no sample is unknown (no --mask and no voids, or an empty mask); writing the input unchanged",
            args.input.display()
        );
    }
    let seconds = grow_and_write(growth, search, outputs, &args.out, &args.heights)?;
    println!(
        "{}: filled {total} of {}×{} samples in {seconds:.1} s → {}",
        args.input.display(),
        field.columns,
        field.rows,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn grow_free(args: FreeArgs) -> Result<ExitCode> {
    let outputs = reserve_output(&args.out)?;
    let exemplar = load_heightmap(&args.exemplar, &heightmap_options(&args.heights))?;
    let params = args.grow.params(FREE_GROWTH);
    let (columns, rows) = args.size;
    let named = |e: alpenglow::Error| match (&e, e.parameter()) {
        (alpenglow::Error::InvalidArgument { message, .. }, Some("exemplar")) => {
            anyhow::anyhow!("--exemplar {}: {message}", args.exemplar.display())
        }
        _ => e.into(),
    };
    check_free_growth(&exemplar, columns, rows, &params).map_err(named)?;
    // The cost of filling the whole new field, its candidates the exemplar's windows.
    let inside = |side: u32| (side + 1).saturating_sub(params.window) as usize;
    let candidates = params.candidates.min(inside(exemplar.columns) * inside(exemplar.rows));
    let unknown = u64::from(columns) * u64::from(rows);
    let cost = GrowthCost::fill(columns, rows, unknown, &FillParams { candidates, ..params });
    let search = prepare_search(&cost, &args.grow, &format!("--size {columns}x{rows}"))?;
    let growth = progress::phase("planning the growth", || {
        plan_free_growth(&exemplar, columns, rows, &params)
    })
    .map_err(named)?;
    let seconds = grow_and_write(growth, search, outputs, &args.out, &args.heights)?;
    let (from, to) = (args.exemplar.display(), args.out.display());
    let (c, r) = (exemplar.columns, exemplar.rows);
    println!("{from}: grew {columns}×{rows} samples from its {c}×{r} in {seconds:.1} s → {to}");
    Ok(ExitCode::SUCCESS)
}

/// Loads A or B of `transition`: a procedural spec or a height-map file.
fn load_field(source: &str, args: &HeightArgs) -> Result<HeightField> {
    if source.starts_with(PREFIX) {
        let spec: TerrainSpec = source.parse().map_err(|e: String| anyhow::anyhow!(e))?;
        return Ok(spec.generate()?);
    }
    Ok(load_heightmap(Path::new(source), &heightmap_options(args))?)
}

fn transition(args: TransitionArgs) -> Result<ExitCode> {
    let mut outputs = reserve_output(&args.out)?;
    let a = load_field(&args.a, &args.heights)?;
    let params = TransitionParams {
        grow: args.grow.params(TransitionParams::default().grow),
        band_metres: args.band,
        axis: match args.axis {
            AxisArg::X => Axis::X,
            AxisArg::Y => Axis::Y,
        },
        blur_radius: args.blur,
    };
    let b = load_field(&args.b, &args.heights)?;
    check_fields(&a, &b)?;
    params.grow.validate(a.columns, a.rows)?;
    let band = band_of(a.columns, a.rows, a.spacing, &params)?;
    let cost = GrowthCost::transition(a.columns, a.rows, &band, &params);
    let search = prepare_search(&cost, &args.grow, &format!("{} and {}", args.a, args.b))?;
    let (growth, transition) = progress::phase("planning the transition", || plan_transition(&a, &b, &params))?;
    drop(b);
    let step_paths = step_paths(&args.out, args.steps);
    for path in &step_paths {
        outputs.add(Some(path), "--steps")?;
    }
    let total = growth.unknown_count();
    let mut steps: Vec<HeightField> = Vec::new();
    let mut observe = |field: &HeightField, unknown: &[bool]| {
        let left = unknown.iter().filter(|&&u| u).count();
        // Step I is written when the grown share first reaches I/(K+1).
        while steps.len() < step_paths.len() && (total - left) * (step_paths.len() + 1) >= (steps.len() + 1) * total {
            steps.push(transition.partial(field, unknown));
        }
        Ok(())
    };
    let started = Instant::now();
    let residual = grow_with(growth, search, &mut observe)?;
    let joined = progress::phase("blurring the band", || transition.finish(&residual, params.blur_radius));
    let seconds = started.elapsed().as_secs_f64();
    progress::phase("writing", || {
        for (path, step) in step_paths.iter().zip(&steps) {
            outputs.stage(Some(path), || encode_field(path, step, &args.heights))?;
        }
        outputs.stage(Some(&args.out), || encode_field(&args.out, &joined, &args.heights))
    })?;
    outputs.commit()?;
    println!(
        "transition {}×{}: a band of {} samples from {} grown in {seconds:.1} s → {}",
        a.columns,
        a.rows,
        band.width,
        band.start,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The search of `--search`, chosen after its cost was checked.
enum Search {
    Cpu,
    /// The GPU passes on the device of `--device`, with its validation report.
    Gpu(Context),
}

/// Logs the estimated cost of the growth (info) and refuses it when its
/// memory or its time on the search of `--search` exceeds the limits
/// (`--max-hours`); `field` names the input in errors. A GPU search is
/// first checked at the fastest rate any GPU is assumed to reach, before
/// the device is made, so that what no device does in time is refused at
/// once; then at the rate of the device made (lavapipe: a CPU).
fn prepare_search(cost: &GrowthCost, args: &GrowArgs, field: &str) -> Result<Search> {
    let limits = MemoryLimits::host_only();
    let max_seconds = args.max_hours * 3600.0;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let checked = |device: SearchDevice, limits: &MemoryLimits| -> Result<()> {
        log::info!("synthesis estimate: {}", cost.summary(device));
        Ok(cost.check(device, limits, max_seconds, field)?)
    };
    match args.search {
        SearchArg::Cpu => {
            checked(
                SearchDevice::Cpu {
                    threads: cost.cpu_threads(threads),
                },
                &limits,
            )?;
            Ok(Search::Cpu)
        }
        SearchArg::Gpu => {
            cost.check(SearchDevice::Gpu, &limits, max_seconds, field)?;
            let ctx = super::context(&args.device)?;
            // The device's own heaps and largest allocation decide now.
            let device = if ctx.info().device_type == "CPU" {
                SearchDevice::CpuDevice { threads }
            } else {
                SearchDevice::Gpu
            };
            checked(device, &ctx.memory_limits())?;
            Ok(Search::Gpu(ctx))
        }
    }
}

/// Grows `growth` with `search` and writes the result to `out`; returns
/// the seconds the growth took.
fn grow_and_write(
    growth: Growth,
    search: Search,
    mut outputs: Outputs,
    out: &Path,
    heights: &HeightArgs,
) -> Result<f64> {
    let started = Instant::now();
    let grown = grow_with(growth, search, &mut |_, _| Ok(()))?;
    let seconds = started.elapsed().as_secs_f64();
    progress::phase("writing", || {
        outputs.stage(Some(out), || encode_field(out, &grown, heights))
    })?;
    outputs.commit()?;
    Ok(seconds)
}

/// Grows `growth` with `search` (on the GPU: validated with `--validation`
/// when asked), with a progress bar on stderr when it is a terminal.
/// The files of `--steps K` beside `out`: STEM-step-I.EXT, I = 1..=K.
fn step_paths(out: &Path, steps: u32) -> Vec<PathBuf> {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    (1..=steps)
        .map(|i| out.with_file_name(format!("{stem}-step-{i}.{ext}")))
        .collect()
}

fn grow_with(
    growth: Growth,
    search: Search,
    observe: &mut dyn FnMut(&HeightField, &[bool]) -> alpenglow::Result<()>,
) -> Result<HeightField> {
    let bar = progress::bar(growth.unknown_count() as u64, "{pos}/{len} samples grown");
    let mut report = |done: usize, _| bar.set_position(done as u64);
    let grown = match search {
        Search::Cpu => {
            let mut search = CpuSearch {
                exemplar: growth.exemplar().clone(),
                config: growth.search_config(),
            };
            growth.grow_observed(&mut search, &mut report, observe)?
        }
        Search::Gpu(ctx) => {
            let validation = ctx.validation_report();
            let grown = {
                let mut search = GpuSearch::new(&ctx, growth.exemplar().clone(), growth.search_config())?;
                growth.grow_observed(&mut search, &mut report, observe)?
            };
            drop(ctx);
            super::check_validation(validation)?;
            grown
        }
    };
    bar.finish_and_clear();
    Ok(grown)
}

/// The bytes of `field` written to `out` (by extension) with the height
/// mapping and row order of `args`.
fn encode_field(out: &Path, field: &HeightField, args: &HeightArgs) -> alpenglow::Result<Vec<u8>> {
    use alpenglow::Error;
    let (w, h) = (field.columns as usize, field.rows as usize);
    let (scale, offset) = (f64::from(args.height_scale), f64::from(args.height_offset));
    let flip = args.rows == RowsArg::NorthUp;
    // Image row i shows field row i (south-up) or h−1−i (north-up).
    let raw_at = |i: usize| {
        let (c, r) = (i % w, i / w);
        let row = if flip { h - 1 - r } else { r };
        (c, row, (f64::from(field.heights[row * w + c]) - offset) / scale)
    };
    let is_png = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        let mut values = Vec::with_capacity(w * h);
        for i in 0..w * h {
            let (c, r, raw) = raw_at(i);
            let value = raw as f32;
            if !value.is_finite() {
                // Only a tiny --height-scale divides a finite height past f32.
                return Err(Error::invalid(
                    "--height-scale",
                    format!(
                        "{scale}: height {} m at column {c}, row {r} divided by it exceeds the EXR's 32-bit floats",
                        field.heights[r * w + c]
                    ),
                ));
            }
            values.push(value);
        }
        return encode_exr_height(&values, field.columns, field.rows);
    }
    let mut values = Vec::with_capacity(w * h);
    for i in 0..w * h {
        let (c, r, raw) = raw_at(i);
        let rounded = raw.round();
        if !(0.0..=65535.0).contains(&rounded) {
            return Err(Error::output(
                out,
                format!(
                    "height {} m at column {c}, row {r} is outside the 16-bit PNG range {offset}..={} m \
                     (set --height-scale and --height-offset, or write .exr)",
                    field.heights[r * w + c],
                    offset + 65535.0 * scale
                ),
            ));
        }
        values.push(rounded as u16);
    }
    encode_png_gray16(&values, field.columns, field.rows)
}
