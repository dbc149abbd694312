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

/// The crease edges of a triangle mesh and, per welded vertex, those of the
/// triangles around it (module docs), for clip lines of the surfels sampled
/// from it.
///
/// Storage and time are linear in the mesh (plus a sort per vertex): a
/// triangle's nearby creases are the union of its three corners' lists,
/// gathered per query rather than stored per triangle, which grew with the
/// square of a vertex's triangle count (a fanned cap of 50,000 triangles
/// took 8.5 GB). A long list (a fan's hub) is kept in spatial order with an
/// implicit bounding-box tree (`VertexTree`), so a query visits only the
/// creases whose projection can come within the surfel's radius.
#[derive(Clone, Debug, Default)]
pub struct Creases {
    /// End points of every crease edge.
    edges: Vec<[Vec3; 2]>,
    /// Welded vertex ids of each triangle's corners.
    corners: Vec<[u32; 3]>,
    /// Crease edges of the triangles around welded vertex v (each once):
    /// `around[start[v]..start[v + 1]]`, in the order of its tree.
    start: Vec<u32>,
    around: Vec<u32>,
    /// Bounding-box trees of the vertices with more than [`LEAF_EDGES`]
    /// edges, by vertex id.
    trees: HashMap<u32, VertexTree>,
    /// Centroid of each triangle (which side to keep when a surfel centre
    /// lies on a line).
    centroids: Vec<Vec3>,
}

/// Edges per leaf of a [`VertexTree`]; shorter lists have no tree.
const LEAF_EDGES: usize = 16;

/// Implicit binary tree over one vertex's edge list: node 0 spans the whole
/// list, node i over `[lo, hi)` has children 2i+1 over `[lo, mid)` and 2i+2
/// over `[mid, hi)` with `mid = lo + (hi - lo) / 2`, leaves at most
/// [`LEAF_EDGES`] long; `boxes[i]` bounds node i's edges (min, max).
#[derive(Clone, Debug, Default)]
struct VertexTree {
    boxes: Vec<[Vec3; 2]>,
}

/// Position bits with −0 made +0, for welding.
fn weld_key(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// The bounding box of edges `ids`.
fn bounds(edges: &[[Vec3; 2]], ids: &[u32]) -> [Vec3; 2] {
    ids.iter().fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &e| {
        let [p, q] = edges[e as usize];
        [lo.min(p).min(q), hi.max(p).max(q)]
    })
}

impl VertexTree {
    /// Orders `ids` spatially (median splits along the longest axis of the
    /// edge midpoints) and builds the tree of that order.
    fn new(edges: &[[Vec3; 2]], ids: &mut [u32]) -> VertexTree {
        let mut tree = VertexTree::default();
        tree.build(edges, ids, 0);
        tree
    }

