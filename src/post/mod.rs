//! Post-processing: what turns the frame's HDR radiance into its outputs.
//! The resampling passes of the simulator cameras (§3.3) work on lists of a
//! view's images ([`resample`]): [`resolve`] (anti-aliasing), [`distortion`]
//! (lens distortion); [`motion_blur`] blurs the radiance.

pub mod aovs;
pub mod distortion;
pub mod exposure;
pub mod motion_blur;
pub mod overlay;
pub mod present;
pub mod resample;
pub mod resolve;
pub mod tonemap;

#[cfg(test)]
mod tests;
