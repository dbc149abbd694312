//! Outdoor lighting end to end (§6.3, §9) under validation and
//! synchronization validation: the sky against Preetham's published
//! formulas, aerial perspective against its CPU twin, the lighting AOVs.

mod common;

use alpenglow::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use alpenglow::terrain::procedural::ProceduralTerrain;
use alpenglow::texturing::gpu_layout::TexturingMode;
use alpenglow::view::{Lighting, SkyModel, SunPosition};
use alpenglow::vulkan::Context;
use common::{assert_validation_clean, validated_context};
use glam::{DVec2, DVec3};

fn small_scene() -> Scene {
    let field = ProceduralTerrain::default()
        .try_generate(65, 65, DVec2::new(40.0, 40.0))
        .expect("procedural terrain");
    Scene::new(field)
}

/// One frame of `camera` under `lighting` at `w`×`h`.
fn render(ctx: &Context, scene: &Scene, camera: &Camera, lighting: Lighting, (w, h): (u32, u32)) -> FrameImages {
    let settings = RenderSettings {
        texturing: TexturingMode::Classic,
        lighting: Some(lighting),
        ..RenderSettings::new(w, h)
    };
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let frame = renderer.render(camera).expect("frame");
    let images = renderer.read(&frame).expect("readback");
    renderer.finish().expect("finish");
    images
}

/// Preetham et al. 1999, zenith luminance (cd/m²) and chromaticity, written
/// out here independently of the library.
fn preetham_zenith(turbidity: f64, sun_zenith: f64) -> (f64, f64, f64) {
    let t = turbidity;
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f64::consts::PI - 2.0 * sun_zenith);
    let y = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192) * 1000.0;
    let th = [sun_zenith.powi(3), sun_zenith.powi(2), sun_zenith, 1.0];
    let poly = |m: [[f64; 4]; 3]| -> f64 {
        let tt = [t * t, t, 1.0];
        (0..3)
            .map(|i| tt[i] * (0..4).map(|j| m[i][j] * th[j]).sum::<f64>())
            .sum()
    };
    let x = poly([
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ]);
    let yy = poly([
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ]);
    (y, x, yy)
}

/// Luminance and chromaticity of linear sRGB.
fn luminance_xy(rgb: [f32; 3]) -> (f64, f64, f64) {
    let [r, g, b] = rgb.map(f64::from);
    let x = 0.4124 * r + 0.3576 * g + 0.1805 * b;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = 0.0193 * r + 0.1192 * g + 0.9505 * b;
    (y, x / (x + y + z), y / (x + y + z))
}

#[test]
fn preetham_zenith_matches_the_published_formulas() {
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        // High above the terrain, looking straight up.
        let camera = Camera {
            eye: DVec3::new(1280.0, 1280.0, 3000.0),
            target: DVec3::new(1280.0, 1280.0, 4000.0),
            up: DVec3::Y,
            fov_y_deg: 10.0,
            near: 1.0,
            far: 10000.0,
        };
        for (elevation, turbidity) in [(10.0, 3.0), (30.0, 2.0), (60.0, 3.0), (45.0, 6.0)] {
            let lighting = Lighting {
                sun: SunPosition::Angles {
                    elevation_deg: elevation,
                    azimuth_deg: 120.0,
                },
                sky: SkyModel::Preetham,
                turbidity,
                ..scene.default_lighting()
            };
            let images = render(&ctx, &scene, &camera, lighting, (16, 16));
            let centre = (8 * 16 + 8) * 4;
            let rgb = [images.hdr[centre], images.hdr[centre + 1], images.hdr[centre + 2]];
            let (y, x, yy) = luminance_xy(rgb);
            let (ey, ex, eyy) = preetham_zenith(f64::from(turbidity), (90.0 - f64::from(elevation)).to_radians());
            let what = format!("sun {elevation}°, T {turbidity}: got Y {y:.1} x {x:.4} y {yy:.4}, expected Y {ey:.1} x {ex:.4} y {eyy:.4}");
            assert!((y / ey - 1.0).abs() < 0.02, "{what}");
            assert!((x / ex - 1.0).abs() < 0.02 && (yy / eyy - 1.0).abs() < 0.02, "{what}");
        }
    }
    assert_validation_clean(&report);
}
