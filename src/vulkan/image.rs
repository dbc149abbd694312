//! 2-D images: device-local, registered in the descriptor heap, with their
//! own memory or placed in a [`MemoryBlock`] shared with other images whose
//! uses never overlap (render-graph transient aliasing).

use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;

use super::context::{vk_err, Context};
use super::heap::HeapKind;
use super::memory::{allocate, subresource_range, AccessState, Barrier, Buffer, Garbage};
use crate::error::{Error, Result};

/// What a 2-D image is for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageDesc {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub format: vk::Format,
    pub usage: vk::ImageUsageFlags,
}

/// Whether `format` holds depth.
pub fn is_depth_format(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::D16_UNORM | vk::Format::D32_SFLOAT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT
    )
}

/// A 2-D GPU image with one view. Sampled and storage images get
/// descriptor-heap handles.
pub struct Image {
    ctx: Context,
    pub(crate) raw: vk::Image,
    pub(crate) view: vk::ImageView,
    memory: Option<ImageMemory>,
    desc: ImageDesc,
    sampled_handle: Option<u32>,
    storage_handle: Option<u32>,
    pub(crate) state: Mutex<AccessState>,
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Image").field("name", &self.desc.name).finish()
    }
}

impl Image {
    /// Creates a device-local image with its own memory and its view,
    /// registered in the heap.
    pub fn new(ctx: &Context, desc: ImageDesc) -> Result<Image> {
        Image::create(ctx, desc, None)
    }

    /// Creates an image placed at the start of `block`, sharing its memory
    /// with other images. The caller (the render graph) orders every use of
    /// the images sharing a block.
    pub fn new_aliased(ctx: &Context, desc: ImageDesc, block: Arc<MemoryBlock>) -> Result<Image> {
        Image::create(ctx, desc, Some(block))
    }

    fn create(ctx: &Context, desc: ImageDesc, block: Option<Arc<MemoryBlock>>) -> Result<Image> {
        let max = ctx.max_image_dimension();
        if desc.width == 0 || desc.height == 0 || desc.width > max || desc.height > max {
            return Err(Error::invalid(
                "image size",
                format!(
                    "'{}' is {}x{}; each side must be in 1..={max}",
                    desc.name, desc.width, desc.height
                ),
            ));
        }
        let device = &ctx.shared.device;
        let info = image_create_info(&desc);
        // SAFETY: valid create info on a live device.
        let raw = unsafe { device.create_image(&info, None) }.map_err(vk_err("vkCreateImage"))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { device.get_image_memory_requirements(raw) };
        let memory = match block {
            Some(block) => block
                .fits(&desc.name, &requirements)
                .map(|_| ImageMemory::Aliased(block)),
            None => allocate(ctx, &desc.name, requirements, MemoryLocation::GpuOnly, false).map(ImageMemory::Owned),
        };
        let memory = match memory {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: the image was never used.
                unsafe { device.destroy_image(raw, None) };
                return Err(e);
            }
        };
        let allocation = memory.allocation();
        // SAFETY: the allocation satisfies the image's requirements (checked by `fits`
        // for shared blocks) and the image is unbound.
        let bound = unsafe { device.bind_image_memory(raw, allocation.memory(), allocation.offset()) };
        let aspect = if is_depth_format(desc.format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(subresource_range(aspect));
        let view = bound.map_err(vk_err("vkBindImageMemory")).and_then(|_| {
            // SAFETY: the image is bound to memory; the view matches its format.
            unsafe { device.create_image_view(&view_info, None) }.map_err(vk_err("vkCreateImageView"))
        });
        let view = match view {
            Ok(v) => v,
            Err(e) => {
                ctx.defer_destroy(Garbage::Image(raw, vk::ImageView::null(), memory.into_owned()));
                return Err(e);
            }
        };
        ctx.name_object(raw, &desc.name);
        ctx.name_object(view, &desc.name);
        let heap = &ctx.shared.heap;
        let sampled_handle = if desc.usage.contains(vk::ImageUsageFlags::SAMPLED) {
            Some(heap.register_image(device, HeapKind::SampledImage, view)?)
        } else {
            None
        };
        let storage_handle = if desc.usage.contains(vk::ImageUsageFlags::STORAGE) {
            Some(heap.register_image(device, HeapKind::StorageImage, view)?)
        } else {
            None
        };
        Ok(Image {
            ctx: ctx.clone(),
            raw,
            view,
            memory: Some(memory),
            desc,
            sampled_handle,
            storage_handle,
            state: Mutex::new(AccessState::UNUSED),
        })
    }

