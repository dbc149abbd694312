//! The GPU half of geometry image warping (dissertation §7.4.2 "Warp and
//! Zoom", §7.4.3; `ALGORITHMS.md` §3 items 5–7): the sketch atlas and a
//! wavelet noise tile on the GPU, the per-frame warp from the CPU
//! ([`crate::terrain::lod`]), and the compute pass `terrain.warp` that
//! writes the warped, displaced `N×N` geometry image straight into the
//! vertex buffer that `terrain.draw` ([`crate::terrain::shading`]) draws
//! with the fixed grid's index buffer (render-to-vertex-buffer).
//!
//! Frame graph: `terrain.warp` (compute: reads the atlas, the noise tile and
//! this frame's warp upload; writes the vertex buffer) → `terrain.draw`
//! (vertex input). The CPU stage runs in [`crate::terrain::Terrain`]'s
//! `prepare`, before the frame is recorded (the profile's
//! `prepare.terrain`).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::graph::{BufferAccess, BufferId, ImageId, RenderGraph, Stage, UploadRegion};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::surface::wavelet_noise::{self, NOISE_TILE};
use crate::terrain::lod::{DebugScalar, LodSettings, MAX_SNAP};
use crate::terrain::TerrainFrame;
use crate::view::{pass_name, Frame, Provides, ViewIndex};
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, Format, Image, ImageDesc, ImageUsageFlags,
    MemoryLocation,
};

/// Default output grid side (vertices), as in the text.
pub const DEFAULT_GRID_SIDE: u32 = 512;
/// Bytes per vertex: position (xyz, w = split octave) and normal (xyz,
/// w = debug scalar).
pub const VERTEX_STRIDE: u32 = 32;
/// Conservative shift of detail from geometry to shading, in octaves (also
/// `SPLIT_BIAS` in `glsl/include/terrain_detail.glsl`).
pub const SPLIT_BIAS: f32 = 0.5;
/// Detail octaves at most, in geometry and shading (also
/// `MAX_DETAIL_OCTAVES` in `glsl/include/terrain_detail.glsl`).
pub const MAX_DETAIL_OCTAVES: u32 = 8;

/// What `terrain.draw` shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TerrainView {
    /// Shaded terrain.
    #[default]
    Shaded,
    /// Importance map (normalised, square-root colour ramp).
    Importance,
    /// Obtained / demanded sample density (green: within [0.5, 1]).
    DensityRatio,
    /// Split octave per vertex (0 blue … 6 red).
    SplitOctave,
    /// Every fourth grid line of the warped mesh.
    Wireframe,
}

impl TerrainView {
    /// The value the shaders test (`VIEW_*` in `terrain_draw.glsl`).
    pub fn code(self) -> u32 {
        self as u32
    }

    pub(crate) fn debug_scalar(self) -> DebugScalar {
        match self {
            TerrainView::Importance => DebugScalar::Importance,
            TerrainView::DensityRatio => DebugScalar::DensityRatio,
            _ => DebugScalar::None,
        }
    }
}

/// Settings of the terrain LOD and its detail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TerrainSettings {
    /// Output grid side `N` (vertices per side, 2..=2048).
    pub grid_side: u32,
    pub lod: LodSettings,
    /// Procedural displacement and bump mapping (`--no-terrain-detail`).
    pub detail: bool,
    /// With `detail`, the octaves finer than the mesh bump-map the normal
    /// per pixel (`--no-detail-shading` turns this off: detail in geometry
    /// only, the centre panel of Fig. 7.14).
    pub detail_shading: bool,
    /// Detail amplitude relative to the atlas spacing: octave k has
    /// amplitude `amplitude · d0 · 2^(−k·H)`.
    pub detail_amplitude: f32,
    /// Roughness exponent `H` of the detail octaves.
    pub detail_h: f32,
    /// Seed of the wavelet noise tile.
    pub noise_seed: u64,
    pub view: TerrainView,
}

impl Default for TerrainSettings {
    fn default() -> Self {
        Self {
            grid_side: DEFAULT_GRID_SIDE,
            lod: LodSettings::default(),
            detail: true,
            detail_shading: true,
            detail_amplitude: 0.15,
            detail_h: 0.9,
            noise_seed: wavelet_noise::DEFAULT_NOISE_SEED,
            view: TerrainView::Shaded,
        }
    }
}

