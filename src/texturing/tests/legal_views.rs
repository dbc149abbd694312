//! Every legal view renders in the atlas mode (issue 15), under validation
//! and synchronization validation, and matches the per-pixel reference
//! (`TexturingMode::Direct`, the same layer tree evaluated per pixel):
//!
//! * small height fields, 2 to 129 samples a side, 1 to 100 m apart: their
//!   nodes narrower than a sample cell once kept the cell's whole height
//!   range as their error, so every visible node refined down to the
//!   deepest level (millions of tiles, a page table of 39 M words or no
//!   settling); the selection is now bounded too (`MAX_SELECTED`);
//! * a tiny field of view and a tall one-pixel-wide image;
//! * on the CPU alone: the selection and atlas fit for views a software
//!   device cannot render in a test's time (1×16384, 16384×1, 4096² to
//!   16384²), settled through the tile cache frame by frame, and the tile
//!   budget's whole range.

use crate::io::heightmap::HeightField;
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::test_support::{assert_validation_clean, dump_pngs, mean_flip, validated_context};
use crate::texturing::atlas::TileCache;
use crate::texturing::fit::select_to_fit;
use crate::texturing::generation::{TextureStreaming, PAGE_TABLE_WORDS};
use crate::texturing::page_table::PageTable;
use crate::texturing::quadtree::{HeightBounds, NeededTile, MAX_SELECTED};
use crate::texturing::streaming::{MAX_ATLAS_TEXTURES, MAX_TILE_BUDGET};
use crate::view::{Lighting, ShadowMode};
use crate::vulkan::Context;
use glam::{DVec2, DVec3};

/// Image size of the small-field renders.
const WIDTH: u32 = 64;
const HEIGHT: u32 = 40;
/// Frames without progress before a settled render gives up (as the CLI).
const SETTLE_FRAMES: u32 = 64;
/// Mean FLIP of the atlas against the direct reference (the sweep measured
/// 0.011 to 0.047 on lavapipe).
const MAX_MEAN_FLIP: f32 = 0.06;
/// The largest 2-D image side of lavapipe (`maxImageDimension2D`).
const LAVAPIPE_MAX_IMAGE_2D: u32 = 16384;

/// `n`×`n` samples `spacing` apart: hills whose relief is a tenth of the
/// field's size, and a rough component at the sample scale.
fn field(n: u32, spacing: f64) -> HeightField {
    let size = f64::from(n - 1) * spacing;
    HeightField::from_fn(n, n, DVec2::splat(spacing), |c, r| {
        let (x, y) = (f64::from(c) / f64::from(n - 1), f64::from(r) / f64::from(n - 1));
        let hills = 0.1 * size * ((x * 5.1).sin() * (y * 3.7).cos() + 0.5 * x);
        let rough = spacing * 0.3 * f64::from((c * 7919 + r * 104_729) % 17) / 17.0;
        (hills + rough) as f32
    })
}

fn settings(mode: TexturingMode, width: u32, height: u32) -> RenderSettings {
    let mut settings = RenderSettings {
        texturing: mode,
        // The textures under test, not haze or shadows over them.
        lighting: Some(Lighting {
            aerial_perspective: false,
            shadows: ShadowMode::Off,
            ..Default::default()
        }),
        ..RenderSettings::new(width, height)
    };
    settings.shadows.atlas_size = 256;
    settings
}

/// A settled frame of `camera` in `mode`.
fn render(ctx: &Context, scene: &Scene, camera: &Camera, mode: TexturingMode, size: (u32, u32)) -> FrameImages {
    let mut renderer = Renderer::new(ctx, scene, settings(mode, size.0, size.1)).expect("renderer");
    let frame = renderer
        .render_settled(camera, SETTLE_FRAMES)
        .unwrap_or_else(|e| panic!("{mode:?}: {e}"));
    let images = renderer.read(&frame).expect("read");
    renderer.finish().expect("finish");
    images
}

