//! Procedural rocks (dissertation §6.1.4; `ALGORITHMS.md` §1, last bullet):
//! 4–20 random points → convex hull → repeated 1-to-4 triangle subdivision,
//! the new vertices displaced by noise along the normal.
//!
//! The pipeline of [`generate_rock`]:
//!
//! 1. **Points.** [`RockParams::points`] points are drawn with
//!    [`SplitMix64`] in a shell `0.8…1.0` of an axis-aligned ellipsoid whose
//!    half axes are `size/2 · (0.75…1)` each, the vertical one further
//!    multiplied by `1 − 0.75·flatten`. Random directions (normalised
//!    Gaussian triples) make a degenerate (coplanar) set practically
//!    impossible; should the hull still fail, the points are drawn again with
//!    the next sub-seed, up to [`MAX_ATTEMPTS`] times, before an error is
//!    returned.
//! 2. **Convex hull.** The incremental algorithm (O(n²) for n points): an
//!    initial tetrahedron from extreme points, then every further point
//!    deletes the faces it sees (signed distance above `ε = 10⁻⁹ ·` the
//!    bounding-box diagonal) and is joined to their horizon. Points within ε
//!    of the hull count as inside. Collinear, coplanar or coincident inputs,
//!    non-finite coordinates and a zero-area face are reported as errors; the
//!    result is checked to be closed and consistently oriented. Triangles are
//!    counter-clockwise seen from outside (outward normals `(b − a) × (c − a)`).
//! 3. **Subdivision.** [`RockParams::subdivisions`] rounds of 1-to-4
//!    subdivision; the edge midpoints are shared between the two triangles of
//!    an edge (a hash map on the sorted edge), so the surface stays closed and
//!    of genus 0. Round `l` (from 0) moves every new midpoint `m` of edge
//!    `(a, b)` along the averaged normal `normalize(n_a + n_b)` (area-weighted
//!    vertex normals of the current mesh) by
//!    `roughness · size · decayˡ · N(m · 2ˡ·2/size + o)`, with `N` the 3-D
//!    gradient noise [`gradient_noise_3d`] (range [−1, 1]) under a per-level
//!    seed and `o` a per-rock offset: each round halves the noise wavelength
//!    and scales the amplitude by `decay`, a fractal displacement. The
//!    displacement is clamped to 0.3 times the smaller height of the edge's
//!    two triangles, so that slivers and short hull edges do not fold over.
//!    Old vertices stay where they are.
//! 4. **Attributes.** Smooth vertex normals (area-weighted face normals) and
//!    grey-brown sRGB vertex colours: a per-rock base between grey and brown
//!    and lightness, varied per vertex by two octaves of low-amplitude noise.
//! 5. **Placement.** The rock is translated so that its lowest point lies at
//!    z = 0 and its bounding box is centred on x = y = 0.
//!
//! A hull of n points has `2n' − 4` faces for its n' ≤ n extreme points;
//! after k rounds the mesh has `4ᵏ` times as many, e.g. at most
//! 36 · 4⁷ = 589 824 triangles for 20 points and 7 rounds. Everything is
//! computed in `f64` from the seed alone, so a parameter set gives the same
//! rock on every run.

use std::collections::{HashMap, HashSet};

use glam::{DVec3, Vec3};

use crate::error::{Error, Result};
use crate::points::TriangleMesh;
use crate::random::SplitMix64;

/// How many point sets [`generate_rock`] draws (sub-seeds) before it gives up
/// on a degenerate hull.
pub const MAX_ATTEMPTS: u32 = 16;

/// Most rounds of subdivision: 7 gives the text's rock of Fig. 10.11
/// (12 · 4⁷ = 196 608 triangles from 8 hull points; at most 36 · 4⁷ =
/// 589 824 for 20).
pub const MAX_SUBDIVISIONS: u32 = 7;

/// Largest accepted [`RockParams::size`] in metres.
pub const MAX_SIZE: f32 = 1.0e4;

/// Parameters of one procedural rock (dissertation §6.1.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RockParams {
    /// Seed of everything random: points, noise, colours.
    pub seed: u64,
    /// Number of random points whose convex hull is the base shape, 4..=20.
    pub points: u32,
    /// Rounds of 1-to-4 subdivision, 0..=[`MAX_SUBDIVISIONS`].
    pub subdivisions: u32,
    /// Displacement amplitude of the first round relative to `size`, 0..=1
    /// (e.g. 0.15).
    pub roughness: f32,
    /// Amplitude factor from one round to the next, 0..=1 (e.g. 0.5).
    pub decay: f32,
    /// Approximate diameter in metres, in (0, [`MAX_SIZE`]].
    pub size: f32,
    /// Vertical squash, 0..=1: the vertical half axis of the point
    /// ellipsoid is multiplied by `1 − 0.75·flatten`, so flattened rocks sit
    /// on the ground.
    pub flatten: f32,
}

