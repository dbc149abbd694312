//! Reversed depth (issue 28): a driver's eye 2 m above flat ground looking
//! at ridges 20–130 km away, with a near plane of 0.1 m and a far plane of
//! 100 km (a far/near ratio of 10⁶). A forward depth buffer (near 0,
//! far 1) keeps about 2⁻²⁴ of relative precision near 1, so at 50 km it
//! cannot tell apart surfaces a few per cent apart in depth and the ridges
//! lose their order; reversed depth (near 1, far 0) in a float buffer keeps
//! the float's relative precision at every distance. In both raster paths
//! the rendered view depth must match the CPU ray cast of the B-spline
//! surface ([`crate::terrain::raycast`], without procedural detail) on the
//! ridges about 50 km away, and agree with the render of a near plane of
//! 50 m on the distant ground as a whole (a near plane of 0.01 m too); an
//! infinite far plane renders the ridges beyond 100 km as well.

use super::compute_raster::render_with;
use super::terrain::raycast_depth_of;
use crate::io::heightmap::HeightField;
use crate::renderer::{Camera, FrameImages, RenderSettings, Scene};
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::visibility::RasterPath;
use crate::test_support::dump_pngs;
use glam::{DVec2, DVec3};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 128;
/// Pixels whose ray cast depth lies in this range (m) are the distant
/// ground, compared with the render of a near plane of 50 m.
const DISTANT: (f32, f32) = (20_000.0, 100_000.0);
/// Pixels whose ray cast depth lies in this range (m) are compared with the
/// ray cast (farther, the LOD's grid is too coarse for the narrow ridges).
const AROUND_50_KM: (f32, f32) = (30_000.0, 70_000.0);
/// Relative depth error above which a pixel counts as off the ray cast.
const MAX_RELATIVE_ERROR: f32 = 0.03;
/// Share of the pixels allowed off the ray cast (the mesh and the exact
/// surface may differ on the ridges' steep flanks).
const MAX_OFF_RAY_CAST: f64 = 0.02;
/// Share of the distant pixels allowed to differ from the near-50 render
/// by more than 1 % in depth.
const MAX_OFF_NEAR_50: f64 = 0.005;

/// Spacing (m) of the ridge field's samples.
const SPACING: f64 = 250.0;

/// Ridges across the view direction (+x), each higher than the one before
/// it as seen from the eye, so every one shows over its predecessor, and
/// pairs of them close together in depth; rolling along y.
fn ridges() -> HeightField {
    // (distance in km, height in m)
    const RIDGES: [(f64, f64); 10] = [
        (20.0, 450.0),
        (24.0, 600.0),
        (33.0, 950.0),
        (38.0, 1150.0),
        (50.0, 1700.0),
        (56.0, 2000.0),
        (70.0, 2700.0),
        (78.0, 3100.0),
        (95.0, 3900.0),
        (130.0, 5600.0),
    ];
    HeightField::from_fn(640, 120, DVec2::splat(SPACING), |c, r| {
        let (x, y) = (f64::from(c) * SPACING, f64::from(r) * SPACING);
        let h: f64 = (RIDGES.iter().enumerate())
            .map(|(k, &(km, height))| {
                let along = 1.0 + 0.15 * (y / 4000.0 + k as f64).sin();
                let u = (x - km * 1000.0) / 1500.0;
                height * along * (-0.5 * u * u).exp()
            })
            .fold(0.0, f64::max);
        h as f32
    })
}

/// The driver's eye at the field's west edge, 2 m up, looking east a
/// degree and a half above the horizon.
fn camera(near: f64, far: f64) -> Camera {
    let eye = DVec3::new(500.0, 15_000.0, 2.0);
    Camera {
        eye,
        target: eye + DVec3::new(100_000.0, 0.0, 2600.0),
        up: DVec3::Z,
        fov_y_deg: 6.0,
        near,
        far,
    }
}

fn render(scene: &Scene, cameras: &[Camera], raster: RasterPath) -> Vec<FrameImages> {
    let settings = RenderSettings {
        raster,
        terrain: TerrainSettings {
            detail: false,
            ..Default::default()
        },
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    let frames: Vec<Vec<Camera>> = cameras.iter().map(|&c| vec![c]).collect();
    render_with(scene, &frames, settings)
}

/// View depth as grey levels for the dumps: log scale from 1 m (black) to
/// 100 km (white); sky blue.
fn depth_image(depth: &[f32]) -> Vec<u8> {
    depth
        .iter()
        .flat_map(|&d| match d.is_finite() {
            true => {
                let v = (255.0 * d.max(1.0).log10() / 5.0).clamp(0.0, 255.0) as u8;
                [v, v, v, 255]
            }
            false => [90, 140, 230, 255],
        })
        .collect()
}

/// Whether pixel `k`'s ray cast depth is well conditioned: it and its four
/// neighbours hit, within 5 % of one another (not a silhouette, nor ground
/// so grazing that a centimetre of height moves the hit by kilometres).
fn conditioned(cpu: &[f32], k: usize) -> bool {
    let (w, h) = (WIDTH as usize, HEIGHT as usize);
    let (x, y) = (k % w, k / w);
    if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
        return false;
    }
    let c = cpu[k];
    [k - 1, k + 1, k - w, k + w]
        .iter()
        .all(|&n| ((cpu[n] - c) / c).abs() <= 0.05)
}

