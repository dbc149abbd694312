//! Sequential point trees (dissertation §10.1; `ALGORITHMS.md` §7).
//!
//! A point hierarchy is built over the input surfels with an octree, every
//! node gets a disk (centre, normal, diameter) and a geometric error, and the
//! recursive level-of-detail traversal of §10.1.5 is replaced by the
//! non-recursive interval test `r_min ≤ r < r_max` of §10.1.6, r being the
//! node's own eye distance. The nodes are then sorted by decreasing `r_max`
//! (§10.1.7) so that, per object and frame, only a prefix of the list has to
//! be sent to the GPU ([`SequentialPointTree::prefix_len`]) and the vertex
//! stage culls the rest ([`SequentialPointTree::select`] is the CPU reference
//! of that test).
//!
//! # Build (§10.1.3, §10.1.4)
//!
//! The leaves are the input surfels (a surfel of radius ρ is a leaf disk of
//! diameter 2ρ with zero error; it keeps the surfel's clip lines, §10.2.4,
//! while inner nodes have none). The surfels are inserted into an octree over
//! their bounding cube; a cell with more than [`SptOptions::leaf_size`]
//! surfels is split into its eight octants until [`SptOptions::max_depth`]. A
//! cell holding one surfel is that leaf; a cell holding 2..=`leaf_size`
//! surfels (or any number at `max_depth`, e.g. duplicates) is an inner node
//! whose children are those leaves; a split cell is an inner node whose
//! children are the non-empty octants. A split with a single non-empty octant
//! creates no node (chains of one-child nodes would only repeat their child),
//! so every inner node has at least two children.
//!
//! For an inner node with children i (centre p_i, unit normal n_i, disk radius
//! r_i = d_i/2):
//!
//! * centre `p = mean(p_i)` and colour = mean of the children's colours
//!   (unweighted, as the text says "averaged"; colours are averaged as stored,
//!   i.e. in sRGB code values, rounded);
//! * normal `n = normalise(mean(n_i))`. When the children's normals cancel
//!   (`|mean(n_i)| < 0.01`, e.g. both sides of a thin leaf or a whole closed
//!   surface) the mean has no usable direction; we then take the principal
//!   axis of the normals, the dominant eigenvector of `Σ a_i n_i n_iᵀ` with
//!   areas `a_i = r_i²` as weights (power iteration started at the normal of
//!   the child with the largest area), oriented to agree with that largest
//!   child. For two opposite disks this is the larger disk's normal; for the
//!   degenerate case where the iteration fails it is that normal outright.
//! * diameter d: the disk centred at p in the node's plane that bounds the
//!   children's disks projected into that plane. The projection of child disk
//!   i is an ellipse centred at the projection of p_i with semi-major axis r_i,
//!   so every point of it lies within `|P(p_i − p)| + r_i` of p (P the
//!   projection onto the plane), and `d = 2·max_i(|P(p_i − p)| + r_i)`. The
//!   text approximates a minimal bounding disk with a modified Welzl
//!   algorithm; a minimal disk generally has a centre other than the mean,
//!   while the text (and the GPU, which draws the disk at p) needs the disk
//!   centred at p, so we bound around p. Since `d ≥ 2 r_i = d_i` the diameter
//!   grows monotonically up the hierarchy, as §10.1.3 requires.
//! * perpendicular error (Fig. 10.4; the text's Eq. is garbled, restated in
//!   `ALGORITHMS.md`): with `δ_i = r_i·sqrt(1 − (n_i·n)²)`, the half extent of
//!   disk i along n, `e_p = max_i((p_i − p)·n + δ_i) − min_i((p_i − p)·n − δ_i)`,
//!   the distance between the two planes parallel to the node disk that
//!   enclose all children disks.
//! * tangential error (Fig. 10.5): slabs of [`SLAB_DIRECTIONS`] = 8
//!   orientations `u_k = cos(kπ/8)·t + sin(kπ/8)·b`, k = 0..8 ((t, b) an
//!   orthonormal basis of the plane; a slab and its opposite are the same, so
//!   half a turn covers all orientations at 22.5° steps) are fitted around the
//!   projected children; along u_k child i spans `(p_i − p)·u_k ± r_i·sqrt(1 −
//!   (n_i·u_k)²)` (projecting along n does not change the component along
//!   u_k ⊥ n). `e_t = max(0, d − min_k width_k)`.
//! * geometric error `e_g = sqrt(e_p² + e_t²)`.
//! * colour (§10.1.9): when the children's colours differ by more than
//!   [`SptOptions::color_threshold`] — measured as the largest per-channel
//!   range `max_c(max_i c_i,c − min_i c_i,c)` in 8-bit sRGB code values — the
//!   error is raised to the diameter: `e_g = max(e_g, d)`. This forces small
//!   splats where the colour varies, so the averaging that the node would do
//!   only ever blurs over about ε in the image. Only `e_g` is raised; `e_p`
//!   and `e_t` stay geometric (the view-dependent test `e_p·sin α + e_t·cos α`
//!   of [`super::spt_view`] keeps the stored interval for such nodes).
//!
//! Because d bounds the children only in the node's plane, e_p can exceed d
//! (children stacked along n). The text's bound `e_g ≤ d` holds for its
//! bounding-sphere d; we do not cap e_g, which can only make the node be
//! selected later (at a larger distance), i.e. it errs on the side of detail.
//!
//! # Monotonicity (derived)
//!
//! The sequential test reproduces the recursive traversal of §10.1.5 only if
//! the per-node distances `r_min` grow towards the root: the traversal stops
//! at the first node (from the root) with `e_g/r < ε`, i.e. `r > r_min`,
//! which is the node the interval test picks only if all its ancestors fail,
//! i.e. have larger `r_min`. The errors computed above are with respect to
//! the children's disks and need not be monotone (a parent can fit its
//! children better than a child fits its own). We therefore clamp upward:
//! `e_p ≥ max_i e_p,i`, `e_t ≥ max_i e_t,i` and `e_g ≥ max_i e_g,i`. Then on
//! every leaf-to-root path `0 = r_min(leaf) ≤ r_min(v_1) ≤ … ≤ r_min(root)`,
//! and without the overlap term the intervals `[r_min(v), r_min(parent(v)))`
//! tile `[0, ∞)`: for a constant r exactly one node per path is selected.
//!
//! # Distances and units
//!
//! With the pixel threshold ε, `r_min = e_g/ε` (leaves 0) and `r_max =
//! r_min(parent) + |p − p_parent|` (§10.1.6). The text's ε is an image-space
//! size at unit distance: `e_g/r` is the size the error projects to for a
//! focal length of 1, so ε is dimensionless (approximately radians). For a
//! pinhole camera with vertical field of view θ and H pixel rows one pixel is
//! `2·tan(θ/2)/H` at unit distance; [`epsilon_from_pixels`] converts.
//! Distances (`r_min`, `r_max`, the r passed to the test) are in the units of
//! the surfel positions.
//!
//! The root's `r_max` is "∞"; we store [`ROOT_R_MAX`] = `f32::MAX` instead of
//! `f32::INFINITY` because Vulkan shaders need not preserve infinities unless
//! the device reports `shaderSignedZeroInfNanPreserve`; for every finite r,
//! `r < f32::MAX` as well, so the test is unchanged. All stored values are
//! therefore finite.
//!
//! # The overlap term (derived)
//!
//! Without overlap (`r_max = r_min(parent)`), r varying over the object can
//! leave holes (§10.1.6). With `r_max(c) = r_min(v) + |p_c − p_v|` (v the
//! parent of c) no leaf is left uncovered whenever r is 1-Lipschitz in the
//! position, which the Euclidean eye distance (and the view depth) is: walk
//! down a leaf's path from the root, whose `r_max` exceeds every finite r. At
//! a node v with `r(p_v) < r_max(v)` either `r(p_v) ≥ r_min(v)` (v is
//! selected) or `r(p_v) < r_min(v)`, and then its child c on the path has
//! `r(p_c) ≤ r(p_v) + |p_c − p_v| < r_min(v) + |p_c − p_v| = r_max(c)`, so
//! the argument repeats one level down; it ends at the latest at the leaf,
//! whose `r_min` is 0. The proof uses the stored (f32) positions and parent
//! `r_min`; the sum is rounded upward to f32 so that rounding cannot break
//! it. The price is overdraw: with overlap, a node and some of its
//! descendants can both be selected.
//!
//! # Sequentialisation (§10.1.7)
//!
//! The nodes are sorted by decreasing `r_max`. Nodes of equal `r_max` (all
//! children of one parent without the overlap term, children equally far
//! from their parent with it) are ordered by depth, then by their values
//! (position, normal, diameter, errors, colour): an order that depends
//! neither on ε nor on the order of the build, so that a tree re-derived for
//! another ε ([`SequentialPointTree::with_epsilon`]) is exactly the tree
//! built with it. `r_min` is computed from the error as stored (f32) for the
//! same reason. Nodes equal in all these values are leaves of one parent
//! (coincident duplicates), whose order does not matter.