    /// Wraps image `raw` of a swapchain (owned and destroyed by it) with a
    /// view; no heap handles (it is written by transfers and attachments only).
    pub(crate) fn from_swapchain(ctx: &Context, raw: vk::Image, desc: ImageDesc) -> Result<Image> {
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(subresource_range(vk::ImageAspectFlags::COLOR));
        // SAFETY: `raw` is a live swapchain image of this device; the view matches its format.
        let view =
            unsafe { ctx.shared.device.create_image_view(&view_info, None) }.map_err(vk_err("vkCreateImageView"))?;
        ctx.name_object(view, &desc.name);
        Ok(Image {
            ctx: ctx.clone(),
            raw,
            view,
            memory: None,
            desc,
            sampled_handle: None,
            storage_handle: None,
            state: Mutex::new(AccessState::UNUSED),
        })
    }

    /// The image's description.
    pub fn desc(&self) -> &ImageDesc {
        &self.desc
    }

    /// Heap index for sampling (layout SHADER_READ_ONLY_OPTIMAL).
    pub(crate) fn sampled_handle(&self) -> Option<u32> {
        self.sampled_handle
    }

    /// Heap index for storage access (layout GENERAL).
    pub(crate) fn storage_handle(&self) -> Option<u32> {
        self.storage_handle
    }

