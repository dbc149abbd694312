//! Baking: validate the declarations, cull passes whose outputs nobody uses,
//! fix the execution order, derive usage flags and create the transient
//! resources (once; they are reused by every frame).

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

use super::alias::{assign_slots, AliasSlot};
use super::uploads::{UploadArena, UploadWriter};
use super::{Access, Attachments, ImageId, ImageInfo, PassDecl, PassKind, RenderGraph, ResourceDecl, ResourceId};
use crate::error::{Error, Result};
use crate::profile::FrameProfile;
use crate::vulkan::{
    AccessState, AcquiredImage, Buffer, BufferDesc, BufferUsageFlags, Context, Image, ImageDesc, ImageUsageFlags,
    MemoryBlock, PresentSync,
};

/// The physical resource(s) behind a graph resource.
pub(crate) enum Physical {
    Image(Vec<Arc<Image>>),
    Buffer(Vec<Arc<Buffer>>),
    /// A transient nobody uses after culling.
    Unused,
}

impl Physical {
    /// The image frame `frame` uses (per-frame imports rotate).
    pub(crate) fn image(&self, frame: u64) -> Option<&Arc<Image>> {
        match self {
            Physical::Image(v) if !v.is_empty() => Some(&v[frame as usize % v.len()]),
            _ => None,
        }
    }

    /// The buffer frame `frame` uses.
    pub(crate) fn buffer(&self, frame: u64) -> Option<&Arc<Buffer>> {
        match self {
            Physical::Buffer(v) if !v.is_empty() => Some(&v[frame as usize % v.len()]),
            _ => None,
        }
    }
}

pub(crate) struct BakedPass<P> {
    pub name: String,
    /// The debug label (the name as a C string, made once).
    pub label: std::ffi::CString,
    pub kind: PassKind,
    pub uses: Vec<(ResourceId, Access)>,
    pub record: super::RecordFn<P>,
    /// The pass's number in its graph (what its bindings carry).
    pub serial: u32,
    /// What the graph begins rendering into around the closure.
    pub attachments: Attachments,
}

pub(crate) struct PendingFrame {
    pub frame: u64,
    pub cpu_start_ms: f64,
    pub cpu_ms: f64,
    /// Per pass: CPU start (ms from frame start) and CPU recording time.
    pub cpu_passes: Vec<(f64, f64)>,
    /// The CPU stages before recording (techniques' `prepare`).
    pub prepare: super::execute::PrepareTimes,
}

/// The most frame profiles a graph keeps by default (about a minute at
/// 60 frames per second).
pub const DEFAULT_PROFILE_HISTORY: usize = 4096;

/// A baked render graph: passes in execution order with their resources,
/// ready to record frame after frame ([`BakedGraph::execute`]).
pub struct BakedGraph<P> {
    pub(crate) passes: Vec<BakedPass<P>>,
    pub(crate) physical: Vec<Physical>,
    pub(crate) imported: Vec<bool>,
    /// Tracked state of each transient across frames.
    pub(crate) transient_states: Vec<AccessState>,
    /// Alias slot of each transient image that shares memory.
    pub(crate) alias_of: Vec<Option<usize>>,
    pub(crate) alias_slots: Vec<AliasSlot>,
    pub(crate) final_accesses: Vec<(ResourceId, Access)>,
    pub(crate) culled: Vec<String>,
    pub(crate) pending: VecDeque<PendingFrame>,
    pub(crate) profiles: Vec<FrameProfile>,
    /// The most profiles kept (the oldest are dropped and their memory
    /// reused): [`BakedGraph::set_profile_history`].
    pub(crate) profile_history: usize,
    /// Whether each pass is wrapped in a pipeline-statistics query:
    /// [`BakedGraph::set_pipeline_stats`].
    pub(crate) pipeline_stats: bool,
    /// GPU zones for Tracy (feature `tracy`; nothing without it).
    pub(crate) tracy: crate::profile::tracy::GpuZones,
    /// Per-frame scratch reused by every frame (no allocation per frame):
    /// which resources the frame touched, and the CPU times of the passes
    /// of completed frames.
    pub(crate) touched: Vec<bool>,
    pub(crate) spare_cpu_passes: Vec<Vec<(f64, f64)>>,
    pub(crate) epoch: Instant,
    /// The upload arena, when a region was declared.
    pub(crate) uploads: Option<UploadArena>,
    /// The graph's number (what its passes' bindings carry).
    pub(crate) serial: u32,
    /// The semaphores of the next frame's swapchain image, when one is
    /// bound ([`BakedGraph::bind_presented`]).
    pub(crate) present: Option<PresentSync>,
}

