//! Tests of [`super`]: the mesh sampler.
use super::*;

fn unit_square() -> TriangleMesh {
    TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    }
}

/// Separate triangles of different sizes, triangle t in the plane z = t.
fn stacked_triangles() -> TriangleMesh {
    let sizes = [1.0f32, 0.37, 2.5, 0.05, 1.3, 0.8];
    let mut mesh = TriangleMesh::default();
    for (t, &s) in sizes.iter().enumerate() {
        let z = t as f32;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([
            Vec3::new(0.0, 0.0, z),
            Vec3::new(s, 0.0, z),
            Vec3::new(0.2 * s, 0.7 * s, z),
        ]);
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    mesh
}

fn options(count: usize, method: SamplingMethod, seed: u64) -> SamplingOptions {
    SamplingOptions { count, method, seed }
}

fn distance_to_mesh(mesh: &TriangleMesh, p: Vec3) -> f32 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = (b - a).cross(c - a);
            if n.length() == 0.0 {
                return f32::INFINITY;
            }
            let n = n.normalize();
            let plane = (p - a).dot(n).abs();
            // Inside test by edge functions (with a small tolerance).
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(e0, e1)| (e1 - e0).cross(p - e0).dot(n) >= -1e-5);
            if inside {
                plane
            } else {
                f32::INFINITY
            }
        })
        .fold(f32::INFINITY, f32::min)
}

fn min_distance(surfels: &[Surfel]) -> f32 {
    let mut best = f32::INFINITY;
    for (i, a) in surfels.iter().enumerate() {
        for b in &surfels[i + 1..] {
            best = best.min(a.position.distance(b.position));
        }
    }
    best
}

#[test]
fn count_is_exact() {
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        for mesh in [unit_square(), stacked_triangles()] {
            for count in [1, 2, 7, 100, 1013] {
                let surfels = sample_mesh(&mesh, &options(count, method, 42)).unwrap();
                assert_eq!(surfels.len(), count, "{method:?}");
            }
        }
    }
}

#[test]
fn samples_lie_on_the_mesh() {
    let mut mesh = stacked_triangles();
    // Tilt the triangles out of their planes.
    for p in &mut mesh.positions {
        p.z += 0.3 * p.x - 0.2 * p.y;
    }
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        for s in sample_mesh(&mesh, &options(2000, method, 5)).unwrap() {
            assert!(distance_to_mesh(&mesh, s.position) < 1e-5, "{s:?}");
            assert_eq!(s.color, DEFAULT_COLOR);
        }
    }
}

#[test]
fn stratified_counts_follow_area() {
    let mesh = stacked_triangles();
    let areas: Vec<f32> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let total: f32 = areas.iter().sum();
    for (count, seed) in [(10, 1), (333, 2), (5000, 3), (5000, 4)] {
        let surfels = sample_mesh(&mesh, &options(count, SamplingMethod::Stratified, seed)).unwrap();
        let mut per = vec![0usize; areas.len()];
        for s in &surfels {
            per[s.position.z.round() as usize] += 1;
        }
        for (t, &a) in areas.iter().enumerate() {
            let expected = count as f32 * a / total;
            assert!(
                (per[t] as f32 - expected).abs() <= 1.0 + 1e-3,
                "triangle {t}: {} vs {expected}",
                per[t]
            );
        }
    }
}

#[test]
fn blue_noise_spreads_samples() {
    let mesh = unit_square();
    let count = 1000;
    let stratified = sample_mesh(&mesh, &options(count, SamplingMethod::Stratified, 9)).unwrap();
    let blue = sample_mesh(&mesh, &options(count, SamplingMethod::BlueNoise, 9)).unwrap();
    let (ds, db) = (min_distance(&stratified), min_distance(&blue));
    let r_max = (1.0 / (2.0 * 3.0f32.sqrt() * count as f32)).sqrt();
    println!(
        "min distance: stratified {ds:.5}, blue noise {db:.5} (2·r_max = {:.5})",
        2.0 * r_max
    );
    assert!(db >= 1.5 * ds, "blue noise {db} vs stratified {ds}");
    assert!(db > r_max, "blue noise {db} vs r_max {r_max}");
}

