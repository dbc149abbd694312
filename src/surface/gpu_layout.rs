//! What the texturing shaders read (`glsl/include/surface_layers.glsl`): the
//! layer tree as a flat depth-first array, and the per-frame constants.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::input_maps::MapBindings;
use super::layers::{Constraint, LayerTree, MAX_BLUR_RADII};
use crate::error::Result;
use crate::graph::{Binding, PassBuilder, PassContext, RenderGraph, Stage, UploadRegion};

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
    /// Constraints ([`pack_constraint`]): altitude, elevation, slope,
    /// rainfall, radiation, temperature.
    pub hats: [[f32; 4]; 6],
    /// Parent index (u32::MAX: root), level, and for a `height_blur` layer
    /// the sampled handle of its blurred height field and 1 (else 0, 0).
    pub tree: [u32; 4],
}

/// The layers buffer: the layers in evaluation order, then the samples of
/// their sampled functions (floats).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackedLayers {
    pub layers: Vec<GpuLayer>,
    pub samples: Vec<f32>,
}

impl PackedLayers {
    /// The buffer's contents.
    pub fn bytes(&self) -> Vec<u8> {
        let mut bytes = bytemuck::cast_slice::<GpuLayer, u8>(&self.layers).to_vec();
        bytes.extend_from_slice(bytemuck::cast_slice(&self.samples));
        bytes
    }
}

/// Floats per [`GpuLayer`].
const LAYER_FLOATS: usize = std::mem::size_of::<GpuLayer>() / 4;

/// A constraint as the shader reads it: unused (0, 0, 0, 0); a hat
/// (min, max, fuzz, 1); a sampled function of n samples (min, max, index of
/// its first sample among the buffer's floats, 1 + n), its samples appended
/// to `samples` (which follow `layer_count` layers in the buffer).
pub fn pack_constraint(c: Option<&Constraint>, layer_count: usize, samples: &mut Vec<f32>) -> [f32; 4] {
    match c {
        None => [0.0; 4],
        Some(Constraint::Hat(h)) => [h.min, h.max, h.fuzz, 1.0],
        Some(Constraint::Sampled(s)) => {
            let first = layer_count * LAYER_FLOATS + samples.len();
            samples.extend_from_slice(&s.samples);
            [s.min, s.max, first as f32, 1.0 + s.samples.len() as f32]
        }
    }
}

/// The tree in evaluation order, with the samples of its sampled functions;
/// `blurred`: the sampled handle of the blurred height field of each
/// `height_blur` radius ([`crate::surface::input_maps::MapBindings::blurred_handles`]).
pub fn pack_layers(tree: &LayerTree, blurred: &[(f32, u32)]) -> PackedLayers {
    let count = tree.layers.len();
    let mut samples = Vec::new();
    let layers = (tree.layers.iter())
        .map(|flat| {
            let l = &flat.layer;
            let blur = (l.height_blur).and_then(|r| blurred.iter().find(|(radius, _)| *radius == r));
            let constraints = [
                l.altitude.as_ref(),
                l.elevation.as_ref(),
                l.slope.as_ref(),
                l.inputs[0].as_ref(),
                l.inputs[1].as_ref(),
                l.inputs[2].as_ref(),
            ];
            GpuLayer {
                color_roughness: l.color.extend(l.roughness).to_array(),
                noise: [l.noise_bias, l.noise_scale, l.noise_wavelength, l.roughness_wavelength],
                hats: constraints.map(|c| pack_constraint(c, count, &mut samples)),
                tree: [
                    flat.parent.map_or(u32::MAX, |p| p as u32),
                    flat.level as u32,
                    blur.map_or(0, |(_, handle)| *handle),
                    u32::from(blur.is_some()),
                ],
            }
        })
        .collect();
    PackedLayers { layers, samples }
}