impl Default for RockParams {
    /// A plausible boulder: 12 points, 4 subdivisions, 1 m across, slightly
    /// flattened.
    fn default() -> Self {
        Self {
            seed: 1,
            points: 12,
            subdivisions: 4,
            roughness: 0.15,
            decay: 0.5,
            size: 1.0,
            flatten: 0.3,
        }
    }
}

impl RockParams {
    /// Checks every field's range (see the field documentation).
    pub fn validate(&self) -> Result<()> {
        if !(4..=20).contains(&self.points) {
            return Err(Error::invalid(
                "rock points",
                format!("{} is outside 4..=20", self.points),
            ));
        }
        if self.subdivisions > MAX_SUBDIVISIONS {
            return Err(Error::invalid(
                "rock subdivisions",
                format!("{} is outside 0..={MAX_SUBDIVISIONS}", self.subdivisions),
            ));
        }
        let unit = |what: &str, v: f32| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(Error::invalid(what, format!("{v} is outside [0, 1]")))
            }
        };
        unit("rock roughness", self.roughness)?;
        unit("rock decay", self.decay)?;
        unit("rock flatten", self.flatten)?;
        if !(self.size > 0.0 && self.size <= MAX_SIZE) {
            return Err(Error::invalid(
                "rock size",
                format!("{} is outside (0, {MAX_SIZE}] metres", self.size),
            ));
        }
        Ok(())
    }
}

/// Generates one rock (dissertation §6.1.4): random points → convex hull →
/// `subdivisions` rounds of noise-displaced 1-to-4 subdivision; see the
/// module documentation for the details.
///
/// The mesh has counter-clockwise (outward) triangles, smooth unit vertex
/// normals and sRGB vertex colours; its lowest point is at z = 0 and its
/// bounding box is centred on x = y = 0. Deterministic per parameter set.
///
/// Errors: a parameter out of range ([`RockParams::validate`]), or no
/// non-degenerate hull in [`MAX_ATTEMPTS`] point sets.
pub fn generate_rock(params: &RockParams) -> Result<TriangleMesh> {
    build_rock(params, sample_points)
}

/// Parameters for `count` varied rocks to scatter over a terrain
/// (dissertation §6.1.4), deterministic per `seed`: 6–20 points, sizes
/// log-uniform in 0.3–2.5 m, roughness 0.08–0.22, decay 0.35–0.5 (at most
/// 0.5, where every round adds the same slope, as the noise frequency
/// doubles), flatten 0.1–0.6, 3 subdivisions (4 for rocks above 1 m). Every entry passes
/// [`RockParams::validate`]. Placement is up to the caller.
pub fn rock_field(count: usize, seed: u64) -> Vec<RockParams> {
    let mut rng = SplitMix64(seed);
    // No up-front reservation for huge counts (a capacity overflow would panic).
    let mut out = Vec::with_capacity(count.min(4096));
    for _ in 0..count {
        let rock_seed = rng.next_u64();
        let points = 6 + (rng.next_u64() % 15) as u32;
        let size = 0.3 * (2.5f64 / 0.3).powf(rng.next_f64());
        let roughness = 0.08 + 0.14 * rng.next_f64();
        let decay = 0.35 + 0.15 * rng.next_f64();
        let flatten = 0.1 + 0.5 * rng.next_f64();
        out.push(RockParams {
            seed: rock_seed,
            points,
            subdivisions: if size > 1.0 { 4 } else { 3 },
            roughness: roughness as f32,
            decay: decay as f32,
            size: size as f32,
            flatten: flatten as f32,
        });
    }
    out
}

/// Seeded 3-D gradient (Perlin) noise with a unit-period lattice, used for
/// the displacement of §6.1.4 (the 3-D counterpart of
/// [`crate::terrain::procedural::gradient_noise`]).
///
/// Every integer lattice point gets one of Perlin's twelve cube-edge
/// directions, normalised, chosen by a [`SplitMix64`] hash of
/// `(seed, i, j, k)`; the eight corner contributions are blended with the
/// quintic fade `6t⁵ − 15t⁴ + 10t³`, so the noise is C² smooth, does not
/// repeat and is zero at lattice points. Unit-gradient noise in three
/// dimensions is bounded by `√3/2`; the result is scaled by `2/√3` and
/// clamped, so it lies in **[−1, 1]**. Non-finite input gives 0.
pub fn gradient_noise_3d(seed: u64, p: DVec3) -> f64 {
    if !p.is_finite() {
        return 0.0;
    }
    let cell = p.floor();
    // `as` saturates for huge inputs; it never panics.
    let (i, j, k) = (cell.x as i64, cell.y as i64, cell.z as i64);
    let f = p - cell;
    let corner = |di: i64, dj: i64, dk: i64| {
        let h = lattice_hash(seed, i.wrapping_add(di), j.wrapping_add(dj), k.wrapping_add(dk));
        let g = GRADIENTS_3D[(h >> 60) as usize];
        let d = f - DVec3::new(di as f64, dj as f64, dk as f64);
        (g[0] * d.x + g[1] * d.y + g[2] * d.z) * std::f64::consts::FRAC_1_SQRT_2
    };
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let lerp = |a: f64, b: f64, t: f64| a + t * (b - a);
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
    let n = lerp(lerp(x00, x10, v), lerp(x01, x11, v), w) * (2.0 / 3f64.sqrt());
    if n.is_finite() {
        n.clamp(-1.0, 1.0)
    } else {
        0.0
    }
}

