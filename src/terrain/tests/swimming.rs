//! The swimming metric (dissertation §7.4.3, §7.4.5;
//! [`crate::terrain::swimming`]): the CPU rasterizer against an analytic
//! plane and against the ray cast, zero swimming for a static camera and
//! for a world-static mesh, and more swimming for a deliberately jittered
//! warp than for the plain one; the world-anchored plan (the remedy,
//! `LodSettings::snap`) swims at most half as much as the plain warp and
//! keeps the density of Fig. 7.12 for an eye anywhere in its snap cell.
//! Small images and grids (a debug build);
//! the figures of the default sizes are in `docs/PERFORMANCE.md`
//! (`--bin swimming`).

use glam::{DVec2, DVec3};

use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::surface::bspline::sample_bspline;
use crate::terrain::importance::Frustum;
use crate::terrain::lod::{
    sketch_importance, DebugScalar, LodFrame, LodMode, LodSettings, ANCHORED_SNAP, DEFAULT_SNAP, HEIGHT_FACTOR,
};
use crate::terrain::procedural::ProceduralTerrain;
use crate::terrain::swimming::{camera_path, measure, rasterize, shade, Mesh, Swimming};
use crate::terrain::warp::{density_ratio, fraction_within};
use crate::test_support::jacksboro_field;
use crate::view::{Camera, View};

const SIZE: (u32, u32) = (96, 54);
const SKETCH: usize = 32;
const SIDE: usize = 64;

fn field() -> HeightField {
    ProceduralTerrain::default()
        .try_generate(129, 129, DVec2::splat(40.0))
        .expect("procedural terrain")
}

/// Low over the southern part of the field, looking north just below the horizon.
fn start(field: &HeightField) -> Camera {
    let e = field.extent();
    let (_, hi) = field.min_max();
    let eye = DVec3::new(0.5 * e.x, 0.15 * e.y, f64::from(hi) + 40.0);
    Camera {
        eye,
        target: eye + DVec3::new(0.0, 1000.0, -80.0),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 1.0,
        far: 50_000.0,
    }
}

/// The test's sketch side, `mode`, and the plain plan (no snapping: the
/// text's per-frame plan).
fn settings(mode: LodMode) -> LodSettings {
    LodSettings {
        sketch_side: SKETCH,
        mode,
        snap: 0.0,
        ..Default::default()
    }
}

/// The swimming of the renderer's LOD in `mode` along `cameras`, every
/// frame's warped sketch map moved by `jitter(k, warped)` first.
fn lod_swimming(
    field: &HeightField,
    cameras: &[Camera],
    mode: LodMode,
    jitter: impl FnMut(usize, &mut [DVec3]),
) -> Swimming {
    lod_swimming_with(field, cameras, settings(mode), jitter)
}

/// [`lod_swimming`] with explicit LOD settings.
fn lod_swimming_with(
    field: &HeightField,
    cameras: &[Camera],
    settings: LodSettings,
    mut jitter: impl FnMut(usize, &mut [DVec3]),
) -> Swimming {
    let mut frame = LodFrame::default();
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    measure(field, cameras, SIZE, |k, camera| {
        frame.plan(field, camera, aspect, &settings, DebugScalar::None)?;
        let mut warped = frame.warp.positions.clone();
        jitter(k, &mut warped);
        Mesh::from_warp(field, &warped, SKETCH, SIDE)
    })
    .expect("swimming")
}

/// A plane at z = 0 seen straight down from 100 m: depth 100 everywhere
/// it is drawn, and the plane's shading.
#[test]
fn rasterizer_draws_a_plane_exactly() {
    let field = HeightField::from_fn(9, 9, DVec2::splat(100.0), |_, _| 0.0);
    let side = 5;
    let positions: Vec<DVec3> = (0..side * side)
        .map(|k| DVec3::new((k % side) as f64 * 200.0, (k / side) as f64 * 200.0, 0.0))
        .collect();
    let mesh = Mesh::new(&field, side, positions);
    let camera = Camera {
        eye: DVec3::new(400.0, 400.0, 100.0),
        target: DVec3::new(400.0, 400.0, 0.0),
        up: DVec3::Y,
        fov_y_deg: 60.0,
        near: 1.0,
        far: 1000.0,
    };
    let raster = rasterize(&mesh, &View::new(camera, 40, 30));
    assert!(
        raster.depth.iter().all(|&d| (d - 100.0).abs() < 1e-9),
        "every pixel sees the plane at 100 m"
    );
    assert!(raster.luminance.iter().all(|&l| (l - shade(DVec3::Z)).abs() < 1e-12));
}

