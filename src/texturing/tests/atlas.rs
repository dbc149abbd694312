//! Cached procedural textures (dissertation §8.2) on the GPU, under
//! validation and synchronization validation:
//!
//! * the atlas against its reference, the same layer tree evaluated per
//!   pixel (`--texturing direct`): mean FLIP ≤ [`MAX_MEAN_FLIP`] on the
//!   default scene and on the real Jacksboro DEM;
//! * seams: pixels where neighbouring pixels are coloured from different
//!   tiles (found through the frame's page table) are no worse than
//!   [`MAX_SEAM_FLIP`] in mean FLIP against the reference;
//! * extra input maps (rainfall) steer the layers in both modes;
//! * streaming over a flythrough: no frame generates more than the budget,
//!   the hit rate exceeds 95 %, and a small atlas evicts tiles and still
//!   matches the reference once settled.

use crate::io::heightmap::{load_heightmap, HeightmapOptions};
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::surface::layers::LayerTree;
use crate::test_support::{
    assert_validation_clean, data, dump_pngs, flip_errors, jacksboro_field, jacksboro_valley_camera, mean_flip,
    validated_context,
};
use crate::texturing::atlas::{AtlasSettings, GenerationBudget};
use crate::texturing::generation::{TextureFrameStats, TextureStreaming};
use crate::texturing::page_table::PageTable;
use glam::{DVec2, DVec3};

/// Mean FLIP of the atlas against the direct reference (the bound).
const MAX_MEAN_FLIP: f32 = 0.05;
/// Mean FLIP over tile-border pixels.
const MAX_SEAM_FLIP: f32 = 0.05;
const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
const SETTLE_FRAMES: u32 = 16;

fn settings(texturing: TexturingMode, streaming: TextureStreaming) -> RenderSettings {
    RenderSettings {
        texturing,
        texture_streaming: streaming,
        // The textures under test, not the haze between them and the camera.
        lighting: Some(crate::view::Lighting {
            aerial_perspective: false,
            ..Default::default()
        }),
        ..RenderSettings::new(WIDTH, HEIGHT)
    }
}

/// A settled frame of `camera` in `mode`, with the atlas's page table.
fn render(scene: &Scene, camera: &Camera, mode: TexturingMode) -> (FrameImages, Option<PageTable>) {
    let (ctx, report) = validated_context();
    let out = {
        let mut renderer = Renderer::new(&ctx, scene, settings(mode, TextureStreaming::default())).expect("renderer");
        let frame = renderer.render_settled(camera, SETTLE_FRAMES).expect("frame");
        let table = renderer.texture_page_table().expect("page table");
        let images = renderer.read(&frame).expect("read");
        renderer.finish().expect("finish");
        (images, table)
    };
    drop(ctx);
    assert_validation_clean(&report);
    out
}

/// World xy of every terrain pixel (None for sky), from the view depth.
fn world_xy(frame: &FrameImages, camera: &Camera) -> Vec<Option<DVec2>> {
    let (right, up, forward) = crate::view::View::new(*camera, frame.width, frame.height).ray_basis();
    let (right, up, forward) = (right.as_dvec3(), up.as_dvec3(), forward.as_dvec3());
    (0..frame.height)
        .flat_map(|y| (0..frame.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = f64::from(frame.depth[(y * frame.width + x) as usize]);
            if !d.is_finite() || d >= camera.far * 0.99 {
                return None;
            }
            let ndc_x = (f64::from(x) + 0.5) / f64::from(frame.width) * 2.0 - 1.0;
            let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(frame.height) * 2.0;
            let p: DVec3 = camera.eye + d * (forward + ndc_x * right + ndc_y * up);
            Some(p.truncate())
        })
        .collect()
}

/// Pixels whose right or lower neighbour is coloured from another tile.
fn seam_pixels(frame: &FrameImages, camera: &Camera, table: &PageTable, extent: DVec2) -> Vec<bool> {
    let xy = world_xy(frame, camera);
    let tile = |i: usize| {
        xy[i]
            .and_then(|p| table.lookup(p, extent))
            .map(|e| (e.texture, e.atlas_origin.map(f32::to_bits)))
    };
    let tiles: Vec<_> = (0..xy.len()).map(tile).collect();
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut seam = vec![false; w * h];
    for y in 0..h - 1 {
        for x in 0..w - 1 {
            let i = y * w + x;
            for j in [i + 1, i + w] {
                if let (Some(a), Some(b)) = (tiles[i], tiles[j]) {
                    if a != b {
                        seam[i] = true;
                        seam[j] = true;
                    }
                }
            }
        }
    }
    seam
}

