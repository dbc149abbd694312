//! `lighting.reference`, the Monte Carlo reference of sky light (§9.2),
//! against its CPU twin (`src/lighting/reference/cpu.rs`, same random
//! numbers, exact f64 ray casting): every texel of a small rough field
//! within three standard errors, with two bounces, the sun separate and in
//! the environment, chunked dispatches and progressive frames; the maps are
//! not recomputed while the lighting stays the same. Under validation and
//! synchronization validation. Timings: `benchmarks/src/bin/lighting_bench.rs`.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::graph::RenderGraph;
use crate::io::heightmap::HeightField;
use crate::lighting::constants::{LightingFrame, LIGHTING_ALBEDO_OVERRIDE, LIGHTING_SUN_IN_ENVIRONMENT};
use crate::lighting::reference::{
    CpuReference, MonteCarloReference, ReferenceProgress, ReferenceSettings, ReferenceWork, SunInput,
};
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::lighting::sun_direction;
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, FrameRing, MemoryLocation};
use bytemuck::Zeroable;
use glam::{DVec2, Vec3};

/// The analytic test sky: constant + per unit ω.z.
const SKY: (Vec3, Vec3) = (Vec3::new(0.2, 0.3, 0.5), Vec3::new(0.6, 0.8, 1.2));

fn test_sky(d: Vec3) -> Vec3 {
    SKY.0 + SKY.1 * d.z
}

/// The maps read back: RGBA per texel, sun visibility per texel.
struct Maps {
    sky: Vec<[f32; 4]>,
    sun: Vec<f32>,
}

fn lighting(sun_in_environment: bool, radius: f32) -> LightingFrame {
    let mut l = LightingFrame::zeroed();
    let s = sun_direction(35.0, 120.0);
    l.sun = [s.x, s.y, s.z, radius];
    l.sun_irradiance = [3.0, 2.5, 2.0, 0.0];
    l.models[3] = if sun_in_environment {
        LIGHTING_SUN_IN_ENVIRONMENT
    } else {
        0
    };
    l
}

/// Rough hills: smooth waves plus hashed noise, steep enough for
/// interreflections and cast shadows.
fn rough_field(columns: u32, rows: u32) -> HeightField {
    HeightField::from_fn(columns, rows, DVec2::new(2.0, 3.0), |c, r| {
        let (x, y) = (f64::from(c), f64::from(r));
        let k = (x * 12.9898 + y * 78.233).sin() * 43_758.545;
        (30.0 + 9.0 * (x * 0.5).sin() * (y * 0.4).cos() + 4.0 * (k - k.floor())) as f32
    })
}

fn readback(ctx: &Context, name: &str, size: u64) -> Arc<Buffer> {
    let desc = BufferDesc {
        name: name.into(),
        size,
        usage: BufferUsageFlags::TRANSFER_DST,
        location: MemoryLocation::GpuToCpu,
    };
    Arc::new(Buffer::new(ctx, desc).expect("readback buffer"))
}

/// Runs one frame per entry of `frames` (the lighting of that frame) and
/// reads the maps back after the last; returns the progress of each frame
/// and the wall time of all of them.
fn run_gpu(
    ctx: &Context,
    field: &HeightField,
    settings: ReferenceSettings,
    frames: &[LightingFrame],
    sky: Option<(Vec3, Vec3)>,
) -> (Maps, Vec<ReferenceProgress>, Duration) {
    let mut reference = MonteCarloReference::new(ctx, field, settings).expect("reference");
    reference.set_test_sky(sky);
    let texels = u64::from(field.columns * field.rows);
    let (sky_buffer, sun_buffer) = (readback(ctx, "sky", texels * 16), readback(ctx, "sun", texels * 4));
    let mut graph: RenderGraph<ReferenceWork> = RenderGraph::new();
    let region = graph.upload_region("lighting", std::mem::size_of::<LightingFrame>() as u64);
    let images = reference.declare(&mut graph, region, &[]);
    let (sky_id, sun_id) = (
        graph.import_buffer(sky_buffer.clone()),
        graph.import_buffer(sun_buffer.clone()),
    );
    graph.read_back_images(
        "readback",
        vec![(images.sky_light, sky_id), (images.sun_visibility, sun_id)],
    );
    let mut baked = graph.bake(ctx).expect("bake");
    let mut ring = FrameRing::new(ctx).unwrap();
    let mut progress = Vec::new();
    let start = Instant::now();
    for frame in frames {
        let index = ring.wait_for_next().unwrap();
        let mut constants = *frame;
        reference.fill(&mut constants);
        baked.uploads(index).write_pod(region, &constants).unwrap();
        let (work, frame_progress) = reference.prepare(frame);
        progress.push(frame_progress);
        baked.execute(&mut ring, &work, &[]).unwrap();
    }
    baked.finish(&mut ring).unwrap();
    let elapsed = start.elapsed();
    let maps = Maps {
        sky: bytemuck::pod_collect_to_vec(sky_buffer.mapped().unwrap()),
        sun: bytemuck::pod_collect_to_vec(sun_buffer.mapped().unwrap()),
    };
    (maps, progress, elapsed)
}