#[test]
fn both_sides_of_a_thin_sheet_keep_samples() {
    let mut mesh = unit_square();
    mesh.positions.extend([
        Vec3::new(0.0, 0.0, 1e-3),
        Vec3::new(1.0, 0.0, 1e-3),
        Vec3::new(1.0, 1.0, 1e-3),
        Vec3::new(0.0, 1.0, 1e-3),
    ]);
    mesh.triangles.extend([[4, 6, 5], [4, 7, 6]]); // Facing −z.
    let surfels = sample_mesh(&mesh, &options(1000, SamplingMethod::BlueNoise, 4)).unwrap();
    let back = surfels.iter().filter(|s| s.normal == -Vec3::Z).count();
    assert!((450..=550).contains(&back), "{back} of 1000 on the back");
}

#[test]
fn normals_follow_winding_or_vertices() {
    let mut mesh = unit_square();
    mesh.triangles[1] = [0, 3, 2]; // Clockwise from +z.
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        for s in sample_mesh(&mesh, &options(500, method, 1)).unwrap() {
            assert!(s.normal.is_normalized());
            let expected = if s.position.x > s.position.y { Vec3::Z } else { -Vec3::Z };
            if (s.position.x - s.position.y).abs() > 1e-4 {
                assert_eq!(s.normal, expected, "{s:?}");
            }
        }
    }

    let mut mesh = unit_square();
    mesh.normals = Some(vec![Vec3::X, Vec3::Y * 3.0, Vec3::Z, Vec3::ZERO]);
    for s in sample_mesh(&mesh, &options(500, SamplingMethod::Stratified, 1)).unwrap() {
        assert!(s.normal.is_normalized());
        assert!(s.normal.min_element() >= 0.0);
    }
}

#[test]
fn colours_are_interpolated() {
    let mut mesh = unit_square();
    mesh.colors = Some(vec![[255, 0, 10]; 4]);
    for s in sample_mesh(&mesh, &options(100, SamplingMethod::BlueNoise, 1)).unwrap() {
        assert_eq!(s.color, [255, 0, 10]);
    }
    mesh.colors = Some(vec![[0, 0, 0], [200, 0, 0], [200, 0, 0], [0, 0, 0]]);
    for s in sample_mesh(&mesh, &options(100, SamplingMethod::Stratified, 1)).unwrap() {
        assert!((f32::from(s.color[0]) - 200.0 * s.position.x).abs() <= 1.0, "{s:?}");
    }
}

#[test]
fn deterministic_for_a_seed() {
    let mesh = stacked_triangles();
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        let a = sample_mesh(&mesh, &options(777, method, 11)).unwrap();
        let b = sample_mesh(&mesh, &options(777, method, 11)).unwrap();
        let c = sample_mesh(&mesh, &options(777, method, 12)).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}

#[test]
fn disks_cover_the_square() {
    let mesh = unit_square();
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        for (count, seed) in [(500, 1), (2000, 2), (5000, 3)] {
            let surfels = sample_mesh(&mesh, &options(count, method, seed)).unwrap();
            let r = surfels[0].radius;
            let expected = (1.0 / (std::f32::consts::PI * count as f32)).sqrt() * method.radius_overlap();
            assert!((r - expected).abs() < 1e-6 * expected);
            assert!(surfels.iter().all(|s| s.radius == r));
            // Blue noise covers the boundary too; stratified sampling is
            // only promised to cover points a sample spacing inside the
            // open boundary (module docs).
            let inset = match method {
                SamplingMethod::Stratified => (1.0 / count as f32).sqrt(),
                SamplingMethod::BlueNoise => 0.0,
            };
            let mut worst = 0.0f32;
            for i in 0..50 {
                for j in 0..50 {
                    let at = |i: usize| inset + (1.0 - 2.0 * inset) * i as f32 / 49.0;
                    let q = Vec3::new(at(i), at(j), 0.0);
                    let d = surfels
                        .iter()
                        .map(|s| s.position.distance(q))
                        .fold(f32::INFINITY, f32::min);
                    worst = worst.max(d);
                }
            }
            println!("{method:?} {count}: largest gap {worst:.4}, radius {r:.4}");
            assert!(worst < r, "{method:?} {count}: hole of {worst} with radius {r}");
        }
    }
}

