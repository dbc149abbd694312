//! `alpenglow spt build IN OUT`: a PLY or OBJ file → surfels (meshes sampled
//! evenly, point clouds completed with PCA normals and neighbour radii) →
//! sequential point tree (§10.1) → versioned SPT file, with a progress bar.
//!
//! Every option and the input are checked, and the build's time and memory
//! estimated ([`alpenglow::tools::spt::plan_build`]), before anything is
//! sampled: a bad option or file is a one-line error within milliseconds.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;

use alpenglow::files::{load_points_file, write_spt, PointInput};
use alpenglow::tools::budget::MemoryLimits;
use alpenglow::tools::spt::{
    build_spt, complete_cloud, epsilon_from_pixels, plan_build, sample_mesh_reporting, SamplingMethod, SamplingOptions,
    SptOptions,
};
use alpenglow::Error;

use super::args::{SamplingArg, SptBuildArgs};
use super::progress;

/// The tree's options from `--epsilon`, `--fov-y` and `--rows`, each
/// checked in the words of its flag.
fn spt_options(args: &SptBuildArgs) -> alpenglow::Result<SptOptions> {
    if !(args.epsilon.is_finite() && args.epsilon > 0.0) {
        return Err(Error::invalid(
            "--epsilon",
            format!("{} px is not a positive number", args.epsilon),
        ));
    }
    if !(args.fov_y.is_finite() && args.fov_y > 0.0 && args.fov_y < 180.0) {
        return Err(Error::invalid("--fov-y", format!("{}° is not in (0, 180)", args.fov_y)));
    }
    if args.rows == 0 {
        return Err(Error::invalid(
            "--rows",
            "0: the threshold needs at least one image row",
        ));
    }
    let epsilon = epsilon_from_pixels(args.epsilon, args.fov_y.to_radians(), args.rows)
        .ok()
        .filter(|e| e.is_finite() && *e > 0.0)
        .ok_or_else(|| {
            // The three together make the angle: all three are the culprit
            // (`--fov-y 1e-45` alone underflows it).
            Error::invalid(
                "--epsilon/--fov-y/--rows",
                format!(
                    "{} px at {}° over {} rows is not a representable angle",
                    args.epsilon, args.fov_y, args.rows
                ),
            )
        })?;
    Ok(SptOptions {
        epsilon,
        ..SptOptions::default()
    })
}

/// A library error of sampling or building in the words of the file it
/// came from: content errors name `path` (the checks of
/// [`plan_build`] report them first; this keeps any that slip through
/// naming the file too).
fn in_file(path: &Path, e: Error) -> Error {
    match e {
        Error::InvalidArgument { parameter, message } if !parameter.starts_with("--") => {
            Error::input(path, format!("{parameter}: {message}"))
        }
        other => other,
    }
}

pub fn build(args: SptBuildArgs) -> Result<ExitCode> {
    let started = Instant::now();
    let options = spt_options(&args)?;
    let sampling = SamplingOptions {
        count: args.samples,
        method: match args.sampling {
            SamplingArg::Stratified => SamplingMethod::Stratified,
            SamplingArg::BlueNoise => SamplingMethod::BlueNoise,
        },
        seed: args.seed,
    };
    let input = progress::phase("reading", || load_points_file(&args.input))?;
    let cost = plan_build(&args.input, &input, &sampling, &options)?;
    log::info!("spt build estimate: {}", cost.summary());
    let option = match input {
        PointInput::Mesh(_) => format!("--samples {}", args.samples),
        PointInput::Points(_) => args.input.display().to_string(),
    };
    cost.check(&option, &MemoryLimits::host_only(), args.max_hours * 3600.0)?;

    let surfels = match &input {
        PointInput::Mesh(mesh) => {
            let bar = progress::bar(1000, "{percent:>3}% sampling the mesh");
            let surfels = sample_mesh_reporting(mesh, &sampling, &mut |f| {
                bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64)
            });
            bar.finish_and_clear();
            surfels
        }
        PointInput::Points(cloud) => progress::phase("estimating normals and radii", || complete_cloud(cloud)),
    }
    .map_err(|e| in_file(&args.input, e))?;
    drop(input);
    let bar = progress::bar(1000, "{percent:>3}% building the point tree");
    let tree = build_spt(&surfels, &options, &mut |f| {
        bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64)
    });
    bar.finish_and_clear();
    let tree = tree.map_err(|e| in_file(&args.input, e))?;
    progress::phase("writing", || write_spt(&args.output, &tree))?;
    let leaves = tree.nodes.iter().filter(|n| n.is_leaf).count();
    println!(
        "{}: {} surfels → {} nodes ({} leaves), ε = {} px at {}° over {} rows; {:.2} s → {}",
        args.input.display(),
        surfels.len(),
        tree.nodes.len(),
        leaves,
        args.epsilon,
        args.fov_y,
        args.rows,
        started.elapsed().as_secs_f64(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
