//! The Monte Carlo reference of sky light on the terrain (dissertation §9.2:
//! "references computed by Monte Carlo ray tracing"; `ALGORITHMS.md` §6):
//! distributed ray tracing of the height field under the frame's sky and
//! sun, 0–2 interreflection bounces, a fixed seed. Every cheaper sky-light
//! method (SH transfer, AO, sky patches; §9.3–9.5) is compared against it.
//!
//! # The surface
//!
//! The height field as bilinear patches: sample `(c, r)` at world
//! `(c·dx, r·dy, h[c, r])`, the cell `[c, c+1] × [r, r+1]` interpolating its
//! four corners bilinearly; outside the rectangle there is no surface. Each
//! texel is estimated at its sample point with the normal from central
//! differences of the heights (one-sided at the border). A hit point `y`
//! inside a cell is shaded with the bilinear interpolation of its corners'
//! normals (renormalised). Rays are intersected exactly with the patches
//! (along a ray each patch is a quadratic in `t`); a ray hits where it goes
//! from on-or-above to below the surface. Ray origins are lifted by
//! [`ray_offset`] along +Z (always above a height field).
//!
//! (The renderer draws the uniform cubic B-spline of its samples, §7.4,
//! which does not pass through them; so it hands the reference, as the
//! sky-light bake, the B-spline at the samples,
//! [`crate::surface::bspline::knot_field`]: on steep relief the raw
//! samples' deeper valleys see up to 0.02 less sky than the drawn surface.)
//!
//! # The quantity (what the maps hold)
//!
//! Let `E` be the environment: the sky (`sky_radiance`, without the sun's
//! disc) and, **only when** `LIGHTING_SUN_IN_ENVIRONMENT` is set, the sun's
//! disc. Let the sun be the disc of angular radius `sun.w` around `sun.xyz`
//! with irradiance `sun_irradiance.rgb` on a plane facing it. The terrain
//! is Lambertian with albedo `ρ_b` (the frame's albedo override when
//! `LIGHTING_ALBEDO_OVERRIDE` is set, else [`ReferenceSettings::bounce_albedo`]).
//!
//! * `maps.x`.rgb, the **sky light per unit albedo**, is `L_o(x)/ρ(x)`: the
//!   radiance leaving `x` divided by its albedo, due to **everything except
//!   the direct sun at `x` itself when the sun is a separate term**:
//!   * the sky seen directly from `x` (cosine-weighted, occluded by terrain);
//!   * for `bounces ≥ 1`, light reflected once (twice for 2) by other
//!     terrain towards `x`: at each hit point `y` the sky it sees directly,
//!     and the direct sun at `y` (with a shadow ray) unless
//!     [`ReferenceSettings::sun_bounces`] is off and the sun is not in the
//!     environment;
//!   * when `LIGHTING_SUN_IN_ENVIRONMENT` is set, also the direct sun at `x`:
//!     `E_sun/π · max(0, n·s) · V_sun(x)`. The renderer must then not add
//!     its own direct sun term (set `LIGHTING_NO_SUN_DIRECT` with it).
//!
//!   A path of length `k + 1` (k bounces) contributes only for
//!   `k ≤ bounces`: with 0 bounces, rays that hit terrain add nothing
//!   (`T_x = (1/π)·max(0, n·ω)·V(x, ω)`, `ALGORITHMS.md` §6). This equals
//!   the SH transfer of eq. 9.9–9.11 with bounces of albedo `ρ_b` when the
//!   SH environment holds the same terms (set `sun_bounces = false` to
//!   compare with a transfer of the sky alone while the sun is separate).
//! * `maps.x`.a, the **sky visibility**: the fraction of cosine-weighted
//!   directions at `x` whose ray escapes the height field,
//!   `(1/π)∫ V(x, ω) max(0, n·ω) dω` (1 − ambient occlusion).
//! * `maps.z`, the **sun visibility**: the fraction of shadow rays towards
//!   points spread uniformly over the sun's disc that escape (geometric:
//!   neither the facing `n·s` nor the sun's elevation enter).
//!
//! A ray that escapes the field below the horizon (through the side of the
//! rectangle) sees the sky at the horizon in its azimuth ([`horizon_clamp`]).
//!
//! # The estimator
//!
//! Per texel, `samples` paths: the first direction from a stratified
//! (Hammersley, Cranley–Patterson-rotated per texel) cosine-weighted sample,
//! so that `(1/N) Σ L(x, ω_i)` estimates `L_o/ρ`; deeper directions and the
//! disc points of shadow rays from a per-texel hashed PCG ([`sampling`]).
//! Deterministic for a seed. The GPU pass (`glsl/lighting/reference.comp`,
//! [`MonteCarloReference`]) and the CPU twin ([`CpuReference`]) draw the same
//! random numbers, so they agree far within the Monte Carlo error.

