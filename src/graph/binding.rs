//! Bindings come from declarations (kajiya's `SimpleRenderPass`, Granite's
//! `RenderPassCreator`): declaring a heap access on a pass
//! ([`super::PassBuilder::sample`], [`super::PassBuilder::storage_image`],
//! [`super::PassBuilder::storage_buffer`], [`super::PassBuilder::upload`])
//! returns a [`Binding`], and only that pass's [`super::PassContext::handle`]
//! turns it into the bindless heap handle a shader indexes. The raw handle
//! getters of images, buffers and upload regions are private to `vulkan/`
//! and `graph/`, so a shader cannot reach a resource its pass did not
//! declare: there would be no barrier for it, and no validation layer sees
//! bindless accesses.
//!
//! What a pass cannot do, checked by the compiler:
//!
//! ```compile_fail
//! // No handle from a bare resource id: `PassContext` has no such getter.
//! use alpenglow::bench::{ImageId, PassContext};
//! fn reach(pass: &PassContext<'_>, image: ImageId) -> u32 {
//!     pass.sampled(image).unwrap()
//! }
//! ```
//!
//! ```compile_fail
//! // No handle from the physical image either: the getter is private.
//! use alpenglow::bench::{ImageId, PassContext};
//! fn reach(pass: &PassContext<'_>, image: ImageId) -> Option<u32> {
//!     pass.image(image).unwrap().sampled_handle()
//! }
//! ```
//!
//! ```compile_fail
//! // No binding made up outside a declaration: its fields are private.
//! use alpenglow::bench::Binding;
//! let forged = Binding { pass: 0, graph: 0, target: todo!() };
//! ```
//!
//! What it does instead (compiles):
//!
//! ```no_run
//! use alpenglow::bench::{Binding, ImageId, ImageInfo, PassContext, RenderGraph, Stage};
//! fn declare(graph: &mut RenderGraph<()>, image: ImageId) {
//!     let mut pass = graph.pass("blur");
//!     let source: Binding = pass.sample(image, Stage::Compute);
//!     pass.record(move |ctx: &mut PassContext<'_>, _: &()| {
//!         let _handle: u32 = ctx.handle(source)?;
//!         Ok(())
//!     });
//! }
//! ```

use std::sync::atomic::{AtomicU32, Ordering};

use super::uploads::UploadRegion;
use super::ResourceId;

/// A heap binding a pass declared: a resource and how its shaders reach it.
/// Turned into a heap handle only by the declaring pass's
/// [`super::PassContext::handle`]; a binding of another pass (or another
/// graph) is an error there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub(crate) graph: u32,
    pub(crate) pass: u32,
    pub(crate) target: BindingTarget,
}

/// What a [`Binding`] reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BindingTarget {
    /// The image's sampled heap entry (`texture2D[]`).
    SampledImage(ResourceId),
    /// The image's storage heap entry (`image2D[]`).
    StorageImage(ResourceId),
    /// The buffer's storage heap entry.
    StorageBuffer(ResourceId),
    /// This frame slot's copy of an upload region.
    Upload(UploadRegion),
}

/// A number for each graph, so that a binding of one graph is refused by
/// the passes of another.
pub(crate) fn next_graph_serial() -> u32 {
    static NEXT: AtomicU32 = AtomicU32::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}
