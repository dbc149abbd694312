//! Warped against uniform geometry images in screen space (dissertation
//! §7.4, Fig. 7.9): the projected area of the output grid's quads in pixels
//! (median, 90th percentile, and their ratio) at the same vertex count,
//! for the default scene and the Jacksboro DEM. No GPU needed: the CPU
//! replica of warp-and-zoom (`alpenglow::bench`).
//!
//! `cargo run --release -p alpenglow-bench --bin quad_area`

use alpenglow::bench::{projected_quad_areas, zoom_positions, DebugScalar, LodFrame, View};
use alpenglow::tools::profile::quantile;
use alpenglow::{Camera, LodMode, LodSettings, Scene};
use alpenglow_bench::terrain::{jacksboro, low};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;
const SIDE: usize = 512;

fn main() -> alpenglow::Result<()> {
    let default = Scene::default_terrain()?;
    let dem = jacksboro()?;
    let views: Vec<(&str, &Scene, Camera)> = vec![
        ("default scene, default camera", &default, default.default_camera()),
        ("default scene, low and grazing", &default, low(&default)),
        ("DEM, default camera", &dem, dem.default_camera()),
        ("DEM, low and grazing", &dem, low(&dem)),
    ];
    println!("{SIDE}² vertices, {WIDTH}×{HEIGHT}: projected quad area in pixels (quads wholly in view)");
    for (name, scene, camera) in views {
        for mode in [LodMode::Uniform, LodMode::Warped] {
            let settings = LodSettings {
                mode,
                ..Default::default()
            };
            let mut frame = LodFrame::default();
            frame.plan(
                &scene.heights,
                &camera,
                f64::from(WIDTH) / f64::from(HEIGHT),
                &settings,
                DebugScalar::None,
            )?;
            let positions = zoom_positions(&scene.heights, &frame.warp.positions, settings.sketch_side, SIDE)?;
            let areas = projected_quad_areas(&positions, SIDE, &View::new(camera, WIDTH, HEIGHT));
            let (median, p90) = (quantile(&areas, 0.5), quantile(&areas, 0.9));
            println!(
                "  {name:<34} {:<8} quads in view {:>7}  median {median:>8.3}  p90 {p90:>8.3}  p90/median {:>6.1}",
                format!("{mode:?}"),
                areas.len(),
                p90 / median
            );
        }
    }
    Ok(())
}
