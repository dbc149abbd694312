//! Mesh → surfels: even, area-weighted surface samples, the input of the
//! sequential point tree build (dissertation §10.1; `ALGORITHMS.md` §7,
//! "uniform surface samples → octree").
//!
//! Two methods ([`SamplingMethod`]):
//!
//! * **Stratified.** The samples are spread over the triangles by systematic
//!   sampling of the cumulative area: with one random offset `u ∈ [0, 1)`,
//!   sample `i` falls at area `(i + u)·A/N` along the triangles in file
//!   order. Every triangle thus gets the floor or the ceiling of its expected
//!   share `N·aⱼ/A`, and the total is exactly N. Inside a triangle its `nⱼ`
//!   points are the first `nⱼ` points of the R2 rank-1 lattice (Roberts'
//!   plastic-number sequence, low discrepancy for every n) under a random
//!   per-triangle Cranley–Patterson shift, mapped to the triangle by Heitz's
//!   2019 low-distortion square → triangle map, which is area preserving and
//!   piecewise linear, so the spacing of the lattice survives. Samples of
//!   neighbouring triangles do not know about each other and can lie close
//!   together across a shared edge.
//! * **Blue noise.** [`BLUE_NOISE_CANDIDATES`]·N stratified candidates are
//!   thinned to N by Yuksel's weighted sample elimination (2015): each
//!   candidate is weighted by its neighbours within `2·r_max`,
//!   `w = (1 − d̂/(2·r_max))^8` with `d̂ = clamp(d, 2·r_min, 2·r_max)`,
//!   `r_max = sqrt(A/(2√3·N))` (densest packing of N disks on area A) and
//!   `r_min = r_max·(1 − (N/M)^1.5)·0.65`; the heaviest is removed and its
//!   neighbours' weights lowered, until N remain. Distances are Euclidean;
//!   candidates whose normals differ by more than 120° do not interact, so
//!   both sides of a thin sheet (a leaf, a wall) keep their samples.
//!   Neighbours come from the kd-tree of [`super::estimate`], weights are
//!   kept in an indexed max-heap; 35k output samples take about 0.6 s in a
//!   release build, stratified sampling about 1 ms.
//!
//! Attributes: the normal is the barycentric interpolation of the vertex
//! normals when the mesh has them (taken as given, whatever their relation to
//! the winding), else the face normal `(b − a) × (c − a)`, outward for
//! counter-clockwise triangles; the colour is the interpolated vertex colour,
//! else mid grey.
//!
//! Radius: all surfels of one call get `sqrt(A/(π·N)) · overlap`. At
//! `sqrt(A/(π·N))` the N disks have exactly the area of the surface; a
//! hexagonal arrangement needs an overlap of 1.1 to leave no holes, and these
//! samples are less regular, so the overlap is the largest hole measured
//! (distance from a surface point to the nearest sample over
//! `sqrt(A/(π·N))`, 20–40 seeds, N = 200–8000, a 2-triangle and an
//! 800-triangle unit square) plus a margin, per method
//! ([`SamplingMethod::radius_overlap`]):
//!
//! * stratified: holes up to 2.46 inside the surface → **2.75**. At acute
//!   corners of open boundaries (the 45° corners of a 2-triangle square)
//!   holes reach 3.6, since samples of neighbouring triangles are
//!   independent; closed meshes have no such corners.
//! * blue noise: holes up to 2.26 (2.49 once, on an open boundary) →
//!   **2.4**. Elimination keeps boundary samples (they have fewer
//!   neighbours), so open boundaries are covered too.
//!
//! An overlap of 1.5 leaves holes with both methods (largest gaps above).
//!
//! Clip lines (§10.2.4): a surfel within its radius of a crease of the mesh
//! (an edge whose two triangles' normals differ by more than 30°) is clipped
//! along it, at most twice; see [`super::clip`] for the rules.
//!
//! Degenerate (zero-area) triangles are skipped. Sampling is deterministic
//! for a given seed.

use std::cmp::Ordering;

use glam::Vec3;

use super::clip::{ClipLines, Creases};
use super::estimate::KdTree;
use crate::error::{Error, Result};
use crate::points::{Surfel, TriangleMesh};
use crate::random::SplitMix64;