impl<P> BakedGraph<P> {
    /// Binds the swapchain image `acquired` to `image` (declared with
    /// [`RenderGraph::import_presented`]) for the next frame: the frame
    /// waits for its acquisition, overwrites it (its old contents are
    /// discarded) and signals its presentation.
    pub fn bind_presented(&mut self, image: ImageId, acquired: &AcquiredImage) -> Result<()> {
        let is_presented = matches!(self.physical.get(image.0 .0), Some(Physical::Image(v)) if v.len() <= 1)
            && self.final_accesses.contains(&(image.0, Access::Present));
        if !is_presented {
            return Err(Error::Graph(
                "bind_presented: the image was not imported as presented".into(),
            ));
        }
        acquired.image.set_state(AccessState::UNUSED);
        self.physical[image.0 .0] = Physical::Image(vec![acquired.image.clone()]);
        self.present = Some(acquired.sync);
        Ok(())
    }

    /// Whether a swapchain image is bound for the next frame.
    pub fn present_bound(&self) -> bool {
        self.present.is_some()
    }

    /// Forgets the swapchain images bound for the frame just submitted.
    pub(crate) fn unbind_presented(&mut self) {
        self.present = None;
        for (r, access) in &self.final_accesses {
            if *access == Access::Present {
                self.physical[r.0] = Physical::Image(Vec::new());
            }
        }
    }

    /// Names of the passes in execution order.
    pub fn pass_names(&self) -> Vec<String> {
        self.passes.iter().map(|p| p.name.clone()).collect()
    }

    /// Keeps at most `frames` profiles (at least 1): older ones are
    /// dropped and their memory reused, so a renderer that never takes
    /// its profiles stops allocating for them once the history is full.
    pub fn set_profile_history(&mut self, frames: usize) {
        self.profile_history = frames.max(1);
        let excess = self.profiles.len().saturating_sub(self.profile_history);
        self.profiles.drain(..excess);
    }

    /// Wraps every pass in a pipeline-statistics query (from the next
    /// frame on; [`crate::profile::PassTiming::pipeline_stats`]); an error
    /// naming the feature when the device lacks `pipelineStatisticsQuery`.
    pub fn set_pipeline_stats(&mut self, ctx: &Context, on: bool) -> Result<()> {
        if on && !ctx.has_feature("pipelineStatisticsQuery") {
            return Err(Error::Device(format!(
                "pipeline statistics need the device feature pipelineStatisticsQuery, which '{}' lacks",
                ctx.info().name
            )));
        }
        self.pipeline_stats = on;
        Ok(())
    }

    /// Names of the passes that were culled because nothing used their output.
    pub fn culled_passes(&self) -> &[String] {
        &self.culled
    }

    /// The physical image behind a transient or imported image (slot 0).
    pub fn image(&self, id: super::ImageId) -> Option<&Arc<Image>> {
        self.physical.get(id.0 .0).and_then(|p| p.image(0))
    }

    /// The upload regions of frame `frame` (the next frame, once
    /// [`crate::vulkan::FrameRing::wait_for_next`] returned it): what a
    /// technique's `prepare` writes before the frame is recorded.
    pub fn uploads(&self, frame: u64) -> UploadWriter<'_> {
        match &self.uploads {
            Some(u) => u.writer(frame),
            None => UploadWriter::empty(),
        }
    }
}

/// Which passes must run: those that write an imported or output resource,
/// and, transitively, the last writer of everything a live pass reads.
pub(crate) fn live_passes<P>(graph: &RenderGraph<P>) -> Vec<bool> {
    let n = graph.passes.len();
    let mut live = vec![false; n];
    let is_root_resource =
        |r: ResourceId| graph.resources[r.0].is_imported() || graph.outputs.iter().any(|(o, _)| *o == r);
    let mut work: Vec<usize> = Vec::new();
    for (i, pass) in graph.passes.iter().enumerate() {
        if pass.uses.iter().any(|(r, a)| a.writes() && is_root_resource(*r)) {
            live[i] = true;
            work.push(i);
        }
    }
    while let Some(i) = work.pop() {
        for (r, a) in &graph.passes[i].uses {
            if !a.reads() {
                continue;
            }
            // The last earlier pass writing `r` produces what pass i reads.
            let producer = (0..i)
                .rev()
                .find(|&j| graph.passes[j].uses.iter().any(|(r2, a2)| r2 == r && a2.writes()));
            if let Some(j) = producer {
                if !live[j] {
                    live[j] = true;
                    work.push(j);
                }
            }
        }
    }
    live
}

