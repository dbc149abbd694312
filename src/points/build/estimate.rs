//! Attribute estimation for point clouds that lack them (dissertation §10.1;
//! `ALGORITHMS.md` §7). The sequential point tree is built from oriented disks
//! (surfels), so a bare scan — positions only — first needs a normal and a disk
//! radius per point. Both come from the k nearest neighbours:
//!
//! * **Normals** ([`estimate_normals`]): principal component analysis of the
//!   k-neighbourhood (the point itself included). The normal is the
//!   eigenvector of the smallest eigenvalue of the neighbourhood covariance,
//!   found with cyclic Jacobi rotations (robust for symmetric 3×3 matrices,
//!   including repeated eigenvalues). PCA gives a line, not a direction; the
//!   signs are made consistent as in Hoppe et al. 1992: a minimum spanning
//!   tree of the symmetrised k-nearest-neighbour graph with edge cost
//!   `1 − |nᵢ·nⱼ|` is grown from a seed, flipping each new normal to agree with
//!   its tree parent. The cost makes propagation go through nearly parallel
//!   normals first, so it does not jump across sharp folds. Each connected
//!   component is seeded at its point farthest from the bounding-box centre,
//!   whose normal is turned to point away from that centre (outwards for
//!   closed objects); when that is ambiguous (the seed normal is nearly
//!   perpendicular to the outward direction, as for a flat patch) the
//!   normal's largest component is made positive instead.
//! * **Radii** ([`estimate_radii`]): from `d_k`, the distance to the k-th
//!   nearest other point. On a surface with local sample density ρ the k
//!   nearest points lie in a disk of area `k/ρ`, so `d_k/√k` estimates
//!   `sqrt(1/(πρ))`, the radius at which disks exactly add up to the surface
//!   area. The radius is that times [`RADIUS_OVERLAP`]:
//!   `r = 1.75 · d_k / √k`. On a square grid with spacing h and k = 6
//!   (`d_6 = √2·h`) this is `1.01·h`, well above the `h/√2` that covers the
//!   grid. Irregular clouds need more: on stratified and blue-noise samples of
//!   a square (module [`super::sampling`], 10 seeds, k = 6 and 8) the largest
//!   hole needed 1.55–1.63 `· d_k/√k`; since the radius follows the local
//!   density, this is less than the uniform radius of mesh sampling needs.
//!
//! Neighbours come from a small kd-tree (`KdTree`, median splits on the
//! widest axis, buckets of 8): exact k-nearest and fixed-radius queries in
//! `O(log n)` expected time, independent of how unevenly scans are sampled
//! (which rules out a uniform grid), and robust to the many equal
//! coordinates of axis-aligned planes. It is hand-written rather than a
//! crate (such as `kiddo`) because the two queries needed fit in two hundred
//! lines and no dependency is added to the build.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::Vec3;

use super::clip::ClipLines;
use crate::error::{Error, Result};
use crate::points::{PointCloud, Surfel};

/// Neighbourhood size for normals in [`complete_cloud`] (the point included).
pub const DEFAULT_NORMAL_K: usize = 8;
/// Neighbour rank for radii in [`complete_cloud`] (the point excluded).
pub const DEFAULT_RADIUS_K: usize = 6;
/// Disk overlap factor: radius = `RADIUS_OVERLAP · d_k / √k` (module docs).
pub const RADIUS_OVERLAP: f32 = 1.75;
/// Colour of points without one (mid grey, sRGB).
pub const DEFAULT_COLOR: [u8; 3] = [128, 128, 128];

/// Unit normals from PCA of the `k` nearest neighbours (the point itself
/// included, so `3 ≤ k ≤ positions.len()`), oriented consistently over the
/// neighbour graph (minimum spanning tree, outward seed; see the module docs,
/// §10.1).
///
/// Errors on empty or non-finite input and on `k` out of range.
#[cfg(test)]
pub fn estimate_normals(positions: &[Vec3], k: usize) -> Result<Vec<Vec3>> {
    validate_positions(positions)?;
    check_normal_k(positions.len(), k)?;
    let tree = KdTree::new(positions);
    Ok(normals_with_tree(&tree, positions, k))
}

/// Disk radii `RADIUS_OVERLAP · d_k / √k`, `d_k` the distance to the k-th
/// nearest other point (`1 ≤ k < positions.len()`; module docs, §10.1). Points
/// whose k nearest neighbours all coincide with them get the median of the
/// other radii.
///
/// Errors on empty or non-finite input, on `k` out of range and when all
/// points coincide.
#[cfg(test)]
pub fn estimate_radii(positions: &[Vec3], k: usize) -> Result<Vec<f32>> {
    validate_positions(positions)?;
    check_radius_k(positions.len(), k)?;
    let tree = KdTree::new(positions);
    radii_with_tree(&tree, positions, k)
}