    fn build(&mut self, edges: &[[Vec3; 2]], ids: &mut [u32], node: usize) {
        if self.boxes.len() <= node {
            self.boxes.resize(node + 1, [Vec3::ZERO; 2]);
        }
        self.boxes[node] = bounds(edges, ids);
        if ids.len() <= LEAF_EDGES {
            return;
        }
        let mid_point = |e: &u32| {
            let [p, q] = edges[*e as usize];
            p + q
        };
        let (lo, hi) = ids.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), e| {
            (lo.min(mid_point(e)), hi.max(mid_point(e)))
        });
        let size = hi - lo;
        let axis = if size.x >= size.y && size.x >= size.z {
            0
        } else if size.y >= size.z {
            1
        } else {
            2
        };
        let mid = ids.len() / 2;
        ids.select_nth_unstable_by(mid, |a, b| mid_point(a)[axis].total_cmp(&mid_point(b)[axis]));
        let (left, right) = ids.split_at_mut(mid);
        self.build(edges, left, 2 * node + 1);
        self.build(edges, right, 2 * node + 2);
    }

    /// Appends to `found` the edges of `ids` (the list this tree was built
    /// on) in the leaves whose boxes, projected by `project`, may come
    /// within `radius` of the origin. Conservative: an edge whose projected
    /// segment comes closer than `radius` is never left out.
    fn visit(&self, ids: &[u32], project: &dyn Fn(Vec3) -> Vec2, radius: f32, found: &mut Vec<u32>) {
        let mut stack = vec![(0usize, 0usize, ids.len())];
        while let Some((node, lo, hi)) = stack.pop() {
            let [a, b] = self.boxes[node];
            let (mut min, mut max) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
            for k in 0..8 {
                let corner = Vec3::new(
                    if k & 1 == 0 { a.x } else { b.x },
                    if k & 2 == 0 { a.y } else { b.y },
                    if k & 4 == 0 { a.z } else { b.z },
                );
                let p = project(corner);
                (min, max) = (min.min(p), max.max(p));
            }
            // Distance from the origin to the projected box, with a margin
            // for rounding in the exact test.
            let gap = Vec2::ZERO.max(min).max(-max);
            let scale = min.abs().max(max.abs()).max_element();
            if gap.length() > radius * (1.0 + 1e-3) + 1e-5 * scale {
                continue;
            }
            if hi - lo <= LEAF_EDGES {
                found.extend_from_slice(&ids[lo..hi]);
            } else {
                let mid = lo + (hi - lo) / 2;
                stack.push((2 * node + 2, mid, hi));
                stack.push((2 * node + 1, lo, mid));
            }
        }
    }
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
        drop(ids);
        let (edges, own) = crease_edges(&corners, &welded, normals);
        let mut creases = Creases {
            edges,
            corners,
            start: Vec::new(),
            around: Vec::new(),
            trees: HashMap::new(),
            centroids,
        };
        if !creases.edges.is_empty() {
            creases.gather_around(welded.len(), &own);
        }
        creases
    }

    /// Fills `start`/`around` (the crease edges of the triangles around each
    /// welded vertex, `own[t]` those of triangle t) and the trees of the
    /// long lists.
    fn gather_around(&mut self, vertices: usize, own: &[Vec<u32>]) {
        let mut count = vec![0u32; vertices + 1];
        for (t, c) in self.corners.iter().enumerate() {
            for &v in c {
                count[v as usize + 1] += own[t].len() as u32;
            }
        }
        for v in 0..vertices {
            count[v + 1] += count[v];
        }
        let mut fill = count.clone();
        let mut around = vec![0u32; count[vertices] as usize];
        for (t, c) in self.corners.iter().enumerate() {
            for &v in c {
                for &e in &own[t] {
                    around[fill[v as usize] as usize] = e;
                    fill[v as usize] += 1;
                }
            }
        }
        // Sort and deduplicate each list in place, compacting.
        let mut start = vec![0u32; vertices + 1];
        let mut kept = 0usize;
        for v in 0..vertices {
            let (from, to) = (count[v] as usize, count[v + 1] as usize);
            around[from..to].sort_unstable();
            let mut last = None;
            for k in from..to {
                if last != Some(around[k]) {
                    last = Some(around[k]);
                    around[kept] = around[k];
                    kept += 1;
                }
            }
            start[v + 1] = kept as u32;
        }
        around.truncate(kept);
        around.shrink_to_fit();
        for v in 0..vertices {
            let (from, to) = (start[v] as usize, start[v + 1] as usize);
            if to - from > LEAF_EDGES {
                let tree = VertexTree::new(&self.edges, &mut around[from..to]);
                self.trees.insert(v as u32, tree);
            }
        }
        self.start = start;
        self.around = around;
    }

    /// Number of crease edges.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether the mesh has no crease.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// The clip lines of a surfel sampled in triangle `triangle` (an index of
    /// the triangles given to [`Creases::new`]) with centre `centre`, unit
    /// normal `normal` and radius `radius` (module docs).
    pub fn lines(&self, triangle: usize, centre: Vec3, normal: Vec3, radius: f32) -> ClipLines {
        let Some(corners) = self.corners.get(triangle) else {
            return ClipLines::NONE;
        };
        if self.edges.is_empty() || !(radius.is_finite() && radius > 0.0) {
            return ClipLines::NONE;
        }
        let (t, b) = tangent_frame(normal);
        let project = |p: Vec3| {
            let d = p - centre;
            Vec2::new(d.dot(t), d.dot(b))
        };
        // The crease edges around the corners that may cut the disk.
        let mut near = Vec::new();
        for &v in corners {
            let ids = &self.around[self.start[v as usize] as usize..self.start[v as usize + 1] as usize];
            match self.trees.get(&v) {
                Some(tree) => tree.visit(ids, &project, radius, &mut near),
                None => near.extend_from_slice(ids),
            }
        }
        near.sort_unstable();
        near.dedup();
        self.lines_of(&near, triangle, centre, normal, radius)
    }

    /// The clip lines of a surfel (as [`Creases::lines`]) from the crease
    /// edges `near` (sorted ids), nearest first.
    fn lines_of(&self, near: &[u32], triangle: usize, centre: Vec3, normal: Vec3, radius: f32) -> ClipLines {
        let (t, b) = tangent_frame(normal);
        let project = |p: Vec3| {
            let d = p - centre;
            Vec2::new(d.dot(t), d.dot(b))
        };
        // (segment distance, line) of every crease edge cutting the disk.
        let mut candidates: Vec<(f32, ClipLine)> = Vec::new();
        for &e in near {
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

/// The crease edges of triangles with welded corners `corners` and unit
/// face normals `normals` (edges of exactly two triangles whose normals
/// differ by more than [`CREASE_ANGLE_DEGREES`]), as end points, and per
/// triangle the ids of its own crease edges. One pass over an edge map.
fn crease_edges(corners: &[[u32; 3]], welded: &[Vec3], normals: &[Vec3]) -> (Vec<[Vec3; 2]>, Vec<Vec<u32>>) {
    // Edge → (first triangle, second triangle, count).
    let mut edge_map: HashMap<(u32, u32), (u32, u32, u32)> = HashMap::with_capacity(corners.len() * 3 / 2);
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
    let mut own: Vec<Vec<u32>> = vec![Vec::new(); corners.len()];
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
    (edges, own)
}

#[cfg(test)]
mod tests;
