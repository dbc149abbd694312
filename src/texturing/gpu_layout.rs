//! What the texturing shaders read (`glsl/include/surface_layers.glsl`): the
//! layer tree as a flat depth-first array, and the per-frame constants.

use bytemuck::{Pod, Zeroable};

use super::layers::{Hat, LayerTree};

/// How the terrain is coloured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TexturingMode {
    /// Surface types from altitude, slope and orientation (§7.4.3 "Colour").
    Classic,
    /// The surface-layer tree evaluated per pixel (§8.2; the reference of the atlas).
    Direct,
    /// The surface-layer tree evaluated into cached tiles of a texture atlas
    /// (§8.2), sampled through a per-frame page table.
    #[default]
    Atlas,
}

impl TexturingMode {
    /// Value of `TerrainTexturing.handles.w` in the shaders.
    pub fn code(self) -> u32 {
        match self {
            TexturingMode::Classic => 0,
            TexturingMode::Direct => 1,
            TexturingMode::Atlas => 2,
        }
    }
}

/// One layer (`SurfaceLayer` in surface_layers.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuLayer {
    /// Linear colour, roughness B_S.
    pub color_roughness: [f32; 4],
    /// c_S, n_S, coverage-noise wavelength, displacement-noise wavelength.
    pub noise: [f32; 4],
    /// Hats (min, max, fuzz, 1 = used): altitude, elevation, slope, rainfall, radiation, temperature.
    pub hats: [[f32; 4]; 6],
    /// Parent index (u32::MAX: root), level, 0, 0.
    pub tree: [u32; 4],
}

fn hat(h: Option<Hat>) -> [f32; 4] {
    h.map_or([0.0; 4], |h| [h.min, h.max, h.fuzz, 1.0])
}

/// The tree in evaluation order.
pub fn pack_layers(tree: &LayerTree) -> Vec<GpuLayer> {
    tree.layers
        .iter()
        .map(|flat| {
            let l = &flat.layer;
            GpuLayer {
                color_roughness: l.color.extend(l.roughness).to_array(),
                noise: [l.noise_bias, l.noise_scale, l.noise_wavelength, l.roughness_wavelength],
                hats: [
                    hat(l.altitude),
                    hat(l.elevation),
                    hat(l.slope),
                    hat(l.inputs[0]),
                    hat(l.inputs[1]),
                    hat(l.inputs[2]),
                ],
                tree: [flat.parent.map_or(u32::MAX, |p| p as u32), flat.level as u32, 0, 0],
            }
        })
        .collect()
}

/// Per-frame constants of terrain texturing (`TerrainTexturing`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct TexturingFrame {
    /// Layers (storage), sketch atlas heights (sampled), noise tile (sampled), mode.
    pub handles: [u32; 4],
    /// Height-field columns, rows, layer count, 0.
    pub grid: [u32; 4],
    /// Sample spacing x, y (metres), lowest and highest height.
    pub spacing_range: [f32; 4],
    /// Page table (storage), atlas texture count, atlas size (texels), 0.
    pub atlas: [u32; 4],
    /// Terrain rectangle x, y (metres), 0, 0.
    pub extent: [f32; 4],
    /// Input maps (sampled handles: rainfall, radiation, temperature), bit k
    /// of w set when map k is present.
    pub maps: [u32; 4],
    /// Sampled handles of the atlas colour textures, in texture order.
    pub color: [u32; 32],
    /// Sampled handles of the atlas normal textures.
    pub normal: [u32; 32],
    /// terrain.draw: view ([`crate::terrain::geometry_image::TerrainView::code`]),
    /// detail on (0/1), grid side N, 0.
    pub draw: [u32; 4],
}
