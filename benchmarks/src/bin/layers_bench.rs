//! Benchmark of surface layers from a real image (§8.3;
//! `alpenglow::tools::layers`) on the Rocky Mountain pair of
//! `tests/data/real-world` (304 × 374 image, 152 × 187 DEM):
//! `cargo run --release -p alpenglow-bench --bin layers_bench [-- RUNS]` (default 5).
//!
//! Prints the median CPU time of each step over the runs — the quantities
//! at the pixels (B-spline altitude and slope), the modelled light (with
//! cast shadows), the classification (with k-means and the automatic k),
//! the distribution functions, the tree, the calibration of the noise bias
//! — and of the whole `build_layers`.

use std::time::Instant;

use alpenglow::bench::{calibrate, classify, distributions, shading, tree, Registration};
use alpenglow::files::{load_heightmap, InputLimits};
use alpenglow::tools::layers::{build_layers, load_rgb_image, FromImageOptions};
use alpenglow::tools::profile::median;
use alpenglow::{HeightmapOptions, RowOrder};
use glam::DVec2;

/// Milliseconds `f` takes, with its result.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let value = f();
    (value, start.elapsed().as_secs_f64() * 1e3)
}

fn main() -> alpenglow::Result<()> {
    let runs: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5).max(1);
    let dir = alpenglow_bench::repo_root().join("tests/data/real-world");
    let options = HeightmapOptions {
        spacing: Some(DVec2::new(233.6, 234.3)),
        rows: RowOrder::NorthUp,
        ..Default::default()
    };
    let field = load_heightmap(&dir.join("rmnp-dem.png"), &options)?;
    let image = load_rgb_image(&dir.join("rmnp-rgb.png"), &InputLimits::default())?;
    let maps = [None, None, None];
    let o = FromImageOptions::default();
    let names = [
        "quantities",
        "light",
        "classify",
        "distributions",
        "tree",
        "calibrate",
        "build_layers",
    ];
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for _ in 0..runs {
        let registration = Registration::new(image.width(), image.height(), &field, o.image_rows)?;
        let positions = registration.world_positions();
        let (samples, t0) = timed(|| distributions::Samples::at(&field, &maps, &positions));
        let samples = samples?;
        let (light, t1) =
            timed(|| shading::relative_illumination(&field, &positions, o.sun_azimuth_deg, o.sun_elevation_deg));
        let snow = 3469.0;
        let (classes, t2) = timed(|| classify::classify(&image, &registration, &light, &samples.altitude, snow, &o));
        let classes = classes?;
        let (functions, t3) = timed(|| distributions::estimate(&classes, &samples, o.bins));
        let provenance = tree::Provenance {
            options: o.clone(),
            snow_min_altitude: snow,
            spacing: field.spacing,
        };
        let (mut generated, t4) = timed(|| tree::build(&classes, &functions, &provenance));
        let fractions = classes.fractions();
        let targets: Vec<f64> = generated.layers.iter().map(|l| fractions[l.class]).collect();
        let points = calibrate::sample_positions(&positions, registration.width as usize, &classes.status);
        let (calibrated, t5) = timed(|| {
            calibrate::calibrate(
                &mut generated.layers,
                &targets,
                tree::layer_tree,
                &field,
                &maps,
                &points,
            )
        });
        calibrated?;
        let (all, t6) = timed(|| build_layers(&image, &field, &maps, &o));
        all?;
        for (list, t) in times.iter_mut().zip([t0, t1, t2, t3, t4, t5, t6]) {
            list.push(t);
        }
    }
    println!(
        "layers from a real image: {}×{} image, {}×{} DEM, median of {runs} run(s)",
        image.width(),
        image.height(),
        field.columns,
        field.rows
    );
    for (name, list) in names.iter().zip(&times) {
        println!("  {name:<14} {:>9.1} ms", median(list.iter().copied()));
    }
    Ok(())
}
