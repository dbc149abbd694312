//! The bindless descriptor heap: one global, update-after-bind descriptor set
//! with arrays of sampled images, storage images, storage buffers and
//! samplers, and the one pipeline layout every pipeline uses.
//!
//! A resource gets a stable `u32` index ("handle") in its array when it is
//! created; shaders index the arrays with handles passed in push constants.
//! A released handle is reused only after the GPU has completed every
//! submission that could still read it (tracked on the timeline semaphore).
//! Handle 0 of every array is never given out: shaders read 0 as "none"
//! (e.g. no sky-light map), so a resource that happened to get slot 0
//! would be taken for a missing one.
//!
//! GLSL side (`glsl/include/heap.glsl`): binding 0 `texture2D[]`, 1 storage
//! `image2D[]`, 2 storage `buffer[]`, 3 `sampler[]`; push constants up to
//! [`PUSH_CONSTANT_BYTES`].

use std::sync::Mutex;

use ash::vk;

use super::context::vk_err;
use crate::error::{Error, Result};

/// Bytes of push constants every pipeline may use.
pub const PUSH_CONSTANT_BYTES: u32 = 128;

/// The descriptor arrays of the heap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeapKind {
    SampledImage = 0,
    StorageImage = 1,
    StorageBuffer = 2,
}

struct HandleAllocator {
    capacity: u32,
    /// The next never-used handle (from [`FIRST_HANDLE`]).
    next: u32,
    free: Vec<u32>,
    /// Released handles and the timeline value after which they are free.
    pending: Vec<(u64, u32)>,
}

/// The first handle given out: 0 means "none" to the shaders.
const FIRST_HANDLE: u32 = 1;

impl HandleAllocator {
    fn new(capacity: u32) -> HandleAllocator {
        HandleAllocator {
            capacity,
            next: FIRST_HANDLE,
            free: Vec::new(),
            pending: Vec::new(),
        }
    }

    fn allocate(&mut self, what: &str) -> Result<u32> {
        if let Some(h) = self.free.pop() {
            return Ok(h);
        }
        if self.next >= self.capacity {
            return Err(Error::Device(format!(
                "descriptor heap is full: all {} {what} handles are in use",
                self.capacity - FIRST_HANDLE
            )));
        }
        self.next += 1;
        Ok(self.next - 1)
    }
}

pub(crate) struct DescriptorHeap {
    pub layout: vk::DescriptorSetLayout,
    pub pipeline_layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    pub set: vk::DescriptorSet,
    samplers: Vec<vk::Sampler>,
    handles: Mutex<[HandleAllocator; 3]>,
}

