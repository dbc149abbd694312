//! The tile generation passes of the texture atlas (dissertation §8.2.2–8.2.4;
//! the pipeline is described in [`super::generation`]): `texturing.upsample`,
//! one `texturing.layer<i>.<name>` per layer, `texturing.finish`, and the
//! optional `texturing.readback` of the colour textures. Each dispatches one
//! thread per texel of all of the frame's dirty tiles, as
//! [`TextureFrame`] says.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::graph::{
    Binding, BufferAccess, BufferId, ImageAccess, ImageId, PassContext, RenderGraph, Stage, UploadRegion,
};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::surface::gpu_layout::DetailPush;
use crate::texturing::generation::{GenerationInputs, TextureFrame, TileJob, GROUP};
use crate::view::{Frame, Provides};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, MemoryLocation};

/// Push constants of every `texturing.*` pass (`Push` in
/// glsl/include/texture_tiles.glsl).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct TileGenerationPush {
    /// Tile jobs, texel states (storage buffers), layers (storage buffer),
    /// noise tile (sampled).
    handles: [u32; 4],
    /// Jobs, texels, layer index, height field (sampled; in the layer
    /// passes only for `height_blur` layers).
    counts: [u32; 4],
    /// Height-field columns, rows.
    grid: [u32; 4],
    /// Sample spacing x, y (metres), lowest and highest height.
    spacing_range: [f32; 4],
    /// Input maps ([`crate::surface::input_maps::MapBindings::handles`]).
    maps: [u32; 4],
    /// Terrain rectangle x, y (metres).
    extent: [f32; 4],
}

/// Push constants of `texturing.upsample` (`Push` in
/// glsl/include/texture_tiles.glsl with `TEXTURE_TILES_DETAIL_WINDOW`): the
/// detail window in place of the input maps and the extent.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct UpsamplePush {
    handles: [u32; 4],
    counts: [u32; 4],
    grid: [u32; 4],
    spacing_range: [f32; 4],
    window: DetailPush,
}

/// The push constants every generation pass starts from.
pub(crate) fn base_push(field: &HeightField) -> TileGenerationPush {
    let (lo, hi) = field.min_max();
    let extent = field.extent();
    TileGenerationPush {
        handles: [0; 4],
        counts: [0; 4],
        grid: [field.columns, field.rows, 0, 0],
        spacing_range: [field.spacing.x as f32, field.spacing.y as f32, lo, hi],
        maps: [0; 4],
        extent: [extent.x as f32, extent.y as f32, 0.0, 0.0],
    }
}

/// The resources every generation pass shares.
pub(crate) struct GenerationPasses {
    /// This frame's tile jobs, written by `texturing.finish`.
    pub jobs: UploadRegion,
    pub scratch: BufferId,
    pub base_push: TileGenerationPush,
}