/// Surfels for a point cloud, filling what the file lacked (§10.1): normals by
/// `estimate_normals` with k = `DEFAULT_NORMAL_K`, radii by
/// `estimate_radii` with k = `DEFAULT_RADIUS_K`, colour
/// `DEFAULT_COLOR`. Both k are lowered for clouds too small for them.
///
/// Given normals are normalised; zero or non-finite ones are replaced by a
/// PCA normal turned towards the given normals of its neighbours. Given radii
/// that are not finite and positive are replaced by estimates.
///
/// Given clip lines (§10.2.4) are kept: they are relative to the tangent
/// frame of the point's normal, so a point whose normal is estimated rather
/// than given gets none (its lines' frame is unknown).
///
/// Errors on empty or non-finite positions, attribute arrays whose length
/// differs from the positions', and clouds too small to estimate what is
/// missing (fewer than 3 points for normals, 2 for radii).
pub fn complete_cloud(cloud: &PointCloud) -> Result<Vec<Surfel>> {
    let positions = &cloud.positions;
    validate_positions(positions)?;
    let n = positions.len();
    let check_len = |what: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(Error::invalid("point cloud", format!("{len} {what} for {n} points")))
        }
    };
    if let Some(normals) = &cloud.normals {
        check_len("normals", normals.len())?;
    }
    if let Some(colors) = &cloud.colors {
        check_len("colours", colors.len())?;
    }
    if let Some(radii) = &cloud.radii {
        check_len("radii", radii.len())?;
    }
    if let Some(clip) = &cloud.clip {
        check_len("clip lines", clip.len())?;
    }

    let tree_cell = std::cell::OnceCell::new();
    let tree = || tree_cell.get_or_init(|| KdTree::new(positions));
    let normal_k = DEFAULT_NORMAL_K.min(n);

    let normals = match &cloud.normals {
        None => {
            check_normal_k(n, normal_k)?;
            normals_with_tree(tree(), positions, normal_k)
        }
        Some(given) => {
            let mut normals: Vec<Vec3> = given.iter().map(|v| v.normalize_or_zero()).collect();
            if normals.contains(&Vec3::ZERO) {
                check_normal_k(n, normal_k)?;
                repair_normals(tree(), positions, normal_k, &mut normals);
            }
            normals
        }
    };

    let valid_radius = |r: f32| r.is_finite() && r > 0.0;
    let radii = match &cloud.radii {
        Some(given) if given.iter().all(|&r| valid_radius(r)) => given.clone(),
        given => {
            let radius_k = DEFAULT_RADIUS_K.min(n.saturating_sub(1));
            check_radius_k(n, radius_k)?;
            let estimated = radii_with_tree(tree(), positions, radius_k)?;
            match given {
                Some(given) => given
                    .iter()
                    .zip(&estimated)
                    .map(|(&g, &e)| if valid_radius(g) { g } else { e })
                    .collect(),
                None => estimated,
            }
        }
    };

    let given_normal = |i: usize| {
        cloud
            .normals
            .as_ref()
            .is_some_and(|given| given[i].normalize_or_zero() != Vec3::ZERO)
    };
    Ok((0..n)
        .map(|i| Surfel {
            position: positions[i],
            normal: normals[i],
            radius: radii[i],
            color: cloud.colors.as_ref().map_or(DEFAULT_COLOR, |c| c[i]),
            clip: match &cloud.clip {
                Some(clip) if given_normal(i) => clip[i],
                _ => ClipLines::NONE,
            },
        })
        .collect())
}

fn validate_positions(positions: &[Vec3]) -> Result<()> {
    if positions.is_empty() {
        return Err(Error::invalid("point cloud", "no points"));
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::invalid(
            "point cloud",
            format!("point {i} is not finite ({})", positions[i]),
        ));
    }
    if positions.len() > u32::MAX as usize {
        return Err(Error::invalid("point cloud", "more than 2³² points"));
    }
    Ok(())
}

fn check_normal_k(n: usize, k: usize) -> Result<()> {
    if k < 3 || k > n {
        return Err(Error::invalid(
            "normal neighbourhood size k",
            format!("{k} must be at least 3 and at most the number of points ({n})"),
        ));
    }
    Ok(())
}

