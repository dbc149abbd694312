//! Wall times of the two expensive lighting computations, as benchmarks
//! rather than tests (no timing belongs in a test):
//!
//! * `bake`: the sky-light bake (§9.3–9.5: horizon tracing, SH transfer,
//!   bounces) of smooth fields, 513² and 1025² by default
//!   (`ALPENGLOW_BAKE_SIZES=129,513` to choose), for 3 and 5 bands with 0
//!   and 1 bounces;
//! * `reference`: one frame of the Monte Carlo reference (§9.2) of 129² and
//!   513² fields at 64 and 256 paths per texel, one bounce.
//!
//! `cargo run --release -p alpenglow-bench --bin lighting_bench -- bake|reference`
//! (without validation; figures in docs/PERFORMANCE.md).

use std::time::Instant;

use alpenglow::bench::{
    sun_direction, BakeSettings, FrameRing, LightingFrame, MonteCarloReference, ReferenceSettings, ReferenceWork,
    RenderGraph, SkyLightBake,
};
use alpenglow::{Context, ContextOptions, DeviceSelector, HeightField};
use bytemuck::Zeroable;
use glam::DVec2;

fn main() -> alpenglow::Result<()> {
    let what = std::env::args().nth(1).unwrap_or_default();
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    println!("device: {} ({})", ctx.info().name, ctx.info().driver_name);
    match what.as_str() {
        "bake" => bake(&ctx),
        "reference" => reference(&ctx),
        _ => Err(alpenglow::Error::invalid(
            "benchmark",
            format!("'{what}': expected bake or reference"),
        )),
    }
}

/// Smooth hills of `n`² samples at 30 m.
fn hills(n: u32) -> HeightField {
    HeightField::from_fn(n, n, DVec2::new(30.0, 30.0), |c, r| {
        let (x, y) = (c as f32 / 64.0, r as f32 / 64.0);
        400.0 * (x.sin() * y.cos()) + 150.0 * (2.3 * x + 1.7 * y).sin()
    })
}

fn bake(ctx: &Context) -> alpenglow::Result<()> {
    let sizes: Vec<u32> = std::env::var("ALPENGLOW_BAKE_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![513, 1025]);
    for n in sizes {
        let field = hills(n);
        for (bands, bounces) in [(3, 0), (3, 1), (5, 0), (5, 1)] {
            let settings = BakeSettings {
                sh_bands: bands,
                bounces,
                ..BakeSettings::default()
            };
            let start = Instant::now();
            match SkyLightBake::compute(ctx, &field, &settings, &mut |_| {}) {
                Ok(_) => println!(
                    "{n}² bands {bands} bounces {bounces}: {:.1} s",
                    start.elapsed().as_secs_f64()
                ),
                Err(e) => println!("{n}² bands {bands} bounces {bounces}: {e}"),
            }
        }
    }
    Ok(())
}

fn reference(ctx: &Context) -> alpenglow::Result<()> {
    let mut frame = LightingFrame::zeroed();
    let s = sun_direction(35.0, 120.0);
    frame.sun = [s.x, s.y, s.z, 0.004_654];
    frame.sun_irradiance = [3.0, 2.5, 2.0, 0.0];
    for n in [129u32, 513] {
        let field = hills(n);
        for samples in [64u32, 256] {
            let settings = ReferenceSettings {
                samples,
                bounces: 1,
                ..ReferenceSettings::default()
            };
            let mut reference = MonteCarloReference::new(ctx, &field, settings)?;
            let mut graph: RenderGraph<ReferenceWork> = RenderGraph::new();
            let region = graph.upload_region("lighting", std::mem::size_of::<LightingFrame>() as u64);
            reference.declare(&mut graph, region, &[]);
            let mut baked = graph.bake(ctx)?;
            let mut ring = FrameRing::new(ctx)?;
            let start = Instant::now();
            let index = ring.wait_for_next()?;
            let mut constants = frame;
            reference.fill(&mut constants);
            baked.uploads(index).write_pod(region, &constants)?;
            let (work, _) = reference.prepare(&frame);
            baked.execute(&mut ring, &work, &[])?;
            baked.finish(&mut ring)?;
            println!(
                "{n}² field, {samples} paths per texel, 1 bounce: {:.2} s",
                start.elapsed().as_secs_f64()
            );
        }
    }
    Ok(())
}
