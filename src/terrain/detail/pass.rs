//! The detail window on the device: the R32F image, the frame's upload
//! region of arrived tiles and `terrain.detail`, the compute pass that
//! copies them into the image's slots (the graph derives its barriers
//! against the passes that sample the window).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::{DetailWindow, TileUpload};
use crate::error::Result;
use crate::graph::{ImageAccess, ImageId, RenderGraph, Stage, UploadRegion, UploadWriter};
use crate::shaders;
use crate::terrain::TerrainFrame;
use crate::view::{Frame, Provides};
use crate::vulkan::{ComputePipeline, Context, Format, Image, ImageDesc, ImageUsageFlags};

pub use crate::surface::gpu_layout::DetailPush;

/// What `terrain.detail` copies this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DetailUploads {
    /// Tiles in the upload region.
    pub tiles: u32,
    /// Samples a side of a tile.
    pub tile_side: u32,
    /// The window's shader constants.
    pub push: DetailPush,
}

/// Push constants of `terrain.detail` (`glsl/terrain/detail_upload.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct UploadPush {
    /// Upload region (storage), window image (storage), tiles, tile side.
    handles: [u32; 4],
}

/// Bytes of one tile's record: its texel corner and size, then
/// `tile_side²` heights (rows `tile_side` apart).
fn record_bytes(tile_side: u32) -> u64 {
    16 + 4 * u64::from(tile_side).pow(2)
}

/// The window's image, its upload region and `terrain.detail`, declared.
pub struct DetailDevice {
    pub image: ImageId,
    region: UploadRegion,
}

impl DetailDevice {
    /// Writes this frame's `uploads` into the region.
    pub fn write(&self, uploads: &[TileUpload], tile_side: u32, out: &mut UploadWriter<'_>) -> Result<()> {
        let mut record = Vec::with_capacity(record_bytes(tile_side) as usize);
        for (k, u) in uploads.iter().enumerate() {
            record.clear();
            let head = [u.corner.0, u.corner.1, u.tile.width, u.tile.height];
            record.extend_from_slice(bytemuck::cast_slice(&head));
            for row in u.tile.heights.chunks_exact(u.tile.width as usize) {
                record.extend_from_slice(bytemuck::cast_slice(row));
                record.resize(record.len() + 4 * (tile_side - u.tile.width) as usize, 0);
            }
            out.write_at(self.region, k as u64 * record_bytes(tile_side), &record)?;
        }
        Ok(())
    }
}

/// Creates the window's image and upload region and declares
/// `terrain.detail` (before the passes that sample the image).
pub fn declare_detail_upload<S: Provides<TerrainFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    window: &DetailWindow,
) -> Result<DetailDevice> {
    let side = window.side();
    let image = Image::new(
        ctx,
        ImageDesc {
            name: "terrain detail window".into(),
            width: side,
            height: side,
            format: Format::R32_SFLOAT,
            usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED,
        },
    )?;
    let image = graph.import_image(Arc::new(image));
    let tile_side = window.tile_side();
    let region = graph.upload_region(
        "terrain detail tiles",
        u64::from(window.max_uploads()) * record_bytes(tile_side),
    );
    let pipeline = ComputePipeline::new(ctx, shaders::TERRAIN_DETAIL_UPLOAD)?;
    let mut pass = graph.pass("terrain.detail");
    let source = pass.upload(region, Stage::Compute);
    // Read-write: the slots not uploaded this frame keep their tiles.
    let target = pass.storage_image(image, ImageAccess::StorageReadWrite(Stage::Compute));
    pass.record(move |ctx, frame| {
        let uploads = frame.prepared::<TerrainFrame>()?.detail;
        if uploads.tiles == 0 {
            return Ok(());
        }
        let push = UploadPush {
            handles: [
                ctx.handle(source)?,
                ctx.handle(target)?,
                uploads.tiles,
                uploads.tile_side,
            ],
        };
        let groups = uploads.tile_side.div_ceil(8);
        ctx.dispatch(&pipeline, &push, [groups, groups, uploads.tiles])
    });
    Ok(DetailDevice { image, region })
}