fn validate<P>(graph: &RenderGraph<P>) -> Result<()> {
    for pass in &graph.passes {
        if let Some(m) = pass.misdeclared.first() {
            return Err(Error::Graph(format!("pass '{}' declares {m}", pass.name)));
        }
        for (r, a) in &pass.uses {
            let decl = graph
                .resources
                .get(r.0)
                .ok_or_else(|| Error::Graph(format!("pass '{}' uses an unknown resource #{}", pass.name, r.0)))?;
            if matches!(decl, ResourceDecl::Uploads) && *a != Access::StorageBufferRead(access_stage(*a)) {
                return Err(Error::Graph(format!(
                    "pass '{}' declares {a:?} on the upload arena, which shaders only read",
                    pass.name
                )));
            }
            let fits = if decl.is_image() { a.is_image() } else { a.is_buffer() };
            if !fits {
                return Err(Error::Graph(format!(
                    "pass '{}' declares {a:?} on '{}', which is {}",
                    pass.name,
                    decl.name(),
                    if decl.is_image() { "an image" } else { "a buffer" }
                )));
            }
        }
        if pass.record.is_none() {
            return Err(Error::Graph(format!("pass '{}' has no recording closure", pass.name)));
        }
        check_attachments(graph, pass)?;
    }
    for (r, a) in &graph.outputs {
        if r.0 >= graph.resources.len() {
            return Err(Error::Graph(format!("output #{} is not a resource of this graph", r.0)));
        }
        let presented = matches!(graph.resources[r.0], ResourceDecl::Presented { .. });
        if a.is_some() && graph.resources[r.0].is_image() && !presented {
            return Err(Error::Graph(format!(
                "'{}': only buffers can be read back",
                graph.resources[r.0].name()
            )));
        }
    }
    Ok(())
}

/// Every [`super::RenderGraph::edge`] holds among the live passes (which
/// run in declaration order).
fn check_edges<P>(graph: &RenderGraph<P>, live: &[bool]) -> Result<()> {
    let names = || {
        (graph.passes.iter().zip(live))
            .filter(|(_, l)| **l)
            .map(|(p, _)| p.name.as_str())
    };
    for edge in &graph.edges {
        let last_before = names().enumerate().filter(|(_, n)| n.starts_with(&edge.before)).last();
        let first_after = names().enumerate().find(|(_, n)| n.starts_with(&edge.after));
        if let (Some((b, before)), Some((a, after))) = (last_before, first_after) {
            if b > a {
                return Err(Error::Graph(format!(
                    "'{before}' is declared after '{after}', but the edge {}… → {}… orders it before: {}",
                    edge.before, edge.after, edge.reason
                )));
            }
        }
    }
    Ok(())
}

/// The format of an image resource.
fn image_format(decl: &ResourceDecl) -> Option<crate::vulkan::Format> {
    match decl {
        ResourceDecl::TransientImage { info, .. } => Some(info.format),
        ResourceDecl::ImportedImages(images) => images.first().map(|i| i.desc().format),
        ResourceDecl::Presented { format, .. } => Some(*format),
        _ => None,
    }
}

