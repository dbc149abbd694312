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

/// Parameters of `sample_mesh`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplingOptions {
    /// Number of surfels to produce (> 0), exactly.
    pub count: usize,
    pub method: SamplingMethod,
    /// Seed of the (deterministic) random choices.
    pub seed: u64,
}

/// Host memory sampling `count` surfels with `method` needs at its peak
/// (`crate::budget`): `count` × `bytes_per_sample` (about 550 B a
/// surfel for blue noise, which holds `BLUE_NOISE_CANDIDATES` candidates a
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

/// `sample_mesh`, reporting the fraction done (0 first, 1 last, about
/// every `PROGRESS_STEP` candidates of blue-noise elimination in between).
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
#[path = "sampling_tests.rs"]
mod tests;
