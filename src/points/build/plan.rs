//! `spt build` before it samples (§10.1): the input is checked with errors
//! that name its file, and the build's time and memory are estimated from
//! its counts, so that a bad file or an absurd `--samples` is refused in
//! milliseconds instead of after seconds (or hours) of sampling.
//!
//! # Checks ([`plan_build`])
//!
//! A mesh: `--samples` at least 1 (and at most 2³²/5 for blue noise), at
//! least one triangle with a positive area, a sample radius
//! `sqrt(A/(π·N))·overlap` that is positive and finite. A point cloud: at
//! least 3 points when normals must be estimated, 2 when radii must, and
//! not all in one place. Both: a bounding box whose size, and whose
//! `r_min = e_g/ε` at the tree's root, fit the tree's f32 values. These
//! are the errors [`super::sampling`], [`super::estimate`] and
//! [`super::spt`] would otherwise report only after their work.
//!
//! # Cost ([`BuildCost`])
//!
//! Time: per triangle ([`SECONDS_PER_TRIANGLE`]: areas, creases), per
//! output sample of blue noise ([`BLUE_NOISE_SECONDS_PER_SAMPLE`]) or
//! stratified sampling ([`STRATIFIED_SECONDS_PER_SAMPLE`]), per point whose
//! normal or radius is estimated ([`COMPLETION_SECONDS_PER_POINT`]) and per
//! surfel of the tree build ([`BUILD_SECONDS_PER_SURFEL`]). Release builds
//! on the 2-core build VM: 35,000 blue-noise samples of the bunny in 0.6 s
//! unloaded (17 µs a sample, [`super::sampling`]); whole `spt build` runs
//! of the bunny at load 6–8 (other builds sharing both cores) took 78 µs a
//! blue-noise sample (100,000 and 300,000 samples: 7.8 s and 23.1 s) and
//! 7.3 µs a stratified one (1,000,000: 7.3 s, nearly all of it the tree
//! build). The rates lie between the unloaded and the loaded figures.
//! Memory: the largest of the sampling's
//! ([`super::sampling::bytes_per_sample`]), the build's
//! ([`super::spt::BUILD_BYTES_PER_SURFEL`] plus the surfels) and the
//! writing's (the tree and its bytes) peaks, counted from the allocations;
//! the same runs peaked at 565 bytes a sample of resident memory (300,000
//! blue-noise samples: 185 MiB estimated, 176 MiB measured).

use std::path::Path;

use glam::{DVec3, Vec3};

use super::input::PointInput;
use super::sampling::{bytes_per_sample, SamplingMethod, SamplingOptions, BLUE_NOISE_CANDIDATES};
use super::spt::{SptOptions, BUILD_BYTES_PER_SURFEL};
use crate::budget::{check_duration, format_bytes, format_duration, Footprint, MemoryLimits};
use crate::error::{Error, Result};
use crate::points::{PointCloud, Surfel, TriangleMesh};

/// Seconds per mesh triangle (areas, cumulative areas, creases).
pub const SECONDS_PER_TRIANGLE: f64 = 1.0e-6;
/// Seconds per output sample of blue-noise sampling (module docs).
pub const BLUE_NOISE_SECONDS_PER_SAMPLE: f64 = 3.0e-5;
/// Seconds per output sample of stratified sampling (1 ms for 35,000).
pub const STRATIFIED_SECONDS_PER_SAMPLE: f64 = 1.0e-7;
/// Seconds per point whose normal (PCA of 8 neighbours) or radius (6th
/// neighbour) is estimated.
pub const COMPLETION_SECONDS_PER_POINT: f64 = 4.0e-6;
/// Seconds per surfel of the tree build (octree, errors, sort).
pub const BUILD_SECONDS_PER_SURFEL: f64 = 4.0e-6;
/// Host bytes per point of completing a cloud: its kd-tree (40), neighbour
/// lists (8 × 4), normals and radii (16).
const COMPLETION_BYTES_PER_POINT: u64 = 40 + 32 + 16;
/// Bytes per node of the written file (76 measured, with the header).
const FILE_BYTES_PER_NODE: u64 = 80;

/// What a build of a checked input costs (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildCost {
    /// Surfels of the tree: `--samples` for a mesh, the points of a cloud.
    pub surfels: u64,
    /// Triangles of a mesh (0 for a cloud).
    pub triangles: u64,
    /// How a mesh is sampled; None for a cloud.
    pub method: Option<SamplingMethod>,
    /// Points of a cloud whose normal or radius is estimated.
    pub completed: u64,
}

