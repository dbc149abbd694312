//! Sky light on the terrain (§9.3–9.5) on the GPU, under validation and
//! synchronization validation:
//!
//! * the GLSL SH basis equals the CPU one (the sun's delta in the
//!   environment projection is `E · y_i(sun)`);
//! * a flat plane under a constant sky gets sky light L per unit albedo in
//!   every mode (sh with 3 and 5 bands, ao, patches 4 and 8, off);
//! * a valley is less visible and darker than a crest, and a bounce adds light;
//! * a field larger than the device's storage buffers hold bakes at its
//!   capacity (area-averaged) and sees the sky as a bake of the same terrain
//!   sampled at that size does;
//! * the cache: a second bake loads; corrupt, truncated and stale files
//!   are rebuilt to the same data; an unwritable or unreadable cache is
//!   skipped (a warning), the bake goes on.

use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

use crate::graph::{BufferAccess, RenderGraph};
use crate::io::heightmap::HeightField;
use crate::lighting::constants::{LightingFrame, LIGHTING_SUN_IN_ENVIRONMENT, SKY_PREETHAM};
use crate::lighting::sh;
use crate::lighting::sky_light::{BakeSettings, SkyLight, SkyLightBake, ENVIRONMENT_VEC4S};
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::{Frame, FrameLighting, Lighting, SkyLightMode};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, FrameRing, MemoryLocation};
use bytemuck::Zeroable;
use glam::{DVec2, DVec3};

/// Luminance-ish scale of the test sky.
const SKY: f32 = 1000.0;

/// A Preetham frame whose Perez terms vanish: the sky is constant.
fn constant_sky(sun: DVec3, sun_in_environment: bool) -> LightingFrame {
    let mut f = LightingFrame::zeroed();
    f.sun = [sun.x as f32, sun.y as f32, sun.z as f32, 0.004_654];
    f.sun_irradiance = [5000.0, 4000.0, 3000.0, 0.0];
    f.zenith = [SKY, 0.3127, 0.3290, 3.0];
    f.perez_norm = [1.0, 1.0, 1.0, 0.0];
    f.models = [
        SKY_PREETHAM,
        0,
        0,
        if sun_in_environment {
            LIGHTING_SUN_IN_ENVIRONMENT
        } else {
            0
        },
    ];
    f
}

fn lighting(mode: SkyLightMode, bands: u32, patches: u32) -> Lighting {
    Lighting {
        sky_light: mode,
        sh_bands: bands,
        sky_patches: patches,
        ..Lighting::default()
    }
}

