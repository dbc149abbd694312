//! The three panels of Fig. 7.14 (dissertation §7.4.3, "Procedural
//! Detail"): the height field alone (`detail: false`), the procedural
//! detail in the geometry only (`detail_shading: false`: the octaves the
//! mesh holds displace it, none bump-map the normal) and the detail in
//! geometry and lighting (the default). Expected, on both raster paths:
//! the centre and right panels share their geometry (the depth agrees
//! pixel for pixel: bump mapping changes shading only), the left one
//! differs from them in depth; and the fine-scale shading grows from left
//! to right (mean absolute Laplacian of the luminance over the terrain:
//! displacement adds the mesh's octaves to the normal, bump mapping the
//! octaves down to the pixel). Validation and synchronization validation
//! are on throughout. `ALPENGLOW_DUMP=DIR` writes the three panels
//! (192×108, `super::terrain::render`).

use glam::{DVec2, DVec3};

use crate::renderer::{Camera, FrameImages, Scene};
use crate::surface::bspline::sample_bspline;
use crate::terrain::geometry_image::TerrainSettings;
use crate::test_support::{dump_pngs, jacksboro_field, RASTER_PATHS};
use crate::RasterPath;

/// Fraction of the terrain pixels whose depth moves by more than 0.5 %
/// when the detail goes into the geometry, at least.
const MOVED_AT_LEAST: f64 = 0.2;

fn render(scene: &Scene, camera: &Camera, terrain: TerrainSettings, raster: RasterPath) -> FrameImages {
    super::terrain::render(scene, std::slice::from_ref(camera), (terrain, raster))
        .pop()
        .expect("one frame")
}

/// Mean absolute 4-neighbour Laplacian of the luminance (0..1) over
/// pixels whose neighbourhood is all terrain.
fn fine_shading(frame: &FrameImages) -> f64 {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let lum = |i: usize| {
        let p = &frame.rgba8[4 * i..4 * i + 3];
        (0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])) / 255.0
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            let around = [i - 1, i + 1, i - w, i + w];
            if !frame.depth[i].is_finite() || around.iter().any(|&j| !frame.depth[j].is_finite()) {
                continue;
            }
            let lap: f64 = around.iter().map(|&j| lum(j)).sum::<f64>() - 4.0 * lum(i);
            sum += lap.abs();
            n += 1;
        }
    }
    assert!(n > w * h / 4, "too little terrain in view ({n} pixels)");
    sum / n as f64
}

/// A low view up a slope of the Jacksboro DEM (30 m samples: the detail
/// amplitude is 4.5 m), the ground 150 m to 3 km ahead.
fn camera(scene: &Scene) -> Camera {
    let ground = |p: DVec2| sample_bspline(&scene.heights, p.x, p.y);
    let eye = DVec2::new(13600.0, 9600.0);
    let target = DVec2::new(14200.0, 10400.0);
    Camera {
        eye: eye.extend(ground(eye) + 60.0),
        target: target.extend(ground(target)),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 1.0,
        far: 30000.0,
    }
}

#[test]
fn detail_in_geometry_moves_depth_and_bump_mapping_only_shading() {
    let scene = Scene::new(jacksboro_field());
    let camera = camera(&scene);
    let none = TerrainSettings {
        detail: false,
        ..Default::default()
    };
    let geometry = TerrainSettings {
        detail_shading: false,
        ..Default::default()
    };
    for raster in RASTER_PATHS {
        let panels = [none, geometry, TerrainSettings::default()].map(|t| render(&scene, &camera, t, raster));
        let [left, centre, right] = &panels;
        dump_pngs(
            &[
                ("fig-7-14-original", &left.rgba8),
                ("fig-7-14-geometry", &centre.rgba8),
                ("fig-7-14-geometry-lighting", &right.rgba8),
            ],
            left.width,
            left.height,
        );
        let (mut terrain, mut same, mut moved) = (0usize, 0usize, 0usize);
        for i in 0..left.depth.len() {
            let (l, c, r) = (left.depth[i], centre.depth[i], right.depth[i]);
            if !(l.is_finite() || c.is_finite()) {
                continue;
            }
            terrain += 1;
            if c == r || (c.is_finite() && r.is_finite() && ((c - r) / c).abs() < 1e-5) {
                same += 1;
            }
            if !(l.is_finite() && c.is_finite()) || ((l - c) / c).abs() > 0.005 {
                moved += 1;
            }
        }
        let roughness = panels.each_ref().map(fine_shading);
        let moved_fraction = moved as f64 / terrain as f64;
        println!(
            "{raster:?}: {terrain} terrain pixels; centre = right depth at {same}; depth moved by the detail at {:.1} %; fine shading left {:.4}, centre {:.4}, right {:.4}",
            100.0 * moved_fraction,
            roughness[0],
            roughness[1],
            roughness[2]
        );
        assert_eq!(same, terrain, "{raster:?}: bump mapping changed the geometry");
        assert!(
            moved_fraction >= MOVED_AT_LEAST,
            "{raster:?}: the detail moved only {:.1} % of the depth",
            100.0 * moved_fraction
        );
        assert!(
            roughness[0] < roughness[1] && roughness[1] < roughness[2],
            "{raster:?}: fine shading not growing left to right: {roughness:?}"
        );
    }
}
