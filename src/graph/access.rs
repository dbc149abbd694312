//! What a pass does with a resource, and the pure function that derives the
//! synchronization2 barrier between what happened to a resource before and
//! what a pass does next. No device needed: unit-tested below.

use crate::vulkan::{
    AccessFlags2 as A, AccessState, Barrier, BufferUsageFlags, ImageLayout as L, ImageUsageFlags,
    PipelineStageFlags2 as S,
};

/// Shader stages an access happens in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    Compute,
    Vertex,
    Fragment,
    /// Vertex and fragment.
    Graphics,
}

impl Stage {
    fn flags(self) -> S {
        match self {
            Stage::Compute => S::COMPUTE_SHADER,
            Stage::Vertex => S::VERTEX_SHADER,
            Stage::Fragment => S::FRAGMENT_SHADER,
            Stage::Graphics => S::VERTEX_SHADER | S::FRAGMENT_SHADER,
        }
    }
}

/// How a pass uses a resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Sampled through the heap's `texture2D[]` (SHADER_READ_ONLY_OPTIMAL).
    SampledImage(Stage),
    /// Read as a storage image (GENERAL).
    StorageImageRead(Stage),
    /// Written as a storage image (GENERAL); previous contents not needed.
    StorageImageWrite(Stage),
    /// Read and written as a storage image (GENERAL).
    StorageImageReadWrite(Stage),
    /// Colour attachment, cleared or fully overwritten.
    ColorAttachmentWrite,
    /// Colour attachment loaded and blended.
    ColorAttachmentReadWrite,
    /// Depth attachment, tested and written.
    DepthAttachmentWrite,
    /// Depth attachment, tested only.
    DepthAttachmentRead,
    /// Storage buffer read through the heap.
    StorageBufferRead(Stage),
    /// Storage buffer written through the heap; previous contents not needed.
    StorageBufferWrite(Stage),
    /// Storage buffer read and written.
    StorageBufferReadWrite(Stage),
    /// Vertex buffer (vertex input).
    VertexBuffer,
    /// Index buffer.
    IndexBuffer,
    /// Indirect draw/dispatch arguments.
    IndirectBuffer,
    /// Source of a copy.
    TransferSrc,
    /// Destination of a copy; previous contents not needed.
    TransferDst,
    /// Read by the host after the frame completes.
    HostRead,
    /// Presented to a window after the frame (a swapchain image's final
    /// layout; the submission's semaphore signal orders it).
    Present,
}

