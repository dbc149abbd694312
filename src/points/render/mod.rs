//! Rendering of sequential point trees with splats (dissertation §10.1.7,
//! §10.2, §10.3; `ALGORITHMS.md` §7–8), as render-graph passes that follow
//! the three passes of Table 10.1:
//!
//! | pass | mode | what |
//! |---|---|---|
//! | (`prepare`) | both | CPU prefix per instance ([`selection`]) and instance records, before recording ([`PointRenderer`]) |
//! | `points.visibility` | ewa | depth: ray–plane depth pushed back by ε; the ids of the winning surfel |
//! | `points.accumulate` | ewa | depth test ≤ without writes, additive (w·colour, w), (w·normal, w·depth) into float targets; the ids of the last surfel |
//! | `points.normalize` | ewa | compute, per pixel: divide by w, shade, write radiance, view depth, W, world normal and ids (the winner's, else the last surfel's) |
//! | `points.clear`, `points.visibility`, `points.accumulate`, `points.normalize` | ewa, compute path | the same three passes in compute ([`compute`]): 64-bit (depth, record) words and fixed-point integer sums, deterministic to the byte; with the terrain on the compute path too, tested against its visibility keys and normalized by `terrain.shade` (no `points.normalize`) |
//! | `points.opaque` | opaque | opaque discs with ray–plane depth, shaded directly, with normal and ids |
//! | `points.clear`, `points.opaque`, `points.opaque.resolve` | opaque, compute path | the nearest (depth, splat index) word per pixel by 64-bit `atomicMax`, the winner shaded per pixel ([`compute_opaque`]) |
//! | `points.single_pass.triangles` | single-pass | hybrid triangles as opaque shaded triangles with depth, when the scene has any |
//! | `points.single_pass.clear` | single-pass, compute | every tile's cut mark, range and the sort state 0 (§10.4; interlock: every pixel's state z_d = +inf, sums 0) |
//! | `points.single_pass.count` | single-pass, compute | per splat: EWA set-up kept with its pixels and reach (a lower bound of its samples' depth less z_f), the reach range, each workgroup's entries (8×8-pixel tiles the box touches) |
//! | `points.single_pass.prefix` | single-pass, compute | one workgroup: each binning workgroup's first entry, the frame's entries, the sort key's layout |
//! | `points.single_pass.scatter` | single-pass, compute | per kept splat: (key = tile, reach; slot; the tile's 4×2 blocks its box touches) at positions fixed by draw order |
//! | `points.single_pass.radix{0..2}.{count,scan,scatter}` | single-pass, compute | a stable LSD radix sort of the entries' keys, 8 bits a pass (3 passes at 512², 4 from 2¹³ tiles): each tile's list a slice, front to back |
//! | `points.single_pass.ranges` | single-pass, compute | per sorted entry: where its tile's slice starts and ends, into the tile's range words |
//! | `points.single_pass.merge` | single-pass, compute | a workgroup per tile, no barrier: each subgroup walks the sorted slice (dropped whole and counted if the capacity cut it) from memory, the fuzzy depth test (§10.4) front to back per pixel until the reach passes every z_d, normalised and shaded, written once |
//! | `points.single_pass` | single-pass, interlock | raster pass: every splat fragment merged with the fuzzy depth test (§10.4) in a pixel-ordered critical section |
//! | `points.single_pass.resolve` | single-pass, interlock | compute: as `points.normalize`, from the pixel state |
//!
//! The primitives `object-quad` and `object-instanced` ([`object_space`],
//! §10.3) draw the same passes with object-space quads and the kernel in a
//! texture instead of the screen-space EWA set-up.
//!
//! On the compute raster path (`--raster compute`, the default where the
//! device has 64-bit buffer atomics) EWA and opaque splats are drawn by
//! compute passes ([`compute`], [`compute_opaque`], issue 29); the
//! primitives are the hardware path's.
//!
//! The graph derives every barrier between them. Shaders: `glsl/points/`.

