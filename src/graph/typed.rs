//! Typed handles of graph resources and the accesses each kind accepts: an
//! [`ImageId`] is declared with an [`ImageAccess`], a [`BufferId`] (or an
//! upload region) with a [`BufferAccess`]; both map onto the graph's one
//! [`Access`] vocabulary, from which barriers are derived.

use super::access::{Access, Stage};
use super::ResourceId;

/// An image of a render graph (transient or imported).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ImageId(pub(crate) ResourceId);

/// A buffer of a render graph (transient or imported).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BufferId(pub(crate) ResourceId);

/// What a pass does with an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ImageAccess {
    /// Sampled through the heap's `texture2D[]` (SHADER_READ_ONLY_OPTIMAL).
    Sampled(Stage),
    /// Read as a storage image (GENERAL).
    StorageRead(Stage),
    /// Written as a storage image (GENERAL); previous contents not needed.
    StorageWrite(Stage),
    /// Read and written as a storage image (GENERAL).
    StorageReadWrite(Stage),
    /// Colour attachment, cleared or fully overwritten.
    ColorAttachmentWrite,
    /// Colour attachment loaded and blended.
    ColorAttachmentReadWrite,
    /// Depth attachment, tested and written.
    DepthAttachmentWrite,
    /// Depth attachment, tested only.
    DepthAttachmentRead,
    /// Source of a copy.
    TransferSrc,
    /// Destination of a copy; previous contents not needed.
    TransferDst,
}

/// What a pass does with a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BufferAccess {
    /// Storage buffer read through the heap.
    StorageRead(Stage),
    /// Storage buffer written through the heap; previous contents not needed.
    StorageWrite(Stage),
    /// Storage buffer read and written.
    StorageReadWrite(Stage),
    /// Vertex buffer (vertex input).
    Vertex,
    /// Index buffer.
    Index,
    /// Indirect draw/dispatch arguments.
    Indirect,
    /// Source of a copy.
    TransferSrc,
    /// Destination of a copy; previous contents not needed.
    TransferDst,
}

impl From<ImageAccess> for Access {
    fn from(a: ImageAccess) -> Access {
        match a {
            ImageAccess::Sampled(s) => Access::SampledImage(s),
            ImageAccess::StorageRead(s) => Access::StorageImageRead(s),
            ImageAccess::StorageWrite(s) => Access::StorageImageWrite(s),
            ImageAccess::StorageReadWrite(s) => Access::StorageImageReadWrite(s),
            ImageAccess::ColorAttachmentWrite => Access::ColorAttachmentWrite,
            ImageAccess::ColorAttachmentReadWrite => Access::ColorAttachmentReadWrite,
            ImageAccess::DepthAttachmentWrite => Access::DepthAttachmentWrite,
            ImageAccess::DepthAttachmentRead => Access::DepthAttachmentRead,
            ImageAccess::TransferSrc => Access::TransferSrc,
            ImageAccess::TransferDst => Access::TransferDst,
        }
    }
}

impl From<BufferAccess> for Access {
    fn from(a: BufferAccess) -> Access {
        match a {
            BufferAccess::StorageRead(s) => Access::StorageBufferRead(s),
            BufferAccess::StorageWrite(s) => Access::StorageBufferWrite(s),
            BufferAccess::StorageReadWrite(s) => Access::StorageBufferReadWrite(s),
            BufferAccess::Vertex => Access::VertexBuffer,
            BufferAccess::Index => Access::IndexBuffer,
            BufferAccess::Indirect => Access::IndirectBuffer,
            BufferAccess::TransferSrc => Access::TransferSrc,
            BufferAccess::TransferDst => Access::TransferDst,
        }
    }
}

/// A typed graph resource and the accesses it accepts.
pub trait Resource: Copy {
    /// [`ImageAccess`] for images, [`BufferAccess`] for buffers.
    type Access: Into<Access> + Copy;
    /// The untyped resource.
    fn id(self) -> ResourceId;
}

impl Resource for ImageId {
    type Access = ImageAccess;
    fn id(self) -> ResourceId {
        self.0
    }
}

impl Resource for BufferId {
    type Access = BufferAccess;
    fn id(self) -> ResourceId {
        self.0
    }
}
