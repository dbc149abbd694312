//! The physical atmosphere, the second sky model ([`crate::view::SkyModel::Physical`]):
//! Rayleigh, Mie and ozone with single and multiple scattering precomputed
//! every frame into small lookup tables by compute passes, after Hillaire
//! 2020 ("A Scalable and Production Ready Sky and Atmosphere Rendering
//! Technique", EGSR) with Bruneton 2017's Earth and transmittance
//! parameterisation ("A Qualitative and Quantitative Evaluation of 8 Clear
//! Sky Models", TVCG). The dissertation's sky is Preetham's (§6.3, §9.1);
//! this model goes beyond the text and is right for a low sun.
//!
//! - [`AtmosphereParameters`]: the Earth defaults, the turbidity mapping,
//!   [`AtmosphereParameters::fill`] for the LightingFrame.
//! - [`PhysicalAtmosphere`]: the tables and the passes
//!   (`lighting.transmittance` 256×64, `lighting.multiscattering` 32×32,
//!   `lighting.sky_view` 192×108 per view); [`AtmosphereLuts`] names the
//!   graph images every consumer declares as sampled reads.
//! - [`sun_transmittance`]: the CPU twin of the transmittance table, for the
//!   sun's radiance at the ground.
//!
//! Per frame, for each view: fill its `LightingFrame` (ground altitude in
//! `mie[3]` first), then the atmosphere's part, and upload it; a consumer
//! declares sampled reads of the view's tables:
//!
//! ```text
//! let atmosphere = PhysicalAtmosphere::new(&ctx, &AtmosphereParameters::default(), LutSizes::default(), views)?;
//! let luts = atmosphere.declare(&mut graph, &[(view.name.as_str(), lighting_region)])?;
//! let mut pass = graph.pass("sky").graphics();
//! let tables = luts.reads(view_index)?.map(|id| pass.sample(id, Stage::Fragment));
//! // prepare: AtmosphereParameters::for_turbidity(lighting.turbidity)?.fill(&mut frame);
//! //          atmosphere.fill_altitude(view_index, camera.eye.z, &mut frame)?;
//! // record (the pass that writes the constants): frame.atmosphere[..3] = ctx.handle(tables[i])?
//! //          frame.sun_radiance from sun_transmittance(&params, eye altitude, sun) × disc radiance
//! ```
//!
//! Radiance is absolute: linear sRGB with luminance in cd/m², the solar
//! irradiance at the top of the atmosphere being the extraterrestrial sun
//! luminance × colour × the disc's solid angle ([`solar_irradiance`]), the
//! Preetham sky's scale. GLSL: `glsl/include/atmosphere_physical.glsl`,
//! `glsl/include/sky_physical.glsl`.

mod parameters;
mod passes;
mod twin;

pub use parameters::AtmosphereParameters;
pub use passes::{LutSizes, PhysicalAtmosphere};
pub use twin::sun_transmittance;
#[cfg(test)]
pub use twin::{transmittance_lut_r_mu, transmittance_to_top};