mod compute;
mod compute_opaque;
pub mod gpu_layout;
pub mod object_space;
mod passes;
mod pipeline_spec;
pub mod selection;
pub mod shadow;
mod single_pass;
pub mod stats;
mod technique;
mod triangles;

#[cfg(test)]
pub(crate) use single_pass::with_entry_capacity;
#[cfg(test)]
pub(crate) use single_pass::{with_radix_sort, RadixSort};
pub use stats::PointFrameStats;
pub use technique::{PointRenderer, PointsFrame};

use crate::error::{Error, Result};

/// How splats are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SplatMode {
    /// Opaque discs in one pass: the fast baseline.
    Opaque,
    /// Perspective-accurate EWA splatting in three passes (§10.2).
    #[default]
    Ewa,
    /// The same kernels in one pass with a fuzzy depth test (§10.4): each
    /// fragment nearer than z_d − z_fuzzy replaces the pixel's splats, one
    /// within ±z_fuzzy blends by weight, z_fuzzy = `visibility_offset` ×
    /// the incoming splat's radius; see [`SplatBackend`].
    SinglePass,
}

/// How single-pass splatting (§10.4) orders each pixel's merges (the
/// fuzzy-depth operator is not commutative).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SplatBackend {
    /// Compute passes, tile-binned (§10.4 with the tile order of 3D Gaussian
    /// splatting): the splats' boxes binned into 8×8-pixel tiles, the
    /// entries radix-sorted by (tile, reach: the nearest depth a sample can
    /// have less z_f; ties in draw order)
    /// and each tile's list merged front to back per pixel in registers,
    /// then shaded. No locks,
    /// deterministic (two renders are byte-identical), the same on every
    /// device. Tile entries beyond the entry buffer's capacity drop whole
    /// tiles' lists, counted in [`PointFrameStats::tile_entries_dropped`].
    #[default]
    Compute,
    /// A raster pass whose fragments merge inside a pixel-ordered critical
    /// section (VK_EXT_fragment_shader_interlock,
    /// `fragmentShaderPixelInterlock`): merges follow primitive order.
    Interlock,
}

/// The screen-space reconstruction kernel of a splat (§10.2, Figs. 10.15–10.17).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SplatKernel {
    /// Perspective-accurate splatting (§10.2.2): the exact projection of the
    /// splat's cut-off ellipse (a conic through the homogeneous map T),
    /// convolved with the screen-space low-pass filter.
    #[default]
    Perspective,
    /// The affine EWA approximation of Zwicker et al. 2001 that the text
    /// compares it with: the object-space Gaussian mapped through the
    /// Jacobian of the projection at the splat centre, convolved with the
    /// low-pass filter, centred on the projected centre. Cheaper to set up,
    /// but its footprints shrink and shift against the true ones at grazing
    /// angles and near silhouettes.
    Affine,
}

impl SplatKernel {
    pub const ALL: [SplatKernel; 2] = [SplatKernel::Perspective, SplatKernel::Affine];

    pub fn name(self) -> &'static str {
        match self {
            SplatKernel::Perspective => "perspective",
            SplatKernel::Affine => "affine",
        }
    }

    /// The kernel's code in the frame header (`SPLAT_KERNEL_*` in splat_setup.glsl).
    pub(crate) fn code(self) -> u32 {
        match self {
            SplatKernel::Perspective => 0,
            SplatKernel::Affine => 1,
        }
    }
}

/// The error a sequential point tree's interval test uses (§10.1.4, §10.1.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SptError {
    /// The geometric error `e_g = sqrt(e_p² + e_t²)`: the stored interval
    /// `r_min ≤ r < r_max`, the same at every view angle.
    #[default]
    Isotropic,
    /// The split error `e_p·sin α + e_t·cos α` (α between the view vector
    /// and the node's normal), tested exactly in the vertex stage against
    /// the node's and its parent's view-dependent `r_min`
    /// ([`crate::points::build::spt_view`]): fewer splats where surfaces
    /// are seen face-on (bumps) or at grazing angles (flat parts); the
    /// CPU prefix is the isotropic one.
    ViewDependent,
}