/// Mean FLIP of the atlas against the direct reference for `camera`.
fn atlas_against_direct(ctx: &Context, name: &str, scene: &Scene, camera: &Camera, size: (u32, u32)) -> f32 {
    let atlas = render(ctx, scene, camera, TexturingMode::Atlas, size);
    let direct = render(ctx, scene, camera, TexturingMode::Direct, size);
    let names = (format!("{name}-atlas"), format!("{name}-direct"));
    dump_pngs(&[(&names.0, &atlas.rgba8), (&names.1, &direct.rgba8)], size.0, size.1);
    mean_flip(&direct.rgba8, &atlas.rgba8, size.0, size.1).0
}

/// One context per field: while this test was written, the direct mode's
/// image of a field was seen to depend on the renderers an earlier field made
/// on the same context (5×5 samples 1 m apart: mean FLIP 0.18 after other
/// fields, 0.011 alone). `a_render_does_not_depend_on_earlier_renderers`
/// replays that sequence on one context and finds the same bytes.
#[test]
fn small_fields_settle_and_match_direct() {
    let mut worst = (0.0f32, String::new());
    for n in [2, 3, 5, 17, 33, 65, 129] {
        for spacing in [1.0, 7.0, 100.0] {
            let (ctx, report) = validated_context();
            let scene = Scene::new(field(n, spacing));
            let name = format!("field-{n}x{n}-{spacing}m");
            let mean = atlas_against_direct(&ctx, &name, &scene, &scene.default_camera(), (WIDTH, HEIGHT));
            eprintln!("{name}: mean FLIP atlas vs direct {mean:.4}");
            drop(ctx);
            assert_validation_clean(&report);
            if mean > worst.0 {
                worst = (mean, name);
            }
        }
    }
    assert!(worst.0 <= MAX_MEAN_FLIP, "{}: mean FLIP {:.4}", worst.1, worst.0);
}

/// The direct mode's frame of a field is the same bytes alone and after the
/// atlas and direct renderers of six other fields on the same context.
#[test]
fn a_render_does_not_depend_on_earlier_renderers() {
    let (ctx, report) = validated_context();
    let small = Scene::new(field(5, 1.0));
    let direct = |scene: &Scene| {
        render(
            &ctx,
            scene,
            &scene.default_camera(),
            TexturingMode::Direct,
            (WIDTH, HEIGHT),
        )
    };
    let alone = direct(&small);
    for n in [2, 3] {
        for spacing in [1.0, 7.0, 100.0] {
            let other = Scene::new(field(n, spacing));
            let _ = render(
                &ctx,
                &other,
                &other.default_camera(),
                TexturingMode::Atlas,
                (WIDTH, HEIGHT),
            );
            let _ = direct(&other);
        }
    }
    let _ = render(
        &ctx,
        &small,
        &small.default_camera(),
        TexturingMode::Atlas,
        (WIDTH, HEIGHT),
    );
    let after = direct(&small);
    dump_pngs(
        &[("direct-alone", &alone.rgba8), ("direct-after", &after.rgba8)],
        WIDTH,
        HEIGHT,
    );
    let differ = alone.rgba8.iter().zip(&after.rgba8).filter(|(a, b)| a != b).count();
    assert_eq!(
        differ, 0,
        "{differ} bytes of the direct frame changed after other renderers"
    );
    drop(ctx);
    assert_validation_clean(&report);
}

/// A camera 3 km from the centre of a 65×65 field 40 m apart, looking at
/// it through `fov_y_deg`.
fn distant_camera(scene: &Scene, fov_y_deg: f64) -> Camera {
    let extent = scene.heights.extent();
    let target = DVec3::new(extent.x * 0.5, extent.y * 0.5, 0.0);
    let target = target.with_z(f64::from(scene.heights.height(32, 32)));
    Camera {
        eye: target + DVec3::new(0.0, -2500.0, 1500.0),
        target,
        fov_y_deg,
        ..scene.default_camera()
    }
}