use glam::{DMat3, DVec3, Vec3};

use super::clip::ClipLines;
use crate::error::{Error, Result};
use crate::points::Surfel;

/// `parent` of the root node.
pub const NO_PARENT: u32 = u32::MAX;

/// `r_max` of the root: stands for ∞ (see the module documentation).
pub const ROOT_R_MAX: f32 = f32::MAX;

/// Number of slab orientations for the tangential error (§10.1.4).
pub const SLAB_DIRECTIONS: usize = 8;

/// Largest accepted [`SptOptions::max_depth`] (bounds the build's recursion).
pub const MAX_DEPTH_LIMIT: u32 = 64;

/// Below this length of the mean child normal the normals are treated as
/// cancelling (see the module documentation).
const NORMAL_CANCEL: f64 = 0.01;

/// One node of a sequential point tree (§10.1.3, §10.1.6): a disk with its
/// errors and the view-distance interval in which it is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SptNode {
    /// Disk centre (mean of the children's centres; the surfel's for leaves).
    pub position: Vec3,
    /// Unit disk normal.
    pub normal: Vec3,
    /// Disk diameter d (world units); the splat's image size is ∝ d / r.
    pub diameter: f32,
    /// sRGB colour (mean of the children's colours, §10.1.9).
    pub color: [u8; 3],
    /// Perpendicular error (world units; 0 for leaves).
    pub e_p: f32,
    /// Tangential error (world units; 0 for leaves).
    pub e_t: f32,
    /// Geometric error, including the colour term of §10.1.9 (world units).
    pub e_g: f32,
    /// Smallest eye distance at which the node is drawn: `e_g / ε` (0 for leaves).
    pub r_min: f32,
    /// Eye distance from which an ancestor is drawn instead:
    /// `r_min(parent) + |p − p_parent|`; [`ROOT_R_MAX`] for the root.
    pub r_max: f32,
    /// Whether the node is an input surfel.
    pub is_leaf: bool,
    /// Index of the parent in [`SequentialPointTree::nodes`]; [`NO_PARENT`] for the root.
    pub parent: u32,
    /// Number of edges to the root (root 0); for level-of-detail debug views.
    pub depth: u32,
    /// Clip lines for sharp features (§10.2.4): a leaf's are its surfel's,
    /// an inner node has [`ClipLines::NONE`].
    pub clip: ClipLines,
}

/// A point hierarchy as a list sorted by decreasing `r_max` (§10.1.7).
#[derive(Clone, Debug, PartialEq)]
pub struct SequentialPointTree {
    /// All nodes, inner and leaves, sorted by decreasing `r_max`.
    pub nodes: Vec<SptNode>,
    /// Centre of a sphere containing every node's disk (hence every node centre).
    pub bounds_centre: Vec3,
    /// Radius of that sphere (world units).
    pub bounds_radius: f32,
    /// The threshold ε the tree was built with (see [`SptOptions::epsilon`]).
    pub epsilon: f32,
}

/// Parameters of [`build_spt`].
#[derive(Clone, Debug, PartialEq)]
pub struct SptOptions {
    /// Error threshold ε as an image-space size at unit distance
    /// (dimensionless, ≈ radians): `r_min = e_g / ε` (§10.1.6). One pixel of a
    /// pinhole camera is [`epsilon_from_pixels`]`(1, fov_y, rows)`. Finite, > 0.
    pub epsilon: f32,
    /// Most surfels an octree cell may hold before it is split (≥ 1; default 1).
    pub leaf_size: usize,
    /// Deepest octree level (≤ `MAX_DEPTH_LIMIT`); cells there are not split
    /// further whatever their count (duplicate points end up there).
    pub max_depth: u32,
    /// Children colour difference (largest per-channel range, 8-bit sRGB code
    /// values) above which a node's error is raised to its diameter (§10.1.9).
    /// ≥ 0; 0 reacts to any difference, ≥ 255 or ∞ disables the colour term.
    pub color_threshold: f32,
    /// Whether `r_max` includes the overlap term `|p − p_parent|` that avoids
    /// holes when r varies over the object (§10.1.6; default true). Without
    /// it a constant r selects exactly one node per leaf-to-root path.
    pub overlap: bool,
}

impl Default for SptOptions {
    /// ε = one pixel of a 60° (vertical) camera with 1080 rows, leaves of one
    /// surfel, depth 32, colour threshold 24 (≈ 9 % of full scale), overlap on.
    fn default() -> Self {
        SptOptions {
            epsilon: 2.0 * (30.0f32).to_radians().tan() / 1080.0,
            leaf_size: 1,
            max_depth: 32,
            color_threshold: 24.0,
            overlap: true,
        }
    }
}

/// The ε of [`SptOptions::epsilon`] for a threshold of `pixels` pixels of a
/// pinhole camera with vertical field of view `fov_y` (radians) and
/// `height_px` pixel rows: `pixels · 2·tan(fov_y/2) / height_px`.
pub fn epsilon_from_pixels(pixels: f32, fov_y: f32, height_px: u32) -> Result<f32> {
    if !(pixels.is_finite() && pixels > 0.0) {
        return Err(Error::invalid(
            "pixel threshold",
            format!("{pixels} is not a positive number"),
        ));
    }
    if !(fov_y.is_finite() && fov_y > 0.0 && fov_y < std::f32::consts::PI) {
        return Err(Error::invalid("field of view", format!("{fov_y} rad is not in (0, π)")));
    }
    if height_px == 0 {
        return Err(Error::invalid("image height", "0 rows"));
    }
    Ok(pixels * 2.0 * (fov_y * 0.5).tan() / height_px as f32)
}

impl SequentialPointTree {
    /// Number of leading nodes with `r_max ≥ r_lo` (binary search, §10.1.7):
    /// with `r_lo` a lower bound of r over the object (e.g.
    /// [`Self::min_eye_distance`]) no node after this prefix can pass the
    /// interval test. A NaN `r_lo` gives the whole list.
    pub fn prefix_len(&self, r_lo: f32) -> usize {
        if r_lo.is_nan() {
            return self.nodes.len();
        }
        self.nodes.partition_point(|n| n.r_max >= r_lo)
    }

    /// Lower bound of the eye distance of every node centre:
    /// `max(0, |eye − bounds_centre| − bounds_radius)`.
    pub fn min_eye_distance(&self, eye: Vec3) -> f32 {
        ((eye - self.bounds_centre).length() - self.bounds_radius).max(0.0)
    }

