//! Terrains and views shared by the terrain LOD programs (`quad_area`,
//! `swimming`).

use alpenglow::files::load_heightmap;
use alpenglow::{Camera, HeightmapOptions, Scene};
use glam::{DVec2, DVec3};

/// The Jacksboro DEM of the tests (`tests/data/jacksboro-fault.png`,
/// 74.4 m × 92.6 m spacing).
pub fn jacksboro() -> alpenglow::Result<Scene> {
    Ok(Scene::new(load_heightmap(
        &crate::repo_root().join("tests/data/jacksboro-fault.png"),
        &HeightmapOptions {
            scale: 1.0,
            offset: 0.0,
            spacing: Some(DVec2::new(74.4, 92.6)),
            ..Default::default()
        },
    )?))
}

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
