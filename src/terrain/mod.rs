//! Terrain: procedural height fields (§6.1) and terrain LOD by geometry
//! image warping (§7.4). The files follow Fig. 7.8: [`sketch_map`] →
//! [`importance`] → [`warp`] (combined per frame by [`lod`], in
//! [`Terrain`]'s `prepare`) → [`geometry_image`] (`terrain.warp`) →
//! [`shading`] (`terrain.draw`); [`technique`] ties them into the frame.
//! [`ground`] is the CPU twin of the drawn surface, for height queries. The
//! cubic B-spline and the wavelet noise of the detail octaves are shared
//! with the other techniques (`crate::surface::bspline`,
//! `crate::surface::wavelet_noise`).

pub mod detail;
pub mod geometry_image;
pub mod ground;
pub mod importance;
// Fig. 6.1's value and lattice convolution noise: only its tests use them.
#[cfg(test)]
mod lattice_noise;
pub mod lod;
pub mod procedural;
pub mod raycast;
pub mod shading;
pub mod shadow;
pub mod sketch_map;
pub mod swimming;
pub mod technique;
pub mod visibility;
pub mod warp;
pub mod zoom;

pub use technique::{Terrain, TerrainFrame, TerrainTexturing};

#[cfg(test)]
mod tests;
