//! The GPU's tile generation (`texturing.upsample`, one `texturing.layer*`
//! pass per layer, `texturing.finish`; dissertation §8.2) against its CPU
//! twin (`src/texturing/reference.rs`, which evaluates the tree with
//! `texturing::layers::evaluate`): the atlas's colour texels, read back, equal
//! the CPU's sRGB-encoded colour at the same world positions within
//! `MAX_CODE_DIFFERENCE` (tests/common/atlas.rs) code values, for the default tree and for a tree
//! driven by a rainfall input map, under validation; and a tree of sampled
//! functions (§8.3) on altitude, slope and rainfall, whose direct-mode frame
//! (the same evaluation per pixel) also matches the atlas frame.

mod common;

use alpenglow::io::heightmap::{load_heightmap, HeightmapOptions};
use alpenglow::renderer::{FrameImages, RenderSettings, Renderer, Scene};
use alpenglow::texturing::generation::TextureStreaming;
use alpenglow::texturing::gpu_layout::TexturingMode;
use alpenglow::texturing::layers::LayerTree;
use common::atlas::check_texels_against_cpu;
use common::{assert_validation_clean, data, dump_pngs, jacksboro_field, mean_flip, validated_context};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 90;
/// Mean FLIP of the atlas frame against the direct frame (as tests/texturing_atlas.rs).
const MAX_MEAN_FLIP: f32 = 0.05;

/// A settled frame of the default camera in `mode`, under validation.
/// `readback` (atlas mode): also the atlas, read back, with the frame's page
/// table and the atlas size, compared with the CPU twin on a 6×6 grid of
/// inner texels of every tile the frame draws from.
fn render(name: &str, scene: &Scene, mode: TexturingMode, readback: bool) -> FrameImages {
    let (ctx, report) = validated_context();
    let (images, atlas) = {
        let streaming = TextureStreaming {
            readback,
            ..TextureStreaming::default()
        };
        let settings = RenderSettings {
            texturing: mode,
            texture_streaming: streaming,
            // The textures under test, not the haze between them and the camera.
            lighting: Some(alpenglow::view::Lighting {
                aerial_perspective: false,
                ..Default::default()
            }),
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        let frame = renderer.render_settled(&scene.default_camera(), 16).expect("frame");
        let atlas = readback.then(|| {
            assert!(renderer.pass_names().iter().any(|p| p == "texturing.readback"));
            let atlas = renderer.read_texture_atlas(&frame).expect("atlas readback");
            let table = renderer.texture_page_table().expect("table").expect("atlas mode");
            (atlas, table, streaming.atlas.size)
        });
        let images = renderer.read(&frame).expect("read");
        renderer.finish().expect("finish");
        (images, atlas)
    };
    drop(ctx);
    assert_validation_clean(&report);
    if let Some((atlas, table, atlas_size)) = atlas {
        let tiles = check_texels_against_cpu(name, scene, &atlas, atlas_size, &table);
        assert!(tiles > 5, "{name}: only {tiles} tiles");
    }
    images
}

fn check_atlas_against_cpu(name: &str, scene: &Scene) {
    render(name, scene, TexturingMode::Atlas, true);
}

#[test]
fn atlas_texels_match_the_cpu_reference() {
    let mut scene = Scene::new(jacksboro_field());
    check_atlas_against_cpu("default tree", &scene);
    scene.layers = LayerTree::load(&data("layers-rainfall.toml")).expect("layers");
    scene.input_maps[0] = Some(load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map"));
    check_atlas_against_cpu("rainfall tree", &scene);
}

/// A tree of sampled functions (§8.3): meadow low and gentle and where it
/// rains, scree on middle slopes, snow high up; `lo`, `hi`: the height
/// field's range (the altitude functions' domain).
fn sampled_tree(lo: f32, hi: f32) -> LayerTree {
    let text = format!(
        r#"
        [root]
        name = "rock"
        color = [0.30, 0.27, 0.24]
        roughness = 1.0
        roughness_wavelength = 60.0

        [[root.children]]
        name = "meadow"
        color = [0.12, 0.30, 0.06]
        slope = {{ samples = [1.0, 0.9, 0.4, 0.0] }}
        altitude = {{ samples = [1.0, 1.0, 0.7, 0.3, 0.0], min = {lo}, max = {hi} }}
        rainfall = {{ samples = [0.0, 0.4, 1.0], min = 0.0, max = 255.0 }}
        noise_bias = 1.2
        noise_scale = 0.4
        noise_wavelength = 150.0

        [[root.children]]
        name = "scree"
        color = [0.55, 0.50, 0.42]
        slope = {{ samples = [0.0, 0.3, 1.0, 1.0, 0.6, 0.2], max = 60.0 }}
        elevation = {{ samples = [0.2, 1.0, 0.5] }}

        [[root.children]]
        name = "snow"
        color = [0.88, 0.90, 0.93]
        altitude = {{ samples = [0.0, 0.0, 0.0, 0.5, 1.0, 1.0], min = {lo}, max = {hi} }}
        noise_bias = 1.0
        noise_scale = 0.5
        noise_wavelength = 80.0
        "#
    );
    LayerTree::parse(&text, "sampled tree").expect("sampled tree")
}

#[test]
fn sampled_functions_match_the_cpu_reference_in_atlas_and_direct_mode() {
    let mut scene = Scene::new(jacksboro_field());
    let (lo, hi) = scene.heights.min_max();
    scene.layers = sampled_tree(lo, hi);
    scene.input_maps[0] = Some(load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map"));
    let atlas = render("sampled tree", &scene, TexturingMode::Atlas, true);
    let direct = render("sampled tree", &scene, TexturingMode::Direct, false);
    dump_pngs(
        &[("sampled-atlas", &atlas.rgba8), ("sampled-direct", &direct.rgba8)],
        WIDTH,
        HEIGHT,
    );
    let (mean, _) = mean_flip(&direct.rgba8, &atlas.rgba8, WIDTH, HEIGHT);
    eprintln!("sampled tree: mean FLIP atlas vs direct {mean:.4}");
    assert!(mean <= MAX_MEAN_FLIP, "mean FLIP {mean:.4} > {MAX_MEAN_FLIP}");
    // Every layer dominates somewhere in both frames (classes: 10 + layer).
    for (mode, frame) in [("atlas", &atlas), ("direct", &direct)] {
        for layer in 0..4u32 {
            let share = frame.class.iter().filter(|&&c| c == 10 + layer).count() as f64 / frame.class.len() as f64;
            assert!(share > 0.01, "{mode}: layer {layer} dominates {share:.4} of the frame");
        }
    }
}