/// Disk radius factor over `sqrt(A/(π·N))` for [`SamplingMethod::Stratified`]
/// (module docs).
pub const STRATIFIED_RADIUS_OVERLAP: f32 = 2.75;
/// Disk radius factor over `sqrt(A/(π·N))` for [`SamplingMethod::BlueNoise`]
/// (module docs).
pub const BLUE_NOISE_RADIUS_OVERLAP: f32 = 2.4;
/// Candidates per output sample for [`SamplingMethod::BlueNoise`] (Yuksel
/// recommends about 5).
pub const BLUE_NOISE_CANDIDATES: usize = 5;
/// Colour of samples on meshes without vertex colours (mid grey, sRGB).
pub const DEFAULT_COLOR: [u8; 3] = [128, 128, 128];

/// How samples are placed on the surface (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplingMethod {
    /// Systematic area allocation, low-discrepancy points per triangle.
    Stratified,
    /// Weighted sample elimination of 5× stratified candidates (Poisson
    /// disk). The default: evener, so smaller disks cover the surface.
    #[default]
    BlueNoise,
}

impl SamplingMethod {
    /// The disk radius over `sqrt(A/(π·N))` that covers the surface without
    /// holes for this method (module docs).
    pub const fn radius_overlap(self) -> f32 {
        match self {
            SamplingMethod::Stratified => STRATIFIED_RADIUS_OVERLAP,
            SamplingMethod::BlueNoise => BLUE_NOISE_RADIUS_OVERLAP,
        }
    }
}

/// Parameters of [`sample_mesh`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplingOptions {
    /// Number of surfels to produce (> 0), exactly.
    pub count: usize,
    pub method: SamplingMethod,
    /// Seed of the (deterministic) random choices.
    pub seed: u64,
}

/// Host memory sampling `count` surfels with `method` needs at its peak
/// ([`crate::budget`]): `count` × [`bytes_per_sample`] (about 550 B a
/// surfel for blue noise, which holds [`BLUE_NOISE_CANDIDATES`] candidates a
/// surfel). The point tree built from the surfels is counted by
/// `crate::points::build::plan`.
pub fn sampling_footprint(count: usize, method: SamplingMethod) -> crate::budget::Footprint {
    crate::budget::Footprint::per_item(count as u64, bytes_per_sample(method), 0)
}

/// Samples `options.count` surfels evenly (area-weighted) over the mesh
/// (§10.1; method, attributes and radius in the module docs), with clip
/// lines along the mesh's creases (§10.2.4, [`super::clip`]).
///
/// Errors when the count is 0, an index is out of range, vertex normals or
/// colours do not match the vertex count, a used vertex is not finite, or the
/// mesh has no area.
pub fn sample_mesh(mesh: &TriangleMesh, options: &SamplingOptions) -> Result<Vec<Surfel>> {
    Ok(sample_mesh_traced(mesh, options)?.0)
}

/// [`sample_mesh`], reporting the fraction done (0 first, 1 last, about
/// every [`PROGRESS_STEP`] candidates of blue-noise elimination in between).
pub fn sample_mesh_reporting(
    mesh: &TriangleMesh,
    options: &SamplingOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<Surfel>> {
    Ok(sample_traced(mesh, options, progress)?.0)
}

/// Candidates of blue-noise elimination between two progress reports.
pub const PROGRESS_STEP: usize = 1 << 14;

/// [`sample_mesh`], also returning for each surfel the index in
/// `mesh.triangles` of the triangle it was sampled on (for hybrid
/// point–polygon rendering, [`super::hybrid`]).
pub fn sample_mesh_traced(mesh: &TriangleMesh, options: &SamplingOptions) -> Result<(Vec<Surfel>, Vec<u32>)> {
    sample_traced(mesh, options, &mut |_| {})
}

fn sample_traced(
    mesh: &TriangleMesh,
    options: &SamplingOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Vec<Surfel>, Vec<u32>)> {
    progress(0.0);
    let count = options.count;
    if count == 0 {
        return Err(Error::invalid("sample count", "must be positive"));
    }
    crate::budget::MemoryLimits::host_only().check(
        "sample count",
        &format!("{count} samples"),
        sampling_footprint(count, options.method),
    )?;
    let prepared = Prepared::new(mesh)?;
    let radius =
        ((prepared.total_area / (std::f64::consts::PI * count as f64)).sqrt() as f32) * options.method.radius_overlap();
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::invalid(
            "mesh",
            format!("surface area {} too small for {count} samples", prepared.total_area),
        ));
    }
    let samples = match options.method {
        SamplingMethod::Stratified => prepared.stratified(count, options.seed)?,
        SamplingMethod::BlueNoise => {
            let candidates = count
                .checked_mul(BLUE_NOISE_CANDIDATES)
                .filter(|&m| m <= u32::MAX as usize)
                .ok_or_else(|| Error::invalid("sample count", format!("{count} is too large for blue noise")))?;
            let candidates = prepared.stratified(candidates, options.seed)?;
            progress(0.1);
            eliminate(candidates, count, prepared.total_area, progress)
        }
    };
    let vertices: Vec<[usize; 3]> = prepared.triangles.iter().map(|t| t.vertices).collect();
    let normals: Vec<Vec3> = prepared.triangles.iter().map(|t| t.face_normal).collect();
    let creases = Creases::new(&mesh.positions, &vertices, &normals);
    progress(0.95);
    let traced = samples
        .into_iter()
        .map(|Sample { mut surfel, triangle }| {
            surfel.radius = radius;
            surfel.clip = creases.lines(triangle as usize, surfel.position, surfel.normal, radius);
            (surfel, prepared.triangles[triangle as usize].index)
        })
        .unzip();
    progress(1.0);
    Ok(traced)
}