impl BuildCost {
    /// Estimated seconds (module docs).
    pub fn seconds(&self) -> f64 {
        let sampling = match self.method {
            Some(SamplingMethod::BlueNoise) => BLUE_NOISE_SECONDS_PER_SAMPLE,
            Some(SamplingMethod::Stratified) => STRATIFIED_SECONDS_PER_SAMPLE,
            None => 0.0,
        };
        self.triangles as f64 * SECONDS_PER_TRIANGLE
            + self.surfels as f64 * (sampling + BUILD_SECONDS_PER_SURFEL)
            + self.completed as f64 * COMPLETION_SECONDS_PER_POINT
    }

    /// Peak host memory (module docs).
    pub fn footprint(&self) -> Footprint {
        let n = self.surfels;
        let surfel = std::mem::size_of::<Surfel>() as u64;
        let first = match self.method {
            Some(method) => n.saturating_mul(bytes_per_sample(method)),
            None => self.completed.saturating_mul(COMPLETION_BYTES_PER_POINT),
        };
        let build = n.saturating_mul(surfel + BUILD_BYTES_PER_SURFEL);
        // Writing: the surfels, the tree (1.6 nodes a surfel) and its bytes.
        let node = std::mem::size_of::<crate::points::build::spt::SptNode>() as u64;
        let write = n.saturating_mul(surfel + 8 * (node + FILE_BYTES_PER_NODE) / 5);
        Footprint::host(first.max(build).max(write))
    }

    /// One line for the log.
    pub fn summary(&self) -> String {
        format!(
            "{} surfels{}: about {} and {} of host memory",
            self.surfels,
            if self.triangles > 0 {
                format!(" from {} triangles", self.triangles)
            } else {
                String::new()
            },
            format_duration(self.seconds()),
            format_bytes(self.footprint().host)
        )
    }

    /// Refuses the build when its memory exceeds `limits` or its time
    /// `max_seconds`, naming `option` (`--samples N` for a mesh, the file
    /// for a cloud) and `--max-hours`.
    pub fn check(&self, option: &str, limits: &MemoryLimits, max_seconds: f64) -> Result<()> {
        let what = format!("{} surfels", self.surfels);
        limits.check(option, &what, self.footprint())?;
        let what = match self.method {
            Some(SamplingMethod::BlueNoise) => format!(
                "sampling {} surfels by blue noise and building their tree",
                self.surfels
            ),
            Some(SamplingMethod::Stratified) => format!("sampling {} surfels and building their tree", self.surfels),
            None => format!("building the tree of {} points", self.surfels),
        };
        check_duration(option, &what, self.seconds(), max_seconds, "--max-hours")
    }
}

/// Checks `input`, read from `path`, for a build with `sampling` and
/// `options` (module docs) and returns its cost. Errors name `path`, or
/// `--samples` or `--epsilon` and `path` where the option is at fault.
pub fn plan_build(
    path: &Path,
    input: &PointInput,
    sampling: &SamplingOptions,
    options: &SptOptions,
) -> Result<BuildCost> {
    let bad = |message: String| Error::input(path, message);
    let (cost, lo, hi, radius) = match input {
        PointInput::Mesh(mesh) => {
            let (lo, hi, radius) = check_mesh(path, mesh, sampling)?;
            let cost = BuildCost {
                surfels: sampling.count as u64,
                triangles: mesh.triangles.len() as u64,
                method: Some(sampling.method),
                completed: 0,
            };
            (cost, lo, hi, radius)
        }
        PointInput::Points(cloud) => {
            let (lo, hi, radius, completed) = check_cloud(cloud).map_err(bad)?;
            let cost = BuildCost {
                surfels: cloud.positions.len() as u64,
                triangles: 0,
                method: None,
                completed,
            };
            (cost, lo, hi, radius)
        }
    };
    // The root's errors are at most about the box's diagonal plus a disk.
    let reach = (hi - lo).length() + 2.0 * radius;
    let fits = |v: f64| v.is_finite() && v <= f64::from(f32::MAX);
    if !fits(4.0 * hi.abs().max(lo.abs()).max_element()) || !fits(4.0 * reach) {
        return Err(bad(format!(
            "coordinates too large: the model spans {reach:.3e} units, beyond the tree's f32 values"
        )));
    }
    if !fits(4.0 * reach / f64::from(options.epsilon)) {
        return Err(Error::invalid(
            "--epsilon",
            format!(
                "ε = {:e} is too small for the {reach:.3e}-unit model of {}: r_min = e_g/ε overflows f32",
                options.epsilon,
                path.display()
            ),
        ));
    }
    Ok(cost)
}