    /// CPU reference of the vertex-stage test (§10.1.6): the indices of the
    /// nodes with `r_min ≤ r(p) < r_max`, p the node's centre, in list order.
    /// Nodes where `r` is NaN are not selected.
    pub fn select(&self, r: impl Fn(Vec3) -> f32) -> Vec<usize> {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| {
                let d = r(n.position);
                n.r_min <= d && d < n.r_max
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// The same tree for another threshold ε (§10.1.6): `r_min = e_g/ε`
    /// (leaves 0) and `r_max = r_min(parent) + |p − p_parent|` (root
    /// [`ROOT_R_MAX`]) are re-derived from the stored errors and positions,
    /// and the nodes re-sorted by decreasing `r_max` with the build's
    /// tie-breaking, so the result equals [`build_spt`] with that ε. Whether
    /// `r_max` has the overlap term ([`SptOptions::overlap`]) is read off the
    /// tree: some child has `r_max > r_min(parent)` only with it (a tree in
    /// which every child sits at its parent's centre comes out the same either
    /// way).
    ///
    /// Errors (one line): ε not positive and finite; ε so small that a
    /// distance overflows f32; a parent index out of range.
    pub fn with_epsilon(&self, epsilon: f32) -> Result<SequentialPointTree> {
        validate_epsilon(epsilon)?;
        let n = self.nodes.len();
        let mut overlap = false;
        for (i, node) in self.nodes.iter().enumerate() {
            if node.parent == NO_PARENT {
                continue;
            }
            let parent = self.nodes.get(node.parent as usize).ok_or_else(|| {
                Error::invalid(
                    "sequential point tree",
                    format!("node {i}: parent index {} of {n} is out of range", node.parent),
                )
            })?;
            overlap |= node.r_max > parent.r_min;
        }
        let eps = f64::from(epsilon);
        let r_min: Vec<f32> = self
            .nodes
            .iter()
            .map(|node| r_min_of(node.is_leaf, node.e_g, eps).ok_or_else(|| epsilon_overflow(epsilon)))
            .collect::<Result<_>>()?;
        let mut nodes = self.nodes.clone();
        for (i, node) in nodes.iter_mut().enumerate() {
            node.r_min = r_min[i];
            node.r_max = if node.parent == NO_PARENT {
                ROOT_R_MAX
            } else {
                let p = node.parent as usize;
                r_max_of(node.position, self.nodes[p].position, r_min[p], overlap)
            };
            if !node.r_max.is_finite() {
                return Err(epsilon_overflow(epsilon));
            }
        }
        Ok(SequentialPointTree {
            nodes: sequentialise(nodes),
            bounds_centre: self.bounds_centre,
            bounds_radius: self.bounds_radius,
            epsilon,
        })
    }
}

/// Peak host bytes per surfel of [`build_spt`] (besides the surfels
/// themselves), counted from its allocations: the f64 positions and normals
/// (48), the octree's index lists (4, twice while a cell is split), the
/// build nodes, the tree nodes twice while they are sorted, and the sort's
/// order and renumbering (8 + 4 per node), with 1.6 nodes per surfel (the
/// bunny's trees have 1.50–1.55; at most 2). Measured: 565 bytes a surfel
/// of peak resident memory for all of `spt build` (100,000 and 300,000
/// blue-noise samples of the bunny). `crate::points::build::plan`
/// estimates `spt build`'s memory with it.
pub const BUILD_BYTES_PER_SURFEL: u64 =
    (48 + 8 + 8 * (std::mem::size_of::<Work>() + 2 * std::mem::size_of::<SptNode>() + 12) / 5) as u64;

/// A node during the build, in f64 (sums of many positions and squared
/// distances stay exact enough and cannot overflow).
#[derive(Clone, Debug)]
struct Work {
    position: DVec3,
    normal: DVec3,
    /// Disk radius d/2.
    radius: f64,
    color: [u8; 3],
    e_p: f64,
    e_t: f64,
    e_g: f64,
    is_leaf: bool,
    parent: u32,
    clip: ClipLines,
}

struct Builder<'a, 'p> {
    surfels: &'a [Surfel],
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    options: &'a SptOptions,
    /// Nodes in post-order: children before their parent, root last.
    work: Vec<Work>,
    leaves_done: usize,
    last_percent: u32,
    progress: &'a mut (dyn FnMut(f32) + 'p),
}

impl Builder<'_, '_> {
    fn push_leaf(&mut self, i: u32) -> usize {
        let i = i as usize;
        let s = &self.surfels[i];
        self.work.push(Work {
            position: self.positions[i],
            normal: self.normals[i],
            radius: f64::from(s.radius),
            color: s.color,
            e_p: 0.0,
            e_t: 0.0,
            e_g: 0.0,
            is_leaf: true,
            parent: NO_PARENT,
            clip: s.clip,
        });
        self.leaves_done += 1;
        // The octree pass is 90 % of the reported progress.
        let fraction = 0.9 * self.leaves_done as f32 / self.surfels.len() as f32;
        let percent = (fraction * 100.0) as u32;
        if percent > self.last_percent {
            self.last_percent = percent;
            (self.progress)(fraction);
        }
        self.work.len() - 1
    }

    fn push_inner(&mut self, children: &[usize]) -> usize {
        let node = combine(&self.work, children, self.options.color_threshold);
        let index = self.work.len();
        for &c in children {
            self.work[c].parent = index as u32;
        }
        self.work.push(node);
        index
    }

    /// Builds the subtree of the octree cell `[lo, lo + size]³` holding
    /// `indices` (non-empty) and returns its node.
    fn cell(&mut self, indices: Vec<u32>, lo: DVec3, size: f64, depth: u32) -> usize {
        if indices.len() == 1 {
            return self.push_leaf(indices[0]);
        }
        if indices.len() <= self.options.leaf_size || depth >= self.options.max_depth {
            let children: Vec<usize> = indices.iter().map(|&i| self.push_leaf(i)).collect();
            return self.push_inner(&children);
        }
        let half = size * 0.5;
        let mid = lo + DVec3::splat(half);
        let mut octants: [Vec<u32>; 8] = Default::default();
        for &i in &indices {
            let p = self.positions[i as usize];
            let o = usize::from(p.x >= mid.x) | usize::from(p.y >= mid.y) << 1 | usize::from(p.z >= mid.z) << 2;
            octants[o].push(i);
        }
        drop(indices);
        let corner = |o: usize| {
            lo + DVec3::new(
                if o & 1 != 0 { half } else { 0.0 },
                if o & 2 != 0 { half } else { 0.0 },
                if o & 4 != 0 { half } else { 0.0 },
            )
        };
        let occupied = octants.iter().filter(|v| !v.is_empty()).count();
        if occupied == 1 {
            // No node for a one-child cell: descend directly.
            let o = octants.iter().position(|v| !v.is_empty()).unwrap_or(0);
            let only = std::mem::take(&mut octants[o]);
            return self.cell(only, corner(o), half, depth + 1);
        }
        let mut children = Vec::with_capacity(occupied);
        for (o, octant) in octants.iter_mut().enumerate() {
            if !octant.is_empty() {
                let v = std::mem::take(octant);
                children.push(self.cell(v, corner(o), half, depth + 1));
            }
        }
        self.push_inner(&children)
    }
}

/// Half extent, along the unit direction `dir`, of a disk of unit radius with
/// unit normal `normal`: `sqrt(1 − (normal·dir)²)`.
fn disk_extent(normal: DVec3, dir: DVec3) -> f64 {
    let c = normal.dot(dir);
    (1.0 - c * c).max(0.0).sqrt()
}

/// The normal of an inner node: the normalised mean of the children's
/// normals, or, where they cancel, their area-weighted principal axis
/// oriented like the largest child (see the module documentation).
fn node_normal(work: &[Work], children: &[usize], mean: DVec3) -> DVec3 {
    let len = mean.length();
    if len >= NORMAL_CANCEL && len.is_finite() {
        return mean / len;
    }
    // The child with the largest area (first on ties).
    let mut largest = children[0];
    for &c in children {
        if work[c].radius > work[largest].radius {
            largest = c;
        }
    }
    let reference = work[largest].normal;
    let mut m = DMat3::ZERO;
    for &c in children {
        let n = work[c].normal;
        let a = work[c].radius * work[c].radius;
        m += DMat3::from_cols(n * n.x, n * n.y, n * n.z) * a;
    }
    let mut v = reference;
    for _ in 0..64 {
        let next = m * v;
        let l = next.length();
        if !(l.is_finite() && l > 0.0) {
            return reference;
        }
        v = next / l;
    }
    if v.dot(reference) < 0.0 {
        v = -v;
    }
    if v.is_finite() && (v.length() - 1.0).abs() < 1e-6 {
        v
    } else {
        reference
    }
}

/// Disk and errors of the inner node over `children` (at least two), §10.1.4
/// and §10.1.9; see the module documentation for each formula.
fn combine(work: &[Work], children: &[usize], color_threshold: f32) -> Work {
    let k = children.len() as f64;
    let mut position = DVec3::ZERO;
    let mut normal_sum = DVec3::ZERO;
    let mut color_sum = [0u64; 3];
    let mut color_min = [u8::MAX; 3];
    let mut color_max = [u8::MIN; 3];
    let (mut child_e_p, mut child_e_t, mut child_e_g) = (0.0f64, 0.0f64, 0.0f64);
    for &c in children {
        let w = &work[c];
        position += w.position;
        normal_sum += w.normal;
        for ch in 0..3 {
            color_sum[ch] += u64::from(w.color[ch]);
            color_min[ch] = color_min[ch].min(w.color[ch]);
            color_max[ch] = color_max[ch].max(w.color[ch]);
        }
        child_e_p = child_e_p.max(w.e_p);
        child_e_t = child_e_t.max(w.e_t);
        child_e_g = child_e_g.max(w.e_g);
    }
    position /= k;
    let n = node_normal(work, children, normal_sum / k);
    let color = [0, 1, 2].map(|ch| ((color_sum[ch] as f64 / k).round()).clamp(0.0, 255.0) as u8);

    // Bounding disk around p in the node's plane.
    let mut radius = 0.0f64;
    for &c in children {
        let v = work[c].position - position;
        let lateral = (v - v.dot(n) * n).length();
        radius = radius.max(lateral + work[c].radius);
    }
    let diameter = 2.0 * radius;

    // Perpendicular error: the slab along n enclosing the children's disks.
    let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
    for &c in children {
        let w = &work[c];
        let h = (w.position - position).dot(n);
        let a = w.radius * disk_extent(w.normal, n);
        hi = hi.max(h + a);
        lo = lo.min(h - a);
    }
    let mut e_p = (hi - lo).max(0.0);

    // Tangential error: d minus the tightest slab across the plane.
    let (t, b) = n.any_orthonormal_pair();
    let mut tightest = f64::INFINITY;
    for s in 0..SLAB_DIRECTIONS {
        let angle = std::f64::consts::PI * s as f64 / SLAB_DIRECTIONS as f64;
        let u = angle.cos() * t + angle.sin() * b;
        let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
        for &c in children {
            let w = &work[c];
            let h = (w.position - position).dot(u);
            let a = w.radius * disk_extent(w.normal, u);
            hi = hi.max(h + a);
            lo = lo.min(h - a);
        }
        tightest = tightest.min(hi - lo);
    }
    let mut e_t = (diameter - tightest).max(0.0);

    // Monotone up the hierarchy (see "Monotonicity").
    e_p = e_p.max(child_e_p);
    e_t = e_t.max(child_e_t);
    let mut e_g = (e_p * e_p + e_t * e_t).sqrt().max(child_e_g);

    // Colour (§10.1.9).
    let range = (0..3).map(|ch| color_max[ch] - color_min[ch]).max().unwrap_or(0);
    if f32::from(range) > color_threshold {
        e_g = e_g.max(diameter);
    }

    Work {
        position,
        normal: n,
        radius,
        color,
        e_p,
        e_t,
        e_g,
        is_leaf: false,
        parent: NO_PARENT,
        clip: ClipLines::NONE,
    }
}

/// The smallest f32 ≥ `x` (for x ≥ 0 finite; larger values give ∞).
fn f32_round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x && y.is_finite() {
        f32::from_bits(y.to_bits() + 1)
    } else {
        y
    }
}