/// Peak host bytes per output sample of [`sample_mesh`] with `method`,
/// counted from its allocations: per candidate (one per sample stratified,
/// [`BLUE_NOISE_CANDIDATES`] for blue noise) the sample and, for blue noise,
/// its kd-tree entry (40), weight (8), heap slots (8) and removal flag (1);
/// then the output surfel and its triangle index.
/// `crate::points::build::plan` estimates `spt build`'s memory with it.
pub const fn bytes_per_sample(method: SamplingMethod) -> u64 {
    let sample = std::mem::size_of::<Sample>();
    let candidates = match method {
        SamplingMethod::Stratified => sample,
        SamplingMethod::BlueNoise => BLUE_NOISE_CANDIDATES * (sample + 40 + 8 + 8 + 1),
    };
    (candidates + std::mem::size_of::<Surfel>() + 4) as u64
}

/// A surfel (radius still 0) and the index of the triangle it lies in.
#[derive(Clone, Copy, Debug)]
struct Sample {
    surfel: Surfel,
    triangle: u32,
}

/// A non-degenerate triangle.
struct Triangle {
    vertices: [usize; 3],
    face_normal: Vec3,
    /// Index in the mesh's triangle list.
    index: u32,
}

/// The usable triangles with their cumulative areas.
struct Prepared<'a> {
    mesh: &'a TriangleMesh,
    triangles: Vec<Triangle>,
    /// Cumulative area up to and including each triangle.
    cumulative: Vec<f64>,
    total_area: f64,
}

impl<'a> Prepared<'a> {
    fn new(mesh: &'a TriangleMesh) -> Result<Self> {
        let n = mesh.positions.len();
        if let Some(normals) = &mesh.normals {
            if normals.len() != n {
                return Err(Error::invalid(
                    "mesh",
                    format!("{} vertex normals for {n} vertices", normals.len()),
                ));
            }
        }
        if let Some(colors) = &mesh.colors {
            if colors.len() != n {
                return Err(Error::invalid(
                    "mesh",
                    format!("{} vertex colours for {n} vertices", colors.len()),
                ));
            }
        }
        let mut triangles = Vec::with_capacity(mesh.triangles.len());
        let mut cumulative = Vec::with_capacity(mesh.triangles.len());
        let mut total_area = 0.0f64;
        for (t, indices) in mesh.triangles.iter().enumerate() {
            let vertices = indices.map(|i| i as usize);
            if let Some(&bad) = vertices.iter().find(|&&i| i >= n) {
                return Err(Error::invalid("mesh", format!("triangle {t} uses vertex {bad} of {n}")));
            }
            let [a, b, c] = vertices.map(|i| mesh.positions[i]);
            if !(a.is_finite() && b.is_finite() && c.is_finite()) {
                return Err(Error::invalid("mesh", format!("triangle {t} has a non-finite vertex")));
            }
            let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
            let cross = (b - a).cross(c - a);
            let area = 0.5 * cross.length();
            let face_normal = cross.normalize_or_zero().as_vec3().normalize_or_zero();
            if !(area > 0.0 && area.is_finite()) || face_normal == Vec3::ZERO {
                continue;
            }
            total_area += area;
            triangles.push(Triangle {
                vertices,
                face_normal,
                index: t as u32,
            });
            cumulative.push(total_area);
        }
        if triangles.is_empty() || !(total_area > 0.0 && total_area.is_finite()) {
            return Err(Error::invalid("mesh", "no triangle with a positive area"));
        }
        Ok(Prepared {
            mesh,
            triangles,
            cumulative,
            total_area,
        })
    }

