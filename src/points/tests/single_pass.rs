//! Single-pass splatting with a fuzzy depth test (dissertation §10.4) on the
//! GPU, under validation and synchronization validation, against the
//! three-pass mode (§10.2) and the analytic checkerboard plane:
//!
//! * the grazing checkerboard: no holes, and against the 16×16 supersampled
//!   analytic reference a mean FLIP over the far plane no worse than the
//!   three-pass mode's + 10 % (no Moiré);
//! * the bunny: the same splats pass the interval test and are drawn as in
//!   the three-pass mode (the set-up is shared), and the images agree
//!   within [`BUNNY_FLIP`] (the modes blend the same kernels; they differ
//!   only where surfaces meet within z_fuzzy);
//! * the compute backend (tile-binned, §10.4) is deterministic: two renders
//!   are byte-identical, and so are renders with either radix sort (a CPU
//!   device's serial blocks, a GPU's shared runs);
//! * a close-up with long tile lists (hundreds of entries per 8×8 tile,
//!   many runs of the merge's walk) still matches the three-pass image;
//! * an entry buffer too small for the frame drops whole tiles' lists,
//!   reported in the statistics, the same on every run;
//! * clip lines (§10.2.4) cut the single-pass splats exactly as the
//!   three-pass ones (a checkerboard clipped at x = 6 m);
//! * over the built-in terrain, the bunny sunk into it is hidden where the
//!   ground is nearer (the depth buffer's test), covering the same pixels
//!   as in the three-pass mode;
//! * the interlock backend fails with a one-line error naming
//!   `fragmentShaderPixelInterlock (VK_EXT_fragment_shader_interlock)` on a
//!   device without it (lavapipe; or `fragmentStoresAndAtomics`), and else
//!   matches the compute backend.

use crate::points::build::clip::{ClipLine, ClipLines};
use crate::points::render::{PointFrameStats, SplatBackend, SplatMode, SplatSettings};
use crate::points::scene::{PointScene, PointTransform};
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::test_support::plane::{
    analytic_plane, grazing_camera, holes, plane_flip, plane_scene, plane_scene_clipped, unlit, FAR_FIELD_Y, SPACING,
};
use crate::test_support::points::{bunny_camera, bunny_object, render_points};
use crate::test_support::{assert_validation_clean, dump_pngs, mean_flip, validated_context};
use glam::Vec3;

/// Mean FLIP between the single-pass and three-pass bunnies (shaded, 160×100).
const BUNNY_FLIP: f32 = 0.03;

#[test]
fn grazing_checkerboard_single_pass_is_as_good_as_three_passes() {
    let camera = grazing_camera();
    let size = (crate::test_support::plane::WIDTH, crate::test_support::plane::HEIGHT);
    let covered = analytic_plane(&camera, 1, 0.1, 0.0);
    let reference = analytic_plane(&camera, 16, 0.1, FAR_FIELD_Y);
    let scene = plane_scene(SPACING);
    let (three, _) = render_points(&scene, &camera, unlit(SplatMode::Ewa), size);
    let three_flip = plane_flip(&three, &reference);
    let (single, stats) = render_points(&scene, &camera, unlit(SplatMode::SinglePass), size);
    eprintln!("{}", stats.summary());
    assert_eq!(holes(&single, &covered), 0, "single pass: W = 0 inside the plane");
    let flip = plane_flip(&single, &reference);
    eprintln!("mean FLIP over the far plane: single pass {flip:.4}, three passes {three_flip:.4}");
    assert!(
        flip <= 1.1 * three_flip,
        "single pass: FLIP {flip} > 1.1 × three-pass {three_flip}"
    );
}