/// Meshes of the B-spline with a vertex at every height-field sample and
/// four times finer, drawn, against the ray cast: a check of the
/// rasterizer's pixel and depth conventions. The triangles cut corners of
/// the B-spline, so the error is not 0, but it must fall about
/// quadratically with the spacing (a pixel offset would not).
#[test]
fn drawn_dense_mesh_matches_the_ray_cast() {
    let field = field();
    let side = field.columns as usize;
    let grid: Vec<DVec3> = (0..side * side)
        .map(|k| DVec3::new((k % side) as f64 * 40.0, (k / side) as f64 * 40.0, 0.0))
        .collect();
    let error = |zoom: usize| {
        let mesh = Mesh::from_warp(&field, &grid, side, zoom * (side - 1) + 1).unwrap();
        measure(&field, &[start(&field); 2], SIZE, |_, _| Ok(mesh.clone())).unwrap()
    };
    let (s, fine) = (error(1), error(4));
    println!(
        "dense meshes against the ray cast: mean relative depth error {:.2e} (40 m), {:.2e} (10 m)",
        s.error, fine.error
    );
    assert!(s.error < 1e-2, "mean relative depth error {}", s.error);
    assert!(
        fine.error < s.error / 6.0,
        "{} at 10 m vs {} at 40 m",
        fine.error,
        s.error
    );
    assert_eq!((s.depth, s.colour), (0.0, 0.0));
    assert!(
        s.pixels > (SIZE.0 * SIZE.1) as usize / 3,
        "{} pixels of ground",
        s.pixels
    );
}

#[test]
fn still_camera_and_world_static_mesh_do_not_swim() {
    let field = field();
    let still = vec![start(&field); 4];
    let s = lod_swimming(&field, &still, LodMode::Warped, |_, _| {});
    assert_eq!((s.depth, s.colour), (0.0, 0.0), "the same camera plans the same mesh");
    assert!(s.error > 0.0 && s.pixels > 0);
    // Moving, but a mesh that never changes.
    let moving = camera_path(start(&field), DVec2::new(10.0, 5.0), 4);
    let side = field.columns as usize;
    let grid: Vec<DVec3> = (0..side * side)
        .map(|k| DVec3::new((k % side) as f64 * 40.0, (k / side) as f64 * 40.0, 0.0))
        .collect();
    let mesh = Mesh::from_warp(&field, &grid, side, side).unwrap();
    let s = measure(&field, &moving, SIZE, |_, _| Ok(mesh.clone())).unwrap();
    assert_eq!((s.depth, s.colour), (0.0, 0.0));
}

/// A slowly moving camera: the warped grid swims; shaking its inner
/// vertices by up to a fifth of a sketch texel per frame (a warp that
/// flickers) makes it swim clearly more, in depth and colour.
#[test]
fn jittered_warp_swims_more() {
    let field = field();
    let cameras = camera_path(start(&field), DVec2::new(10.0, 5.0), 5);
    let plain = lod_swimming(&field, &cameras, LodMode::Warped, |_, _| {});
    let mut random = SplitMix64(7);
    let texel = field.extent().max_element() / (SKETCH - 1) as f64;
    let shaken = lod_swimming(&field, &cameras, LodMode::Warped, |_, warped| {
        for (k, p) in warped.iter_mut().enumerate() {
            let (c, r) = (k % SKETCH, k / SKETCH);
            if c == 0 || r == 0 || c == SKETCH - 1 || r == SKETCH - 1 {
                continue;
            }
            let d = DVec2::new(random.next_f64() - 0.5, random.next_f64() - 0.5) * 0.4 * texel;
            *p += d.extend(0.0);
        }
    });
    println!("plain {plain:?}\nshaken {shaken:?}");
    assert!(
        plain.depth > 0.0 && plain.colour > 0.0,
        "a moving camera's warp changes"
    );
    assert!(
        shaken.depth > 2.0 * plain.depth,
        "depth {} vs {}",
        shaken.depth,
        plain.depth
    );
    assert!(
        shaken.colour > 2.0 * plain.colour,
        "colour {} vs {}",
        shaken.colour,
        plain.colour
    );
}

