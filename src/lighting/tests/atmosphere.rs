//! The physical atmosphere's lookup tables (Hillaire 2020; src/lighting/atmosphere)
//! on a real device under validation and synchronization validation: a tiny
//! graph with `lighting.transmittance`, `lighting.multiscattering`,
//! `lighting.sky_view` and a readback of the three tables. The GPU
//! transmittance agrees with the CPU twin; the zenith luminance at a 60° sun
//! is that of Preetham's sky within a factor 2; a low sun reddens the
//! horizon towards it; no table holds NaN or Inf for sun elevations from
//! −10° to 90°; frames are deterministic. Run with `--nocapture` for the
//! figures.

use std::sync::Arc;

use crate::graph::RenderGraph;
use crate::lighting::atmosphere::{
    transmittance_lut_r_mu, transmittance_to_top, AtmosphereParameters, LutSizes, PhysicalAtmosphere,
};
use crate::lighting::constants::LightingFrame;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::lighting::sun_direction;
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, FrameRing, MemoryLocation};

/// Small tables; the sky view has an odd height so that its middle row is
/// the horizon.
const SIZES: LutSizes = LutSizes {
    transmittance: (64, 16),
    multiscattering: (16, 16),
    sky_view: (24, 33),
};

/// The world altitude of the ground and the camera's eye.
const GROUND_Z: f32 = 250.0;
const EYE_Z: f64 = 300.0;

/// One frame's conditions.
#[derive(Clone, Copy, Debug)]
struct Case {
    sun_elevation_deg: f32,
    turbidity: f32,
}

/// The three tables read back after a frame, RGBA per texel.
struct Tables {
    transmittance: Vec<[f32; 4]>,
    multiscattering: Vec<[f32; 4]>,
    sky_view: Vec<[f32; 4]>,
}

impl Tables {
    fn sky(&self, column: u32, row: u32) -> [f32; 4] {
        self.sky_view[(row * SIZES.sky_view.0 + column) as usize]
    }
}

fn luminance(c: [f32; 4]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Renders one frame per case and reads the tables back.
fn render(cases: &[Case]) -> Vec<Tables> {
    let (ctx, report) = validated_context();
    let tables = {
        let params = AtmosphereParameters::default();
        let atmosphere = PhysicalAtmosphere::new(&ctx, &params, SIZES, 1).expect("atmosphere");
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let region = graph.upload_region("lighting", std::mem::size_of::<LightingFrame>() as u64);
        // Errors, not panics: no view, more views than tables, an unknown view.
        assert!(atmosphere
            .declare(&mut RenderGraph::<()>::new(), &[], |_, _| true)
            .is_err());
        assert!(atmosphere
            .declare(
                &mut RenderGraph::<()>::new(),
                &[("a", region), ("b", region)],
                |_, _| true
            )
            .is_err());
        let mut scratch: LightingFrame = bytemuck::Zeroable::zeroed();
        assert!(atmosphere.fill_altitude(1, EYE_Z, &mut scratch).is_err());
        let luts = atmosphere
            .declare(&mut graph, &[("", region)], |_, _| true)
            .expect("declare");
        let readback = |name: &str, (w, h): (u32, u32)| {
            Arc::new(
                Buffer::new(
                    &ctx,
                    BufferDesc {
                        name: name.into(),
                        size: u64::from(w * h) * 16,
                        usage: BufferUsageFlags::TRANSFER_DST,
                        location: MemoryLocation::GpuToCpu,
                    },
                )
                .expect("readback buffer"),
            )
        };
        let buffers = [
            readback("transmittance readback", SIZES.transmittance),
            readback("multiscattering readback", SIZES.multiscattering),
            readback("sky view readback", SIZES.sky_view),
        ];
        let ids: Vec<_> = buffers.iter().map(|b| graph.import_buffer(b.clone())).collect();
        let [transmittance, multiscattering, sky_view] = luts.reads(0).expect("view 0");
        graph.read_back_images(
            "atmosphere.readback",
            vec![(transmittance, ids[0]), (multiscattering, ids[1]), (sky_view, ids[2])],
        );
        let mut baked = graph.bake(&ctx).expect("bake");
        assert_eq!(
            baked.pass_names()[..4],
            [
                "lighting.transmittance",
                "lighting.multiscattering",
                "lighting.sky_view",
                "atmosphere.readback"
            ]
        );
        let mut frames = FrameRing::new(&ctx).expect("frame ring");
        let mut tables = Vec::new();
        for case in cases {
            let index = frames.wait_for_next().expect("next frame");
            let p = AtmosphereParameters::for_turbidity(case.turbidity).expect("turbidity");
            let mut lighting: LightingFrame = bytemuck::Zeroable::zeroed();
            lighting.sun = sun_direction(case.sun_elevation_deg, 120.0)
                .extend(0.004_654)
                .to_array();
            lighting.mie[3] = GROUND_Z;
            p.fill(&mut lighting);
            atmosphere.fill_altitude(0, EYE_Z, &mut lighting).expect("altitude");
            baked
                .uploads(index)
                .write_pod(region, &lighting)
                .expect("upload the LightingFrame");
            baked.execute(&mut frames, &(), &[]).expect("frame");
            baked.finish(&mut frames).expect("finish");
            let read = |b: &Buffer| -> Vec<[f32; 4]> { bytemuck::pod_collect_to_vec(b.mapped().expect("mapped")) };
            tables.push(Tables {
                transmittance: read(&buffers[0]),
                multiscattering: read(&buffers[1]),
                sky_view: read(&buffers[2]),
            });
        }
        tables
    };
    drop(ctx);
    assert_validation_clean(&report);
    tables
}

/// Preetham's zenith luminance (cd/m²) for turbidity `t` and sun zenith `theta_s`.
fn preetham_zenith(t: f32, theta_s: f32) -> f32 {
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * theta_s);
    1000.0 * ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192)
}