/// Every texel of the GPU maps against the CPU twin: sky light within 3
/// standard errors (plus f32 rounding), visibilities within 3 binomial
/// standard deviations plus two rays (a ray the f32 tracer decides
/// differently near a grazing contact).
fn compare(field: &HeightField, settings: ReferenceSettings, frame: &LightingFrame, maps: &Maps) {
    let cpu = CpuReference::new(field, settings).unwrap();
    let (sun, albedo) = SunInput::from_frame(frame, settings.bounce_albedo);
    let n = settings.samples as f32;
    let (mut worst, mut mean_dev) = (0.0f32, 0.0f32);
    for r in 0..field.rows {
        for c in 0..field.columns {
            let i = (r * field.columns + c) as usize;
            let e = cpu.texel(c, r, &sun, albedo, &test_sky).unwrap();
            let gpu = Vec3::from_slice(&maps.sky[i][..3]);
            let tolerance = 3.0 * e.standard_error + 1e-3 * e.sky_light.abs() + Vec3::splat(1e-4);
            let deviation = (gpu - e.sky_light).abs();
            assert!(
                deviation.cmple(tolerance).all(),
                "texel ({c}, {r}): GPU {gpu} vs CPU {} ± {}",
                e.sky_light,
                e.standard_error
            );
            worst = worst.max((deviation / tolerance).max_element());
            mean_dev += (deviation / e.sky_light.abs().max(Vec3::splat(1e-3))).max_element();
            for (g, p) in [(maps.sky[i][3], e.sky_visibility), (maps.sun[i], e.sun_visibility)] {
                let sigma = (p * (1.0 - p) / n).sqrt();
                assert!(
                    (g - p).abs() <= 3.0 * sigma + 2.0 / n,
                    "texel ({c}, {r}): visibility {g} vs {p}"
                );
            }
        }
    }
    eprintln!(
        "GPU vs CPU: worst deviation {worst:.3} of the tolerance, mean relative {:.2e}",
        mean_dev / (field.columns * field.rows) as f32
    );
}

#[test]
fn gpu_matches_the_cpu_twin_with_bounces() {
    let (ctx, report) = validated_context();
    {
        let field = rough_field(17, 13);
        let settings = ReferenceSettings {
            samples: 64,
            bounces: 2,
            rows_per_dispatch: 5,
            ..ReferenceSettings::default()
        };
        // The sun separate (bounced), with a wide disc: partial sun visibility.
        let frame = lighting(false, 0.05);
        let (maps, progress, _) = run_gpu(&ctx, &field, settings, &[frame, frame], Some(SKY));
        assert!(progress[0].restarted && progress[0].complete());
        assert!(!progress[1].restarted, "unchanged lighting must not recompute");
        compare(&field, settings, &frame, &maps);
        assert!(
            maps.sun.iter().any(|&v| v > 0.0 && v < 1.0),
            "no partial sun visibility"
        );
        assert!(maps.sky.iter().any(|t| t[3] < 0.9), "no occluded sky");

        // The sun in the environment, one bounce, progressive over frames.
        let settings = ReferenceSettings {
            samples: 32,
            bounces: 1,
            rows_per_frame: Some(4),
            ..ReferenceSettings::default()
        };
        let mut frame = lighting(true, 0.004_654);
        frame.models[3] |= LIGHTING_ALBEDO_OVERRIDE;
        frame.exposure[3] = 0.7;
        let (maps, progress, _) = run_gpu(&ctx, &field, settings, &[frame; 4], Some(SKY));
        assert_eq!(progress.iter().map(|p| p.rows_done).collect::<Vec<_>>(), [4, 8, 12, 13]);
        compare(&field, settings, &frame, &maps);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn flat_field_and_v_valley_on_the_gpu_match_the_analytic_values() {
    let (ctx, report) = validated_context();
    {
        let field = HeightField::from_fn(20, 9, DVec2::new(5.0, 5.0), |_, _| 1200.0);
        let settings = ReferenceSettings {
            samples: 16,
            bounces: 2,
            ..ReferenceSettings::default()
        };
        let sky = (Vec3::new(1.0, 2.0, 4.0), Vec3::ZERO);
        let (maps, _, _) = run_gpu(&ctx, &field, settings, &[lighting(false, 0.004_654)], Some(sky));
        for (t, s) in maps.sky.iter().zip(&maps.sun) {
            assert!((Vec3::from_slice(&t[..3]) - sky.0).abs().max_element() < 1e-5, "{t:?}");
            assert_eq!((t[3], *s), (1.0, 1.0));
        }
        // The bottom of a V valley with 45° walls sees cos 45° of the sky
        // (see the CPU twin's analytic test).
        let tan = 1.0f64;
        let valley = HeightField::from_fn(33, 41, DVec2::new(2.0, 2.0), |c, _| {
            ((f64::from(c) - 16.0).abs() * 2.0 * tan + 100.0) as f32
        });
        let settings = ReferenceSettings {
            samples: 1024,
            bounces: 0,
            ..ReferenceSettings::default()
        };
        let (maps, _, _) = run_gpu(&ctx, &valley, settings, &[lighting(false, 0.004_654)], Some(sky));
        let bottom = maps.sky[20 * 33 + 16];
        assert!((bottom[3] - std::f32::consts::FRAC_1_SQRT_2).abs() < 0.01, "{bottom:?}");
        assert!((bottom[0] - bottom[3]).abs() < 1e-4, "{bottom:?}");
    }
    drop(ctx);
    assert_validation_clean(&report);
}
