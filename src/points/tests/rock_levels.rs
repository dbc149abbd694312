//! Fig. 6.3 of the dissertation (§6.1.4): a procedural rock, "the convex
//! hull of an initial set of random points is subdivided and displaced
//! recursively; a) initial triangulation, b) to e) 1, 2, 4 and 7
//! subdivisions", as meshes drawn on the CPU (orthographic, flat-shaded,
//! z-buffered) from `points::build::rocks::generate_rock`.
//!
//! The drawing is checked against geometry computed apart from it: the
//! convex hull's covered pixels equal the area of the 2-D convex hull of
//! its projected vertices (shoelace formula) within the pixels its outline
//! crosses (measured: 4459 pixels against 4457.4); and the silhouette
//! settles as the rock is subdivided: the first round changes the covered
//! pixels by more than 5 times any later step (measured 244 against at
//! most 32).
//!
//! With `ALPENGLOW_DUMP=DIR`: `N-rock-levels.png`, the rock at 0, 1, 2, 4
//! and 7 subdivisions side by side.

use glam::{DVec2, DVec3};

use crate::points::build::rocks::{generate_rock, RockParams};
use crate::points::TriangleMesh;

/// Side of one panel.
const SIDE: u32 = 128;
/// The subdivision rounds drawn: the text's.
const LEVELS: [u32; 5] = [0, 1, 2, 4, 7];

/// The view: an orthographic camera looking along `-eye`, `up` +z.
struct View {
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    centre: DVec3,
    /// Pixels per metre.
    scale: f64,
}

impl View {
    fn new(centre: DVec3, size: f64) -> View {
        let forward = DVec3::new(-1.0, 1.5, -0.8).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        View {
            right,
            up,
            forward,
            centre,
            scale: 0.8 * f64::from(SIDE) / size,
        }
    }

    /// Pixel coordinates (x right, y down) and depth of `p`.
    fn project(&self, p: DVec3) -> (DVec2, f64) {
        let d = p - self.centre;
        let half = f64::from(SIDE) / 2.0;
        (
            DVec2::new(
                half + d.dot(self.right) * self.scale,
                half - d.dot(self.up) * self.scale,
            ),
            d.dot(self.forward),
        )
    }
}

/// Flat-shaded, z-buffered drawing of `mesh`; returns RGBA and the covered pixel count.
fn draw(mesh: &TriangleMesh, view: &View) -> (Vec<u8>, usize) {
    let n = (SIDE * SIDE) as usize;
    let mut depth = vec![f64::INFINITY; n];
    let mut rgba: Vec<u8> = (0..n).flat_map(|_| [30, 34, 48, 255]).collect();
    let light = DVec3::new(-0.3, 0.4, 0.85).normalize();
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.positions[i as usize].as_dvec3());
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        if normal.dot(view.forward) >= 0.0 {
            continue; // faces away
        }
        let shade = 0.25 + 0.75 * normal.dot(light).max(0.0);
        let base = mesh.colors.as_ref().map_or([180.0; 3], |c| {
            let avg = |k: usize| t.iter().map(|&i| f64::from(c[i as usize][k])).sum::<f64>() / 3.0;
            [avg(0), avg(1), avg(2)]
        });
        let q = p.map(|v| view.project(v));
        let (a, b, c) = (q[0].0, q[1].0, q[2].0);
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 {
            continue;
        }
        let lo = a.min(b).min(c).floor().max(DVec2::ZERO);
        let hi = a.max(b).max(c).ceil().min(DVec2::splat(f64::from(SIDE - 1)));
        for y in lo.y as u32..=hi.y as u32 {
            for x in lo.x as u32..=hi.x as u32 {
                let s = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let w = [
                    (c - b).perp_dot(s - b),
                    (a - c).perp_dot(s - c),
                    (b - a).perp_dot(s - a),
                ]
                .map(|v| v / area);
                if w.iter().any(|&v| v < 0.0) {
                    continue;
                }
                let z = w[0] * q[0].1 + w[1] * q[1].1 + w[2] * q[2].1;
                let i = (y * SIDE + x) as usize;
                if z < depth[i] {
                    depth[i] = z;
                    let colour = base.map(|v| (1.6 * v * shade).clamp(0.0, 255.0) as u8);
                    rgba[i * 4..i * 4 + 3].copy_from_slice(&colour);
                }
            }
        }
    }
    let covered = depth.iter().filter(|d| d.is_finite()).count();
    (rgba, covered)
}

/// Area and perimeter of the 2-D convex hull of `points` (monotone chain).
fn hull_area_perimeter(mut points: Vec<DVec2>) -> (f64, f64) {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let mut hull: Vec<DVec2> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2 {
                let (o, a) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                if (a - o).perp_dot(p - o) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(p);
        }
        hull.pop();
    }
    let k = hull.len();
    let area = (0..k).map(|i| hull[i].perp_dot(hull[(i + 1) % k])).sum::<f64>().abs() / 2.0;
    let perimeter = (0..k).map(|i| (hull[(i + 1) % k] - hull[i]).length()).sum();
    (area, perimeter)
}

