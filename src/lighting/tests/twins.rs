//! Outdoor lighting end to end (§6.3, §9) under validation and
//! synchronization validation: the sky against Preetham's published
//! formulas, aerial perspective against its CPU twin, the lighting AOVs.

use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::procedural::ProceduralTerrain;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::{Lighting, SkyModel, SunPosition};
use crate::vulkan::Context;
use glam::{DVec2, DVec3};

fn small_scene() -> Scene {
    let field = ProceduralTerrain::default()
        .try_generate(65, 65, DVec2::new(40.0, 40.0))
        .expect("procedural terrain");
    Scene::new(field)
}

/// One frame of `camera` under `lighting` at `w`×`h`.
fn render(
    ctx: &Context,
    scene: &Scene,
    camera: &Camera,
    (lighting, raster): (Lighting, crate::RasterPath),
    (w, h): (u32, u32),
) -> FrameImages {
    let settings = RenderSettings {
        texturing: TexturingMode::Classic,
        lighting: Some(lighting),
        raster,
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
            let images = render(&ctx, &scene, &camera, (lighting, crate::RasterPath::Auto), (16, 16));
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

/// The world point of pixel (x, y) at view depth `depth`, and its view ray.
fn pixel_world(camera: &Camera, (w, h): (u32, u32), (x, y): (u32, u32), depth: f32) -> (DVec3, DVec3) {
    let (right, up, forward) = crate::view::View::new(*camera, w, h).ray_basis();
    let ndc_x = (f64::from(x) + 0.5) / f64::from(w) * 2.0 - 1.0;
    let ndc_y = (f64::from(y) + 0.5) / f64::from(h) * 2.0 - 1.0;
    let dir = (forward.as_dvec3() + right.as_dvec3() * ndc_x - up.as_dvec3() * ndc_y).normalize();
    let t = f64::from(depth) / dir.dot(camera.forward());
    (camera.eye + dir * t, dir)
}

#[test]
fn sun_visibility_agrees_with_a_cpu_ray_cast_on_the_real_dem() {
    for raster in crate::test_support::RASTER_PATHS {
        sun_visibility_agrees_with_a_cpu_ray_cast_on_the_real_dem_in(raster);
    }
}

fn sun_visibility_agrees_with_a_cpu_ray_cast_on_the_real_dem_in(raster: crate::RasterPath) {
    use crate::surface::bspline::sample_bspline_gradient;
    use crate::terrain::raycast::Raycaster;
    use crate::view::{ShadowMode, SkyLightMode};

    let (ctx, report) = validated_context();
    {
        let scene = Scene::new(crate::test_support::jacksboro_field());
        let camera = crate::test_support::jacksboro_valley_camera();
        let caster = Raycaster::new(&scene.heights).expect("ray caster");
        let size = (160, 100);
        for (elevation, azimuth) in [(12.0f32, 300.0f32), (50.0, 200.0)] {
            let lighting = Lighting {
                sun: SunPosition::Angles {
                    elevation_deg: elevation,
                    azimuth_deg: azimuth,
                },
                shadows: ShadowMode::Cascaded,
                sky_light: SkyLightMode::Off,
                ..scene.default_lighting()
            };
            let mut settings = RenderSettings {
                texturing: TexturingMode::Classic,
                lighting: Some(lighting),
                raster,
                ..RenderSettings::new(size.0, size.1)
            };
            settings.terrain.detail = false;
            let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
            let frame = renderer.render(&camera).expect("frame");
            let images = renderer.read(&frame).expect("readback");
            renderer.finish().expect("finish");
            let sun_gpu = images.visibility_channel(0);
            let sun = lighting.sun_direction().as_dvec3();
            let lit = |x: i64, y: i64| sun_gpu[(y * i64::from(size.0) + x) as usize] > 0.5;
            let (mut compared, mut agreed, mut shadowed) = (0u32, 0u32, 0u32);
            for y in 2..i64::from(size.1) - 2 {
                for x in 2..i64::from(size.0) - 2 {
                    let depth = images.depth[(y * i64::from(size.0) + x) as usize];
                    if !depth.is_finite() {
                        continue;
                    }
                    // Away from shadow edges: a 5×5 neighbourhood of one verdict.
                    let centre = lit(x, y);
                    if (-2..=2).any(|dy| (-2..=2).any(|dx| lit(x + dx, y + dy) != centre)) {
                        continue;
                    }
                    let (world, _) = pixel_world(&camera, size, (x as u32, y as u32), depth);
                    let g = sample_bspline_gradient(&scene.heights, world.x, world.y);
                    let normal = DVec3::new(-g.x, -g.y, 1.0).normalize();
                    // Surfaces facing away shadow themselves; the AOV is the cast-shadow term.
                    if normal.dot(sun) < 0.15 {
                        continue;
                    }
                    let origin = world + DVec3::Z * 4.0 + sun * 8.0;
                    let cpu_lit = caster.raycast(origin, sun, f64::INFINITY).is_none();
                    compared += 1;
                    agreed += u32::from(cpu_lit == centre);
                    shadowed += u32::from(!centre);
                }
            }
            let share = f64::from(agreed) / f64::from(compared.max(1));
            println!("sun {elevation}°: {agreed}/{compared} agree ({share:.3}), {shadowed} in shadow");
            assert!(compared > 2000, "too few terrain pixels compared: {compared}");
            assert!(
                share >= 0.95,
                "sun {elevation}°: only {share:.3} of pixels agree with the ray cast"
            );
            if elevation < 20.0 {
                assert!(
                    shadowed > 100,
                    "a low sun over the DEM must cast shadows ({shadowed} shadowed pixels)"
                );
            }
        }
    }
    assert_validation_clean(&report);
}

#[test]
fn aerial_perspective_matches_its_cpu_twin() {
    for raster in crate::test_support::RASTER_PATHS {
        aerial_perspective_matches_its_cpu_twin_in(raster);
    }
}

fn aerial_perspective_matches_its_cpu_twin_in(raster: crate::RasterPath) {
    use crate::lighting::aerial::{
        aerial_perspective, distant_radiance, optical_depth, AerialCoefficients, SCALE_HEIGHTS_M,
    };
    use crate::lighting::preetham::PreethamSky;
    use crate::view::{Exposure, ShadowMode, SkyLightMode};

    let (ctx, report) = validated_context();
    {
        let scene = Scene::new(crate::test_support::jacksboro_field());
        let ground = f64::from(scene.height_range().0);
        let camera = crate::test_support::jacksboro_valley_camera();
        let size = (96, 60);
        let lighting = Lighting {
            sun: SunPosition::Angles {
                elevation_deg: 35.0,
                azimuth_deg: 160.0,
            },
            sky: SkyModel::Preetham,
            turbidity: 3.0,
            exposure: Exposure::Ev100(14.0),
            shadows: ShadowMode::Off,
            sky_light: SkyLightMode::Off,
            ..scene.default_lighting()
        };
        let without = Lighting {
            aerial_perspective: false,
            ..lighting
        };
        let on = render(&ctx, &scene, &camera, (lighting, raster), size);
        let off = render(&ctx, &scene, &camera, (without, raster), size);
        let sun = lighting.sun_direction();
        let sky = PreethamSky::new(sun, lighting.turbidity).expect("sky");
        let coefficients = AerialCoefficients::for_turbidity(lighting.turbidity).expect("coefficients");
        let (mut compared, mut far) = (0u32, 0u32);
        for y in 0..size.1 {
            for x in 0..size.0 {
                let i = (y * size.0 + x) as usize;
                let depth = on.depth[i];
                if !depth.is_finite() {
                    continue;
                }
                let (world, dir) = pixel_world(&camera, size, (x, y), depth);
                let distance = (world - camera.eye).length() as f32;
                let l0 = glam::Vec3::from_slice(&off.hdr[i * 4..i * 4 + 3]);
                let l_inf = distant_radiance(
                    |d| sky.radiance(d),
                    &coefficients,
                    dir.as_vec3(),
                    sun,
                    sky.sun_irradiance(),
                );
                let tau = optical_depth(
                    &coefficients,
                    distance,
                    (camera.eye.z - ground) as f32,
                    (world.z - ground) as f32,
                    SCALE_HEIGHTS_M,
                );
                let expected = aerial_perspective(l0, tau, l_inf);
                let got = glam::Vec3::from_slice(&on.hdr[i * 4..i * 4 + 3]);
                let error = ((got - expected).abs() / expected.max(glam::Vec3::splat(1.0))).max_element();
                assert!(
                    error < 0.02,
                    "pixel ({x}, {y}) at {distance:.0} m: got {got}, expected {expected} (L0 {l0}, L∞ {l_inf})"
                );
                compared += 1;
                far += u32::from(distance > 10_000.0);
            }
        }
        assert!(
            compared > 1000 && far > 50,
            "{compared} pixels compared, {far} beyond 10 km"
        );
    }
    assert_validation_clean(&report);
}
