//! Hybrid point–polygon rendering (dissertation §10.1.8; `ALGORITHMS.md` §7):
//! a mesh is drawn with its own triangles where they are large in the image
//! and with the sequential point tree of its surface samples where they are
//! small.
//!
//! A triangle whose longest side s appears larger than the error threshold
//! (s/r ≥ ε, r the eye distance) needs at least two splats, so drawing it as
//! a triangle is the better option: it gets `r_max = s/ε` and is drawn iff
//! `r < r_max`. The triangles are sorted by decreasing `r_max` like the
//! splats, so per object and frame the CPU sends the prefix with
//! `r_max > r_lo` and the vertex stage does the exact test
//! (`glsl/points/hybrid.vert`). For that test r is a lower bound of the eye
//! distance of every point of the triangle (the distance to its centroid
//! minus the centroid's largest vertex distance), so a triangle is drawn
//! whenever any of its surfels would have been.
//!
//! The text then removes "all points with an `r_max` smaller than the `r_max`
//! of the original triangle". We make that precise as a floor on each node's
//! `r_min`: a surfel sampled on triangle T is not needed while T is drawn, so
//! its leaf gets `r_min ≥ s_T/ε`; an inner node is not needed while *all*
//! the triangles under it are drawn, so its floor is the smallest one of its
//! leaves. `r_max` is left as built, and nodes whose interval becomes empty
//! (`floor ≥ r_max`) are removed from the list — for a mesh of large
//! triangles, all but the coarse levels.
//!
//! No holes (derived): take a surfel on T and an eye distance r ≥ s_T/ε
//! (below it T is drawn). On the surfel's leaf-to-root path let A be the
//! lowest node with `r_max(A) > r` (the root's is ∞). If A is the leaf, its
//! floor is s_T/ε ≤ r. Otherwise its child C on the path has
//! `r_max(C) ≤ r`, and since `r_max(C) = r_min(A) + |p_C − p_A| ≥ r_min(A)`
//! the built `r_min(A) ≤ r`; A's floor is at most s_T/ε ≤ r as well. So A is
//! drawn: the hybrid tree covers every r that the triangle does not (with
//! r constant over the object; where it varies the overlap term of
//! §10.1.6 works as in the plain tree).
//!
//! A surfel disk reaches beyond its own triangle (radius ≈ 2.4 sample
//! spacings), and a sliver triangle may have no sample at all, so its area
//! is covered only by its neighbours' surfels. A surfel's floor is therefore
//! the smallest `s` over its triangle and the triangles sharing a vertex with
//! it: a surfel stays while any of those is too small to be drawn.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;

use super::sampling::{sample_mesh_traced, SamplingOptions, DEFAULT_COLOR};
use super::spt::{build_spt, SequentialPointTree, SptOptions, NO_PARENT};
use crate::error::{Error, Result};
use crate::points::{Surfel, TriangleMesh};

/// One triangle of a hybrid object, object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HybridTriangle {
    /// Counter-clockwise corners.
    pub positions: [Vec3; 3],
    /// Unit vertex normals (the face normal when the mesh has none).
    pub normals: [Vec3; 3],
    /// sRGB vertex colours.
    pub colors: [[u8; 3]; 3],
    /// Longest side s (object units): drawn while `r < s/ε`.
    pub longest_edge: f32,
}

impl HybridTriangle {
    /// Centroid and the largest distance from it to a corner: the bounding
    /// sphere whose near side bounds the eye distance (module docs).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let [a, b, c] = self.positions;
        let centre = (a + b + c) / 3.0;
        let radius = self
            .positions
            .iter()
            .map(|p| (*p - centre).length())
            .fold(0.0, f32::max);
        (centre, radius)
    }
}

/// The triangles of a hybrid object and what is needed to derive its point
/// list at any ε.
#[derive(Clone, Debug)]
pub struct HybridMesh {
    /// The triangles with positive area, sorted by decreasing `longest_edge`.
    pub triangles: Vec<HybridTriangle>,
    /// The tree of every surfel, before the floors (kept for other ε).
    pub full_tree: Arc<SequentialPointTree>,
    /// Radius of the surfels (object units): the triangles' visibility offset.
    pub surfel_radius: f32,
    /// Floor edge length per leaf, keyed by the bits of the leaf's position
    /// (a leaf's position is its surfel's, exactly); coincident surfels keep
    /// the smaller floor.
    leaf_edges: HashMap<[u32; 3], f32>,
}

