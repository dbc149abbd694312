//! The GPU neighbourhood search of height-field synthesis (dissertation
//! §7.3; `ALGORITHMS.md` §2): the rule of [`super::search`] as compute
//! passes of one render graph, baked once and executed per batch of queries.
//!
//! The exemplar's texels and candidate centres are uploaded once. Per batch,
//! the queries' taps and pixels go through the graph's upload arena, and
//!
//! 1. `synthesis.clear` resets the per-query results;
//! 2. `synthesis.distance` computes s(c) of every (query, candidate) into a
//!    queries × candidates buffer, the taps summed in the CPU twin's order
//!    with every operation `precise` (bit-identical to
//!    [`super::search::weighted_mismatch`]), and keeps each query's smallest
//!    s (`atomicMin` on an order-preserving key of the float);
//! 3. `synthesis.accept` finds each query's smallest choice hash among the
//!    candidates with s ≤ (1 + ε)·best;
//! 4. `synthesis.pick` the smallest candidate with that hash, so the choice
//!    is the smallest (hash, candidate) as in [`super::search::choose_from`];
//! 5. `synthesis.resolve` writes the pick, its s and the best s into a
//!    host-visible buffer; the host divides by Σ w as the CPU does.
//!
//! Batches are as large as the s buffer allows (at most
//! [`GpuSearchLimits::distance_bytes`], the device's storage-buffer range
//! and its dispatch size); two are in flight at once. The one difference
//! from the CPU twin a device may show is in subnormal intermediate values,
//! which Vulkan lets a device flush to zero (no test data comes near them).

use std::ops::Range;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::search::{
    check, normalised_choice, total_weight, Choice, Exemplar, NeighbourhoodSearch, Query, SearchConfig,
};
use crate::error::{Error, Result};
use crate::graph::{
    BakedGraph, Binding, BufferAccess, BufferId, BufferInfo, FrameOutcome, RenderGraph, Stage, UploadRegion,
};
use crate::profile::FrameProfile;
use crate::shaders;
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, FrameRing, MemoryLocation, SpirV, FRAMES_IN_FLIGHT,
};

/// Bounds of one batch of queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpuSearchLimits {
    /// The most bytes of a batch's s buffer (queries × candidates × 4).
    pub distance_bytes: u64,
    /// The most queries per batch.
    pub batch_queries: u32,
    /// The most workgroups a pass dispatches along the candidates (also
    /// bounded by the device's limit); each workgroup loops over the blocks
    /// of candidates beyond them.
    pub candidate_workgroups: u32,
}

impl Default for GpuSearchLimits {
    /// 64 MiB of s (16 M query–candidate pairs, plenty to fill a GPU),
    /// 4096 queries per batch, the device's workgroup count.
    fn default() -> Self {
        GpuSearchLimits {
            distance_bytes: 64 << 20,
            batch_queries: 4096,
            candidate_workgroups: u32::MAX,
        }
    }
}

/// Invocations of `distance.comp` per workgroup × candidates per invocation.
const DISTANCE_BLOCK: u32 = 64 * 4;
/// Candidates per workgroup of `accept.comp` and `pick.comp`.
const ACCEPT_BLOCK: u32 = 256;
/// Queries per workgroup of `clear.comp` and `resolve.comp`.
const QUERY_GROUP: u32 = 64;
/// Bytes of one tap and of one readback entry.
const TAP_BYTES: u64 = 16;
const READBACK_BYTES: u64 = 16;
/// Completed frames' profiles kept between [`GpuSearch::take_profiles`] calls.
const KEPT_PROFILES: usize = 256;

// A batch's readback is read after the next batch was submitted (module
// docs), so each batch in flight needs its own frame slot.
const _: () = assert!(FRAMES_IN_FLIGHT >= 2);

/// Push constants of every pass (`glsl/include/synthesis_search.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SearchPush {
    inputs: [u32; 4],
    outputs: [u32; 4],
    sizes: [u32; 4],
    rule: [u32; 4],
}

/// What a batch's passes get: its number of queries.
#[derive(Clone, Copy, Debug)]
struct Batch {
    queries: u32,
}

/// The graph resources of the passes and the constants of their push constants.
#[derive(Clone, Copy)]
struct Bindings {
    texels: BufferId,
    centres: BufferId,
    taps: UploadRegion,
    pixels: UploadRegion,
    sums: BufferId,
    results: BufferId,
    readback: BufferId,
    /// Candidates, window n, exemplar width.
    shape: [u32; 3],
    /// Seed, bits of λ, bits of 1 + ε.
    rule: [u32; 3],
}

