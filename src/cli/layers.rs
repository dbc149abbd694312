//! `alpenglow layers from-image`: a surface-layer tree estimated from a
//! real colour image registered to a height map (dissertation §8.3; see
//! `alpenglow::tools::layers`).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use glam::DVec2;

use alpenglow::files::{load_heightmap, InputLimits};
use alpenglow::tools::layers::{
    build_layers, load_mask, load_rgb_image, ClassCount, FromImageOptions, PixelStatus, INPUT_NAMES, MAX_CLASSES,
};
use alpenglow::{HeightField, HeightmapOptions, RowOrder};

use super::args::{parse_input_map, parse_spacing, RowsArg};
use super::outputs::Outputs;

#[derive(Subcommand, Debug)]
pub enum LayersCommand {
    /// Estimate a layer tree from a colour image registered to a height map (§8.3).
    FromImage(FromImageArgs),
}

#[derive(Args, Debug)]
pub struct FromImageArgs {
    /// True-colour image (PNG or JPEG) covering the height map's area: its
    /// size is the height map's times an integer (1, 2, …).
    #[arg(long, value_name = "FILE")]
    pub image: PathBuf,
    /// Height map (as `render --heightmap`).
    #[arg(long, value_name = "FILE")]
    pub heightmap: PathBuf,
    /// Metres between height samples: DX or DX,DY (default: the file's
    /// georeferencing, else 1 with a warning).
    #[arg(long, value_parser = parse_spacing, value_name = "DX[,DY]")]
    pub spacing: Option<(f64, f64)>,
    /// Multiplier of height-map values (to metres).
    #[arg(long = "height-scale", default_value_t = 1.0, value_parser = crate::cli::args::parse_height_scale, value_name = "FACTOR")]
    pub height_scale: f32,
    /// Added to height-map values after scaling, in metres.
    #[arg(long = "height-offset", default_value_t = 0.0, value_parser = crate::cli::args::parse_height_offset, value_name = "METRES")]
    pub height_offset: f32,
    /// Where the first row of the height map (PNG, EXR, plain TIFF) and of
    /// the image lies: south-up (default, as `render`) or north-up (row 0
    /// the north edge, as in nearly every GIS raster and satellite image).
    #[arg(long, value_enum, default_value = "south-up", value_name = "ORDER")]
    pub rows: RowsArg,
    /// Extra input map NAME=FILE (rainfall, radiation, temperature;
    /// repeatable), spanning the terrain: every layer gets a constraint on it.
    #[arg(long = "input-map", value_parser = parse_input_map, value_name = "NAME=FILE")]
    pub input_maps: Vec<(usize, PathBuf)>,
    /// Chromatic classes: a number 1..=8, or auto (the k in 2..=6 of the
    /// largest silhouette). Near-grey rock and snow come on top.
    #[arg(long, default_value = "auto", value_parser = parse_classes, value_name = "K|auto")]
    pub classes: ClassCount,
    /// Level-2 layers: split every chromatic level-1 class with at least
    /// 10 % of the pixels into K sub-classes (2..=4) by a second k-means
    /// inside the class; the class keeps its largest sub-class's colour,
    /// the others become its children (§8.3).
    #[arg(long, value_parser = clap::value_parser!(u64).range(2..=4), value_name = "K")]
    pub level2: Option<u64>,
    /// Pixels to leave out (e.g. cultivated land, §8.3): an image of the
    /// colour image's size, excluded where non-zero (not black).
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// The image's sun azimuth, degrees clockwise from north.
    #[arg(long = "sun-azimuth", default_value_t = 150.0, value_name = "DEGREES")]
    pub sun_azimuth: f64,
    /// The image's sun elevation, degrees.
    #[arg(long = "sun-elevation", default_value_t = 30.0, value_name = "DEGREES")]
    pub sun_elevation: f64,
    /// Snow below this altitude is cloud and not counted (default: 60 % of
    /// the way from the lowest to the highest height sample).
    #[arg(long = "snow-min-altitude", value_name = "METRES")]
    pub snow_min_altitude: Option<f32>,
    /// Samples of each distribution function, 1..=64.
    #[arg(long, default_value_t = 48, value_name = "COUNT")]
    pub bins: usize,
    /// Weight of the shade-normalised brightness in the clustering space,
    /// 0..=4 (0: hue and saturation alone, as in the text).
    #[arg(long = "value-weight", default_value_t = 0.5, value_name = "WEIGHT")]
    pub value_weight: f64,
    /// Keep dark pixels in modelled shadow (they then cluster with water and dark rock).
    #[arg(long = "no-shade-handling")]
    pub no_shade_handling: bool,
    /// Keep the noise bias of every layer at 1 instead of calibrating it to the class areas.
    #[arg(long = "no-calibration")]
    pub no_calibration: bool,
    /// k-means seed.
    #[arg(long, default_value_t = 1, value_name = "SEED")]
    pub seed: u64,
    /// Largest input file in MiB.
    #[arg(long = "max-input-mb", default_value_t = 2048, value_name = "MIB", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_input_mb: u64,
    /// Output layer tree (TOML).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Also write the class map (each pixel in its class's mean colour,
    /// pixels set aside as shade or cloud in magenta) as PNG.
    #[arg(long = "class-map", value_name = "FILE")]
    pub class_map: Option<PathBuf>,
    /// Also write the distribution histograms (Fig. 8.13) as PNG: a row per
    /// class (its colour swatch first), a panel per quantity (altitude,
    /// slope, the input maps in rainfall, radiation, temperature order),
    /// the written samples as bars from 0 to 1 over the quantity's domain.
    #[arg(long = "histograms", value_name = "FILE")]
    pub histograms: Option<PathBuf>,
    /// Also write the image's hue–saturation histogram (Fig. 8.12; hue
    /// left to right, saturation up, darker for more pixels, near greys at
    /// violet) beside its colour table as PNG.
    #[arg(long = "hs-histogram", value_name = "FILE")]
    pub hs_histogram: Option<PathBuf>,
}

