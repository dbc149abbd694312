//! A safe command-buffer recorder. Passes record through it; barriers are
//! crate-private so only the render graph issues them.

use ash::vk;

use super::context::{vk_err, Context};
use super::heap::PUSH_CONSTANT_BYTES;
use super::image::Image;
use super::memory::{subresource_range, Barrier, Buffer};
use super::pipeline::{ComputePipeline, GraphicsPipeline};
use crate::error::{Error, Result};

/// How a colour attachment starts.
#[derive(Clone, Copy, Debug)]
pub enum LoadOp {
    Clear([f32; 4]),
    Load,
    DontCare,
}

/// Records commands into one command buffer.
pub struct CommandRecorder {
    pub(crate) ctx: Context,
    pub(crate) cmd: vk::CommandBuffer,
    bound_layout_is_graphics: Option<bool>,
}

impl CommandRecorder {
    pub(crate) fn new(ctx: &Context, cmd: vk::CommandBuffer) -> Self {
        CommandRecorder {
            ctx: ctx.clone(),
            cmd,
            bound_layout_is_graphics: None,
        }
    }

    fn device(&self) -> &ash::Device {
        &self.ctx.shared.device
    }

    /// One synchronization2 dependency for all the given transitions.
    pub(crate) fn barriers(&mut self, buffers: &[(&Buffer, Barrier)], images: &[(&Image, Barrier)]) {
        let mut batch = BarrierBatch::default();
        for (buffer, b) in buffers {
            batch.buffer(self, buffer, b);
        }
        for (image, b) in images {
            batch.image(self, image, b);
        }
        batch.flush(self);
    }

    /// Records `buffers` and `images` barriers as one dependency (the
    /// caller batches them, without allocating: [`BarrierBatch`]).
    fn pipeline_barrier(&mut self, buffers: &[vk::BufferMemoryBarrier2<'_>], images: &[vk::ImageMemoryBarrier2<'_>]) {
        if buffers.is_empty() && images.is_empty() {
            return;
        }
        let dependency = vk::DependencyInfo::default()
            .buffer_memory_barriers(buffers)
            .image_memory_barriers(images);
        // SAFETY: the command buffer is recording; the resources are alive until the
        // frame completes (the graph or caller holds them).
        unsafe { self.device().cmd_pipeline_barrier2(self.cmd, &dependency) };
    }

    /// Opens a debug label (RenderDoc, Nsight, validation messages).
    pub fn begin_label(&mut self, name: &str, color: [f32; 4]) {
        if self.ctx.shared.debug_device.is_some() {
            if let Ok(name) = std::ffi::CString::new(name) {
                self.begin_label_c(&name, color);
            }
        }
    }

    /// [`CommandRecorder::begin_label`] of a C string (no allocation).
    pub fn begin_label_c(&mut self, name: &std::ffi::CStr, color: [f32; 4]) {
        if let Some(debug) = &self.ctx.shared.debug_device {
            let label = vk::DebugUtilsLabelEXT::default().label_name(name).color(color);
            // SAFETY: recording command buffer; the label string outlives the call.
            unsafe { debug.cmd_begin_debug_utils_label(self.cmd, &label) };
        }
    }

    /// Closes the innermost debug label.
    pub fn end_label(&mut self) {
        if let Some(debug) = &self.ctx.shared.debug_device {
            // SAFETY: paired with `begin_label` by the caller.
            unsafe { debug.cmd_end_debug_utils_label(self.cmd) };
        }
    }

    pub(crate) fn write_timestamp(&mut self, pool: vk::QueryPool, index: u32, stage: vk::PipelineStageFlags2) {
        // SAFETY: the query was reset in this command buffer before use.
        unsafe { self.device().cmd_write_timestamp2(self.cmd, stage, pool, index) };
    }

    /// Begins query `index` of `pool` (a pipeline-statistics pool).
    pub(crate) fn begin_query(&mut self, pool: vk::QueryPool, index: u32) {
        // SAFETY: the query was reset in this command buffer before use and
        // is not active; the caller ends it outside any render pass instance,
        // as it began.
        unsafe { (self.device()).cmd_begin_query(self.cmd, pool, index, vk::QueryControlFlags::empty()) };
    }

