//! Soft sun shadows (`SunDisc::Soft`, `LIGHTING_SOFT_SUN`; §9.5 "simple
//! soft shadows"): the penumbra of a tall wall's edge under a low sun,
//! rendered by `sun_visibility` (glsl/include/shadows.glsl, the cascades'
//! blocker-distance disc filter) at ground points across the edge, against
//! a CPU ray cast of the sun's disc (4 096 rays spread evenly over the disc
//! of angular radius `SUN_ANGULAR_RADIUS`, each a slab test against the
//! wall), and against the hard shadows of the same maps. The horizon map's
//! disc fraction (a circular segment) is checked against the same kind of
//! ray cast over a straight horizon.

use std::f64::consts::PI;

use glam::DVec3;

use super::shadows::{ray_hits, run, Setup};
use crate::lighting::constants::{LIGHTING_SOFT_SUN, SUN_ANGULAR_RADIUS};
use crate::lighting::shadows::ShadowSettings;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::lighting::sun_direction;
use crate::view::Camera;

/// The wall: 400 m long, 4 m thick, 60 m tall.
const WALL: (DVec3, DVec3) = (DVec3::new(-200.0, -2.0, 0.0), DVec3::new(200.0, 2.0, 60.0));
/// Sun 15° high from −Y: the wall's shadow falls towards +Y and ends near
/// y = 2 + 60 / tan 15° = 225.9 m, 232 m from the wall's top edge.
const SUN: (f32, f32) = (15.0, 180.0);

/// Directions over the sun's disc: `n` points spread evenly over the unit
/// disc (Fibonacci spiral, equal areas), tilted from `sun` by the disc's
/// angular radius.
fn disc_directions(sun: DVec3, n: usize) -> Vec<DVec3> {
    let e1 = sun.cross(DVec3::Z).normalize();
    let e2 = sun.cross(e1);
    let r = f64::from(SUN_ANGULAR_RADIUS).tan();
    (0..n)
        .map(|k| {
            let rho = ((k as f64 + 0.5) / n as f64).sqrt();
            let phi = k as f64 * PI * (3.0 - 5f64.sqrt());
            (sun + (e1 * phi.cos() + e2 * phi.sin()) * rho * r).normalize()
        })
        .collect()
}

/// The fraction of the sun's disc seen from `p` past the wall.
fn disc_visibility(p: DVec3, rays: &[DVec3]) -> f64 {
    rays.iter().filter(|d| !ray_hits(p, **d, WALL)).count() as f64 / rays.len() as f64
}

/// Distance (m) along y between the profile's first points at or above 0.1
/// and 0.9 (the profile rises with y).
fn width_10_90(ys: &[f64], v: &[f64]) -> f64 {
    let at = |level: f64| {
        let i = v
            .iter()
            .position(|&x| x >= level)
            .expect("the profile reaches the level");
        if i == 0 {
            return ys[0];
        }
        // Linear between the samples around the crossing.
        let t = (level - v[i - 1]) / (v[i] - v[i - 1]);
        ys[i - 1] + t * (ys[i] - ys[i - 1])
    };
    at(0.9) - at(0.1)
}

