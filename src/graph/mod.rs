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
//! let mut grid = graph.pass("terrain.grid");
//! let out = grid.storage_buffer(vertices, BufferAccess::StorageWrite(Stage::Compute));
//! grid.record(move |pass, frame: &Frame| {
//!     let push = GridPush { vertices: pass.handle(out)?, .. };
//!     pass.dispatch(&grid_pipeline, &push, [groups, 1, 1])
//! });
//! graph.pass("terrain.draw").graphics()
//!     .pipeline(&draw_pipeline)
//!     .read(vertices, BufferAccess::Vertex)
//!     .color(hdr, LoadOp::Clear([0.0; 4]))
//!     .record(move |pass, frame| { /* bind, draw: the graph begins and ends rendering */ Ok(()) });
//! let mut baked = graph.bake(&ctx)?;
//! baked.execute(&mut frames, &frame, &[])?;
//! ```
//!
//! A pass reaches only what it declared ([`binding`]): heap handles come
//! from the [`Binding`]s its declarations return, images and buffers from
//! its declared ids, attachments from `color`/`depth`.

pub mod access;
mod alias;
mod bake;
pub mod binding;
mod execute;
mod typed;
mod uploads;

use std::sync::Arc;

pub use crate::vulkan::LoadOp;
#[cfg(test)]
pub use access::derive_barrier;
pub use access::{Access, Stage};
pub use bake::{BakedGraph, DEFAULT_PROFILE_HISTORY};
pub use binding::Binding;
pub use execute::{stride_groups, CpuStage, FrameOutcome, PassContext};
pub use typed::{BufferAccess, BufferId, ImageAccess, ImageId, Resource};
pub use uploads::{UploadRegion, UploadWriter};

use crate::error::Result;
use crate::vulkan::{Buffer, Format, GraphicsPipeline, Image, MemoryLocation};
use binding::BindingTarget;

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
    /// A window's swapchain image: a different one each frame, bound
    /// before the frame is executed ([`BakedGraph::bind_presented`]),
    /// presented after it.
    Presented {
        name: String,
        format: Format,
    },
    /// The upload arena: one host-visible buffer per frame slot, created at
    /// bake time from the regions declared.
    Uploads,
}

impl ResourceDecl {
    pub(crate) fn is_imported(&self) -> bool {
        matches!(
            self,
            ResourceDecl::ImportedImages(_)
                | ResourceDecl::ImportedBuffers(_)
                | ResourceDecl::Uploads
                | ResourceDecl::Presented { .. }
        )
    }

    pub(crate) fn is_image(&self) -> bool {
        matches!(
            self,
            ResourceDecl::TransientImage { .. } | ResourceDecl::ImportedImages(_) | ResourceDecl::Presented { .. }
        )
    }

    pub(crate) fn name(&self) -> String {
        match self {
            ResourceDecl::TransientImage { name, .. }
            | ResourceDecl::TransientBuffer { name, .. }
            | ResourceDecl::Presented { name, .. } => name.clone(),
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
    /// The pass's number in its graph (what its bindings carry).
    pub serial: u32,
    /// The attachments the graph begins rendering into around the closure.
    pub attachments: Attachments,
    /// The pipelines the pass draws with, whose attachment formats must
    /// match the attachments (checked at bake).
    pub pipelines: Vec<PipelineFormats>,
}

/// The colour and depth attachments of a graphics pass, in declaration order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Attachments {
    pub colors: Vec<(ResourceId, LoadOp)>,
    /// The depth attachment and its clear value (None: loaded).
    pub depth: Option<(ResourceId, Option<f32>)>,
}

impl Attachments {
    pub(crate) fn is_empty(&self) -> bool {
        self.colors.is_empty() && self.depth.is_none()
    }
}

/// The attachment formats of a pipeline a pass declared.
#[derive(Clone, Debug)]
pub(crate) struct PipelineFormats {
    pub name: &'static str,
    pub colors: Vec<Format>,
    pub depth: Option<Format>,
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
    /// This graph's number (its passes' bindings carry it).
    pub(crate) serial: u32,
    /// Orderings beyond what the declared accesses imply ([`RenderGraph::edge`]).
    pub(crate) edges: Vec<Edge>,
}

/// Every live pass named `before…` runs before every live pass named
/// `after…`, for `reason` ([`RenderGraph::edge`]).
#[derive(Clone, Debug)]
pub(crate) struct Edge {
    pub before: String,
    pub after: String,
    pub reason: &'static str,
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
            serial: binding::next_graph_serial(),
            edges: Vec::new(),
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

