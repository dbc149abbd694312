//! Analytic checks of the CPU twin of the Monte Carlo reference (§9.2).

use glam::{DVec2, Vec3};

use super::{CpuReference, ReferenceSettings, SunInput};
use crate::io::heightmap::HeightField;
use crate::view::lighting::sun_direction;

fn settings(samples: u32, bounces: u32) -> ReferenceSettings {
    ReferenceSettings {
        samples,
        bounces,
        ..ReferenceSettings::default()
    }
}

fn sun(elevation: f32, azimuth: f32, in_environment: bool) -> SunInput {
    SunInput {
        direction: sun_direction(elevation, azimuth),
        angular_radius: 0.004_654,
        irradiance: Vec3::new(3.0, 2.0, 1.0),
        in_environment,
    }
}

/// A valley along Y with straight walls rising at `slope_deg` from its
/// bottom at column 16.
fn v_valley(slope_deg: f64) -> HeightField {
    let tan = slope_deg.to_radians().tan();
    HeightField::from_fn(33, 41, DVec2::new(2.0, 2.0), |c, _| {
        ((f64::from(c) - 16.0).abs() * 2.0 * tan + 100.0) as f32
    })
}

#[test]
fn flat_plane_sees_the_whole_sky() {
    let field = HeightField::from_fn(12, 9, DVec2::new(3.0, 2.0), |_, _| 250.0);
    let sky = |_: Vec3| Vec3::new(1.0, 2.0, 3.0);
    for bounces in 0..=2 {
        let reference = CpuReference::new(&field, settings(64, bounces)).unwrap();
        for (c, r) in [(0, 0), (5, 4), (11, 8)] {
            let e = reference.texel(c, r, &sun(30.0, 40.0, false), 0.3, &sky).unwrap();
            assert!(
                (e.sky_light - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-5,
                "{e:?}"
            );
            assert_eq!(e.sky_visibility, 1.0);
            assert_eq!(e.sun_visibility, 1.0);
            assert!(e.standard_error.max_element() < 1e-5);
        }
    }
    // The sun in the environment adds E/π·cos θ_s at x.
    let reference = CpuReference::new(&field, settings(16, 1)).unwrap();
    let e = reference.texel(5, 4, &sun(30.0, 40.0, true), 0.3, &sky).unwrap();
    let direct = Vec3::new(3.0, 2.0, 1.0) / std::f32::consts::PI * 30f32.to_radians().sin();
    assert!((e.sky_light - Vec3::new(1.0, 2.0, 3.0) - direct).abs().max_element() < 1e-5);
}

/// At the bottom of an infinitely long symmetric V valley whose walls rise
/// at angle α, the cosine-weighted fraction of the sky in view is cos α: in
/// the cross-section, directions within ±(90° − α) of the zenith escape,
/// and the cosine-weighted measure of a 2-D wedge [φ₁, φ₂] (angles from the
/// normal) is (sin φ₂ − sin φ₁)/2 (Nusselt), so (2 sin(90° − α))/2 = cos α.
#[test]
fn v_valley_bottom_sees_cos_alpha_of_the_sky() {
    let sky = |_: Vec3| Vec3::splat(2.0);
    for slope in [30.0, 45.0, 60.0] {
        let field = v_valley(slope);
        let reference = CpuReference::new(&field, settings(4096, 0)).unwrap();
        let e = reference.texel(16, 20, &sun(80.0, 0.0, false), 0.3, &sky).unwrap();
        let expected = slope.to_radians().cos() as f32;
        assert!(
            (e.sky_visibility - expected).abs() < 0.01,
            "{slope}°: {e:?} vs {expected}"
        );
        // No bounces: the sky light is the visible sky.
        assert!((e.sky_light.x - 2.0 * e.sky_visibility).abs() < 1e-4);
    }
}

#[test]
fn v_valley_walls_shadow_a_low_sun_and_bounce_light() {
    let field = v_valley(45.0);
    let sky = |d: Vec3| Vec3::splat(1.0 + d.z);
    let reference = CpuReference::new(&field, settings(256, 0)).unwrap();
    // Across the valley: below the 45° wall shadowed, above it lit.
    assert_eq!(
        reference
            .texel(16, 20, &sun(30.0, 90.0, false), 0.3, &sky)
            .unwrap()
            .sun_visibility,
        0.0
    );
    assert_eq!(
        reference
            .texel(16, 20, &sun(60.0, 90.0, false), 0.3, &sky)
            .unwrap()
            .sun_visibility,
        1.0
    );
    // Along the valley the sun is always visible.
    assert_eq!(
        reference
            .texel(16, 20, &sun(5.0, 0.0, false), 0.3, &sky)
            .unwrap()
            .sun_visibility,
        1.0
    );
    // Bounces add light, more with a higher albedo; bounced sun adds more.
    let at = |bounces: u32, albedo: f32, sun_bounces: bool| {
        let s = ReferenceSettings {
            sun_bounces,
            ..settings(256, bounces)
        };
        let reference = CpuReference::new(&field, s).unwrap();
        reference
            .texel(16, 20, &sun(60.0, 90.0, false), albedo, &sky)
            .unwrap()
            .sky_light
            .x
    };
    let (none, one, two) = (at(0, 0.3, false), at(1, 0.3, false), at(2, 0.3, false));
    assert!(none < one && one < two, "{none} {one} {two}");
    assert!(at(1, 0.6, false) > one);
    assert!(at(1, 0.3, true) > one);
    assert_eq!(at(1, 0.0, true), none);
}

#[test]
fn estimates_are_deterministic_for_a_seed() {
    let field = v_valley(40.0);
    let sky = |d: Vec3| Vec3::new(1.0, d.z, 0.5);
    let run = |seed: u32| {
        let s = ReferenceSettings {
            seed,
            ..settings(32, 2)
        };
        CpuReference::new(&field, s)
            .unwrap()
            .texel(14, 3, &sun(35.0, 120.0, false), 0.5, &sky)
            .unwrap()
    };
    assert_eq!(run(1), run(1));
    assert_ne!(run(1).sky_light, run(2).sky_light);
}

#[test]
fn bad_settings_are_named() {
    let field = v_valley(40.0);
    let name = |s: ReferenceSettings| {
        CpuReference::new(&field, s)
            .unwrap_err()
            .parameter()
            .map(str::to_string)
    };
    assert_eq!(name(settings(0, 1)).as_deref(), Some("lighting.reference.samples"));
    assert_eq!(name(settings(8, 3)).as_deref(), Some("lighting.reference.bounces"));
    let reference = CpuReference::new(&field, settings(8, 1)).unwrap();
    let sky = |_: Vec3| Vec3::ONE;
    assert!(reference.texel(33, 0, &sun(30.0, 0.0, false), 0.3, &sky).is_err());
}
