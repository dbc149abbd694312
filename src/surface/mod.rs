//! What the techniques share: the ground surface and the surface material,
//! below every technique folder (terrain, texturing, points, lighting, …),
//! which import from here and never from each other in a cycle.
//!
//! * The ground surface: [`bspline`], the cubic B-spline through the height
//!   samples (the sketch atlas of geometry image warping, dissertation §7.4),
//!   and [`wavelet_noise`], the procedural detail of §7.4.3 that the terrain
//!   displaces and bump-maps with and the surface layers evaluate (§8.2).
//! * The surface material (dissertation §8.2, Table 8.1): [`layers`], the
//!   surface-layer tree (TOML file, built-in default, coverage, the CPU
//!   reference evaluation); [`input_maps`], the rainfall, radiation and
//!   temperature maps registered to the height field, and
//!   [`blurred_height`], the blurred height fields of `height_blur` layers
//!   (§8.2.3); [`gpu_layout`], the layers buffer the shaders read
//!   (`glsl/include/surface_layers.glsl`) and the per-frame texturing
//!   constants; [`dominant`], the dominant layer of a point (the class
//!   AOV); [`plants`], the plant models a layer's vegetation names
//!   (§6.2.1; built into point trees by the points technique).
pub mod blurred_height;
pub mod bspline;
pub mod dominant;
pub mod gpu_layout;
pub mod input_maps;
pub mod layers;
pub mod plants;
pub mod wavelet_noise;
