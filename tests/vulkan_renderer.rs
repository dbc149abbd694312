//! The renderer on a real device under validation and synchronization
//! validation: render-to-vertex-buffer, frames in flight, readback,
//! descriptor-heap handle reuse, device selection errors.

mod common;

use std::sync::Arc;

use alpenglow::graph::{BufferAccess, BufferInfo, ImageAccess, ImageInfo, RenderGraph, Stage};
use alpenglow::renderer::{Camera, RenderSettings, Renderer, Scene};
use alpenglow::terrain::procedural::ProceduralTerrain;
use alpenglow::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, Context, ContextOptions, DeviceSelector, Format, FrameRing, MemoryLocation,
};
use common::{assert_validation_clean, validated_context};
use glam::{DVec2, DVec3};

fn small_scene() -> Scene {
    let field = ProceduralTerrain::default()
        .try_generate(65, 49, DVec2::new(40.0, 55.0))
        .expect("procedural terrain");
    Scene::new(field)
}

#[test]
fn render_to_vertex_buffer_frames_in_flight_are_validation_clean() {
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        let settings = RenderSettings {
            width: 96,
            height: 64,
            views: Vec::new(),
            msaa: 1,
            motion_blur: None,
            readback: true,
            outputs: Default::default(),
            readback_slots: 3,
            terrain: Default::default(),
            points: Default::default(),
            texturing: Default::default(),
            texture_streaming: Default::default(),
            shadows: Default::default(),
            cache_dir: None,
            lighting: None,
        };
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let layers = scene.layers.layers.iter().enumerate();
        let layer_passes = layers.map(|(i, l)| format!("texturing.layer{i}.{}", l.layer.name.replace(' ', "_")));
        let mut expected: Vec<String> = [
            "lighting.transmittance",
            "lighting.multiscattering",
            "lighting.sky_view",
            "lighting.environment",
            "lighting.sky_light",
            "sky",
            "terrain.warp",
            "texturing.upsample",
        ]
        .map(String::from)
        .to_vec();
        expected.extend(layer_passes);
        expected.extend(
            [
                "texturing.finish",
                "shadow.clear",
                "terrain.shadow",
                "terrain.draw",
                "aovs",
                "exposure.meter",
                "tonemap",
                "readback",
            ]
            .map(String::from),
        );
        assert_eq!(renderer.pass_names(), expected);
        let camera = scene.default_camera();
        // Several frames, two in flight: exercises cross-frame barrier state.
        let mut last = None;
        for _ in 0..4 {
            let frame = renderer.render(&camera).expect("frame");
            if let Some(previous) = last.replace(frame) {
                let images = renderer.read(&previous).expect("readback");
                assert_eq!(images.rgba8.len(), 96 * 64 * 4);
            }
        }
        let last = last.expect("a frame");
        let images = renderer.read(&last).expect("readback");
        // Bottom centre sees terrain drawn from the compute-written vertex buffer;
        // the top row sees sky.
        let bottom = ((63 * 96) + 48) as usize;
        assert!(
            images.depth[bottom].is_finite() && images.depth[bottom] > 0.0,
            "terrain at the bottom"
        );
        assert!(images.depth[48].is_infinite(), "sky at the top");
        // A frame whose readback slot was reused cannot be read any more.
        renderer.render(&camera).expect("frame");
        renderer.render(&camera).expect("frame");
        let err = renderer.read(&last).expect_err("slot reused").to_string();
        assert!(err.contains("overwritten"), "{err}");
        let profiles = renderer.finish().expect("timings");
        assert_eq!(profiles.len(), 6, "every frame's timestamps come back");
        for p in &profiles {
            assert_eq!(p.passes.len(), expected.len());
            assert!(p.passes.iter().all(|t| t.gpu_ms.is_finite() && t.gpu_ms >= 0.0));
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn renders_are_deterministic() {
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        let settings = RenderSettings {
            width: 80,
            height: 48,
            views: Vec::new(),
            msaa: 1,
            motion_blur: None,
            readback: true,
            outputs: Default::default(),
            readback_slots: 3,
            terrain: Default::default(),
            points: Default::default(),
            texturing: Default::default(),
            texture_streaming: Default::default(),
            shadows: Default::default(),
            cache_dir: None,
            lighting: None,
        };
        let camera = scene.default_camera();
        let mut first = Renderer::new(&ctx, &scene, settings.clone()).expect("renderer");
        let a = first.render(&camera).and_then(|f| first.read(&f)).expect("frame a");
        let mut second = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let b = second.render(&camera).and_then(|f| second.read(&f)).expect("frame b");
        assert!(a.rgba8 == b.rgba8, "sRGB bytes differ between identical frames");
        assert!(
            a.hdr.iter().zip(&b.hdr).all(|(x, y)| x.to_bits() == y.to_bits()),
            "HDR differs between identical frames"
        );
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
        assert!(
            (a.class == b.class && a.instance == b.instance)
                && (bits(&a.normal) == bits(&b.normal) && bits(&a.distance) == bits(&b.distance))
                && bits(&a.motion) == bits(&b.motion),
            "the AOVs differ between identical frames"
        );
        first.finish().unwrap();
        second.finish().unwrap();
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn graph_culls_unused_passes_and_writes_a_storage_buffer_drawn_by_the_next_pass() {
    let (ctx, report) = validated_context();
    {
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let target = Arc::new(
            Buffer::new(
                &ctx,
                BufferDesc {
                    name: "result".into(),
                    size: 256,
                    usage: BufferUsageFlags::TRANSFER_DST | BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuToCpu,
                },
            )
            .unwrap(),
        );
        let scratch = graph.create_buffer(
            "scratch",
            BufferInfo {
                size: 256,
                location: MemoryLocation::GpuOnly,
            },
        );
        let unused = graph.create_image("unused", ImageInfo::new(8, 8, Format::R8G8B8A8_UNORM));
        let result = graph.import_buffer(target.clone());
        graph
            .pass("never used")
            .read(scratch, BufferAccess::StorageRead(Stage::Compute))
            .write(unused, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| panic!("a culled pass must not record"));
        graph
            .pass("copy")
            .transfer()
            .read(scratch, BufferAccess::TransferSrc)
            .write(result, BufferAccess::TransferDst)
            .record(move |pass, _| {
                let (src, dst) = (pass.buffer(scratch)?, pass.buffer(result)?);
                pass.cmd().copy_buffer(src, dst, 256);
                Ok(())
            });
        graph.read_back(result);
        let mut baked = graph.bake(&ctx).expect("bake");
        assert_eq!(baked.pass_names(), ["copy"]);
        assert_eq!(baked.culled_passes(), ["never used"]);
        assert!(baked.image(unused).is_none(), "a culled transient is not created");
        let mut frames = FrameRing::new(&ctx).unwrap();
        for _ in 0..3 {
            baked.execute(&mut frames, &(), &[]).unwrap();
        }
        baked.finish(&mut frames).unwrap();
        assert_eq!(baked.take_profiles().len(), 3);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn heap_handles_are_reused_only_after_the_gpu_is_done() {
    let (ctx, report) = validated_context();
    {
        let storage = |name: &str| {
            Buffer::new(
                &ctx,
                BufferDesc {
                    name: name.into(),
                    size: 64,
                    usage: BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
            )
            .unwrap()
        };
        let first = storage("first");
        let handle = first.storage_handle().expect("storage buffers get a heap handle");
        drop(first);
        let second = storage("second");
        assert_ne!(
            second.storage_handle(),
            Some(handle),
            "released handle reused before the GPU finished"
        );
        ctx.wait_idle().unwrap();
        let third = storage("third");
        assert_eq!(
            third.storage_handle(),
            Some(handle),
            "released handle recycled once the GPU is done"
        );
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn missing_devices_and_bad_cameras_are_clear_errors() {
    for selector in [
        DeviceSelector::Name("no-such-gpu-xyz".into()),
        DeviceSelector::Index(99),
    ] {
        let err = Context::new(&ContextOptions {
            validation: true,
            device: selector,
        })
        .expect_err("no such device");
        let text = err.to_string();
        assert!(text.contains("no Vulkan device"), "{text}");
        assert_eq!(text.lines().count(), 1);
    }
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        let mut renderer = Renderer::new(
            &ctx,
            &scene,
            RenderSettings {
                width: 16,
                height: 16,
                views: Vec::new(),
                msaa: 1,
                motion_blur: None,
                readback: true,
                outputs: Default::default(),
                readback_slots: 3,
                terrain: Default::default(),
                points: Default::default(),
                texturing: Default::default(),
                texture_streaming: Default::default(),
                shadows: Default::default(),
                cache_dir: None,
                lighting: None,
            },
        )
        .unwrap();
        let bad = Camera {
            eye: DVec3::ONE,
            target: DVec3::ONE,
            ..scene.default_camera()
        };
        assert!(renderer
            .render(&bad)
            .unwrap_err()
            .to_string()
            .contains("eye equals target"));
        assert!(Renderer::new(
            &ctx,
            &scene,
            RenderSettings {
                width: 0,
                height: 16,
                views: Vec::new(),
                msaa: 1,
                motion_blur: None,
                readback: false,
                outputs: Default::default(),
                readback_slots: 3,
                terrain: Default::default(),
                points: Default::default(),
                texturing: Default::default(),
                texture_streaming: Default::default(),
                shadows: Default::default(),
                cache_dir: None,
                lighting: None,
            }
        )
        .is_err());
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// A simulator hands the renderer to its render thread: `Renderer` is `Send`
/// (a compile-time check; the test fails to build otherwise).
#[test]
fn renderer_is_send() {
    fn assert_send<T: Send>() {}
    assert_send::<Renderer>();
    assert_send::<alpenglow::graph::BakedGraph<alpenglow::view::Frame>>();
}
