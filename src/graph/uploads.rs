//! The per-frame upload arena: every host-written, GPU-read per-frame datum
//! of every technique (warp maps, tile jobs, page tables, point instance
//! records, per-frame constants) in one host-visible buffer per frame slot.
//! Regions are declared with the passes ([`super::RenderGraph::upload_region`]),
//! laid out at bake time (each at the device's storage-buffer offset
//! alignment, with its own heap handle so shaders index it from 0), and
//! written in a technique's `prepare`, after the frame slot's previous use
//! completed and before recording ([`super::BakedGraph::uploads`]).

use std::sync::Arc;

use bytemuck::Pod;

use super::typed::{BufferAccess, Resource};
use super::ResourceId;
use crate::error::{Error, Result};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, MemoryLocation};

/// A region of the upload arena (typed: reads are declared with
/// [`BufferAccess::StorageRead`], writes come from the host only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct UploadRegion {
    pub(crate) index: usize,
    pub(crate) size: u64,
    pub(crate) arena: ResourceId,
}

impl UploadRegion {
    /// Capacity in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }
}

impl Resource for UploadRegion {
    type Access = BufferAccess;
    fn id(self) -> ResourceId {
        self.arena
    }
}

/// The arena's buffers and the layout of its regions.
pub(crate) struct UploadArena {
    /// One buffer per frame slot.
    pub buffers: Vec<Arc<Buffer>>,
    /// Per region: offset, size, and its heap handle in each slot's buffer.
    pub regions: Vec<(u64, u64, Vec<u32>)>,
    pub names: Vec<String>,
}

impl UploadArena {
    /// Lays out `regions` (name, size) and creates the per-slot buffers.
    pub fn new(ctx: &Context, regions_decl: &[(String, u64)]) -> Result<UploadArena> {
        let align = ctx.storage_buffer_alignment();
        let mut layout = Vec::with_capacity(regions_decl.len());
        let mut end = 0u64;
        for (_, size) in regions_decl {
            let offset = end.div_ceil(align) * align;
            layout.push((offset, *size));
            end = offset + size;
        }
        let buffers = Buffer::per_frame(
            ctx,
            BufferDesc {
                name: "upload arena".into(),
                size: end.max(4),
                usage: BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        let regions = layout
            .into_iter()
            .map(|(offset, size)| {
                let handles = buffers
                    .iter()
                    .map(|b| b.range_handle(offset, size))
                    .collect::<Result<Vec<_>>>()?;
                Ok((offset, size, handles))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(UploadArena {
            buffers,
            regions,
            names: regions_decl.iter().map(|(n, _)| n.clone()).collect(),
        })
    }

    /// The writer of frame `frame`'s slot.
    pub fn writer(&self, frame: u64) -> UploadWriter<'_> {
        UploadWriter {
            arena: Some(self),
            slot: frame as usize % self.buffers.len().max(1),
        }
    }

    /// The heap handle of `region` in frame `frame`'s slot.
    pub fn handle(&self, region: UploadRegion, frame: u64) -> Result<u32> {
        self.regions
            .get(region.index)
            .and_then(|(_, _, handles)| handles.get(frame as usize % handles.len().max(1)))
            .copied()
            .ok_or_else(|| Error::Graph(format!("upload region #{} is not of this graph", region.index)))
    }
}

/// Writes the upload regions of one frame slot (whose previous frame has
/// completed).
pub struct UploadWriter<'a> {
    /// None when the graph declares no region.
    arena: Option<&'a UploadArena>,
    slot: usize,
}

impl UploadWriter<'_> {
    /// A writer for a graph without upload regions (every write fails).
    pub(crate) fn empty() -> UploadWriter<'static> {
        UploadWriter { arena: None, slot: 0 }
    }

    fn arena(&self) -> Result<&UploadArena> {
        self.arena
            .ok_or_else(|| Error::Graph("the graph declares no upload region".into()))
    }

    /// Writes `bytes` at the start of `region`; more than its size is an error.
    pub fn write(&mut self, region: UploadRegion, bytes: &[u8]) -> Result<()> {
        self.write_at(region, 0, bytes)
    }

    /// Writes `value` at the start of `region`.
    pub fn write_pod<T: Pod>(&mut self, region: UploadRegion, value: &T) -> Result<()> {
        self.write_at(region, 0, bytemuck::bytes_of(value))
    }

    /// Writes `bytes` at byte `offset` of `region`.
    pub fn write_at(&mut self, region: UploadRegion, offset: u64, bytes: &[u8]) -> Result<()> {
        let arena = self.arena()?;
        let (start, size, _) = arena
            .regions
            .get(region.index)
            .ok_or_else(|| Error::Graph(format!("upload region #{} is not of this graph", region.index)))?;
        if offset + bytes.len() as u64 > *size {
            return Err(Error::Graph(format!(
                "upload region '{}': {} bytes at {offset} exceed its {size}",
                arena.names[region.index],
                bytes.len()
            )));
        }
        arena.buffers[self.slot].write(start + offset, bytes)
    }
}
