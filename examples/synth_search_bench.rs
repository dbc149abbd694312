//! Throughput of the neighbourhood search of height-field synthesis (§7.3):
//! the GPU passes (`synthesis::gpu`) against the CPU twin
//! (`synthesis::search::CpuSearch`, all cores) on random data, as a
//! benchmark rather than a test. Prints queries/s and candidate·taps/s of
//! each, the GPU time per pass, and whether the choices agree.
//!
//! `cargo run --release --example synth_search_bench -- [QUERIES [SIDE [WINDOW [REPEATS]]]]`
//! (default 256 queries, a 134² exemplar = 16384 candidates of window 7,
//! 5 repeats; without validation; figures in docs/PERFORMANCE.md).

use std::sync::Arc;
use std::time::Instant;

use alpenglow::bench::{Exemplar, NeighbourhoodSearch, Query, SearchConfig, SplitMix64};
use alpenglow::tools::synth::{CpuSearch, GpuSearch};
use alpenglow::{Context, ContextOptions, DeviceSelector};

fn arg(i: usize, default: u32) -> u32 {
    std::env::args().nth(i).and_then(|a| a.parse().ok()).unwrap_or(default)
}

fn main() -> alpenglow::Result<()> {
    let (queries, side, window, repeats) = (arg(1, 256), arg(2, 134), arg(3, 7), arg(4, 5).max(1));
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_name);
    let mut rng = SplitMix64(2006);
    let texels = (0..side * side)
        .map(|_| {
            let (hx, hy) = rng.gaussian_pair();
            [rng.next_f64() as f32 * 100.0, hx as f32, hy as f32]
        })
        .collect();
    let exemplar = Arc::new(Exemplar {
        width: side,
        height: side,
        texels,
        candidates: Exemplar::inside_centres(side, side, window),
    });
    let taps = window * window;
    let queries: Vec<Query> = (0..queries)
        .map(|pixel| Query {
            pixel,
            taps: (0..taps)
                .map(|_| {
                    let known = rng.next_f64() < 0.6;
                    [rng.next_f64() as f32 * 100.0, 0.0, 0.0, if known { 1.0 } else { 0.0 }]
                })
                .collect(),
        })
        .collect();
    let config = SearchConfig {
        window,
        lambda: 1.0,
        epsilon: 0.05,
        seed: 1,
    };
    let pairs = queries.len() as f64 * exemplar.candidates.len() as f64;
    println!(
        "{} queries × {} candidates, window {window} ({taps} taps, ~60 % known), {repeats} repeats",
        queries.len(),
        exemplar.candidates.len()
    );
    let report = |name: &str, seconds: f64| {
        println!(
            "{name}: {:.1} ms per call, {:.0} queries/s, {:.3e} candidate·taps/s",
            seconds * 1e3,
            queries.len() as f64 / seconds,
            pairs * f64::from(taps) / seconds
        );
    };

    let mut gpu = GpuSearch::new(&ctx, exemplar.clone(), config)?;
    let gpu_choices = gpu.choose(&queries)?; // warm-up
    gpu.take_profiles()?;
    let start = Instant::now();
    for _ in 0..repeats {
        gpu.choose(&queries)?;
    }
    report("GPU", start.elapsed().as_secs_f64() / f64::from(repeats));
    let profiles = gpu.take_profiles()?;
    for (i, name) in gpu.pass_names().iter().enumerate() {
        let ms: f64 = profiles.iter().filter_map(|p| p.passes.get(i)).map(|p| p.gpu_ms).sum();
        println!("  {name}: {:.3} ms GPU per call", ms / f64::from(repeats));
    }

    let mut cpu = CpuSearch {
        exemplar: exemplar.clone(),
        config,
    };
    let start = Instant::now();
    let cpu_choices = cpu.choose(&queries)?;
    report(
        &format!(
            "CPU ({} threads)",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ),
        start.elapsed().as_secs_f64(),
    );
    let differ = gpu_choices.iter().zip(&cpu_choices).filter(|(g, c)| g != c).count();
    println!("choices that differ between GPU and CPU: {differ} of {}", queries.len());
    Ok(())
}