/// The mesh checks of the module docs: the bounding box of the used
/// vertices and the sample radius.
fn check_mesh(path: &Path, mesh: &TriangleMesh, sampling: &SamplingOptions) -> Result<(DVec3, DVec3, f64)> {
    let count = sampling.count;
    if count == 0 {
        return Err(Error::invalid("--samples", "0: a mesh needs at least one sample"));
    }
    if sampling.method == SamplingMethod::BlueNoise && count.saturating_mul(BLUE_NOISE_CANDIDATES) > u32::MAX as usize {
        return Err(Error::invalid(
            "--samples",
            format!(
                "{count} is more than blue noise can take ({}; --sampling stratified has no such limit)",
                u32::MAX as usize / BLUE_NOISE_CANDIDATES
            ),
        ));
    }
    let n = mesh.positions.len();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mut area = 0.0f64;
    for (t, indices) in mesh.triangles.iter().enumerate() {
        let mut corners = [DVec3::ZERO; 3];
        for (corner, &i) in corners.iter_mut().zip(indices) {
            let p = *mesh
                .positions
                .get(i as usize)
                .ok_or_else(|| Error::input(path, format!("triangle {t} uses vertex {i} of {n}")))?;
            if !p.is_finite() {
                return Err(Error::input(path, format!("triangle {t} has a non-finite vertex")));
            }
            *corner = p.as_dvec3();
            lo = lo.min(*corner);
            hi = hi.max(*corner);
        }
        // As the sampler weighs triangles: degenerate ones are skipped.
        let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let a = 0.5 * cross.length();
        if a > 0.0 && a.is_finite() && cross.normalize_or_zero().as_vec3().normalize_or_zero() != Vec3::ZERO {
            area += a;
        }
    }
    if !(area > 0.0 && area.is_finite()) {
        return Err(Error::input(
            path,
            format!(
                "no triangle with a positive, finite area (of {}); nothing to sample",
                mesh.triangles.len()
            ),
        ));
    }
    let radius = ((area / (std::f64::consts::PI * count as f64)).sqrt() as f32) * sampling.method.radius_overlap();
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::input(
            path,
            format!("the surface area {area:e} is too small for --samples {count}: the disks' radius underflows"),
        ));
    }
    Ok((lo, hi, f64::from(radius)))
}

/// The cloud checks of the module docs: the bounding box, the largest
/// given radius and the points whose normal or radius is estimated.
fn check_cloud(cloud: &PointCloud) -> std::result::Result<(DVec3, DVec3, f64, u64), String> {
    let n = cloud.positions.len();
    if n == 0 {
        return Err("no points".into());
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (i, p) in cloud.positions.iter().enumerate() {
        if !p.is_finite() {
            return Err(format!("point {i} is not finite ({p})"));
        }
        lo = lo.min(p.as_dvec3());
        hi = hi.max(p.as_dvec3());
    }
    let needs_normals = cloud.normals.as_ref().map_or(true, |normals| {
        normals.iter().any(|v| v.normalize_or_zero() == Vec3::ZERO)
    });
    let valid = |r: &f32| r.is_finite() && *r > 0.0;
    let needs_radii = cloud.radii.as_ref().map_or(true, |radii| !radii.iter().all(valid));
    if needs_normals && n < 3 {
        return Err(format!(
            "{n} point(s) without normals: estimating them needs at least 3"
        ));
    }
    if needs_radii && n < 2 {
        return Err("1 point without a radius: estimating it needs at least 2".into());
    }
    if needs_radii && lo == hi {
        return Err(format!(
            "all {n} points lie at {}: their radii cannot be estimated",
            lo.as_vec3()
        ));
    }
    let largest = cloud
        .radii
        .as_ref()
        .map_or(0.0, |radii| radii.iter().copied().filter(valid).fold(0.0f32, f32::max));
    let completed = if needs_normals || needs_radii { n as u64 } else { 0 };
    Ok((lo, hi, f64::from(largest), completed))
}

#[cfg(test)]
#[path = "plan_tests.rs"]
mod tests;
