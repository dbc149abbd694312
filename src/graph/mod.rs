//! The render graph. Passes declare what they read and write; [`RenderGraph::bake`]
//! orders them, culls the ones nobody needs, creates the transient resources
//! and returns a [`BakedGraph`] that records and times every frame, deriving
//! each barrier and layout transition from the declared accesses.
//!
//! Handles are typed: an [`ImageId`] takes an [`ImageAccess`], a
//! [`BufferId`] a [`BufferAccess`], so a buffer cannot be declared as an image
//! access. Host-written per-frame data goes into one upload arena per frame
//! slot ([`RenderGraph::upload_region`], [`UploadRegion`]), written before
//! recording ([`BakedGraph::uploads`]); recording closures are `Fn + Send +
//! Sync` and only read the frame's prepared data `P`.
//!
//! ```text
//! let mut graph = RenderGraph::new();
//! let vertices = graph.import_buffer(vertex_buffer);
//! let hdr = graph.create_image("hdr", ImageInfo::new(w, h, Format::R32G32B32A32_SFLOAT));
//! graph.pass("terrain.grid")
//!     .write(vertices, BufferAccess::StorageWrite(Stage::Compute))
//!     .record(move |pass, frame: &Frame| { /* bind, push, dispatch */ Ok(()) });
//! graph.pass("terrain.draw").graphics()
//!     .read(vertices, BufferAccess::Vertex)
//!     .write(hdr, ImageAccess::ColorAttachmentWrite)
//!     .record(move |pass, frame| { /* begin_rendering, draw */ Ok(()) });
//! let mut baked = graph.bake(&ctx)?;
//! baked.execute(&mut frames, &frame, &[])?;
//! ```

pub mod access;
mod alias;
mod bake;
mod execute;
mod typed;
mod uploads;

use std::sync::Arc;

#[cfg(test)]
pub use access::derive_barrier;
pub use access::{Access, Stage};
pub use bake::{BakedGraph, DEFAULT_PROFILE_HISTORY};
pub use execute::{CpuStage, FrameOutcome, PassContext};
pub use typed::{BufferAccess, BufferId, ImageAccess, ImageId, Resource};
pub use uploads::{UploadRegion, UploadWriter};

use crate::error::Result;
use crate::vulkan::{Buffer, Format, Image, MemoryLocation};

/// A resource of the graph (transient or imported), by index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ResourceId(pub(crate) usize);

/// Size and format of a transient image; usage is derived from the accesses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageInfo {
    pub width: u32,
    pub height: u32,
    pub format: Format,
}

impl ImageInfo {
    /// A `width`×`height` image of `format`.
    pub fn new(width: u32, height: u32, format: Format) -> Self {
        ImageInfo { width, height, format }
    }
}

/// Size and memory of a transient buffer; usage is derived from the accesses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BufferInfo {
    pub size: u64,
    pub location: MemoryLocation,
}

pub(crate) enum ResourceDecl {
    TransientImage {
        name: String,
        info: ImageInfo,
    },
    TransientBuffer {
        name: String,
        info: BufferInfo,
    },
    /// One physical image per frame slot (or one shared by all).
    ImportedImages(Vec<Arc<Image>>),
    ImportedBuffers(Vec<Arc<Buffer>>),
    /// The upload arena: one host-visible buffer per frame slot, created at
    /// bake time from the regions declared.
    Uploads,
}

impl ResourceDecl {
    pub(crate) fn is_imported(&self) -> bool {
        matches!(
            self,
            ResourceDecl::ImportedImages(_) | ResourceDecl::ImportedBuffers(_) | ResourceDecl::Uploads
        )
    }

    pub(crate) fn is_image(&self) -> bool {
        matches!(
            self,
            ResourceDecl::TransientImage { .. } | ResourceDecl::ImportedImages(_)
        )
    }

    pub(crate) fn name(&self) -> String {
        match self {
            ResourceDecl::TransientImage { name, .. } | ResourceDecl::TransientBuffer { name, .. } => name.clone(),
            ResourceDecl::ImportedImages(i) => i.first().map(|i| i.desc().name.clone()).unwrap_or_default(),
            ResourceDecl::ImportedBuffers(b) => b.first().map(|b| b.desc().name.clone()).unwrap_or_default(),
            ResourceDecl::Uploads => "upload arena".into(),
        }
    }
}