fn check_against_direct(name: &str, scene: &Scene, camera: &Camera) {
    let (atlas, table) = render(scene, camera, TexturingMode::Atlas);
    let (direct, _) = render(scene, camera, TexturingMode::Direct);
    let names = (format!("{name}-atlas"), format!("{name}-direct"));
    dump_pngs(&[(&names.0, &atlas.rgba8), (&names.1, &direct.rgba8)], WIDTH, HEIGHT);
    let (mean, _) = mean_flip(&direct.rgba8, &atlas.rgba8, WIDTH, HEIGHT);
    let values = flip_errors(&direct.rgba8, &atlas.rgba8, WIDTH, HEIGHT);
    let seams = seam_pixels(
        &atlas,
        camera,
        &table.expect("atlas page table"),
        scene.heights.extent(),
    );
    let seam_values: Vec<f32> = values.iter().zip(&seams).filter(|(_, &s)| s).map(|(&v, _)| v).collect();
    let seam_mean = seam_values.iter().sum::<f32>() / seam_values.len().max(1) as f32;
    eprintln!(
        "{name}: mean FLIP atlas vs direct {mean:.4}; {} seam pixels, their mean FLIP {seam_mean:.4}",
        seam_values.len()
    );
    assert!(mean <= MAX_MEAN_FLIP, "{name}: mean FLIP {mean:.4} > {MAX_MEAN_FLIP}");
    assert!(
        seam_values.len() > 100,
        "{name}: only {} seam pixels",
        seam_values.len()
    );
    assert!(
        seam_mean <= MAX_SEAM_FLIP,
        "{name}: seam FLIP {seam_mean:.4} > {MAX_SEAM_FLIP}"
    );
}

#[test]
fn default_scene_atlas_matches_direct_reference() {
    // The terrain and rocks of the default scene: plants would only add the
    // same splats to both renders.
    let mut scene = Scene::default_terrain().expect("scene");
    scene.add_rocks(crate::renderer::scene::DEFAULT_ROCKS.2).expect("rocks");
    check_against_direct("default", &scene, &scene.default_camera());
}

#[test]
fn real_dem_atlas_matches_direct_reference() {
    let scene = Scene::new(jacksboro_field());
    check_against_direct("jacksboro-oblique", &scene, &scene.default_camera());
    check_against_direct("jacksboro-valley", &scene, &jacksboro_valley_camera());
}

/// A driver's view, 2 m above the ground of the real DEM looking along it:
/// the finest nodes get the larger tiles (§8.2.4), every tile fits, and the
/// atlas still matches the reference.
#[test]
fn ground_level_view_settles_and_matches_direct_reference() {
    let scene = Scene::new(jacksboro_field());
    let (x, y) = (15000.0, 12000.0);
    let ground = |x: f64, y: f64| crate::surface::bspline::sample_bspline(&scene.heights, x, y);
    let camera = Camera {
        eye: DVec3::new(x, y, ground(x, y) + 2.0),
        target: DVec3::new(x + 100.0, y + 60.0, ground(x + 100.0, y + 60.0) + 1.0),
        up: DVec3::Z,
        fov_y_deg: 60.0,
        near: 0.1,
        far: 100000.0,
    };
    check_against_direct("ground", &scene, &camera);
}

/// A low flight over the Jacksboro DEM: `frames` cameras `step` metres apart.
fn flight(frames: usize, step: f64) -> Vec<Camera> {
    (0..frames)
        .map(|i| {
            let eye = DVec3::new(6000.0 + step * i as f64, 8000.0 + 0.5 * step * i as f64, 1100.0);
            Camera {
                eye,
                target: eye + DVec3::new(3000.0, 1500.0, -500.0),
                up: DVec3::Z,
                fov_y_deg: 50.0,
                near: 5.0,
                far: 100000.0,
            }
        })
        .collect()
}

