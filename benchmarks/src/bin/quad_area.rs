//! Warped against uniform geometry images in screen space (dissertation
//! §7.4, Fig. 7.9): the projected area of the output grid's quads in pixels
//! (median, 90th percentile, and their ratio) at the same vertex count,
//! for the default scene and the Jacksboro DEM. No GPU needed: the CPU
//! replica of warp-and-zoom (`alpenglow::bench`).
//!
//! `cargo run --release -p alpenglow-bench --bin quad_area`

use alpenglow::bench::{projected_quad_areas, zoom_positions, DebugScalar, LodFrame, View};
use alpenglow::files::load_heightmap;
use alpenglow::tools::profile::quantile;
use alpenglow::{Camera, HeightmapOptions, LodMode, LodSettings, Scene};
use glam::{DVec2, DVec3};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;
const SIDE: usize = 512;

fn main() -> alpenglow::Result<()> {
    let default = Scene::default_terrain()?;
    let dem = Scene::new(load_heightmap(
        &alpenglow_bench::repo_root().join("tests/data/jacksboro-fault.png"),
        &HeightmapOptions {
            scale: 1.0,
            offset: 0.0,
            spacing: Some(DVec2::new(74.4, 92.6)),
            ..Default::default()
        },
    )?);
    let views: Vec<(&str, &Scene, Camera)> = vec![
        ("default scene, default camera", &default, default.default_camera()),
        (
            "default scene, low and grazing",
            &default,
            alpenglow_views::low(&default),
        ),
        ("DEM, default camera", &dem, dem.default_camera()),
        ("DEM, low and grazing", &dem, alpenglow_views::low(&dem)),
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

mod alpenglow_views {
    use super::*;

    /// Low over the southern part of the terrain, looking north just below the horizon.
    pub fn low(scene: &Scene) -> Camera {
        let e = scene.heights.extent();
        let (lo, hi) = scene.height_range();
        let eye = DVec3::new(
            e.x * 0.5,
            e.y * 0.15,
            f64::from(hi) + 0.02 * f64::from(hi - lo).max(10.0),
        );
        Camera {
            eye,
            target: eye + DVec3::new(0.0, 1000.0, -60.0),
            ..scene.default_camera()
        }
    }
}