/// `r_min = e_g/ε` of a node (0 for leaves), `None` when it overflows f32.
fn r_min_of(is_leaf: bool, e_g: f32, epsilon: f64) -> Option<f32> {
    let r_min = if is_leaf {
        0.0
    } else {
        (f64::from(e_g) / epsilon) as f32
    };
    r_min.is_finite().then_some(r_min)
}

/// `r_max` of a non-root node at `position` whose parent is at
/// `parent_position` with `parent_r_min` (§10.1.6): with the overlap term
/// `r_min(parent) + |p − p_parent|`, rounded up to f32 (see "The overlap
/// term"), else `r_min(parent)`.
fn r_max_of(position: Vec3, parent_position: Vec3, parent_r_min: f32, overlap: bool) -> f32 {
    if overlap {
        let distance = (position.as_dvec3() - parent_position.as_dvec3()).length();
        f32_round_up(f64::from(parent_r_min) + distance)
    } else {
        parent_r_min
    }
}

fn epsilon_overflow(epsilon: f32) -> Error {
    Error::invalid(
        "SPT epsilon",
        format!("{epsilon} is too small: r_min = e_g/ε overflows f32"),
    )
}

/// The order among nodes of equal `r_max` (see "Sequentialisation"): by
/// depth, then by the node's values. It depends only on the node itself, not
/// on ε or on the order of the build, so [`SequentialPointTree::with_epsilon`]
/// sorts exactly like [`build_spt`].
fn tie_order(a: &SptNode, b: &SptNode) -> std::cmp::Ordering {
    let floats = |n: &SptNode| {
        [
            n.position.x,
            n.position.y,
            n.position.z,
            n.normal.x,
            n.normal.y,
            n.normal.z,
            n.diameter,
            n.e_p,
            n.e_t,
            n.e_g,
        ]
    };
    a.depth
        .cmp(&b.depth)
        .then(b.is_leaf.cmp(&a.is_leaf))
        .then_with(|| {
            floats(a)
                .iter()
                .zip(floats(b).iter())
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .then(a.color.cmp(&b.color))
}

/// Sorts `nodes` by decreasing `r_max`, ties by [`tie_order`] (§10.1.7), and
/// renumbers the parent indices (which must be in range).
fn sequentialise(nodes: Vec<SptNode>) -> Vec<SptNode> {
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    order.sort_by(|&a, &b| {
        let (a, b) = (&nodes[a], &nodes[b]);
        b.r_max.total_cmp(&a.r_max).then_with(|| tie_order(a, b))
    });
    let mut new_index = vec![0u32; nodes.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    order
        .iter()
        .map(|&old| {
            let mut n = nodes[old];
            if n.parent != NO_PARENT {
                n.parent = new_index[n.parent as usize];
            }
            n
        })
        .collect()
}

fn validate_epsilon(epsilon: f32) -> Result<()> {
    if !(epsilon.is_finite() && epsilon > 0.0) {
        return Err(Error::invalid(
            "SPT epsilon",
            format!("{epsilon} is not a positive finite number"),
        ));
    }
    Ok(())
}

fn validate_options(options: &SptOptions) -> Result<()> {
    validate_epsilon(options.epsilon)?;
    if options.leaf_size == 0 {
        return Err(Error::invalid("SPT leaf size", "must be at least 1"));
    }
    if options.max_depth > MAX_DEPTH_LIMIT {
        return Err(Error::invalid(
            "SPT max depth",
            format!("{} exceeds the limit of {MAX_DEPTH_LIMIT}", options.max_depth),
        ));
    }
    if options.color_threshold.is_nan() || options.color_threshold < 0.0 {
        return Err(Error::invalid(
            "SPT colour threshold",
            format!("{} is not a number ≥ 0", options.color_threshold),
        ));
    }
    Ok(())
}

/// Builds the sequential point tree of `surfels` (§10.1.3–10.1.7, colour
/// §10.1.9); see the module documentation for every formula and decision.
///
/// `progress` is called with increasing fractions in [0, 1], first 0 and
/// last 1.
///
/// Errors (one line): no surfels; a surfel with a non-finite position, a zero
/// or non-finite normal or a radius that is not positive and finite (the
/// message names its index); options out of range; more surfels than the
/// u32 node indices hold; values that overflow f32 (ε too small or
/// coordinates too large).
pub fn build_spt(
    surfels: &[Surfel],
    options: &SptOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<SequentialPointTree> {
    validate_options(options)?;
    if surfels.is_empty() {
        return Err(Error::invalid(
            "surfels",
            "no surfels to build a sequential point tree from",
        ));
    }
    // At most 2n − 1 nodes; indices and NO_PARENT must fit u32.
    if surfels.len() > (u32::MAX / 2) as usize {
        return Err(Error::invalid(
            "surfels",
            format!("{} surfels exceed the limit of {}", surfels.len(), u32::MAX / 2),
        ));
    }
    let (positions, normals) = checked_surfels(surfels)?;
    progress(0.0);

    let (mut lo, mut hi) = (positions[0], positions[0]);
    for p in &positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let extent = (hi - lo).max_element();
    let size = if extent > 0.0 { extent } else { 1.0 };

    let mut builder = Builder {
        surfels,
        positions,
        normals,
        options,
        work: Vec::with_capacity(2 * surfels.len()),
        leaves_done: 0,
        last_percent: 0,
        progress,
    };
    let root = builder.cell((0..surfels.len() as u32).collect(), lo, size, 0);
    let work = builder.work;
    let progress = builder.progress;
    debug_assert_eq!(root, work.len() - 1);

    let nodes = top_down(&work, options)?;

    // Bounding sphere of all node disks (so of all node centres too), a
    // little enlarged to stay conservative after rounding to f32.
    let centre = ((lo + hi) * 0.5).as_vec3();
    let mut radius = 0.0f64;
    for n in &nodes {
        radius = radius.max((n.position.as_dvec3() - centre.as_dvec3()).length() + 0.5 * f64::from(n.diameter));
    }
    let bounds_radius = f32_round_up(radius * (1.0 + 1e-6));
    if !bounds_radius.is_finite() {
        return Err(Error::invalid(
            "surfels",
            "coordinates too large: the bounding sphere overflows f32",
        ));
    }

    let sorted = sequentialise(nodes);
    progress(1.0);

    Ok(SequentialPointTree {
        nodes: sorted,
        bounds_centre: centre,
        bounds_radius,
        epsilon: options.epsilon,
    })
}

/// The surfels' positions and unit normals, after checking that every
/// position is finite, every normal non-zero and every radius positive.
fn checked_surfels(surfels: &[Surfel]) -> Result<(Vec<DVec3>, Vec<DVec3>)> {
    let mut positions = Vec::with_capacity(surfels.len());
    let mut normals = Vec::with_capacity(surfels.len());
    for (i, s) in surfels.iter().enumerate() {
        if !s.position.is_finite() {
            return Err(Error::invalid(format!("surfel {i}"), "position is not finite"));
        }
        let n = s.normal.as_dvec3();
        let len = n.length();
        if !(len.is_finite() && len > 1e-6) {
            return Err(Error::invalid(format!("surfel {i}"), "normal is zero or not finite"));
        }
        if !(s.radius.is_finite() && s.radius > 0.0) {
            return Err(Error::invalid(
                format!("surfel {i}"),
                format!("radius {} is not positive and finite", s.radius),
            ));
        }
        positions.push(s.position.as_dvec3());
        normals.push(n / len);
    }
    Ok((positions, normals))
}

/// The tree's nodes from the built cells, top-down: r_min, r_max and depth
/// (parents follow their children in `work`, so a reverse sweep sees every
/// parent first); an error when a value overflows f32.
fn top_down(work: &[Work], options: &SptOptions) -> Result<Vec<SptNode>> {
    let eps = f64::from(options.epsilon);
    let mut nodes: Vec<SptNode> = Vec::with_capacity(work.len());
    nodes.resize(
        work.len(),
        SptNode {
            position: Vec3::ZERO,
            normal: Vec3::Z,
            diameter: 0.0,
            color: [0; 3],
            e_p: 0.0,
            e_t: 0.0,
            e_g: 0.0,
            r_min: 0.0,
            r_max: 0.0,
            is_leaf: false,
            parent: NO_PARENT,
            depth: 0,
            clip: ClipLines::NONE,
        },
    );
    for i in (0..work.len()).rev() {
        let w = &work[i];
        let position = w.position.as_vec3();
        // From the stored (f32) error, so that [`SequentialPointTree::with_epsilon`]
        // reproduces it exactly.
        let r_min = r_min_of(w.is_leaf, w.e_g as f32, eps).ok_or_else(|| epsilon_overflow(options.epsilon))?;
        let (r_max, depth) = if w.parent == NO_PARENT {
            (ROOT_R_MAX, 0)
        } else {
            let parent = &nodes[w.parent as usize];
            (
                r_max_of(position, parent.position, parent.r_min, options.overlap),
                parent.depth + 1,
            )
        };
        let node = SptNode {
            position,
            normal: w.normal.as_vec3().normalize_or(Vec3::Z),
            diameter: (2.0 * w.radius) as f32,
            color: w.color,
            e_p: w.e_p as f32,
            e_t: w.e_t as f32,
            e_g: w.e_g as f32,
            r_min,
            r_max,
            is_leaf: w.is_leaf,
            parent: w.parent,
            depth,
            clip: w.clip,
        };
        let finite = node.position.is_finite()
            && node.diameter.is_finite()
            && node.e_p.is_finite()
            && node.e_t.is_finite()
            && node.e_g.is_finite()
            && node.r_max.is_finite();
        if !finite {
            return Err(Error::invalid(
                "surfels",
                "coordinates too large: the tree's values overflow f32",
            ));
        }
        nodes[i] = node;
    }

    Ok(nodes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Test inputs from the project's generator.
    struct Rng(crate::random::SplitMix64);

    impl Rng {
        fn new(seed: u64) -> Rng {
            Rng(crate::random::SplitMix64(seed))
        }
        /// Uniform in [0, 1).
        fn f(&mut self) -> f32 {
            (self.0.next_u64() >> 40) as f32 / (1u64 << 24) as f32
        }
        fn color(&mut self) -> [u8; 3] {
            let v = self.0.next_u64();
            [v as u8, (v >> 8) as u8, (v >> 16) as u8]
        }
    }

    fn sphere(count: usize, seed: u64) -> Vec<Surfel> {
        let mut rng = Rng::new(seed);
        let radius = 2.0 * (4.0 * std::f32::consts::PI / count as f32).sqrt();
        (0..count)
            .map(|_| {
                let z = 2.0 * rng.f() - 1.0;
                let phi = 2.0 * std::f32::consts::PI * rng.f();
                let s = (1.0 - z * z).max(0.0).sqrt();
                let n = Vec3::new(s * phi.cos(), s * phi.sin(), z);
                Surfel {
                    position: n * 3.0 + Vec3::new(1.0, -2.0, 0.5),
                    normal: n,
                    radius: radius * 3.0,
                    color: rng.color(),
                    clip: ClipLines::NONE,
                }
            })
            .collect()
    }

    fn plane(count: usize, seed: u64) -> Vec<Surfel> {
        let mut rng = Rng::new(seed);
        (0..count)
            .map(|_| Surfel {
                position: Vec3::new(10.0 * rng.f(), 10.0 * rng.f(), 0.0),
                normal: Vec3::Z,
                radius: 0.3,
                color: [200, 180, (rng.f() * 8.0) as u8],
                clip: ClipLines::NONE,
            })
            .collect()
    }

    fn build(surfels: &[Surfel], options: &SptOptions) -> SequentialPointTree {
        build_spt(surfels, options, &mut |_| {}).unwrap()
    }

    fn path(tree: &SequentialPointTree, leaf: usize) -> Vec<usize> {
        let mut v = vec![leaf];
        let mut i = leaf;
        while tree.nodes[i].parent != NO_PARENT {
            i = tree.nodes[i].parent as usize;
            v.push(i);
            assert!(v.len() <= tree.nodes.len(), "cycle in parents");
        }
        v
    }

    fn leaves(tree: &SequentialPointTree) -> Vec<usize> {
        (0..tree.nodes.len()).filter(|&i| tree.nodes[i].is_leaf).collect()
    }

    fn check_structure(tree: &SequentialPointTree, surfels: &[Surfel]) {
        let n = &tree.nodes;
        assert_eq!(leaves(tree).len(), surfels.len());
        assert_eq!(n.iter().filter(|x| x.parent == NO_PARENT).count(), 1);
        let mut child_count = vec![0usize; n.len()];
        for (i, node) in n.iter().enumerate() {
            assert!(node.position.is_finite() && node.normal.is_finite());
            assert!(
                (node.normal.length() - 1.0).abs() < 1e-4,
                "node {i} normal {:?}",
                node.normal
            );
            assert!(node.diameter > 0.0);
            assert!(node.e_p >= 0.0 && node.e_t >= 0.0 && node.e_g >= 0.0);
            if node.is_leaf {
                assert_eq!(node.r_min, 0.0);
                assert_eq!(node.e_g, 0.0);
            }
            if node.parent == NO_PARENT {
                assert_eq!(node.r_max, ROOT_R_MAX);
                assert_eq!(node.depth, 0);
            } else {
                let p = &n[node.parent as usize];
                child_count[node.parent as usize] += 1;
                assert!(!p.is_leaf);
                assert_eq!(node.depth, p.depth + 1);
                assert!(node.e_g <= p.e_g, "monotone e_g");
                assert!(node.e_p <= p.e_p && node.e_t <= p.e_t, "monotone e_p, e_t");
                assert!(node.diameter <= p.diameter * (1.0 + 1e-6), "monotone d");
                assert!(node.r_min <= p.r_min);
                assert!(node.r_min <= node.r_max, "nesting");
            }
            assert!((node.r_min - node.e_g / tree.epsilon).abs() <= 1e-5 * node.r_min.max(1.0) || node.is_leaf);
        }
        for (i, node) in n.iter().enumerate() {
            if !node.is_leaf {
                assert!(child_count[i] >= 2, "inner node {i} has {} children", child_count[i]);
            }
        }
        // Leaves are the input surfels.
        let mut a: Vec<[u32; 3]> = surfels
            .iter()
            .map(|s| s.position.to_array().map(f32::to_bits))
            .collect();
        let mut b: Vec<[u32; 3]> = leaves(tree)
            .iter()
            .map(|&i| n[i].position.to_array().map(f32::to_bits))
            .collect();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
    }

    fn inputs() -> Vec<(&'static str, Vec<Surfel>)> {
        vec![("sphere", sphere(1500, 1)), ("plane", plane(1500, 2))]
    }

    /// Eye distances spanning the whole tree: from 0 through the range of r_min.
    fn constant_rs(tree: &SequentialPointTree) -> Vec<f32> {
        let top = tree.nodes.iter().map(|n| n.r_min).fold(0.0f32, f32::max);
        let mut rs = vec![0.0, 1e-3];
        for k in 0..=12 {
            rs.push(top * k as f32 / 10.0);
        }
        rs.push(top * 100.0);
        rs
    }

    #[test]
    fn structure_and_sorting() {
        for (name, surfels) in inputs() {
            for leaf_size in [1, 4] {
                let options = SptOptions {
                    leaf_size,
                    ..SptOptions::default()
                };
                let tree = build(&surfels, &options);
                check_structure(&tree, &surfels);
                // (d) sorted by decreasing r_max.
                assert!(tree.nodes.windows(2).all(|w| w[0].r_max >= w[1].r_max), "{name}");
                assert_eq!(tree.nodes[0].parent, NO_PARENT, "{name}: the root comes first");
            }
        }
    }

    #[test]
    fn constant_r_selects_exactly_one_per_path_without_overlap() {
        for (name, surfels) in inputs() {
            let options = SptOptions {
                overlap: false,
                ..SptOptions::default()
            };
            let tree = build(&surfels, &options);
            let rs = constant_rs(&tree);
            let mut distinct_cuts = std::collections::BTreeSet::new();
            for &r in &rs {
                let mut selected = vec![false; tree.nodes.len()];
                for i in tree.select(|_| r) {
                    selected[i] = true;
                }
                distinct_cuts.insert(selected.iter().filter(|&&s| s).count());
                for leaf in leaves(&tree) {
                    let count = path(&tree, leaf).iter().filter(|&&i| selected[i]).count();
                    assert_eq!(count, 1, "{name}: r = {r}, leaf {leaf}");
                }
            }
            assert!(
                distinct_cuts.len() >= 4,
                "{name}: the r values should give different cuts"
            );
        }
    }

    #[test]
    fn constant_r_with_overlap_covers_every_path() {
        for (name, surfels) in inputs() {
            let tree = build(&surfels, &SptOptions::default());
            for r in constant_rs(&tree) {
                let mut selected = vec![false; tree.nodes.len()];
                for i in tree.select(|_| r) {
                    selected[i] = true;
                }
                for leaf in leaves(&tree) {
                    let count = path(&tree, leaf).iter().filter(|&&i| selected[i]).count();
                    assert!(count >= 1, "{name}: r = {r}, leaf {leaf}");
                }
            }
        }
    }

    fn eyes(tree: &SequentialPointTree) -> Vec<Vec3> {
        let c = tree.bounds_centre;
        let far = tree.nodes.iter().map(|n| n.r_min).fold(0.0f32, f32::max);
        vec![
            c,
            c + Vec3::new(0.3, 0.2, 0.1),
            c + Vec3::new(tree.bounds_radius * 1.5, 0.0, 1.0),
            c + Vec3::new(0.0, 4.0, 2.0),
            c + Vec3::new(far * 0.3, -far * 0.2, far * 0.1),
            c + Vec3::new(far * 0.8, far * 0.1, 0.0),
            c + Vec3::new(-far * 2.0, 0.0, far),
        ]
    }

    #[test]
    fn varying_r_leaves_no_holes() {
        for (name, surfels) in inputs() {
            for epsilon in [1e-3, 1e-2, 0.1] {
                let options = SptOptions {
                    epsilon,
                    ..SptOptions::default()
                };
                let tree = build(&surfels, &options);
                for eye in eyes(&tree) {
                    let mut selected = vec![false; tree.nodes.len()];
                    let chosen = tree.select(|p| (p - eye).length());
                    for &i in &chosen {
                        selected[i] = true;
                    }
                    for leaf in leaves(&tree) {
                        assert!(
                            path(&tree, leaf).iter().any(|&i| selected[i]),
                            "{name}: hole at leaf {leaf}, eye {eye}, ε {epsilon}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn varying_r_without_overlap_can_leave_holes_that_overlap_fills() {
        // Why the overlap term exists (§10.1.6): find a configuration where
        // the plain intervals leave a hole; the default tree has none (above).
        let surfels = plane(1500, 2);
        let tree = build(
            &surfels,
            &SptOptions {
                overlap: false,
                epsilon: 1e-2,
                ..SptOptions::default()
            },
        );
        let mut holes = 0;
        for eye in eyes(&tree) {
            let mut selected = vec![false; tree.nodes.len()];
            for i in tree.select(|p| (p - eye).length()) {
                selected[i] = true;
            }
            holes += leaves(&tree)
                .iter()
                .filter(|&&l| !path(&tree, l).iter().any(|&i| selected[i]))
                .count();
        }
        assert!(holes > 0, "expected holes without the overlap term");
    }

    #[test]
    fn prefix_contains_every_selected_node() {
        for (name, surfels) in inputs() {
            let tree = build(&surfels, &SptOptions::default());
            for eye in eyes(&tree) {
                let r = |p: Vec3| (p - eye).length();
                let selected = tree.select(r);
                let r_lo_exact = tree.nodes.iter().map(|n| r(n.position)).fold(f32::INFINITY, f32::min);
                let r_lo_bound = tree.min_eye_distance(eye);
                assert!(r_lo_bound <= r_lo_exact);
                let exact = tree.prefix_len(r_lo_exact);
                let bound = tree.prefix_len(r_lo_bound);
                assert!(bound >= exact);
                for &i in &selected {
                    assert!(i < exact, "{name}: node {i} selected beyond the prefix {exact}");
                }
                // The prefix is exactly the nodes with r_max ≥ r_lo.
                assert!(tree.nodes[..exact].iter().all(|n| n.r_max >= r_lo_exact));
                assert!(tree.nodes[exact..].iter().all(|n| n.r_max < r_lo_exact));
            }
            assert_eq!(tree.prefix_len(0.0), tree.nodes.len());
            assert_eq!(tree.prefix_len(f32::NAN), tree.nodes.len());
            assert_eq!(tree.prefix_len(f32::INFINITY), 0);
            assert_eq!(tree.prefix_len(f32::MAX), 1, "{name}: only the root reaches ∞");
        }
    }

    fn disk(x: f32, color: [u8; 3]) -> Surfel {
        Surfel {
            position: Vec3::new(x, 0.0, 0.0),
            normal: Vec3::Z,
            radius: 0.5,
            color,
            clip: ClipLines::NONE,
        }
    }

    fn root(tree: &SequentialPointTree) -> SptNode {
        tree.nodes[0]
    }

    #[test]
    fn two_disks_side_by_side() {
        // Two coplanar unit-diameter disks 1 apart: d = 2, e_p = 0, the
        // tightest slab (across the pair) is 1 wide, e_t = 1, e_g = 1.
        let tree = build(&[disk(0.0, [10; 3]), disk(1.0, [10; 3])], &SptOptions::default());
        let r = root(&tree);
        assert!(!r.is_leaf);
        assert_eq!(tree.nodes.len(), 3);
        assert!((r.position - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
        assert!((r.normal - Vec3::Z).length() < 1e-6);
        assert!((r.diameter - 2.0).abs() < 1e-5, "{}", r.diameter);
        assert!(r.e_p.abs() < 1e-6);
        assert!((r.e_t - 1.0).abs() < 1e-5, "{}", r.e_t);
        assert!((r.e_g - 1.0).abs() < 1e-5);
        assert!(r.e_g < r.diameter);
        assert!((r.r_min - 1.0 / tree.epsilon).abs() < 1e-2 * r.r_min);
        for c in &tree.nodes[1..] {
            assert!((c.r_max - (r.r_min + 0.5)).abs() <= 1e-3);
        }
    }

    #[test]
    fn color_difference_raises_error_to_diameter() {
        // §10.1.9: different colours raise e_g to d.
        let options = SptOptions::default();
        let tree = build(&[disk(0.0, [200, 20, 20]), disk(1.0, [20, 20, 200])], &options);
        let r = root(&tree);
        assert!(r.e_g >= r.diameter, "e_g {} < d {}", r.e_g, r.diameter);
        assert_eq!(r.color, [110, 20, 110]);
        // Below the threshold nothing changes.
        let tree = build(&[disk(0.0, [100; 3]), disk(1.0, [110; 3])], &options);
        assert!(root(&tree).e_g < root(&tree).diameter);
        // Threshold 0 reacts to that small difference.
        let zero = SptOptions {
            color_threshold: 0.0,
            ..options
        };
        let tree = build(&[disk(0.0, [100; 3]), disk(1.0, [110; 3])], &zero);
        assert!(root(&tree).e_g >= root(&tree).diameter);
        // The raised error propagates up (monotone).
        let surfels = [
            disk(0.0, [255, 0, 0]),
            disk(1.0, [0, 0, 255]),
            disk(10.0, [0; 3]),
            disk(11.0, [0; 3]),
        ];
        let tree = build(&surfels, &SptOptions::default());
        check_structure(&tree, &surfels);
        let coloured = tree
            .nodes
            .iter()
            .find(|n| !n.is_leaf && n.parent != NO_PARENT && n.color == [128, 0, 128])
            .copied()
            .unwrap();
        assert!(coloured.e_g >= coloured.diameter);
        assert!(root(&tree).e_g >= coloured.e_g);
    }

    #[test]
    fn perpendicular_error_of_stacked_and_tilted_disks() {
        // Two parallel disks 1 apart along their normal, leaf_size 2: e_p = 1.
        let a = disk(0.0, [0; 3]);
        let b = Surfel {
            position: Vec3::new(0.0, 0.0, 1.0),
            ..a
        };
        let options = SptOptions {
            leaf_size: 2,
            ..SptOptions::default()
        };
        let r = root(&build(&[a, b], &options));
        assert!((r.e_p - 1.0).abs() < 1e-5, "{}", r.e_p);
        assert!((r.diameter - 1.0).abs() < 1e-5);
        assert!(r.e_t.abs() < 1e-5);
        // Disks seen edge-on (normals ±X, node normal Z) add their radius
        // on both sides of the slab: e_p = 2 · 0.5.
        let edge_on = |x: f32, y: f32, normal: Vec3| Surfel {
            position: Vec3::new(x, y, 0.0),
            normal,
            ..a
        };
        let four = [
            edge_on(0.0, 0.0, Vec3::X),
            edge_on(2.0, 0.0, -Vec3::X),
            edge_on(0.0, 2.0, Vec3::Z),
            edge_on(2.0, 2.0, Vec3::Z),
        ];
        let options = SptOptions {
            leaf_size: 4,
            ..SptOptions::default()
        };
        let r = root(&build(&four, &options));
        assert!((r.normal - Vec3::Z).length() < 1e-6);
        assert!((r.e_p - 1.0).abs() < 1e-5, "{}", r.e_p);
        assert!((r.diameter - (2.0 * 2f32.sqrt() + 1.0)).abs() < 1e-5, "{}", r.diameter);
    }

    /// Points on the rim of a surfel's disk.
    fn rim(s: &Surfel, count: usize) -> Vec<Vec3> {
        let (t, b) = s.normal.normalize().any_orthonormal_pair();
        (0..count)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / count as f32;
                s.position + s.radius * (a.cos() * t + a.sin() * b)
            })
            .collect()
    }

    #[test]
    fn errors_match_brute_force_on_disk_rims() {
        // One inner node over a few random disks: the closed forms for d,
        // e_p and e_t against densely sampled disk rims.
        let mut rng = Rng::new(7);
        for _ in 0..20 {
            let count = 2 + (rng.0.next_u64() % 5) as usize;
            let surfels: Vec<Surfel> = (0..count)
                .map(|_| Surfel {
                    position: Vec3::new(rng.f(), rng.f(), rng.f() * 0.3) * 4.0,
                    normal: Vec3::new(rng.f() - 0.5, rng.f() - 0.5, 1.0).normalize(),
                    radius: 0.2 + rng.f(),
                    color: [50; 3],
                    clip: ClipLines::NONE,
                })
                .collect();
            let options = SptOptions {
                leaf_size: 8,
                ..SptOptions::default()
            };
            let tree = build(&surfels, &options);
            assert_eq!(tree.nodes.len(), count + 1);
            let r = root(&tree);
            let points: Vec<Vec3> = surfels.iter().flat_map(|s| rim(s, 2000)).collect();
            let n = r.normal;
            let (lo, hi) = points.iter().fold((f32::MAX, f32::MIN), |(lo, hi), q| {
                let h = (*q - r.position).dot(n);
                (lo.min(h), hi.max(h))
            });
            assert!(
                (r.e_p - (hi - lo)).abs() < 1e-3 * r.diameter,
                "e_p {} vs {}",
                r.e_p,
                hi - lo
            );
            let lateral = points
                .iter()
                .map(|q| {
                    let v = *q - r.position;
                    (v - v.dot(n) * n).length()
                })
                .fold(0.0f32, f32::max);
            assert!(
                lateral <= 0.5 * r.diameter * (1.0 + 1e-5),
                "disk does not bound the children"
            );
            let (t, b) = n.any_orthonormal_pair();
            let tightest = (0..SLAB_DIRECTIONS)
                .map(|k| {
                    let a = std::f32::consts::PI * k as f32 / SLAB_DIRECTIONS as f32;
                    let u = a.cos() * t + a.sin() * b;
                    let (lo, hi) = points.iter().fold((f32::MAX, f32::MIN), |(lo, hi), q| {
                        let h = (*q - r.position).dot(u);
                        (lo.min(h), hi.max(h))
                    });
                    hi - lo
                })
                .fold(f32::MAX, f32::min);
            let e_t = (r.diameter - tightest).max(0.0);
            assert!((r.e_t - e_t).abs() < 1e-3 * r.diameter, "e_t {} vs {}", r.e_t, e_t);
            assert!((r.e_g - r.e_p.hypot(r.e_t)).abs() < 1e-5 * r.diameter);
        }
    }

    #[test]
    fn cancelling_normals_fall_back_to_largest_child() {
        let a = Surfel {
            radius: 0.4,
            ..disk(0.0, [0; 3])
        };
        let b = Surfel {
            normal: -Vec3::Z,
            radius: 0.6,
            ..a
        };
        let options = SptOptions {
            leaf_size: 2,
            ..SptOptions::default()
        };
        let r = root(&build(&[a, b], &options));
        assert!((r.normal + Vec3::Z).length() < 1e-5, "{:?}", r.normal);
        assert!(r.e_p.abs() < 1e-5);
        // Coincident duplicates beyond max_depth end in one inner node.
        let many = vec![a; 5];
        let tree = build(&many, &SptOptions::default());
        assert_eq!(tree.nodes.len(), 6);
        check_structure(&tree, &many);
    }

    #[test]
    fn progress_is_monotone_from_zero_to_one() {
        let surfels = sphere(2000, 3);
        let mut seen = Vec::new();
        build_spt(&surfels, &SptOptions::default(), &mut |f| seen.push(f)).unwrap();
        assert_eq!(seen.first(), Some(&0.0));
        assert_eq!(seen.last(), Some(&1.0));
        assert!(seen.windows(2).all(|w| w[0] <= w[1]));
        assert!(seen.len() > 10 && seen.len() < 200, "{}", seen.len());
    }

    #[test]
    fn single_surfel_is_a_root_leaf() {
        let tree = build(&[disk(1.0, [1, 2, 3])], &SptOptions::default());
        assert_eq!(tree.nodes.len(), 1);
        let r = root(&tree);
        assert!(r.is_leaf);
        assert_eq!((r.r_min, r.r_max, r.parent), (0.0, ROOT_R_MAX, NO_PARENT));
        assert_eq!(tree.select(|_| 1e30), vec![0]);
        assert!((tree.bounds_radius - 0.5).abs() < 1e-5);
    }

    /// A way to spoil a surfel and the word the error must contain.
    type SurfelCase = (fn(&mut Surfel), &'static str);

    #[test]
    fn bad_input_is_an_error() {
        let mut nop = |_: f32| {};
        let o = SptOptions::default();
        let err = build_spt(&[], &o, &mut nop).unwrap_err().to_string();
        assert!(err.contains("no surfels"), "{err}");
        let good = disk(0.0, [0; 3]);
        let surfel_cases: [SurfelCase; 7] = [
            (|s| s.position.x = f32::NAN, "position"),
            (|s| s.position.y = f32::INFINITY, "position"),
            (|s| s.normal = Vec3::ZERO, "normal"),
            (|s| s.normal.y = f32::NAN, "normal"),
            (|s| s.radius = 0.0, "radius"),
            (|s| s.radius = f32::INFINITY, "radius"),
            (|s| s.radius = f32::NAN, "radius"),
        ];
        for (spoil, what) in surfel_cases {
            let mut bad = good;
            spoil(&mut bad);
            let err = build_spt(&[good, bad], &o, &mut nop).unwrap_err().to_string();
            assert!(err.contains("surfel 1") && err.contains(what), "{err}");
            assert!(!err.contains('\n'));
        }
        let option_cases: [fn(&mut SptOptions); 7] = [
            |o| o.epsilon = 0.0,
            |o| o.epsilon = f32::NAN,
            |o| o.epsilon = f32::INFINITY,
            |o| o.leaf_size = 0,
            |o| o.max_depth = MAX_DEPTH_LIMIT + 1,
            |o| o.color_threshold = f32::NAN,
            |o| o.color_threshold = -1.0,
        ];
        for spoil in option_cases {
            let mut options = o.clone();
            spoil(&mut options);
            let err = build_spt(&[good], &options, &mut nop).unwrap_err().to_string();
            assert!(err.contains("SPT"), "{err}");
        }
        // ε so small that r_min overflows; coordinates so large that f32 does.
        let tiny = SptOptions {
            epsilon: f32::from_bits(1),
            ..o.clone()
        };
        let err = build_spt(&[good, disk(1.0, [0; 3])], &tiny, &mut nop)
            .unwrap_err()
            .to_string();
        assert!(err.contains("epsilon"), "{err}");
        let huge = [disk(-3e38, [0; 3]), disk(3e38, [0; 3])];
        let err = build_spt(&huge, &o, &mut nop).unwrap_err().to_string();
        assert!(err.contains("overflow"), "{err}");
    }

    /// Relative comparison for re-derived distances.
    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) || a == b
    }

    #[test]
    fn with_epsilon_equals_a_build_with_that_epsilon() {
        for (name, surfels) in inputs() {
            for overlap in [true, false] {
                for leaf_size in [1, 4] {
                    let options = |epsilon: f32| SptOptions {
                        epsilon,
                        overlap,
                        leaf_size,
                        ..SptOptions::default()
                    };
                    for (e1, e2) in [(1e-3, 1e-2), (0.05, 2e-4), (1e-3, 1e-3)] {
                        let direct = build(&surfels, &options(e2));
                        let derived = build(&surfels, &options(e1)).with_epsilon(e2).unwrap();
                        assert_eq!(derived.epsilon, e2);
                        assert_eq!(derived.nodes.len(), direct.nodes.len());
                        check_structure(&derived, &surfels);
                        assert!(derived.nodes.windows(2).all(|w| w[0].r_max >= w[1].r_max));
                        // The same multiset of nodes (parents by position),
                        // distances within rounding …
                        let key = |t: &SequentialPointTree, i: usize| {
                            let n = &t.nodes[i];
                            let parent = (n.parent != NO_PARENT)
                                .then(|| t.nodes[n.parent as usize].position.to_array().map(f32::to_bits));
                            (n.depth, n.position.to_array().map(f32::to_bits), parent, i)
                        };
                        let mut a: Vec<_> = (0..direct.nodes.len()).map(|i| key(&direct, i)).collect();
                        let mut b: Vec<_> = (0..derived.nodes.len()).map(|i| key(&derived, i)).collect();
                        a.sort_unstable();
                        b.sort_unstable();
                        for (ka, kb) in a.iter().zip(&b) {
                            assert_eq!((ka.0, ka.1, ka.2), (kb.0, kb.1, kb.2), "{name}");
                            let (x, y) = (&direct.nodes[ka.3], &derived.nodes[kb.3]);
                            assert!(
                                close(x.r_min, y.r_min) && close(x.r_max, y.r_max),
                                "{name}: {x:?} {y:?}"
                            );
                            assert_eq!((x.e_g, x.diameter, x.is_leaf), (y.e_g, y.diameter, y.is_leaf));
                        }
                        // … and in fact the identical list.
                        assert_eq!(derived, direct, "{name} overlap {overlap} leaf {leaf_size} {e1}→{e2}");
                    }
                }
            }
        }
        // A tree loaded from elsewhere: leaves keep their clip lines.
        let mut surfels = plane(200, 9);
        let line = crate::points::build::clip::ClipLine {
            angle: 1.0,
            offset: 0.1,
        };
        surfels[17].clip = ClipLines([Some(line), None]);
        let tree = build(&surfels, &SptOptions::default());
        let derived = tree.with_epsilon(0.1).unwrap();
        let clipped: Vec<_> = derived.nodes.iter().filter(|n| n.clip != ClipLines::NONE).collect();
        assert_eq!(clipped.len(), 1);
        assert!(clipped[0].is_leaf && clipped[0].position == surfels[17].position);
    }

    #[test]
    fn with_epsilon_rejects_bad_epsilon() {
        let tree = build(&plane(100, 3), &SptOptions::default());
        for bad in [0.0, -1e-3, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let err = tree.with_epsilon(bad).unwrap_err().to_string();
            assert!(err.contains("epsilon"), "{err}");
        }
        let err = tree.with_epsilon(f32::from_bits(1)).unwrap_err().to_string();
        assert!(err.contains("overflows") && !err.contains('\n'), "{err}");
        let mut broken = tree.clone();
        broken.nodes[5].parent = 1_000_000;
        let err = broken.with_epsilon(0.01).unwrap_err().to_string();
        assert!(err.contains("node 5") && err.contains("out of range"), "{err}");
    }

    #[test]
    fn epsilon_conversion() {
        let e = epsilon_from_pixels(1.0, 60f32.to_radians(), 1080).unwrap();
        assert!((e - SptOptions::default().epsilon).abs() < 1e-9);
        assert!(epsilon_from_pixels(0.0, 1.0, 10).is_err());
        assert!(epsilon_from_pixels(1.0, 4.0, 10).is_err());
        assert!(epsilon_from_pixels(1.0, 1.0, 0).is_err());
    }
}
