//! Swimming of the terrain mesh along slow camera paths (dissertation
//! §7.4.3, §7.4.5): the per-pixel change of depth and colour that the
//! mesh's change alone causes between consecutive frames, for the warped
//! grid, the uniform grid of the same vertex count and a world-static mesh
//! (a vertex at every height-field sample: like the ray-cast reference, 0
//! by construction), on the default procedural terrain and the Jacksboro
//! DEM, forward and sideways; and the renderer's world-anchored plan
//! (`LodSettings::snap`, `--lod-snap`, the §7.4.3/§7.4.5 remedy) against the
//! plain per-frame warp. Besides the mean per-frame change it prints the
//! worst single pair (the pop of a replan), and per path the eye's height
//! above the ground and the snap grids the height-adaptive plan used. The metric is defined in
//! `src/terrain/swimming.rs` (`alpenglow::bench::measure_swimming`). No
//! GPU needed.
//!
//! `cargo run --release -p alpenglow-bench --bin swimming [-- OPTIONS]`:
//! `--frames K` (default 96: several replans at the default snap),
//! `--size WxH` (default 320x180), `--snap A,B,…` (snaps of the anchored
//! rows, in whole-terrain sketch texels; default 1, `--lod-snap 1`),
//! `--warped-only` (leave out the uniform and world-static rows).

use alpenglow::bench::{camera_path, measure_swimming, Anchor, DebugScalar, LodFrame, Mesh, Swimming};
use alpenglow::{Camera, HeightField, LodMode, LodSettings, Scene};
use alpenglow_bench::terrain::{jacksboro, low};
use glam::{DVec2, DVec3};

/// Output grid side (the renderer's default).
const SIDE: usize = 512;
/// Camera step per frame, in height-field spacings.
const STEP: f64 = 0.25;

/// How a frame's mesh is made.
#[derive(Clone, Copy, Debug)]
enum Planner {
    /// The per-frame LOD of the renderer in this mode with this snap.
    Lod(LodMode, f64),
    /// One vertex per height-field sample, the same every frame.
    WorldStatic,
}

/// The command line's options.
struct Options {
    frames: usize,
    size: (u32, u32),
    snaps: Vec<f64>,
    warped_only: bool,
}

fn options() -> alpenglow::Result<Options> {
    let bad = |what: &str, v: &str| alpenglow::Error::invalid(what, format!("{v:?}"));
    let mut o = Options {
        frames: 96,
        size: (320, 180),
        snaps: vec![alpenglow::ANCHORED_LOD_SNAP],
        warped_only: false,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut k = 0;
    while k < args.len() {
        let value = args.get(k + 1).map_or("", String::as_str);
        match args[k].as_str() {
            "--frames" => o.frames = value.parse().map_err(|_| bad("--frames", value))?,
            "--size" => {
                let (w, h) = value.split_once('x').ok_or_else(|| bad("--size", value))?;
                o.size = (
                    w.parse().map_err(|_| bad("--size", value))?,
                    h.parse().map_err(|_| bad("--size", value))?,
                );
            }
            "--snap" => {
                o.snaps = (value.split(','))
                    .map(|v| v.parse().map_err(|_| bad("--snap", value)))
                    .collect::<alpenglow::Result<_>>()?;
            }
            "--warped-only" => {
                o.warped_only = true;
                k += 1;
                continue;
            }
            other => return Err(bad("swimming option", other)),
        }
        k += 2;
    }
    Ok(o)
}

fn run(field: &HeightField, cameras: &[Camera], size: (u32, u32), planner: Planner) -> alpenglow::Result<Swimming> {
    let aspect = f64::from(size.0) / f64::from(size.1);
    let mut frame = LodFrame::default();
    let mut fixed: Option<Mesh> = None;
    measure_swimming(field, cameras, size, |_, camera| match planner {
        Planner::Lod(mode, snap) => {
            let settings = LodSettings {
                mode,
                snap,
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
    let o = options()?;
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
    let (frames, (width, height)) = (o.frames, o.size);
    println!(
        "{frames} frames, {width}×{height}, {SIDE}² vertices, steps of {STEP} height-field spacing per frame\n\
         depth: mean relative depth change ×1e3 (worst pair); colour: mean |Δ luminance| in 8-bit levels \
         (worst pair); error: mean relative depth error against the ray cast ×1e3"
    );
    let mut planners = Vec::new();
    if !o.warped_only {
        planners.push(("uniform".to_string(), Planner::Lod(LodMode::Uniform, 0.0)));
    }
    planners.push(("warped".to_string(), Planner::Lod(LodMode::Warped, 0.0)));
    for &snap in &o.snaps {
        planners.push((format!("anchored, snap {snap}"), Planner::Lod(LodMode::Warped, snap)));
    }
    if !o.warped_only {
        planners.push(("world-static mesh".to_string(), Planner::WorldStatic));
    }
    for (name, scene, start) in starts {
        let d0 = scene.heights.spacing.min_element();
        for (path, step) in [
            ("forward", DVec2::new(STEP * d0, 0.0)),
            ("sideways", DVec2::new(0.0, STEP * d0)),
        ] {
            let cameras = camera_path(start, step, frames);
            // The eye's height above the ground along the path and the snap grids it gets.
            let heights = cameras
                .iter()
                .map(|c| c.eye.z - alpenglow::bench::sample_bspline(&scene.heights, c.eye.x, c.eye.y));
            let (low, high) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), h| (a.min(h), b.max(h)));
            for &snap in &o.snaps {
                let settings = LodSettings {
                    snap,
                    ..Default::default()
                };
                let mut grids: Vec<f64> = Vec::new();
                let mut level = None;
                for c in &cameras {
                    let anchor: Anchor = settings.anchor(&scene.heights, c, level)?;
                    level = anchor.level;
                    if !grids.contains(&anchor.spacing) {
                        grids.push(anchor.spacing);
                    }
                }
                println!(
                    "  {name} {path}: eye {low:.0}–{high:.0} m above the ground; snap {snap}: grids {:?} m",
                    grids.iter().map(|g| format!("{g:.2}")).collect::<Vec<_>>()
                );
            }
            for (label, planner) in &planners {
                let s = run(&scene.heights, &cameras, (width, height), *planner)?;
                println!(
                    "  {name:<22} {path:<9} {label:<20} depth {:>6.3} ({:>6.3})  colour {:>6.3} ({:>6.3})  error {:>6.3}  ({} pixels)",
                    1e3 * s.depth,
                    1e3 * s.worst_depth,
                    255.0 * s.colour,
                    255.0 * s.worst_colour,
                    1e3 * s.error,
                    s.pixels
                );
            }
        }
    }
    Ok(())
}