/// A field of view of 0.001° (a patch of 5 cm seen from 3 km) and a
/// 1×2048 image: the finest nodes the quadtree allows, clamped to its depth.
#[test]
fn tiny_field_of_view_and_tall_image_render() {
    let (ctx, report) = validated_context();
    let scene = Scene::new(field(65, 40.0));
    let narrow = atlas_against_direct(
        &ctx,
        "fov-0.001",
        &scene,
        &distant_camera(&scene, 0.001),
        (WIDTH, HEIGHT),
    );
    eprintln!("fov 0.001°: mean FLIP atlas vs direct {narrow:.4}");
    let tall = render(&ctx, &scene, &scene.default_camera(), TexturingMode::Atlas, (1, 2048));
    let direct = render(&ctx, &scene, &scene.default_camera(), TexturingMode::Direct, (1, 2048));
    let close = tall
        .rgba8
        .iter()
        .zip(&direct.rgba8)
        .filter(|(a, b)| a.abs_diff(**b) <= 16)
        .count();
    eprintln!("1×2048: {close} of {} bytes within 16 of direct", tall.rgba8.len());
    drop(ctx);
    assert_validation_clean(&report);
    assert!(narrow <= MAX_MEAN_FLIP, "fov 0.001°: mean FLIP {narrow:.4}");
    assert!(close >= tall.rgba8.len() * 9 / 10, "1×2048: {close} bytes close");
}

/// The tiles the atlas draws for `cameras` (camera, width, height) of
/// `scene`, fitted to the atlas and the page table.
fn select(scene: &Scene, cameras: &[(Camera, u32, u32)], streaming: &TextureStreaming) -> Vec<NeededTile> {
    let views: Vec<_> = cameras
        .iter()
        .map(|&(camera, w, h)| crate::view::View::new(camera, w, h).footprint())
        .collect();
    let bounds = HeightBounds::new(&scene.heights, streaming.quadtree.max_depth).expect("bounds");
    let (needed, _) = select_to_fit(scene.heights.extent(), &views, streaming, &bounds).expect("selection");
    assert!(!needed.is_empty(), "nothing selected");
    let words = PageTable::words_for(needed.iter().map(|t| t.node));
    assert!(
        needed.len() <= MAX_SELECTED && words <= PAGE_TABLE_WORDS,
        "{words} words"
    );
    needed
}

/// Settles `cameras` of `scene` through the tile cache on the CPU, as the
/// renderer does (a tile budget per frame, no GPU time); the frames taken.
fn settle_on_cpu(scene: &Scene, cameras: &[(Camera, u32, u32)], streaming: &TextureStreaming) -> u64 {
    let extent = scene.heights.extent();
    let needed = select(scene, cameras, streaming);
    let mut cache = TileCache::new(streaming.atlas).expect("cache");
    let (mut fewest, mut frame) = (usize::MAX, 0);
    loop {
        frame += 1;
        let plan = cache.plan_frame(frame, &needed, streaming.budget);
        let words = PageTable::build(&plan, extent).expect("page table").words().len();
        assert!(words <= PAGE_TABLE_WORDS, "{words} page-table words");
        assert!(plan.stats.generated <= streaming.budget.tiles + 1);
        if plan.stats.deferred == 0 {
            return frame;
        }
        assert!(
            plan.stats.deferred < fewest,
            "frame {frame} made no progress: {:?}",
            plan.stats
        );
        fewest = plan.stats.deferred;
    }
}