impl TerrainSettings {
    /// Checks the sizes and detail parameters.
    pub fn validate(&self) -> Result<()> {
        if !(2..=2048).contains(&self.grid_side) {
            return Err(Error::invalid(
                "terrain.grid_side",
                format!("{} (must be 2..=2048)", self.grid_side),
            ));
        }
        if !(4..=1024).contains(&self.lod.sketch_side) {
            return Err(Error::invalid(
                "terrain.lod.sketch_side",
                format!("{} (must be 4..=1024)", self.lod.sketch_side),
            ));
        }
        if !(self.lod.snap.is_finite() && (0.0..=MAX_SNAP).contains(&self.lod.snap)) {
            return Err(Error::invalid(
                "terrain.lod.snap",
                format!("{} (must be in 0..={MAX_SNAP})", self.lod.snap),
            ));
        }
        if !(self.detail_amplitude.is_finite() && self.detail_amplitude >= 0.0 && self.detail_amplitude <= 10.0) {
            return Err(Error::invalid(
                "terrain.detail_amplitude",
                format!("{} (must be in 0..=10)", self.detail_amplitude),
            ));
        }
        if !(self.detail_h.is_finite() && self.detail_h >= 0.0 && self.detail_h <= 2.0) {
            return Err(Error::invalid(
                "terrain.detail_h",
                format!("{} (must be in 0..=2)", self.detail_h),
            ));
        }
        Ok(())
    }

    /// What `terrain.draw` reads of the settings (`TerrainTexturing.draw`):
    /// view, bump mapping on (0/1: `detail` and `detail_shading`), grid side.
    pub fn draw_constants(&self) -> [u32; 4] {
        [
            self.view.code(),
            u32::from(self.detail && self.detail_shading),
            self.grid_side,
            0,
        ]
    }
}

/// Push constants of `terrain.warp` (`glsl/terrain/warp.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct WarpPush {
    /// Sketch atlas (sampled), warp upload (storage), vertices (storage),
    /// noise tile (sampled).
    pub handles: [u32; 4],
    /// Grid side N, sketch side, height-field columns, rows.
    pub grid: [u32; 4],
    /// Sample spacing x, y (metres), detail amplitude, detail H.
    pub spacing: [f32; 4],
    /// Terrain rectangle x, y (metres), d0, detail on (1) or off (0).
    pub extent: [f32; 4],
    /// The streamed detail window (off: zeros; set per frame).
    pub window: crate::terrain::detail::DetailPush,
}

/// Indices of the two triangles of every grid cell, counter-clockwise seen
/// from above (+Z) for a grid whose rows run along `s` and columns along
/// `t` with `s × t = +z`.
pub fn grid_indices(columns: u32, rows: u32) -> Vec<u32> {
    let mut indices = Vec::with_capacity(((columns - 1) * (rows - 1) * 6) as usize);
    for r in 0..rows - 1 {
        for c in 0..columns - 1 {
            let i = r * columns + c;
            indices.extend_from_slice(&[i, i + 1, i + columns, i + 1, i + columns + 1, i + columns]);
        }
    }
    indices
}

/// GPU resources of the warped terrain shared by every view: the height
/// field as the sketch atlas, the noise tile and the grid's indices.
pub struct GeometryImage {
    pub field: Arc<HeightField>,
    pub settings: TerrainSettings,
    /// The sketch atlas: the whole height field, R32F.
    pub atlas: Arc<Image>,
    /// Wavelet noise tile (R32F, `NOISE_TILE`²).
    pub noise: Arc<Image>,
    /// Fixed grid topology, built once.
    pub indices: Arc<Buffer>,
}

impl GeometryImage {
    /// Uploads the atlas and the noise tile, creates the index buffer.
    pub fn new(ctx: &Context, field: Arc<HeightField>, settings: TerrainSettings) -> Result<GeometryImage> {
        settings.validate()?;
        let max = ctx.max_image_dimension();
        if field.columns > max || field.rows > max {
            return Err(Error::invalid(
                "height field",
                format!(
                    "{}×{} samples exceed the device's image limit of {max} per side",
                    field.columns, field.rows
                ),
            ));
        }
        let image = |name: &str, w: u32, h: u32, data: &[f32]| {
            Image::with_data(
                ctx,
                ImageDesc {
                    name: name.into(),
                    width: w,
                    height: h,
                    format: Format::R32_SFLOAT,
                    usage: ImageUsageFlags::SAMPLED,
                },
                bytemuck::cast_slice(data),
            )
            .map(Arc::new)
        };
        let atlas = image("sketch atlas", field.columns, field.rows, &field.heights)?;
        let tile = wavelet_noise::noise_tile(settings.noise_seed, NOISE_TILE)?;
        let noise = image("wavelet noise tile", NOISE_TILE as u32, NOISE_TILE as u32, &tile)?;
        let side = settings.grid_side;
        let indices = Arc::new(Buffer::with_data(
            ctx,
            "terrain grid indices",
            BufferUsageFlags::INDEX_BUFFER,
            bytemuck::cast_slice(&grid_indices(side, side)),
        )?);
        Ok(GeometryImage {
            field,
            settings,
            atlas,
            noise,
            indices,
        })
    }

    /// Sketch-atlas spacing `d0`: the finer of the two sample spacings.
    pub fn atlas_spacing(&self) -> f32 {
        self.field.spacing.x.min(self.field.spacing.y) as f32
    }

