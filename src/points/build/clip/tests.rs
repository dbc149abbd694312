//! Tests of clip lines and crease detection.

use super::*;

#[test]
fn tangent_frame_is_orthonormal_and_right_handed() {
    let mut rng = crate::random::SplitMix64(7);
    for _ in 0..1000 {
        let n = Vec3::new(
            rng.next_f64() as f32 - 0.5,
            rng.next_f64() as f32 - 0.5,
            rng.next_f64() as f32 - 0.5,
        );
        if n.length() < 1e-3 {
            continue;
        }
        let n = n.normalize();
        let (t, b) = tangent_frame(n);
        assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        assert!(t.dot(b).abs() < 1e-5 && t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5);
        assert!((t.cross(b) - n).length() < 1e-4, "{n} {t} {b}");
    }
    for n in [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y] {
        let (t, b) = tangent_frame(n);
        assert!((t.cross(b) - n).length() < 1e-6);
    }
}

#[test]
fn packed_lines_keep_the_right_side() {
    let lines = ClipLines([
        Some(ClipLine {
            angle: 0.0,
            offset: 0.25,
        }),
        None,
    ]);
    assert!(lines.keeps(0.2, 5.0) && !lines.keeps(0.3, 0.0));
    assert_eq!(lines.packed(), [0.0, 0.25, 0.0, f32::MAX]);
    assert!(ClipLines::NONE.keeps(1e6, -1e6));
}

/// A closed cylinder of radius 1 and height 1 with `n` segments, its caps
/// fanned around a centre vertex: (positions, triangles, face normals).
fn fanned_cylinder(n: usize) -> (Vec<Vec3>, Vec<[usize; 3]>, Vec<Vec3>) {
    let ring = |k: usize, z: f32| {
        let a = std::f32::consts::TAU * (k % n) as f32 / n as f32;
        Vec3::new(a.cos(), a.sin(), z)
    };
    let mut positions: Vec<Vec3> = (0..n)
        .map(|k| ring(k, 0.0))
        .chain((0..n).map(|k| ring(k, 1.0)))
        .collect();
    positions.push(Vec3::new(0.0, 0.0, 0.0));
    positions.push(Vec3::new(0.0, 0.0, 1.0));
    let (bottom, top) = (2 * n, 2 * n + 1);
    let mut triangles = Vec::new();
    for k in 0..n {
        let next = (k + 1) % n;
        triangles.push([k, next, n + next]);
        triangles.push([k, n + next, n + k]);
        triangles.push([bottom, next, k]);
        triangles.push([top, n + k, n + next]);
    }
    let normals = face_normals(&positions, &triangles);
    (positions, triangles, normals)
}

/// A star-shaped polygon of `n` vertices whose rim zigzags up and down,
/// fanned from its first vertex (as loaders triangulate a face): every
/// spoke is a crease.
fn zigzag_fan(n: usize) -> (Vec<Vec3>, Vec<[usize; 3]>, Vec<Vec3>) {
    let positions: Vec<Vec3> = (0..n)
        .map(|k| {
            let a = std::f32::consts::PI * k as f32 / n as f32;
            Vec3::new(a.cos(), a.sin(), if k % 2 == 0 { 0.0 } else { 0.4 })
        })
        .collect();
    let triangles: Vec<[usize; 3]> = (1..n - 1).map(|k| [0, k, k + 1]).collect();
    let normals = face_normals(&positions, &triangles);
    (positions, triangles, normals)
}

