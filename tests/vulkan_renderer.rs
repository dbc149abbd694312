//! The renderer on a real device under validation and synchronization
//! validation: render-to-vertex-buffer, frames in flight, readback,
//! determinism, device selection errors. (The render graph's and the
//! descriptor heap's own tests are in `src/graph/tests/device.rs`.)

mod common;

use alpenglow::glam::DVec3;
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, ProceduralTerrain, RasterPath, Renderer, Scene, Settings,
    ShadowSettings, TextureStreaming,
};
use common::{assert_validation_clean, validated_context};

fn small_scene() -> Scene {
    Scene::from_terrain(&ProceduralTerrain::default(), (65, 49), (40.0, 55.0)).expect("procedural terrain")
}

/// `width`×`height` with the default texture streaming and shadow settings
/// (not the ones `Settings::new` sizes for the image).
fn settings(width: u32, height: u32, readback: bool) -> Settings {
    let mut settings = Settings::new(width, height);
    settings.readback = readback;
    settings.texture_streaming = TextureStreaming::default();
    settings.shadows = ShadowSettings::default();
    settings
}

/// The passes of a frame of `scene` drawn by `raster`, in order.
fn expected_passes(scene: &Scene, raster: RasterPath) -> Vec<String> {
    let hardware = raster == RasterPath::Hardware;
    let mut expected: Vec<&str> = vec![
        "lighting.transmittance",
        "lighting.multiscattering",
        "lighting.sky_view",
        "lighting.environment",
        "lighting.sky_light",
        "terrain.warp",
    ];
    // The compute path's terrain.shade shades the sky.
    expected.extend(hardware.then_some("sky"));
    expected.push("texturing.upsample");
    let layers = scene.layers.layers.iter().enumerate();
    let layer_passes = layers.map(|(i, l)| format!("texturing.layer{i}.{}", l.layer.name.replace(' ', "_")));
    let mut expected: Vec<String> = expected.into_iter().map(String::from).collect();
    expected.extend(layer_passes);
    let terrain: &[&str] = match hardware {
        true => &["shadow.clear", "terrain.shadow", "terrain.draw"],
        false => &[
            "terrain.shadow_clear",
            "terrain.shadow",
            "terrain.shadow_big",
            "shadow.copy",
            "terrain.raster_clear",
            "terrain.raster",
            "terrain.raster_big",
            "terrain.shade",
        ],
    };
    expected.push("texturing.finish".into());
    expected.extend(terrain.iter().map(|s| s.to_string()));
    let post = ["aovs", "exposure.meter", "exposure.average", "tonemap", "readback"];
    expected.extend(post.map(String::from));
    expected
}

#[test]
fn render_to_vertex_buffer_frames_in_flight_are_validation_clean() {
    for raster in [RasterPath::Hardware, RasterPath::Compute] {
        frames_in_flight_are_validation_clean(raster);
    }
}

fn frames_in_flight_are_validation_clean(raster: RasterPath) {
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        let mut settings = settings(96, 64, true);
        settings.raster = raster;
        // Two readback slots: the frame two renders back is overwritten.
        settings.readback_slots = 2;
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        assert_eq!(renderer.raster_path(), raster);
        let expected = expected_passes(&scene, raster);
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
    for raster in [RasterPath::Hardware, RasterPath::Compute] {
        renders_are_deterministic_in(raster);
    }
}

fn renders_are_deterministic_in(raster: RasterPath) {
    let (ctx, report) = validated_context();
    {
        let scene = small_scene();
        let mut settings = settings(80, 48, true);
        settings.raster = raster;
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
        let mut renderer = Renderer::new(&ctx, &scene, settings(16, 16, true)).unwrap();
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
        assert!(Renderer::new(&ctx, &scene, settings(0, 16, false)).is_err());
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
}