/// Renders `cameras`; returns every frame's texture statistics and the last frame.
fn fly(scene: &Scene, cameras: &[Camera], streaming: TextureStreaming) -> (Vec<TextureFrameStats>, FrameImages) {
    let (ctx, report) = validated_context();
    let out = {
        let mut renderer = Renderer::new(&ctx, scene, settings(TexturingMode::Atlas, streaming)).expect("renderer");
        for camera in cameras {
            renderer.render(camera).expect("frame");
        }
        let last = cameras.last().expect("a camera");
        let frame = renderer.render_settled(last, SETTLE_FRAMES).expect("settled frame");
        let images = renderer.read(&frame).expect("read");
        renderer.finish().expect("finish");
        (renderer.take_texture_stats().expect("stats"), images)
    };
    drop(ctx);
    assert_validation_clean(&report);
    out
}

#[test]
fn flythrough_stays_within_budget_and_hits_the_cache() {
    let scene = Scene::new(jacksboro_field());
    let cameras = flight(40, 10.0);
    let streaming = TextureStreaming {
        budget: GenerationBudget {
            tiles: 8,
            texels: 8 * 128 * 128,
            gpu_time: None,
        },
        ..TextureStreaming::default()
    };
    let (stats, _) = fly(&scene, &cameras, streaming);
    assert!(stats.len() >= cameras.len());
    for s in &stats {
        assert!(s.tiles.generated <= 8, "frame {}: {:?}", s.frame, s.tiles);
        assert!(s.texels_generated <= 8 * 128 * 128, "frame {}: {:?}", s.frame, s.tiles);
    }
    // After the first frames filled the atlas, the flight reuses tiles.
    let steady = &stats[8..cameras.len()];
    let (hits, visible): (usize, usize) = steady
        .iter()
        .fold((0, 0), |(h, v), s| (h + s.tiles.hits, v + s.tiles.visible));
    let hit_rate = hits as f64 / visible as f64;
    let generated: usize = steady.iter().map(|s| s.tiles.generated).sum();
    eprintln!(
        "flythrough: hit rate {hit_rate:.4} over {} frames, {generated} tiles generated",
        steady.len()
    );
    assert!(hit_rate > 0.95, "hit rate {hit_rate:.4}");
    assert!(generated > 0, "the flight must need new tiles");
}

#[test]
fn small_atlas_evicts_and_still_matches_reference() {
    let scene = Scene::new(jacksboro_field());
    let cameras = flight(12, 150.0);
    let mut streaming = TextureStreaming::default();
    streaming.atlas = AtlasSettings {
        size: 1024,
        textures: [1; 8],
        ..streaming.atlas
    };
    let (stats, atlas) = fly(&scene, &cameras, streaming);
    let evicted: usize = stats.iter().map(|s| s.tiles.evicted).sum();
    assert!(
        evicted > 0,
        "one texture per size must evict over this flight: {stats:?}"
    );
    let last = cameras.last().expect("camera");
    let (direct, _) = render(&scene, last, TexturingMode::Direct);
    let (mean, _) = mean_flip(&direct.rgba8, &atlas.rgba8, WIDTH, HEIGHT);
    eprintln!("small atlas: {evicted} tiles evicted; last frame mean FLIP {mean:.4} against direct");
    assert!(mean <= MAX_MEAN_FLIP, "mean FLIP {mean:.4}");
}

/// A tree whose layers follow the rainfall map (tests/data/rainfall.png:
/// dry west, wet east): atlas and direct agree, and a reversed map changes
/// the image.
#[test]
fn input_maps_drive_the_layers() {
    let mut scene = Scene::new(jacksboro_field());
    scene.layers = LayerTree::load(&data("layers-rainfall.toml")).expect("layers");
    let rainfall = load_heightmap(&data("rainfall.png"), &HeightmapOptions::default()).expect("map");
    scene.input_maps[0] = Some(rainfall.clone());
    check_against_direct("rainfall", &scene, &scene.default_camera());
    let (wet_east, _) = render(&scene, &scene.default_camera(), TexturingMode::Atlas);
    let mut reversed = rainfall;
    reversed.heights.iter_mut().for_each(|v| *v = 255.0 - *v);
    scene.input_maps[0] = Some(reversed);
    let (wet_west, _) = render(&scene, &scene.default_camera(), TexturingMode::Atlas);
    let (mean, _) = mean_flip(&wet_east.rgba8, &wet_west.rgba8, WIDTH, HEIGHT);
    assert!(
        mean > 0.1,
        "reversing the rainfall map changed little: mean FLIP {mean:.4}"
    );
}