#[test]
fn degenerate_triangles_are_skipped() {
    let mut mesh = unit_square();
    mesh.positions.push(Vec3::new(5.0, 5.0, 5.0));
    mesh.triangles.insert(0, [4, 4, 4]);
    mesh.triangles.push([0, 1, 1]);
    let surfels = sample_mesh(&mesh, &options(300, SamplingMethod::Stratified, 3)).unwrap();
    assert_eq!(surfels.len(), 300);
    assert!(surfels.iter().all(|s| s.position.z == 0.0 && s.normal == Vec3::Z));
}

#[test]
fn bad_input_is_an_error() {
    let mesh = unit_square();
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        assert!(sample_mesh(&mesh, &options(0, method, 0)).is_err());
        assert!(sample_mesh(&TriangleMesh::default(), &options(10, method, 0)).is_err());
        let mut flat = unit_square();
        flat.positions = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::X * 3.0];
        assert!(sample_mesh(&flat, &options(10, method, 0)).is_err());
        let mut bad = unit_square();
        bad.triangles.push([0, 1, 9]);
        assert!(sample_mesh(&bad, &options(10, method, 0)).is_err());
        let mut bad = unit_square();
        bad.positions[2].x = f32::NAN;
        assert!(sample_mesh(&bad, &options(10, method, 0)).is_err());
        let mut bad = unit_square();
        bad.normals = Some(vec![Vec3::Z; 3]);
        assert!(sample_mesh(&bad, &options(10, method, 0)).is_err());
        let mut bad = unit_square();
        bad.colors = Some(vec![[1; 3]; 5]);
        assert!(sample_mesh(&bad, &options(10, method, 0)).is_err());
    }
    assert!(sample_mesh(&mesh, &options(usize::MAX / 2, SamplingMethod::BlueNoise, 0)).is_err());
    assert!(sample_mesh(&mesh, &options(usize::MAX / 2, SamplingMethod::Stratified, 0)).is_err());
}

/// The unit cube [0, 1]³, outward counter-clockwise, two triangles per
/// face; `split`: every face has its own four vertices (as OBJ files with
/// face normals have them), else the 8 corners are shared.
fn cube(split: bool) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    let corner = |p: Vec3| (p.x as u32) | (p.y as u32) << 1 | (p.z as u32) << 2;
    if !split {
        mesh.positions = (0..8u32)
            .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32))
            .collect();
    }
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut quad = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
            if side == 0.0 {
                quad.reverse();
            }
            let points = quad.map(|(a, b)| {
                let mut p = Vec3::ZERO;
                p[axis] = side;
                p[u] = a;
                p[v] = b;
                p
            });
            let index = points.map(|p| {
                if split {
                    mesh.positions.push(p);
                    mesh.positions.len() as u32 - 1
                } else {
                    corner(p)
                }
            });
            mesh.triangles.push([index[0], index[1], index[2]]);
            mesh.triangles.push([index[0], index[2], index[3]]);
        }
    }
    mesh
}

#[test]
fn cube_edges_clip_the_surfels_near_them() {
    use crate::points::build::clip::tangent_frame;
    for split in [false, true] {
        let mesh = cube(split);
        for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
            let surfels = sample_mesh(&mesh, &options(3000, method, 3)).unwrap();
            let (mut near, mut corners) = (0, 0);
            for s in &surfels {
                let r = s.radius;
                let axis = (0..3).find(|&k| s.normal[k].abs() == 1.0).unwrap();
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                // The face's four edges: (distance, unit direction towards it).
                let mut edges = Vec::new();
                for w in [u, v] {
                    let mut e = Vec3::ZERO;
                    e[w] = 1.0;
                    edges.push((s.position[w], -e));
                    edges.push((1.0 - s.position[w], e));
                }
                let dmin = edges.iter().map(|e| e.0).fold(f32::INFINITY, f32::min);
                let lines = s.clip.0.iter().flatten().count();
                if dmin > r * (1.0 + 1e-4) {
                    assert_eq!(s.clip, ClipLines::NONE, "{s:?}: the middle of a face");
                    continue;
                }
                let cut: Vec<(f32, Vec3)> = edges.iter().copied().filter(|e| e.0 < r).collect();
                if dmin < r * (1.0 - 1e-4) {
                    // One line per edge closer than r (two at most),
                    // give or take edges at distance ≈ r.
                    let sure = cut.iter().filter(|e| e.0 < r * (1.0 - 1e-4)).count();
                    assert!((sure.min(2)..=cut.len().min(2)).contains(&lines), "{s:?}");
                    near += 1;
                    corners += usize::from(lines == 2);
                }
                assert!(s.clip.keeps(0.0, 0.0), "{s:?}: the centre is kept");
                let (t, b) = tangent_frame(s.normal);
                let tangent = |q: Vec3| (q.dot(t), q.dot(b));
                for &(d, dir) in &cut {
                    // The point of the disk across the edge goes, the
                    // point short of it on the face stays.
                    let (a, c) = tangent(dir * r);
                    assert!(d > r * 0.999 || !s.clip.keeps(a, c), "{s:?}: across {dir}");
                    let (a, c) = tangent(dir * d * 0.99);
                    assert!(s.clip.keeps(a, c), "{s:?}: short of {dir}");
                }
            }
            println!("{method:?}, split {split}: {near} of 3000 surfels clipped, {corners} twice");
            assert!(near > 300 && corners > 5, "{near} {corners}");
        }
    }
}

