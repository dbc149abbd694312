//! `alpenglow dem import` and `alpenglow dem info`: height pyramids
//! (`.hpyr`, `alpenglow::files::HeightPyramid`), the tiled on-disk form in
//! which fields of any size are rendered (`render --heightmap FILE.hpyr`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use alpenglow::files::{
    load_heightmap, write_pyramid, FieldRows, HeightPyramid, HeightRows, HgtMosaic, PyramidOptions, PyramidSummary,
    DEFAULT_TILE_SIDE,
};
use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use glam::DVec2;

use crate::cli::synth::{heightmap_options, HeightArgs};

#[derive(Subcommand, Debug)]
pub enum DemCommand {
    /// Write a height pyramid (.hpyr) from a height map (PNG, EXR, GeoTIFF;
    /// with the gdal feature any GDAL raster, streamed: COG, VRT, ...) or
    /// from SRTM .hgt cells (several cells: one mosaic, streamed).
    Import(ImportArgs),
    /// Describe a height pyramid; --verify reads and checks every tile.
    Info(InfoArgs),
}

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The height map, or the .hgt cells of a mosaic (a full rectangle of
    /// whole degrees).
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,
    /// The pyramid to write (.hpyr).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Samples per tile side, 16..=4096.
    #[arg(long = "tile-side", default_value_t = DEFAULT_TILE_SIDE, value_name = "SAMPLES")]
    pub tile_side: u32,
    /// Height quantum in metres, 1/1024..=1 (the largest error is half of it).
    #[arg(long = "height-step", default_value_t = 1.0 / 256.0, value_name = "METRES")]
    pub height_step: f64,
    #[command(flatten)]
    pub heights: HeightArgs,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The pyramid.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Read and check every tile.
    #[arg(long)]
    pub verify: bool,
}

pub fn run(command: DemCommand) -> Result<ExitCode> {
    match command {
        DemCommand::Import(args) => import(args),
        DemCommand::Info(args) => info(args),
    }
}

fn is_hgt(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("hgt"))
}

fn import(args: ImportArgs) -> Result<ExitCode> {
    let options = PyramidOptions {
        tile_side: args.tile_side,
        height_step: args.height_step,
    };
    options.validate()?;
    let started = Instant::now();
    let summary = if args.inputs.iter().all(|p| is_hgt(p)) {
        let mut mosaic = HgtMosaic::open(&args.inputs)?;
        if let Some((dx, dy)) = args.heights.spacing {
            mosaic = mosaic.with_spacing(DVec2::new(dx, dy))?;
        }
        if args.heights.height_scale != 1.0 || args.heights.height_offset != 0.0 {
            log::warn!("--height-scale and --height-offset are ignored for .hgt cells (metres already)");
        }
        write_pyramid(&args.out, &mut mosaic, &options)?
    } else {
        let [input] = args.inputs.as_slice() else {
            bail!("several inputs make a mosaic only of SRTM .hgt cells; import other height maps one at a time (or a GDAL VRT of them)");
        };
        import_one(input, &args, &options)?
    };
    let samples = f64::from(summary.columns) * f64::from(summary.rows);
    println!(
        "{}: {}×{} samples, {} levels, {} tiles, {:.1} MiB ({:.2} bytes a sample), heights {:.1}..{:.1} m, in {:.1} s",
        args.out.display(),
        summary.columns,
        summary.rows,
        summary.levels,
        summary.tiles,
        summary.bytes as f64 / f64::from(1 << 20),
        summary.bytes as f64 / samples,
        summary.min_height,
        summary.max_height,
        started.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

/// Whether `path` is read by GDAL (feature `gdal`): everything but the
/// PNG and EXR height maps, whose row order and value mapping are
/// alpenglow's own (`--rows`, `--height-scale`).
fn read_by_gdal(path: &Path) -> bool {
    let own = ["png", "exr"];
    cfg!(feature = "gdal")
        && !path
            .extension()
            .is_some_and(|e| own.iter().any(|o| e.eq_ignore_ascii_case(o)))
}

/// The pyramid of one height map (streamed by GDAL where it reads it).
fn import_one(input: &Path, args: &ImportArgs, options: &PyramidOptions) -> Result<PyramidSummary> {
    if read_by_gdal(input) {
        #[cfg(feature = "gdal")]
        {
            let spacing = args.heights.spacing.map(|(dx, dy)| DVec2::new(dx, dy));
            let mut rows = alpenglow::files::GdalRows::open(
                input,
                spacing,
                f64::from(args.heights.height_scale),
                f64::from(args.heights.height_offset),
            )?;
            return Ok(write_pyramid(&args.out, &mut rows, options)?);
        }
    }
    let field = load_heightmap(input, &heightmap_options(&args.heights))?;
    let mut rows = FieldRows::new(&field, input);
    Ok(write_pyramid(&args.out, &mut rows as &mut dyn HeightRows, options)?)
}

fn info(args: InfoArgs) -> Result<ExitCode> {
    let pyramid = HeightPyramid::open(&args.file)?;
    let (columns, rows) = pyramid.size();
    let spacing = pyramid.spacing();
    let extent = pyramid.extent();
    let (lo, hi) = pyramid.height_range();
    println!(
        "{}: {columns}×{rows} samples at {}×{} m ({:.3}×{:.3} km), heights {lo:.2}..{hi:.2} m (step {} m), tiles of {}², {:.1} MiB",
        args.file.display(),
        spacing.x,
        spacing.y,
        extent.x / 1000.0,
        extent.y / 1000.0,
        pyramid.height_step(),
        pyramid.tile_side(),
        pyramid.file_bytes() as f64 / f64::from(1 << 20)
    );
    for level in 0..pyramid.levels() {
        let (c, r) = pyramid.level_size(level);
        let (tx, ty) = pyramid.tiles(level);
        let s = pyramid.level_spacing(level);
        println!(
            "  level {level}: {c}×{r} samples, {tx}×{ty} tiles, {:.2}×{:.2} m",
            s.x, s.y
        );
    }
    if args.verify {
        let started = Instant::now();
        pyramid.verify()?;
        println!(
            "every tile read and checked in {:.1} s",
            started.elapsed().as_secs_f64()
        );
    }
    Ok(ExitCode::SUCCESS)
}