impl DescriptorHeap {
    pub fn new(device: &ash::Device) -> Result<Self> {
        let counts = [4096u32, 4096, 4096, 16];
        let types = [
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::DescriptorType::STORAGE_IMAGE,
            vk::DescriptorType::STORAGE_BUFFER,
            vk::DescriptorType::SAMPLER,
        ];
        let bindings: Vec<_> = (0..4)
            .map(|i| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(types[i])
                    .descriptor_count(counts[i])
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        let flags = [vk::DescriptorBindingFlags::UPDATE_AFTER_BIND | vk::DescriptorBindingFlags::PARTIALLY_BOUND; 4];
        let mut binding_flags = vk::DescriptorSetLayoutBindingFlagsCreateInfo::default().binding_flags(&flags);
        let layout_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::UPDATE_AFTER_BIND_POOL)
            .bindings(&bindings)
            .push_next(&mut binding_flags);
        // SAFETY: valid create infos on a live device; the features were enabled.
        let layout = unsafe { device.create_descriptor_set_layout(&layout_info, None) }
            .map_err(vk_err("vkCreateDescriptorSetLayout"))?;
        let pool_sizes: Vec<_> = (0..4)
            .map(|i| vk::DescriptorPoolSize {
                ty: types[i],
                descriptor_count: counts[i],
            })
            .collect();
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .flags(vk::DescriptorPoolCreateFlags::UPDATE_AFTER_BIND)
            .max_sets(1)
            .pool_sizes(&pool_sizes);
        // SAFETY: as above.
        let pool =
            unsafe { device.create_descriptor_pool(&pool_info, None) }.map_err(vk_err("vkCreateDescriptorPool"))?;
        let layouts = [layout];
        let alloc_info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(pool)
            .set_layouts(&layouts);
        // SAFETY: the pool has room for exactly this set.
        let set =
            unsafe { device.allocate_descriptor_sets(&alloc_info) }.map_err(vk_err("vkAllocateDescriptorSets"))?[0];
        let push = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::ALL,
            offset: 0,
            size: PUSH_CONSTANT_BYTES,
        }];
        let pipeline_layout_info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(&layouts)
            .push_constant_ranges(&push);
        // SAFETY: as above.
        let pipeline_layout = unsafe { device.create_pipeline_layout(&pipeline_layout_info, None) }
            .map_err(vk_err("vkCreatePipelineLayout"))?;

        let mut samplers = Vec::new();
        for (filter, mode) in [
            (vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_EDGE),
            (vk::Filter::NEAREST, vk::SamplerAddressMode::CLAMP_TO_EDGE),
            (vk::Filter::LINEAR, vk::SamplerAddressMode::REPEAT),
            (vk::Filter::NEAREST, vk::SamplerAddressMode::REPEAT),
        ] {
            let info = vk::SamplerCreateInfo::default()
                .mag_filter(filter)
                .min_filter(filter)
                .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
                .address_mode_u(mode)
                .address_mode_v(mode)
                .address_mode_w(mode)
                .max_lod(vk::LOD_CLAMP_NONE);
            // SAFETY: as above.
            samplers.push(unsafe { device.create_sampler(&info, None) }.map_err(vk_err("vkCreateSampler"))?);
        }
        let sampler_infos: Vec<_> = samplers
            .iter()
            .map(|&s| vk::DescriptorImageInfo::default().sampler(s))
            .collect();
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(3)
            .descriptor_type(vk::DescriptorType::SAMPLER)
            .image_info(&sampler_infos);
        // SAFETY: the set is not in use yet; the samplers are live.
        unsafe { device.update_descriptor_sets(&[write], &[]) };

        let handles = [0, 1, 2].map(|i| HandleAllocator::new(counts[i]));
        Ok(DescriptorHeap {
            layout,
            pipeline_layout,
            pool,
            set,
            samplers,
            handles: Mutex::new(handles),
        })
    }

    fn allocate(&self, kind: HeapKind) -> Result<u32> {
        let mut handles = self
            .handles
            .lock()
            .map_err(|_| Error::Device("heap lock poisoned".into()))?;
        handles[kind as usize].allocate(match kind {
            HeapKind::SampledImage => "sampled-image",
            HeapKind::StorageImage => "storage-image",
            HeapKind::StorageBuffer => "storage-buffer",
        })
    }

    /// Gives `view` a handle in the sampled- or storage-image array.
    pub fn register_image(&self, device: &ash::Device, kind: HeapKind, view: vk::ImageView) -> Result<u32> {
        let handle = self.allocate(kind)?;
        let (binding, ty, layout) = match kind {
            HeapKind::SampledImage => (
                0,
                vk::DescriptorType::SAMPLED_IMAGE,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            ),
            _ => (1, vk::DescriptorType::STORAGE_IMAGE, vk::ImageLayout::GENERAL),
        };
        let info = [vk::DescriptorImageInfo::default().image_view(view).image_layout(layout)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.set)
            .dst_binding(binding)
            .dst_array_element(handle)
            .descriptor_type(ty)
            .image_info(&info);
        let _guard = self.handles.lock();
        // SAFETY: the binding is update-after-bind and this element is unused by any
        // pending command buffer (fresh or recycled only after the GPU finished);
        // the mutex serialises host access to the set.
        unsafe { device.update_descriptor_sets(&[write], &[]) };
        Ok(handle)
    }

    /// Gives a storage buffer a handle in the storage-buffer array.
    pub fn register_buffer(&self, device: &ash::Device, buffer: vk::Buffer, size: u64) -> Result<u32> {
        self.register_buffer_range(device, buffer, 0, size)
    }

    /// Gives the bytes `offset..offset + size` of a storage buffer a handle
    /// in the storage-buffer array (`offset` aligned to
    /// `minStorageBufferOffsetAlignment`).
    pub fn register_buffer_range(
        &self,
        device: &ash::Device,
        buffer: vk::Buffer,
        offset: u64,
        size: u64,
    ) -> Result<u32> {
        let handle = self.allocate(HeapKind::StorageBuffer)?;
        let info = [vk::DescriptorBufferInfo {
            buffer,
            offset,
            range: size,
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.set)
            .dst_binding(2)
            .dst_array_element(handle)
            .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
            .buffer_info(&info);
        let _guard = self.handles.lock();
        // SAFETY: as in `register_image`.
        unsafe { device.update_descriptor_sets(&[write], &[]) };
        Ok(handle)
    }

    /// Returns `handle`; it is reused once the timeline passes `after`.
    pub fn release(&self, kind: HeapKind, handle: u32, after: u64) {
        if let Ok(mut handles) = self.handles.lock() {
            handles[kind as usize].pending.push((after, handle));
        }
    }

    /// Makes handles whose last use has completed available again.
    pub fn recycle(&self, completed: u64) {
        if let Ok(mut handles) = self.handles.lock() {
            for allocator in handles.iter_mut() {
                if !allocator.pending.iter().any(|(after, _)| *after <= completed) {
                    continue;
                }
                let (ready, waiting): (Vec<_>, Vec<_>) =
                    allocator.pending.drain(..).partition(|(after, _)| *after <= completed);
                allocator.pending = waiting;
                allocator.free.extend(ready.into_iter().map(|(_, h)| h));
            }
        }
    }

    pub fn destroy(self, device: &ash::Device) {
        // SAFETY: the device is idle; nothing uses the heap any more.
        unsafe {
            for s in &self.samplers {
                device.destroy_sampler(*s, None);
            }
            device.destroy_pipeline_layout(self.pipeline_layout, None);
            device.destroy_descriptor_pool(self.pool, None);
            device.destroy_descriptor_set_layout(self.layout, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handle_zero_is_never_given_out() {
        let mut handles = HandleAllocator::new(3);
        assert_eq!(handles.allocate("test").ok(), Some(1));
        assert_eq!(handles.allocate("test").ok(), Some(2));
        let full = handles.allocate("test").err().map(|e| e.to_string());
        assert!(
            full.is_some_and(|e| e.contains("all 2 test handles")),
            "a full array is an error"
        );
        handles.free.push(1);
        assert_eq!(handles.allocate("test").ok(), Some(1));
    }
}