/// The views a software device cannot render in a test's time: tall and
/// wide strips of 16384 pixels, a tiny field of view at 1280×720, and
/// images of 4096² to 16384² (an atlas within its limits, coarsened to fit).
#[test]
fn extreme_views_select_fit_and_settle_on_the_cpu() {
    let scene = Scene::new(field(129, 30.0));
    let camera = scene.default_camera();
    let cases = [
        ("1×16384", camera, 1, 16384),
        ("16384×1", camera, 16384, 1),
        ("fov 0.001° 1280×720", distant_camera(&scene, 0.001), 1280, 720),
        ("4096²", camera, 4096, 4096),
        ("8192²", camera, 8192, 8192),
        ("16384²", camera, 16384, 16384),
    ];
    for (name, camera, w, h) in cases {
        let streaming = TextureStreaming::for_image(w, h);
        streaming.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        let textures = streaming.atlas.texture_tile_sizes().len();
        assert!(textures <= MAX_ATLAS_TEXTURES, "{name}: {textures} textures");
        assert!(streaming.atlas.size <= LAVAPIPE_MAX_IMAGE_2D, "{name}");
        // Settling the largest takes hundreds of frames of thousands of
        // tiles: their selection and fit are checked, the rest settle.
        let frames = match u64::from(w) * u64::from(h) <= 4096 * 4096 {
            true => settle_on_cpu(&scene, &[(camera, w, h)], &streaming).to_string(),
            false => format!("{} tiles, not", select(&scene, &[(camera, w, h)], &streaming).len()),
        };
        eprintln!(
            "{name}: atlas {} textures of {}², {} MiB; settled after {frames} frames",
            textures,
            streaming.atlas.size,
            streaming.atlas_bytes() >> 20
        );
    }
}

/// A steep 2×2 field seen from up close at 1280×720: the selection stays
/// small (it once refined every visible node to level 12) and settles.
#[test]
fn steep_tiny_field_selects_few_tiles() {
    let scene = Scene::new(HeightField::from_fn(2, 2, DVec2::splat(1.0), |c, r| {
        (c * 7 + r * 3) as f32 * 0.05
    }));
    let streaming = TextureStreaming::for_image(1280, 720);
    let needed = select(&scene, &[(scene.default_camera(), 1280, 720)], &streaming);
    assert!(needed.len() < 2000, "{} tiles", needed.len());
    let frames = settle_on_cpu(&scene, &[(scene.default_camera(), 1280, 720)], &streaming);
    assert!(frames < 64, "{frames} frames");
}

/// Every tile budget of the advertised range (the CLI's parser reads the
/// same constant) is valid and settles; the range's ends and outside it.
#[test]
fn every_tile_budget_of_the_range_is_valid() {
    let scene = Scene::new(field(65, 40.0));
    let base = TextureStreaming::for_image(640, 360);
    assert_eq!(base.max_tile_budget(), MAX_TILE_BUDGET);
    for tiles in 1..=MAX_TILE_BUDGET {
        let streaming = base.with_tile_budget(tiles).expect("in range");
        streaming.validate().unwrap_or_else(|e| panic!("budget {tiles}: {e}"));
        if tiles == 1 || tiles >= 250 {
            settle_on_cpu(&scene, &[(scene.default_camera(), 640, 360)], &streaming);
        }
    }
    assert!(base.with_tile_budget(0).is_err() && base.with_tile_budget(MAX_TILE_BUDGET + 1).is_err());
}

/// The largest tile budget renders on the GPU (its scratch buffer is the
/// largest one frame needs).
#[test]
fn largest_tile_budget_renders() {
    let (ctx, report) = validated_context();
    let scene = Scene::new(field(65, 40.0));
    {
        let mut settings = settings(TexturingMode::Atlas, WIDTH, HEIGHT);
        settings.texture_streaming = settings
            .texture_streaming
            .with_tile_budget(MAX_TILE_BUDGET)
            .expect("budget");
        let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
        let frame = renderer
            .render_settled(&scene.default_camera(), SETTLE_FRAMES)
            .expect("frame");
        renderer.read(&frame).expect("read");
        renderer.finish().expect("finish");
        let stats = renderer.take_texture_stats().expect("stats");
        assert!(stats.iter().all(|s| s.tiles.generated <= MAX_TILE_BUDGET as usize + 1));
    }
    drop(ctx);
    assert_validation_clean(&report);
}