    /// A window's swapchain image of `format`, presented after every
    /// frame: the renderer binds the image it acquired before each frame
    /// ([`BakedGraph::bind_presented`]); its contents start undefined.
    pub fn import_presented(&mut self, name: &str, format: Format) -> ImageId {
        let id = self.declare(ResourceDecl::Presented {
            name: name.into(),
            format,
        });
        self.outputs.push((id, Some(Access::Present)));
        ImageId(id)
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
    /// their own heap handle (a pass's [`PassBuilder::upload`] binding) from offset 0. Every
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

    /// An explicit ordering the declared accesses do not imply: every live
    /// pass whose name starts with `before` runs before every live pass
    /// whose name starts with `after`, for `reason` (e.g. a workaround of
    /// a validation layer). Passes run in declaration order; bake checks
    /// the edge and names it when a declaration breaks it.
    pub fn edge(&mut self, before: &str, after: &str, reason: &'static str) {
        self.edges.push(Edge {
            before: before.into(),
            after: after.into(),
            reason,
        });
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
        let serial = self.passes.len() as u32;
        PassBuilder {
            graph: self,
            decl: PassDecl {
                name: name.into(),
                kind,
                uses: Vec::new(),
                record: None,
                misdeclared: Vec::new(),
                serial,
                attachments: Attachments::default(),
                pipelines: Vec::new(),
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

    fn binding(&self, target: BindingTarget) -> Binding {
        Binding {
            graph: self.graph.serial,
            pass: self.decl.serial,
            target,
        }
    }

    /// Declares that the pass's shaders at `stage` sample `image`, and
    /// returns the binding its closure turns into the heap handle
    /// ([`PassContext::handle`]).
    pub fn sample(&mut self, image: ImageId, stage: Stage) -> Binding {
        self.decl.uses.push((image.0, Access::SampledImage(stage)));
        self.binding(BindingTarget::SampledImage(image.0))
    }

    /// Declares a storage-image access (`StorageRead`, `StorageWrite` or
    /// `StorageReadWrite`) of `image`, and returns its binding.
    pub fn storage_image(&mut self, image: ImageId, access: ImageAccess) -> Binding {
        if !matches!(
            access,
            ImageAccess::StorageRead(_) | ImageAccess::StorageWrite(_) | ImageAccess::StorageReadWrite(_)
        ) {
            self.decl
                .misdeclared
                .push(format!("storage_image() of the non-storage access {access:?}"));
        }
        self.decl.uses.push((image.0, access.into()));
        self.binding(BindingTarget::StorageImage(image.0))
    }

    /// Declares a storage-buffer access (`StorageRead`, `StorageWrite` or
    /// `StorageReadWrite`) of `buffer`, and returns its binding.
    pub fn storage_buffer(&mut self, buffer: BufferId, access: BufferAccess) -> Binding {
        if !matches!(
            access,
            BufferAccess::StorageRead(_) | BufferAccess::StorageWrite(_) | BufferAccess::StorageReadWrite(_)
        ) {
            self.decl
                .misdeclared
                .push(format!("storage_buffer() of the non-storage access {access:?}"));
        }
        self.decl.uses.push((buffer.0, access.into()));
        self.binding(BindingTarget::StorageBuffer(buffer.0))
    }

    /// Declares that the pass's shaders at `stage` read the upload region
    /// `region`, and returns its binding: the closure turns it into this
    /// frame's handle, and may write the region's contents while recording
    /// ([`PassContext::write_upload`]) — where they embed other bindings'
    /// handles.
    pub fn upload(&mut self, region: UploadRegion, stage: Stage) -> Binding {
        self.decl.uses.push((region.arena, Access::StorageBufferRead(stage)));
        self.binding(BindingTarget::Upload(region))
    }

    /// Declares a colour attachment, in order: `Load` reads and blends
    /// into it, `Clear`/`DontCare` overwrite it. The graph begins rendering
    /// into the pass's attachments before its closure and ends after.
    pub fn color(mut self, image: ImageId, load: LoadOp) -> Self {
        let access = match load {
            LoadOp::Load => Access::ColorAttachmentReadWrite,
            LoadOp::Clear(_) | LoadOp::DontCare => Access::ColorAttachmentWrite,
        };
        self.decl.uses.push((image.0, access));
        self.decl.attachments.colors.push((image.0, load));
        self
    }

    /// Declares the depth attachment, tested and written; cleared to
    /// `clear` when given, else loaded.
    pub fn depth(self, image: ImageId, clear: Option<f32>) -> Self {
        self.set_depth(image, clear, Access::DepthAttachmentWrite)
    }

    /// Declares the depth attachment, tested only (loaded, not written).
    pub fn depth_read(self, image: ImageId) -> Self {
        self.set_depth(image, None, Access::DepthAttachmentRead)
    }

    fn set_depth(mut self, image: ImageId, clear: Option<f32>, access: Access) -> Self {
        if self.decl.attachments.depth.is_some() {
            self.decl.misdeclared.push("a second depth attachment".into());
        }
        self.decl.uses.push((image.0, access));
        self.decl.attachments.depth = Some((image.0, clear));
        self
    }

    /// Declares a pipeline the pass draws with: at bake, its attachment
    /// formats must be those of the pass's attachments.
    pub fn pipeline(mut self, pipeline: &GraphicsPipeline) -> Self {
        self.decl.pipelines.push(PipelineFormats {
            name: pipeline.name(),
            colors: pipeline.color_formats().to_vec(),
            depth: pipeline.depth_format(),
        });
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
