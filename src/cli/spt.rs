//! `alpenglow spt build IN OUT`: a PLY or OBJ file → surfels (meshes sampled
//! evenly, point clouds completed with PCA normals and neighbour radii) →
//! sequential point tree (§10.1) → versioned SPT file, with a progress bar.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};

use alpenglow::points::build::estimate::complete_cloud;
use alpenglow::points::build::input::{load_points_file, PointInput};
use alpenglow::points::build::sampling::{sample_mesh, SamplingMethod, SamplingOptions};
use alpenglow::points::build::spt::{build_spt, epsilon_from_pixels, SptOptions};
use alpenglow::points::build::spt_file::write_spt;

use super::args::{SamplingArg, SptBuildArgs};

pub fn build(args: SptBuildArgs) -> Result<ExitCode> {
    let started = Instant::now();
    let surfels = match load_points_file(&args.input)? {
        PointInput::Mesh(mesh) => sample_mesh(
            &mesh,
            &SamplingOptions {
                count: args.samples,
                method: match args.sampling {
                    SamplingArg::Stratified => SamplingMethod::Stratified,
                    SamplingArg::BlueNoise => SamplingMethod::BlueNoise,
                },
                seed: args.seed,
            },
        )?,
        PointInput::Points(cloud) => complete_cloud(&cloud)?,
    };
    let options = SptOptions {
        epsilon: epsilon_from_pixels(args.epsilon, args.fov_y.to_radians(), args.rows)?,
        ..SptOptions::default()
    };
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {percent}% building the point tree")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let tree = build_spt(&surfels, &options, &mut |f| {
        bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64)
    })?;
    bar.finish_and_clear();
    write_spt(&args.output, &tree)?;
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
