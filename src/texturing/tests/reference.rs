//! The GPU's tile generation (`texturing.upsample`, one `texturing.layer*`
//! pass per layer, `texturing.finish`; dissertation §8.2) against its CPU
//! twin (`src/texturing/reference.rs`, which evaluates the tree with
//! `surface::layers::evaluate`): the atlas's colour texels, read back, equal
//! the CPU's sRGB-encoded colour at the same world positions within
//! `MAX_CODE_DIFFERENCE` (src/test_support/atlas.rs) code values, for the default tree and for a tree
//! driven by a rainfall input map, under validation; and a tree of sampled
//! functions (§8.3) on altitude, slope and rainfall, whose direct-mode frame
//! (the same evaluation per pixel) also matches the atlas frame.
//!
//! With `ALPENGLOW_DUMP=DIR` the colour textures of the atlas, as read back
//! and compared, are written as `N-TREE-atlas-texture-I.png` (Fig. 8.7):
//! the inner texels of the tiles the frame draws from, the rest black.

use crate::io::heightmap::{load_heightmap, HeightmapOptions};
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::surface::layers::LayerTree;
use crate::terrain::geometry_image::TerrainSettings;
use crate::test_support::atlas::{check_texels_against_cpu, used_tiles};
use crate::test_support::{assert_validation_clean, data, dump_pngs, jacksboro_field, mean_flip, validated_context};
use crate::texturing::generation::TextureStreaming;
use crate::texturing::reference::ReferenceSurface;
use glam::DVec2;

const WIDTH: u32 = 160;
const HEIGHT: u32 = 90;
/// Mean FLIP of the atlas frame against the direct frame (as src/texturing/tests/atlas.rs).
const MAX_MEAN_FLIP: f32 = 0.05;

/// A settled frame of `camera` in `mode`, under validation.
/// `readback` (atlas mode): also the atlas, read back, with the frame's page
/// table and the atlas size, compared with the CPU twin on a 6×6 grid of
/// inner texels of every tile the frame draws from.
fn render(name: &str, scene: &Scene, camera: &Camera, mode: TexturingMode, readback: bool) -> FrameImages {
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
            lighting: Some(crate::view::Lighting {
                aerial_perspective: false,
                ..Default::default()
            }),
            ..RenderSettings::new(WIDTH, HEIGHT)
        };
        let mut renderer = Renderer::new(&ctx, scene, settings).expect("renderer");
        let frame = renderer.render_settled(camera, 16).expect("frame");
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
        // Fig. 8.7 (a part of the texture atlas): the tiles in use, as read back.
        for (i, texture) in used_tiles(&atlas, atlas_size, &table) {
            let what = format!("{}-atlas-texture-{i}", name.replace(' ', "-"));
            dump_pngs(&[(&what, &texture)], atlas_size, atlas_size);
        }
    }
    images
}

