//! The CIE clear and overcast skies (§6.3, eqs. 6.18 and 6.19) rendered
//! under validation against the text's formulas, written out here in f64
//! in their published form (not the Perez coefficients the library turns
//! them into): the luminance of every sky pixel of a wide view, relative to
//! the zenith luminance, and that luminance itself (Preetham's formula for
//! the clear sky, Krochmann and Seidl's for the overcast one).

use glam::{DVec2, DVec3};

use crate::renderer::{Camera, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::procedural::ProceduralTerrain;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::{Lighting, SkyModel, SunPosition};

/// Eq. 6.18 over the zenith luminance: view zenith angle θ, sun zenith
/// angle θ_s, angle γ between view and sun.
fn cie_clear(theta: f64, theta_s: f64, gamma: f64) -> f64 {
    let f = |a: f64| 0.91 + 10.0 * (-3.0 * a).exp() + 0.45 * a.cos().powi(2);
    f(gamma) * (1.0 - (-0.32 / theta.cos()).exp()) / (f(theta_s) * (1.0 - (-0.32f64).exp()))
}

/// Eq. 6.19 over the zenith luminance.
fn cie_overcast(theta: f64) -> f64 {
    (1.0 + 2.0 * theta.cos()) / 3.0
}

/// Preetham 1999's zenith luminance (cd/m²), written out independently.
fn preetham_zenith_luminance(turbidity: f64, theta_s: f64) -> f64 {
    let chi = (4.0 / 9.0 - turbidity / 120.0) * (std::f64::consts::PI - 2.0 * theta_s);
    ((4.0453 * turbidity - 4.9710) * chi.tan() - 0.2155 * turbidity + 2.4192) * 1000.0
}

#[test]
fn cie_skies_follow_the_published_distributions() {
    let (ctx, report) = validated_context();
    {
        let field = ProceduralTerrain::default()
            .try_generate(65, 65, DVec2::new(40.0, 40.0))
            .expect("procedural terrain");
        let scene = Scene::new(field);
        // High above the terrain, looking 45° up towards the south-west: the
        // view spans elevations from 0° to 90° and passes near the sun.
        let camera = Camera {
            eye: DVec3::new(1280.0, 1280.0, 3000.0),
            target: DVec3::new(1280.0 - 700.0, 1280.0 - 700.0, 3000.0 + 990.0),
            up: DVec3::Z,
            fov_y_deg: 90.0,
            near: 1.0,
            far: 10000.0,
        };
        let (w, h) = (48u32, 48u32);
        let (elevation, azimuth, turbidity) = (35.0f64, 200.0f64, 3.0f32);
        let sun = {
            let (e, a) = (elevation.to_radians(), azimuth.to_radians());
            DVec3::new(e.cos() * a.sin(), e.cos() * a.cos(), e.sin())
        };
        let theta_s = (90.0 - elevation).to_radians();
        for sky in [SkyModel::CieClear, SkyModel::CieOvercast] {
            let lighting = Lighting {
                sun: SunPosition::Angles {
                    elevation_deg: elevation as f32,
                    azimuth_deg: azimuth as f32,
                },
                sky,
                turbidity,
                ..scene.default_lighting()
            };
            let settings = RenderSettings {
                texturing: TexturingMode::Classic,
                lighting: Some(lighting),
                ..RenderSettings::new(w, h)
            };
            let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
            let frame = renderer.render(&camera).expect("frame");
            let images = renderer.read(&frame).expect("readback");
            renderer.finish().expect("finish");
            let zenith = match sky {
                SkyModel::CieClear => preetham_zenith_luminance(f64::from(turbidity), theta_s),
                _ => 123.0 + 8600.0 * elevation.to_radians().sin(),
            };
            let tan = (45f64).to_radians().tan();
            let (forward, right, up) = (camera.forward(), camera.right(), camera.image_up());
            let (mut checked, mut worst, mut near_sun) = (0, 0.0f64, 0);
            for y in 0..h {
                for x in 0..w {
                    let ndc = DVec2::new(
                        (2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0) * tan,
                        (1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)) * tan,
                    );
                    let dir = (forward + ndc.x * right + ndc.y * up).normalize();
                    let gamma = dir.dot(sun).clamp(-1.0, 1.0).acos();
                    // Sky only (the view clamp of the models is below 1°), and
                    // clear of the sun's disc and its pixel footprint.
                    // The overcast sky hides the sun: no disc to step around.
                    let at_sun = gamma < 3f64.to_radians();
                    near_sun += usize::from(at_sun && dir.z >= 0.05);
                    if dir.z < 0.05 || (at_sun && sky == SkyModel::CieClear) {
                        continue;
                    }
                    let theta = dir.z.acos();
                    let expected = zenith
                        * match sky {
                            SkyModel::CieClear => cie_clear(theta, theta_s, gamma),
                            _ => cie_overcast(theta),
                        };
                    let i = ((y * w + x) * 4) as usize;
                    let rgb = [images.hdr[i], images.hdr[i + 1], images.hdr[i + 2]].map(f64::from);
                    let luminance = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
                    let error = (luminance / expected - 1.0).abs();
                    assert!(
                        error < 0.03,
                        "{sky:?}: pixel ({x}, {y}), elevation {:.1}°, γ {:.1}°: {luminance:.1} cd/m², expected {expected:.1}",
                        90.0 - theta.to_degrees(),
                        gamma.to_degrees()
                    );
                    worst = worst.max(error);
                    checked += 1;
                    if sky == SkyModel::CieOvercast {
                        // White: the chromaticity of D65.
                        let sum = 0.4124 * rgb[0]
                            + 0.3576 * rgb[1]
                            + 0.1805 * rgb[2]
                            + luminance
                            + 0.0193 * rgb[0]
                            + 0.1192 * rgb[1]
                            + 0.9505 * rgb[2];
                        let cx = (0.4124 * rgb[0] + 0.3576 * rgb[1] + 0.1805 * rgb[2]) / sum;
                        assert!((cx - 0.3127).abs() < 0.005, "{sky:?}: x {cx}");
                    }
                }
            }
            assert!(checked > (w * h / 3) as usize, "{sky:?}: only {checked} sky pixels");
            assert!(near_sun > 0, "the view should pass near the sun");
            eprintln!(
                "{sky:?}: {checked} sky pixels within {:.2} % of the formula",
                worst * 100.0
            );
        }
    }
    assert_validation_clean(&report);
}
