//! The tile generation passes of the texture atlas (dissertation §8.2.2–8.2.4;
//! the pipeline is described in [`super::generation`]): `texturing.upsample`,
//! one `texturing.layer<i>.<name>` per layer, `texturing.finish`, and the
//! optional `texturing.readback` of the colour textures. Each dispatches one
//! thread per texel of all of the frame's dirty tiles, as
//! [`TextureFrame`] says.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::texturing::generation::{GenerationInputs, TextureFrame, GROUP};
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
    /// Input maps ([`InputMaps::handles`]).
    maps: [u32; 4],
    /// Terrain rectangle x, y (metres).
    extent: [f32; 4],
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
    pub jobs: UploadRegion,
    pub scratch: BufferId,
    pub base_push: TileGenerationPush,
}

impl GenerationPasses {
    /// `texturing.upsample`: the base surface at every dirty texel.
    pub fn declare_upsample<S: Provides<TextureFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        heights: ImageId,
    ) -> Result<()> {
        let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_UPSAMPLE)?;
        let (jobs, scratch, base_push) = (self.jobs, self.scratch, self.base_push);
        graph
            .pass("texturing.upsample")
            .read(heights, ImageAccess::Sampled(Stage::Compute))
            .read(jobs, BufferAccess::StorageRead(Stage::Compute))
            .write(scratch, BufferAccess::StorageWrite(Stage::Compute))
            .record(move |pass, frame| {
                let tiles = frame.prepared::<TextureFrame>()?;
                let push = TileGenerationPush {
                    handles: [pass.upload(jobs)?, pass.storage_buffer(scratch)?, 0, 0],
                    counts: [tiles.jobs, tiles.texels as u32, 0, pass.sampled(heights)?],
                    ..base_push
                };
                dispatch(pass.cmd(), &pipeline, &push)
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
        let (jobs, scratch, base_push) = (self.jobs, self.scratch, self.base_push);
        let (layers, noise, maps, heights) = (inputs.layers, inputs.noise, inputs.maps, inputs.heights);
        for (i, flat) in inputs.tree.layers.iter().enumerate() {
            let name = format!(
                "texturing.layer{i}.{}",
                crate::error::printable(&flat.layer.name.replace(char::is_whitespace, "_"))
            );
            let pipeline = layer_pipeline.clone();
            let mut pass = graph
                .pass(&name)
                .read(jobs, BufferAccess::StorageRead(Stage::Compute))
                .read(layers, BufferAccess::StorageRead(Stage::Compute))
                .read(noise, ImageAccess::Sampled(Stage::Compute));
            for map in maps.present() {
                pass = pass.read(map, ImageAccess::Sampled(Stage::Compute));
            }
            // A height_blur layer reads the base height beside its blurred one.
            let blurred = flat.layer.height_blur.is_some();
            if blurred {
                pass = pass.read(heights, ImageAccess::Sampled(Stage::Compute));
            }
            pass.write(scratch, BufferAccess::StorageReadWrite(Stage::Compute))
                .record(move |pass, frame| {
                    let tiles = frame.prepared::<TextureFrame>()?;
                    let push = TileGenerationPush {
                        handles: [
                            pass.upload(jobs)?,
                            pass.storage_buffer(scratch)?,
                            pass.storage_buffer(layers)?,
                            pass.sampled(noise)?,
                        ],
                        counts: [
                            tiles.jobs,
                            tiles.texels as u32,
                            i as u32,
                            if blurred { pass.sampled(heights)? } else { 0 },
                        ],
                        maps: maps.handles(),
                        ..base_push
                    };
                    dispatch(pass.cmd(), &pipeline, &push)
                });
        }
        Ok(())
    }

    /// `texturing.finish`: colour and normal into the atlas.
    pub fn declare_finish<S: Provides<TextureFrame> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        images: &[ImageId],
    ) -> Result<()> {
        let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_FINISH)?;
        let (jobs, scratch, base_push) = (self.jobs, self.scratch, self.base_push);
        let mut pass = graph
            .pass("texturing.finish")
            .read(jobs, BufferAccess::StorageRead(Stage::Compute))
            .read(scratch, BufferAccess::StorageRead(Stage::Compute));
        for &image in images {
            pass = pass.write(image, ImageAccess::StorageReadWrite(Stage::Compute));
        }
        pass.record(move |pass, frame| {
            let tiles = frame.prepared::<TextureFrame>()?;
            let push = TileGenerationPush {
                handles: [pass.upload(jobs)?, pass.storage_buffer(scratch)?, 0, 0],
                counts: [tiles.jobs, tiles.texels as u32, 0, 0],
                ..base_push
            };
            dispatch(pass.cmd(), &pipeline, &push)
        });
        Ok(())
    }
}

/// `texturing.readback`: every colour texture into host buffers.
pub(crate) fn add_atlas_readback<S: Provides<TextureFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    colors: &[(ImageId, u32)],
    atlas_size: u32,
) -> Result<Vec<Vec<Arc<Buffer>>>> {
    let mut copies = Vec::new();
    let mut buffers = Vec::new();
    for (k, &(image, _)) in colors.iter().enumerate() {
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
fn dispatch(
    cmd: &mut crate::vulkan::CommandRecorder,
    pipeline: &ComputePipeline,
    push: &TileGenerationPush,
) -> Result<()> {
    let groups = u64::from(push.counts[1]).div_ceil(GROUP);
    if groups == 0 {
        return Ok(());
    }
    cmd.bind_compute(pipeline);
    cmd.push_constants(push)?;
    cmd.dispatch(groups as u32, 1, 1);
    Ok(())
}