    /// Exactly `count` stratified samples (module docs), radius left 0;
    /// errors only when they do not fit in memory.
    fn stratified(&self, count: usize, seed: u64) -> Result<Vec<Sample>> {
        // Roberts' R2 sequence: 1/g and 1/g² for the plastic number g.
        const G: f64 = 1.324_717_957_244_746;
        const ALPHA: [f64; 2] = [1.0 / G, 1.0 / (G * G)];
        let mut rng = SplitMix64(seed);
        let offset = rng.next_f64();
        let scale = count as f64 / self.total_area;
        let last = self.triangles.len() - 1;
        let mut surfels = Vec::new();
        surfels
            .try_reserve_exact(count)
            .map_err(|e| Error::invalid("sample count", format!("{count} surfels: {e}")))?;
        let mut before = 0usize;
        for (t, triangle) in self.triangles.iter().enumerate() {
            // Lattice points (i + offset) below the scaled cumulative area.
            let end = if t == last {
                count as f64
            } else {
                self.cumulative[t] * scale
            };
            let upto = ((end - offset).ceil().max(0.0) as usize).clamp(before, count);
            let n = upto - before;
            before = upto;
            if n == 0 {
                continue;
            }
            let mut local = SplitMix64(seed ^ (t as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03));
            let shift = [local.next_f64(), local.next_f64()];
            for i in 0..n {
                let u = (shift[0] + i as f64 * ALPHA[0]).fract();
                let v = (shift[1] + i as f64 * ALPHA[1]).fract();
                surfels.push(Sample {
                    surfel: self.surfel(triangle, square_to_triangle(u as f32, v as f32)),
                    triangle: t as u32,
                });
            }
        }
        Ok(surfels)
    }

    /// The surfel at barycentric coordinates `b` of a triangle, radius 0.
    fn surfel(&self, triangle: &Triangle, b: [f32; 3]) -> Surfel {
        let [i, j, k] = triangle.vertices;
        let mesh = self.mesh;
        let position = mesh.positions[i] * b[0] + mesh.positions[j] * b[1] + mesh.positions[k] * b[2];
        let normal = mesh
            .normals
            .as_ref()
            .map(|n| (n[i] * b[0] + n[j] * b[1] + n[k] * b[2]).normalize_or_zero())
            .filter(|n| *n != Vec3::ZERO)
            .unwrap_or(triangle.face_normal);
        let color = mesh.colors.as_ref().map_or(DEFAULT_COLOR, |c| {
            [0, 1, 2].map(|ch| {
                let v = f32::from(c[i][ch]) * b[0] + f32::from(c[j][ch]) * b[1] + f32::from(c[k][ch]) * b[2];
                v.round().clamp(0.0, 255.0) as u8
            })
        });
        Surfel {
            position,
            normal,
            radius: 0.0,
            color,
            clip: ClipLines::NONE,
        }
    }
}

/// Heitz 2019, "A low-distortion map between triangle and square": area
/// preserving, continuous and piecewise linear; returns barycentric
/// coordinates.
fn square_to_triangle(u: f32, v: f32) -> [f32; 3] {
    let (b0, b1) = if u < v {
        let b0 = u * 0.5;
        (b0, v - b0)
    } else {
        let b1 = v * 0.5;
        (u - b1, b1)
    };
    [b0, b1, (1.0 - b0 - b1).max(0.0)]
}