/// `K|auto` of `--classes`.
fn parse_classes(s: &str) -> std::result::Result<ClassCount, String> {
    if s == "auto" {
        return Ok(ClassCount::Auto);
    }
    match s.parse::<usize>() {
        Ok(k) if (1..=MAX_CLASSES).contains(&k) => Ok(ClassCount::Fixed(k)),
        _ => Err(format!("'{s}' is not auto or a number 1..={MAX_CLASSES}")),
    }
}

fn row_order(rows: RowsArg) -> RowOrder {
    match rows {
        RowsArg::NorthUp => RowOrder::NorthUp,
        RowsArg::SouthUp => RowOrder::SouthUp,
    }
}

/// The height field and input maps of the arguments.
fn load_inputs(args: &FromImageArgs, limits: InputLimits) -> Result<(HeightField, [Option<HeightField>; 3])> {
    let field = load_heightmap(
        &args.heightmap,
        &HeightmapOptions {
            scale: args.height_scale,
            offset: args.height_offset,
            spacing: args.spacing.map(|(dx, dy)| DVec2::new(dx, dy)),
            rows: row_order(args.rows),
            limits,
        },
    )?;
    let mut maps: [Option<HeightField>; 3] = Default::default();
    for (k, path) in &args.input_maps {
        if maps[*k].is_some() {
            bail!("--input-map {} is given twice", INPUT_NAMES[*k]);
        }
        let opts = HeightmapOptions {
            spacing: Some(DVec2::ONE),
            limits,
            ..HeightmapOptions::default()
        };
        maps[*k] = Some(load_heightmap(path, &opts)?);
    }
    Ok((field, maps))
}

pub fn run(command: LayersCommand) -> Result<ExitCode> {
    match command {
        LayersCommand::FromImage(args) => from_image(args),
    }
}

fn from_image(args: FromImageArgs) -> Result<ExitCode> {
    let mut outputs = Outputs::default();
    outputs.add(Some(&args.out), "--out")?;
    outputs.add_image(args.class_map.as_deref(), "--class-map")?;
    outputs.add_image(args.histograms.as_deref(), "--histograms")?;
    outputs.add_image(args.hs_histogram.as_deref(), "--hs-histogram")?;
    let limits = InputLimits::with_max_file_mib(args.max_input_mb);
    let (field, maps) = load_inputs(&args, limits)?;
    let image = load_rgb_image(&args.image, &limits)?;
    let exclude = match &args.mask {
        Some(path) => Some(load_mask(path, image.width(), image.height(), &limits)?),
        None => None,
    };
    let options = FromImageOptions {
        classes: args.classes,
        image_rows: row_order(args.rows),
        sun_azimuth_deg: args.sun_azimuth,
        sun_elevation_deg: args.sun_elevation,
        shade_handling: !args.no_shade_handling,
        snow_min_altitude: args.snow_min_altitude,
        bins: args.bins,
        seed: args.seed,
        calibrate: !args.no_calibration,
        value_weight: args.value_weight,
        level2: args.level2.map(|k| k as usize),
        exclude,
    };
    let started = Instant::now();
    let generated = build_layers(&image, &field, &maps, &options)?;
    let seconds = started.elapsed().as_secs_f64();
    let mut sources = vec![format!(
        "Image: {} ({}×{}); height map: {} ({}×{}, spacing {} × {} m).",
        args.image.display(),
        image.width(),
        image.height(),
        args.heightmap.display(),
        field.columns,
        field.rows,
        field.spacing.x,
        field.spacing.y
    )];
    for (k, path) in &args.input_maps {
        sources.push(format!("Input map {}: {}.", INPUT_NAMES[*k], path.display()));
    }
    if let Some(path) = &args.mask {
        sources.push(format!("Mask: {}.", path.display()));
    }
    let toml = generated.to_toml(&sources);
    outputs.stage(Some(&args.out), || Ok(toml.into_bytes()))?;
    if let Some(path) = &args.class_map {
        let c = &generated.classification;
        let colours: Vec<[u8; 3]> = (c.classes.iter())
            .map(|class| alpenglow::tools::layers::srgb8(class.linear))
            .collect();
        let rgba: Vec<u8> = (c.labels.iter().zip(&c.status))
            .flat_map(|(&l, &s)| {
                let [r, g, b] = match s {
                    PixelStatus::Counted => colours.get(usize::from(l)).copied().unwrap_or([0; 3]),
                    _ => [255, 0, 255],
                };
                [r, g, b, 255]
            })
            .collect();
        outputs.stage_image(Some(path), &rgba, image.width(), image.height())?;
    }
    if let Some(path) = &args.histograms {
        let colours: Vec<_> = generated.classification.classes.iter().map(|c| c.linear).collect();
        let plot = alpenglow::tools::layers::plot_distributions(&generated.distributions, &colours);
        outputs.stage_image(Some(path), &plot.rgba, plot.width, plot.height)?;
    }
    if let Some(path) = &args.hs_histogram {
        let plot = alpenglow::tools::layers::plot_hue_saturation(&image);
        outputs.stage_image(Some(path), &plot.rgba, plot.width, plot.height)?;
    }
    outputs.commit()?;
    let c = &generated.classification;
    let summary: Vec<String> = (c.classes.iter())
        .zip(c.fractions())
        .map(|(class, f)| format!("{} {:.1} %", class.name, 100.0 * f))
        .collect();
    println!(
        "{} classes ({}) in {seconds:.2} s; wrote {}",
        c.classes.len(),
        summary.join(", "),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
