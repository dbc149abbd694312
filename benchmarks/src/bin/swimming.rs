//! Swimming of the terrain mesh along slow camera paths (dissertation
//! §7.4.3, §7.4.5): the per-pixel change of depth and colour that the
//! mesh's change alone causes between consecutive frames, for the warped
//! grid, the uniform grid of the same vertex count and a world-static mesh
//! (a vertex at every height-field sample: like the ray-cast reference, 0
//! by construction), on the default procedural terrain and the Jacksboro
//! DEM, forward and sideways. The metric is defined in
//! `src/terrain/swimming.rs` (`alpenglow::bench::measure_swimming`). No GPU
//! needed; about three minutes on two cores.
//!
//! `cargo run --release -p alpenglow-bench --bin swimming`

use alpenglow::bench::{camera_path, measure_swimming, DebugScalar, LodFrame, Mesh, Swimming};
use alpenglow::{Camera, HeightField, LodMode, LodSettings, Scene};
use alpenglow_bench::terrain::{jacksboro, low};
use glam::{DVec2, DVec3};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
/// Output grid side (the renderer's default).
const SIDE: usize = 512;
const FRAMES: usize = 24;
/// Camera step per frame, in height-field spacings.
const STEP: f64 = 0.25;

/// How a frame's mesh is made.
#[derive(Clone, Copy, Debug)]
enum Planner {
    /// The per-frame LOD of the renderer in this mode.
    Lod(LodMode),
    /// One vertex per height-field sample, the same every frame.
    WorldStatic,
}

fn run(field: &HeightField, cameras: &[Camera], planner: Planner) -> alpenglow::Result<Swimming> {
    let aspect = f64::from(WIDTH) / f64::from(HEIGHT);
    let mut frame = LodFrame::default();
    let mut fixed: Option<Mesh> = None;
    measure_swimming(field, cameras, (WIDTH, HEIGHT), |_, camera| match planner {
        Planner::Lod(mode) => {
            let settings = LodSettings {
                mode,
                ..Default::default()
            };
            frame.plan(field, camera, aspect, &settings, DebugScalar::None)?;
            Mesh::from_warp(field, &frame.warp.positions, settings.sketch_side, SIDE)
        }
        Planner::WorldStatic => {
            if fixed.is_none() {
                // Square: the larger sample count on both axes, over the extent.
                let side = field.columns.max(field.rows) as usize;
                let e = field.extent();
                let grid: Vec<DVec3> = (0..side * side)
                    .map(|k| (DVec2::new((k % side) as f64, (k / side) as f64) / (side - 1) as f64 * e).extend(0.0))
                    .collect();
                fixed = Some(Mesh::from_warp(field, &grid, side, side)?);
            }
            Ok(fixed.clone().expect("built above"))
        }
    })
}

fn main() -> alpenglow::Result<()> {
    let default = Scene::default_terrain()?;
    let dem = jacksboro()?;
    // Along the valley of the fault (the terrain tests' view).
    let valley = Camera {
        eye: DVec3::new(13600.0, 9600.0, 750.0),
        target: DVec3::new(18500.0, 21500.0, 350.0),
        near: 5.0,
        ..dem.default_camera()
    };
    let starts: [(&str, &Scene, Camera); 2] = [
        ("default terrain, low", &default, low(&default)),
        ("Jacksboro DEM, valley", &dem, valley),
    ];
    println!(
        "{FRAMES} frames, {WIDTH}×{HEIGHT}, {SIDE}² vertices, steps of {STEP} height-field spacing per frame\n\
         depth: mean relative depth change ×1e3; colour: mean |Δ luminance| in 8-bit levels; \
         error: mean relative depth error against the ray cast ×1e3"
    );
    for (name, scene, start) in starts {
        let d0 = scene.heights.spacing.min_element();
        for (path, step) in [
            ("forward", DVec2::new(STEP * d0, 0.0)),
            ("sideways", DVec2::new(0.0, STEP * d0)),
        ] {
            let cameras = camera_path(start, step, FRAMES);
            for (label, planner) in [
                ("uniform", Planner::Lod(LodMode::Uniform)),
                ("warped", Planner::Lod(LodMode::Warped)),
                ("world-static mesh", Planner::WorldStatic),
            ] {
                let s = run(&scene.heights, &cameras, planner)?;
                println!(
                    "  {name:<22} {path:<9} {label:<18} depth {:>6.3}  colour {:>6.3}  error {:>6.3}  ({} pixels)",
                    1e3 * s.depth,
                    255.0 * s.colour,
                    1e3 * s.error,
                    s.pixels
                );
            }
        }
    }
    Ok(())
}