impl GenerationPasses {
    /// `texturing.upsample`: the base surface at every dirty texel, the
    /// height field blended into the streamed detail window `window` (if
    /// the terrain has one) as `terrain.warp` draws it.
    pub fn declare_upsample<S: Provides<TextureFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        (heights, window): (ImageId, Option<ImageId>),
    ) -> Result<()> {
        let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_UPSAMPLE)?;
        let base = self.base_push;
        let mut pass = graph.pass("texturing.upsample");
        let heights = pass.sample(heights, Stage::Compute);
        let window = window.map(|w| pass.sample(w, Stage::Compute));
        let jobs = pass.upload(self.jobs, Stage::Compute);
        let scratch = pass.storage_buffer(self.scratch, BufferAccess::StorageWrite(Stage::Compute));
        pass.record(move |ctx, frame| {
            let tiles = frame.prepared::<TextureFrame>()?;
            let push = UpsamplePush {
                handles: [ctx.handle(jobs)?, ctx.handle(scratch)?, 0, 0],
                counts: [tiles.jobs, tiles.texels as u32, 0, ctx.handle(heights)?],
                grid: base.grid,
                spacing_range: base.spacing_range,
                window: tiles.window.bound(window, ctx)?,
            };
            dispatch(ctx, &pipeline, &push, tiles.texels as u32)
        });
        Ok(())
    }

    /// `texturing.layer<i>.<name>`: one layer over every dirty texel.
    pub fn declare_layers<S: Provides<TextureFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        inputs: &GenerationInputs,
    ) -> Result<()> {
        let layer_pipeline = Arc::new(ComputePipeline::new(ctx, shaders::TEXTURING_LAYER)?);
        let base_push = self.base_push;
        for (i, flat) in inputs.tree.layers.iter().enumerate() {
            let name = format!(
                "texturing.layer{i}.{}",
                crate::error::printable(&flat.layer.name.replace(char::is_whitespace, "_"))
            );
            let pipeline = layer_pipeline.clone();
            let mut pass = graph.pass(&name);
            let jobs = pass.upload(self.jobs, Stage::Compute);
            let table = inputs.layers.read_in(&mut pass, Stage::Compute);
            let noise = pass.sample(inputs.noise, Stage::Compute);
            let maps = inputs.maps.sample_in(&mut pass, Stage::Compute);
            // A height_blur layer reads the base height beside its blurred one.
            let heights = (flat.layer.height_blur.is_some()).then(|| pass.sample(inputs.heights, Stage::Compute));
            let scratch = pass.storage_buffer(self.scratch, BufferAccess::StorageReadWrite(Stage::Compute));
            let layers = inputs.layers.clone();
            pass.record(move |ctx, frame| {
                let tiles = frame.prepared::<TextureFrame>()?;
                layers.write(ctx, table, &maps)?;
                let push = TileGenerationPush {
                    handles: [
                        ctx.handle(jobs)?,
                        ctx.handle(scratch)?,
                        ctx.handle(table)?,
                        ctx.handle(noise)?,
                    ],
                    counts: [
                        tiles.jobs,
                        tiles.texels as u32,
                        i as u32,
                        heights.map_or(Ok(0), |h| ctx.handle(h))?,
                    ],
                    maps: maps.handles(ctx)?,
                    ..base_push
                };
                dispatch(ctx, &pipeline, &push, tiles.texels as u32)
            });
        }
        Ok(())
    }

    /// `texturing.finish`: colour and normal into the atlas textures
    /// (colour, normal per texture). It writes the frame's tile jobs, which
    /// hold the textures' storage handles (the host writes land before the
    /// frame is submitted, so the passes before it read them too).
    pub fn declare_finish<S: Provides<TextureFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        textures: &[[ImageId; 2]],
    ) -> Result<()> {
        let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_FINISH)?;
        let base_push = self.base_push;
        let mut pass = graph.pass("texturing.finish");
        let jobs = pass.upload(self.jobs, Stage::Compute);
        let scratch = pass.storage_buffer(self.scratch, BufferAccess::StorageRead(Stage::Compute));
        let access = ImageAccess::StorageReadWrite(Stage::Compute);
        let textures: Vec<[Binding; 2]> = (textures.iter())
            .map(|&[color, normal]| [pass.storage_image(color, access), pass.storage_image(normal, access)])
            .collect();
        pass.record(move |ctx, frame| {
            let tiles = frame.prepared::<TextureFrame>()?;
            // Job by job, with its texture's storage handles (no allocation).
            for (k, job) in tiles.tile_jobs.iter().enumerate() {
                let [color, normal] = *(textures.get(job.images[0] as usize))
                    .ok_or_else(|| Error::Graph(format!("texturing: no atlas texture {}", job.images[0])))?;
                let job = TileJob {
                    images: [ctx.handle(color)?, ctx.handle(normal)?, 0, 0],
                    ..*job
                };
                let offset = (k * std::mem::size_of::<TileJob>()) as u64;
                ctx.write_upload_at(jobs, offset, bytemuck::bytes_of(&job))?;
            }
            let push = TileGenerationPush {
                handles: [ctx.handle(jobs)?, ctx.handle(scratch)?, 0, 0],
                counts: [tiles.jobs, tiles.texels as u32, 0, 0],
                ..base_push
            };
            dispatch(ctx, &pipeline, &push, tiles.texels as u32)
        });
        Ok(())
    }
}

/// `texturing.readback`: every colour texture into host buffers.
pub(crate) fn add_atlas_readback<S: Provides<TextureFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    colors: &[ImageId],
    atlas_size: u32,
) -> Result<Vec<Vec<Arc<Buffer>>>> {
    let mut copies = Vec::new();
    let mut buffers = Vec::new();
    for (k, &image) in colors.iter().enumerate() {
        let per_frame = Buffer::per_frame(
            ctx,
            BufferDesc {
                name: format!("texture atlas {k} readback"),
                size: u64::from(atlas_size).pow(2) * 4,
                usage: BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        copies.push((image, graph.import_buffers_per_frame(per_frame.clone())));
        buffers.push(per_frame);
    }
    graph.read_back_images("texturing.readback", copies);
    Ok(buffers)
}

/// One thread per dirty texel; nothing when no tile is dirty.
fn dispatch<P: Pod>(ctx: &mut PassContext<'_>, pipeline: &ComputePipeline, push: &P, texels: u32) -> Result<()> {
    let groups = u64::from(texels).div_ceil(GROUP);
    if groups == 0 {
        return Ok(());
    }
    ctx.dispatch(pipeline, push, [groups as u32, 1, 1])
}