/// Perlin's twelve cube-edge gradients (unnormalised, length √2), the first
/// four repeated so that four hash bits pick one (Perlin 2002).
const GRADIENTS_3D: [[f64; 3]; 16] = [
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [-1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [-1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, -1.0, 1.0],
    [0.0, 1.0, -1.0],
    [0.0, -1.0, -1.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [0.0, -1.0, 1.0],
    [0.0, -1.0, -1.0],
];

/// Hash of lattice point `(i, j, k)` under `seed`: chained SplitMix64 steps.
fn lattice_hash(seed: u64, i: i64, j: i64, k: i64) -> u64 {
    let a = SplitMix64(seed ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64();
    let b = SplitMix64(a ^ (j as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)).next_u64();
    SplitMix64(b ^ (k as u64).wrapping_mul(0x1656_67b1_9e37_79f9)).next_u64()
}

/// Quintic fade `6t⁵ − 15t⁴ + 10t³` (Perlin 2002).
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Seed offsets for the independent random streams of one rock.
const NOISE_STREAM: u64 = 0x6e6f_6973_6520_3364; // "noise 3d"
const COLOR_STREAM: u64 = 0x636f_6c6f_7572_7321; // "colours!"

/// The generator with an exchangeable point sampler (tests force degenerate
/// sets through it).
fn build_rock(
    params: &RockParams,
    mut sample: impl FnMut(&RockParams, &mut SplitMix64) -> Vec<DVec3>,
) -> Result<TriangleMesh> {
    params.validate()?;
    let mut master = SplitMix64(params.seed);
    let mut last_error = None;
    let mut hull = None;
    for _ in 0..MAX_ATTEMPTS {
        let mut rng = SplitMix64(master.next_u64());
        match convex_hull(&sample(params, &mut rng)) {
            Ok(h) => {
                hull = Some(h);
                break;
            }
            Err(e) => last_error = Some(e),
        }
    }
    let Some(Hull {
        vertices: mut positions,
        faces: mut triangles,
    }) = hull
    else {
        let why = last_error.map_or_else(String::new, |e| format!(": {e}"));
        return Err(Error::invalid(
            "rock points",
            format!("no non-degenerate convex hull in {MAX_ATTEMPTS} point sets{why}"),
        ));
    };

    // Subdivision with fractal displacement along the normal.
    let size = params.size as f64;
    let noise_seed = SplitMix64(params.seed ^ NOISE_STREAM).next_u64();
    let mut offset_rng = SplitMix64(noise_seed);
    let offset = DVec3::new(offset_rng.next_f64(), offset_rng.next_f64(), offset_rng.next_f64()) * 256.0;
    let mut amplitude = params.roughness as f64 * size;
    let mut frequency = 2.0 / size;
    for level in 0..params.subdivisions {
        let displace = Displacement {
            amplitude,
            frequency,
            seed: noise_seed.wrapping_add(level as u64),
            offset,
        };
        triangles = subdivide(&mut positions, &triangles, &displace);
        amplitude *= params.decay as f64;
        frequency *= 2.0;
    }

    // Placement: lowest point at z = 0, bounding box centred in x and y.
    let (lo, hi) = bounds(&positions);
    let shift = DVec3::new(-(lo.x + hi.x) * 0.5, -(lo.y + hi.y) * 0.5, -lo.z);
    let normals = vertex_normals(&positions, &triangles);
    let colors = rock_colors(&positions, params);
    let positions: Vec<Vec3> = positions.iter().map(|&p| (p + shift).as_vec3()).collect();
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(Error::invalid("rock size", "the rock's coordinates are not finite"));
    }
    let normals = normals
        .iter()
        .map(|n| {
            let n = n.as_vec3().normalize_or_zero();
            if n == Vec3::ZERO {
                Vec3::Z
            } else {
                n
            }
        })
        .collect();
    Ok(TriangleMesh {
        positions,
        normals: Some(normals),
        colors: Some(colors),
        triangles,
    })
}

/// Random points in the shell 0.8–1.0 of a random ellipsoid (module docs, step 1).
fn sample_points(params: &RockParams, rng: &mut SplitMix64) -> Vec<DVec3> {
    let half = params.size as f64 * 0.5;
    let squash = 1.0 - 0.75 * params.flatten as f64;
    let mut axis = || half * (0.75 + 0.25 * rng.next_f64());
    let radii = DVec3::new(axis(), axis(), axis() * squash);
    (0..params.points)
        .map(|_| {
            let mut dir = DVec3::X;
            for _ in 0..8 {
                let (a, b) = rng.gaussian_pair();
                let (c, _) = rng.gaussian_pair();
                let v = DVec3::new(a, b, c);
                if v.length_squared() > 1e-12 {
                    dir = v.normalize();
                    break;
                }
            }
            dir * (0.8 + 0.2 * rng.next_f64()) * radii
        })
        .collect()
}

/// A closed convex polyhedron: the hull's vertices (the extreme input points,
/// in input order) and its outward (counter-clockwise) triangles.
#[derive(Clone, Debug)]
struct Hull {
    vertices: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
}

/// A hull face under construction: vertex indices into the input and its
/// plane `normal · x = offset` (unit outward normal).
#[derive(Clone, Copy, Debug)]
struct Face {
    v: [usize; 3],
    normal: DVec3,
    offset: f64,
}

fn degenerate(message: impl std::fmt::Display) -> Error {
    Error::invalid("rock points", message)
}

/// The convex hull of `points` by the incremental algorithm (module docs,
/// step 2). Errors for fewer than four points, non-finite coordinates and
/// degenerate (coincident, collinear, coplanar) sets.
fn convex_hull(points: &[DVec3]) -> Result<Hull> {
    if points.len() < 4 {
        return Err(degenerate(format!(
            "a convex hull needs 4 points, got {}",
            points.len()
        )));
    }
    if points.iter().any(|p| !p.is_finite()) {
        return Err(degenerate("a point is not finite"));
    }
    let (lo, hi) = bounds(points);
    let scale = (hi - lo).length();
    if !scale.is_finite() {
        return Err(degenerate("the points' coordinates are too large"));
    }
    if scale <= 0.0 {
        return Err(degenerate("all points coincide"));
    }
    let eps = scale * 1e-9;

    let [a, b, c, d] = initial_tetrahedron(points, eps)?;
    let make = |v: [usize; 3]| -> Result<Face> {
        let [pa, pb, pc] = v.map(|i| points[i]);
        let cross = (pb - pa).cross(pc - pa);
        let len = cross.length();
        if !len.is_finite() || len <= eps * scale {
            return Err(degenerate("a hull face has zero area"));
        }
        let normal = cross / len;
        Ok(Face {
            v,
            normal,
            offset: normal.dot(pa),
        })
    };
    let mut faces = vec![make([a, b, c])?, make([a, d, b])?, make([b, d, c])?, make([c, d, a])?];

    for (i, &p) in points.iter().enumerate() {
        if [a, b, c, d].contains(&i) {
            continue;
        }
        let visible: Vec<bool> = faces.iter().map(|f| f.normal.dot(p) - f.offset > eps).collect();
        if !visible.contains(&true) {
            continue; // inside (or within ε of) the current hull
        }
        let edges: HashSet<(usize, usize)> = faces
            .iter()
            .zip(&visible)
            .filter(|(_, &vis)| vis)
            .flat_map(|(f, _)| [(f.v[0], f.v[1]), (f.v[1], f.v[2]), (f.v[2], f.v[0])])
            .collect();
        let mut horizon = Vec::new();
        for (f, _) in faces.iter().zip(&visible).filter(|(_, &vis)| vis) {
            for (s, t) in [(f.v[0], f.v[1]), (f.v[1], f.v[2]), (f.v[2], f.v[0])] {
                if !edges.contains(&(t, s)) {
                    horizon.push((s, t));
                }
            }
        }
        if horizon.len() < 3 {
            return Err(degenerate("inconsistent visibility while building the hull"));
        }
        let mut kept: Vec<Face> = faces
            .iter()
            .zip(&visible)
            .filter(|(_, &vis)| !vis)
            .map(|(f, _)| *f)
            .collect();
        for (s, t) in horizon {
            kept.push(make([s, t, i])?);
        }
        faces = kept;
    }

    let triangles: Vec<[usize; 3]> = faces.iter().map(|f| f.v).collect();
    if !is_closed_and_oriented(&triangles) {
        return Err(degenerate("the hull is not a closed, consistently oriented surface"));
    }
    Ok(compact_hull(points, &triangles))
}

/// The initial tetrahedron of the hull from extreme points, as indices
/// `[a, b, c, d]` with `d` below the plane of (a, b, c), so that the faces
/// (a, b, c), (a, d, b), (b, d, c), (c, d, a) face outward. `eps`: the
/// distance below which points count as coincident, collinear, coplanar.
fn initial_tetrahedron(points: &[DVec3], eps: f64) -> Result<[usize; 4]> {
    let argmax = |f: &dyn Fn(DVec3) -> f64| {
        let mut best = (0, f64::NEG_INFINITY);
        for (i, &p) in points.iter().enumerate() {
            let v = f(p);
            if v > best.1 {
                best = (i, v);
            }
        }
        best
    };
    let (i0, _) = argmax(&|p| -p.x);
    let p0 = points[i0];
    let (i1, d1) = argmax(&|p| (p - p0).length());
    if d1 <= eps {
        return Err(degenerate("all points coincide"));
    }
    let axis = (points[i1] - p0) / d1;
    let (i2, d2) = argmax(&|p| (p - p0).cross(axis).length());
    if d2 <= eps {
        return Err(degenerate("all points are collinear"));
    }
    let plane = (points[i1] - p0).cross(points[i2] - p0).normalize();
    let (i3, d3) = argmax(&|p| (p - p0).dot(plane).abs());
    if d3 <= eps {
        return Err(degenerate("all points are coplanar"));
    }
    // Orient (a, b, c) so that d lies below it; then all four are outward.
    let (a, mut b, mut c, d) = (i0, i1, i2, i3);
    if (points[d] - p0).dot(plane) > 0.0 {
        std::mem::swap(&mut b, &mut c);
    }
    Ok([a, b, c, d])
}

/// The hull of `triangles` over `points`: only the vertices they use, in
/// input order, and the triangles re-indexed to them.
fn compact_hull(points: &[DVec3], triangles: &[[usize; 3]]) -> Hull {
    let mut remap = vec![u32::MAX; points.len()];
    let mut used: Vec<usize> = triangles.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    let vertices = used
        .iter()
        .enumerate()
        .map(|(new, &old)| {
            remap[old] = new as u32;
            points[old]
        })
        .collect();
    let faces = triangles.iter().map(|t| t.map(|i| remap[i])).collect();
    Hull { vertices, faces }
}

/// Whether every directed edge occurs exactly once and its reverse occurs
/// too: a closed, consistently oriented (manifold-edged) triangle surface.
fn is_closed_and_oriented<T: Copy + Eq + std::hash::Hash>(triangles: &[[T; 3]]) -> bool {
    let mut directed = HashSet::with_capacity(triangles.len() * 3);
    for t in triangles {
        for e in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if e.0 == e.1 || !directed.insert(e) {
                return false;
            }
        }
    }
    directed.iter().all(|&(s, t)| directed.contains(&(t, s)))
}

/// Largest displacement of an edge midpoint as a fraction of the smaller
/// height of the edge's two triangles over it. Without it, short hull edges
/// and sliver faces (random points close together) fold over under the full
/// amplitude. At the default parameters triangle heights are roughly
/// 0.3 · size · 2⁻ˡ in round l, so the limit (≈ 0.09 · size · 2⁻ˡ) binds only
/// where the noise is large (amplitude 0.15 · size · 2⁻ˡ times |N|, mostly
/// below 0.6). With it, about 0.25 % of the triangles of a default rock
/// still face against their parent triangle, against 0.45 % without
/// (measured over 20 seeds).
const MAX_RELATIVE_DISPLACEMENT: f64 = 0.3;

/// The noise displacement of one subdivision round.
struct Displacement {
    amplitude: f64,
    frequency: f64,
    seed: u64,
    offset: DVec3,
}

/// One round of 1-to-4 subdivision with shared, displaced edge midpoints
/// (module docs, step 3). Appends the midpoints to `positions` and returns
/// the new triangles, each old triangle `(a, b, c)` becoming
/// `(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)` (same orientation).
fn subdivide(positions: &mut Vec<DVec3>, triangles: &[[u32; 3]], displace: &Displacement) -> Vec<[u32; 3]> {
    let normals = vertex_normals(positions, triangles);
    // Per edge: the smaller height of its two triangles over it, then the midpoint's index.
    let mut edges: HashMap<(u32, u32), (f64, u32)> = HashMap::with_capacity(triangles.len() * 3 / 2);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let twice_area = (b - a).cross(c - a).length();
        for (s, e) in [(0, 1), (1, 2), (2, 0)] {
            let length = positions[t[s] as usize].distance(positions[t[e] as usize]);
            let height = if length > 0.0 { twice_area / length } else { 0.0 };
            let key = (t[s].min(t[e]), t[s].max(t[e]));
            let entry = edges.entry(key).or_insert((f64::INFINITY, u32::MAX));
            entry.0 = entry.0.min(height);
        }
    }
    let mut midpoint = |positions: &mut Vec<DVec3>, s: u32, t: u32| -> u32 {
        let (height, index) = edges.entry((s.min(t), s.max(t))).or_insert((0.0, u32::MAX));
        if *index == u32::MAX {
            let (s, t) = (s as usize, t as usize);
            let m = (positions[s] + positions[t]) * 0.5;
            let n = (normals[s] + normals[t]).normalize_or_zero();
            let noise = gradient_noise_3d(displace.seed, m * displace.frequency + displace.offset);
            let limit = MAX_RELATIVE_DISPLACEMENT * *height;
            positions.push(m + n * (displace.amplitude * noise).clamp(-limit, limit));
            *index = (positions.len() - 1) as u32;
        }
        *index
    };
    let mut out = Vec::with_capacity(triangles.len() * 4);
    for &[a, b, c] in triangles {
        let ab = midpoint(positions, a, b);
        let bc = midpoint(positions, b, c);
        let ca = midpoint(positions, c, a);
        out.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    out
}

/// Unit vertex normals: the sum of the adjacent face normals weighted by
/// area (`(b − a) × (c − a)` is twice the area along the normal); zero for a
/// vertex without area around it.
fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Grey-brown sRGB colours (module docs, step 4).
fn rock_colors(positions: &[DVec3], params: &RockParams) -> Vec<[u8; 3]> {
    let mut rng = SplitMix64(params.seed ^ COLOR_STREAM);
    let seed = rng.next_u64();
    let warmth = rng.next_f64(); // 0 grey … 1 brown
    let lightness = 0.85 + 0.3 * rng.next_f64();
    let grey = DVec3::new(0.50, 0.49, 0.47);
    let brown = DVec3::new(0.52, 0.45, 0.36);
    let f = 2.5 / params.size as f64;
    positions
        .iter()
        .map(|&p| {
            let shade = 1.0
                + 0.12 * gradient_noise_3d(seed, p * f)
                + 0.05 * gradient_noise_3d(seed.wrapping_add(1), p * (4.0 * f));
            let w = (warmth + 0.25 * gradient_noise_3d(seed.wrapping_add(2), p * f)).clamp(0.0, 1.0);
            let c = grey.lerp(brown, w) * (lightness * shade * 255.0);
            [c.x, c.y, c.z].map(|v| v.round().clamp(0.0, 255.0) as u8)
        })
        .collect()
}

/// Axis-aligned bounds of a non-empty point set (±∞ for an empty one).
fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` random points: uniform in a cube or Gaussian.
    fn random_points(seed: u64, n: usize, gaussian: bool) -> Vec<DVec3> {
        let mut rng = SplitMix64(seed);
        (0..n)
            .map(|_| {
                if gaussian {
                    let (a, b) = rng.gaussian_pair();
                    let (c, _) = rng.gaussian_pair();
                    DVec3::new(a, b, c)
                } else {
                    DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 2.0 - 1.0
                }
            })
            .collect()
    }

    fn edge_count(triangles: &[[u32; 3]]) -> usize {
        let edges: HashSet<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(s, t)| (s.min(t), s.max(t)))
            .collect();
        edges.len()
    }

    fn hull_face_count(params: &RockParams) -> usize {
        generate_rock(&RockParams {
            subdivisions: 0,
            ..*params
        })
        .unwrap()
        .triangles
        .len()
    }

    #[test]
    fn hull_contains_every_input_point() {
        for seed in 0..40 {
            for (n, gaussian) in [(4, false), (12, true), (20, false), (200, true), (500, false)] {
                let points = random_points(seed, n, gaussian);
                let hull = convex_hull(&points).unwrap();
                assert!(hull.vertices.len() >= 4 && hull.vertices.len() <= n);
                for f in &hull.faces {
                    let [a, b, c] = f.map(|i| hull.vertices[i as usize]);
                    let normal = (b - a).cross(c - a).normalize();
                    for p in &points {
                        assert!(normal.dot(*p - a) <= 1e-9, "seed {seed}, n {n}: point outside a face");
                    }
                }
                // Every hull vertex is an input point.
                assert!(hull.vertices.iter().all(|v| points.contains(v)));
            }
        }
    }

    #[test]
    fn hull_is_closed_oriented_outward_and_of_genus_zero() {
        for seed in 0..40 {
            let points = random_points(seed, 20, seed % 2 == 0);
            let hull = convex_hull(&points).unwrap();
            assert!(is_closed_and_oriented(&hull.faces));
            let mut directed = HashSet::new();
            for t in &hull.faces {
                for e in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    assert!(directed.insert(e), "directed edge twice");
                }
            }
            // Each undirected edge in exactly two faces.
            assert_eq!(directed.len(), 2 * edge_count(&hull.faces));
            let (v, e, f) = (hull.vertices.len(), edge_count(&hull.faces), hull.faces.len());
            assert_eq!(v as i64 - e as i64 + f as i64, 2);
            assert_eq!(f, 2 * v - 4);
            // Positive signed volume: counter-clockwise seen from outside.
            let volume: f64 = hull
                .faces
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| hull.vertices[i as usize]);
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            assert!(volume > 0.0);
        }
    }

    #[test]
    fn hull_of_a_cube_with_interior_points() {
        let mut points: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        points.extend(random_points(3, 30, false).iter().map(|p| *p * 0.4 + 0.5));
        let hull = convex_hull(&points).unwrap();
        assert_eq!(hull.vertices.len(), 8);
        assert_eq!(hull.faces.len(), 12);
        assert!(is_closed_and_oriented(&hull.faces));
    }

    #[test]
    fn degenerate_point_sets_are_errors_not_panics() {
        let p = DVec3::new(0.3, -0.2, 1.0);
        let coplanar = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.3, 0.7, 0.0),
        ];
        let collinear: Vec<DVec3> = (0..6).map(|i| DVec3::splat(i as f64)).collect();
        let nan = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, f64::NAN)];
        let inf = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, f64::INFINITY)];
        for points in [
            vec![],
            vec![p; 3],
            vec![p; 4],
            vec![p; 20],
            coplanar,
            collinear,
            nan,
            inf,
        ] {
            assert!(convex_hull(&points).is_err(), "{points:?}");
        }
        // Tiny but proper tetrahedra are fine.
        let tiny = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z].map(|v| v * 1e-30 + 5.0e-30);
        assert_eq!(convex_hull(&tiny).unwrap().faces.len(), 4);
    }

    #[test]
    fn forced_coplanar_points_are_retried_or_reported() {
        let params = RockParams::default();
        // The same four coplanar points for every sub-seed: an error.
        let flat =
            |_: &RockParams, _: &mut SplitMix64| vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let err = build_rock(&params, flat).unwrap_err();
        assert!(err.to_string().contains("coplanar"), "{err}");
        // Coplanar only at the first attempt: retried with the next sub-seed.
        let mut attempts = 0;
        let first_flat = |p: &RockParams, rng: &mut SplitMix64| {
            attempts += 1;
            if attempts == 1 {
                vec![DVec3::ZERO; 4]
            } else {
                sample_points(p, rng)
            }
        };
        let mesh = build_rock(&params, first_flat).unwrap();
        assert_eq!(attempts, 2);
        assert!(is_closed_and_oriented(&mesh.triangles));
    }

    #[test]
    fn euler_characteristic_and_face_counts_at_every_level() {
        for seed in [0, 7, 99] {
            for points in [4, 12, 20] {
                let base = RockParams {
                    seed,
                    points,
                    ..Default::default()
                };
                let hull_faces = hull_face_count(&base);
                for k in 0..=6 {
                    if k == 6 && points != 20 {
                        continue; // one large case is enough
                    }
                    let mesh = generate_rock(&RockParams {
                        subdivisions: k,
                        ..base
                    })
                    .unwrap();
                    let (v, e, f) = (mesh.positions.len(), edge_count(&mesh.triangles), mesh.triangles.len());
                    assert_eq!(
                        v as i64 - e as i64 + f as i64,
                        2,
                        "seed {seed}, {points} points, level {k}"
                    );
                    assert_eq!(f, 4usize.pow(k) * hull_faces);
                    assert!(is_closed_and_oriented(&mesh.triangles));
                    assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < v));
                }
            }
        }
    }

    fn outward_fraction(mesh: &TriangleMesh) -> f64 {
        let centroid = mesh.positions.iter().sum::<Vec3>() / mesh.positions.len() as f32;
        let normals = mesh.normals.as_ref().unwrap();
        let outward = mesh
            .positions
            .iter()
            .zip(normals)
            .filter(|(p, n)| n.dot(**p - centroid) > 0.0)
            .count();
        outward as f64 / mesh.positions.len() as f64
    }

    #[test]
    /// Vertex normals are unit and point away from the centroid: on every
    /// vertex of a smooth (roughness 0) rock, which is convex; on at least
    /// 95 % of the vertices on average, and 90 % of every rock, for rough
    /// ones (folds and deep dents of the noise turn some normals inward;
    /// flat, elongated rocks also have normals nearly perpendicular to
    /// `p − centroid`).
    fn normals_point_outward() {
        for seed in 0..10 {
            let mesh = generate_rock(&RockParams {
                seed,
                roughness: 0.0,
                ..Default::default()
            })
            .unwrap();
            assert_eq!(outward_fraction(&mesh), 1.0, "seed {seed}");
        }
        let defaults = (0..20).map(|seed| RockParams {
            seed,
            ..Default::default()
        });
        let fractions: Vec<f64> = defaults
            .chain(rock_field(30, 5))
            .map(|params| {
                let mesh = generate_rock(&params).unwrap();
                let normals = mesh.normals.as_ref().unwrap();
                assert_eq!(normals.len(), mesh.positions.len());
                assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
                let fraction = outward_fraction(&mesh);
                assert!(fraction >= 0.9, "{params:?}: {fraction}");
                fraction
            })
            .collect();
        let mean = fractions.iter().sum::<f64>() / fractions.len() as f64;
        let min = fractions.iter().copied().fold(1.0, f64::min);
        println!(
            "outward normals: mean {mean:.4}, min {min:.4} over {} rocks",
            fractions.len()
        );
        assert!(mean >= 0.95, "{mean}");
    }

    #[test]
    fn deterministic_per_seed_and_different_across_seeds() {
        let params = RockParams::default();
        let a = generate_rock(&params).unwrap();
        assert_eq!(a, generate_rock(&params).unwrap());
        let b = generate_rock(&RockParams { seed: 2, ..params }).unwrap();
        assert_ne!(a.positions, b.positions);
        assert_eq!(rock_field(10, 3), rock_field(10, 3));
        assert_ne!(rock_field(10, 3), rock_field(10, 4));
    }

    #[test]
    fn rests_on_the_ground_centred_and_about_the_requested_size() {
        for seed in 0..10 {
            for size in [0.2f32, 1.0, 3.0] {
                let mesh = generate_rock(&RockParams {
                    seed,
                    size,
                    ..Default::default()
                })
                .unwrap();
                let lo = mesh.positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
                let hi = mesh.positions.iter().fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
                assert_eq!(lo.z, 0.0);
                assert!((lo.x + hi.x).abs() < 1e-5 * size && (lo.y + hi.y).abs() < 1e-5 * size);
                let extent = (hi - lo).max_element();
                assert!(extent > 0.5 * size && extent < 1.5 * size, "{extent} for {size}");
                let colors = mesh.colors.as_ref().unwrap();
                assert_eq!(colors.len(), mesh.positions.len());
                // Grey-brown: red ≥ blue, not saturated.
                assert!(colors.iter().all(|c| c[0] >= c[2] && c[0] < 220 && c[2] > 40));
            }
        }
    }

    #[test]
    fn flatten_squashes_vertically() {
        let height = |flatten| {
            let mesh = generate_rock(&RockParams {
                flatten,
                roughness: 0.0,
                ..Default::default()
            })
            .unwrap();
            mesh.positions.iter().map(|p| p.z).fold(0.0f32, f32::max)
        };
        assert!(height(1.0) < 0.5 * height(0.0));
    }

    #[test]
    fn out_of_range_parameters_are_errors() {
        let ok = RockParams::default();
        assert!(ok.validate().is_ok());
        let bad = [
            RockParams { points: 3, ..ok },
            RockParams { points: 21, ..ok },
            RockParams { points: 0, ..ok },
            RockParams { subdivisions: 8, ..ok },
            RockParams {
                subdivisions: u32::MAX,
                ..ok
            },
            RockParams { roughness: -0.1, ..ok },
            RockParams {
                roughness: f32::NAN,
                ..ok
            },
            RockParams { decay: 1.5, ..ok },
            RockParams {
                decay: f32::INFINITY,
                ..ok
            },
            RockParams { size: 0.0, ..ok },
            RockParams { size: -1.0, ..ok },
            RockParams { size: f32::NAN, ..ok },
            RockParams {
                size: f32::INFINITY,
                ..ok
            },
            RockParams { size: 1e5, ..ok },
            RockParams { flatten: -0.01, ..ok },
            RockParams { flatten: 1.01, ..ok },
        ];
        for params in bad {
            assert!(generate_rock(&params).is_err(), "{params:?}");
        }
        // Extremes inside the ranges work.
        for params in [
            RockParams {
                points: 4,
                subdivisions: 0,
                roughness: 0.0,
                decay: 0.0,
                flatten: 1.0,
                ..ok
            },
            RockParams {
                points: 20,
                subdivisions: 2,
                roughness: 1.0,
                decay: 1.0,
                size: MAX_SIZE,
                ..ok
            },
            RockParams { size: 1e-6, ..ok },
        ] {
            let mesh = generate_rock(&params).unwrap();
            assert!(mesh.positions.iter().all(|p| p.is_finite()));
            assert!(is_closed_and_oriented(&mesh.triangles));
        }
    }

    #[test]
    fn rock_field_parameters_are_valid_and_varied() {
        let field = rock_field(50, 11);
        assert_eq!(field.len(), 50);
        assert!(rock_field(0, 11).is_empty());
        for p in &field {
            p.validate().unwrap();
        }
        let sizes: Vec<f32> = field.iter().map(|p| p.size).collect();
        assert!(sizes.iter().any(|&s| s < 0.8) && sizes.iter().any(|&s| s > 1.2));
        let seeds: HashSet<u64> = field.iter().map(|p| p.seed).collect();
        assert_eq!(seeds.len(), field.len());
        for p in field.iter().take(10) {
            generate_rock(p).unwrap();
        }
    }

    #[test]
    fn noise_is_bounded_smooth_and_seeded() {
        let mut rng = SplitMix64(42);
        let mut max = 0.0f64;
        for _ in 0..20_000 {
            let p = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 40.0 - 20.0;
            let n = gradient_noise_3d(9, p);
            assert!((-1.0..=1.0).contains(&n));
            max = max.max(n.abs());
            let step = gradient_noise_3d(9, p + DVec3::splat(1e-4));
            assert!((step - n).abs() < 1e-2);
        }
        assert!(max > 0.5, "{max}");
        assert_eq!(gradient_noise_3d(9, DVec3::new(3.0, -2.0, 5.0)), 0.0);
        let p = DVec3::new(0.3, 0.6, 0.2);
        assert_ne!(gradient_noise_3d(1, p), gradient_noise_3d(2, p));
        assert_eq!(gradient_noise_3d(1, DVec3::NAN), 0.0);
        assert!(gradient_noise_3d(1, DVec3::splat(1e300)).is_finite());
    }
}
