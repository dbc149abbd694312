//! alpenglow: a Vulkan-native, low-level renderer for large outdoor scenes.
//!
//! Layers, bottom up: [`vulkan`] (the only `unsafe` code), [`graph`] (render
//! graph: passes declare reads and writes; baking derives barriers), the
//! techniques ([`terrain`], [`lighting`]), and [`renderer`] (scenes, frames,
//! outputs) used by the CLI.

pub mod error;
pub mod graph;
pub mod io;
pub mod lighting;
pub mod points;
pub mod profile;
pub mod random;
pub mod renderer;
pub mod shaders;
pub mod terrain;
pub mod texturing;
pub mod vulkan;

pub use error::{Error, Result};