    /// Bytes of one view's warp upload (the warped sketch map).
    pub fn warp_upload_bytes(&self) -> u64 {
        (self.settings.lod.sketch_side as u64).pow(2) * 16
    }

    /// A view's geometry image: the vertex buffer `terrain.warp` writes
    /// and `terrain.draw` reads (`grid_side`² vertices).
    pub fn vertex_buffer(&self, ctx: &Context, view_name: &str) -> Result<Arc<Buffer>> {
        let side = u64::from(self.settings.grid_side);
        Ok(Arc::new(Buffer::new(
            ctx,
            BufferDesc {
                name: pass_name("terrain geometry image (vertices)", view_name),
                size: side * side * u64::from(VERTEX_STRIDE),
                usage: BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::VERTEX_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
        )?))
    }

    /// The push constants of `terrain.warp` but for its handles (the
    /// pass's bindings).
    pub fn warp_push(&self) -> WarpPush {
        let (field, settings) = (&self.field, &self.settings);
        let extent = field.extent();
        WarpPush {
            handles: [0; 4],
            grid: [
                settings.grid_side,
                settings.lod.sketch_side as u32,
                field.columns,
                field.rows,
            ],
            spacing: [
                field.spacing.x as f32,
                field.spacing.y as f32,
                settings.detail_amplitude,
                settings.detail_h,
            ],
            extent: [
                extent.x as f32,
                extent.y as f32,
                self.atlas_spacing(),
                if settings.detail { 1.0 } else { 0.0 },
            ],
            window: Default::default(),
        }
    }
}

/// What one view's `terrain.warp` reads and writes.
#[derive(Clone, Copy, Debug)]
pub struct WarpPass {
    pub view: ViewIndex,
    /// Sketch atlas and noise tile.
    pub atlas: ImageId,
    pub noise: ImageId,
    /// This frame's warped sketch map (written by `prepare`).
    pub upload: UploadRegion,
    /// The view's geometry image.
    pub vertices: BufferId,
    /// The push constants but for the handles ([`GeometryImage::warp_push`]).
    pub push: WarpPush,
    /// The streamed detail window, if the terrain has one.
    pub window: Option<ImageId>,
}

/// Declares `terrain.warp` for one view (§7.4.2 "Warp and Zoom"): the
/// prepared warp of the sketch map, bilinearly to N×N, heights re-sampled
/// from the atlas, detail displacement, normals; into the vertex buffer.
/// Its upload is written by [`crate::terrain::Terrain`]'s `prepare`.
pub fn declare_warp_pass<S: Provides<TerrainFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    pass: WarpPass,
) -> Result<()> {
    let pipeline = ComputePipeline::new(ctx, shaders::TERRAIN_WARP)?;
    let mut builder = graph.pass(name);
    let atlas = builder.sample(pass.atlas, Stage::Compute);
    let noise = builder.sample(pass.noise, Stage::Compute);
    let upload = builder.upload(pass.upload, Stage::Compute);
    let vertices = builder.storage_buffer(pass.vertices, BufferAccess::StorageWrite(Stage::Compute));
    let window = pass.window.map(|w| builder.sample(w, Stage::Compute));
    builder.record(move |ctx, frame| {
        // The view's warp upload is this frame's only when it was prepared.
        let prepared = frame.prepared::<crate::terrain::TerrainFrame>()?;
        prepared.view(pass.view)?;
        let push = WarpPush {
            window: prepared.detail.push.bound(window, ctx)?,
            handles: [
                ctx.handle(atlas)?,
                ctx.handle(upload)?,
                ctx.handle(vertices)?,
                ctx.handle(noise)?,
            ],
            ..pass.push
        };
        let groups = pass.push.grid[0].div_ceil(8);
        ctx.dispatch(&pipeline, &push, [groups, groups, 1])
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_indices_cover_every_cell_once() {
        let idx = grid_indices(3, 2);
        assert_eq!(idx, vec![0, 1, 3, 1, 4, 3, 1, 2, 4, 2, 5, 4]);
    }

    #[test]
    fn settings_are_checked() {
        let ok = TerrainSettings::default();
        assert!(ok.validate().is_ok());
        assert!(TerrainSettings { grid_side: 1, ..ok }.validate().is_err());
        let snap = |snap| TerrainSettings {
            lod: LodSettings { snap, ..ok.lod },
            ..ok
        };
        assert!(snap(0.0).validate().is_ok() && snap(MAX_SNAP).validate().is_ok());
        assert!(snap(-1.0).validate().is_err() && snap(f64::NAN).validate().is_err());
        assert!(TerrainSettings {
            detail_amplitude: f32::NAN,
            ..ok
        }
        .validate()
        .is_err());
        assert_eq!(
            ok.draw_constants(),
            [TerrainView::Shaded.code(), 1, DEFAULT_GRID_SIDE, 0]
        );
    }
}