fn check_radius_k(n: usize, k: usize) -> Result<()> {
    if k == 0 || k >= n {
        return Err(Error::invalid(
            "radius neighbour rank k",
            format!("{k} must be at least 1 and less than the number of points ({n})"),
        ));
    }
    Ok(())
}

/// Unoriented PCA normals plus the neighbour lists (row-major, `k` per point).
fn pca_normals(tree: &KdTree, positions: &[Vec3], k: usize) -> (Vec<Vec3>, Vec<u32>) {
    let mut neighbours = Vec::with_capacity(positions.len() * k);
    let mut normals = Vec::with_capacity(positions.len());
    let mut found = Vec::with_capacity(k);
    let mut heap = BinaryHeap::with_capacity(k + 1);
    for &p in positions {
        tree.nearest(p, k, &mut heap, &mut found);
        normals.push(pca_normal(positions, &found));
        neighbours.extend(found.iter().map(|&(_, j)| j));
    }
    (normals, neighbours)
}

/// The smallest-eigenvalue eigenvector of the covariance of the given points.
fn pca_normal(positions: &[Vec3], found: &[(f32, u32)]) -> Vec3 {
    let count = found.len().max(1) as f64;
    let mut centre = [0.0f64; 3];
    for &(_, j) in found {
        let p = positions[j as usize];
        for (c, v) in centre.iter_mut().zip(p.to_array()) {
            *c += f64::from(v);
        }
    }
    centre.iter_mut().for_each(|c| *c /= count);
    let mut cov = [[0.0f64; 3]; 3];
    for &(_, j) in found {
        let p = positions[j as usize].to_array();
        let d = [0, 1, 2].map(|a| f64::from(p[a]) - centre[a]);
        for r in 0..3 {
            for c in 0..3 {
                cov[r][c] += d[r] * d[c];
            }
        }
    }
    smallest_eigenvector(cov)
}

/// Eigenvector of the smallest eigenvalue of a symmetric 3×3 matrix by cyclic
/// Jacobi rotations (Numerical Recipes §11.1); unit length.
fn smallest_eigenvector(mut a: [[f64; 3]; 3]) -> Vec3 {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let norm2: f64 = a.iter().flatten().map(|x| x * x).sum();
    if !(norm2.is_finite() && norm2 > 0.0) {
        return Vec3::Z;
    }
    for _sweep in 0..50 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if off <= 1e-30 * norm2 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            let r = 3 - p - q;
            let (arp, arq) = (a[r][p], a[r][q]);
            a[r][p] = c * arp - s * arq;
            a[p][r] = a[r][p];
            a[r][q] = s * arp + c * arq;
            a[q][r] = a[r][q];
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let min = (0..3).min_by(|&i, &j| a[i][i].total_cmp(&a[j][j])).unwrap_or(0);
    let e = Vec3::new(v[0][min] as f32, v[1][min] as f32, v[2][min] as f32);
    let e = e.normalize_or_zero();
    if e == Vec3::ZERO {
        Vec3::Z
    } else {
        e
    }
}

fn normals_with_tree(tree: &KdTree, positions: &[Vec3], k: usize) -> Vec<Vec3> {
    let (mut normals, neighbours) = pca_normals(tree, positions, k);
    orient_normals(positions, &mut normals, &neighbours, k);
    normals
}

/// Replaces zero entries of `normals` by PCA normals turned towards the sum of
/// the valid normals among their neighbours.
fn repair_normals(tree: &KdTree, positions: &[Vec3], k: usize, normals: &mut [Vec3]) {
    let mut found = Vec::with_capacity(k);
    let mut heap = BinaryHeap::with_capacity(k + 1);
    let missing: Vec<usize> = (0..normals.len()).filter(|&i| normals[i] == Vec3::ZERO).collect();
    for i in missing {
        tree.nearest(positions[i], k, &mut heap, &mut found);
        let mut n = pca_normal(positions, &found);
        let guide: Vec3 = found.iter().map(|&(_, j)| normals[j as usize]).sum();
        if n.dot(guide) < 0.0 {
            n = -n;
        }
        normals[i] = n;
    }
}