#[cfg(test)]
mod cpu;
mod gpu;
mod pyramid;
#[cfg(test)]
pub mod sampling;
#[cfg(test)]
mod trace;

#[cfg(test)]
mod tests;

#[cfg(test)]
pub use cpu::{CpuReference, SunInput};
#[cfg(test)]
pub use gpu::ReferenceProgress;
pub use gpu::{MonteCarloReference, ReferenceWork};
#[cfg(test)]
pub use trace::HeightFieldTracer;

#[cfg(test)]
use glam::Vec3;

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;

/// Largest `samples` per texel.
pub const MAX_SAMPLES: u32 = 1 << 16;

/// Settings of the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSettings {
    /// Paths per texel (1..=65536).
    pub samples: u32,
    /// Interreflection bounces (0–2).
    pub bounces: u32,
    /// Seed of every random number.
    pub seed: u32,
    /// Albedo of the terrain at bounces when the frame has no albedo
    /// override (0–1).
    pub bounce_albedo: f32,
    /// With the sun a separate term: whether the sun lighting other terrain
    /// (bounced sun) is part of the map. The sun in the environment is
    /// always bounced.
    pub sun_bounces: bool,
    /// Rows per compute dispatch (bounds one dispatch's work).
    pub rows_per_dispatch: u32,
    /// Rows per frame (progressive: the map is complete after
    /// `rows / rows_per_frame` frames); `None`: the whole field each time
    /// the lighting changes.
    pub rows_per_frame: Option<u32>,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            samples: 256,
            bounces: 1,
            seed: 0x5EED_0013,
            bounce_albedo: 0.3,
            sun_bounces: true,
            rows_per_dispatch: 16,
            rows_per_frame: None,
        }
    }
}

impl ReferenceSettings {
    /// Checks every setting; the error names the one out of range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(Error::invalid(
                "lighting.reference.samples",
                format!("{}; must be in 1..={MAX_SAMPLES}", self.samples),
            ));
        }
        if self.bounces > 2 {
            return Err(Error::invalid(
                "lighting.reference.bounces",
                format!("{}; must be 0, 1 or 2", self.bounces),
            ));
        }
        if !(0.0..=1.0).contains(&self.bounce_albedo) {
            return Err(Error::invalid(
                "lighting.reference.bounce_albedo",
                format!("{}; must be in 0..=1", self.bounce_albedo),
            ));
        }
        if self.rows_per_dispatch == 0 || self.rows_per_frame == Some(0) {
            return Err(Error::invalid(
                "lighting.reference.rows_per_dispatch",
                "rows per dispatch and per frame must be positive",
            ));
        }
        Ok(())
    }
}

/// Checks that `field` can be ray traced: at least 2×2 samples, as many
/// heights as samples, finite positive spacing, finite heights.
pub(crate) fn validate_field(field: &HeightField) -> Result<()> {
    let what = "lighting.reference.height_field";
    let (w, h) = (field.columns, field.rows);
    if w < 2 || h < 2 {
        return Err(Error::invalid(
            what,
            format!("{w}×{h} samples; at least 2×2 are needed"),
        ));
    }
    if (w as usize).checked_mul(h as usize) != Some(field.heights.len()) {
        return Err(Error::invalid(
            what,
            format!("{} heights for a {w}×{h} grid", field.heights.len()),
        ));
    }
    let s = field.spacing;
    if !(s.is_finite() && s.x > 0.0 && s.y > 0.0) {
        return Err(Error::invalid(
            what,
            format!("spacing ({}, {}) must be finite and positive", s.x, s.y),
        ));
    }
    if field.heights.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid(what, "a height is not finite"));
    }
    Ok(())
}

/// The vertical lift of every ray origin (m): a thousandth of the smaller
/// spacing plus 10⁻⁵ of the largest |height| (f32 rounding of the GPU).
pub fn ray_offset(field: &HeightField) -> f32 {
    let (lo, hi) = field.min_max();
    let spacing = field.spacing.x.min(field.spacing.y) as f32;
    1e-3 * spacing + 1e-5 * lo.abs().max(hi.abs())
}

/// The direction an escaping ray sees the sky in: `dir` with a negative Z
/// clamped to the horizon (renormalised); straight down becomes the zenith.
#[cfg(test)]
pub fn horizon_clamp(dir: Vec3) -> Vec3 {
    let d = Vec3::new(dir.x, dir.y, dir.z.max(0.0));
    let len = d.length();
    if len > 1e-6 {
        d / len
    } else {
        Vec3::Z
    }
}
