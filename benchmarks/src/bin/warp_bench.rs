//! Micro-benchmark of the CPU geometry image warp (dissertation §7.4.2; the
//! text: "we can do the warping on the CPU in a few milliseconds"):
//! `cargo run --release -p alpenglow-bench --bin warp_bench`.
//!
//! Times `warp`, `warp_into` (buffers reused, the per-frame case) and, for
//! reference, the per-column variant and `importance_map` on a 128² sketch map
//! of the default procedural terrain seen from one side; then the whole
//! per-frame CPU stage (`LodFrame::plan`: sketch map resampled with the cubic
//! B-spline, importance map, warp) for the default scene and camera; prints
//! the median and the spread over 200 runs on one thread.

use std::hint::black_box;
use std::time::Instant;

use alpenglow::bench::{
    importance_map, warp, warp_into, warp_with, Backface, ColumnImportance, DebugScalar, Frustum, ImportanceParams,
    LodFrame, SketchMap, WarpOptions,
};
use alpenglow::{LodSettings, ProceduralTerrain, Scene, SketchAlignment};
use glam::DVec3;

const N: usize = 128;
const RUNS: usize = 200;

/// Median, minimum and maximum milliseconds of `RUNS` calls of `f`.
fn time(mut f: impl FnMut()) -> (f64, f64, f64) {
    f(); // warm-up
    let mut ms: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    (ms[RUNS / 2], ms[0], ms[RUNS - 1])
}

fn main() -> alpenglow::Result<()> {
    let spacing = 10_000.0 / (N - 1) as f64;
    let terrain = ProceduralTerrain::default();
    let sketch: Vec<DVec3> = (0..N * N)
        .map(|k| {
            let (x, y) = ((k % N) as f64 * spacing, (k / N) as f64 * spacing);
            DVec3::new(x, y, terrain.height(x, y))
        })
        .collect();
    let eye = DVec3::new(5000.0, 300.0, 1000.0);
    let frustum = Frustum::perspective(
        eye,
        DVec3::new(0.0, 1.0, -0.15),
        DVec3::Z,
        50f64.to_radians(),
        16.0 / 9.0,
        2.0 * spacing,
    )?;
    let params = ImportanceParams {
        min_distance: spacing,
        frustum: Some(frustum),
        backface: Some(Backface::default()),
        ..Default::default()
    };
    let importance = importance_map(&sketch, N, eye, &params)?;

    let report = |what: &str, (median, min, max): (f64, f64, f64)| {
        println!("{what:<34} median {median:.3} ms  (min {min:.3}, max {max:.3}; {RUNS} runs, {N}²)");
    };
    report(
        "warp (default, box filter)",
        time(|| {
            black_box(warp(black_box(&sketch), black_box(&importance), N).ok());
        }),
    );
    let mut reused = warp(&sketch, &importance, N)?;
    report(
        "warp_into (reused buffers)",
        time(|| {
            black_box(
                warp_into(
                    black_box(&sketch),
                    black_box(&importance),
                    N,
                    WarpOptions::default(),
                    &mut reused,
                )
                .ok(),
            );
        }),
    );
    let per_column = WarpOptions {
        columns: ColumnImportance::PerColumn,
        ..Default::default()
    };
    report(
        "warp (per-column second pass)",
        time(|| {
            black_box(warp_with(black_box(&sketch), black_box(&importance), N, per_column).ok());
        }),
    );
    report(
        "importance_map (all four factors)",
        time(|| {
            black_box(importance_map(black_box(&sketch), N, eye, &params).ok());
        }),
    );
    let scene = Scene::default_terrain()?;
    let camera = scene.default_camera();
    let aspect = 16.0 / 9.0;
    report(
        "sketch map (128², cubic B-spline)",
        time(|| {
            black_box(SketchMap::for_view(&scene.heights, &camera, aspect, SketchAlignment::View, N).ok());
        }),
    );
    let mut frame = LodFrame::default();
    let settings = LodSettings::default();
    report(
        "whole CPU stage per frame (plan)",
        time(|| {
            // A replan every time (the plan of an unchanged key is kept).
            frame.invalidate();
            black_box(
                frame
                    .plan(&scene.heights, &camera, aspect, &settings, DebugScalar::None)
                    .ok(),
            );
        }),
    );
    Ok(())
}