#[test]
fn soft_shadow_penumbra_matches_a_ray_cast_of_the_sun_disc() {
    let (ctx, report) = validated_context();
    {
        let camera = Camera {
            eye: DVec3::new(0.0, 150.0, 40.0),
            target: DVec3::new(0.0, 230.0, 0.0),
            up: DVec3::Z,
            fov_y_deg: 60.0,
            near: 0.5,
            far: 2000.0,
        };
        let settings = ShadowSettings {
            cascades: 4,
            atlas_size: 2048,
            max_distance: 300.0,
            lambda: 0.75,
            pcf_radius: 2,
        };
        let sun = sun_direction(SUN.0, SUN.1).as_dvec3();
        let rays = disc_directions(sun, 4096);
        // Three lines across the shadow's end, every 0.25 m.
        let ys: Vec<f64> = (0..=200).map(|k| 200.0 + 0.25 * k as f64).collect();
        let xs = [-20.0, 0.0, 20.0];
        let probes: Vec<(DVec3, DVec3)> = xs
            .iter()
            .flat_map(|&x| ys.iter().map(move |&y| (DVec3::new(x, y, 0.0), DVec3::Z)))
            .collect();
        let reference: Vec<f64> = ys
            .iter()
            .map(|&y| disc_visibility(DVec3::new(0.0, y, 1e-3), &rays))
            .collect();
        let mut rendered = Vec::new();
        for flags in [LIGHTING_SOFT_SUN, 0] {
            let setup = Setup {
                camera,
                settings,
                wall: Some(WALL),
                flags,
            };
            let (vis, plan) = run(&ctx, (&setup, None), &[SUN], &probes).remove(0);
            let texel = plan.cascades.iter().map(|c| c.texel).fold(f64::INFINITY, f64::min);
            eprintln!("flags {flags}: finest cascade texel {texel:.3} m");
            rendered.push(vis.iter().map(|&v| f64::from(v)).collect::<Vec<f64>>());
        }
        let reference_width = width_10_90(&ys, &reference);
        let mut widths = Vec::new();
        // The analytic penumbra: blocker 60 / sin 15° m away, the disc's
        // radius there d·tan r, on the ground / sin 15°; 10–90 % of a
        // uniform disc's edge profile spans 1.374 radii.
        let d = 60.0 / (15f64.to_radians()).sin();
        let radius_on_ground = d * f64::from(SUN_ANGULAR_RADIUS).tan() / (15f64.to_radians()).sin();
        eprintln!("ray cast 10-90 % width {reference_width:.2} m (analytic disc radius on the ground {radius_on_ground:.2} m)");
        assert!((reference_width / radius_on_ground - 1.374).abs() < 0.05);
        for (name, vis) in ["soft", "hard"].iter().zip(&rendered) {
            for (line, &x) in xs.iter().enumerate() {
                let v = &vis[line * ys.len()..(line + 1) * ys.len()];
                let width = width_10_90(&ys, v);
                let worst = v.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                let mean = v.iter().zip(&reference).map(|(a, b)| (a - b).abs()).sum::<f64>() / v.len() as f64;
                eprintln!(
                    "{name} x = {x}: 10-90 % width {width:.2} m, |render − ray cast| max {worst:.3} mean {mean:.4}"
                );
                if *name == "soft" {
                    assert!(
                        (width / reference_width - 1.0).abs() < 0.25,
                        "soft penumbra {width:.2} m vs ray cast {reference_width:.2} m"
                    );
                    assert!(worst < 0.15 && mean < 0.03, "soft profile: max {worst}, mean {mean}");
                } else {
                    assert!(
                        width < 0.6 * reference_width,
                        "hard edge {width:.2} m not sharper than the disc's"
                    );
                }
                widths.push(width);
            }
        }
        // Soft penumbrae clearly wider than the hard edges, line by line.
        let (soft, hard) = widths.split_at(xs.len());
        assert!(
            soft.iter().zip(hard).all(|(s, h)| *s > 1.6 * h),
            "soft {soft:?} vs hard {hard:?}"
        );
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// `sun_disc_fraction` of glsl/include/horizon.glsl.
fn sun_disc_fraction(x: f64) -> f64 {
    let x = x.clamp(-1.0, 1.0);
    0.5 + (x * (1.0 - x * x).max(0.0).sqrt() + x.asin()) / PI
}

#[test]
fn disc_fraction_above_a_straight_horizon_matches_a_ray_cast() {
    // A horizon at elevation h across the whole sky, the sun at elevation e:
    // the fraction of rays over the disc that clear it.
    let r = f64::from(SUN_ANGULAR_RADIUS);
    let e = 10f64.to_radians();
    let sun = DVec3::new(0.0, e.cos(), e.sin());
    let rays = disc_directions(sun, 20_000);
    for k in -12..=12 {
        let h = e + r * k as f64 / 10.0;
        let clear = rays.iter().filter(|d| d.z.asin() > h).count() as f64 / rays.len() as f64;
        let formula = sun_disc_fraction((e - h) / r);
        assert!(
            (clear - formula).abs() < 0.01,
            "h − e = {k}/10 r: ray cast {clear}, segment {formula}"
        );
    }
}