/// Yuksel 2015 weighted sample elimination of `candidates` down to `target`
/// (module docs); keeps the candidates' order.
/// Reports fractions 0.1‥0.5 while weighing, 0.5‥0.9 while eliminating.
fn eliminate(candidates: Vec<Sample>, target: usize, area: f64, progress: &mut dyn FnMut(f32)) -> Vec<Sample> {
    let m = candidates.len();
    if m <= target {
        return candidates;
    }
    let r_max = (area / (2.0 * 3.0f64.sqrt() * target as f64)).sqrt();
    let r_min = r_max * (1.0 - (target as f64 / m as f64).powf(1.5)) * 0.65;
    let (d_max, d_min) = (2.0 * r_max, 2.0 * r_min);
    let d_max2 = (d_max * d_max) as f32;
    let weight = |d2: f32| (1.0 - (f64::from(d2).sqrt().clamp(d_min, d_max) / d_max)).powi(8);
    // Opposite-facing samples (more than 120° apart) do not interact.
    let interacts = |a: &Sample, b: &Sample| a.surfel.normal.dot(b.surfel.normal) > -0.5;

    let positions: Vec<Vec3> = candidates.iter().map(|s| s.surfel.position).collect();
    let tree = KdTree::new(&positions);
    let mut weights = vec![0.0f64; m];
    for (i, s) in candidates.iter().enumerate() {
        let mut w = 0.0;
        tree.for_each_within(s.surfel.position, d_max2, &mut |j, d2| {
            if j as usize != i && interacts(s, &candidates[j as usize]) {
                w += weight(d2);
            }
        });
        weights[i] = w;
        if i % PROGRESS_STEP == 0 {
            progress(0.1 + 0.4 * i as f32 / m as f32);
        }
    }
    let mut heap = WeightHeap::new(&weights);
    let mut removed = vec![false; m];
    for step in target..m {
        if step % PROGRESS_STEP == 0 {
            progress(0.5 + 0.4 * (step - target) as f32 / (m - target) as f32);
        }
        let Some(i) = heap.pop(&weights) else {
            break;
        };
        removed[i] = true;
        let s = &candidates[i];
        tree.for_each_within(s.surfel.position, d_max2, &mut |j, d2| {
            let j = j as usize;
            if j != i && !removed[j] && interacts(s, &candidates[j]) {
                weights[j] -= weight(d2);
                heap.decreased(j, &weights);
            }
        });
    }
    candidates
        .into_iter()
        .zip(removed)
        .filter_map(|(s, gone)| (!gone).then_some(s))
        .collect()
}

/// An indexed binary max-heap of candidates by weight (ties: larger index
/// first, for determinism); the weights live outside and may only decrease.
struct WeightHeap {
    /// Candidate indices in heap order.
    heap: Vec<u32>,
    /// Position of each candidate in `heap`.
    position: Vec<u32>,
}

impl WeightHeap {
    fn new(weights: &[f64]) -> Self {
        let n = weights.len();
        let mut heap = WeightHeap {
            heap: (0..n as u32).collect(),
            position: (0..n as u32).collect(),
        };
        for at in (0..n / 2).rev() {
            heap.sift_down(at, weights);
        }
        heap
    }

    fn above(weights: &[f64], a: u32, b: u32) -> bool {
        weights[a as usize].total_cmp(&weights[b as usize]).then(a.cmp(&b)) == Ordering::Greater
    }

    /// Removes and returns the heaviest candidate.
    fn pop(&mut self, weights: &[f64]) -> Option<usize> {
        let top = *self.heap.first()?;
        let last = self.heap.pop()?;
        if !self.heap.is_empty() {
            self.heap[0] = last;
            self.position[last as usize] = 0;
            self.sift_down(0, weights);
        }
        Some(top as usize)
    }

    /// Restores the order after `weights[item]` decreased (`item` in the heap).
    fn decreased(&mut self, item: usize, weights: &[f64]) {
        self.sift_down(self.position[item] as usize, weights);
    }

    fn sift_down(&mut self, mut at: usize, weights: &[f64]) {
        let n = self.heap.len();
        loop {
            let (l, r) = (2 * at + 1, 2 * at + 2);
            let mut best = at;
            if l < n && Self::above(weights, self.heap[l], self.heap[best]) {
                best = l;
            }
            if r < n && Self::above(weights, self.heap[r], self.heap[best]) {
                best = r;
            }
            if best == at {
                return;
            }
            self.heap.swap(at, best);
            self.position[self.heap[at] as usize] = at as u32;
            self.position[self.heap[best] as usize] = best as u32;
            at = best;
        }
    }
}

#[cfg(test)]
mod tests {
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
}
