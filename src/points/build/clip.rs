//! Clip lines for sharp features (dissertation §10.2.4; `ALGORITHMS.md` §8):
//! up to two lines per splat in the splat's tangent plane; a fragment of the
//! splat counts only on the kept side of each line.
//!
//! The tangent frame of a disk with unit normal n is [`tangent_frame`]
//! (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017),
//! computed identically by `glsl/include/splat.glsl`. A line is stored as an
//! angle θ and an offset c in object units: the kept side is
//! `u·cos θ + v·sin θ ≤ c`, (u, v) the tangent coordinates of a point
//! relative to the disk centre. No line is `c = +∞` (stored as `f32::MAX`).
//!
//! # Lines from meshes
//!
//! The text intersects the tangent planes of adjacent splats at sharp bends
//! (Fig. 10.20). For surfels sampled from a triangle mesh the bends are
//! known exactly, so we take them from the mesh instead ([`Creases`]):
//!
//! * vertices are welded by position (files often split a vertex wherever
//!   its normal changes, exactly at the creases), and an edge shared by
//!   exactly two triangles is a **crease** when their face normals differ
//!   by more than [`CREASE_ANGLE_DEGREES`] = 30°. Boundary edges (one
//!   triangle) and non-manifold edges (more than two) are not clipped.
//! * a surfel sampled in triangle T considers the crease edges of T and of
//!   every triangle sharing a (welded) vertex with T, which covers creases
//!   that run just past T's corners. An edge is projected into the surfel's
//!   tangent plane; edges steeper than 30° to that plane (the far edges of
//!   the neighbouring faces at a corner, which project to nearly a point)
//!   are skipped. If the projected *segment* comes closer to the centre than
//!   the surfel radius, the projected *line* becomes a clip line keeping the
//!   side with the centre (with T's centroid when the centre is on the line).
//! * of those, the two whose segments are nearest are kept (lines that
//!   coincide, as collinear edges of one crease give, count once). Two
//!   lines suffice at the corners of a cube (§10.2.4).

use std::collections::HashMap;

use glam::{Vec2, Vec3};

/// Orthonormal tangent vectors (t, b) of the unit normal `n`, with
/// `t × b = n` (Duff et al. 2017, branchless).
pub fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// One clip line in a disk's tangent frame: keeps `u·cos θ + v·sin θ ≤ offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipLine {
    /// Direction of the line's outward normal in the tangent frame (radians).
    pub angle: f32,
    /// Signed distance of the line from the disk centre (object units).
    pub offset: f32,
}

/// Up to two clip lines of a splat.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipLines(pub [Option<ClipLine>; 2]);

impl ClipLines {
    /// No clipping.
    pub const NONE: ClipLines = ClipLines([None, None]);

    /// `(θ0, c0, θ1, c1)` as the GPU reads them; a missing line has
    /// `c = f32::MAX`.
    pub fn packed(&self) -> [f32; 4] {
        let pack = |l: Option<ClipLine>| l.map_or((0.0, f32::MAX), |l| (l.angle, l.offset));
        let (a0, c0) = pack(self.0[0]);
        let (a1, c1) = pack(self.0[1]);
        [a0, c0, a1, c1]
    }

    /// Whether the tangent-plane point (u, v) is kept by every line.
    pub fn keeps(&self, u: f32, v: f32) -> bool {
        self.0
            .iter()
            .flatten()
            .all(|l| u * l.angle.cos() + v * l.angle.sin() <= l.offset)
    }
}

/// Dihedral angle (between the face normals) above which a mesh edge is a
/// crease and clips the surfels near it (module docs).
pub const CREASE_ANGLE_DEGREES: f32 = 30.0;

/// Edges steeper than this (sine of the angle to the tangent plane) are not
/// projected into a surfel's tangent plane (module docs).
const MAX_EDGE_SLOPE: f32 = 0.5;

/// The crease edges of a triangle mesh and, per triangle, those near it
/// (module docs), for clip lines of the surfels sampled from it.
#[derive(Clone, Debug, Default)]
pub struct Creases {
    /// End points of every crease edge.
    edges: Vec<[Vec3; 2]>,
    /// Crease edges near triangle t: `near[start[t]..start[t + 1]]`.
    start: Vec<u32>,
    near: Vec<u32>,
    /// Centroid of each triangle (which side to keep when a surfel centre
    /// lies on a line).
    centroids: Vec<Vec3>,
}

