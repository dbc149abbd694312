//! Normal clustering for back-face culling of sequential point trees
//! (dissertation §10.1.10; `ALGORITHMS.md` §7).
//!
//! The text splits the sequential list into 128 lists of "equal quantised
//! normals" from a recursive subdivision of an octahedron and skips, per
//! frame, the lists whose normals face away from the camera (about 50 %
//! fewer points). Here:
//!
//! * **Cells.** The unit sphere is divided by central projection of the
//!   octahedron `|x| + |y| + |z| = 1` whose 8 faces are each subdivided twice
//!   1-to-4 (edge midpoints): 8 · 16 = [`CLUSTER_COUNT`] = 128 triangles.
//!   Central projection maps straight lines to great circles, so this is
//!   exactly the geodesic subdivision with normalised midpoints. A direction
//!   n lies in octant `o = [x<0] + 2[y<0] + 4[z<0]`; with `(X, Y) =
//!   (|x|, |y|)/(|x| + |y| + |z|)` the face is a triangle grid of side 4:
//!   `i = ⌊4X⌋, j = ⌊4Y⌋` and the fractional parts decide between the
//!   upward triangle `(i, j), (i+1, j), (i, j+1)` (10 per face) and the
//!   downward one `(i+1, j), (i, j+1), (i+1, j+1)` (6 per face)
//!   ([`cluster_of`]). Cells reach 12°–19° from their axis and differ in
//!   area by up to 3.5× (the cells at the octahedron's vertices are the
//!   largest on the sphere).
//! * **Axis and cone.** A cell's central axis is the circumcentre of its
//!   spherical triangle (the unit normal of the plane through its three
//!   projected corners), equally far from the three corners ([`cell_axis`]).
//!   A cluster stores the largest angle α between that axis and the normal
//!   of any of its nodes, as `cos α` rounded down and `sin α` rounded up
//!   (conservative), and the bounding sphere of its nodes' centres.
//! * **Lists.** The nodes are reordered so that every cluster is a
//!   contiguous range, each range sorted by decreasing `r_max` (ties keep
//!   the tree's order), so the per-object prefix search of §10.1.7 works per
//!   cluster ([`ClusteredTree::cluster_prefix_len`]); parent indices are
//!   renumbered. Clusters without nodes have `len` 0.
//! * **Back-face test** ([`NormalCluster::is_back_facing`], conservative).
//!   A splat is a disk through p with normal n, so every point q of it has
//!   `n·(e − q) = n·(e − p)`: it faces away from the eye e iff `n·(e − p) <
//!   0`. For all p in a sphere (c, R) and all unit n in the cone (a, α),
//!   `max n·(e − p) = max_n n·w + R` with `w = e − c`, and with θ the angle
//!   between a and w, `max_n n·w = |w|·cos(max(0, θ − α))`. The cluster is
//!   back-facing iff `θ > α` and `|w|·cos(θ − α) + R < 0`, where `|w|·cos(θ
//!   − α) = (a·w)·cos α + |a × w|·sin α`. Evaluated in f64 with a small
//!   margin; the rounded cos/sin only ever enlarge the cone in the culling
//!   region (cos θ < 0). Splats are two-sided, so this is only valid for
//!   the closed objects the text assumes: an inner node whose children's
//!   normals cancel (both sides of a thin sheet) carries one side's normal
//!   and is culled with that side.
//!
//! [`ClusteredTree::prefix_points`] counts the prefix points with and
//! without cluster culling for one eye, using each cluster's own bounding
//! sphere (tighter than the object's; any sphere containing the cluster's
//! node centres is valid).

use glam::{DVec3, Vec3};

use super::spt::{SequentialPointTree, SptNode, NO_PARENT};

/// Number of normal clusters: 8 octahedron faces, each subdivided twice
/// 1-to-4 (§10.1.10).
pub const CLUSTER_COUNT: usize = 128;