/// Clip lines (§10.2.4) cut the single-pass splats as the three-pass ones:
/// the checkerboard ends at x = 6 m, the surfels that straddle it clipped
/// there. Without the clip lines their disks overhang the edge.
#[test]
fn clip_lines_cut_single_pass_splats_as_three_pass_ones() {
    const EDGE: f32 = 6.0;
    let clipped = |p: Vec3| match p.x < EDGE {
        true if p.x + SPACING > EDGE => Some(ClipLines([
            Some(ClipLine {
                angle: 0.0,
                offset: EDGE - p.x,
            }),
            None,
        ])),
        true => Some(ClipLines::NONE),
        false => None,
    };
    let unclipped = |p: Vec3| clipped(p).map(|_| ClipLines::NONE);
    let camera = grazing_camera();
    let size = (crate::test_support::plane::WIDTH, crate::test_support::plane::HEIGHT);
    let render = |scene: &Scene, mode| render_points(scene, &camera, unlit(mode), size).0;
    let scene = plane_scene_clipped(SPACING, clipped);
    let (three, single_frame) = (render(&scene, SplatMode::Ewa), render(&scene, SplatMode::SinglePass));
    let overhanging_frame = render(&plane_scene_clipped(SPACING, unclipped), SplatMode::SinglePass);
    // Fig. 10.21: the covered pixels (grey) without clip lines (left; red:
    // the splats' overhang beyond the edge) and with them (right).
    let mask = |frame: &FrameImages, other: Option<&FrameImages>| -> Vec<u8> {
        let weight = |f: &FrameImages, i: usize| f.weight.as_ref().is_some_and(|w| w[i] > 0.0);
        (0..frame.depth.len())
            .flat_map(|i| match (weight(frame, i), other.map(|o| weight(o, i))) {
                (false, _) => [255, 255, 255, 255],
                (true, Some(false)) => [220, 30, 30, 255],
                (true, _) => [110, 110, 110, 255],
            })
            .collect()
    };
    crate::test_support::dump_pngs(
        &[
            (
                "fig-10-21-without-clip-lines",
                &mask(&overhanging_frame, Some(&single_frame)),
            ),
            ("fig-10-21-with-clip-lines", &mask(&single_frame, None)),
        ],
        size.0,
        size.1,
    );
    let (three, single, overhanging) = (covered(&three), covered(&single_frame), covered(&overhanging_frame));
    eprintln!(
        "covered pixels: clipped three passes {three}, single pass {single}; unclipped single pass {overhanging}"
    );
    assert!(
        three.abs_diff(single) * 1000 <= three,
        "clipped: three passes {three}, single pass {single}"
    );
    assert!(
        overhanging > single + 100,
        "the clip lines cut {} pixels",
        overhanging - single
    );
}

fn bunny_scene() -> Scene {
    let mut points = PointScene::default();
    points.add(bunny_object(false), PointTransform::parse("r=90,0,0").unwrap());
    Scene::points_only(points)
}

fn covered(frame: &FrameImages) -> usize {
    frame.weight.as_ref().unwrap().iter().filter(|w| **w > 0.0).count()
}

/// `scene` in three passes and in a single pass at 160×100; asserts that
/// both cover the same pixels (within 1 %) and that their mean FLIP stays
/// within [`BUNNY_FLIP`]; returns both frames and the three-pass coverage.
fn three_and_single_pass(scene: &Scene, camera: &Camera, label: &str) -> ([(FrameImages, PointFrameStats); 2], usize) {
    three_and_single_pass_at(scene, camera, label, (160, 100))
}

/// [`three_and_single_pass`] at `size`.
fn three_and_single_pass_at(
    scene: &Scene,
    camera: &Camera,
    label: &str,
    size: (u32, u32),
) -> ([(FrameImages, PointFrameStats); 2], usize) {
    let single_pass = SplatSettings {
        mode: SplatMode::SinglePass,
        ..SplatSettings::default()
    };
    let frames = [SplatSettings::default(), single_pass].map(|s| render_points(scene, camera, s, size));
    let [(three, _), (single, _)] = &frames;
    let (a, b) = (covered(three), covered(single));
    assert!(
        a.abs_diff(b) * 100 <= a,
        "{label}: covered pixels: three passes {a}, single pass {b}"
    );
    let (flip, heat) = mean_flip(&three.rgba8, &single.rgba8, size.0, size.1);
    let names = ["three-pass", "single-pass", "flip"].map(|n| format!("{label}-{n}"));
    let images = [
        (names[0].as_str(), &three.rgba8[..]),
        (names[1].as_str(), &single.rgba8[..]),
        (names[2].as_str(), &heat[..]),
    ];
    dump_pngs(&images, size.0, size.1);
    eprintln!("{label}: mean FLIP single pass vs three passes {flip:.4}; covered {a} vs {b}");
    assert!(flip <= BUNNY_FLIP, "{label}: FLIP {flip} > {BUNNY_FLIP}");
    (frames, a)
}