impl SptError {
    pub const ALL: [SptError; 2] = [SptError::Isotropic, SptError::ViewDependent];

    pub fn name(self) -> &'static str {
        match self {
            SptError::Isotropic => "isotropic",
            SptError::ViewDependent => "view-dependent",
        }
    }

    /// The test's code in the frame header (`SPT_ERROR_*` in spt_interval.glsl).
    pub(crate) fn code(self) -> u32 {
        match self {
            SptError::Isotropic => 0,
            SptError::ViewDependent => 1,
        }
    }
}

/// The primitive that carries a splat (§10.3, Table 10.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SplatPrimitive {
    /// Point primitives covering the splat's bounding square; splats larger
    /// than the device's largest point size fall back to quads.
    Point,
    /// Quads by vertex pulling: six vertices per splat read the same splat
    /// record (no duplicated splat data).
    #[default]
    Quad,
    /// Instanced quads: one instance of six vertices per splat.
    Instanced,
    /// The text's quadruplication (§10.3, Table 10.3): object-space quads in
    /// the splat's tangent plane with the kernel in a texture, the splat data
    /// duplicated into 4 vertices per splat, 6 indices (no EWA set-up).
    ObjectQuad,
    /// The text's instancing (§10.3, Table 10.3): one 4-vertex object-space
    /// quad instanced per splat with per-instance splat attributes, the
    /// kernel in a texture (no EWA set-up).
    ObjectInstanced,
}

impl SplatMode {
    pub const ALL: [SplatMode; 3] = [SplatMode::Opaque, SplatMode::Ewa, SplatMode::SinglePass];

    pub fn name(self) -> &'static str {
        match self {
            SplatMode::Opaque => "opaque",
            SplatMode::Ewa => "ewa",
            SplatMode::SinglePass => "single-pass",
        }
    }
}

impl SplatBackend {
    pub const ALL: [SplatBackend; 2] = [SplatBackend::Compute, SplatBackend::Interlock];

    pub fn name(self) -> &'static str {
        match self {
            SplatBackend::Compute => "compute",
            SplatBackend::Interlock => "interlock",
        }
    }
}

impl SplatPrimitive {
    pub const ALL: [SplatPrimitive; 5] = [
        SplatPrimitive::Point,
        SplatPrimitive::Quad,
        SplatPrimitive::Instanced,
        SplatPrimitive::ObjectQuad,
        SplatPrimitive::ObjectInstanced,
    ];
    /// alpenglow's primitives: the screen-space EWA set-up in the vertex stage (§10.2.2).
    pub const SCREEN_SPACE: [SplatPrimitive; 3] =
        [SplatPrimitive::Point, SplatPrimitive::Quad, SplatPrimitive::Instanced];
    /// The text's object-space quads with the kernel in a texture (§10.3).
    pub const OBJECT_SPACE: [SplatPrimitive; 2] = [SplatPrimitive::ObjectQuad, SplatPrimitive::ObjectInstanced];

    pub fn name(self) -> &'static str {
        match self {
            SplatPrimitive::Point => "point",
            SplatPrimitive::Quad => "quad",
            SplatPrimitive::Instanced => "instanced",
            SplatPrimitive::ObjectQuad => "object-quad",
            SplatPrimitive::ObjectInstanced => "object-instanced",
        }
    }

    /// Whether the splat is an object-space quad with the kernel in a texture (§10.3).
    pub fn is_object_space(self) -> bool {
        Self::OBJECT_SPACE.contains(&self)
    }
}

