//! The terrain's compute path (issue 28, [`crate::terrain::visibility`])
//! against the hardware path it replaces, on the Jacksboro DEM under
//! validation and synchronization validation: the same views rendered by
//! both must agree to a mean FLIP of at most [`MAX_MEAN_FLIP`] and in view
//! depth to 1e-4 relative on at least [`MIN_DEPTH_AGREEMENT`] of the pixels
//! both cover (silhouettes may pick the other of two triangles), and cover
//! the same pixels but for [`MAX_COVERAGE_DIFFERENCE`] of them.

use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::terrain::visibility::RasterPath;
use crate::test_support::{assert_validation_clean, dump_pngs, jacksboro_field, mean_flip, validated_context};
use glam::DVec3;

const WIDTH: u32 = 192;
const HEIGHT: u32 = 108;
/// Mean FLIP of the compute path against the hardware path (issue 28's bound).
const MAX_MEAN_FLIP: f32 = 0.02;
/// Share of the pixels both paths cover whose view depths agree to 1e-4.
const MIN_DEPTH_AGREEMENT: f64 = 0.99;
/// Share of the pixels only one path covers.
const MAX_COVERAGE_DIFFERENCE: f64 = 0.002;

fn cameras(scene: &Scene) -> Vec<(&'static str, Camera)> {
    let base = scene.default_camera();
    vec![
        ("default", base),
        (
            "low-grazing",
            Camera {
                eye: DVec3::new(2000.0, 3000.0, 1150.0),
                target: DVec3::new(20000.0, 20000.0, 600.0),
                near: 10.0,
                ..base
            },
        ),
        (
            "near-ground",
            Camera {
                eye: DVec3::new(13600.0, 9600.0, 750.0),
                target: DVec3::new(18500.0, 21500.0, 350.0),
                near: 0.5,
                ..base
            },
        ),
    ]
}

fn render(scene: &Scene, cameras: &[(&str, Camera)], raster: RasterPath) -> Vec<FrameImages> {
    let (ctx, report) = validated_context();
    let frames = {
        let settings = RenderSettings {
            raster,
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        assert_eq!(renderer.raster_path(), raster);
        let frames = (cameras.iter())
            .map(|(_, c)| renderer.render(c).and_then(|f| renderer.read(&f)).expect("frame"))
            .collect();
        renderer.finish().expect("finish");
        frames
    };
    drop(ctx);
    assert_validation_clean(&report);
    frames
}

#[test]
fn compute_path_matches_the_hardware_path() {
    let scene = Scene::new(jacksboro_field());
    let cameras = cameras(&scene);
    let hardware = render(&scene, &cameras, RasterPath::Hardware);
    let compute = render(&scene, &cameras, RasterPath::Compute);
    for (((name, _), h), c) in cameras.iter().zip(&hardware).zip(&compute) {
        dump_pngs(
            &[(&format!("{name}-hardware"), &h.rgba8), (&format!("{name}-compute"), &c.rgba8)],
            WIDTH,
            HEIGHT,
        );
        let flip = mean_flip(&h.rgba8, &c.rgba8, WIDTH, HEIGHT).0;
        let (mut both, mut agree, mut one) = (0usize, 0usize, 0usize);
        for (&dh, &dc) in h.depth.iter().zip(&c.depth) {
            match (dh.is_finite(), dc.is_finite()) {
                (true, true) => {
                    both += 1;
                    agree += usize::from((dh - dc).abs() <= 1e-4 * dh.abs());
                }
                (false, false) => {}
                _ => one += 1,
            }
        }
        let pixels = h.depth.len() as f64;
        let agreement = agree as f64 / both.max(1) as f64;
        eprintln!(
            "{name}: mean FLIP {flip:.4}, depth agreement {agreement:.4} of {both} pixels, {one} covered by one path only"
        );
        assert!(both > 0, "{name}: no terrain");
        assert!(flip <= MAX_MEAN_FLIP, "{name}: mean FLIP {flip:.4}");
        assert!(agreement >= MIN_DEPTH_AGREEMENT, "{name}: depth agrees on {agreement:.4}");
        assert!(one as f64 / pixels <= MAX_COVERAGE_DIFFERENCE, "{name}: {one} pixels covered by one path");
    }
}
