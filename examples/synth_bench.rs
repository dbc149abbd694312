//! Hole-filling time of pixel growing (dissertation §7.3; the text: "up to
//! several minutes for relatively small height fields"):
//! `cargo run --release --example synth_bench -- [--search cpu|gpu] [--sizes 64,128,256] [--estimate 256]`.
//!
//! The Jacksboro DEM (`tests/data/jacksboro-fault.png`, 403×344) resampled
//! bilinearly to 1025² samples; a square hole of each size in its centre,
//! filled with the default parameters (window 7, λ 0.25, ε 0.1, waves of
//! 256, 16384 candidates). Prints one row per size: samples, seconds,
//! microseconds per sample. Sizes given to `--estimate` are not run: their
//! time is estimated from the per-sample rate of the largest size run (the
//! search's cost per sample is candidates × window², whatever the hole).

use std::path::Path;
use std::time::Instant;

use alpenglow::files::load_heightmap;
use alpenglow::tools::synth::{fill_holes_cpu, plan_hole_fill, FillParams, GpuSearch};
use alpenglow::{Context, ContextOptions, HeightField, HeightmapOptions};
use glam::DVec2;

const SIDE: u32 = 1025;

/// The DEM resampled to `SIDE`² samples (bilinear).
fn dem() -> alpenglow::Result<HeightField> {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/jacksboro-fault.png"));
    let spacing = DVec2::new(74.4, 92.6);
    let full = load_heightmap(
        path,
        &HeightmapOptions {
            spacing: Some(spacing),
            ..HeightmapOptions::default()
        },
    )?;
    let (sx, sy) = (
        f64::from(full.columns - 1) / f64::from(SIDE - 1),
        f64::from(full.rows - 1) / f64::from(SIDE - 1),
    );
    Ok(HeightField::from_fn(
        SIDE,
        SIDE,
        DVec2::new(spacing.x * sx, spacing.y * sy),
        |c, r| {
            let (x, y) = (f64::from(c) * sx, f64::from(r) * sy);
            let (c0, r0) = (x.floor() as u32, y.floor() as u32);
            let (fx, fy) = (x - f64::from(c0), y - f64::from(r0));
            let h = |c: u32, r: u32| f64::from(full.height(c, r));
            let top = h(c0, r0) * (1.0 - fx) + h(c0 + 1, r0) * fx;
            let bottom = h(c0, r0 + 1) * (1.0 - fx) + h(c0 + 1, r0 + 1) * fx;
            (top * (1.0 - fy) + bottom * fy) as f32
        },
    ))
}

fn list(value: Option<String>) -> Vec<u32> {
    value
        .map(|v| v.split(',').filter_map(|s| s.trim().parse().ok()).collect())
        .unwrap_or_default()
}

fn main() -> alpenglow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut search, mut sizes, mut estimate) = ("cpu".to_string(), vec![64, 128, 256], vec![]);
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "--search" => search = args.next().unwrap_or_default(),
            "--sizes" => sizes = list(args.next()),
            "--estimate" => estimate = list(args.next()),
            other => {
                eprintln!("unknown option {other}; see the example's documentation");
                std::process::exit(2);
            }
        }
    }
    if search != "cpu" && search != "gpu" {
        eprintln!("--search {search}: use cpu or gpu");
        std::process::exit(2);
    }
    let ctx = if search == "gpu" {
        Some(Context::new(&ContextOptions::default())?)
    } else {
        None
    };
    let field = dem()?;
    let params = FillParams::default();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let device = ctx
        .as_ref()
        .map_or(format!("{threads} threads"), |c| c.info().name.clone());
    println!(
        "synth_bench: {SIDE}² DEM, window {}, {} candidates, batch {}, {search} search ({device})",
        params.window, params.candidates, params.batch
    );
    println!("{:>6} {:>8} {:>10} {:>12}", "hole", "samples", "seconds", "µs/sample");
    let mut rate = None;
    for &size in &sizes {
        let samples = u64::from(size) * u64::from(size);
        if estimate.contains(&size) {
            if let Some(seconds_per_sample) = rate {
                let seconds = seconds_per_sample * samples as f64;
                println!(
                    "{size:>5}² {samples:>8} {seconds:>10.0} {:>12.1}  (estimated)",
                    seconds_per_sample * 1e6
                );
            }
            continue;
        }
        let lo = (SIDE - size) / 2;
        let unknown: Vec<bool> = (0..SIDE * SIDE)
            .map(|i| (lo..lo + size).contains(&(i % SIDE)) && (lo..lo + size).contains(&(i / SIDE)))
            .collect();
        let started = Instant::now();
        match &ctx {
            Some(ctx) => {
                let growth = plan_hole_fill(&field, &unknown, &params)?;
                let mut gpu = GpuSearch::new(ctx, growth.exemplar().clone(), growth.search_config())?;
                growth.grow(&mut gpu, &mut |_, _| {})?;
            }
            None => {
                fill_holes_cpu(&field, &unknown, &params, &mut |_, _| {})?;
            }
        }
        let seconds = started.elapsed().as_secs_f64();
        rate = Some(seconds / samples as f64);
        println!(
            "{size:>5}² {samples:>8} {seconds:>10.1} {:>12.1}",
            seconds / samples as f64 * 1e6
        );
    }
    Ok(())
}