/// The remedy (§7.4.3, §7.4.5; [`crate::terrain::lod`]): the plan's eye
/// snapped to the world grid of `--lod-snap 1` (one whole-terrain sketch
/// texel, 165 m here), along a path of 960 m (about six replans), swims at
/// most half as much as the plain per-frame plan, in depth and in colour.
/// Between replans the mesh is world-static: most pairs change nothing.
/// The price is accuracy: the plan is made for an eye up to `0.87 G` away
/// (measured: 1.2–2.1× the plain plan's mean depth error, still less than
/// half the uniform grid's; `docs/PERFORMANCE.md`), bounded here by 2×.
#[test]
fn anchored_plan_swims_at_most_half_as_much() {
    let field = field();
    let cameras = camera_path(start(&field), DVec2::new(40.0, 0.0), 24);
    let plain = lod_swimming(&field, &cameras, LodMode::Warped, |_, _| {});
    let anchored_settings = LodSettings {
        snap: ANCHORED_SNAP,
        ..settings(LodMode::Warped)
    };
    let anchored = lod_swimming_with(&field, &cameras, anchored_settings, |_, _| {});
    println!("plain {plain:?}\nanchored {anchored:?}");
    assert!(anchored.depth > 0.0, "the path crosses grid points: the plan changes");
    assert!(
        anchored.depth <= 0.5 * plain.depth,
        "depth {} vs {}",
        anchored.depth,
        plain.depth
    );
    assert!(
        anchored.colour <= 0.5 * plain.colour,
        "colour {} vs {}",
        anchored.colour,
        plain.colour
    );
    assert!(
        anchored.error <= 2.0 * plain.error,
        "error {} vs {}",
        anchored.error,
        plain.error
    );
}

/// Fig. 7.12 with the remedy: the plan made for the snapped eye, judged by
/// the importance of the real eye (the density it should have), on both
/// terrains and with the eye at every corner of its snap cell (the farthest
/// from the grid point): at least 80 % of the warped texels inside the real
/// frustum get between half and all of the demanded density, as the plain
/// plan does.
#[test]
fn anchored_plan_keeps_the_density_ratio() {
    let procedural = ProceduralTerrain::default()
        .try_generate(257, 257, DVec2::splat(40.0))
        .expect("procedural terrain");
    let (n, aspect) = (128, 16.0 / 9.0);
    for (name, field) in [("procedural", procedural), ("Jacksboro DEM", jacksboro_field())] {
        let anchored = LodSettings {
            sketch_side: n,
            snap: ANCHORED_SNAP,
            ..Default::default()
        };
        let plain = LodSettings { snap: 0.0, ..anchored };
        let grid = anchored.snap * field.extent().max_element() / (n - 1) as f64;
        let base = start(&field);
        // The grid point nearest the start, and the eye at ±0.49 G from it.
        let point = (base.eye / grid).round() * grid;
        let mut worst: f64 = 1.0;
        for corner in 0..8 {
            let sign = |bit: usize| if corner & bit == 0 { -0.49 } else { 0.49 };
            let eye = point + DVec3::new(sign(1), sign(2), sign(4)) * grid;
            let camera = Camera {
                eye,
                target: base.target + (eye - base.eye),
                ..base
            };
            let anchor = anchored.anchor(&field, &camera, None).expect("anchor");
            println!(
                "{name}: eye {:.0} m above the ground, grid {:.1} m",
                eye.z - sample_bspline(&field, eye.x, eye.y),
                anchor.spacing
            );
            let fraction = |settings: &LodSettings| {
                let mut frame = LodFrame::default();
                frame
                    .plan(&field, &camera, aspect, settings, DebugScalar::None)
                    .expect("plan");
                let sketch = frame.sketch.as_ref().expect("sketch map");
                let factors = settings.factors;
                let wanted = sketch_importance(sketch, &camera, (aspect, 0.0), factors).expect("importance");
                let d = density_ratio(&frame.warp.positions, &sketch.geometry, &wanted, n).expect("density");
                let frustum = Frustum::perspective(
                    camera.eye,
                    camera.forward(),
                    camera.up,
                    camera.fov_y_deg.to_radians(),
                    aspect,
                    0.0,
                )
                .expect("frustum");
                let inside: Vec<f64> = (frame.warp.positions.iter().zip(&d.combined))
                    .filter(|(p, _)| frustum.contains(**p))
                    .map(|(_, &r)| r)
                    .collect();
                assert!(inside.len() > n * n / 4, "{name}: {} texels in view", inside.len());
                fraction_within(&inside, 0.5, 1.0)
            };
            let (with, without) = (fraction(&anchored), fraction(&plain));
            println!(
                "{name}, eye {eye:.0} ({:.0} m cell): in [0.5, 1] {:.1} % anchored, {:.1} % plain",
                grid,
                100.0 * with,
                100.0 * without
            );
            worst = worst.min(with);
        }
        assert!(worst >= 0.8, "{name}: only {:.1} % in [0.5, 1]", 100.0 * worst);
    }
}