/// Consistent signs by a minimum spanning tree over the symmetrised kNN graph
/// with cost `1 − |nᵢ·nⱼ|` (Hoppe et al. 1992; module docs).
fn orient_normals(positions: &[Vec3], normals: &mut [Vec3], neighbours: &[u32], k: usize) {
    let n = positions.len();
    // Symmetrised adjacency in compressed rows.
    let mut degree = vec![0u32; n + 1];
    for (i, row) in neighbours.chunks(k).enumerate() {
        for &j in row {
            if j as usize != i {
                degree[i] += 1;
                degree[j as usize] += 1;
            }
        }
    }
    let mut start = vec![0usize; n + 1];
    for i in 0..n {
        start[i + 1] = start[i] + degree[i] as usize;
    }
    let mut fill = start.clone();
    let mut adjacency = vec![0u32; start[n]];
    for (i, row) in neighbours.chunks(k).enumerate() {
        for &j in row {
            if j as usize != i {
                adjacency[fill[i]] = j;
                fill[i] += 1;
                adjacency[fill[j as usize]] = i as u32;
                fill[j as usize] += 1;
            }
        }
    }

    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let centre = (lo + hi) * 0.5;
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| {
        let da = (positions[a as usize] - centre).length_squared();
        let db = (positions[b as usize] - centre).length_squared();
        db.total_cmp(&da).then(a.cmp(&b))
    });

    let mut visited = vec![false; n];
    let mut heap = BinaryHeap::new();
    for seed in order {
        let seed = seed as usize;
        if visited[seed] {
            continue;
        }
        let outward = (positions[seed] - centre).normalize_or_zero();
        let along = normals[seed].dot(outward);
        let flip = if along.abs() > 1e-3 {
            along < 0.0
        } else {
            let m = normals[seed];
            let largest = if m.x.abs() >= m.y.abs() && m.x.abs() >= m.z.abs() {
                m.x
            } else if m.y.abs() >= m.z.abs() {
                m.y
            } else {
                m.z
            };
            largest < 0.0
        };
        if flip {
            normals[seed] = -normals[seed];
        }
        visited[seed] = true;
        let push_edges = |from: usize, heap: &mut BinaryHeap<Edge>, visited: &[bool], normals: &[Vec3]| {
            for &to in &adjacency[start[from]..start[from + 1]] {
                if !visited[to as usize] {
                    let cost = 1.0 - normals[from].dot(normals[to as usize]).abs();
                    heap.push(Edge {
                        cost,
                        from: from as u32,
                        to,
                    });
                }
            }
        };
        push_edges(seed, &mut heap, &visited, normals);
        while let Some(edge) = heap.pop() {
            let to = edge.to as usize;
            if visited[to] {
                continue;
            }
            visited[to] = true;
            if normals[edge.from as usize].dot(normals[to]) < 0.0 {
                normals[to] = -normals[to];
            }
            push_edges(to, &mut heap, &visited, normals);
        }
    }
}

/// A graph edge in a min-heap by cost (ties by indices, for determinism).
#[derive(Clone, Copy, Debug)]
struct Edge {
    cost: f32,
    from: u32,
    to: u32,
}

impl PartialEq for Edge {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Edge {}
impl PartialOrd for Edge {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Edge {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap.
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.to.cmp(&self.to))
            .then(other.from.cmp(&self.from))
    }
}

fn radii_with_tree(tree: &KdTree, positions: &[Vec3], k: usize) -> Result<Vec<f32>> {
    let mut found = Vec::with_capacity(k + 1);
    let mut heap = BinaryHeap::with_capacity(k + 2);
    let scale = RADIUS_OVERLAP / (k as f32).sqrt();
    let mut radii = Vec::with_capacity(positions.len());
    for (i, &p) in positions.iter().enumerate() {
        tree.nearest(p, k + 1, &mut heap, &mut found);
        // The k-th nearest point other than i (i may not be among the results
        // when more than k points coincide with it).
        let d2 = found
            .iter()
            .filter(|&&(_, j)| j as usize != i)
            .nth(k - 1)
            .map_or(0.0, |&(d2, _)| d2);
        radii.push(scale * d2.sqrt());
    }
    let mut positive: Vec<f32> = radii.iter().copied().filter(|&r| r > 0.0 && r.is_finite()).collect();
    if positive.len() < radii.len() {
        if positive.is_empty() {
            return Err(Error::invalid(
                "point cloud",
                "all points coincide; radii cannot be estimated",
            ));
        }
        let mid = positive.len() / 2;
        let (_, &mut median, _) = positive.select_nth_unstable_by(mid, f32::total_cmp);
        for r in &mut radii {
            if !(*r > 0.0 && r.is_finite()) {
                *r = median;
            }
        }
    }
    Ok(radii)
}

/// Bucket size of [`KdTree`] leaves.
const LEAF_SIZE: usize = 8;
/// Marks a [`KdNode`] as a leaf.
const LEAF: u8 = 3;

