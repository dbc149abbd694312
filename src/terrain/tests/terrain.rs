//! The warped terrain against the height field it came from (dissertation
//! §7.4; issue 3): with procedural detail off, the rendered depth must agree
//! with a CPU ray cast of the same surface (the sketch atlas's cubic
//! B-spline, [`crate::terrain::raycast`]) for at least 95 % of the
//! pixels within 2 % relative depth, and the mesh must have no cracks or
//! holes, at the geometry image's borders included: no pixel where the ray
//! cast hits the terrain may show sky. Also: the warped mesh is far more
//! uniform in screen space than a uniform one of the same vertex count.
//! Validation and synchronization validation are on throughout.

use crate::profile::quantile;
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::lod::{DebugScalar, LodFrame, LodMode, LodSettings};
use crate::terrain::raycast::Raycaster;
use crate::terrain::zoom::{projected_quad_areas, zoom_positions};
use crate::test_support::{assert_validation_clean, jacksboro_field, validated_context};
use crate::view::View;
use crate::RasterPath;
use glam::DVec3;

const WIDTH: u32 = 192;
const HEIGHT: u32 = 108;

/// The terrain tests' views of the Jacksboro DEM (shared with the compute
/// path's tests).
pub(super) fn views(scene: &Scene) -> Vec<(&'static str, Camera)> {
    let base = scene.default_camera();
    vec![
        ("high oblique", base),
        (
            "low grazing",
            Camera {
                eye: DVec3::new(2000.0, 3000.0, 1150.0),
                target: DVec3::new(20000.0, 20000.0, 600.0),
                near: 10.0,
                ..base
            },
        ),
        (
            "along the valley",
            Camera {
                eye: DVec3::new(13600.0, 9600.0, 750.0),
                target: DVec3::new(18500.0, 21500.0, 350.0),
                near: 5.0,
                ..base
            },
        ),
        (
            "inside, looking down at a corner",
            Camera {
                eye: DVec3::new(3000.0, 3000.0, 9000.0),
                target: DVec3::new(0.0, 0.0, 300.0),
                ..base
            },
        ),
    ]
}