impl Access {
    /// Pipeline stages, access flags and image layout of this access.
    pub fn state(self) -> (S, A, L) {
        use Access::*;
        match self {
            SampledImage(s) => (s.flags(), A::SHADER_SAMPLED_READ, L::SHADER_READ_ONLY_OPTIMAL),
            StorageImageRead(s) => (s.flags(), A::SHADER_STORAGE_READ, L::GENERAL),
            StorageImageWrite(s) => (s.flags(), A::SHADER_STORAGE_WRITE, L::GENERAL),
            StorageImageReadWrite(s) => (s.flags(), A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE, L::GENERAL),
            ColorAttachmentWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            ColorAttachmentReadWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            DepthAttachmentWrite => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                L::DEPTH_ATTACHMENT_OPTIMAL,
            ),
            DepthAttachmentRead => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_READ_ONLY_OPTIMAL,
            ),
            StorageBufferRead(s) => (s.flags(), A::SHADER_STORAGE_READ, L::UNDEFINED),
            StorageBufferWrite(s) => (s.flags(), A::SHADER_STORAGE_WRITE, L::UNDEFINED),
            StorageBufferReadWrite(s) => (
                s.flags(),
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                L::UNDEFINED,
            ),
            VertexBuffer => (S::VERTEX_ATTRIBUTE_INPUT, A::VERTEX_ATTRIBUTE_READ, L::UNDEFINED),
            IndexBuffer => (S::INDEX_INPUT, A::INDEX_READ, L::UNDEFINED),
            IndirectBuffer => (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ, L::UNDEFINED),
            TransferSrc => (S::ALL_TRANSFER, A::TRANSFER_READ, L::TRANSFER_SRC_OPTIMAL),
            TransferDst => (S::ALL_TRANSFER, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
            HostRead => (S::HOST, A::HOST_READ, L::UNDEFINED),
            Present => (S::NONE, A::NONE, L::PRESENT_SRC_KHR),
        }
    }

    /// Whether the access writes.
    pub fn writes(self) -> bool {
        use Access::*;
        matches!(
            self,
            StorageImageWrite(_)
                | StorageImageReadWrite(_)
                | ColorAttachmentWrite
                | ColorAttachmentReadWrite
                | DepthAttachmentWrite
                | StorageBufferWrite(_)
                | StorageBufferReadWrite(_)
                | TransferDst
        )
    }

    /// Whether the access reads.
    pub fn reads(self) -> bool {
        use Access::*;
        !matches!(
            self,
            StorageImageWrite(_) | ColorAttachmentWrite | StorageBufferWrite(_) | TransferDst
        )
    }

    /// Whether this access applies to images (else buffers).
    pub fn is_image(self) -> bool {
        use Access::*;
        matches!(
            self,
            SampledImage(_)
                | StorageImageRead(_)
                | StorageImageWrite(_)
                | StorageImageReadWrite(_)
                | ColorAttachmentWrite
                | ColorAttachmentReadWrite
                | DepthAttachmentWrite
                | DepthAttachmentRead
                | TransferSrc
                | TransferDst
                | Present
        )
    }

    /// Whether this access applies to buffers (transfers apply to both).
    pub fn is_buffer(self) -> bool {
        !self.is_image() || matches!(self, Access::TransferSrc | Access::TransferDst)
    }

    /// Image usage flags this access needs.
    pub fn image_usage(self) -> ImageUsageFlags {
        use Access::*;
        match self {
            SampledImage(_) => ImageUsageFlags::SAMPLED,
            StorageImageRead(_) | StorageImageWrite(_) | StorageImageReadWrite(_) => ImageUsageFlags::STORAGE,
            ColorAttachmentWrite | ColorAttachmentReadWrite => ImageUsageFlags::COLOR_ATTACHMENT,
            DepthAttachmentWrite | DepthAttachmentRead => ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            TransferSrc => ImageUsageFlags::TRANSFER_SRC,
            TransferDst => ImageUsageFlags::TRANSFER_DST,
            _ => ImageUsageFlags::empty(),
        }
    }

    /// Buffer usage flags this access needs.
    pub fn buffer_usage(self) -> BufferUsageFlags {
        use Access::*;
        match self {
            StorageBufferRead(_) | StorageBufferWrite(_) | StorageBufferReadWrite(_) => {
                BufferUsageFlags::STORAGE_BUFFER
            }
            VertexBuffer => BufferUsageFlags::VERTEX_BUFFER,
            IndexBuffer => BufferUsageFlags::INDEX_BUFFER,
            IndirectBuffer => BufferUsageFlags::INDIRECT_BUFFER,
            TransferSrc => BufferUsageFlags::TRANSFER_SRC,
            TransferDst => BufferUsageFlags::TRANSFER_DST,
            _ => BufferUsageFlags::empty(),
        }
    }
}