/// Whether `depth` is off `reference` by more than `tolerance`, relative
/// (a miss where the reference hits is off, two misses agree).
fn off(depth: f32, reference: f32, tolerance: f32) -> bool {
    let relative = ((depth - reference) / reference).abs();
    (depth.is_finite() || reference.is_finite()) && (relative.is_nan() || relative > tolerance)
}

/// Of the well-conditioned pixels about 50 km away (by the ray cast
/// `cpu`): the share whose depth in `frame` is off by more than
/// [`MAX_RELATIVE_ERROR`], and their count.
fn wrong_share(frame: &FrameImages, cpu: &[f32]) -> (f64, usize) {
    let (mut distant, mut wrong) = (0usize, 0usize);
    for (k, (&g, &c)) in frame.depth.iter().zip(cpu).enumerate() {
        if (AROUND_50_KM.0..=AROUND_50_KM.1).contains(&c) && conditioned(cpu, k) {
            distant += 1;
            wrong += usize::from(off(g, c, MAX_RELATIVE_ERROR));
        }
    }
    (wrong as f64 / distant.max(1) as f64, distant)
}

/// Of the distant pixels: the share where `frame` and `reference` (the
/// same view with a far near plane) disagree in depth by more than 1 %.
fn disagreement(frame: &FrameImages, reference: &FrameImages, cpu: &[f32]) -> f64 {
    let (mut distant, mut differ) = (0usize, 0usize);
    for ((&g, &r), &c) in frame.depth.iter().zip(&reference.depth).zip(cpu) {
        if (DISTANT.0..=DISTANT.1).contains(&c) {
            distant += 1;
            differ += usize::from(off(g, r, 0.01));
        }
    }
    differ as f64 / distant.max(1) as f64
}

fn distant_ridges_keep_their_order(raster: RasterPath) {
    let scene = Scene::new(ridges());
    let cameras = [
        camera(0.1, 100_000.0),
        camera(50.0, 100_000.0),
        camera(0.01, 100_000.0),
        camera(0.1, f64::INFINITY),
    ];
    let frames = render(&scene, &cameras, raster);
    let cpu = raycast_depth_of(&scene, &cameras[0], (WIDTH, HEIGHT));
    dump_pngs(&[("ridges-ray-cast-depth", &depth_image(&cpu))], WIDTH, HEIGHT);
    let names = ["near 0.1", "near 50", "near 0.01", "near 0.1, infinite far"];
    for (name, frame) in names.iter().zip(&frames) {
        let prefix = format!("ridges-{}-{name}", raster.name());
        dump_pngs(
            &[
                (&prefix, &frame.rgba8),
                (&format!("{prefix}-depth"), &depth_image(&frame.depth)),
            ],
            WIDTH,
            HEIGHT,
        );
        let (wrong, distant) = wrong_share(frame, &cpu);
        let differ = disagreement(frame, &frames[1], &cpu);
        eprintln!(
            "{} path, {name}: {wrong:.4} of {distant} pixels at 30-70 km off the ray cast, {differ:.4} off near 50",
            raster.name()
        );
        assert!(
            distant > (WIDTH * HEIGHT / 10) as usize,
            "{name}: only {distant} pixels at 30-70 km"
        );
        if name.contains("infinite") {
            // The ridges beyond 100 km show too; the LOD spreads the grid
            // over the whole terrain, coarser at 50 km than for a far plane
            // of 100 km.
            let beyond = frame.depth.iter().filter(|&&d| d.is_finite() && d > 100_000.0).count();
            assert!(
                beyond > (WIDTH * HEIGHT / 100) as usize,
                "{name}: {beyond} pixels beyond 100 km"
            );
            assert!(
                wrong <= 0.1,
                "{} path, {name}: {wrong:.4} off the ray cast",
                raster.name()
            );
            continue;
        }
        assert!(
            wrong <= MAX_OFF_RAY_CAST,
            "{} path, {name}: {wrong:.4} off the ray cast",
            raster.name()
        );
        assert!(
            differ <= MAX_OFF_NEAR_50,
            "{} path, {name}: {differ:.4} off near 50",
            raster.name()
        );
    }
}

#[test]
fn distant_ridges_keep_their_order_in_the_hardware_path() {
    distant_ridges_keep_their_order(RasterPath::Hardware);
}

#[test]
fn distant_ridges_keep_their_order_in_the_compute_path() {
    distant_ridges_keep_their_order(RasterPath::Compute);
}
