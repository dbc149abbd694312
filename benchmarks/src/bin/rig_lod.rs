//! Which terrain LOD serves a rig best (§7.4 for several views)? Compares a
//! warped grid per view (each view's sketch map and importance, what the
//! renderer does) with one grid for the union of the views (a sketch map
//! around the rig, importance by distance alone, no frustum factor):
//!
//! `cargo run --release -p alpenglow-bench --bin rig_lod -- [--dem tests/data/jacksboro-fault.png] [--height 2]`
//!
//! For each view of a `ring6` rig at 640×480, it prints how many of the
//! grid's quads land in the view and their median and 90th-percentile
//! projected area in pixels (smaller: finer geometry), and the CPU time of
//! the plans (the per-view grids cost one warp each).

use std::time::Instant;

use alpenglow::bench::{projected_quad_areas, zoom_positions, DebugScalar, LodFrame, View};
use alpenglow::files::load_heightmap;
use alpenglow::tools::profile::quantile;
use alpenglow::{Camera, HeightmapOptions, LodSettings, Rig, Scene, SketchAlignment};
use glam::{DVec2, DVec3};

const GRID: usize = 512;

fn main() -> alpenglow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|k| args.get(k + 1))
            .cloned()
    };
    let scene = match value("--dem") {
        Some(path) => Scene::new(load_heightmap(
            std::path::Path::new(&path),
            &HeightmapOptions {
                spacing: Some(DVec2::new(74.4, 92.6)),
                ..HeightmapOptions::default()
            },
        )?),
        None => Scene::default_terrain()?,
    };
    let above: f64 = value("--height").map_or(2.0, |h| h.parse().expect("--height metres"));
    let field = &scene.heights;
    let (c, r) = (field.columns / 2, field.rows * 2 / 5);
    let eye = DVec3::new(
        f64::from(c) * field.spacing.x,
        f64::from(r) * field.spacing.y,
        f64::from(field.height(c, r)) + above,
    );
    let rig_camera = Camera {
        eye,
        target: eye + DVec3::Y,
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.5,
        far: 2.0 * field.extent().length(),
    };
    let rig = Rig::ring6(640);
    let cameras = rig.cameras(&rig_camera)?;
    let (w, h) = (640, 480);
    let settings = LodSettings::default();
    let n = settings.sketch_side;

    // One grid per view.
    let t = Instant::now();
    let mut per_view = Vec::new();
    for camera in &cameras {
        let mut lod = LodFrame::default();
        lod.plan(field, camera, f64::from(w) / f64::from(h), &settings, DebugScalar::None)?;
        per_view.push(zoom_positions(field, &lod.warp.positions, n, GRID)?);
    }
    let per_view_ms = t.elapsed().as_secs_f64() * 1e3;

    // One grid for the union: looking straight down over the rig, a frustum
    // wide enough to cover the terrain, importance by distance from the eye.
    let t = Instant::now();
    let down = Camera {
        target: eye - DVec3::Z,
        up: DVec3::Y,
        fov_y_deg: 179.0,
        ..rig_camera
    };
    let mut union_settings = settings;
    union_settings.factors.frustum = false;
    union_settings.factors.backface = false;
    union_settings.alignment = SketchAlignment::Axes;
    let mut lod = LodFrame::default();
    lod.plan(field, &down, 1.0, &union_settings, DebugScalar::None)?;
    let union = zoom_positions(field, &lod.warp.positions, n, GRID)?;
    let union_ms = t.elapsed().as_secs_f64() * 1e3;

    println!("ring6 at {w}×{h}, eye {above} m above the ground at {eye:.0}; {GRID}² grid");
    println!(
        "{:<12} {:>24} {:>24}",
        "view", "per-view: quads, median/p90 px", "union: quads, median/p90 px"
    );
    for ((camera, grid), spec) in cameras.iter().zip(&per_view).zip(&rig.views) {
        let view = View::new(*camera, w, h);
        let mine = projected_quad_areas(grid, GRID, &view);
        let shared = projected_quad_areas(&union, GRID, &view);
        println!(
            "{:<12} {:>8} {:>7.2} {:>7.2} {:>8} {:>7.2} {:>7.2}",
            spec.name,
            mine.len(),
            quantile(&mine, 0.5),
            quantile(&mine, 0.9),
            shared.len(),
            quantile(&shared, 0.5),
            quantile(&shared, 0.9)
        );
    }
    println!("CPU LOD: per view {per_view_ms:.1} ms for 6 plans (incl. zoom), union {union_ms:.1} ms for 1");
    Ok(())
}