/// The recording closure of a pass: gets the pass context and the frame's
/// prepared data. `Fn`, not `FnMut`: recording reads, it never plans.
pub type RecordFn<P> = Box<dyn Fn(&mut PassContext<'_>, &P) -> Result<()> + Send + Sync>;

/// What kind of queue work a pass records (for labels and timestamps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassKind {
    Compute,
    Graphics,
    Transfer,
}

pub(crate) struct PassDecl<P> {
    pub name: String,
    pub kind: PassKind,
    pub uses: Vec<(ResourceId, Access)>,
    pub record: Option<RecordFn<P>>,
    /// Accesses declared with the wrong verb (`read` of a write access, or
    /// `write` of a read-only one), reported when baking.
    pub misdeclared: Vec<String>,
}

/// A render graph being declared. `P` is the per-frame parameter type every
/// pass's recording closure receives (camera, time, ...).
pub struct RenderGraph<P> {
    pub(crate) resources: Vec<ResourceDecl>,
    pub(crate) passes: Vec<PassDecl<P>>,
    /// Resources whose final contents are wanted after the frame.
    pub(crate) outputs: Vec<(ResourceId, Option<Access>)>,
    /// Let transient images whose uses do not overlap share memory.
    pub(crate) alias_transients: bool,
    /// Regions of the upload arena: (name, size in bytes).
    pub(crate) upload_regions: Vec<(String, u64)>,
    /// The upload arena's resource, once a region was declared.
    pub(crate) upload_arena: Option<ResourceId>,
}

impl<P> Default for RenderGraph<P> {
    fn default() -> Self {
        RenderGraph {
            resources: Vec::new(),
            passes: Vec::new(),
            outputs: Vec::new(),
            alias_transients: true,
            upload_regions: Vec::new(),
            upload_arena: None,
        }
    }
}