/// The snap grid adapts to the eye's height above the ground (module
/// documentation of [`crate::terrain::lod`], "Height-adaptive grid"): an
/// eye high above the ground gets the coarsest grid of the default snap,
/// one 2 m above it a grid of at most `HEIGHT_FACTOR × 2 m` and a planned
/// eye no lower than the ground under it, one under the ground (or with a snap of 0) none;
/// a level is kept while the height allows it and is less than four times
/// its grid, and a fresh plan picks the coarsest grid the height allows.
#[test]
fn snap_grid_follows_the_height_above_the_ground() {
    let field = field();
    let settings = LodSettings {
        sketch_side: SKETCH,
        snap: DEFAULT_SNAP,
        ..Default::default()
    };
    let coarsest = DEFAULT_SNAP * field.extent().max_element() / (SKETCH - 1) as f64;
    let at = |xy: DVec2, height: f64| {
        let eye = xy.extend(sample_bspline(&field, xy.x, xy.y) + height);
        Camera {
            eye,
            target: eye + DVec3::new(0.0, 1000.0, -80.0),
            ..start(&field)
        }
    };
    let mut random = SplitMix64(31);
    for _ in 0..50 {
        let xy = DVec2::new(random.next_f64(), random.next_f64()) * field.extent();
        let high = settings.anchor(&field, &at(xy, 2.0 * coarsest), None).expect("anchor");
        assert_eq!((high.spacing, high.level), (coarsest, Some(0)), "a flying eye");
        let walking = at(xy, 2.0);
        let low = settings.anchor(&field, &walking, None).expect("anchor");
        assert!(
            low.spacing <= HEIGHT_FACTOR * 2.0 && low.spacing > 0.5 * HEIGHT_FACTOR * 2.0,
            "grid {} m for an eye 2 m up",
            low.spacing
        );
        assert!(low.camera.eye.distance(walking.eye) <= 0.5 * 3f64.sqrt() * low.spacing + 1e-9);
        let ground = sample_bspline(&field, xy.x, xy.y);
        assert!(
            low.camera.eye.z >= ground - 1e-9,
            "the planned eye is no lower than the ground under the real one"
        );
        // Hysteresis: the last level kept while its grid is in [¼, 1] of what the height allows.
        let level = low.level.expect("snapped");
        let kept = settings.anchor(&field, &at(xy, 4.0), Some(level)).expect("anchor");
        assert_eq!(kept.level, Some(level), "2 m's grid at 4 m");
        let fresh = settings.anchor(&field, &at(xy, 4.0), None).expect("anchor");
        assert!(
            fresh.level.expect("snapped") < level,
            "a fresh plan at 4 m takes a coarser grid"
        );
        let finer = settings.anchor(&field, &at(xy, 0.9), Some(level)).expect("anchor");
        assert!(
            finer.level.expect("snapped") > level,
            "2 m's grid is too coarse at 0.9 m"
        );
        let under = at(xy, -1.0);
        let unsnapped = |camera: &Camera, settings: &LodSettings| {
            let anchor = settings.anchor(&field, camera, Some(level)).expect("anchor");
            (anchor.spacing, anchor.level, anchor.camera) == (0.0, None, *camera)
        };
        assert!(unsnapped(&under, &settings), "an eye under the ground");
        assert!(unsnapped(&walking, &LodSettings { snap: 0.0, ..settings }), "snap 0");
    }
}