#[test]
fn bunny_single_pass_matches_three_passes() {
    let ([(_, three_stats), (single, stats)], covered) =
        three_and_single_pass(&bunny_scene(), &bunny_camera(0.5), "bunny");
    eprintln!(
        "three passes: {}\nsingle pass:  {}",
        three_stats.summary(),
        stats.summary()
    );
    assert_eq!(stats.interval_passed, three_stats.interval_passed);
    assert_eq!(stats.drawn_splats, three_stats.drawn_splats);
    assert!(covered > 1000, "the bunny covers {covered} pixels");
    // The AOVs are written where the splats are: class, instance and a unit normal.
    let weight = single.weight.as_ref().unwrap();
    for (i, w) in weight.iter().enumerate() {
        if *w > 0.0 {
            assert_eq!(single.class[i], 3, "pixel {i}: class of point objects");
            assert_eq!(single.instance[i], 1, "pixel {i}: instance id");
            let n = &single.normal[3 * i..3 * i + 3];
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((length - 1.0).abs() < 1e-3, "pixel {i}: normal length {length}");
        }
    }
}

fn single_pass() -> SplatSettings {
    SplatSettings {
        mode: SplatMode::SinglePass,
        ..SplatSettings::default()
    }
}

/// The tile-binned compute backend sorts every tile's list by a total order
/// before merging, so the order in which the GPU binned the splats does not
/// show: two renders agree to the byte (colour, W, depth, normal, ids).
#[test]
fn single_pass_renders_are_byte_identical() {
    let scene = bunny_scene();
    let camera = bunny_camera(0.5);
    let [(a, stats), (b, _)] = [0, 1].map(|_| render_points(&scene, &camera, single_pass(), (160, 100)));
    eprintln!("{}", stats.summary());
    assert!(covered(&a) > 1000, "the bunny covers {} pixels", covered(&a));
    assert_byte_identical(&a, &b, "two renders");
}

/// Asserts that `a` and `b` agree to the byte: colour, W, depth, normal, ids.
fn assert_byte_identical(a: &FrameImages, b: &FrameImages, what: &str) {
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert!(a.rgba8 == b.rgba8, "{what}: tone-mapped colour differs");
    assert!(bits(&a.hdr) == bits(&b.hdr), "{what}: radiance differs");
    assert!(
        bits(a.weight.as_ref().unwrap()) == bits(b.weight.as_ref().unwrap()),
        "{what}: W differs"
    );
    assert!(bits(&a.depth) == bits(&b.depth), "{what}: view depth differs");
    assert!(bits(&a.normal) == bits(&b.normal), "{what}: normal differs");
    assert!(a.class == b.class && a.instance == b.instance, "{what}: ids differ");
}

/// The two radix sorts (serial blocks with 12-bit digits, a CPU device's;
/// shared runs with 8-bit digits, a GPU's) are stable sorts of the same
/// keys, so every tile's list comes out in the same order and the images
/// agree to the byte: the distant bunny, a close-up with long tile lists
/// (several radix blocks; the operator is not commutative, so any
/// reordering of equal keys would show), and an entry buffer that
/// overflows (seven blocks; nearly every tile's list cut).
#[test]
fn both_radix_sorts_give_the_same_image() {
    use crate::points::render::{with_entry_capacity, with_radix_sort, RadixSort};
    let scene = bunny_scene();
    let cases = [
        ("distant", 0.5, (160, 100), None),
        ("close-up", 0.3, (64, 64), None),
        ("overflow", 0.5, (160, 100), Some(13_500)),
    ];
    for (what, distance, size, capacity) in cases {
        let camera = bunny_camera(distance);
        let render = |sort| {
            with_radix_sort(sort, || match capacity {
                Some(c) => with_entry_capacity(c, || render_points(&scene, &camera, single_pass(), size)),
                None => render_points(&scene, &camera, single_pass(), size),
            })
        };
        let (serial, serial_stats) = render(RadixSort::SerialBlocks);
        let (runs, runs_stats) = render(RadixSort::SharedRuns);
        eprintln!("{what}: {}", runs_stats.summary());
        // The overflow keeps a few tiles (their lists fit below the capacity).
        let least = if capacity.is_some() { 0 } else { 500 };
        assert!(
            covered(&runs) > least,
            "{what}: the bunny covers {} pixels",
            covered(&runs)
        );
        let counts = |s: &PointFrameStats| (s.drawn_splats, s.longest_tile_list, s.tile_entries_dropped);
        assert_eq!(counts(&serial_stats), counts(&runs_stats), "{what}");
        let dropped = runs_stats.tile_entries_dropped.expect("GPU counters");
        assert_eq!(dropped > 0, capacity.is_some(), "{what}: {dropped} entries dropped");
        assert_byte_identical(&serial, &runs, what);
    }
}