fn position_key(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

/// Samples `mesh`, builds the tree of its surfels and returns the hybrid
/// object's point list (floors applied, see the module docs) with its
/// triangles.
///
/// Errors as [`sample_mesh_traced`] and [`build_spt`].
pub fn build_hybrid(
    mesh: &TriangleMesh,
    sampling: &SamplingOptions,
    options: &SptOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(SequentialPointTree, HybridMesh)> {
    let (surfels, sources) = sample_mesh_traced(mesh, sampling)?;
    let full_tree = build_spt(&surfels, options, progress)?;
    let hybrid = HybridMesh::new(mesh, &surfels, &sources, Arc::new(full_tree))?;
    let tree = hybrid.point_tree(&hybrid.full_tree);
    Ok((tree, hybrid))
}

impl HybridMesh {
    /// The triangles of `mesh` and the floors of `surfels`, where surfel i
    /// lies on mesh triangle `sources[i]`; `full_tree` is their tree.
    pub fn new(
        mesh: &TriangleMesh,
        surfels: &[Surfel],
        sources: &[u32],
        full_tree: Arc<SequentialPointTree>,
    ) -> Result<HybridMesh> {
        if surfels.len() != sources.len() {
            return Err(Error::invalid(
                "hybrid mesh",
                format!("{} surfels with {} source triangles", surfels.len(), sources.len()),
            ));
        }
        let n = mesh.positions.len();
        let edge = |t: &[u32; 3]| -> Option<f32> {
            let [a, b, c] = t.map(|i| mesh.positions.get(i as usize).copied());
            let (a, b, c) = (a?, b?, c?);
            Some((b - a).length().max((c - b).length()).max((a - c).length()))
        };
        // Smallest longest-side of the triangles around each vertex.
        let mut vertex_edge = vec![f32::INFINITY; n];
        for t in &mesh.triangles {
            let s = edge(t).ok_or_else(|| Error::invalid("hybrid mesh", "a triangle index is out of range"))?;
            for &v in t {
                let e = &mut vertex_edge[v as usize];
                *e = e.min(s);
            }
        }
        let mut leaf_edges = HashMap::with_capacity(surfels.len());
        for (surfel, &source) in surfels.iter().zip(sources) {
            let t = mesh
                .triangles
                .get(source as usize)
                .ok_or_else(|| Error::invalid("hybrid mesh", format!("source triangle {source} is out of range")))?;
            let floor = t.iter().map(|&v| vertex_edge[v as usize]).fold(f32::INFINITY, f32::min);
            let entry = leaf_edges.entry(position_key(surfel.position)).or_insert(floor);
            *entry = entry.min(floor);
        }

        let mut triangles = Vec::with_capacity(mesh.triangles.len());
        for t in &mesh.triangles {
            let positions = t.map(|i| mesh.positions[i as usize]);
            let face = (positions[1] - positions[0]).cross(positions[2] - positions[0]);
            let face_normal = face.normalize_or_zero();
            if face_normal == Vec3::ZERO || !face.is_finite() {
                continue;
            }
            let normals = match &mesh.normals {
                Some(normals) => t.map(|i| {
                    let n = normals
                        .get(i as usize)
                        .copied()
                        .unwrap_or(face_normal)
                        .normalize_or_zero();
                    if n == Vec3::ZERO {
                        face_normal
                    } else {
                        n
                    }
                }),
                None => [face_normal; 3],
            };
            let colors = match &mesh.colors {
                Some(colors) => t.map(|i| colors.get(i as usize).copied().unwrap_or(DEFAULT_COLOR)),
                None => [DEFAULT_COLOR; 3],
            };
            triangles.push(HybridTriangle {
                positions,
                normals,
                colors,
                longest_edge: edge(t).unwrap_or(0.0),
            });
        }
        triangles.sort_by(|a, b| b.longest_edge.total_cmp(&a.longest_edge));
        Ok(HybridMesh {
            triangles,
            surfel_radius: surfels.first().map_or(0.0, |s| s.radius),
            full_tree,
            leaf_edges,
        })
    }

    /// `r_max = s/ε` of a triangle for threshold `epsilon`.
    pub fn triangle_r_max(triangle: &HybridTriangle, epsilon: f32) -> f32 {
        triangle.longest_edge / epsilon
    }

    /// Number of leading triangles with `r_max > r_lo` at threshold
    /// `epsilon`: no later triangle can pass the test `r < r_max` when
    /// `r_lo` bounds r from below. A NaN `r_lo` gives every triangle.
    pub fn prefix_len(&self, r_lo: f32, epsilon: f32) -> usize {
        if r_lo.is_nan() {
            return self.triangles.len();
        }
        self.triangles
            .partition_point(|t| Self::triangle_r_max(t, epsilon) > r_lo)
    }

    /// Per node of `full` (this object's tree at some ε): its raised `r_min`
    /// `max(r_min, floor/ε)`, or None where the interval became empty
    /// (module docs).
    pub fn floored_r_min(&self, full: &SequentialPointTree) -> Vec<Option<f32>> {
        let nodes = &full.nodes;
        let mut floor: Vec<f32> = nodes
            .iter()
            .map(|n| {
                if n.is_leaf {
                    self.leaf_edges.get(&position_key(n.position)).copied().unwrap_or(0.0)
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        // Children before parents: deepest first.
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(nodes[i].depth));
        for &i in &order {
            let parent = nodes[i].parent;
            if parent != NO_PARENT {
                let p = parent as usize;
                floor[p] = floor[p].min(floor[i]);
            }
        }
        nodes
            .iter()
            .zip(&floor)
            .map(|(n, &f)| {
                let f = if f.is_finite() { f / full.epsilon } else { 0.0 };
                let r_min = n.r_min.max(f);
                (r_min < n.r_max).then_some(r_min)
            })
            .collect()
    }

    /// The point list drawn with the triangles: `full` with the floors
    /// applied and the empty nodes removed, still sorted by decreasing
    /// `r_max`. A node whose parent was removed refers to its nearest
    /// remaining ancestor; `r_max` values are the built ones (not re-derived
    /// from the new parents), so the result is not for
    /// [`SequentialPointTree::with_epsilon`] — derive the full tree at the
    /// new ε and call this again.
    pub fn point_tree(&self, full: &SequentialPointTree) -> SequentialPointTree {
        let r_min = self.floored_r_min(full);
        let mut new_index = vec![NO_PARENT; full.nodes.len()];
        let mut next = 0u32;
        for (i, r) in r_min.iter().enumerate() {
            if r.is_some() {
                new_index[i] = next;
                next += 1;
            }
        }
        let kept_ancestor = |mut p: u32| {
            while p != NO_PARENT && new_index[p as usize] == NO_PARENT {
                p = full.nodes[p as usize].parent;
            }
            if p == NO_PARENT {
                NO_PARENT
            } else {
                new_index[p as usize]
            }
        };
        let nodes = full
            .nodes
            .iter()
            .zip(&r_min)
            .filter_map(|(n, r)| {
                r.map(|r_min| {
                    let mut node = *n;
                    node.r_min = r_min;
                    node.parent = kept_ancestor(n.parent);
                    node
                })
            })
            .collect();
        SequentialPointTree {
            nodes,
            bounds_centre: full.bounds_centre,
            bounds_radius: full.bounds_radius,
            epsilon: full.epsilon,
        }
    }

    /// This object at threshold `epsilon`: the point list and the hybrid
    /// data with the full tree re-derived.
    pub fn with_epsilon(&self, epsilon: f32) -> Result<(SequentialPointTree, HybridMesh)> {
        let full = Arc::new(self.full_tree.with_epsilon(epsilon)?);
        let hybrid = HybridMesh {
            full_tree: full,
            ..self.clone()
        };
        Ok((hybrid.point_tree(&hybrid.full_tree), hybrid))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::sampling::SamplingMethod;
    use crate::points::build::spt::epsilon_from_pixels;

    /// A unit square in z = 0: two large triangles on the left half, a fan
    /// of small ones on the right.
    fn mixed_square() -> TriangleMesh {
        let mut positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let mut triangles = vec![[0, 1, 2], [0, 2, 3]];
        let n = 16;
        for j in 0..=n {
            for i in 0..=n {
                positions.push(Vec3::new(0.5 + 0.5 * i as f32 / n as f32, j as f32 / n as f32, 0.0));
            }
        }
        let at = |i: u32, j: u32| 4 + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        TriangleMesh {
            positions,
            normals: None,
            colors: None,
            triangles,
        }
    }

    fn epsilon() -> f32 {
        epsilon_from_pixels(1.0, 50f32.to_radians(), 400).unwrap()
    }

    fn build(mesh: &TriangleMesh) -> (SequentialPointTree, HybridMesh) {
        build_at(mesh, epsilon())
    }

    fn build_at(mesh: &TriangleMesh, epsilon: f32) -> (SequentialPointTree, HybridMesh) {
        let sampling = SamplingOptions {
            count: 4000,
            method: SamplingMethod::Stratified,
            seed: 7,
        };
        let options = SptOptions {
            epsilon,
            ..SptOptions::default()
        };
        build_hybrid(mesh, &sampling, &options, &mut |_| {}).expect("hybrid")
    }

    #[test]
    fn triangles_are_sorted_and_the_prefix_bounds_the_test() {
        let (_, hybrid) = build(&mixed_square());
        assert_eq!(hybrid.triangles.len(), 2 + 2 * 16 * 16);
        assert!(hybrid
            .triangles
            .windows(2)
            .all(|w| w[0].longest_edge >= w[1].longest_edge));
        let eps = hybrid.full_tree.epsilon;
        for r_lo in [0.0, 1.0, 10.0, 30.0, 1e6] {
            let k = hybrid.prefix_len(r_lo, eps);
            assert!(hybrid.triangles[k..]
                .iter()
                .all(|t| HybridMesh::triangle_r_max(t, eps) <= r_lo));
            assert!(hybrid.triangles[..k]
                .iter()
                .all(|t| HybridMesh::triangle_r_max(t, eps) > r_lo));
        }
        assert_eq!(hybrid.prefix_len(f32::NAN, eps), hybrid.triangles.len());
    }

    /// At constant r, every surfel is covered: by its triangle (r < its
    /// r_max) or by a node of its leaf-to-root path in the floored tree.
    #[test]
    fn floors_leave_no_holes_at_any_distance() {
        let mesh = mixed_square();
        let sampling = SamplingOptions {
            count: 4000,
            method: SamplingMethod::Stratified,
            seed: 7,
        };
        let (surfels, sources) = sample_mesh_traced(&mesh, &sampling).unwrap();
        let (tree, hybrid) = build(&mesh);
        let full = &hybrid.full_tree;
        let eps = full.epsilon;
        let r_min = hybrid.floored_r_min(full);
        let leaf_of: HashMap<[u32; 3], usize> = full
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.is_leaf)
            .map(|(i, n)| (position_key(n.position), i))
            .collect();
        let mut tested_between = 0;
        for r in [0.5f32, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0, 200.0, 1000.0] {
            for (surfel, &t) in surfels.iter().zip(&sources) {
                let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
                let s = (b - a).length().max((c - b).length()).max((a - c).length());
                if r < s / eps {
                    continue;
                }
                tested_between += 1;
                let mut node = leaf_of[&position_key(surfel.position)];
                let mut covered = false;
                loop {
                    let n = &full.nodes[node];
                    covered |= r_min[node].is_some_and(|lo| lo <= r && r < n.r_max);
                    if n.parent == NO_PARENT {
                        break;
                    }
                    node = n.parent as usize;
                }
                assert!(covered, "surfel at {} uncovered at r = {r}", surfel.position);
            }
        }
        assert!(tested_between > 0);
        // The floors remove points: near the mesh the large triangles replace
        // most of the left half's nodes.
        assert!(tree.nodes.len() < full.nodes.len());
        let near = |t: &SequentialPointTree| t.select(|_| 2.0).len();
        assert!(near(&tree) * 10 < near(full) * 7, "{} vs {}", near(&tree), near(full));
        // Far away every triangle is small: the same nodes are drawn.
        let far = |t: &SequentialPointTree| t.select(|_| 1e5).len();
        assert_eq!(far(&tree), far(full));
    }

    #[test]
    fn parents_refer_to_kept_ancestors_and_other_epsilons_match_a_build() {
        let mesh = mixed_square();
        let (tree, hybrid) = build(&mesh);
        assert!(tree.nodes.windows(2).all(|w| w[0].r_max >= w[1].r_max));
        for n in &tree.nodes {
            if n.parent != NO_PARENT {
                assert!((n.parent as usize) < tree.nodes.len());
            }
        }
        let (again, _) = hybrid.with_epsilon(epsilon() * 2.0).unwrap();
        let (built, _) = build_at(&mesh, epsilon() * 2.0);
        assert_eq!(again, built);
        assert_ne!(again, tree);
    }

    #[test]
    fn mismatched_sources_are_an_error() {
        let mesh = mixed_square();
        let (_, hybrid) = build(&mesh);
        let err = HybridMesh::new(&mesh, &[], &[0], hybrid.full_tree.clone()).unwrap_err();
        assert!(err.to_string().contains("source triangles"), "{err}");
    }
}