impl<P: 'static> RenderGraph<P> {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// A transient image, created at bake time and reused every frame.
    pub fn create_image(&mut self, name: &str, info: ImageInfo) -> ImageId {
        ImageId(self.declare(ResourceDecl::TransientImage {
            name: name.into(),
            info,
        }))
    }

    fn declare(&mut self, decl: ResourceDecl) -> ResourceId {
        self.resources.push(decl);
        ResourceId(self.resources.len() - 1)
    }

    /// A transient buffer, created at bake time and reused every frame.
    pub fn create_buffer(&mut self, name: &str, info: BufferInfo) -> BufferId {
        BufferId(self.declare(ResourceDecl::TransientBuffer {
            name: name.into(),
            info,
        }))
    }

    /// A persistent image owned outside the graph; its state is tracked across
    /// frames (and across graphs).
    pub fn import_image(&mut self, image: Arc<Image>) -> ImageId {
        self.import_images_per_frame(vec![image])
    }

    /// One persistent image per frame in flight, used round-robin.
    pub fn import_images_per_frame(&mut self, images: Vec<Arc<Image>>) -> ImageId {
        ImageId(self.declare(ResourceDecl::ImportedImages(images)))
    }

    /// A persistent buffer owned outside the graph (vertex buffers, atlases).
    pub fn import_buffer(&mut self, buffer: Arc<Buffer>) -> BufferId {
        self.import_buffers_per_frame(vec![buffer])
    }

    /// One persistent buffer per frame in flight (readback targets).
    pub fn import_buffers_per_frame(&mut self, buffers: Vec<Arc<Buffer>>) -> BufferId {
        BufferId(self.declare(ResourceDecl::ImportedBuffers(buffers)))
    }

    /// `size` bytes of the per-frame upload arena: host-written before each
    /// frame is recorded ([`BakedGraph::uploads`]), read by shaders through
    /// their own heap handle ([`PassContext::upload`]) from offset 0. Every
    /// region of every technique lives in one host-visible buffer per frame
    /// slot.
    pub fn upload_region(&mut self, name: &str, size: u64) -> UploadRegion {
        let arena = match self.upload_arena {
            Some(arena) => arena,
            None => {
                let arena = self.declare(ResourceDecl::Uploads);
                self.upload_arena = Some(arena);
                arena
            }
        };
        self.upload_regions.push((name.into(), size.max(4)));
        UploadRegion {
            index: self.upload_regions.len() - 1,
            size: size.max(4),
            arena,
        }
    }

    /// Whether transient images whose uses within a frame do not overlap may
    /// share memory (default: yes).
    pub fn set_transient_aliasing(&mut self, enabled: bool) {
        self.alias_transients = enabled;
    }

    /// Keeps the passes that produce `resource` even if no pass reads it.
    pub fn keep(&mut self, resource: impl Resource) {
        self.outputs.push((resource.id(), None));
    }

    /// The host reads `buffer` after the frame: a final barrier makes the
    /// GPU's writes visible to the host.
    pub fn read_back(&mut self, buffer: BufferId) {
        self.outputs.push((buffer.0, Some(Access::HostRead)));
    }

    /// Declares `name`, a transfer pass copying each image into its buffer,
    /// and reads the buffers back to the host after the frame.
    pub fn read_back_images(&mut self, name: &str, copies: Vec<(ImageId, BufferId)>) {
        let mut pass = self.pass(name).transfer();
        for &(image, buffer) in &copies {
            pass = pass
                .read(image, ImageAccess::TransferSrc)
                .write(buffer, BufferAccess::TransferDst);
        }
        let recorded = copies.clone();
        pass.record(move |pass, _| {
            for &(image, buffer) in &recorded {
                let (image, buffer) = (pass.image(image)?, pass.buffer(buffer)?);
                pass.cmd().copy_image_to_buffer(image, buffer);
            }
            Ok(())
        });
        for (_, buffer) in copies {
            self.read_back(buffer);
        }
    }

    /// Starts declaring a compute pass.
    pub fn pass(&mut self, name: &str) -> PassBuilder<'_, P> {
        self.begin_pass(name, PassKind::Compute)
    }

    /// Starts declaring a pass of the given kind.
    pub fn begin_pass(&mut self, name: &str, kind: PassKind) -> PassBuilder<'_, P> {
        PassBuilder {
            graph: self,
            decl: PassDecl {
                name: name.into(),
                kind,
                uses: Vec::new(),
                record: None,
                misdeclared: Vec::new(),
            },
        }
    }

    /// Orders, culls, creates transients; see [`BakedGraph`].
    pub fn bake(self, ctx: &crate::vulkan::Context) -> Result<BakedGraph<P>> {
        bake::bake(self, ctx)
    }
}

/// Declares one pass: `graph.pass("name").read(..).write(..).record(..)`.
pub struct PassBuilder<'g, P> {
    graph: &'g mut RenderGraph<P>,
    decl: PassDecl<P>,
}

impl<P: 'static> PassBuilder<'_, P> {
    /// Marks the pass as graphics (draws into attachments).
    pub fn graphics(mut self) -> Self {
        self.decl.kind = PassKind::Graphics;
        self
    }

    /// Marks the pass as transfer (copies).
    pub fn transfer(mut self) -> Self {
        self.decl.kind = PassKind::Transfer;
        self
    }

    /// Declares a read of `resource` (`access` must not write).
    pub fn read<R: Resource>(mut self, resource: R, access: R::Access) -> Self {
        let (resource, access) = (resource.id(), access.into());
        if access.writes() {
            self.decl
                .misdeclared
                .push(format!("read() of the writing access {access:?}"));
        }
        self.decl.uses.push((resource, access));
        self
    }

    /// Declares a write (or read-write) of `resource` (`access` must write).
    pub fn write<R: Resource>(mut self, resource: R, access: R::Access) -> Self {
        let (resource, access) = (resource.id(), access.into());
        if !access.writes() {
            self.decl
                .misdeclared
                .push(format!("write() of the read-only access {access:?}"));
        }
        self.decl.uses.push((resource, access));
        self
    }

    /// Finishes the pass with the closure that records its commands.
    pub fn record(mut self, record: impl Fn(&mut PassContext<'_>, &P) -> Result<()> + Send + Sync + 'static) {
        self.decl.record = Some(Box::new(record));
        self.graph.passes.push(self.decl);
    }
}

#[cfg(test)]
mod tests;