/// A static kd-tree over points for exact k-nearest-neighbour and
/// fixed-radius queries (module docs). Each inner node splits its points at
/// the median of its widest axis with ties kept on one side, and stores the
/// largest coordinate on the left and the smallest on the right: points on
/// axis-aligned planes (floors, walls, grids) share coordinates, and a plain
/// median split would scatter equal values over both sides, forcing queries
/// into both. Build and queries use explicit stacks, so no input can
/// overflow the call stack.
pub(crate) struct KdTree {
    points: Vec<Vec3>,
    ids: Vec<u32>,
    nodes: Vec<KdNode>,
}

#[derive(Clone, Copy, Debug)]
struct KdNode {
    /// The node's points: `points[start..end]`.
    start: u32,
    end: u32,
    /// Split axis, or [`LEAF`].
    axis: u8,
    /// Largest coordinate on `axis` in the left child.
    left_max: f32,
    /// Smallest coordinate on `axis` in the right child.
    right_min: f32,
    /// Index of the left child; the right one follows it.
    left: u32,
}

/// A candidate neighbour in a max-heap by squared distance.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Neighbour {
    d2: f32,
    id: u32,
}

impl PartialEq for Neighbour {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Neighbour {}
impl PartialOrd for Neighbour {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Neighbour {
    fn cmp(&self, other: &Self) -> Ordering {
        self.d2.total_cmp(&other.d2).then(self.id.cmp(&other.id))
    }
}

impl KdTree {
    /// Builds the tree (`O(n log n)` for distinct coordinates); ids are
    /// indices into `positions`, which must be finite and fewer than 2³².
    pub(crate) fn new(positions: &[Vec3]) -> Self {
        let mut items: Vec<(Vec3, u32)> = positions.iter().enumerate().map(|(i, &p)| (p, i as u32)).collect();
        let mut nodes = vec![KdNode {
            start: 0,
            end: items.len() as u32,
            axis: LEAF,
            left_max: 0.0,
            right_min: 0.0,
            left: 0,
        }];
        let mut stack = vec![0usize];
        while let Some(index) = stack.pop() {
            let (start, end) = (nodes[index].start as usize, nodes[index].end as usize);
            if end - start <= LEAF_SIZE {
                continue;
            }
            let slice = &mut items[start..end];
            let (lo, hi) = slice.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), (p, _)| (lo.min(*p), hi.max(*p)),
            );
            let extent = hi - lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            if extent[axis] <= 0.0 {
                continue; // All points coincide: one (large) leaf.
            }
            let mid = slice.len() / 2;
            slice.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
            let median = slice[mid].0[axis];
            // Left: coordinates < median; if there are none (the median is
            // the minimum), ≤ median. Both sides are non-empty since the
            // extent is positive.
            let mut split = partition(slice, |p| p[axis] < median);
            if split == 0 {
                split = partition(slice, |p| p[axis] <= median);
            }
            let left_max = slice[..split]
                .iter()
                .map(|(p, _)| p[axis])
                .fold(f32::NEG_INFINITY, f32::max);
            let right_min = slice[split..]
                .iter()
                .map(|(p, _)| p[axis])
                .fold(f32::INFINITY, f32::min);
            let left = nodes.len();
            let child = |start: usize, end: usize| KdNode {
                start: start as u32,
                end: end as u32,
                axis: LEAF,
                left_max: 0.0,
                right_min: 0.0,
                left: 0,
            };
            nodes.push(child(start, start + split));
            nodes.push(child(start + split, end));
            let node = &mut nodes[index];
            node.axis = axis as u8;
            node.left_max = left_max;
            node.right_min = right_min;
            node.left = left as u32;
            stack.push(left);
            stack.push(left + 1);
        }
        let (points, ids) = items.into_iter().unzip();
        KdTree { points, ids, nodes }
    }

    /// Lower bounds of the squared distance from `q` to the children of an
    /// inner node, from the gap along its axis.
    fn child_bounds(&self, node: &KdNode, q: Vec3) -> (f32, f32) {
        let x = q[node.axis as usize];
        let to_left = (x - node.left_max).max(0.0);
        let to_right = (node.right_min - x).max(0.0);
        (to_left * to_left, to_right * to_right)
    }

