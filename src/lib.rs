//! alpenglow: a Vulkan-native, low-level renderer for large outdoor scenes.
//!
//! Layers, bottom up (each uses only the ones below it):
//! [`vulkan`] (the only `unsafe` code) → [`graph`] (render graph: passes
//! declare reads and writes; baking derives barriers) → [`view`] (cameras,
//! views, the frame's shared targets and uploads) → the techniques
//! ([`terrain`], [`synthesis`], [`texturing`], [`lighting`],
//! [`points`], [`post`]) →
//! [`renderer`] (composition: scenes, frames, outputs) → the CLI (binary
//! only). [`io`], [`budget`] (the memory model), [`profile`], [`random`],
//! [`shaders`] and [`error`] are leaves every layer may use.
//!
//! Every module but [`vulkan`] is `#[forbid(unsafe_code)]`.

#[forbid(unsafe_code)]
pub mod budget;
#[forbid(unsafe_code)]
pub mod error;
#[forbid(unsafe_code)]
pub mod graph;
#[forbid(unsafe_code)]
pub mod io;
#[forbid(unsafe_code)]
pub mod lighting;
#[forbid(unsafe_code)]
pub mod points;
#[forbid(unsafe_code)]
pub mod post;
#[forbid(unsafe_code)]
pub mod profile;
#[forbid(unsafe_code)]
pub mod random;
#[forbid(unsafe_code)]
pub mod renderer;
#[forbid(unsafe_code)]
pub mod shaders;
#[forbid(unsafe_code)]
pub mod synthesis;
#[forbid(unsafe_code)]
pub mod terrain;
#[forbid(unsafe_code)]
pub mod texturing;
#[forbid(unsafe_code)]
pub mod view;
pub mod vulkan;

/// Helpers shared by the in-crate white-box tests (validated context, FLIP,
/// goldens, the Jacksboro DEM).
#[cfg(test)]
#[forbid(unsafe_code)]
pub(crate) mod test_support;

pub use error::{Error, Result};
