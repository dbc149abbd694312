//! Post-processing: what turns the frame's HDR radiance into its outputs.

pub mod aovs;
pub mod exposure;
pub mod tonemap;