/// Slots of the handles in [`SearchPush`]: `inputs` 0–3, `outputs` 4–7.
const TEXELS: usize = 0;
const CENTRES: usize = 1;
const TAPS: usize = 2;
const PIXELS: usize = 3;
const SUMS: usize = 4;
const RESULTS: usize = 5;
const READBACK: usize = 6;

/// One pass of the search: name, shader, accesses (each with the slot of
/// its handle in the push constants) and its dispatch (from the batch's
/// query count).
struct PassSpec {
    name: &'static str,
    shader: SpirV,
    reads: Vec<(usize, BufferId)>,
    uploads: Vec<(usize, UploadRegion)>,
    writes: Vec<(usize, BufferId, BufferAccess)>,
    dispatch: Box<dyn Fn(u32) -> [u32; 3] + Send + Sync>,
}

/// The neighbourhood search on the GPU (module docs); its choices equal
/// [`super::search::CpuSearch`]'s.
pub struct GpuSearch {
    ctx: Context,
    exemplar: Arc<Exemplar>,
    config: SearchConfig,
    batch_queries: u32,
    taps: UploadRegion,
    pixels: UploadRegion,
    /// One host-visible buffer per frame slot.
    readback: Vec<Arc<Buffer>>,
    graph: BakedGraph<Batch>,
    frames: FrameRing,
}

impl GpuSearch {
    /// The search of `exemplar` by `config` with `GpuSearchLimits::default`.
    pub fn new(ctx: &Context, exemplar: Arc<Exemplar>, config: SearchConfig) -> Result<GpuSearch> {
        GpuSearch::with_limits(ctx, exemplar, config, GpuSearchLimits::default())
    }

    /// The search with explicit batch bounds (tests use small ones to
    /// exercise the splitting).
    pub fn with_limits(
        ctx: &Context,
        exemplar: Arc<Exemplar>,
        config: SearchConfig,
        limits: GpuSearchLimits,
    ) -> Result<GpuSearch> {
        check(&exemplar, &config, &[])?;
        let batch_queries = plan_batch(ctx, &exemplar, &config, &limits)?;
        let texels: Vec<[f32; 4]> = exemplar.texels.iter().map(|t| [t[0], t[1], t[2], 0.0]).collect();
        let texels = Arc::new(Buffer::with_data(
            ctx,
            "synthesis exemplar texels",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&texels),
        )?);
        let centres = Arc::new(Buffer::with_data(
            ctx,
            "synthesis candidate centres",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&exemplar.candidates),
        )?);
        let readback = Buffer::per_frame(
            ctx,
            BufferDesc {
                name: "synthesis readback".into(),
                size: u64::from(batch_queries) * READBACK_BYTES,
                usage: BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        let candidates = exemplar.candidates.len() as u32;
        let taps_per_query = u64::from(config.window * config.window);
        let mut graph = RenderGraph::new();
        let bindings = Bindings {
            texels: graph.import_buffer(texels),
            centres: graph.import_buffer(centres),
            taps: graph.upload_region("synthesis taps", u64::from(batch_queries) * taps_per_query * TAP_BYTES),
            pixels: graph.upload_region("synthesis pixels", u64::from(batch_queries) * 4),
            sums: graph.create_buffer(
                "synthesis sums",
                BufferInfo {
                    size: u64::from(batch_queries) * u64::from(candidates) * 4,
                    location: MemoryLocation::GpuOnly,
                },
            ),
            results: graph.create_buffer(
                "synthesis results",
                BufferInfo {
                    size: u64::from(batch_queries) * 16,
                    location: MemoryLocation::GpuOnly,
                },
            ),
            readback: graph.import_buffers_per_frame(readback.clone()),
            shape: [candidates, config.window, exemplar.width],
            rule: [config.seed, config.lambda.to_bits(), (1.0 + config.epsilon).to_bits()],
        };
        let workgroups = limits
            .candidate_workgroups
            .clamp(1, ctx.shared.limits.max_compute_work_group_count[0]);
        for spec in pass_specs(&bindings, candidates, workgroups) {
            declare(ctx, &mut graph, &bindings, spec)?;
        }
        graph.read_back(bindings.readback);
        Ok(GpuSearch {
            ctx: ctx.clone(),
            exemplar,
            config,
            batch_queries,
            taps: bindings.taps,
            pixels: bindings.pixels,
            readback,
            graph: graph.bake(ctx)?,
            frames: FrameRing::new(ctx)?,
        })
    }

    /// Queries per batch (a call with more is split).
    pub fn batch_queries(&self) -> u32 {
        self.batch_queries
    }

    /// The search's parameters.
    pub fn config(&self) -> &SearchConfig {
        &self.config
    }

    /// Names of the passes in execution order.
    pub fn pass_names(&self) -> Vec<String> {
        self.graph.pass_names()
    }

    /// Waits for the batches in flight and returns the timings of the
    /// batches run since the last call (at most the latest 256), one
    /// profile per batch, with a GPU time per pass.
    pub fn take_profiles(&mut self) -> Result<Vec<FrameProfile>> {
        self.graph.finish(&mut self.frames)?;
        Ok(self.graph.take_profiles())
    }

    /// Writes the taps and pixels of `queries` into frame `frame`'s uploads.
    fn upload(&self, frame: u64, queries: &[Query]) -> Result<()> {
        let mut writer = self.graph.uploads(frame);
        let taps_bytes = u64::from(self.config.window * self.config.window) * TAP_BYTES;
        for (i, query) in queries.iter().enumerate() {
            writer.write_at(self.taps, i as u64 * taps_bytes, bytemuck::cast_slice(&query.taps))?;
        }
        let pixels: Vec<u32> = queries.iter().map(|q| q.pixel).collect();
        writer.write(self.pixels, bytemuck::cast_slice(&pixels))
    }

    /// Waits for the batch `outcome` ran on and turns its readback into the
    /// choices of `queries`.
    fn collect(&self, outcome: FrameOutcome, queries: &[Query], out: &mut Vec<Choice>) -> Result<()> {
        self.ctx.wait(outcome.timeline)?;
        let buffer = &self.readback[outcome.frame as usize % self.readback.len()];
        let candidates = self.exemplar.candidates.len() as u32;
        let entries = buffer.mapped()?.chunks_exact(READBACK_BYTES as usize);
        for (query, entry) in queries.iter().zip(entries) {
            let word =
                |i: usize| u32::from_le_bytes([entry[4 * i], entry[4 * i + 1], entry[4 * i + 2], entry[4 * i + 3]]);
            let candidate = word(0);
            if candidate >= candidates {
                return Err(Error::Graph(format!(
                    "synthesis.resolve returned candidate {candidate} of {candidates}"
                )));
            }
            out.push(normalised_choice(
                candidate,
                f32::from_bits(word(1)),
                key_float(word(2)),
                total_weight(query),
            ));
        }
        Ok(())
    }
}