/// A close-up at 64×64: long tile lists (over 512 entries in an 8×8 tile,
/// 64 runs and more of the merge's walk, the surfaces behind skipped by
/// the reach) and the image still matches the three-pass one.
#[test]
fn long_tile_lists_match_three_passes() {
    let ([_, (_, stats)], covered) = three_and_single_pass_at(&bunny_scene(), &bunny_camera(0.3), "close-up", (64, 64));
    eprintln!("single pass: {}", stats.summary());
    assert!(covered > 64 * 64 / 4, "the bunny covers {covered} pixels");
    let longest = stats.longest_tile_list.expect("GPU counters");
    assert!(longest > 512, "the longest tile list holds {longest} entries");
    assert_eq!(stats.tile_entries_dropped, Some(0));
}

/// An entry buffer too small for the frame: the lists that do not fit are
/// dropped whole, never written out of bounds (validation stays clean), the
/// statistics report the dropped entries, and the image is the same on
/// every run.
#[test]
fn entry_overflow_is_reported() {
    let scene = bunny_scene();
    let camera = bunny_camera(0.5);
    let (full, full_stats) = render_points(&scene, &camera, single_pass(), (160, 100));
    let capacity = 3000;
    let [(a, stats), (b, _)] = [0, 1].map(|_| {
        crate::points::render::with_entry_capacity(capacity, || {
            render_points(&scene, &camera, single_pass(), (160, 100))
        })
    });
    eprintln!("capacity {capacity}: {}", stats.summary());
    let dropped = stats.tile_entries_dropped.expect("GPU counters");
    assert!(dropped > 0, "no entries dropped");
    assert_eq!(full_stats.tile_entries_dropped, Some(0));
    assert!(stats.summary().contains("DROPPED"), "{}", stats.summary());
    assert!(a.rgba8 == b.rgba8, "the overflow is not deterministic");
    assert!(
        covered(&a) < covered(&full),
        "dropped tiles show no splats: {} vs {}",
        covered(&a),
        covered(&full)
    );
    dump_pngs(&[("overflow", &a.rgba8[..]), ("full", &full.rgba8[..])], 160, 100);
}

#[test]
fn interlock_backend_needs_the_extension() {
    let scene = bunny_scene();
    let camera = bunny_camera(0.5);
    let settings = SplatSettings {
        mode: SplatMode::SinglePass,
        backend: SplatBackend::Interlock,
        ..SplatSettings::default()
    };
    let (ctx, report) = validated_context();
    let interlock = ctx.has_feature("fragmentShaderPixelInterlock");
    if interlock && ctx.has_feature("fragmentStoresAndAtomics") {
        drop(ctx);
        let (interlock, _) = render_points(&scene, &camera, settings, (160, 100));
        let compute = SplatSettings {
            backend: SplatBackend::Compute,
            ..settings
        };
        let (reference, _) = render_points(&scene, &camera, compute, (160, 100));
        let (flip, _) = mean_flip(&reference.rgba8, &interlock.rgba8, 160, 100);
        assert!(flip <= BUNNY_FLIP, "interlock vs compute FLIP {flip}");
    } else {
        let error = match Renderer::new(
            &ctx,
            &scene,
            RenderSettings {
                points: settings,
                ..RenderSettings::new(160, 100)
            },
        ) {
            Ok(_) => panic!("the interlock backend rendered on a device without it"),
            Err(e) => e.to_string(),
        };
        eprintln!("{error}");
        assert!(!error.contains('\n'), "one line: {error}");
        let named = match interlock {
            false => "fragmentShaderPixelInterlock (VK_EXT_fragment_shader_interlock)",
            true => "fragmentStoresAndAtomics",
        };
        assert!(error.contains(named), "names {named}: {error}");
        drop(ctx);
    }
    assert_validation_clean(&report);
}

/// Over the terrain the splats test against its depth buffer: the bunny,
/// scaled to a hill and sunk into the built-in terrain, is hidden where the
/// ground is nearer, as in the three-pass mode.
#[test]
fn terrain_hides_single_pass_splats_as_it_hides_three_pass_ones() {
    let mut scene = Scene::default_procedural().expect("built-in terrain");
    let transform = PointTransform::parse("t=5120,5120,0;r=90,0,0;s=6000").unwrap();
    scene.points.add(bunny_object(false), transform);
    let camera = Camera {
        eye: glam::DVec3::new(5120.0, 3900.0, 1700.0),
        target: glam::DVec3::new(5120.0, 5120.0, 500.0),
        ..scene.default_camera()
    };
    let (_, covered) = three_and_single_pass(&scene, &camera, "terrain");
    let pixels = 160 * 100;
    assert!(
        covered > pixels / 10 && covered < pixels * 9 / 10,
        "the bunny covers {covered} pixels, partly hidden"
    );
}