/// Derives the barrier (if any) needed before `access`, given what happened
/// to the resource so far, and updates `state`.
///
/// * A write, or a layout change, waits for the last write (write-after-write)
///   and for every read since (write-after-read); the last write's accesses are
///   made available. A layout change then counts as a write at the
///   destination stages.
/// * A read waits for the last write unless that write was already made
///   visible to the reading stages and accesses by an earlier barrier.
/// * `discard`: the previous contents are not needed (transient resource at
///   its first use in a frame, or a pure write), so the old layout is UNDEFINED.
pub fn derive_barrier(state: &mut AccessState, access: Access, discard: bool) -> Option<Barrier> {
    let (stages, accesses, layout) = access.state();
    let layout = if access.is_image() { layout } else { L::UNDEFINED };
    let layout_change = layout != state.layout && layout != L::UNDEFINED;
    let old_layout = if discard && !access.reads() {
        L::UNDEFINED
    } else {
        state.layout
    };
    let read_access = accesses & !write_access_bits();
    let barrier;
    if access.writes() || layout_change {
        let src_stages = state.write_stages | state.read_stages | state.visible_stages;
        let src_access = state.write_access;
        barrier = if src_stages.is_empty() && !layout_change {
            None
        } else {
            Some(Barrier {
                src_stages,
                src_access,
                dst_stages: stages,
                dst_access: accesses,
                old_layout: if layout_change { old_layout } else { state.layout },
                new_layout: if layout_change { layout } else { state.layout },
            })
        };
        if access.writes() {
            *state = AccessState::written(stages, accesses & write_access_bits(), layout);
        } else {
            // A layout transition for a read: it is a write at `stages`, visible to this read.
            *state = AccessState {
                write_stages: stages,
                write_access: A::NONE,
                read_stages: stages,
                visible_stages: stages,
                visible_access: read_access,
                layout,
            };
        }
        if access.writes() && access.reads() {
            state.read_stages = stages;
        }
    } else {
        let covered = state.visible_stages.contains(stages) && state.visible_access.contains(read_access);
        if state.write_stages.is_empty() || covered {
            barrier = None;
        } else {
            barrier = Some(Barrier {
                src_stages: state.write_stages | state.visible_stages,
                src_access: state.write_access,
                dst_stages: stages,
                dst_access: accesses,
                old_layout: state.layout,
                new_layout: state.layout,
            });
            state.visible_stages |= stages;
            state.visible_access |= read_access;
        }
        state.read_stages |= stages;
    }
    barrier
}