fn face_normals(positions: &[Vec3], triangles: &[[usize; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .map(|t| {
            (positions[t[1]] - positions[t[0]])
                .cross(positions[t[2]] - positions[t[0]])
                .normalize()
        })
        .collect()
}

/// The crease edges near each triangle as the first version stored them:
/// for every triangle, the crease edges of every triangle sharing a welded
/// vertex with it (sorted ids); quadratic in a vertex's triangle count.
fn near_by_triangle(creases: &Creases, positions: &[Vec3], triangles: &[[usize; 3]]) -> Vec<Vec<u32>> {
    let vertices = creases
        .corners
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut welded = vec![Vec3::ZERO; vertices];
    for (c, t) in creases.corners.iter().zip(triangles) {
        for k in 0..3 {
            welded[c[k] as usize] = positions[t[k]];
        }
    }
    let normals = face_normals(positions, triangles);
    let (edges, own) = crease_edges(&creases.corners, &welded, &normals);
    assert_eq!(edges, creases.edges);
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); vertices];
    for (t, c) in creases.corners.iter().enumerate() {
        for &v in c {
            around[v as usize].push(t as u32);
        }
    }
    (creases.corners.iter())
        .map(|c| {
            let mut found: Vec<u32> = (c.iter())
                .flat_map(|&v| around[v as usize].iter().flat_map(|&u| own[u as usize].iter().copied()))
                .collect();
            found.sort_unstable();
            found.dedup();
            found
        })
        .collect()
}

#[test]
fn lines_match_the_per_triangle_lists_they_replace() {
    let mut rng = crate::random::SplitMix64(11);
    let meshes = [fanned_cylinder(7), fanned_cylinder(90), zigzag_fan(300), zigzag_fan(9)];
    for (m, (positions, triangles, normals)) in meshes.iter().enumerate() {
        let creases = Creases::new(positions, triangles, normals);
        assert!(!creases.is_empty());
        let reference = near_by_triangle(&creases, positions, triangles);
        let (mut clipped, mut queries) = (0, 0);
        for _ in 0..20_000 {
            let t = (rng.next_u64() % triangles.len() as u64) as usize;
            let [a, b, c] = triangles[t].map(|v| positions[v]);
            let (u, v) = (rng.next_f64() as f32, rng.next_f64() as f32);
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let centre = a + u * (b - a) + v * (c - a);
            // Mostly the face normal, sometimes tilted.
            let tilt = Vec3::new(rng.next_f64() as f32, rng.next_f64() as f32, rng.next_f64() as f32) - 0.5;
            let normal = if rng.next_u64() % 4 == 0 {
                (normals[t] + tilt).normalize()
            } else {
                normals[t]
            };
            let radius = 10f32.powf(-3.0 + 3.0 * rng.next_f64() as f32);
            let got = creases.lines(t, centre, normal, radius);
            let want = creases.lines_of(&reference[t], t, centre, normal, radius);
            assert_eq!(got, want, "mesh {m}, triangle {t}, centre {centre}, radius {radius}");
            clipped += usize::from(got != ClipLines::NONE);
            queries += 1;
        }
        assert!(clipped > queries / 50, "mesh {m}: {clipped} of {queries} clipped");
    }
}

#[test]
fn a_fan_of_a_hundred_thousand_vertices_stays_linear() {
    // 50,000 segments: 100,002 vertices, each cap a fan of 50,000 triangles
    // around its centre (the first version stored 50,000² edge ids per cap).
    let n = 50_000;
    let (positions, triangles, normals) = fanned_cylinder(n);
    let creases = Creases::new(&positions, &triangles, &normals);
    assert_eq!(creases.len(), 2 * n, "the two rims");
    assert!(creases.around.len() <= 9 * triangles.len(), "{}", creases.around.len());
    let boxes: usize = creases.trees.values().map(|t| t.boxes.len()).sum();
    assert!(boxes <= creases.around.len(), "{boxes}");
    // Surfels on the bottom cap near the rim are clipped by it, and a query
    // visits a few leaves only, so many of them are quick.
    let radius = 0.01;
    let mut clipped = 0;
    for k in 0..20_000 {
        let t = 4 * (k * 7 % n) + 2;
        let [hub, p, q] = triangles[t].map(|v| positions[v]);
        let centre = hub + 0.995 * (0.5 * (p + q) - hub);
        let lines = creases.lines(t, centre, normals[t], radius);
        clipped += usize::from(lines.0[0].is_some());
        assert!(lines.keeps(0.0, 0.0));
    }
    assert_eq!(clipped, 20_000);
}