/// Triangle-grid side per octahedron face (two 1-to-4 subdivisions).
const SIDE: usize = 4;
/// Triangles per face.
const PER_FACE: usize = SIDE * SIDE;
/// First local index of upward triangles of row `i` (10 per face).
const UP_BASE: [usize; SIDE] = [0, 4, 7, 9];
/// First local index of downward triangles of row `i` (6 per face, after the 10).
const DOWN_BASE: [usize; SIDE - 1] = [10, 13, 15];

/// One normal cluster: a contiguous range of [`ClusteredTree::nodes`] with a
/// cone bounding its nodes' normals and a sphere bounding their centres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCluster {
    /// Index of the cluster's first node in [`ClusteredTree::nodes`].
    pub first: u32,
    /// Number of nodes (0 for an empty cell).
    pub len: u32,
    /// Unit central axis of the cell ([`cell_axis`]).
    pub axis: Vec3,
    /// `cos α`, α the largest angle between `axis` and a node normal of the
    /// cluster, rounded down (1 for an empty cluster).
    pub cos_angle: f32,
    /// `sin α` (α ∈ [0, π]), rounded up (0 for an empty cluster).
    pub sin_angle: f32,
    /// Centre of a sphere containing every node centre of the cluster.
    pub centre: Vec3,
    /// Radius of that sphere (object units; 0 for an empty cluster).
    pub radius: f32,
}

/// A sequential point tree split into [`CLUSTER_COUNT`] normal clusters
/// (§10.1.10; module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ClusteredTree {
    /// The tree's nodes, cluster by cluster, each cluster by decreasing
    /// `r_max`; parent indices refer to this list.
    pub nodes: Vec<SptNode>,
    /// [`CLUSTER_COUNT`] clusters, in cell order, covering `nodes` in order.
    pub clusters: Vec<NormalCluster>,
    /// For each node, its index in the tree's list.
    pub source: Vec<u32>,
    /// The tree's bounding sphere (every node's disk).
    pub bounds_centre: Vec3,
    pub bounds_radius: f32,
    /// The tree's ε.
    pub epsilon: f32,
}

/// The cell (0..[`CLUSTER_COUNT`]) of direction `n` (any length; module
/// docs). Zero or non-finite directions give cell 0.
pub fn cluster_of(n: Vec3) -> usize {
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    if !(l1.is_finite() && l1 > 0.0) {
        return 0;
    }
    let octant = usize::from(n.x.is_sign_negative())
        | usize::from(n.y.is_sign_negative()) << 1
        | usize::from(n.z.is_sign_negative()) << 2;
    let (x, y) = (SIDE as f32 * n.x.abs() / l1, SIDE as f32 * n.y.abs() / l1);
    let i = (x as usize).min(SIDE - 1);
    let j = (y as usize).min(SIDE - 1 - i);
    let (fx, fy) = (x - i as f32, y - j as f32);
    let local = if fx + fy > 1.0 && i + j < SIDE - 1 {
        DOWN_BASE[i] + j
    } else {
        UP_BASE[i] + j
    };
    octant * PER_FACE + local
}

/// The three corners of cell `cell` on the octahedron `|x|+|y|+|z| = 1`.
fn cell_corners(cell: usize) -> [DVec3; 3] {
    let (octant, local) = (cell / PER_FACE % 8, cell % PER_FACE);
    let sign = DVec3::new(
        if octant & 1 != 0 { -1.0 } else { 1.0 },
        if octant & 2 != 0 { -1.0 } else { 1.0 },
        if octant & 4 != 0 { -1.0 } else { 1.0 },
    );
    let point = |i: usize, j: usize| {
        let (x, y) = (i as f64 / SIDE as f64, j as f64 / SIDE as f64);
        DVec3::new(x, y, 1.0 - x - y) * sign
    };
    let row = |base: &[usize]| base.iter().rposition(|&b| b <= local).unwrap_or(0);
    if local < DOWN_BASE[0] {
        let i = row(&UP_BASE);
        let j = local - UP_BASE[i];
        [point(i, j), point(i + 1, j), point(i, j + 1)]
    } else {
        let i = row(&DOWN_BASE);
        let j = local - DOWN_BASE[i];
        [point(i + 1, j), point(i, j + 1), point(i + 1, j + 1)]
    }
}

