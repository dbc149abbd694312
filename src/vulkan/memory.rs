//! Typed GPU buffers and images on gpu-allocator, with staging uploads,
//! readback and destruction deferred until the GPU is done with them.

use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

use super::context::{vk_err, Context, Shared};
use super::frames::FRAMES_IN_FLIGHT;
use super::heap::HeapKind;
use crate::error::{Error, Result};

/// What the GPU last did with a resource, as the render graph tracks it
/// across passes and frames: the last write, who has read since, to which
/// stages and accesses that write has been made visible, and the layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccessState {
    /// Stages and accesses of the last write (a layout transition counts as one).
    pub write_stages: vk::PipelineStageFlags2,
    pub write_access: vk::AccessFlags2,
    /// Stages that read the resource since the last write.
    pub read_stages: vk::PipelineStageFlags2,
    /// Stages and accesses the last write has been made visible to.
    pub visible_stages: vk::PipelineStageFlags2,
    pub visible_access: vk::AccessFlags2,
    /// Current image layout (UNDEFINED for buffers).
    pub layout: vk::ImageLayout,
}

impl AccessState {
    /// Never used: nothing to wait for, contents undefined.
    pub const UNUSED: AccessState = AccessState {
        write_stages: vk::PipelineStageFlags2::NONE,
        write_access: vk::AccessFlags2::NONE,
        read_stages: vk::PipelineStageFlags2::NONE,
        visible_stages: vk::PipelineStageFlags2::NONE,
        visible_access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::UNDEFINED,
    };

    /// Just written by `stages`/`access`, leaving `layout`.
    pub const fn written(stages: vk::PipelineStageFlags2, access: vk::AccessFlags2, layout: vk::ImageLayout) -> Self {
        AccessState {
            write_stages: stages,
            write_access: access,
            read_stages: vk::PipelineStageFlags2::NONE,
            visible_stages: vk::PipelineStageFlags2::NONE,
            visible_access: vk::AccessFlags2::NONE,
            layout,
        }
    }
}

/// One pipeline barrier: wait for `src_*`, make it visible to `dst_*`, and
/// change the layout from `old_layout` to `new_layout` (images).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Barrier {
    pub src_stages: vk::PipelineStageFlags2,
    pub src_access: vk::AccessFlags2,
    pub dst_stages: vk::PipelineStageFlags2,
    pub dst_access: vk::AccessFlags2,
    pub old_layout: vk::ImageLayout,
    pub new_layout: vk::ImageLayout,
}

/// An object waiting for the GPU to finish before it is destroyed.
pub(crate) enum Garbage {
    Buffer(vk::Buffer, Allocation),
    Image(vk::Image, vk::ImageView, Option<Allocation>),
    /// The view of an image owned elsewhere (a swapchain's).
    ImageView(vk::ImageView),
    Memory(Allocation),
    Pipeline(vk::Pipeline),
    CommandPool(vk::CommandPool),
    QueryPool(vk::QueryPool),
}

impl Garbage {
    pub(crate) fn destroy(self, shared: &Shared) {
        let device = &shared.device;
        // SAFETY: the object's last use has completed on the GPU (the caller checked
        // the timeline, or the device is idle) and nothing refers to it any more.
        unsafe {
            match self {
                Garbage::Buffer(buffer, allocation) => {
                    device.destroy_buffer(buffer, None);
                    free(shared, allocation);
                }
                Garbage::ImageView(view) => device.destroy_image_view(view, None),
                Garbage::Image(image, view, allocation) => {
                    device.destroy_image_view(view, None);
                    device.destroy_image(image, None);
                    if let Some(allocation) = allocation {
                        free(shared, allocation);
                    }
                }
                Garbage::Memory(allocation) => free(shared, allocation),
                Garbage::Pipeline(p) => device.destroy_pipeline(p, None),
                Garbage::CommandPool(p) => device.destroy_command_pool(p, None),
                Garbage::QueryPool(p) => device.destroy_query_pool(p, None),
            }
        }
    }
}