/// A graphics pass's attachments against the pipelines it declared: same
/// colour formats in the same order, same depth format (Granite checks its
/// render passes against the pipelines' formats the same way).
fn check_attachments<P>(graph: &RenderGraph<P>, pass: &PassDecl<P>) -> Result<()> {
    let attachments = &pass.attachments;
    if attachments.is_empty() {
        return match pass.pipelines.first() {
            Some(p) => Err(Error::Graph(format!(
                "pass '{}' declares the pipeline '{}' but no attachment",
                pass.name, p.name
            ))),
            None => Ok(()),
        };
    }
    if pass.kind != PassKind::Graphics {
        return Err(Error::Graph(format!(
            "pass '{}' declares attachments but is not a graphics pass",
            pass.name
        )));
    }
    let format_of = |r: ResourceId| graph.resources.get(r.0).and_then(image_format);
    let colors: Vec<_> = attachments.colors.iter().map(|(r, _)| format_of(*r)).collect();
    let depth = attachments.depth.and_then(|(r, _)| format_of(r));
    if pass.pipelines.is_empty() {
        return Err(Error::Graph(format!(
            "graphics pass '{}' declares attachments but no pipeline (PassBuilder::pipeline)",
            pass.name
        )));
    }
    for pipeline in &pass.pipelines {
        let wanted: Vec<_> = pipeline.colors.iter().copied().map(Some).collect();
        if wanted != colors || pipeline.depth != depth {
            return Err(Error::Graph(format!(
                "pass '{}': the pipeline '{}' renders into colours {:?} and depth {:?}, \
                 but the pass declares colours {colors:?} and depth {depth:?}",
                pass.name, pipeline.name, pipeline.colors, pipeline.depth
            )));
        }
    }
    Ok(())
}

/// The stage of a storage-buffer access (Compute for any other).
fn access_stage(a: Access) -> super::Stage {
    match a {
        Access::StorageBufferRead(s) | Access::StorageBufferWrite(s) | Access::StorageBufferReadWrite(s) => s,
        _ => super::Stage::Compute,
    }
}

fn transient_image_desc(name: String, info: &ImageInfo, usage: ImageUsageFlags) -> ImageDesc {
    ImageDesc {
        name,
        width: info.width,
        height: info.height,
        format: info.format,
        usage,
    }
}

/// Chooses which transient images share memory and allocates the shared
/// blocks: per resource, its alias slot and block (None: own memory).
#[allow(clippy::type_complexity)]
fn plan_aliasing<P>(
    graph: &RenderGraph<P>,
    live: &[bool],
    image_usage: &[ImageUsageFlags],
    ctx: &Context,
) -> Result<(Vec<Option<usize>>, Vec<Option<Arc<MemoryBlock>>>)> {
    let n = graph.resources.len();
    let mut alias_of = vec![None; n];
    let mut blocks = vec![None; n];
    if !graph.alias_transients {
        return Ok((alias_of, blocks));
    }
    let live_passes: Vec<&PassDecl<P>> = graph
        .passes
        .iter()
        .zip(live)
        .filter(|(_, l)| **l)
        .map(|(p, _)| p)
        .collect();
    let mut candidates = Vec::new();
    let mut intervals = Vec::new();
    for (r, decl) in graph.resources.iter().enumerate() {
        let ResourceDecl::TransientImage { name, info } = decl else {
            continue;
        };
        let used: Vec<usize> = (0..live_passes.len())
            .filter(|&p| live_passes[p].uses.iter().any(|(id, _)| id.0 == r))
            .collect();
        let kept = graph.outputs.iter().any(|(o, _)| o.0 == r);
        if let (Some(&first), Some(&last), false) = (used.first(), used.last(), kept) {
            let desc = transient_image_desc(name.clone(), info, image_usage[r]);
            candidates.push((r, desc));
            intervals.push((first, last));
        }
    }
    let slots = assign_slots(&intervals);
    let slot_count = slots.iter().max().map_or(0, |m| m + 1);
    let mut next_slot = 0;
    for slot in 0..slot_count {
        let members: Vec<usize> = (0..candidates.len()).filter(|&i| slots[i] == slot).collect();
        if members.len() < 2 {
            continue;
        }
        let descs: Vec<&ImageDesc> = members.iter().map(|&i| &candidates[i].1).collect();
        let name = descs.iter().map(|d| d.name.as_str()).collect::<Vec<_>>().join(" | ");
        if let Some(block) = MemoryBlock::for_images(ctx, &format!("aliased: {name}"), &descs)? {
            for &i in &members {
                alias_of[candidates[i].0] = Some(next_slot);
                blocks[candidates[i].0] = Some(block.clone());
            }
            log::debug!("render graph: {name} share {} bytes", block.size());
            next_slot += 1;
        }
    }
    Ok((alias_of, blocks))
}