    /// The `k` nearest points to `q` (ties broken arbitrarily but
    /// deterministically), written to `out` as `(squared distance, id)` by
    /// increasing distance. `heap` is scratch space.
    pub(crate) fn nearest(&self, q: Vec3, k: usize, heap: &mut BinaryHeap<Neighbour>, out: &mut Vec<(f32, u32)>) {
        heap.clear();
        out.clear();
        if k == 0 || self.points.is_empty() {
            return;
        }
        // (node, lower bound of the squared distance to its points)
        let mut stack: Vec<(u32, f32)> = Vec::with_capacity(64);
        stack.push((0, 0.0));
        while let Some((index, bound)) = stack.pop() {
            if heap.len() == k && heap.peek().is_some_and(|top| bound > top.d2) {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.axis == LEAF {
                for i in node.start as usize..node.end as usize {
                    let candidate = Neighbour {
                        d2: (self.points[i] - q).length_squared(),
                        id: self.ids[i],
                    };
                    if heap.len() < k {
                        heap.push(candidate);
                    } else if heap.peek().is_some_and(|top| candidate < *top) {
                        heap.pop();
                        heap.push(candidate);
                    }
                }
                continue;
            }
            let (to_left, to_right) = self.child_bounds(node, q);
            let (left, right) = (node.left, node.left + 1);
            // The nearer child goes on top of the stack.
            if to_left <= to_right {
                stack.push((right, to_right));
                stack.push((left, to_left));
            } else {
                stack.push((left, to_left));
                stack.push((right, to_right));
            }
        }
        out.extend(heap.drain().map(|n| (n.d2, n.id)));
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }

    /// Calls `f(id, squared distance)` for every point strictly closer to `q`
    /// than `sqrt(r2)`.
    pub(crate) fn for_each_within(&self, q: Vec3, r2: f32, f: &mut impl FnMut(u32, f32)) {
        if self.points.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if node.axis == LEAF {
                for i in node.start as usize..node.end as usize {
                    let d2 = (self.points[i] - q).length_squared();
                    if d2 < r2 {
                        f(self.ids[i], d2);
                    }
                }
                continue;
            }
            let (to_left, to_right) = self.child_bounds(node, q);
            if to_right < r2 {
                stack.push(node.left + 1);
            }
            if to_left < r2 {
                stack.push(node.left);
            }
        }
    }
}