/// Every access flag that writes.
pub fn write_access_bits() -> A {
    A::SHADER_STORAGE_WRITE
        | A::SHADER_WRITE
        | A::COLOR_ATTACHMENT_WRITE
        | A::DEPTH_STENCIL_ATTACHMENT_WRITE
        | A::TRANSFER_WRITE
        | A::HOST_WRITE
        | A::MEMORY_WRITE
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresh() -> AccessState {
        AccessState::UNUSED
    }

    #[test]
    fn first_write_to_a_fresh_buffer_needs_no_barrier() {
        let mut s = fresh();
        assert_eq!(
            derive_barrier(&mut s, Access::StorageBufferWrite(Stage::Compute), true),
            None
        );
        assert_eq!(s.write_stages, S::COMPUTE_SHADER);
        assert_eq!(s.write_access, A::SHADER_STORAGE_WRITE);
    }

    #[test]
    fn render_to_vertex_buffer_barrier_is_exact() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::StorageBufferWrite(Stage::Compute), true);
        let b = derive_barrier(&mut s, Access::VertexBuffer, false).expect("RAW needs a barrier");
        assert_eq!(b.src_stages, S::COMPUTE_SHADER);
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.dst_stages, S::VERTEX_ATTRIBUTE_INPUT);
        assert_eq!(b.dst_access, A::VERTEX_ATTRIBUTE_READ);
        // A second draw from the same buffer needs nothing more.
        assert_eq!(derive_barrier(&mut s, Access::VertexBuffer, false), None);
    }

    #[test]
    fn write_after_read_waits_for_readers_without_memory_access() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::StorageBufferWrite(Stage::Compute), true);
        derive_barrier(&mut s, Access::VertexBuffer, false);
        let b = derive_barrier(&mut s, Access::StorageBufferWrite(Stage::Compute), true).expect("WAR");
        assert!(b.src_stages.contains(S::VERTEX_ATTRIBUTE_INPUT));
        assert!(b.src_stages.contains(S::COMPUTE_SHADER));
        assert_eq!(b.dst_access, A::SHADER_STORAGE_WRITE);
    }

    #[test]
    fn write_after_write_makes_the_first_write_available() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::TransferDst, true);
        let b = derive_barrier(&mut s, Access::StorageBufferWrite(Stage::Compute), true).expect("WAW");
        assert_eq!(b.src_stages, S::ALL_TRANSFER);
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
    }

    #[test]
    fn image_layout_transitions_follow_the_access() {
        let mut s = fresh();
        let b = derive_barrier(&mut s, Access::ColorAttachmentWrite, true).expect("initial layout transition");
        assert_eq!(b.old_layout, L::UNDEFINED);
        assert_eq!(b.new_layout, L::COLOR_ATTACHMENT_OPTIMAL);
        let b = derive_barrier(&mut s, Access::StorageImageRead(Stage::Compute), false).expect("RAW + layout");
        assert_eq!(b.old_layout, L::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(b.new_layout, L::GENERAL);
        assert_eq!(b.src_stages, S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(b.dst_access, A::SHADER_STORAGE_READ);
        let b = derive_barrier(&mut s, Access::TransferSrc, false).expect("layout change");
        assert_eq!(b.old_layout, L::GENERAL);
        assert_eq!(b.new_layout, L::TRANSFER_SRC_OPTIMAL);
        assert!(
            b.src_stages.contains(S::COMPUTE_SHADER),
            "waits for the compute read (WAR on layout)"
        );
    }

    #[test]
    fn read_in_a_new_stage_chains_on_the_earlier_barrier() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::StorageImageWrite(Stage::Compute), true);
        let first = derive_barrier(&mut s, Access::SampledImage(Stage::Fragment), false).expect("transition");
        assert_eq!(first.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
        // Same stage again: already visible.
        assert_eq!(
            derive_barrier(&mut s, Access::SampledImage(Stage::Fragment), false),
            None
        );
        // Vertex stage: must wait for the transition, which completed before FRAGMENT.
        let b = derive_barrier(&mut s, Access::SampledImage(Stage::Vertex), false).expect("new stage");
        assert!(b.src_stages.contains(S::FRAGMENT_SHADER));
        assert_eq!(b.old_layout, b.new_layout);
    }

    #[test]
    fn discarding_transient_uses_undefined_old_layout() {
        let mut s = AccessState::written(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE, L::GENERAL);
        s.read_stages = S::ALL_TRANSFER;
        let b = derive_barrier(&mut s, Access::ColorAttachmentWrite, true).expect("WAR across frames");
        assert_eq!(b.old_layout, L::UNDEFINED);
        assert!(b.src_stages.contains(S::ALL_TRANSFER | S::COMPUTE_SHADER));
    }

    #[test]
    fn read_write_storage_keeps_contents() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::StorageImageWrite(Stage::Compute), true);
        let b = derive_barrier(&mut s, Access::StorageImageReadWrite(Stage::Compute), true).expect("RAW/WAW");
        assert_eq!(b.old_layout, L::GENERAL, "read-write must not discard");
        assert_eq!(b.new_layout, L::GENERAL);
    }

    #[test]
    fn host_read_after_copy() {
        let mut s = fresh();
        derive_barrier(&mut s, Access::TransferDst, true);
        let b = derive_barrier(&mut s, Access::HostRead, false).expect("host visibility");
        assert_eq!(b.dst_stages, S::HOST);
        assert_eq!(b.dst_access, A::HOST_READ);
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
    }

    #[test]
    fn usage_flags_cover_accesses() {
        assert!(Access::VertexBuffer
            .buffer_usage()
            .contains(BufferUsageFlags::VERTEX_BUFFER));
        assert!(Access::SampledImage(Stage::Fragment)
            .image_usage()
            .contains(ImageUsageFlags::SAMPLED));
        assert!(Access::DepthAttachmentWrite.is_image() && !Access::DepthAttachmentWrite.is_buffer());
        assert!(Access::TransferSrc.is_image() && Access::TransferSrc.is_buffer());
    }
}