/// Settings of point rendering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplatSettings {
    pub mode: SplatMode,
    pub primitive: SplatPrimitive,
    /// Kernel cut-off F_G in standard deviations (1 < F_G < 2, §10.2.2); the
    /// cut-off ellipse is the splat's disk.
    pub cutoff: f32,
    /// Visibility pass offset ε along the view ray, in splat radii (§10.2.3);
    /// single-pass mode's z_fuzzy is ε × the incoming splat's radius (§10.4).
    pub visibility_offset: f32,
    /// Shade splats (sun, sky, haze); false writes their albedo (tests, debugging).
    pub shaded: bool,
    /// Draw back-facing splats too (open surfaces such as leaves); by default
    /// they are culled, as for the closed surfaces of scans and rocks.
    pub two_sided: bool,
    /// Split every list into 128 normal clusters and skip clusters that face
    /// away (§10.1.10); only for closed surfaces.
    pub normal_clusters: bool,
    /// Error threshold ε of the trees (as [`crate::points::build::spt::SptOptions::epsilon`]);
    /// None keeps the ε each tree was built with.
    pub epsilon: Option<f32>,
    /// The single-pass mode's backend (§10.4); ignored by the other modes.
    pub backend: SplatBackend,
    /// The screen-space kernel of the screen-space primitives (every mode
    /// and path); the object-space primitives take only the perspective one.
    pub kernel: SplatKernel,
    /// The error of the interval test (§10.1.4, §10.1.7); view-dependent
    /// needs a screen-space primitive (every mode and path, and the shadow
    /// casters).
    pub error: SptError,
}

impl Default for SplatSettings {
    fn default() -> Self {
        SplatSettings {
            mode: SplatMode::Ewa,
            primitive: SplatPrimitive::Quad,
            cutoff: 1.5,
            visibility_offset: 1.0,
            shaded: true,
            two_sided: false,
            normal_clusters: false,
            epsilon: None,
            backend: SplatBackend::Compute,
            kernel: SplatKernel::Perspective,
            error: SptError::Isotropic,
        }
    }
}

impl SplatSettings {
    /// Checks the numbers.
    pub fn validate(&self) -> Result<()> {
        if self.mode == SplatMode::SinglePass && self.primitive != SplatPrimitive::Quad {
            return Err(Error::invalid(
                "points.primitive",
                format!(
                    "{}: single-pass splatting rasterises its splats itself (compute) or as quads (interlock); \
                     the primitive applies to the ewa and opaque modes",
                    self.primitive.name()
                ),
            ));
        }
        if self.kernel != SplatKernel::Perspective && self.primitive.is_object_space() {
            return Err(Error::invalid(
                "points.kernel",
                format!(
                    "{}: the {} primitive draws object-space quads with the kernel in a texture (§10.3); \
                     only the screen-space primitives (point, quad, instanced) take the affine kernel",
                    self.kernel.name(),
                    self.primitive.name()
                ),
            ));
        }
        if self.error != SptError::Isotropic && self.primitive.is_object_space() {
            return Err(Error::invalid(
                "points.error",
                format!(
                    "{}: the {} primitive reads each splat as vertex attributes without its parent; \
                     only the screen-space primitives (point, quad, instanced) take the view-dependent test",
                    self.error.name(),
                    self.primitive.name()
                ),
            ));
        }
        if !(self.cutoff > 1.0 && self.cutoff < 2.0) {
            return Err(Error::invalid(
                "splat cut-off",
                format!("{}; must be in (1, 2)", self.cutoff),
            ));
        }
        if !(self.visibility_offset.is_finite() && self.visibility_offset >= 0.0) {
            return Err(Error::invalid(
                "visibility offset",
                format!("{}; must be ≥ 0", self.visibility_offset),
            ));
        }
        if self.normal_clusters && self.two_sided {
            return Err(Error::invalid(
                "normal clusters",
                "they cull back faces and cannot be combined with two-sided splats",
            ));
        }
        if let Some(e) = self.epsilon {
            if !(e.is_finite() && e > 0.0) {
                return Err(Error::invalid(
                    "points.epsilon",
                    format!("{e} is not a positive number"),
                ));
            }
        }
        Ok(())
    }
}