/// Position bits with −0 made +0, for welding.
fn weld_key(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

impl Creases {
    /// The creases of the triangles `triangles` (vertex indices into
    /// `positions`, assumed in range) with unit face normals `normals`.
    pub fn new(positions: &[Vec3], triangles: &[[usize; 3]], normals: &[Vec3]) -> Creases {
        let centroids = triangles
            .iter()
            .map(|t| (positions[t[0]] + positions[t[1]] + positions[t[2]]) / 3.0)
            .collect();
        // Welded vertex ids of the corners.
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        let mut welded: Vec<Vec3> = Vec::new();
        let corners: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| {
                t.map(|v| {
                    *ids.entry(weld_key(positions[v])).or_insert_with(|| {
                        welded.push(positions[v]);
                        welded.len() as u32 - 1
                    })
                })
            })
            .collect();
        // Edge → (first triangle, second triangle, count).
        let mut edge_map: HashMap<(u32, u32), (u32, u32, u32)> = HashMap::with_capacity(triangles.len() * 3 / 2);
        for (t, c) in corners.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                if a == b {
                    continue;
                }
                let entry = edge_map.entry((a.min(b), a.max(b))).or_insert((t as u32, u32::MAX, 0));
                if entry.2 == 1 {
                    entry.1 = t as u32;
                }
                entry.2 += 1;
            }
        }
        let cos_crease = f64::from(CREASE_ANGLE_DEGREES.to_radians().cos());
        let mut edges = Vec::new();
        let mut own: Vec<Vec<u32>> = vec![Vec::new(); triangles.len()];
        let mut sorted: Vec<_> = edge_map.into_iter().collect();
        sorted.sort_unstable_by_key(|&(key, _)| key);
        for ((a, b), (t0, t1, count)) in sorted {
            if count != 2 {
                continue;
            }
            let (t0, t1) = (t0 as usize, t1 as usize);
            if normals[t0].as_dvec3().dot(normals[t1].as_dvec3()) >= cos_crease {
                continue;
            }
            own[t0].push(edges.len() as u32);
            own[t1].push(edges.len() as u32);
            edges.push([welded[a as usize], welded[b as usize]]);
        }
        let mut start = vec![0u32; triangles.len() + 1];
        let mut near = Vec::new();
        if !edges.is_empty() {
            // Triangles around each welded vertex.
            let mut around: Vec<Vec<u32>> = vec![Vec::new(); welded.len()];
            for (t, c) in corners.iter().enumerate() {
                for &v in c {
                    around[v as usize].push(t as u32);
                }
            }
            let mut found: Vec<u32> = Vec::new();
            for (t, c) in corners.iter().enumerate() {
                found.clear();
                for &v in c {
                    for &u in &around[v as usize] {
                        found.extend_from_slice(&own[u as usize]);
                    }
                }
                found.sort_unstable();
                found.dedup();
                near.extend_from_slice(&found);
                start[t + 1] = near.len() as u32;
            }
        }
        Creases {
            edges,
            start,
            near,
            centroids,
        }
    }

    /// Number of crease edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether the mesh has no crease.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// The clip lines of a surfel sampled in triangle `triangle` (an index of
    /// the triangles given to [`Creases::new`]) with centre `centre`, unit
    /// normal `normal` and radius `radius` (module docs).
    pub fn lines(&self, triangle: usize, centre: Vec3, normal: Vec3, radius: f32) -> ClipLines {
        let (Some(&from), Some(&to)) = (self.start.get(triangle), self.start.get(triangle + 1)) else {
            return ClipLines::NONE;
        };
        if from == to || !(radius.is_finite() && radius > 0.0) {
            return ClipLines::NONE;
        }
        let (t, b) = tangent_frame(normal);
        let project = |p: Vec3| {
            let d = p - centre;
            Vec2::new(d.dot(t), d.dot(b))
        };
        // (segment distance, line) of every crease edge cutting the disk.
        let mut candidates: Vec<(f32, ClipLine)> = Vec::new();
        for &e in &self.near[from as usize..to as usize] {
            let [p, q] = self.edges[e as usize];
            let along = q - p;
            if along.dot(normal).abs() > MAX_EDGE_SLOPE * along.length() {
                continue;
            }
            let (p2, q2) = (project(p), project(q));
            let d = q2 - p2;
            let length = d.length();
            if !(length.is_finite() && length > 1e-6 * radius) {
                continue;
            }
            // Distance from the centre (origin) to the projected segment.
            let s = (-p2.dot(d) / (length * length)).clamp(0.0, 1.0);
            let distance = (p2 + s * d).length();
            if !(distance.is_finite() && distance < radius) {
                continue;
            }
            let mut m = Vec2::new(d.y, -d.x) / length;
            let mut offset = m.dot(p2);
            let reference = if offset.abs() > 1e-6 * radius {
                Vec2::ZERO
            } else {
                project(self.centroids[triangle])
            };
            if m.dot(reference) > offset {
                m = -m;
                offset = -offset;
            }
            candidates.push((
                distance,
                ClipLine {
                    angle: m.y.atan2(m.x),
                    offset,
                },
            ));
        }
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.angle.total_cmp(&y.1.angle)));
        let mut lines = ClipLines::NONE;
        let mut count = 0;
        for (_, line) in candidates {
            let same = |l: &ClipLine| {
                let da = (l.angle - line.angle).abs();
                da.min(std::f32::consts::TAU - da) < 1e-3 && (l.offset - line.offset).abs() < 1e-3 * radius
            };
            if lines.0.iter().flatten().any(same) {
                continue;
            }
            lines.0[count] = Some(line);
            count += 1;
            if count == 2 {
                break;
            }
        }
        lines
    }
}

#[cfg(test)]
mod tests {
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
}