#[test]
fn only_creases_and_not_boundaries_clip() {
    // Flat square: boundary edges only.
    for s in sample_mesh(&unit_square(), &options(500, SamplingMethod::Stratified, 1)).unwrap() {
        assert_eq!(s.clip, ClipLines::NONE);
    }
    // Two squares hinged along the y axis at a dihedral angle below and
    // above 30°.
    for (degrees, creased) in [(20.0f32, false), (40.0, true)] {
        let a = degrees.to_radians();
        let mesh = TriangleMesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(-a.cos(), 1.0, a.sin()),
                Vec3::new(-a.cos(), 0.0, a.sin()),
            ],
            triangles: vec![[0, 3, 2], [0, 2, 1], [0, 1, 4], [0, 4, 5]],
            ..Default::default()
        };
        let surfels = sample_mesh(&mesh, &options(1000, SamplingMethod::BlueNoise, 2)).unwrap();
        let clipped = surfels.iter().filter(|s| s.clip != ClipLines::NONE).count();
        if creased {
            // The fold (x = 0) only: the clip keeps x ≥ 0 on the flat side.
            assert!(clipped > 50, "{clipped}");
            for s in surfels.iter().filter(|s| s.normal == Vec3::Z) {
                let near = s.position.x < s.radius;
                assert_eq!(s.clip != ClipLines::NONE, near, "{s:?}");
                if near {
                    let (t, b) = crate::points::build::clip::tangent_frame(s.normal);
                    let across = Vec3::new(-s.position.x - 1e-3, 0.0, 0.0);
                    assert!(!s.clip.keeps(across.dot(t), across.dot(b)));
                    assert!(s.clip.0[1].is_none());
                }
            }
        } else {
            assert_eq!(clipped, 0);
        }
    }
}

#[test]
fn sample_counts_are_bounded_by_memory() {
    // The sizes the estimate is made of, and what it comes to.
    let blue = sampling_footprint(1, SamplingMethod::BlueNoise).host;
    let stratified = sampling_footprint(1, SamplingMethod::Stratified).host;
    println!("{blue} B a blue-noise sample, {stratified} B a stratified one");
    assert!(
        (400..=800).contains(&blue) && (100..=400).contains(&stratified),
        "{blue} {stratified}"
    );
    assert_eq!(sampling_footprint(1000, SamplingMethod::BlueNoise).host, 1000 * blue);
    assert_eq!(sampling_footprint(usize::MAX, SamplingMethod::BlueNoise).host, u64::MAX);
    // 10⁸ samples need more than any test machine has left after this;
    // the error comes before anything is sampled.
    let e = sample_mesh(&unit_square(), &options(usize::MAX / 64, SamplingMethod::BlueNoise, 1)).unwrap_err();
    assert_eq!(e.parameter(), Some("sample count"));
    assert!(e.to_string().contains("of host memory;"), "{e}");
}

#[test]
fn speed_35k_samples() {
    let mesh = stacked_triangles();
    for method in [SamplingMethod::Stratified, SamplingMethod::BlueNoise] {
        let start = std::time::Instant::now();
        let surfels = sample_mesh(&mesh, &options(35_000, method, 1)).unwrap();
        println!(
            "{method:?}: {} samples in {:.1} ms",
            surfels.len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
}