/// The physical resources: transients created (aliased into `blocks`
/// where planned) with the usage their accesses need, imports checked for
/// it, the upload arena's buffers.
fn create_physical(
    ctx: &Context,
    resources: Vec<ResourceDecl>,
    (image_usage, buffer_usage): (&[ImageUsageFlags], &[BufferUsageFlags]),
    blocks: &[Option<Arc<MemoryBlock>>],
    uploads: Option<&UploadArena>,
) -> Result<Vec<Physical>> {
    let mut physical = Vec::with_capacity(resources.len());
    for (i, decl) in resources.into_iter().enumerate() {
        let p = match decl {
            ResourceDecl::TransientImage { name, info } => {
                if image_usage[i].is_empty() {
                    Physical::Unused
                } else {
                    let desc = transient_image_desc(name, &info, image_usage[i]);
                    let image = match &blocks[i] {
                        Some(block) => Image::new_aliased(ctx, desc, block.clone())?,
                        None => Image::new(ctx, desc)?,
                    };
                    Physical::Image(vec![Arc::new(image)])
                }
            }
            ResourceDecl::TransientBuffer { name, info } => {
                if buffer_usage[i].is_empty() {
                    Physical::Unused
                } else {
                    let buffer = Buffer::new(
                        ctx,
                        BufferDesc {
                            name,
                            size: info.size,
                            usage: buffer_usage[i],
                            location: info.location,
                        },
                    )?;
                    Physical::Buffer(vec![Arc::new(buffer)])
                }
            }
            ResourceDecl::ImportedImages(images) => {
                for image in &images {
                    if !image.desc().usage.contains(image_usage[i]) {
                        return Err(Error::Graph(format!(
                            "imported image '{}' lacks usage {:?}",
                            image.desc().name,
                            image_usage[i] & !image.desc().usage
                        )));
                    }
                }
                Physical::Image(images)
            }
            ResourceDecl::Presented { .. } => Physical::Image(Vec::new()),
            ResourceDecl::ImportedBuffers(buffers) => {
                for buffer in &buffers {
                    if !buffer.desc().usage.contains(buffer_usage[i]) {
                        return Err(Error::Graph(format!(
                            "imported buffer '{}' lacks usage {:?}",
                            buffer.desc().name,
                            buffer_usage[i] & !buffer.desc().usage
                        )));
                    }
                }
                Physical::Buffer(buffers)
            }
            ResourceDecl::Uploads => match uploads {
                Some(u) => Physical::Buffer(u.buffers.clone()),
                None => Physical::Unused,
            },
        };
        physical.push(p);
    }
    Ok(physical)
}