fn free(shared: &Shared, allocation: Allocation) {
    if let Ok(mut allocator) = shared.allocator.lock() {
        if let Err(e) = allocator.free(allocation) {
            log::error!("freeing GPU memory: {e}");
        }
    }
}

/// What a buffer is for.
#[derive(Clone, Debug)]
pub struct BufferDesc {
    pub name: String,
    pub size: u64,
    pub usage: vk::BufferUsageFlags,
    pub location: MemoryLocation,
}

/// A GPU buffer. Storage buffers get a descriptor-heap handle.
pub struct Buffer {
    ctx: Context,
    pub(crate) raw: vk::Buffer,
    allocation: Option<Allocation>,
    desc: BufferDesc,
    storage_handle: Option<u32>,
    /// Heap handles of sub-ranges ([`Buffer::range_handle`]), released with the buffer.
    range_handles: Mutex<Vec<u32>>,
    pub(crate) state: Mutex<AccessState>,
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Buffer")
            .field("name", &self.desc.name)
            .field("size", &self.desc.size)
            .finish()
    }
}

impl Buffer {
    /// Creates a buffer; storage buffers are registered in the descriptor heap.
    pub fn new(ctx: &Context, desc: BufferDesc) -> Result<Buffer> {
        if desc.size == 0 {
            return Err(Error::invalid(
                "buffer size",
                format!("buffer '{}' has size 0", desc.name),
            ));
        }
        let device = &ctx.shared.device;
        let info = vk::BufferCreateInfo::default()
            .size(desc.size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid create info on a live device.
        let raw = unsafe { device.create_buffer(&info, None) }.map_err(vk_err("vkCreateBuffer"))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { device.get_buffer_memory_requirements(raw) };
        let allocation = allocate(ctx, &desc.name, requirements, desc.location, true);
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: the buffer was never used.
                unsafe { device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        // SAFETY: the allocation satisfies the buffer's requirements and is unbound.
        let bound = unsafe { device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) };
        if let Err(e) = bound {
            ctx.defer_destroy(Garbage::Buffer(raw, allocation));
            return Err(vk_err("vkBindBufferMemory")(e));
        }
        ctx.name_object(raw, &desc.name);
        let storage_handle = if desc.usage.contains(vk::BufferUsageFlags::STORAGE_BUFFER) {
            Some(ctx.shared.heap.register_buffer(device, raw, desc.size)?)
        } else {
            None
        };
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            allocation: Some(allocation),
            desc,
            storage_handle,
            range_handles: Mutex::new(Vec::new()),
            state: Mutex::new(AccessState::UNUSED),
        })
    }

    /// One buffer per frame slot ([`FRAMES_IN_FLIGHT`]), named `"{desc.name} {slot}"`.
    pub fn per_frame(ctx: &Context, desc: BufferDesc) -> Result<Vec<Arc<Buffer>>> {
        (0..FRAMES_IN_FLIGHT)
            .map(|i| {
                let desc = BufferDesc {
                    name: format!("{} {i}", desc.name),
                    ..desc.clone()
                };
                Buffer::new(ctx, desc).map(Arc::new)
            })
            .collect()
    }

    /// Creates a device-local buffer filled with `data` through a staging copy.
    pub fn with_data(ctx: &Context, name: &str, usage: vk::BufferUsageFlags, data: &[u8]) -> Result<Buffer> {
        let buffer = Buffer::new(
            ctx,
            BufferDesc {
                name: name.into(),
                size: data.len() as u64,
                usage: usage | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let staging = Buffer::staging(ctx, name, data)?;
        ctx.one_shot(|rec| rec.copy_buffer(&staging, &buffer, data.len() as u64))?;
        buffer.set_state(AccessState::written(
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::ImageLayout::UNDEFINED,
        ));
        Ok(buffer)
    }

    /// A host-visible buffer holding `data`, as a transfer source.
    pub fn staging(ctx: &Context, name: &str, data: &[u8]) -> Result<Buffer> {
        let staging = Buffer::new(
            ctx,
            BufferDesc {
                name: format!("{name} (staging)"),
                size: data.len().max(1) as u64,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        staging.write(0, data)?;
        Ok(staging)
    }

    /// The buffer's description.
    pub fn desc(&self) -> &BufferDesc {
        &self.desc
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.desc.size
    }

    /// The descriptor-heap index of this storage buffer.
    pub(crate) fn storage_handle(&self) -> Option<u32> {
        self.storage_handle
    }

    /// A descriptor-heap handle for the bytes `offset..offset + size` of this
    /// storage buffer (shaders index the range from 0); `offset` must be a
    /// multiple of the device's storage-buffer offset alignment
    /// ([`Context::storage_buffer_alignment`]). Released with the buffer.
    pub(crate) fn range_handle(&self, offset: u64, size: u64) -> Result<u32> {
        let align = self.ctx.storage_buffer_alignment();
        if self.storage_handle.is_none() || offset % align != 0 || size == 0 || offset + size > self.desc.size {
            return Err(Error::invalid(
                "buffer range",
                format!(
                    "{size} bytes at {offset} of '{}' ({} bytes, alignment {align}, storage: {})",
                    self.desc.name,
                    self.desc.size,
                    self.storage_handle.is_some()
                ),
            ));
        }
        let handle = self
            .ctx
            .shared
            .heap
            .register_buffer_range(&self.ctx.shared.device, self.raw, offset, size)?;
        self.range_handles
            .lock()
            .map_err(|_| Error::Device("buffer range lock poisoned".into()))?
            .push(handle);
        Ok(handle)
    }

    /// Copies `data` into a host-visible buffer at `offset`.
    pub fn write(&self, offset: u64, data: &[u8]) -> Result<()> {
        let mapped = self.mapped()?;
        let end = offset as usize + data.len();
        if end > mapped.len() {
            return Err(Error::invalid(
                "buffer write",
                format!("{} bytes past the end of '{}'", end - mapped.len(), self.desc.name),
            ));
        }
        // SAFETY: the range is inside the mapping; the CPU writes only to host-visible
        // memory the GPU is not using (callers write before submitting work on it).
        unsafe {
            std::ptr::copy_nonoverlapping(
                data.as_ptr(),
                mapped.as_ptr().add(offset as usize) as *mut u8,
                data.len(),
            );
        }
        Ok(())
    }

    /// The contents of a host-visible buffer (call after the GPU wrote it and the
    /// frame that wrote it has completed).
    pub fn mapped(&self) -> Result<&[u8]> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..self.desc.size as usize])
            .ok_or_else(|| {
                Error::invalid(
                    "buffer mapping",
                    format!("buffer '{}' is not host-visible", self.desc.name),
                )
            })
    }

    pub fn state(&self) -> AccessState {
        self.state.lock().map(|s| *s).unwrap_or(AccessState::UNUSED)
    }

    pub fn set_state(&self, state: AccessState) {
        if let Ok(mut s) = self.state.lock() {
            *s = state;
        }
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        let ranges = self.range_handles.get_mut().map(std::mem::take).unwrap_or_default();
        for handle in self.storage_handle.into_iter().chain(ranges) {
            self.ctx
                .shared
                .heap
                .release(HeapKind::StorageBuffer, handle, self.ctx.last_submitted());
        }
        if let Some(allocation) = self.allocation.take() {
            self.ctx.defer_destroy(Garbage::Buffer(self.raw, allocation));
        }
    }
}

pub(crate) fn subresource_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

pub(crate) fn allocate(
    ctx: &Context,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation> {
    let mut allocator = ctx
        .shared
        .allocator
        .lock()
        .map_err(|_| Error::Device("allocator lock poisoned".into()))?;
    allocator
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|e| Error::Allocation {
            what: name.to_string(),
            message: e.to_string(),
        })
}
