//! The GPU's tile generation (`texturing.upsample`, one `texturing.layer*`
//! pass per layer, `texturing.finish`; dissertation §8.2) against its CPU
//! twin (`src/texturing/reference.rs`, which evaluates the tree with
//! `texturing::layers::evaluate`): the atlas's colour texels, read back, equal
//! the CPU's sRGB-encoded colour at the same world positions within
//! [`MAX_CODE_DIFFERENCE`] code values, for the default tree and for a tree
//! driven by a rainfall input map, under validation.

mod common;

use std::collections::HashSet;

use alpenglow::io::heightmap::{load_heightmap, HeightmapOptions};
use alpenglow::renderer::{RenderSettings, Renderer, Scene};
use alpenglow::terrain::geometry_image::TerrainSettings;
use alpenglow::texturing::generation::TextureStreaming;
use alpenglow::texturing::layers::LayerTree;
use alpenglow::texturing::page_table::PageEntry;
use alpenglow::texturing::reference::{srgb8, ReferenceSurface};
use common::{assert_validation_clean, data, jacksboro_field, validated_context};
use glam::DVec2;

/// Largest difference of one 8-bit sRGB channel: the GPU computes in f32,
/// stores colour in half floats between passes and rounds once more.
const MAX_CODE_DIFFERENCE: i32 = 2;

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

    let reference = ReferenceSurface::new(
        &scene.heights,
        &scene.layers,
        &scene.input_maps,
        TerrainSettings::default().noise_seed,
    )
    .expect("reference");
    let mut seen = HashSet::new();
    let entries: Vec<&PageEntry> = (table.entries.iter())
        .filter(|e| seen.insert((e.texture, e.atlas_origin.map(f32::to_bits))))
        .collect();
    let (mut worst, mut total, mut count) = (0i32, 0i64, 0i64);
    for e in &entries {
        let inner = e.inner_texels as u32;
        let spacing = DVec2::from(e.node_size.map(f64::from)) / f64::from(inner);
        for b in 0..6 {
            for a in 0..6 {
                let (i, j) = (a * (inner - 1) / 5, b * (inner - 1) / 5);
                let xy =
                    DVec2::from(e.node_min.map(f64::from)) + (DVec2::new(f64::from(i), f64::from(j)) + 0.5) * spacing;
                let cpu = srgb8(reference.evaluate(xy, spacing.max_element()).color);
                let (x, y) = (e.atlas_origin[0] as u32 + i, e.atlas_origin[1] as u32 + j);
                let texel = ((y * atlas_size + x) * 4) as usize;
                let gpu = &atlas[e.texture as usize][texel..texel + 3];
                for c in 0..3 {
                    let d = (i32::from(gpu[c]) - i32::from(cpu[c])).abs();
                    worst = worst.max(d);
                    total += i64::from(d);
                    count += 1;
                }
                assert!(
                    (0..3).all(|c| (i32::from(gpu[c]) - i32::from(cpu[c])).abs() <= MAX_CODE_DIFFERENCE),
                    "{name}: texel ({x}, {y}) of atlas texture {} at world {xy}: GPU {gpu:?}, CPU {cpu:?}",
                    e.texture
                );
            }
        }
    }
    eprintln!(
        "{name}: {} tiles, {} channels compared, largest difference {worst}, mean {:.4} code values",
        entries.len(),
        count,
        total as f64 / count as f64
    );
    assert!(entries.len() > 5, "{name}: only {} tiles", entries.len());
}

#[test]
fn atlas_texels_match_the_cpu_reference() {
    let mut scene = Scene::new(jacksboro_field());
    check_atlas_against_cpu("default tree", &scene);
    scene.layers = LayerTree::load(&data("layers-rainfall.toml")).expect("layers");
    scene.input_maps[0] = Some(load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map"));
    check_atlas_against_cpu("rainfall tree", &scene);
}
