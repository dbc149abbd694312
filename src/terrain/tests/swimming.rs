//! The swimming metric (dissertation §7.4.3, §7.4.5;
//! [`crate::terrain::swimming`]): the CPU rasterizer against an analytic
//! plane and against the ray cast, zero swimming for a static camera and
//! for a world-static mesh, and more swimming for a deliberately jittered
//! warp than for the plain one. Small images and grids (a debug build);
//! the figures of the default sizes are in `docs/PERFORMANCE.md`
//! (`--bin swimming`).

use glam::{DVec2, DVec3};

use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::terrain::lod::{DebugScalar, LodFrame, LodMode, LodSettings};
use crate::terrain::procedural::ProceduralTerrain;
use crate::terrain::swimming::{camera_path, measure, rasterize, shade, Mesh, Swimming};
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

fn settings(mode: LodMode) -> LodSettings {
    LodSettings {
        sketch_side: SKETCH,
        mode,
        ..Default::default()
    }
}

/// The swimming of the renderer's LOD in `mode` along `cameras`, every
/// frame's warped sketch map moved by `jitter(k, warped)` first.
fn lod_swimming(
    field: &HeightField,
    cameras: &[Camera],
    mode: LodMode,
    mut jitter: impl FnMut(usize, &mut [DVec3]),
) -> Swimming {
    let mut frame = LodFrame::default();
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    measure(field, cameras, SIZE, |k, camera| {
        frame.plan(field, camera, aspect, &settings(mode), DebugScalar::None)?;
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