/// The frames of `cameras` at 192×108 under validation (also Fig. 7.14's panels).
pub(super) fn render(
    scene: &Scene,
    cameras: &[Camera],
    (terrain, raster): (TerrainSettings, RasterPath),
) -> Vec<FrameImages> {
    let (ctx, report) = validated_context();
    let frames = {
        let settings = RenderSettings {
            terrain,
            raster,
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        let frames = cameras
            .iter()
            .map(|c| renderer.render(c).and_then(|f| renderer.read(&f)).expect("frame"))
            .collect();
        renderer.finish().expect("finish");
        frames
    };
    drop(ctx);
    assert_validation_clean(&report);
    frames
}

/// CPU depth per pixel (along the forward axis; +inf on a miss).
fn raycast_depth(scene: &Scene, camera: &Camera) -> Vec<f32> {
    raycast_depth_of(scene, camera, (WIDTH, HEIGHT))
}

/// CPU depth per pixel of a `width`×`height` image (along the forward
/// axis; +inf on a miss or beyond the far plane).
pub(super) fn raycast_depth_of(scene: &Scene, camera: &Camera, (width, height): (u32, u32)) -> Vec<f32> {
    let caster = Raycaster::new(&scene.heights).expect("ray caster");
    let aspect = f64::from(width) / f64::from(height);
    let tan_y = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let (right, up, forward) = (
        camera.right() * tan_y * aspect,
        camera.image_up() * tan_y,
        camera.forward(),
    );
    let mut out = Vec::with_capacity((width * height) as usize);
    for j in 0..height {
        for i in 0..width {
            let sx = 2.0 * (f64::from(i) + 0.5) / f64::from(width) - 1.0;
            let sy = 1.0 - 2.0 * (f64::from(j) + 0.5) / f64::from(height);
            // forward·dir = 1, so t is the view depth.
            let dir = forward + sx * right + sy * up;
            let t = caster
                .raycast(camera.eye, dir, camera.far)
                .filter(|&t| t >= camera.near);
            out.push(t.map_or(f32::INFINITY, |t| t as f32));
        }
    }
    out
}

#[test]
fn depth_matches_cpu_ray_cast_without_detail_and_has_no_holes() {
    for raster in crate::test_support::RASTER_PATHS {
        depth_matches_cpu_ray_cast_without_detail_and_has_no_holes_in(raster);
    }
}

fn depth_matches_cpu_ray_cast_without_detail_and_has_no_holes_in(raster: RasterPath) {
    let scene = Scene::new(jacksboro_field());
    let views = views(&scene);
    let cameras: Vec<Camera> = views.iter().map(|v| v.1).collect();
    let terrain = TerrainSettings {
        detail: false,
        ..Default::default()
    };
    let frames = render(&scene, &cameras, (terrain, raster));
    for ((name, camera), frame) in views.iter().zip(&frames) {
        let cpu = raycast_depth(&scene, camera);
        let (mut considered, mut agree, mut holes, mut extra) = (0usize, 0usize, 0usize, 0usize);
        for (&g, &c) in frame.depth.iter().zip(&cpu) {
            if !g.is_finite() && !c.is_finite() {
                continue;
            }
            considered += 1;
            if g.is_finite() && c.is_finite() {
                if ((g - c) / c).abs() <= 0.02 {
                    agree += 1;
                }
            } else if c.is_finite() {
                holes += 1;
            } else {
                extra += 1;
            }
        }
        let fraction = agree as f64 / considered.max(1) as f64;
        println!(
            "{name}: {considered} terrain pixels, {:.2} % within 2 % depth, {holes} holes (ray hits, mesh shows sky), {extra} mesh-only",
            100.0 * fraction
        );
        assert!(
            considered > (WIDTH * HEIGHT / 8) as usize,
            "{name}: the view shows too little terrain"
        );
        assert!(
            fraction >= 0.95,
            "{name}: only {:.2} % of pixels within 2 %",
            100.0 * fraction
        );
        // Silhouette pixels may round either way; a crack would be a run of them.
        let allowed = considered / 500;
        assert!(
            holes <= allowed,
            "{name}: {holes} pixels show sky where the terrain is (allowed {allowed})"
        );
    }
}

/// With detail on, the surface moves by at most the detail amplitude, so
/// the coverage must stay the same: no holes at the borders either.
#[test]
fn detail_keeps_the_mesh_closed() {
    for raster in crate::test_support::RASTER_PATHS {
        detail_keeps_the_mesh_closed_in(raster);
    }
}

fn detail_keeps_the_mesh_closed_in(raster: RasterPath) {
    let scene = Scene::new(jacksboro_field());
    let cameras: Vec<Camera> = views(&scene).iter().map(|v| v.1).collect();
    let frames = render(&scene, &cameras, (TerrainSettings::default(), raster));
    for (camera, frame) in cameras.iter().zip(&frames) {
        let cpu = raycast_depth(&scene, camera);
        let holes = frame
            .depth
            .iter()
            .zip(&cpu)
            .filter(|(g, c)| !g.is_finite() && c.is_finite())
            .count();
        let terrain = cpu.iter().filter(|c| c.is_finite()).count();
        assert!(
            holes <= terrain / 500,
            "{holes} sky pixels over {terrain} terrain pixels"
        );
    }
}

/// Fig. 7.9's point: at the same vertex count, the warped mesh's quads are
/// far more uniform in projected area than a regular grid's over the same
/// sketch map. Measured on the CPU replica of warp-and-zoom (which the depth
/// test above ties to the GPU): the 90th percentile over the median.
#[test]
fn warped_quads_are_more_uniform_on_screen_than_uniform_ones() {
    let scene = Scene::new(jacksboro_field());
    for (name, camera) in views(&scene).into_iter().take(3) {
        let spread = |mode: LodMode| {
            let settings = LodSettings {
                mode,
                ..Default::default()
            };
            let mut frame = LodFrame::default();
            let aspect = 16.0 / 9.0;
            frame
                .plan(&scene.heights, &camera, aspect, &settings, DebugScalar::None)
                .expect("plan");
            let p = zoom_positions(&scene.heights, &frame.warp.positions, settings.sketch_side, 256).expect("zoom");
            let areas = projected_quad_areas(&p, 256, &View::new(camera, 1280, 720));
            quantile(&areas, 0.9) / quantile(&areas, 0.5)
        };
        let (uniform, warped) = (spread(LodMode::Uniform), spread(LodMode::Warped));
        println!("{name}: p90/median of projected quad area: uniform {uniform:.2}, warped {warped:.2}");
        assert!(
            warped < 0.7 * uniform,
            "{name}: warped {warped:.2} vs uniform {uniform:.2}"
        );
    }
}
