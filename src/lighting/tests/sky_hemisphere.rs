//! Fig. 9.3 (§9.5): the two lighting environments of the comparison, sky
//! light only (no sun disc), as hemisphere images: Preetham's model
//! (turbidity 2.1, the text's) on the CPU twin of `preetham_sky`
//! ([`PreethamSky::radiance`]) for `--sky-preset morning` (day 298, 07:30)
//! and `noon` (day 180, 12:00) at 49.6° N. Equidistant fisheye looking
//! down on the hemisphere from above: zenith at the centre, the horizon
//! on the circle, north up, east right; outside the circle black. Each
//! image is exposed on its own (`L / (L + mean)`, sRGB), as the text's
//! are. `ALPENGLOW_DUMP=DIR` writes `N-fig-9-3-sky-morning.png`, `…-noon.png`.
//!
//! Checked against what Preetham's model is known to do: the brightest
//! sky lies around the sun (within 12° of it), the darkest 55°–115° away
//! from it (the Perez function's dark band about 90° from the sun, pulled
//! towards the zenith by the brightening towards the horizon: measured
//! 94° in the morning, 63° at noon), and the noon sky is brighter on
//! average than the morning's.

use glam::Vec3;

use crate::lighting::preetham::{luminance, PreethamSky};
use crate::lighting::solar::SkyPreset;
use crate::test_support::{dump_pngs, linear_to_srgb8};

const SIDE: u32 = 160;

/// The direction of pixel `(x, y)`, None outside the hemisphere.
fn direction(x: u32, y: u32) -> Option<Vec3> {
    let half = SIDE as f32 / 2.0;
    let (u, v) = ((x as f32 + 0.5 - half) / half, (half - y as f32 - 0.5) / half);
    let r = (u * u + v * v).sqrt();
    if r > 1.0 {
        return None;
    }
    let theta = r * std::f32::consts::FRAC_PI_2;
    let phi = u.atan2(v);
    Some(Vec3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos()))
}

struct Hemisphere {
    rgba: Vec<u8>,
    /// (luminance, direction) of every pixel inside the circle.
    samples: Vec<(f32, Vec3)>,
}

fn hemisphere(sky: &PreethamSky) -> Hemisphere {
    let mut samples = Vec::new();
    let mut radiance = Vec::new();
    for y in 0..SIDE {
        for x in 0..SIDE {
            let value = direction(x, y).map(|d| (sky.radiance(d), d));
            if let Some((rgb, d)) = value {
                samples.push((luminance(rgb), d));
            }
            radiance.push(value.map(|v| v.0));
        }
    }
    let mean = samples.iter().map(|s| s.0).sum::<f32>() / samples.len() as f32;
    let rgba = (radiance.iter())
        .flat_map(|r| match r {
            Some(rgb) => {
                let c = *rgb / (luminance(*rgb) + mean);
                [linear_to_srgb8(c.x), linear_to_srgb8(c.y), linear_to_srgb8(c.z), 255]
            }
            None => [0, 0, 0, 255],
        })
        .collect();
    Hemisphere { rgba, samples }
}

#[test]
fn preset_skies_are_brightest_at_the_sun_and_darkest_ninety_degrees_away() {
    let mut means = Vec::new();
    for (name, preset) in [("morning", SkyPreset::Morning), ("noon", SkyPreset::Noon)] {
        let sun = preset.sun().expect("preset sun").direction();
        let sky = PreethamSky::new(sun, preset.turbidity()).expect("sky");
        let image = hemisphere(&sky);
        dump_pngs(&[(&format!("fig-9-3-sky-{name}"), &image.rgba)], SIDE, SIDE);
        let angle = |d: Vec3| d.dot(sun).clamp(-1.0, 1.0).acos().to_degrees();
        let by_luminance = |a: &&(f32, Vec3), b: &&(f32, Vec3)| a.0.total_cmp(&b.0);
        let brightest = image.samples.iter().max_by(by_luminance).unwrap();
        let darkest = image.samples.iter().min_by(by_luminance).unwrap();
        let mean = image.samples.iter().map(|s| s.0).sum::<f32>() / image.samples.len() as f32;
        println!(
            "{name}: sun {:.1}° up; brightest {:.0} cd/m² {:.1}° from the sun, darkest {:.0} cd/m² {:.1}° from it, mean {mean:.0}",
            sun.z.asin().to_degrees(),
            brightest.0,
            angle(brightest.1),
            darkest.0,
            angle(darkest.1)
        );
        assert!(
            angle(brightest.1) < 12.0,
            "{name}: brightest {:.1}° from the sun",
            angle(brightest.1)
        );
        assert!(
            (55.0..115.0).contains(&angle(darkest.1)),
            "{name}: darkest {:.1}° from the sun",
            angle(darkest.1)
        );
        means.push(mean);
    }
    assert!(
        means[1] > means[0],
        "noon sky not brighter than the morning's: {means:?}"
    );
}