fn check_transmittance_matches_twin(tables: &Tables, turbidity: f32) {
    let params = AtmosphereParameters::for_turbidity(turbidity).expect("turbidity");
    let (w, h) = SIZES.transmittance;
    let mut worst = 0.0f64;
    for j in 0..h {
        for i in 0..w {
            let (r, mu) = transmittance_lut_r_mu(
                &params,
                f64::from(i) / f64::from(w - 1),
                f64::from(j) / f64::from(h - 1),
            );
            let cpu = transmittance_to_top(&params, r, mu);
            let gpu = tables.transmittance[(j * w + i) as usize];
            for c in 0..3 {
                let (g, e) = (f64::from(gpu[c]), f64::from(cpu[c]));
                let error = (g - e).abs() / e.max(1e-2);
                worst = worst.max(error);
                assert!(
                    error < 0.01,
                    "texel ({i}, {j}) channel {c}: GPU {g} vs CPU {e} (r {r}, mu {mu})"
                );
            }
        }
    }
    println!(
        "transmittance: worst relative difference GPU vs CPU twin {:.3} %",
        worst * 100.0
    );
}

#[test]
fn atmosphere_tables_under_validation() {
    let mut cases = vec![
        Case {
            sun_elevation_deg: 60.0,
            turbidity: 3.0,
        },
        Case {
            sun_elevation_deg: 80.0,
            turbidity: 3.0,
        },
        Case {
            sun_elevation_deg: 3.0,
            turbidity: 3.0,
        },
        Case {
            sun_elevation_deg: 60.0,
            turbidity: 3.0,
        },
    ];
    for e in [-10.0, -4.0, -0.5, 0.0, 0.5, 10.0, 30.0, 90.0] {
        for t in [1.7, 10.0] {
            cases.push(Case {
                sun_elevation_deg: e,
                turbidity: t,
            });
        }
    }
    let tables = render(&cases);

    // No NaN or Inf, nothing negative.
    for (case, t) in cases.iter().zip(&tables) {
        for (name, table) in [
            ("transmittance", &t.transmittance),
            ("multiscattering", &t.multiscattering),
            ("sky view", &t.sky_view),
        ] {
            assert!(
                table.iter().flatten().all(|v| v.is_finite() && *v >= 0.0),
                "{name} has a NaN, Inf or negative value for {case:?}"
            );
        }
    }

    // Deterministic: the same case twice gives the same bits.
    assert_eq!(tables[0].sky_view, tables[3].sky_view);
    assert_eq!(tables[0].multiscattering, tables[3].multiscattering);

    check_transmittance_matches_twin(&tables[0], cases[0].turbidity);

    // The zenith at a 60° sun against Preetham's Y_z (T = 3).
    let (w, h) = SIZES.sky_view;
    let zenith = (0..w).map(|c| luminance(tables[0].sky(c, 0))).sum::<f32>() / w as f32;
    let preetham = preetham_zenith(3.0, 30f32.to_radians());
    println!("zenith luminance at a 60° sun, T = 3: {zenith:.0} cd/m² (Preetham {preetham:.0})");
    assert!(
        (0.5..=2.0).contains(&(zenith / preetham)),
        "zenith {zenith} cd/m² vs Preetham {preetham}"
    );

    // Towards the sun just above the horizon: redder at a low sun.
    let horizon_row = (h - 1) / 2 - 1;
    let ratio = |t: &Tables| {
        let c = t.sky(0, horizon_row);
        c[0] / c[2]
    };
    let (noon, low) = (ratio(&tables[1]), ratio(&tables[2]));
    println!("horizon towards the sun R/B: sun at 80° {noon:.3}, at 3° {low:.3}");
    assert!(low > noon * 1.2, "R/B at a low sun {low} vs high {noon}");

    // A sun below the horizon leaves a dim twilight sky, not a black one.
    let twilight = luminance(tables[4 + 2 * 2].sky(0, horizon_row));
    let day = luminance(tables[2].sky(0, horizon_row));
    println!("horizon luminance towards the sun: sun at 3° {day:.0}, at −0.5° {twilight:.1} cd/m²");
    assert!(twilight > 0.0 && twilight < day);
}
