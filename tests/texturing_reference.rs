//! The GPU's tile generation (`texturing.upsample`, one `texturing.layer*`
//! pass per layer, `texturing.finish`; dissertation §8.2) against its CPU
//! twin (`src/texturing/reference.rs`, which evaluates the tree with
//! `texturing::layers::evaluate`): the atlas's colour texels, read back, equal
//! the CPU's sRGB-encoded colour at the same world positions within
//! `MAX_CODE_DIFFERENCE` (tests/common/atlas.rs) code values, for the default tree and for a tree
//! driven by a rainfall input map, under validation.

mod common;

use alpenglow::io::heightmap::{load_heightmap, HeightmapOptions};
use alpenglow::renderer::{RenderSettings, Renderer, Scene};
use alpenglow::texturing::generation::TextureStreaming;
use alpenglow::texturing::layers::LayerTree;
use common::atlas::check_texels_against_cpu;
use common::{assert_validation_clean, data, jacksboro_field, validated_context};

/// Renders until settled, reads the atlas back and compares a 6×6 grid of
/// inner texels of every tile the frame draws from.
fn check_atlas_against_cpu(name: &str, scene: &Scene) {
    let (ctx, report) = validated_context();
    let (atlas, table, atlas_size) = {
        let streaming = TextureStreaming {
            readback: true,
            ..TextureStreaming::default()
        };
        let settings = RenderSettings {
            texture_streaming: streaming,
            ..RenderSettings::new(160, 90)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        assert!(renderer.pass_names().iter().any(|p| p == "texturing.readback"));
        let frame = renderer.render_settled(&scene.default_camera(), 16).expect("frame");
        let atlas = renderer.read_texture_atlas(&frame).expect("atlas readback");
        let table = renderer.texture_page_table().expect("table").expect("atlas mode");
        renderer.finish().expect("finish");
        (atlas, table, streaming.atlas.size)
    };
    drop(ctx);
    assert_validation_clean(&report);
    let tiles = check_texels_against_cpu(name, scene, &atlas, atlas_size, &table);
    assert!(tiles > 5, "{name}: only {tiles} tiles");
}

#[test]
fn atlas_texels_match_the_cpu_reference() {
    let mut scene = Scene::new(jacksboro_field());
    check_atlas_against_cpu("default tree", &scene);
    scene.layers = LayerTree::load(&data("layers-rainfall.toml")).expect("layers");
    scene.input_maps[0] = Some(load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map"));
    check_atlas_against_cpu("rainfall tree", &scene);
}