/// The layers buffer ([`pack_layers`]) as an upload region of the frame
/// graph. It embeds the sampled handles of the blurred height fields, so
/// every pass that reads it also writes it, the same bytes each time, from
/// the blurred fields that pass declared ([`LayerTable::write`]).
#[derive(Clone, Debug)]
pub struct LayerTable {
    region: UploadRegion,
    /// The packed table with every blurred handle 0, made once.
    bytes: Arc<[u8]>,
    /// Per `height_blur` layer: the byte offset of its handle (`tree.z`)
    /// and its radius.
    blurred: Arc<[(u64, f32)]>,
}

impl LayerTable {
    /// Packs `tree` and declares its upload region in `graph`.
    pub fn declare<P: 'static>(graph: &mut RenderGraph<P>, tree: &LayerTree) -> LayerTable {
        let radii = tree.blur_radii().into_iter().take(MAX_BLUR_RADII);
        let blurred: Vec<(f32, u32)> = radii.map(|r| (r, 0)).collect();
        let bytes = pack_layers(tree, &blurred).bytes();
        let handle_in_layer = std::mem::offset_of!(GpuLayer, tree) + 2 * std::mem::size_of::<u32>();
        let offsets = (tree.layers.iter().enumerate())
            .filter_map(|(k, l)| l.layer.height_blur.map(|r| (k, r)))
            .map(|(k, r)| ((k * std::mem::size_of::<GpuLayer>() + handle_in_layer) as u64, r))
            .collect();
        LayerTable {
            region: graph.upload_region("surface layers", bytes.len() as u64),
            bytes: bytes.into(),
            blurred: offsets,
        }
    }

    /// Declares that `pass` reads the table at `stage`.
    pub fn read_in<P: 'static>(&self, pass: &mut PassBuilder<'_, P>, stage: Stage) -> Binding {
        pass.upload(self.region, stage)
    }

    /// Writes this frame's table through `table` (the recording pass's
    /// [`LayerTable::read_in`]) with the handles of the blurred height
    /// fields it declared in `maps`, without allocating.
    pub fn write(&self, ctx: &mut PassContext<'_>, table: Binding, maps: &MapBindings) -> Result<()> {
        ctx.write_upload(table, &self.bytes)?;
        for &(offset, radius) in self.blurred.iter() {
            let handle = maps.blurred_handle(ctx, radius)?;
            ctx.write_upload_at(table, offset, bytemuck::bytes_of(&handle))?;
        }
        Ok(())
    }
}

/// The streamed detail window (`crate::terrain::detail`) as
/// `glsl/include/detail_window.glsl` reads it: in `terrain.warp`'s and
/// `texturing.upsample`'s push constants and [`TexturingFrame`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DetailPush {
    /// Sampled handle of the window image, its side, the level's columns
    /// and rows.
    pub grid: [u32; 4],
    /// Where the window's B-spline has its taps in the active rectangle,
    /// level samples: lo x, lo y, hi x, hi y.
    pub valid: [f32; 4],
    /// Level spacing x, y (metres), blend band (samples), on (1) / off (0).
    pub spacing: [f32; 4],
}

impl DetailPush {
    /// These constants with the handle of the window image as `window`
    /// binds it on the recording pass (None, no window: off).
    pub fn bound(self, window: Option<Binding>, ctx: &PassContext<'_>) -> Result<DetailPush> {
        let mut push = self;
        push.grid[0] = window.map(|w| ctx.handle(w)).transpose()?.unwrap_or(0);
        if window.is_none() {
            push.spacing[3] = 0.0;
        }
        Ok(push)
    }

    /// The world rectangle `(min, max)` where the window is drawn (its
    /// B-spline's taps in the active rectangle), if it is on.
    pub fn drawn_rect(&self) -> Option<(glam::DVec2, glam::DVec2)> {
        if self.spacing[3] < 0.5 {
            return None;
        }
        let spacing = glam::DVec2::new(f64::from(self.spacing[0]), f64::from(self.spacing[1]));
        let v = self.valid.map(f64::from);
        Some((
            glam::DVec2::new(v[0], v[1]) * spacing,
            glam::DVec2::new(v[2], v[3]) * spacing,
        ))
    }
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
    /// The streamed detail window direct texturing reads (off: zeros).
    pub window: DetailPush,
}