impl NeighbourhoodSearch for GpuSearch {
    fn choose(&mut self, queries: &[Query]) -> Result<Vec<Choice>> {
        self.choose_reporting(queries, &mut |_| {})
    }

    /// Reports the queries answered after each batch is read back.
    fn choose_reporting(&mut self, queries: &[Query], progress: &mut dyn FnMut(usize)) -> Result<Vec<Choice>> {
        check(&self.exemplar, &self.config, queries)?;
        if self.graph.profiles().len() > KEPT_PROFILES {
            self.graph.take_profiles();
        }
        let mut out = Vec::with_capacity(queries.len());
        let batch = self.batch_queries as usize;
        // The previous batch: read once the next one is submitted, so the
        // GPU runs one while the host prepares the other.
        let mut pending: Option<(FrameOutcome, Range<usize>)> = None;
        for start in (0..queries.len()).step_by(batch) {
            let range = start..(start + batch).min(queries.len());
            let frame = self.frames.wait_for_next()?;
            self.upload(frame, &queries[range.clone()])?;
            let params = Batch {
                queries: range.len() as u32,
            };
            let outcome = self.graph.execute(&mut self.frames, &params, &[])?;
            if let Some((done, done_range)) = pending.replace((outcome, range)) {
                self.collect(done, &queries[done_range], &mut out)?;
                progress(out.len());
            }
        }
        if let Some((done, done_range)) = pending {
            self.collect(done, &queries[done_range], &mut out)?;
        }
        progress(out.len());
        Ok(out)
    }
}

/// The float of an order-preserving key (`key_float` in
/// `synthesis_search.glsl`).
fn key_float(key: u32) -> f32 {
    f32::from_bits(if key & 0x8000_0000 != 0 {
        key & 0x7fff_ffff
    } else {
        !key
    })
}

/// Queries per batch: as many as the s buffer, the taps upload and the
/// dispatch size allow; an error when not even one query fits.
fn plan_batch(ctx: &Context, exemplar: &Exemplar, config: &SearchConfig, limits: &GpuSearchLimits) -> Result<u32> {
    let range = ctx.max_storage_buffer_range();
    let texel_bytes = exemplar.texels.len() as u64 * TAP_BYTES;
    if texel_bytes > range {
        return Err(Error::invalid(
            "exemplar",
            format!(
                "{}×{} texels need {texel_bytes} bytes; the device's storage buffers hold at most {range}",
                exemplar.width, exemplar.height
            ),
        ));
    }
    let row_bytes = exemplar.candidates.len() as u64 * 4;
    let sums_cap = limits.distance_bytes.min(range);
    let taps_bytes = u64::from(config.window) * u64::from(config.window) * TAP_BYTES;
    let max_groups = ctx.shared.limits.max_compute_work_group_count;
    let batch = (sums_cap / row_bytes)
        .min(range / taps_bytes)
        .min(u64::from(limits.batch_queries))
        .min(u64::from(max_groups[1]));
    if batch == 0 {
        let why = if limits.batch_queries == 0 {
            "the batch limit is 0 queries".to_string()
        } else if taps_bytes > range {
            format!(
                "a {0}×{0} window's taps need {taps_bytes} bytes; the device's storage buffers hold at most {range}",
                config.window
            )
        } else {
            format!(
                "{} candidates need {row_bytes} bytes of distances per query, more than the batch's {sums_cap}",
                exemplar.candidates.len()
            )
        };
        return Err(Error::invalid("synthesis search", why));
    }
    Ok(batch as u32)
}