/// Moves the items whose position satisfies `left` to the front; returns
/// their count.
fn partition(items: &mut [(Vec3, u32)], left: impl Fn(Vec3) -> bool) -> usize {
    let mut split = 0;
    for i in 0..items.len() {
        if left(items[i].0) {
            items.swap(i, split);
            split += 1;
        }
    }
    split
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator for test data.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
    }

    fn fibonacci_sphere(n: usize, centre: Vec3, radius: f32) -> Vec<Vec3> {
        let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f32;
                centre + radius * Vec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn kd_tree_matches_brute_force() {
        let mut rng = Lcg(7);
        let mut points: Vec<Vec3> = (0..2000)
            .map(|_| Vec3::new(rng.next(), rng.next() * 0.3, rng.next() * 2.0))
            .collect();
        // Duplicates and a cluster.
        points.extend_from_within(..50);
        points.extend((0..100).map(|i| Vec3::splat(0.5) + Vec3::X * i as f32 * 1e-4));
        // Axis-aligned planes and grids share coordinates.
        points.extend((0..900).map(|i| Vec3::new((i % 30) as f32 / 30.0, 0.25, (i / 30) as f32 / 30.0)));
        points.extend((0..400).map(|_| Vec3::new(rng.next(), rng.next(), 0.75)));
        let tree = KdTree::new(&points);
        let mut heap = BinaryHeap::new();
        let mut out = Vec::new();
        for qi in 0..200 {
            let q = if qi % 2 == 0 {
                points[qi * 7]
            } else {
                Vec3::new(rng.next(), rng.next(), rng.next())
            };
            let mut brute: Vec<f32> = points.iter().map(|p| (*p - q).length_squared()).collect();
            brute.sort_by(f32::total_cmp);
            for k in [1, 5, 17] {
                tree.nearest(q, k, &mut heap, &mut out);
                assert_eq!(out.len(), k);
                for (m, &(d2, id)) in out.iter().enumerate() {
                    assert_eq!(d2, brute[m]);
                    assert_eq!(d2, (points[id as usize] - q).length_squared());
                }
            }
            let r2 = 0.01;
            let mut count = 0;
            tree.for_each_within(q, r2, &mut |id, d2| {
                assert!(d2 < r2);
                assert_eq!(d2, (points[id as usize] - q).length_squared());
                count += 1;
            });
            assert_eq!(count, brute.iter().filter(|&&d2| d2 < r2).count());
        }
    }

    #[test]
    fn jacobi_finds_smallest_eigenvector() {
        // R · diag(3, 1, 0.2) · Rᵀ for a generic rotation R.
        let rot = glam::DMat3::from_quat(glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0));
        let d = glam::DMat3::from_diagonal(glam::DVec3::new(3.0, 1.0, 0.2));
        let m = rot * d * rot.transpose();
        let a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| m.col(c)[r]));
        let e = smallest_eigenvector(a).as_dvec3();
        assert!(e.dot(rot.z_axis).abs() > 1.0 - 1e-6, "{e} vs {}", rot.z_axis);
        // Repeated eigenvalues and already diagonal input.
        let e = smallest_eigenvector([[2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 2.0]]);
        assert_eq!(e.abs(), Vec3::Y);
        let e = smallest_eigenvector([[0.0; 3]; 3]);
        assert!(e.is_normalized());
    }

    #[test]
    fn plane_normals_agree() {
        let normal = Vec3::new(0.3, -0.5, 0.8).normalize();
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let mut rng = Lcg(3);
        let points: Vec<Vec3> = (0..40)
            .flat_map(|i| (0..40).map(move |j| (i, j)))
            .map(|(i, j)| {
                let a = i as f32 * 0.1 + (rng.next() - 0.5) * 0.04;
                let b = j as f32 * 0.1 + (rng.next() - 0.5) * 0.04;
                Vec3::new(5.0, -2.0, 1.0) + a * u + b * v
            })
            .collect();
        let normals = estimate_normals(&points, 8).unwrap();
        let sign = normals[0].dot(normal).signum();
        for n in &normals {
            assert!(n.is_normalized());
            assert!(n.dot(normal) * sign > 0.999, "{n} vs {normal}");
        }
    }

    #[test]
    fn sphere_normals_point_outwards() {
        let centre = Vec3::new(1.0, 2.0, -3.0);
        let points = fibonacci_sphere(2000, centre, 2.0);
        let normals = estimate_normals(&points, 8).unwrap();
        for (p, n) in points.iter().zip(&normals) {
            let radial = (*p - centre).normalize();
            assert!(n.dot(radial) > 0.95, "{n} at {p}");
        }
    }

    #[test]
    fn two_spheres_are_oriented_separately() {
        let mut points = fibonacci_sphere(800, Vec3::ZERO, 1.0);
        points.extend(fibonacci_sphere(800, Vec3::new(5.0, 0.0, 0.0), 0.5));
        let normals = estimate_normals(&points, 8).unwrap();
        for (i, (p, n)) in points.iter().zip(&normals).enumerate() {
            let centre = if i < 800 { Vec3::ZERO } else { Vec3::new(5.0, 0.0, 0.0) };
            assert!(n.dot((*p - centre).normalize()) > 0.95, "{i}: {n} at {p}");
        }
    }

    #[test]
    fn grid_radii_match_spacing() {
        let h = 0.25;
        let points: Vec<Vec3> = (0..30)
            .flat_map(|i| (0..30).map(move |j| Vec3::new(i as f32 * h, 2.0, j as f32 * h)))
            .collect();
        let radii = estimate_radii(&points, 6).unwrap();
        // d_6 = √2·h on a square grid, so r = 1.75·√2/√6·h ≈ 1.01·h.
        let expected = RADIUS_OVERLAP * 2.0f32.sqrt() / 6.0f32.sqrt() * h;
        for i in 2..28 {
            for j in 2..28 {
                let r = radii[i * 30 + j];
                assert!((r - expected).abs() < 1e-3 * h, "{r} vs {expected}");
                assert!(r > h / 2.0f32.sqrt(), "disks must cover the grid");
            }
        }
        assert!(radii.iter().all(|&r| r.is_finite() && r > 0.0));
    }

    #[test]
    fn duplicate_points_get_positive_radii() {
        let mut points: Vec<Vec3> = (0..20).map(|i| Vec3::X * i as f32).collect();
        points.extend(std::iter::repeat(Vec3::new(3.0, 1.0, 0.0)).take(10));
        let radii = estimate_radii(&points, 2).unwrap();
        assert!(radii.iter().all(|&r| r.is_finite() && r > 0.0));
        assert!(estimate_radii(&[Vec3::ONE; 5], 2).is_err());
    }

    #[test]
    fn bad_input_is_an_error() {
        let points = fibonacci_sphere(10, Vec3::ZERO, 1.0);
        assert!(estimate_normals(&points, 11).is_err());
        assert!(estimate_normals(&points, 2).is_err());
        assert!(estimate_normals(&points, 10).is_ok());
        assert!(estimate_radii(&points, 10).is_err());
        assert!(estimate_radii(&points, 0).is_err());
        assert!(estimate_radii(&points, 9).is_ok());
        assert!(estimate_normals(&[], 8).is_err());
        assert!(estimate_radii(&[], 6).is_err());
        let mut bad = points.clone();
        bad[3].y = f32::NAN;
        assert!(estimate_normals(&bad, 8).is_err());
        bad[3].y = f32::INFINITY;
        assert!(estimate_radii(&bad, 6).is_err());
        assert!(complete_cloud(&PointCloud::default()).is_err());
        assert!(complete_cloud(&PointCloud {
            positions: points.clone(),
            colors: Some(vec![[0; 3]; 3]),
            ..Default::default()
        })
        .is_err());
        assert!(complete_cloud(&PointCloud {
            positions: points.clone(),
            clip: Some(vec![ClipLines::NONE; 3]),
            ..Default::default()
        })
        .is_err());
        assert!(complete_cloud(&PointCloud {
            positions: points[..2].to_vec(),
            ..Default::default()
        })
        .is_err());
    }

    #[test]
    fn complete_cloud_fills_and_keeps() {
        let points = fibonacci_sphere(500, Vec3::ZERO, 1.0);
        let surfels = complete_cloud(&PointCloud {
            positions: points.clone(),
            ..Default::default()
        })
        .unwrap();
        assert_eq!(surfels.len(), 500);
        for s in &surfels {
            assert!(s.normal.dot(s.position.normalize()) > 0.95);
            assert!(s.radius > 0.0 && s.radius.is_finite());
            assert_eq!(s.color, DEFAULT_COLOR);
        }

        // Given attributes are kept; invalid ones are repaired.
        let mut normals: Vec<Vec3> = points.iter().map(|p| -*p * 2.0).collect();
        normals[7] = Vec3::ZERO;
        let mut radii = vec![0.5; 500];
        radii[9] = f32::NAN;
        let colors: Vec<[u8; 3]> = (0..500).map(|i| [i as u8, 1, 2]).collect();
        let line = |angle: f32| crate::points::build::clip::ClipLine { angle, offset: 0.01 };
        let clip: Vec<ClipLines> = (0..500).map(|i| ClipLines([Some(line(i as f32)), None])).collect();
        let surfels = complete_cloud(&PointCloud {
            positions: points.clone(),
            normals: Some(normals),
            colors: Some(colors),
            radii: Some(radii),
            clip: Some(clip.clone()),
        })
        .unwrap();
        for (i, s) in surfels.iter().enumerate() {
            assert!(s.normal.is_normalized());
            assert!(
                s.normal.dot(s.position.normalize()) < -0.95,
                "{i}: inward like the given ones"
            );
            assert_eq!(s.color, [i as u8, 1, 2]);
            // Clip lines are kept where the normal (their frame) was given.
            let expected = if i == 7 { ClipLines::NONE } else { clip[i] };
            assert_eq!(s.clip, expected, "{i}");
            if i != 9 {
                assert_eq!(s.radius, 0.5);
            }
        }
        assert!(surfels[9].radius > 0.0 && surfels[9].radius < 0.5);

        // Tiny clouds use smaller neighbourhoods.
        let tiny = complete_cloud(&PointCloud {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            ..Default::default()
        })
        .unwrap();
        assert!(tiny.iter().all(|s| s.normal.z.abs() > 0.999 && s.radius > 0.0));
    }

    #[test]
    fn estimate_is_deterministic() {
        let points = fibonacci_sphere(1000, Vec3::ZERO, 1.0);
        assert_eq!(
            estimate_normals(&points, 8).unwrap(),
            estimate_normals(&points, 8).unwrap()
        );
        assert_eq!(estimate_radii(&points, 6).unwrap(), estimate_radii(&points, 6).unwrap());
    }

    #[test]
    fn speed_35k_points() {
        let points = fibonacci_sphere(35_000, Vec3::ZERO, 1.0);
        let start = std::time::Instant::now();
        let surfels = complete_cloud(&PointCloud {
            positions: points,
            ..Default::default()
        })
        .unwrap();
        println!(
            "complete_cloud: {} points in {:.1} ms (normals k = {DEFAULT_NORMAL_K}, radii k = {DEFAULT_RADIUS_K})",
            surfels.len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
}