pub(crate) fn bake<P: 'static>(graph: RenderGraph<P>, ctx: &Context) -> Result<BakedGraph<P>> {
    validate(&graph)?;
    let serial = graph.serial;
    let live = live_passes(&graph);
    check_edges(&graph, &live)?;
    let mut image_usage = vec![ImageUsageFlags::empty(); graph.resources.len()];
    let mut buffer_usage = vec![BufferUsageFlags::empty(); graph.resources.len()];
    for (pass, _) in graph.passes.iter().zip(&live).filter(|(_, l)| **l) {
        for (r, a) in &pass.uses {
            image_usage[r.0] |= a.image_usage();
            buffer_usage[r.0] |= a.buffer_usage();
        }
    }
    let (alias_of, blocks) = plan_aliasing(&graph, &live, &image_usage, ctx)?;
    let uploads = match graph.upload_arena {
        Some(_) => Some(UploadArena::new(ctx, &graph.upload_regions)?),
        None => None,
    };
    let imported = graph.resources.iter().map(ResourceDecl::is_imported).collect();
    let usage = (image_usage.as_slice(), buffer_usage.as_slice());
    let physical = create_physical(ctx, graph.resources, usage, &blocks, uploads.as_ref())?;
    let mut passes = Vec::new();
    let mut culled = Vec::new();
    for (decl, alive) in graph.passes.into_iter().zip(live) {
        let PassDecl {
            name,
            kind,
            uses,
            record,
            serial,
            attachments,
            ..
        } = decl;
        match (alive, record) {
            (true, Some(record)) => passes.push(BakedPass {
                label: std::ffi::CString::new(name.replace('\0', " ")).unwrap_or_default(),
                name,
                kind,
                uses,
                record,
                serial,
                attachments,
            }),
            _ => culled.push(name),
        }
    }
    if !culled.is_empty() {
        log::debug!("render graph: culled passes {culled:?}");
    }
    let final_accesses = graph.outputs.iter().filter_map(|(r, a)| a.map(|a| (*r, a))).collect();
    Ok(BakedGraph {
        passes,
        transient_states: vec![AccessState::UNUSED; physical.len()],
        alias_slots: vec![AliasSlot::default(); alias_of.iter().flatten().max().map_or(0, |m| m + 1)],
        alias_of,
        physical,
        imported,
        final_accesses,
        present: None,
        culled,
        pending: VecDeque::new(),
        profiles: Vec::new(),
        profile_history: DEFAULT_PROFILE_HISTORY,
        pipeline_stats: false,
        tracy: Default::default(),
        touched: Vec::new(),
        spare_cpu_passes: Vec::new(),
        epoch: Instant::now(),
        uploads,
        serial,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{ImageAccess, ImageInfo, Stage};
    use crate::vulkan::Format;

    #[test]
    fn passes_without_used_outputs_are_culled() {
        let mut g: RenderGraph<()> = RenderGraph::new();
        let a = g.create_image("a", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        let b = g.create_image("b", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        let unused = g.create_image("unused", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        g.pass("write a")
            .write(a, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.pass("write unused")
            .read(a, ImageAccess::Sampled(Stage::Compute))
            .write(unused, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.pass("a to b")
            .read(a, ImageAccess::Sampled(Stage::Compute))
            .write(b, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.keep(b);
        assert_eq!(live_passes(&g), vec![true, false, true]);
    }

    #[test]
    fn reads_of_writing_accesses_are_rejected() {
        let mut g: RenderGraph<()> = RenderGraph::new();
        let a = g.create_image("a", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        g.pass("bad")
            .read(a, ImageAccess::ColorAttachmentWrite)
            .record(|_, _| Ok(()));
        let err = validate(&g).unwrap_err().to_string();
        assert!(
            err.contains("'bad'") && err.contains("read() of the writing access"),
            "{err}"
        );
    }

    #[test]
    fn an_edge_broken_by_the_declaration_order_is_named() {
        let declare = |first: &str, second: &str| {
            let mut g: RenderGraph<()> = RenderGraph::new();
            for name in [first, second] {
                let out = g.create_image(name, ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
                g.pass(name)
                    .write(out, ImageAccess::StorageWrite(Stage::Compute))
                    .record(|_, _| Ok(()));
                g.keep(out);
            }
            g.edge("texturing.", "terrain.shadow", "the reason");
            let live = live_passes(&g);
            check_edges(&g, &live).map_err(|e| e.to_string())
        };
        assert_eq!(declare("texturing.generate", "terrain.shadow@left"), Ok(()));
        let err = declare("terrain.shadow@left", "texturing.generate").unwrap_err();
        assert!(
            err.contains("'texturing.generate' is declared after 'terrain.shadow@left'") && err.contains("the reason"),
            "{err}"
        );
        assert_eq!(declare("sky", "tonemap"), Ok(()), "an edge without its passes holds");
    }

    #[test]
    fn only_the_last_writer_before_a_read_is_its_producer() {
        let mut g: RenderGraph<()> = RenderGraph::new();
        let a = g.create_image("a", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        let out = g.create_image("out", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        g.pass("overwritten")
            .write(a, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.pass("rewrite")
            .write(a, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.pass("accumulate")
            .write(a, ImageAccess::StorageReadWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        g.pass("use")
            .read(a, ImageAccess::Sampled(Stage::Fragment))
            .write(out, ImageAccess::ColorAttachmentWrite)
            .record(|_, _| Ok(()));
        g.keep(out);
        assert_eq!(live_passes(&g), vec![false, true, true, true]);
    }

    #[test]
    fn upload_regions_are_read_only() {
        let mut g: RenderGraph<()> = RenderGraph::new();
        let region = g.upload_region("constants", 64);
        g.pass("writes an upload")
            .write(region, crate::graph::BufferAccess::StorageWrite(Stage::Compute))
            .record(|_, _| Ok(()));
        let err = validate(&g).unwrap_err().to_string();
        assert!(err.contains("upload arena"), "{err}");
        let mut g: RenderGraph<()> = RenderGraph::new();
        let region = g.upload_region("constants", 64);
        g.pass("reads an upload")
            .read(region, crate::graph::BufferAccess::StorageRead(Stage::Fragment))
            .record(|_, _| Ok(()));
        assert!(validate(&g).is_ok());
    }
}