/// The passes of the module docs, in order.
fn pass_specs(b: &Bindings, candidates: u32, max_x: u32) -> Vec<PassSpec> {
    let per_query = move |block: u32| candidates.div_ceil(block).min(max_x);
    let write = BufferAccess::StorageWrite(Stage::Compute);
    let read_write = BufferAccess::StorageReadWrite(Stage::Compute);
    vec![
        PassSpec {
            name: "synthesis.clear",
            shader: shaders::SYNTHESIS_CLEAR,
            reads: vec![],
            uploads: vec![],
            writes: vec![(RESULTS, b.results, write)],
            dispatch: Box::new(|q| [q.div_ceil(QUERY_GROUP), 1, 1]),
        },
        PassSpec {
            name: "synthesis.distance",
            shader: shaders::SYNTHESIS_DISTANCE,
            reads: vec![(TEXELS, b.texels), (CENTRES, b.centres)],
            uploads: vec![(TAPS, b.taps)],
            writes: vec![(SUMS, b.sums, write), (RESULTS, b.results, read_write)],
            dispatch: Box::new(move |q| [per_query(DISTANCE_BLOCK), q, 1]),
        },
        PassSpec {
            name: "synthesis.accept",
            shader: shaders::SYNTHESIS_ACCEPT,
            reads: vec![(SUMS, b.sums)],
            uploads: vec![(PIXELS, b.pixels)],
            writes: vec![(RESULTS, b.results, read_write)],
            dispatch: Box::new(move |q| [per_query(ACCEPT_BLOCK), q, 1]),
        },
        PassSpec {
            name: "synthesis.pick",
            shader: shaders::SYNTHESIS_PICK,
            reads: vec![(SUMS, b.sums)],
            uploads: vec![(PIXELS, b.pixels)],
            writes: vec![(RESULTS, b.results, read_write)],
            dispatch: Box::new(move |q| [per_query(ACCEPT_BLOCK), q, 1]),
        },
        PassSpec {
            name: "synthesis.resolve",
            shader: shaders::SYNTHESIS_RESOLVE,
            reads: vec![(SUMS, b.sums), (RESULTS, b.results)],
            uploads: vec![],
            writes: vec![(READBACK, b.readback, write)],
            dispatch: Box::new(|q| [q.div_ceil(QUERY_GROUP), 1, 1]),
        },
    ]
}

/// Declares `spec` in `graph`: its bindings, and a recording that pushes
/// their handles and dispatches.
fn declare(ctx: &Context, graph: &mut RenderGraph<Batch>, bindings: &Bindings, spec: PassSpec) -> Result<()> {
    let pipeline = ComputePipeline::new(ctx, spec.shader)?;
    let mut pass = graph.pass(spec.name);
    let read = BufferAccess::StorageRead(Stage::Compute);
    let mut slots: Vec<(usize, Binding)> = Vec::new();
    for (slot, buffer) in spec.reads {
        slots.push((slot, pass.storage_buffer(buffer, read)));
    }
    for (slot, region) in spec.uploads {
        slots.push((slot, pass.upload(region, Stage::Compute)));
    }
    for (slot, buffer, access) in spec.writes {
        slots.push((slot, pass.storage_buffer(buffer, access)));
    }
    let ([candidates, window, width], [seed, lambda, tolerance]) = (bindings.shape, bindings.rule);
    let dispatch = spec.dispatch;
    pass.record(move |ctx, batch| {
        let mut handles = [0u32; 8];
        for &(slot, binding) in &slots {
            handles[slot] = ctx.handle(binding)?;
        }
        let push = SearchPush {
            inputs: [handles[0], handles[1], handles[2], handles[3]],
            outputs: [handles[4], handles[5], handles[6], handles[7]],
            sizes: [batch.queries, candidates, window, width],
            rule: [seed, lambda, tolerance, 0],
        };
        ctx.dispatch(&pipeline, &push, dispatch(batch.queries))
    });
    Ok(())
}