fn host_buffer(ctx: &Context, name: &str, size: u64) -> Arc<Buffer> {
    Arc::new(
        Buffer::new(
            ctx,
            BufferDesc {
                name: name.into(),
                size,
                usage: BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )
        .unwrap(),
    )
}

/// Per frame: (environment as vec4s, sky-light map as RGBA f32).
type Output = (Vec<[f32; 4]>, Vec<[f32; 4]>);

/// Runs the two per-frame passes once per (lighting constants, lighting).
fn run_frames(ctx: &Context, sky: &SkyLight, frames_in: &[(LightingFrame, Lighting)]) -> Vec<Output> {
    let texels = sky.bake().texels();
    let mut out = Vec::new();
    for (constants, lighting) in frames_in {
        let mut graph: RenderGraph<Frame<()>> = RenderGraph::new();
        let region = graph.upload_region("lighting", std::mem::size_of::<LightingFrame>() as u64);
        let ids = sky.declare(&mut graph, region, &[], |_| true);
        let env = host_buffer(ctx, "environment readback", u64::from(ENVIRONMENT_VEC4S) * 16);
        let map = host_buffer(ctx, "map readback", texels * 16);
        let (env_id, map_id) = (graph.import_buffer(env.clone()), graph.import_buffer(map.clone()));
        let environment = ids.environment;
        graph
            .pass("environment readback")
            .transfer()
            .read(environment, BufferAccess::TransferSrc)
            .write(env_id, BufferAccess::TransferDst)
            .record(move |pass, _| {
                let (src, dst) = (pass.buffer(environment)?, pass.buffer(env_id)?);
                pass.cmd().copy_buffer(src, dst, src.size());
                Ok(())
            });
        graph.read_back(env_id);
        graph.read_back_images("map readback", vec![(ids.map, map_id)]);
        let mut baked = graph.bake(ctx).unwrap();
        let mut frames = FrameRing::new(ctx).unwrap();
        let next = frames.wait_for_next().unwrap();
        let mut constants = *constants;
        sky.fill(&mut constants);
        baked.uploads(next).write_pod(region, &constants).unwrap();
        baked
            .execute(
                &mut frames,
                &Frame::new(next, Vec::new(), FrameLighting::new(*lighting).unwrap()),
                &[],
            )
            .unwrap();
        baked.finish(&mut frames).unwrap();
        let vec4s = |b: &Buffer| bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(b.mapped().unwrap());
        out.push((vec4s(&env), vec4s(&map)));
    }
    out
}

fn bake(ctx: &Context, field: &HeightField, settings: BakeSettings) -> SkyLightBake {
    SkyLightBake::bake(ctx, field, &settings, None, &mut |_| {}).unwrap()
}

#[test]
fn the_gpu_basis_is_the_cpu_basis() {
    let (ctx, report) = validated_context();
    {
        let field = HeightField::from_fn(9, 9, DVec2::ONE, |_, _| 0.0);
        let sky = SkyLight::new(&ctx, bake(&ctx, &field, BakeSettings::default())).unwrap();
        let l = lighting(SkyLightMode::Sh, 5, 8);
        for sun in [
            DVec3::new(0.3, -0.5, 0.8),
            DVec3::new(-0.7, 0.2, 0.2),
            DVec3::new(0.1, 0.9, -0.3),
        ] {
            let sun = sun.normalize();
            let out = run_frames(
                &ctx,
                &sky,
                &[(constant_sky(sun, true), l), (constant_sky(sun, false), l)],
            );
            let y = sh::basis_all(sun);
            for (i, y) in y.iter().enumerate() {
                for ch in 0..3 {
                    let delta = f64::from(out[0].0[i][ch] - out[1].0[i][ch]);
                    let want = f64::from(constant_sky(sun, true).sun_irradiance[ch]) * y;
                    assert!(
                        (delta - want).abs() < 0.05,
                        "coefficient {i} channel {ch}: {delta} vs {want}"
                    );
                }
            }
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn a_flat_plane_under_a_constant_sky_gets_the_sky_radiance() {
    let (ctx, report) = validated_context();
    {
        let field = HeightField::from_fn(24, 17, DVec2::new(30.0, 20.0), |_, _| 123.0);
        let sky = SkyLight::new(&ctx, bake(&ctx, &field, BakeSettings::default())).unwrap();
        let sun = DVec3::new(0.3, 0.4, 0.5).normalize();
        let modes = [
            lighting(SkyLightMode::Sh, 5, 8),
            lighting(SkyLightMode::Sh, 3, 8),
            lighting(SkyLightMode::Ao, 5, 8),
            lighting(SkyLightMode::Patches, 5, 8),
            lighting(SkyLightMode::Patches, 5, 4),
            lighting(SkyLightMode::Off, 5, 8),
        ];
        let frames: Vec<_> = modes.iter().map(|l| (constant_sky(sun, false), *l)).collect();
        for (out, l) in run_frames(&ctx, &sky, &frames).iter().zip(&modes) {
            let (env, map) = out;
            // The sky is constant (white, luminance SKY) above the horizon;
            // below it the model darkens the horizon towards the ground
            // (sky.glsl), which the flat plane does not see.
            let radiance = [f64::from(SKY); 3];
            assert!(env[0][0] > 1.0 && (f64::from(env[0][0]) / (2.0 * PI.sqrt())) < radiance[0]);
            for texel in map {
                for ch in 0..3 {
                    let rel = (f64::from(texel[ch]) - radiance[ch]).abs() / radiance[ch];
                    // SH: the band-limited transfer rings a little into the darker lower hemisphere.
                    let tolerance = if l.sky_light == SkyLightMode::Sh { 0.03 } else { 0.01 };
                    assert!(rel < tolerance, "{:?}: {} vs {}", l.sky_light, texel[ch], radiance[ch]);
                }
                assert!((texel[3] - 1.0).abs() < 1e-3, "visibility {}", texel[3]);
            }
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn a_valley_sees_less_sky_than_a_crest() {
    let (ctx, report) = validated_context();
    {
        // Ridges along y at columns 0, 32, 64; valleys at 16 and 48.
        let field = HeightField::from_fn(65, 33, DVec2::new(10.0, 10.0), |c, _| {
            60.0 * (2.0 * std::f32::consts::PI * c as f32 / 32.0).cos()
        });
        let direct = bake(
            &ctx,
            &field,
            BakeSettings {
                bounces: 0,
                ..BakeSettings::default()
            },
        );
        let bounced = bake(
            &ctx,
            &field,
            BakeSettings {
                bounces: 2,
                ..BakeSettings::default()
            },
        );
        let data = direct.read_back(&ctx).unwrap();
        let sun = DVec3::new(0.0, 0.6, 0.8);
        let frame = [(constant_sky(sun, false), lighting(SkyLightMode::Sh, 5, 8))];
        let (crest, valley) = (16 * 65 + 32, 16 * 65 + 16);
        let lit = |sky: SkyLightBake| run_frames(&ctx, &SkyLight::new(&ctx, sky).unwrap(), &frame).remove(0).1;
        let (d, b) = (lit(direct), lit(bounced));
        assert!((d[crest][3] - 1.0).abs() < 1e-3, "crest visibility {}", d[crest][3]);
        assert!(d[valley][3] < 0.9, "valley visibility {}", d[valley][3]);
        assert!(
            d[valley][1] < 0.9 * d[crest][1],
            "valley {} vs crest {}",
            d[valley][1],
            d[crest][1]
        );
        assert!(
            b[valley][1] > d[valley][1] * 1.01,
            "a bounce adds light: {} vs {}",
            b[valley][1],
            d[valley][1]
        );
        assert!(b[valley][1] < d[crest][1]);
        // The horizon map towards +X (tile 0, red) at the valley: the
        // steepest rise max_d 60 (1 − cos(π d / 16)) / (10 d) is at d ≈ 11.9.
        let map: Vec<f32> = bytemuck::pod_collect_to_vec(&data.horizon);
        let angle = map[(16 * 130 + 16) * 4];
        assert!((f64::from(angle) - 0.7066).abs() < 0.03, "horizon {angle}");
    }
    drop(ctx);
    assert_validation_clean(&report);
}

fn cache_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-sky-light-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn the_cache_is_used_and_rebuilt_when_damaged() {
    let (ctx, report) = validated_context();
    {
        let field = HeightField::from_fn(20, 12, DVec2::new(5.0, 7.0), |c, r| ((c * 7 + r * 3) % 11) as f32);
        let settings = BakeSettings::default();
        let dir = cache_dir("damage");
        let mut calls = 0;
        let first = SkyLightBake::bake(&ctx, &field, &settings, Some(&dir), &mut |f| {
            assert!((0.0..=1.0).contains(&f));
            calls += 1;
        })
        .unwrap();
        assert!(!first.from_cache && calls >= 3);
        let fresh = first.read_back(&ctx).unwrap();
        let files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        assert_eq!(files.len(), 1);
        let path = files[0].clone();
        let again = |ctx: &Context| SkyLightBake::bake(ctx, &field, &settings, Some(&dir), &mut |_| {}).unwrap();
        let cached = again(&ctx);
        assert!(cached.from_cache);
        assert_eq!(cached.read_back(&ctx).unwrap(), fresh);
        let bytes = std::fs::read(&path).unwrap();
        let mut corrupt = bytes.clone();
        corrupt[bytes.len() / 2] ^= 0x40;
        for damaged in [corrupt, bytes[..bytes.len() / 3].to_vec(), b"garbage".to_vec()] {
            std::fs::write(&path, damaged).unwrap();
            let rebuilt = again(&ctx);
            assert!(!rebuilt.from_cache);
            assert_eq!(rebuilt.read_back(&ctx).unwrap(), fresh);
            assert_eq!(std::fs::read(&path).unwrap(), bytes, "the rebuilt file is rewritten");
        }
        // Stale: the file of other settings under this key's name.
        let other = BakeSettings { bounces: 0, ..settings };
        SkyLightBake::bake(&ctx, &field, &other, Some(&dir), &mut |_| {}).unwrap();
        let other_path = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| *p != path)
            .unwrap();
        std::fs::copy(&other_path, &path).unwrap();
        let rebuilt = again(&ctx);
        assert!(!rebuilt.from_cache);
        assert_eq!(rebuilt.read_back(&ctx).unwrap(), fresh);
        // Unwritable (a file where the cache directory should be) and
        // unreadable (a directory where the cache file should be): the cache
        // is optional, the bake goes on without it (and warns).
        let blocker = cache_dir("blocked");
        std::fs::write(&blocker, b"not a directory").unwrap();
        let unwritable = SkyLightBake::bake(&ctx, &field, &settings, Some(&blocker.join("sub")), &mut |_| {})
            .expect("an unwritable cache is only a warning");
        assert!(!unwritable.from_cache);
        assert_eq!(unwritable.read_back(&ctx).unwrap(), fresh);
        std::fs::remove_file(&path).unwrap();
        std::fs::create_dir(&path).unwrap();
        let unreadable = again(&ctx);
        assert!(!unreadable.from_cache);
        assert_eq!(unreadable.read_back(&ctx).unwrap(), fresh);
        assert!(path.is_dir(), "what is not a cache file is never replaced");
        let _ = std::fs::remove_file(&blocker);
        let _ = std::fs::remove_dir_all(&dir);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// A field beyond the device's storage-buffer range (lavapipe: about 677²
/// texels of a 3-band transfer) used to be an error; it bakes at the
/// capacity, area-averaged over the same extent, and its sky visibility
/// matches an independent bake of the same continuous terrain sampled at
/// that size.
#[test]
fn a_field_beyond_the_device_bakes_at_its_capacity() {
    use crate::lighting::sky_light::fit;
    let (ctx, report) = validated_context();
    {
        let settings = BakeSettings {
            sh_bands: 3,
            bounces: 0,
            ..BakeSettings::default()
        };
        let (side, texels) = fit::bake_capacity(&settings, ctx.max_storage_buffer_range(), ctx.max_image_dimension());
        let n = ((texels as f64).sqrt() as u32 + 40).min(side + 40);
        let extent = 5000.0;
        let terrain = |x: f64, y: f64| {
            (120.0 * (x / 400.0).sin() * (y / 300.0).cos() + 40.0 * (x / 170.0 + y / 230.0).cos()) as f32
        };
        let sampled = |n: u32| {
            let step = extent / f64::from(n - 1);
            HeightField::from_fn(n, n, DVec2::splat(step), |c, r| {
                terrain(f64::from(c) * step, f64::from(r) * step)
            })
        };
        let big = sampled(n);
        let fitted = SkyLightBake::fitted(&ctx, &big, &settings).into_owned();
        assert!(fitted.columns < n && u64::from(fitted.columns) * u64::from(fitted.rows) <= texels);
        let coarse = bake(&ctx, &big, settings);
        assert_eq!((coarse.columns, coarse.rows), (fitted.columns, fitted.rows));
        let reference = bake(&ctx, &sampled(fitted.columns), settings);
        let visibility = |b: &SkyLightBake| -> Vec<f32> {
            let surface: Vec<f32> = bytemuck::pod_collect_to_vec(&b.read_back(&ctx).unwrap().surface);
            surface.chunks_exact(8).map(|t| t[3]).collect()
        };
        let (got, want) = (visibility(&coarse), visibility(&reference));
        assert_eq!(got.len(), want.len());
        let diffs: Vec<f32> = got.iter().zip(&want).map(|(a, b)| (a - b).abs()).collect();
        let mean = diffs.iter().sum::<f32>() / diffs.len() as f32;
        let max = diffs.iter().copied().fold(0.0, f32::max);
        assert!(
            mean < 0.01 && max < 0.1,
            "sky visibility differs: mean {mean}, max {max}"
        );
        let spread = want.iter().copied().fold(1.0, f32::min);
        assert!(
            spread < 0.95,
            "the terrain should occlude some sky (min visibility {spread})"
        );
    }
    drop(ctx);
    assert_validation_clean(&report);
}