    pub(crate) fn aspect(&self) -> vk::ImageAspectFlags {
        if is_depth_format(self.desc.format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        }
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

impl Drop for Image {
    fn drop(&mut self) {
        let heap = &self.ctx.shared.heap;
        let last = self.ctx.last_submitted();
        if let Some(handle) = self.sampled_handle {
            heap.release(HeapKind::SampledImage, handle, last);
        }
        if let Some(handle) = self.storage_handle {
            heap.release(HeapKind::StorageImage, handle, last);
        }
        match self.memory.take() {
            Some(memory) => (self.ctx).defer_destroy(Garbage::Image(self.raw, self.view, memory.into_owned())),
            // A swapchain's image: its swapchain destroys it.
            None => self.ctx.defer_destroy(Garbage::ImageView(self.view)),
        }
    }
}

impl Image {
    /// Creates a device-local image (with TRANSFER_DST added to `desc.usage`)
    /// holding `texels`, tightly packed rows, through a staging copy.
    ///
    /// Errors before creating anything when `texels.len()` is not
    /// width·height·[`texel_bytes`] of the format (or the format's texel
    /// size is not known).
    pub fn with_data(ctx: &Context, mut desc: ImageDesc, texels: &[u8]) -> Result<Image> {
        let per_texel = texel_bytes(desc.format).ok_or_else(|| {
            Error::invalid(
                "image data",
                format!(
                    "'{}': uploading data to {:?} images is not supported",
                    desc.name, desc.format
                ),
            )
        })?;
        let expected = u64::from(desc.width) * u64::from(desc.height) * per_texel;
        if texels.len() as u64 != expected {
            return Err(Error::invalid(
                "image data",
                format!(
                    "'{}' is {}×{} {:?} ({expected} bytes) but {} bytes were given",
                    desc.name,
                    desc.width,
                    desc.height,
                    desc.format,
                    texels.len()
                ),
            ));
        }
        desc.usage |= vk::ImageUsageFlags::TRANSFER_DST;
        let name = desc.name.clone();
        let image = Image::new(ctx, desc)?;
        let staging = Buffer::staging(ctx, &name, texels)?;
        let to_transfer = Barrier {
            src_stages: vk::PipelineStageFlags2::NONE,
            src_access: vk::AccessFlags2::NONE,
            dst_stages: vk::PipelineStageFlags2::ALL_TRANSFER,
            dst_access: vk::AccessFlags2::TRANSFER_WRITE,
            old_layout: vk::ImageLayout::UNDEFINED,
            new_layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        };
        ctx.one_shot(|rec| {
            rec.barriers(&[], &[(&image, to_transfer)]);
            rec.copy_buffer_to_image(&staging, &image);
        })?;
        image.set_state(AccessState::written(
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        ));
        Ok(image)
    }
}

/// Bytes per texel of the uncompressed colour formats the renderer
/// uploads; `None` for others (depth, compressed, multi-planar).
pub fn texel_bytes(format: vk::Format) -> Option<u64> {
    use vk::Format as F;
    Some(match format {
        F::R8_UNORM | F::R8_SNORM | F::R8_UINT | F::R8_SINT | F::R8_SRGB => 1,
        F::R8G8_UNORM | F::R8G8_SNORM | F::R8G8_UINT | F::R8G8_SINT => 2,
        F::R16_UNORM | F::R16_SNORM | F::R16_UINT | F::R16_SINT | F::R16_SFLOAT => 2,
        F::R8G8B8A8_UNORM | F::R8G8B8A8_SNORM | F::R8G8B8A8_UINT | F::R8G8B8A8_SINT | F::R8G8B8A8_SRGB => 4,
        F::B8G8R8A8_UNORM | F::B8G8R8A8_SRGB | F::A2B10G10R10_UNORM_PACK32 | F::B10G11R11_UFLOAT_PACK32 => 4,
        F::R16G16_UNORM | F::R16G16_SNORM | F::R16G16_UINT | F::R16G16_SINT | F::R16G16_SFLOAT => 4,
        F::R32_UINT | F::R32_SINT | F::R32_SFLOAT => 4,
        F::R16G16B16A16_UNORM | F::R16G16B16A16_SNORM | F::R16G16B16A16_UINT | F::R16G16B16A16_SINT => 8,
        F::R16G16B16A16_SFLOAT | F::R32G32_UINT | F::R32G32_SINT | F::R32G32_SFLOAT => 8,
        F::R32G32B32A32_UINT | F::R32G32B32A32_SINT | F::R32G32B32A32_SFLOAT => 16,
        _ => return None,
    })
}

enum ImageMemory {
    Owned(Allocation),
    Aliased(Arc<MemoryBlock>),
}

impl ImageMemory {
    fn allocation(&self) -> &Allocation {
        match self {
            ImageMemory::Owned(a) => a,
            ImageMemory::Aliased(block) => &block.allocation,
        }
    }

    /// The allocation to free with the image (none for a shared block, which
    /// frees its memory when its last image is gone).
    fn into_owned(self) -> Option<Allocation> {
        match self {
            ImageMemory::Owned(a) => Some(a),
            ImageMemory::Aliased(_) => None,
        }
    }
}

/// Device-local memory shared by images whose uses never overlap.
pub struct MemoryBlock {
    ctx: Context,
    allocation: Allocation,
    requirements: vk::MemoryRequirements,
}

impl MemoryBlock {
    /// Memory that can hold each of `descs` (one at a time), or `None` when
    /// no memory type suits them all.
    pub fn for_images(ctx: &Context, name: &str, descs: &[&ImageDesc]) -> Result<Option<Arc<MemoryBlock>>> {
        let mut merged = vk::MemoryRequirements {
            size: 0,
            alignment: 1,
            memory_type_bits: u32::MAX,
        };
        for desc in descs {
            let r = image_requirements(ctx, desc);
            merged.size = merged.size.max(r.size);
            merged.alignment = merged.alignment.max(r.alignment);
            merged.memory_type_bits &= r.memory_type_bits;
        }
        if merged.memory_type_bits == 0 || descs.is_empty() {
            return Ok(None);
        }
        let allocation = allocate(ctx, name, merged, MemoryLocation::GpuOnly, false)?;
        Ok(Some(Arc::new(MemoryBlock {
            ctx: ctx.clone(),
            allocation,
            requirements: merged,
        })))
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.requirements.size
    }

    fn fits(&self, name: &str, r: &vk::MemoryRequirements) -> Result<()> {
        let ok = r.size <= self.requirements.size
            && self.allocation.offset() % r.alignment == 0
            // The block's memory type is one of its merged bits; accepting all of them is sufficient.
            && r.memory_type_bits & self.requirements.memory_type_bits == self.requirements.memory_type_bits;
        if ok {
            Ok(())
        } else {
            Err(Error::Allocation {
                what: name.into(),
                message: "does not fit the shared memory block".into(),
            })
        }
    }
}

impl Drop for MemoryBlock {
    fn drop(&mut self) {
        let allocation = std::mem::take(&mut self.allocation);
        self.ctx.defer_destroy(Garbage::Memory(allocation));
    }
}

/// Memory requirements of an image with `desc`, without creating it
/// (`vkGetDeviceImageMemoryRequirements`, Vulkan 1.3 / maintenance4).
fn image_requirements(ctx: &Context, desc: &ImageDesc) -> vk::MemoryRequirements {
    let info = image_create_info(desc);
    let query = vk::DeviceImageMemoryRequirements::default().create_info(&info);
    let mut out = vk::MemoryRequirements2::default();
    // SAFETY: a valid create info; maintenance4 is enabled.
    unsafe { ctx.shared.device.get_device_image_memory_requirements(&query, &mut out) };
    out.memory_requirements
}

fn image_create_info(desc: &ImageDesc) -> vk::ImageCreateInfo<'static> {
    vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(desc.format)
        .extent(vk::Extent3D {
            width: desc.width,
            height: desc.height,
            depth: 1,
        })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(desc.usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
}