/// The unit central axis of cell `cell` (taken modulo [`CLUSTER_COUNT`]):
/// the circumcentre of its spherical triangle (module docs).
pub fn cell_axis(cell: usize) -> Vec3 {
    let [a, b, c] = cell_corners(cell).map(DVec3::normalize);
    let mut axis = (b - a).cross(c - a).normalize();
    if axis.dot(a + b + c) < 0.0 {
        axis = -axis;
    }
    axis.as_vec3()
}

/// The largest f32 ≤ `x` (finite x).
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) <= x {
        y
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() - 1)
    } else if y == 0.0 {
        -f32::from_bits(1)
    } else {
        f32::from_bits(y.to_bits() + 1)
    }
}

/// The smallest f32 ≥ `x` (finite x).
fn round_up(x: f64) -> f32 {
    -round_down(-x)
}

/// Splits `tree` into [`CLUSTER_COUNT`] normal clusters (§10.1.10; module
/// docs). The tree's nodes should be sorted by decreasing `r_max`, as
/// [`super::spt::build_spt`] and [`super::spt_file::read_spt`] give them;
/// each cluster is sorted by decreasing `r_max` in any case.
pub fn cluster_normals(tree: &SequentialPointTree) -> ClusteredTree {
    let cells: Vec<usize> = tree.nodes.iter().map(|n| cluster_of(n.normal)).collect();
    let mut order: Vec<usize> = (0..tree.nodes.len()).collect();
    order.sort_by(|&a, &b| {
        cells[a]
            .cmp(&cells[b])
            .then(tree.nodes[b].r_max.total_cmp(&tree.nodes[a].r_max))
    });
    let mut new_index = vec![0u32; tree.nodes.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    let nodes: Vec<SptNode> = order
        .iter()
        .map(|&old| {
            let mut n = tree.nodes[old];
            if let Some(&p) = new_index.get(n.parent as usize).filter(|_| n.parent != NO_PARENT) {
                n.parent = p;
            }
            n
        })
        .collect();

    let mut counts = [0usize; CLUSTER_COUNT];
    for &c in &cells {
        counts[c] += 1;
    }
    let mut clusters = Vec::with_capacity(CLUSTER_COUNT);
    let mut first = 0usize;
    for (cell, &len) in counts.iter().enumerate() {
        let members = &nodes[first..first + len];
        let axis = cell_axis(cell);
        let a = axis.as_dvec3();
        // Largest angle to the axis (π for a normal without a direction).
        let mut angle = 0.0f64;
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for n in members {
            let v = n.normal.as_dvec3();
            let theta = a.cross(v).length().atan2(a.dot(v));
            angle = if theta.is_finite() && v.length() > 0.0 {
                angle.max(theta)
            } else {
                std::f64::consts::PI
            };
            lo = lo.min(n.position.as_dvec3());
            hi = hi.max(n.position.as_dvec3());
        }
        let (centre, radius) = if len == 0 {
            (tree.bounds_centre, 0.0)
        } else {
            let centre = ((lo + hi) * 0.5).as_vec3();
            let r = members
                .iter()
                .map(|n| (n.position.as_dvec3() - centre.as_dvec3()).length())
                .fold(0.0f64, f64::max);
            (centre, round_up(r * (1.0 + 1e-6)))
        };
        clusters.push(NormalCluster {
            first: first as u32,
            len: len as u32,
            axis,
            cos_angle: round_down(angle.cos()).max(-1.0),
            sin_angle: round_up(angle.sin().max(0.0)).min(1.0),
            centre,
            radius,
        });
        first += len;
    }
    ClusteredTree {
        nodes,
        clusters,
        source: order.iter().map(|&i| i as u32).collect(),
        bounds_centre: tree.bounds_centre,
        bounds_radius: tree.bounds_radius,
        epsilon: tree.epsilon,
    }
}

impl NormalCluster {
    /// Whether every node of the cluster faces away from `eye_object` (in
    /// the tree's coordinates) wherever in the sphere (`bounds_centre`,
    /// `bounds_radius`) its centre is, for every normal in the cluster's cone
    /// (conservative; module docs). An empty cluster is back-facing;
    /// non-finite input never is.
    pub fn is_back_facing(&self, eye_object: Vec3, bounds_centre: Vec3, bounds_radius: f32) -> bool {
        if self.len == 0 {
            return true;
        }
        let w = eye_object.as_dvec3() - bounds_centre.as_dvec3();
        let a = self.axis.as_dvec3();
        let (cos_a, sin_a) = (f64::from(self.cos_angle), f64::from(self.sin_angle));
        let along = a.dot(w);
        let across = a.cross(w).length();
        let length = w.length();
        let r = f64::from(bounds_radius);
        if !(length.is_finite() && r.is_finite() && along.is_finite()) {
            return false;
        }
        // θ > α (cos θ < cos α), else some normal of the cone points at w.
        if along >= cos_a * length {
            return false;
        }
        let nearest = along * cos_a + across * sin_a;
        nearest + r < -1e-6 * (length + r)
    }
}

impl ClusteredTree {
    /// Number of leading nodes of cluster `cluster` with `r_max ≥ r_lo`
    /// (§10.1.7 per cluster); a NaN `r_lo` gives the whole cluster, an
    /// out-of-range cluster 0.
    pub fn cluster_prefix_len(&self, cluster: usize, r_lo: f32) -> usize {
        let Some(c) = self.clusters.get(cluster) else {
            return 0;
        };
        let (first, len) = (c.first as usize, c.len as usize);
        let Some(nodes) = self.nodes.get(first..first + len) else {
            return 0;
        };
        if r_lo.is_nan() {
            return len;
        }
        nodes.partition_point(|n| n.r_max >= r_lo)
    }

    /// The prefix point counts for an eye at `eye_object` (tree
    /// coordinates) and the lower bound `r_lo` of the eye distance: `(all,
    /// front)`, `all` summed over every cluster (the tree's prefix length)
    /// and `front` over the clusters that are not back-facing with their own
    /// bounding spheres (module docs).
    #[cfg(test)]
    pub fn prefix_points(&self, eye_object: Vec3, r_lo: f32) -> (usize, usize) {
        let (mut all, mut front) = (0, 0);
        for (k, c) in self.clusters.iter().enumerate() {
            let len = self.cluster_prefix_len(k, r_lo);
            all += len;
            if !c.is_back_facing(eye_object, c.centre, c.radius) {
                front += len;
            }
        }
        (all, front)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::clip::ClipLines;
    use crate::points::build::spt::{build_spt, SptOptions};
    use crate::points::Surfel;
    use crate::random::SplitMix64;

    fn unit(rng: &mut SplitMix64) -> Vec3 {
        loop {
            let v = Vec3::new(
                rng.next_f64() as f32 * 2.0 - 1.0,
                rng.next_f64() as f32 * 2.0 - 1.0,
                rng.next_f64() as f32 * 2.0 - 1.0,
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }

    fn surfel(position: Vec3, normal: Vec3, radius: f32) -> Surfel {
        Surfel {
            position,
            normal,
            radius,
            color: [100; 3],
            clip: ClipLines::NONE,
        }
    }

    /// A sphere with outward normals, a blob with random normals, a bumpy plane.
    fn trees() -> Vec<(&'static str, SequentialPointTree)> {
        let mut rng = SplitMix64(5);
        let sphere: Vec<Surfel> = (0..1500)
            .map(|_| {
                let n = unit(&mut rng);
                surfel(n * 2.0 + Vec3::new(1.0, 0.5, -3.0), n, 0.15)
            })
            .collect();
        let blob: Vec<Surfel> = (0..1000)
            .map(|_| surfel(unit(&mut rng) * rng.next_f64() as f32, unit(&mut rng), 0.05))
            .collect();
        let plane: Vec<Surfel> = (0..1000)
            .map(|_| {
                let (x, y) = (rng.next_f64() as f32 * 4.0, rng.next_f64() as f32 * 4.0);
                let n = Vec3::new(0.3 * x.cos(), 0.3 * y.sin(), 1.0).normalize();
                surfel(Vec3::new(x, y, 0.3 * x.sin() - 0.3 * y.cos()), n, 0.1)
            })
            .collect();
        [("sphere", sphere), ("blob", blob), ("plane", plane)]
            .into_iter()
            .map(|(name, s)| (name, build_spt(&s, &SptOptions::default(), &mut |_| {}).unwrap()))
            .collect()
    }

    fn angle(a: Vec3, b: Vec3) -> f32 {
        a.cross(b).length().atan2(a.dot(b))
    }

    #[test]
    fn cells_partition_the_sphere() {
        for cell in 0..CLUSTER_COUNT {
            let axis = cell_axis(cell);
            assert!((axis.length() - 1.0).abs() < 1e-6);
            assert_eq!(cluster_of(axis), cell, "the axis lies in its cell");
            // The corners are equally far from the axis.
            let corners = cell_corners(cell).map(|c| c.normalize().as_vec3());
            let a = corners.map(|c| angle(axis, c));
            assert!((a[0] - a[1]).abs() < 1e-5 && (a[0] - a[2]).abs() < 1e-5, "{a:?}");
        }
        let mut rng = SplitMix64(1);
        let mut counts = [0usize; CLUSTER_COUNT];
        let mut widest = [0.0f32; CLUSTER_COUNT];
        let samples = 200_000;
        for _ in 0..samples {
            let n = unit(&mut rng);
            let c = cluster_of(n);
            counts[c] += 1;
            widest[c] = widest[c].max(angle(n, cell_axis(c)));
        }
        let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
        let (narrow, wide) = widest
            .iter()
            .fold((f32::MAX, 0.0f32), |(a, b), &w| (a.min(w), b.max(w)));
        println!(
            "cells: {lo}..{hi} of {samples} samples (mean {}); axis to farthest sample {:.1}°..{:.1}°",
            samples / CLUSTER_COUNT,
            narrow.to_degrees(),
            wide.to_degrees()
        );
        assert!(*lo > 0 && wide.to_degrees() < 20.0);
        assert_eq!(cluster_of(Vec3::ZERO), 0);
        assert_eq!(cluster_of(Vec3::NAN), 0);
        // The octahedron's vertices and edges fall into some cell.
        for n in [Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(1.0, -1.0, 0.0)] {
            assert!(angle(n, cell_axis(cluster_of(n))) < 20f32.to_radians());
        }
    }

    #[test]
    fn clustering_is_a_permutation_sorted_per_cluster() {
        for (name, tree) in trees() {
            let c = cluster_normals(&tree);
            let n = tree.nodes.len();
            assert_eq!((c.nodes.len(), c.source.len(), c.clusters.len()), (n, n, CLUSTER_COUNT));
            let mut seen = vec![false; n];
            let mut new_index = vec![0u32; n];
            for (i, &s) in c.source.iter().enumerate() {
                assert!(!seen[s as usize], "{name}: node {s} twice");
                seen[s as usize] = true;
                new_index[s as usize] = i as u32;
            }
            for (i, node) in c.nodes.iter().enumerate() {
                let old = tree.nodes[c.source[i] as usize];
                let parent = if old.parent == NO_PARENT {
                    NO_PARENT
                } else {
                    new_index[old.parent as usize]
                };
                assert_eq!(*node, SptNode { parent, ..old });
            }
            let mut next = 0u32;
            for (k, cluster) in c.clusters.iter().enumerate() {
                assert_eq!(cluster.first, next, "{name}: clusters are contiguous");
                next += cluster.len;
                let members = &c.nodes[cluster.first as usize..next as usize];
                assert!(
                    members.windows(2).all(|w| w[0].r_max >= w[1].r_max),
                    "{name}: cluster {k}"
                );
                let cone = cluster.cos_angle.acos();
                for m in members {
                    assert_eq!(cluster_of(m.normal), k);
                    assert!(angle(cluster.axis, m.normal) <= cone + 1e-6);
                    assert!(m.position.distance(cluster.centre) <= cluster.radius);
                }
            }
            assert_eq!(next as usize, n);
            for r_lo in [0.0, 1.0, 10.0, 100.0, 1e4, f32::NAN] {
                let sum: usize = (0..CLUSTER_COUNT).map(|k| c.cluster_prefix_len(k, r_lo)).sum();
                assert_eq!(sum, tree.prefix_len(r_lo), "{name}: r_lo {r_lo}");
                assert_eq!(c.prefix_points(Vec3::ZERO, r_lo).0, sum);
            }
        }
    }

    /// Whether a node faces the eye (f64, the node's exact values).
    fn faces(node: &SptNode, eye: Vec3) -> bool {
        node.normal.as_dvec3().dot(eye.as_dvec3() - node.position.as_dvec3()) >= 0.0
    }

    #[test]
    fn back_facing_clusters_have_no_node_facing_the_eye() {
        let mut rng = SplitMix64(9);
        for (name, tree) in trees() {
            let c = cluster_normals(&tree);
            let (mut culled, mut tested) = (0, 0);
            for _ in 0..300 {
                let distance = tree.bounds_radius * 6.0 * rng.next_f64() as f32;
                let eye = tree.bounds_centre + unit(&mut rng) * distance;
                for cluster in &c.clusters {
                    let members = &c.nodes[cluster.first as usize..(cluster.first + cluster.len) as usize];
                    for (centre, radius) in [
                        (cluster.centre, cluster.radius),
                        (tree.bounds_centre, tree.bounds_radius),
                    ] {
                        tested += 1;
                        if cluster.is_back_facing(eye, centre, radius) {
                            culled += 1;
                            for m in members {
                                assert!(!faces(m, eye), "{name}: culled a node facing {eye}: {m:?}");
                            }
                        }
                    }
                }
            }
            println!("{name}: {culled} of {tested} cluster tests culled");
            assert!(culled > tested / 20, "{name}: the test should cull something");
        }
    }

    #[test]
    fn back_facing_test_against_sampled_cones_and_spheres() {
        // Random cones and spheres: whatever is culled has no facing
        // (normal, point) pair on the cone's rim and the sphere's surface,
        // and what is clearly back-facing is culled.
        let mut rng = SplitMix64(3);
        let (mut culled, mut clear) = (0, 0);
        for _ in 0..3000 {
            let axis = unit(&mut rng);
            let alpha = std::f32::consts::PI * (rng.next_f64() as f32).powi(2);
            let cluster = NormalCluster {
                first: 0,
                len: 1,
                axis,
                cos_angle: alpha.cos(),
                sin_angle: alpha.sin(),
                centre: Vec3::ZERO,
                radius: 0.0,
            };
            let centre = unit(&mut rng) * 2.0 * rng.next_f64() as f32;
            let radius = 2.0 * rng.next_f64() as f32;
            let eye = unit(&mut rng) * 8.0 * rng.next_f64() as f32;
            let w = (eye - centre).as_dvec3();
            let theta = f64::from(angle(axis, (eye - centre).normalize_or(Vec3::X)));
            let exact = w.length() * (theta - f64::from(alpha)).max(0.0).cos() + f64::from(radius);
            let back = cluster.is_back_facing(eye, centre, radius);
            if exact < -1e-3 {
                clear += 1;
                assert!(back, "missed: exact {exact}");
            }
            if !back {
                continue;
            }
            culled += 1;
            assert!(exact < 0.0, "culled with exact {exact}");
            let (t, b) = axis.any_orthonormal_pair();
            for k in 0..64 {
                let phi = std::f32::consts::TAU * k as f32 / 64.0;
                let n = alpha.cos() * axis + alpha.sin() * (phi.cos() * t + phi.sin() * b);
                for _ in 0..4 {
                    let p = centre + unit(&mut rng) * radius;
                    assert!(n.dot(eye - p) < 0.0);
                }
            }
        }
        println!("{culled} of 3000 random cones culled ({clear} clearly back-facing)");
        assert!(culled > 300 && culled >= clear);
        let empty = NormalCluster {
            len: 0,
            ..cluster_normals(&trees()[0].1).clusters[0]
        };
        assert!(empty.is_back_facing(Vec3::ZERO, Vec3::ZERO, 1.0));
        let some = NormalCluster { len: 1, ..empty };
        assert!(!some.is_back_facing(Vec3::NAN, Vec3::ZERO, 1.0));
        assert!(!some.is_back_facing(Vec3::ZERO, Vec3::ZERO, f32::INFINITY));
    }

    #[test]
    fn bunny_back_face_culling_saves_points() {
        use crate::points::build::input::load_obj;
        use crate::points::build::sampling::{sample_mesh, SamplingMethod, SamplingOptions};
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/models/stanford-bunny.obj");
        let mesh = load_obj(&path).unwrap();
        let options = SamplingOptions {
            count: 20_000,
            method: SamplingMethod::Stratified,
            seed: 1,
        };
        let surfels = sample_mesh(&mesh, &options).unwrap();
        let tree = build_spt(&surfels, &SptOptions::default(), &mut |_| {}).unwrap();
        let c = cluster_normals(&tree);
        let (centre, radius) = (tree.bounds_centre, tree.bounds_radius);
        let (mut all, mut front, mut front_object, mut facing) = (0, 0, 0, 0);
        for dir in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
            let eye = centre + dir * 3.0 * radius;
            let r_lo = tree.min_eye_distance(eye);
            let (a, f) = c.prefix_points(eye, r_lo);
            assert_eq!(a, tree.prefix_len(r_lo));
            // The same with the object's bounding sphere for every cluster.
            let fo: usize = (0..CLUSTER_COUNT)
                .filter(|&k| !c.clusters[k].is_back_facing(eye, centre, radius))
                .map(|k| c.cluster_prefix_len(k, r_lo))
                .sum();
            // The ideal: the prefix nodes that actually face the eye.
            let ff = tree.nodes[..a].iter().filter(|n| faces(n, eye)).count();
            println!(
                "bunny from {dir}: prefix {a}, front clusters {f} ({:.1} % fewer; object sphere {:.1} %; \
                 nodes facing away {:.1} %)",
                100.0 * (1.0 - f as f64 / a as f64),
                100.0 * (1.0 - fo as f64 / a as f64),
                100.0 * (1.0 - ff as f64 / a as f64)
            );
            all += a;
            front += f;
            front_object += fo;
            facing += ff;
        }
        let saved = 1.0 - front as f64 / all as f64;
        println!(
            "bunny, six views at 3 bounding radii: {:.1} % fewer points with cluster spheres, {:.1} % with the \
             object sphere, {:.1} % of the nodes face away ({} nodes)",
            100.0 * saved,
            100.0 * (1.0 - front_object as f64 / all as f64),
            100.0 * (1.0 - facing as f64 / all as f64),
            tree.nodes.len()
        );
        assert!(saved > 0.2, "{saved}");
    }
}