    /// Ends query `index` of `pool`, begun by [`CommandRecorder::begin_query`].
    pub(crate) fn end_query(&mut self, pool: vk::QueryPool, index: u32) {
        // SAFETY: the query is active in this command buffer.
        unsafe { self.device().cmd_end_query(self.cmd, pool, index) };
    }

    pub(crate) fn reset_queries(&mut self, pool: vk::QueryPool, count: u32) {
        // SAFETY: recording outside a render pass instance.
        unsafe { self.device().cmd_reset_query_pool(self.cmd, pool, 0, count) };
    }

    fn bind_heap(&mut self, bind_point: vk::PipelineBindPoint) {
        let heap = &self.ctx.shared.heap;
        // SAFETY: the heap set is compatible with the global pipeline layout.
        unsafe {
            self.device()
                .cmd_bind_descriptor_sets(self.cmd, bind_point, heap.pipeline_layout, 0, &[heap.set], &[])
        };
    }

    /// Binds a compute pipeline and the descriptor heap.
    pub fn bind_compute(&mut self, pipeline: &ComputePipeline) {
        // SAFETY: the pipeline is alive for the frame (callers keep it).
        unsafe {
            self.device()
                .cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, pipeline.raw)
        };
        if self.bound_layout_is_graphics != Some(false) {
            self.bind_heap(vk::PipelineBindPoint::COMPUTE);
            self.bound_layout_is_graphics = Some(false);
        }
    }

    /// Binds a graphics pipeline and the descriptor heap.
    pub fn bind_graphics(&mut self, pipeline: &GraphicsPipeline) {
        // SAFETY: as in `bind_compute`.
        unsafe {
            self.device()
                .cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.raw)
        };
        if self.bound_layout_is_graphics != Some(true) {
            self.bind_heap(vk::PipelineBindPoint::GRAPHICS);
            self.bound_layout_is_graphics = Some(true);
        }
    }

    /// Sets the push constants (at most 128 bytes) for all stages.
    pub fn push_constants<T: bytemuck::Pod>(&mut self, data: &T) -> Result<()> {
        let bytes = bytemuck::bytes_of(data);
        if bytes.len() > PUSH_CONSTANT_BYTES as usize {
            return Err(Error::invalid(
                "push constants",
                format!("{} bytes, at most {PUSH_CONSTANT_BYTES}", bytes.len()),
            ));
        }
        let layout = self.ctx.shared.heap.pipeline_layout;
        // SAFETY: the range lies within the layout's push-constant range.
        unsafe {
            self.device()
                .cmd_push_constants(self.cmd, layout, vk::ShaderStageFlags::ALL, 0, bytes)
        };
        Ok(())
    }

    /// Dispatches `x·y·z` workgroups.
    pub fn dispatch(&mut self, x: u32, y: u32, z: u32) {
        // SAFETY: a compute pipeline is bound by the pass.
        unsafe { self.device().cmd_dispatch(self.cmd, x, y, z) };
    }

    /// Starts dynamic rendering into the attachments; viewport and scissor cover
    /// the first attachment.
    pub fn begin_rendering(&mut self, colors: &[(&Image, LoadOp)], depth: Option<(&Image, Option<f32>)>) {
        self.begin_rendering_from(colors.iter().copied(), depth)
    }

    /// [`CommandRecorder::begin_rendering`] from an iterator of colour
    /// attachments (what the render graph calls): at most 8, on the stack,
    /// so beginning a pass allocates nothing; more are ignored.
    pub fn begin_rendering_from<'i>(
        &mut self,
        colors: impl IntoIterator<Item = (&'i Image, LoadOp)>,
        depth: Option<(&Image, Option<f32>)>,
    ) {
        let color_info = |(image, load): (&Image, LoadOp)| {
            let (op, clear) = match load {
                LoadOp::Clear(c) => (vk::AttachmentLoadOp::CLEAR, c),
                LoadOp::Load => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
                LoadOp::DontCare => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
            };
            vk::RenderingAttachmentInfo::default()
                .image_view(image.view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(op)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    color: vk::ClearColorValue { float32: clear },
                })
        };
        let mut inline = [vk::RenderingAttachmentInfo::default(); 8];
        let mut count = 0;
        let mut size = depth.map(|(i, _)| (i.desc().width, i.desc().height));
        for (slot, color) in inline.iter_mut().zip(colors) {
            if count == 0 {
                size = Some((color.0.desc().width, color.0.desc().height));
            }
            *slot = color_info(color);
            count += 1;
        }
        let (width, height) = size.unwrap_or((1, 1));
        let color_infos = &inline[..count];
        let depth_info = depth.map(|(image, clear)| {
            // A depth buffer the graph declared read-only is neither cleared nor stored.
            let read_only = image.state().layout == vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL;
            vk::RenderingAttachmentInfo::default()
                .image_view(image.view)
                .image_layout(if read_only {
                    vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL
                } else {
                    vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL
                })
                .load_op(if clear.is_some() {
                    vk::AttachmentLoadOp::CLEAR
                } else {
                    vk::AttachmentLoadOp::LOAD
                })
                .store_op(if read_only {
                    vk::AttachmentStoreOp::NONE
                } else {
                    vk::AttachmentStoreOp::STORE
                })
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: clear.unwrap_or(1.0),
                        stencil: 0,
                    },
                })
        });
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent: vk::Extent2D { width, height },
        };
        let mut info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(color_infos);
        if let Some(d) = depth_info.as_ref() {
            info = info.depth_attachment(d);
        }
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: width as f32,
            height: height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: attachments are in the layouts the graph transitioned them to.
        unsafe {
            self.device().cmd_begin_rendering(self.cmd, &info);
            self.device().cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.device().cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// Restricts drawing to the `width`×`height` rectangle at (`x`, `y`) of
    /// the attachments (e.g. one cascade's quadrant of a shadow atlas).
    pub fn set_scissor(&mut self, x: u32, y: u32, width: u32, height: u32) {
        let rect = vk::Rect2D {
            offset: vk::Offset2D {
                x: x.min(i32::MAX as u32) as i32,
                y: y.min(i32::MAX as u32) as i32,
            },
            extent: vk::Extent2D { width, height },
        };
        // SAFETY: every graphics pipeline has a dynamic scissor; non-negative offsets.
        unsafe { self.device().cmd_set_scissor(self.cmd, 0, &[rect]) };
    }

    /// Ends dynamic rendering.
    pub fn end_rendering(&mut self) {
        // SAFETY: paired with `begin_rendering`.
        unsafe { self.device().cmd_end_rendering(self.cmd) };
    }

    /// Binds `buffer` as vertex buffer 0.
    pub fn bind_vertex_buffer(&mut self, buffer: &Buffer) {
        // SAFETY: the buffer has VERTEX_BUFFER usage (the graph declared it).
        unsafe { self.device().cmd_bind_vertex_buffers(self.cmd, 0, &[buffer.raw], &[0]) };
    }

    /// Binds `buffer` as a 32-bit index buffer.
    pub fn bind_index_buffer(&mut self, buffer: &Buffer) {
        // SAFETY: the buffer has INDEX_BUFFER usage.
        unsafe {
            self.device()
                .cmd_bind_index_buffer(self.cmd, buffer.raw, 0, vk::IndexType::UINT32)
        };
    }

    /// Draws non-indexed vertices.
    pub fn draw(&mut self, vertices: u32, instances: u32) {
        // SAFETY: inside a rendering instance with a graphics pipeline bound.
        unsafe { self.device().cmd_draw(self.cmd, vertices, instances, 0, 0) };
    }

    /// Draws `vertices` vertices from vertex index `first` (one instance).
    pub fn draw_range(&mut self, vertices: u32, first: u32) {
        // SAFETY: inside a rendering instance with a graphics pipeline bound.
        unsafe { self.device().cmd_draw(self.cmd, vertices, 1, first, 0) };
    }

    /// Draws indexed vertices.
    pub fn draw_indexed(&mut self, indices: u32, instances: u32) {
        // SAFETY: as in `draw`, with an index buffer bound.
        unsafe { self.device().cmd_draw_indexed(self.cmd, indices, instances, 0, 0, 0) };
    }

    /// Draws `indices` indices from `first_index` of the bound index buffer,
    /// `instances` instances from `first_instance` (per-instance attributes
    /// start at that instance).
    pub fn draw_indexed_range(&mut self, indices: u32, first_index: u32, instances: u32, first_instance: u32) {
        // SAFETY: as in `draw_indexed`.
        unsafe {
            self.device()
                .cmd_draw_indexed(self.cmd, indices, instances, first_index, 0, first_instance)
        };
    }

    /// Copies `size` bytes from the start of `src` to the start of `dst`.
    pub fn copy_buffer(&mut self, src: &Buffer, dst: &Buffer, size: u64) {
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset: 0,
            size,
        };
        // SAFETY: both buffers are large enough and in transfer states.
        unsafe { self.device().cmd_copy_buffer(self.cmd, src.raw, dst.raw, &[region]) };
    }

    fn image_copy_region(image: &Image) -> vk::BufferImageCopy {
        vk::BufferImageCopy {
            buffer_offset: 0,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: image.aspect(),
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D {
                width: image.desc().width,
                height: image.desc().height,
                depth: 1,
            },
        }
    }

    /// Copies the whole image into `dst`, tightly packed (image in TRANSFER_SRC layout).
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer) {
        let region = Self::image_copy_region(src);
        // SAFETY: the graph put `src` in TRANSFER_SRC_OPTIMAL; `dst` is large enough.
        unsafe {
            self.device().cmd_copy_image_to_buffer(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                &[region],
            )
        };
    }

    /// Fills the whole colour image `dst` (TRANSFER_DST layout) with `color`.
    pub fn clear_color_image(&mut self, dst: &Image, color: [f32; 4]) {
        let value = vk::ClearColorValue { float32: color };
        let range = super::memory::subresource_range(vk::ImageAspectFlags::COLOR);
        // SAFETY: the graph put `dst` in TRANSFER_DST_OPTIMAL; it is a colour image.
        unsafe {
            (self.device()).cmd_clear_color_image(
                self.cmd,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &value,
                &[range],
            )
        };
    }

    /// Scales the whole colour image `src` (TRANSFER_SRC layout) into the
    /// rectangle `to` = (x, y, width, height) of `dst` (TRANSFER_DST),
    /// filtered linearly, converting the format (a swizzle between RGBA
    /// and BGRA, say). Both formats must support blits (8-bit UNORM do).
    pub fn blit_image(&mut self, src: &Image, dst: &Image, to: [u32; 4]) {
        let corner = |x: u32, y: u32| vk::Offset3D {
            x: x as i32,
            y: y as i32,
            z: 0,
        };
        let (s, d) = (src.desc(), dst.desc());
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let x1 = (to[0] + to[2]).min(d.width);
        let y1 = (to[1] + to[3]).min(d.height);
        let region = vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([
                corner(0, 0),
                vk::Offset3D {
                    z: 1,
                    ..corner(s.width, s.height)
                },
            ])
            .dst_subresource(layers)
            .dst_offsets([corner(to[0], to[1]), vk::Offset3D { z: 1, ..corner(x1, y1) }]);
        // SAFETY: the graph put `src` in TRANSFER_SRC_OPTIMAL and `dst` in
        // TRANSFER_DST_OPTIMAL; the regions lie within both images.
        unsafe {
            self.device().cmd_blit_image(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
                vk::Filter::LINEAR,
            )
        };
    }

    /// Copies tightly packed texels from `src` into the whole image (TRANSFER_DST layout).
    pub fn copy_buffer_to_image(&mut self, src: &Buffer, dst: &Image) {
        let region = Self::image_copy_region(dst);
        // SAFETY: `dst` is in TRANSFER_DST_OPTIMAL; `src` holds enough texels.
        unsafe {
            self.device().cmd_copy_buffer_to_image(
                self.cmd,
                src.raw,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
    }
}

impl Context {
    /// Records commands with `record`, submits them and waits: for uploads and
    /// setup work outside the per-frame graph.
    pub(crate) fn one_shot(&self, record: impl FnOnce(&mut CommandRecorder)) -> Result<()> {
        let device = &self.shared.device;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.shared.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: valid create info on a live device.
        let pool = unsafe { device.create_command_pool(&pool_info, None) }.map_err(vk_err("vkCreateCommandPool"))?;
        let result = (|| {
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            // SAFETY: the pool is live and owned by this thread.
            let cmd =
                unsafe { device.allocate_command_buffers(&alloc) }.map_err(vk_err("vkAllocateCommandBuffers"))?[0];
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            // SAFETY: fresh command buffer.
            unsafe { device.begin_command_buffer(cmd, &begin) }.map_err(vk_err("vkBeginCommandBuffer"))?;
            record(&mut CommandRecorder::new(self, cmd));
            // SAFETY: recording.
            unsafe { device.end_command_buffer(cmd) }.map_err(vk_err("vkEndCommandBuffer"))?;
            let value = self.submit(cmd)?;
            self.wait(value)
        })();
        // SAFETY: the submission completed (or was never made), so the pool is idle.
        unsafe { device.destroy_command_pool(pool, None) };
        result
    }
}

/// Barriers gathered on the stack and recorded as few dependencies as
/// possible (one unless more than [`BarrierBatch::CAPACITY`] of a kind):
/// the frame's barriers allocate nothing.
pub(crate) struct BarrierBatch {
    buffers: [vk::BufferMemoryBarrier2<'static>; BarrierBatch::CAPACITY],
    images: [vk::ImageMemoryBarrier2<'static>; BarrierBatch::CAPACITY],
    counts: (usize, usize),
}

impl Default for BarrierBatch {
    fn default() -> Self {
        BarrierBatch {
            buffers: [vk::BufferMemoryBarrier2::default(); BarrierBatch::CAPACITY],
            images: [vk::ImageMemoryBarrier2::default(); BarrierBatch::CAPACITY],
            counts: (0, 0),
        }
    }
}

impl BarrierBatch {
    pub(crate) const CAPACITY: usize = 32;

    /// Adds a barrier of `buffer` (recording the batch first when full).
    pub(crate) fn buffer(&mut self, cmd: &mut CommandRecorder, buffer: &Buffer, b: &Barrier) {
        if self.counts.0 == Self::CAPACITY {
            self.flush(cmd);
        }
        self.buffers[self.counts.0] = vk::BufferMemoryBarrier2::default()
            .src_stage_mask(b.src_stages)
            .src_access_mask(b.src_access)
            .dst_stage_mask(b.dst_stages)
            .dst_access_mask(b.dst_access)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(buffer.raw)
            .offset(0)
            .size(vk::WHOLE_SIZE);
        self.counts.0 += 1;
    }

    /// Adds a barrier of `image` (recording the batch first when full).
    pub(crate) fn image(&mut self, cmd: &mut CommandRecorder, image: &Image, b: &Barrier) {
        if self.counts.1 == Self::CAPACITY {
            self.flush(cmd);
        }
        self.images[self.counts.1] = vk::ImageMemoryBarrier2::default()
            .src_stage_mask(b.src_stages)
            .src_access_mask(b.src_access)
            .dst_stage_mask(b.dst_stages)
            .dst_access_mask(b.dst_access)
            .old_layout(b.old_layout)
            .new_layout(b.new_layout)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.raw)
            .subresource_range(subresource_range(image.aspect()));
        self.counts.1 += 1;
    }

    /// Records the gathered barriers as one dependency and empties the batch.
    pub(crate) fn flush(&mut self, cmd: &mut CommandRecorder) {
        let (b, i) = self.counts;
        cmd.pipeline_barrier(&self.buffers[..b], &self.images[..i]);
        self.counts = (0, 0);
    }
}