fn check_atlas_against_cpu(name: &str, scene: &Scene) {
    render(name, scene, &scene.default_camera(), TexturingMode::Atlas, true);
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

/// Atlas texels against the CPU twin, and the atlas frame against the
/// direct frame; every layer in `layers` dominates more than 1 % of both
/// frames (classes: 10 + layer). Returns the atlas frame.
fn check_atlas_direct_and_cpu(name: &str, scene: &Scene, camera: &Camera, layers: &[u32]) -> FrameImages {
    let atlas = render(name, scene, camera, TexturingMode::Atlas, true);
    let direct = render(name, scene, camera, TexturingMode::Direct, false);
    let names = (format!("{name}-atlas"), format!("{name}-direct"));
    dump_pngs(&[(&names.0, &atlas.rgba8), (&names.1, &direct.rgba8)], WIDTH, HEIGHT);
    let (mean, _) = mean_flip(&direct.rgba8, &atlas.rgba8, WIDTH, HEIGHT);
    eprintln!("{name}: mean FLIP atlas vs direct {mean:.4}");
    assert!(mean <= MAX_MEAN_FLIP, "{name}: mean FLIP {mean:.4} > {MAX_MEAN_FLIP}");
    for (mode, frame) in [("atlas", &atlas), ("direct", &direct)] {
        for &layer in layers {
            let share = frame.class.iter().filter(|&&c| c == 10 + layer).count() as f64 / frame.class.len() as f64;
            assert!(
                share > 0.01,
                "{name} {mode}: layer {layer} dominates {share:.4} of the frame"
            );
        }
    }
    atlas
}

#[test]
fn sampled_functions_match_the_cpu_reference_in_atlas_and_direct_mode() {
    let mut scene = Scene::new(jacksboro_field());
    let (lo, hi) = scene.heights.min_max();
    scene.layers = sampled_tree(lo, hi);
    scene.input_maps[0] = Some(load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map"));
    check_atlas_direct_and_cpu("sampled tree", &scene, &scene.default_camera(), &[0, 1, 2, 3]);
}

/// 3 km from the height field's highest sample towards the terrain's
/// centre, 800 m above it, looking at it (where the snow is).
fn peak_camera(scene: &Scene) -> Camera {
    let field = &scene.heights;
    let (peak, top) =
        (field.heights.iter().enumerate()).fold((0, f32::MIN), |best, (i, &h)| if h > best.1 { (i, h) } else { best });
    let columns = field.columns as usize;
    let at = DVec2::new((peak % columns) as f64, (peak / columns) as f64) * field.spacing;
    let eye = at + (field.extent() * 0.5 - at).normalize_or_zero() * 3000.0;
    Camera {
        eye: eye.extend(f64::from(top) + 800.0),
        target: at.extend(f64::from(top) - 200.0),
        ..scene.default_camera()
    }
}

/// `height_blur` (§8.2.3, snow in furrows): examples/layers/snow_in_furrows.toml
/// plus a second radius (a lower "firn" layer) evaluate alike on the CPU,
/// in the atlas and per pixel, and the blur changes the layers.
#[test]
fn blurred_heights_match_the_cpu_reference_in_atlas_and_direct_mode() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/layers/snow_in_furrows.toml");
    let text = std::fs::read_to_string(&path).expect("example");
    let firn = "\n[[root.children]]\nname = \"firn\"\ncolor = [0.70, 0.72, 0.78]\nheight_blur = 400.0\n\
                elevation = { samples = [0.0, 0.3, 1.0, 1.0], min = 0.55, max = 0.8 }\n\
                slope = { samples = [1.0, 1.0, 0.2, 0.0], max = 40.0 }\n";
    let mut scene = Scene::new(jacksboro_field());
    scene.layers = LayerTree::parse(&format!("{text}{firn}"), "snow and firn").expect("layers");
    assert_eq!(scene.layers.blur_radii(), [100.0, 400.0]);
    let snow = scene
        .layers
        .layers
        .iter()
        .position(|l| l.layer.name == "snow")
        .expect("snow") as u32;
    let camera = peak_camera(&scene);
    check_atlas_direct_and_cpu("blurred", &scene, &camera, &[0, snow, snow + 1]);
    // The blur matters: on the CPU twin, the snow and firn coverage of the
    // same tree without height_blur differs on a 24 × 24 grid of points
    // over the 6 km around the peak.
    let mut sharp = scene.layers.clone();
    sharp.layers.iter_mut().for_each(|l| l.layer.height_blur = None);
    let seed = TerrainSettings::default().noise_seed;
    let reference = |tree| ReferenceSurface::new(&scene.heights, tree, &scene.input_maps, seed).expect("cpu");
    let (with, without) = (reference(&scene.layers), reference(&sharp));
    let peak = camera.target.truncate();
    let (mut changed, mut covered) = (0, 0);
    for j in 0..24 {
        for i in 0..24 {
            let xy = peak + (DVec2::new(f64::from(i), f64::from(j)) / 23.0 - 0.5) * 6000.0;
            let snow_and_firn = |r: &ReferenceSurface| {
                let c = r.evaluate(xy, 10.0).coverage;
                c[snow as usize] + c[snow as usize + 1]
            };
            let (a, b) = (snow_and_firn(&with), snow_and_firn(&without));
            changed += usize::from((a - b).abs() > 0.1);
            covered += usize::from(a.max(b) > 0.1);
        }
    }
    eprintln!("blurred: snow or firn at {covered} of 576 points, changed by height_blur at {changed}");
    assert!(changed * 5 > covered && covered > 50, "{changed} of {covered}");
}