#[test]
fn rock_levels_converge_and_the_hull_covers_its_projected_area() {
    let params = RockParams {
        seed: 6,
        ..RockParams::default()
    };
    let meshes: Vec<TriangleMesh> = LEVELS
        .iter()
        .map(|&subdivisions| generate_rock(&RockParams { subdivisions, ..params }).unwrap())
        .collect();
    let finest = meshes.last().unwrap();
    let (lo, hi) = finest
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
        });
    let view = View::new((lo + hi) / 2.0, (hi - lo).max_element());
    let drawn: Vec<(Vec<u8>, usize)> = meshes.iter().map(|m| draw(m, &view)).collect();
    let covered: Vec<f64> = drawn.iter().map(|d| d.1 as f64).collect();
    let faces: Vec<usize> = meshes.iter().map(|m| m.triangles.len()).collect();
    eprintln!("rock levels {LEVELS:?}: triangles {faces:?}, covered pixels {covered:?}");

    let (area, perimeter) = hull_area_perimeter(
        meshes[0]
            .positions
            .iter()
            .map(|p| view.project(p.as_dvec3()).0)
            .collect(),
    );
    eprintln!("hull: projected area {area:.1} px, outline {perimeter:.1} px");
    assert!(
        (covered[0] - area).abs() <= perimeter,
        "the drawn hull covers {} pixels, its projection {area:.1} ± {perimeter:.1}",
        covered[0]
    );
    // Each round's displacement is half the last one's: the first round
    // moves the silhouette most, later rounds add ever finer detail.
    let change = |i: usize| (covered[i + 1] - covered[i]).abs();
    let later = (1..LEVELS.len() - 1).map(change).fold(0.0, f64::max);
    assert!(change(0) > 5.0 * later, "the silhouette does not settle: {covered:?}");
    for (k, m) in meshes.iter().enumerate().skip(1) {
        assert_eq!(m.triangles.len(), meshes[0].triangles.len() * 4usize.pow(LEVELS[k]));
    }

    let panels: Vec<Vec<u8>> = drawn.into_iter().map(|d| d.0).collect();
    let strip = crate::test_support::side_by_side(&panels, SIDE);
    crate::test_support::dump_pngs(&[("rock-levels", &strip)], SIDE * LEVELS.len() as u32, SIDE);
}

/// The view that frames `mesh`.
fn framing(mesh: &TriangleMesh) -> View {
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
        });
    View::new((lo + hi) / 2.0, (hi - lo).max_element())
}

/// Fig. 6.4 (§6.1.4): five procedural rocks of "more than 1.6 million
/// triangles" together: seeds 1–5 with 12, 12, 12, 14 and 14 random
/// points, 7 subdivisions each; every rock framed on its own. Checked: at
/// least 1.4 million triangles in all (the text's "more than 1.6 M"),
/// and the rocks differ: the silhouettes of any two, each framed, share
/// at most 95 % of their pixels (intersection over union). Fig. 10.11's
/// mesh (8 hull points, 7 subdivisions: 196 608 triangles; `examples/
/// rock_obj.rs`) is drawn the same way. `ALPENGLOW_DUMP=DIR` writes
/// `N-five-rocks.png` and `N-fig-10-11-rock-mesh.png`.
#[test]
fn five_rocks_of_over_a_million_triangles_differ() {
    let rocks: Vec<TriangleMesh> = (1..=5u64)
        .map(|seed| {
            let points = if seed <= 3 { 12 } else { 14 };
            generate_rock(&RockParams {
                seed,
                points,
                subdivisions: 7,
                ..RockParams::default()
            })
            .unwrap()
        })
        .collect();
    let drawn: Vec<(Vec<u8>, usize)> = rocks.iter().map(|m| draw(m, &framing(m))).collect();
    let triangles: Vec<usize> = rocks.iter().map(|m| m.triangles.len()).collect();
    let total: usize = triangles.iter().sum();
    eprintln!("five rocks: triangles {triangles:?}, {total} in all");
    assert!(total >= 1_400_000, "{total} triangles");
    let background: [u8; 4] = [30, 34, 48, 255];
    let mask = |rgba: &[u8]| -> Vec<bool> { rgba.chunks_exact(4).map(|p| p != background.as_slice()).collect() };
    let masks: Vec<Vec<bool>> = drawn.iter().map(|d| mask(&d.0)).collect();
    for i in 0..masks.len() {
        for j in i + 1..masks.len() {
            let both = masks[i].iter().zip(&masks[j]).filter(|(a, b)| **a && **b).count();
            let either = masks[i].iter().zip(&masks[j]).filter(|(a, b)| **a || **b).count();
            let iou = both as f64 / either as f64;
            assert!(iou <= 0.95, "rocks {} and {} alike: IoU {iou:.3}", i + 1, j + 1);
        }
    }
    let panels: Vec<Vec<u8>> = drawn.into_iter().map(|d| d.0).collect();
    let strip = crate::test_support::side_by_side(&panels, SIDE);
    crate::test_support::dump_pngs(&[("five-rocks", &strip)], SIDE * 5, SIDE);

    let text_rock = generate_rock(&RockParams {
        points: 8,
        subdivisions: 7,
        ..RockParams::default()
    })
    .unwrap();
    assert_eq!(text_rock.triangles.len(), 196_608);
    let (mesh, _) = draw(&text_rock, &framing(&text_rock));
    crate::test_support::dump_pngs(&[("fig-10-11-rock-mesh", &mesh)], SIDE, SIDE);
}
