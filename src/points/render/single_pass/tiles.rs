//! The compute backend of single-pass splatting (dissertation §10.4;
//! [`super::SplatBackend::Compute`]): tile-binned, ordered, lock-free and
//! deterministic. The passes are listed in the module doc of [`super`];
//! the shaders are `glsl/points/single_pass_{bins_clear,bin,prefix,tile}.comp`
//! with `glsl/include/single_pass_tiles.glsl` (layouts), and the radix sort's
//! ([`radix`], one of two by device type: [`RadixSort`])
//! `glsl/points/single_pass_radix{,_runs}_*.comp` with
//! `glsl/include/single_pass_radix.glsl`.
//!
//! Capacity: the entry buffers hold [`entry_capacity`] entries, fixed when
//! the graph is declared (the entry count is only known on the GPU, and
//! nothing waits for it on the CPU; every sort pass is dispatched for the
//! capacity and its workgroups past the entries return at once).
//! `points.single_pass.scatter` writes the entries whose positions fall
//! below the capacity and marks the tiles of the others cut, and
//! `points.single_pass.merge` drops every cut tile's list whole: those
//! tiles show no splats, nothing is written out of bounds, the same tiles
//! are dropped on every run, and their entries are counted into the
//! frame's splat counters: [`PointFrameStats::tile_entries_dropped`]
//! (logged as a warning when the frame's statistics are read). The binned
//! splats (the set-ups `points.single_pass.count` keeps, 128 bytes each)
//! fill at most the device's storage buffer range; the draws past it are
//! not binned and their splats counted there too.
//!
//! [`PointFrameStats::tile_entries_dropped`]: super::super::PointFrameStats::tile_entries_dropped

use bytemuck::{Pod, Zeroable};

use super::super::passes::{
    plan_of, PointBuffers, PointView, ResolvedTargets, ShadingBindings, SplatBindings, SplatPush, NO_HANDLE,
    PASS_OPAQUE,
};
use super::super::PointsFrame;
use super::radix::{self, RadixSort, RADIX_BLOCK};
use super::{declare_clear, workgroups, ResolvedPush, SinglePassPush, ViewPasses, Written, WORKGROUP_SIZE};
use crate::error::Result;
use crate::graph::{Binding, BufferAccess, BufferId, BufferInfo, ImageAccess, PassContext, RenderGraph, Stage};
use crate::shaders;
use crate::view::{Frame, Provides, SceneTargets};
use crate::vulkan::{ComputePipeline, Context, MemoryLocation};

/// Pixels per side of a screen tile (`TILE_SIZE` in glsl/include/single_pass_tiles.glsl).
pub(crate) const TILE_SIZE: u32 = 8;
/// Bytes of a tile entry (`TileEntry`: sort key, slot, blocks).
const ENTRY_BYTES: u64 = 12;
/// Bytes of a binned splat (`BinnedSplat` in glsl/include/single_pass_tiles.glsl):
/// the set-up `points.single_pass.count` keeps for the scatter and the merge.
const BINNED_SPLAT_BYTES: u64 = 128;
/// Words of the sort state after the tiles' cut marks in the bins buffer
/// (glsl/include/single_pass_radix.glsl); each tile's range (two words) follows.
const STATE_WORDS: u32 = 8;
/// Entries per splat the scene could plan (a splat's box touches one to
/// four tiles at the sizes an SPT selects, about nine in a 512² close-up
/// of the bunny).
const ENTRIES_PER_SPLAT: u64 = 12;
/// Fewest entries of a buffer (768 KiB).
const MIN_ENTRIES: u64 = 1 << 16;
/// Most entries of a buffer (192 MiB; two of them), where the device's storage buffer range allows.
const MAX_ENTRIES: u64 = 1 << 24;
/// Which of the binning passes (`points.single_pass.count`, `.scatter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Binning {
    Count,
    Scatter,
}

#[cfg(test)]
thread_local! {
    static CAPACITY_OVERRIDE: std::cell::Cell<Option<u32>> = const { std::cell::Cell::new(None) };
}

/// Runs `f` with every entry buffer this thread declares holding
/// `capacity` entries (tests of the overflow).
#[cfg(test)]
pub(crate) fn with_entry_capacity<R>(capacity: u32, f: impl FnOnce() -> R) -> R {
    super::with_override(&CAPACITY_OVERRIDE, capacity, f)
}

/// The tile entries of a view's entry buffers for a scene whose instances'
/// lists hold `planned_splats` splats together (the most a frame can plan):
/// [`ENTRIES_PER_SPLAT`] each, at least 2¹⁶ and at most 2²⁴ (192 MiB a
/// buffer) or what `max_range` bytes (the device's `maxStorageBufferRange`) hold.
pub(crate) fn entry_capacity(planned_splats: u64, max_range: u64) -> u32 {
    #[cfg(test)]
    if let Some(capacity) = CAPACITY_OVERRIDE.with(|c| c.get()) {
        return capacity;
    }
    let most = MAX_ENTRIES.min(max_range / ENTRY_BYTES).max(MIN_ENTRIES);
    let entries = planned_splats
        .saturating_mul(ENTRIES_PER_SPLAT)
        .clamp(MIN_ENTRIES, most);
    u32::try_from(entries).unwrap_or(u32::MAX)
}

/// What the compute backend's buffers of a view are sized for.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TileCapacity {
    /// Tile entries ([`entry_capacity`]).
    pub entries: u32,
    /// The most splats a frame can plan.
    pub splats: u64,
    /// The most draws a frame can plan.
    pub draws: u64,
}

impl TileCapacity {
    /// Workgroups of the binning passes a frame can dispatch: one word
    /// each in the group buffer, and [`WORKGROUP_SIZE`] binned splats each
    /// in a buffer of at most `max_range` bytes (the device's
    /// `maxStorageBufferRange`; the draws past it are not binned, counted
    /// as dropped).
    fn groups(&self, max_range: u64) -> u32 {
        let groups = self.splats.div_ceil(u64::from(WORKGROUP_SIZE)) + self.draws;
        let most = max_range / (BINNED_SPLAT_BYTES * u64::from(WORKGROUP_SIZE));
        u32::try_from(groups.min(most).max(1)).unwrap_or(u32::MAX)
    }
}

/// A view's tiles and its buffers.
#[derive(Clone, Copy, Debug)]
pub(super) struct TileBins {
    /// One word per tile, then [`STATE_WORDS`], then two per tile (its
    /// slice of the sorted entries; `glsl/include/single_pass_radix.glsl`).
    pub bins: BufferId,
    /// `capacity` entries: the binning's output and the sorted entries.
    pub entries: BufferId,
    /// `capacity` entries: the radix sort's other buffer.
    pub scratch: BufferId,
    /// One word per workgroup of the binning passes.
    groups: BufferId,
    /// A binned splat per slot: [`WORKGROUP_SIZE`] per workgroup of the binning passes.
    splats: BufferId,
    /// The radix sort's digit counts and positions
    /// ([`RadixSort::digit_words`]; layouts in glsl/include/single_pass_radix.glsl).
    pub digits: BufferId,
    /// Which radix sort orders the entries.
    pub sort: RadixSort,
    /// Tiles per row and per column.
    grid: [u32; 2],
    pub capacity: u32,
    group_capacity: u32,
}

impl TileBins {
    pub fn tiles(&self) -> u32 {
        self.grid[0] * self.grid[1]
    }

    /// Words of the bins buffer: a cut mark per tile, the sort state, a range per tile.
    fn bin_words(&self) -> u32 {
        3 * self.tiles() + STATE_WORDS
    }

    /// Radix blocks of the capacity: the stride of the digit rows.
    pub fn blocks(&self) -> u32 {
        self.capacity.div_ceil(RADIX_BLOCK)
    }
}

/// The compute pipelines of the backend.
struct Pipelines {
    clear: ComputePipeline,
    bin: ComputePipeline,
    scatter: ComputePipeline,
    prefix: ComputePipeline,
    ranges: ComputePipeline,
    merge: ComputePipeline,
}

/// The compute backend's passes of one view (see [`super`]); `capacity`:
/// what its buffers are sized for.
pub(super) fn declare<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    at: ViewPasses<'_>,
    capacity: TileCapacity,
) -> Result<()> {
    let (name, targets, written) = (at.name, at.targets, at.written);
    let (buffers, view) = (at.buffers, at.view);
    let pipelines = Pipelines {
        clear: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_BINS_CLEAR)?,
        bin: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_BIN)?,
        scatter: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_SCATTER)?,
        prefix: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_PREFIX)?,
        ranges: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RANGES)?,
        merge: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_TILE)?,
    };
    let grid = [targets.width, targets.height].map(|n| n.div_ceil(TILE_SIZE).max(1));
    let entries = capacity.entries.max(1);
    let group_capacity = capacity.groups(ctx.max_storage_buffer_range());
    let buffer = |graph: &mut RenderGraph<Frame<S>>, what, size: u64| {
        let location = MemoryLocation::GpuOnly;
        graph.create_buffer(what, BufferInfo { size, location })
    };
    let blocks = u64::from(entries.div_ceil(RADIX_BLOCK));
    let sort = RadixSort::for_device(ctx);
    let tiles = TileBins {
        bins: buffer(
            graph,
            "splat tile bins",
            4 * u64::from(3 * grid[0] * grid[1] + STATE_WORDS),
        ),
        entries: buffer(graph, "splat tile entries", ENTRY_BYTES * u64::from(entries)),
        scratch: buffer(graph, "splat tile entries (sort)", ENTRY_BYTES * u64::from(entries)),
        groups: buffer(graph, "splat tile groups", 4 * u64::from(group_capacity)),
        splats: buffer(
            graph,
            "binned splats",
            BINNED_SPLAT_BYTES * u64::from(WORKGROUP_SIZE) * u64::from(group_capacity),
        ),
        digits: buffer(graph, "splat tile digits", 4 * sort.digit_words(blocks)),
        sort,
        grid,
        capacity: entries,
        group_capacity,
    };
    // Every tile's cut mark, the sort state and every tile's range 0.
    let cleared = (&[tiles.bins][..], tiles.bin_words());
    declare_clear(graph, &name("points.single_pass.clear"), cleared, pipelines.clear);
    let count = (name("points.single_pass.count"), Binning::Count);
    declare_binning(graph, count, (buffers, view), tiles, pipelines.bin);
    declare_prefix(
        graph,
        &name("points.single_pass.prefix"),
        (buffers.counter, view),
        tiles,
        pipelines.prefix,
    );
    let scatter = (name("points.single_pass.scatter"), Binning::Scatter);
    declare_binning(graph, scatter, (buffers, view), tiles, pipelines.scatter);
    let sorted = radix::declare(ctx, graph, name, tiles)?;
    declare_ranges(
        graph,
        &name("points.single_pass.ranges"),
        (tiles, sorted),
        pipelines.ranges,
    );
    let merge = (name("points.single_pass.merge"), pipelines.merge);
    declare_merge(graph, merge, (buffers, view), targets, (tiles, sorted, written));
    Ok(())
}

/// Push constants of the binning passes (`Push` in glsl/include/splat.glsl
/// with `SPLAT_SINGLE_PASS_BIN`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BinPush {
    single: SinglePassPush,
    /// The group buffer, the draw's first workgroup in it, the binned splats.
    bin: [u32; 4],
}

/// The first workgroup in the group buffer of each of the frame's draws
/// (splat counts `counts`) that fit `group_capacity` workgroups, the
/// workgroups of those draws, and the splats of the later draws (not
/// binned: the binned splats' buffer is full).
fn draw_groups(counts: impl Iterator<Item = u32>, group_capacity: u32) -> (Vec<u32>, u32, u32) {
    let mut first = 0u32;
    let mut firsts = Vec::new();
    let (mut unbinned, mut full) = (0u32, false);
    for count in counts {
        let groups = count.div_ceil(WORKGROUP_SIZE);
        full |= first.saturating_add(groups) > group_capacity;
        if full {
            unbinned = unbinned.saturating_add(count);
            continue;
        }
        firsts.push(first);
        first += groups;
    }
    (firsts, first, unbinned)
}

/// `points.single_pass.count` ([`Binning::Count`]: the set-ups kept, the
/// depth range, each workgroup's entries, and the splats counted;
/// `glsl/points/single_pass_bin.comp`) or `points.single_pass.scatter`
/// ([`Binning::Scatter`]: the entries written, no barrier;
/// `glsl/points/single_pass_scatter.comp`): one dispatch per planned draw,
/// one invocation per splat.
fn declare_binning<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, binning): (String, Binning),
    (buffers, view): (PointBuffers, PointView),
    tiles: TileBins,
    pipeline: ComputePipeline,
) {
    let compute = Stage::Compute;
    let counting = binning == Binning::Count;
    let mut builder = graph.pass(&name);
    let frame = builder.upload(view.frame, compute);
    let (bins, groups, splats) = match counting {
        true => (
            builder.storage_buffer(tiles.bins, BufferAccess::StorageReadWrite(compute)),
            builder.storage_buffer(tiles.groups, BufferAccess::StorageWrite(compute)),
            builder.storage_buffer(tiles.splats, BufferAccess::StorageWrite(compute)),
        ),
        false => (
            builder.storage_buffer(tiles.bins, BufferAccess::StorageReadWrite(compute)),
            builder.storage_buffer(tiles.groups, BufferAccess::StorageRead(compute)),
            builder.storage_buffer(tiles.splats, BufferAccess::StorageRead(compute)),
        ),
    };
    let entries = (!counting).then(|| builder.storage_buffer(tiles.entries, BufferAccess::StorageWrite(compute)));
    let (builder, splat) = buffers.read_by_at(builder, frame, (compute, compute));
    builder.record(move |pass, frame| {
        let plan = plan_of(frame, view.index)?;
        let entries = entries.map(|e| pass.handle(e)).transpose()?.unwrap_or(NO_HANDLE);
        let mut push = BinPush {
            single: SinglePassPush {
                splat: splat.push(pass, PASS_OPAQUE)?,
                single: [pass.handle(bins)?, entries, 0, 0],
            },
            bin: [pass.handle(groups)?, 0, pass.handle(splats)?, 0],
        };
        let (firsts, _, _) = draw_groups(plan.draws.iter().map(|d| d.count), tiles.group_capacity);
        let cmd = pass.cmd();
        cmd.bind_compute(&pipeline);
        for (d, first) in plan.draws.iter().zip(firsts) {
            (push.single.splat.record, push.single.single[3]) = (d.record, d.count);
            push.bin[1] = first;
            cmd.push_constants(&push)?;
            let (x, y) = workgroups(d.count);
            cmd.dispatch(x, y, 1);
        }
        Ok(())
    });
}

/// `points.single_pass.prefix`: one workgroup: each binning workgroup's
/// first entry, the frame's entries, the sort's state; the longest list
/// into `counter` (`glsl/points/single_pass_prefix.comp`).
fn declare_prefix<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (counter, view): (Option<BufferId>, PointView),
    tiles: TileBins,
    pipeline: ComputePipeline,
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bins = pass.storage_buffer(tiles.bins, BufferAccess::StorageReadWrite(compute));
    let groups = pass.storage_buffer(tiles.groups, BufferAccess::StorageReadWrite(compute));
    let counter = counter.map(|c| pass.storage_buffer(c, BufferAccess::StorageReadWrite(compute)));
    pass.record(move |ctx, frame| {
        let plan = plan_of(frame, view.index)?;
        let (_, group_count, unbinned) = draw_groups(plan.draws.iter().map(|d| d.count), tiles.group_capacity);
        let counter = counter.map(|c| ctx.handle(c)).transpose()?.unwrap_or(NO_HANDLE);
        let push = [
            [ctx.handle(bins)?, tiles.tiles(), tiles.capacity, counter],
            [
                ctx.handle(groups)?,
                group_count,
                unbinned,
                radix::key_bits(tiles.tiles()),
            ],
        ];
        ctx.dispatch(&pipeline, &push, [1, 1, 1])
    });
}

/// `points.single_pass.ranges`: each tile's slice of the `sorted` entries
/// into its range words of the bins buffer, one workgroup per radix block
/// (dispatched for the capacity, as the sort's steps: the blocks past the
/// frame's entries return at once; `glsl/points/single_pass_ranges.comp`).
fn declare_ranges<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (tiles, sorted): (TileBins, BufferId),
    pipeline: ComputePipeline,
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bins = pass.storage_buffer(tiles.bins, BufferAccess::StorageReadWrite(compute));
    let entries = pass.storage_buffer(sorted, BufferAccess::StorageRead(compute));
    pass.record(move |ctx, _| {
        let push = [ctx.handle(bins)?, tiles.tiles(), ctx.handle(entries)?, 0];
        ctx.dispatch(&pipeline, &push, radix::block_groups(tiles.blocks()))
    });
}

/// Push constants of `points.single_pass.merge` (`Push` in
/// glsl/include/splat.glsl with `SPLAT_RESOLVE_COMPUTE` and `SPLAT_SINGLE_PASS`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MergePush {
    splat: SplatPush,
    resolved: ResolvedPush,
    /// Bins, entries, depth buffer (sampled; [`NO_HANDLE`]: none), 1 to keep W where no splat is.
    single: [u32; 4],
    /// The binned splats, 0, 0, 0.
    merge: [u32; 4],
}

/// The heap bindings of `points.single_pass.merge`.
#[derive(Clone, Copy, Debug)]
struct MergeBindings {
    shading: ShadingBindings,
    splat: SplatBindings,
    bins: Binding,
    entries: Binding,
    splats: Binding,
    depth: Option<Binding>,
    outputs: ResolvedTargets,
}

impl MergeBindings {
    /// The pass's push constants (`keep_weight`: the triangles wrote W).
    fn push(&self, pass: &PassContext<'_>, keep_weight: bool) -> Result<MergePush> {
        let depth = self.depth.map(|d| pass.handle(d)).transpose()?.unwrap_or(NO_HANDLE);
        Ok(MergePush {
            splat: self.splat.push(pass, PASS_OPAQUE)?,
            resolved: ResolvedPush::of(&self.outputs, pass)?,
            single: [
                pass.handle(self.bins)?,
                pass.handle(self.entries)?,
                depth,
                u32::from(keep_weight),
            ],
            merge: [pass.handle(self.splats)?, 0, 0, 0],
        })
    }
}

/// `points.single_pass.merge`: one workgroup per tile finds its slice of
/// the sorted entries (dropping it whole, and counting it, when the
/// capacity cut it short), merges the splats front to back per pixel with the fuzzy-depth operator and
/// writes each pixel once, normalised and shaded (W = 0 where no splat is
/// unless the triangles wrote it; `glsl/points/single_pass_tile.comp`).
fn declare_merge<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    (name, pipeline): (String, ComputePipeline),
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    (tiles, sorted, written): (TileBins, BufferId, Written),
) {
    let compute = Stage::Compute;
    let weight = match written.weight {
        true => ImageAccess::StorageReadWrite(compute),
        false => ImageAccess::StorageWrite(compute),
    };
    let mut builder = graph.pass(&name);
    let shading = ShadingBindings::read_in(&mut builder, (&view, targets), compute);
    let bins = builder.storage_buffer(tiles.bins, BufferAccess::StorageRead(compute));
    let entries = builder.storage_buffer(sorted, BufferAccess::StorageRead(compute));
    let splats = builder.storage_buffer(tiles.splats, BufferAccess::StorageRead(compute));
    let depth = written.depth.then(|| builder.sample(view.depth, compute));
    let outputs = ResolvedTargets::declare(&mut builder, (&view, targets), weight);
    // The counter takes the entries of lists dropped for want of capacity.
    let (builder, splat) = buffers.read_by_at(builder, shading.frame, (compute, compute));
    let bindings = MergeBindings {
        shading,
        splat,
        bins,
        entries,
        splats,
        depth,
        outputs,
    };
    builder.record(move |pass, frame| {
        bindings.shading.write_header(pass, frame, view.index)?;
        let push = bindings.push(pass, written.weight)?;
        pass.dispatch(&pipeline, &push, [tiles.grid[0], tiles.grid[1], 1])
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_constants_match_the_shader_block() {
        // handles, mode, outputs, more, single, merge.
        assert_eq!(std::mem::size_of::<MergePush>(), 96);
    }

    #[test]
    fn entry_capacity_is_clamped() {
        let range = u64::from(u32::MAX);
        assert_eq!(entry_capacity(0, range), 1 << 16);
        assert_eq!(entry_capacity(100_000, range), 1_200_000);
        assert_eq!(entry_capacity(u64::MAX, range), 1 << 24);
        assert_eq!(entry_capacity(u64::MAX, 1 << 27), (1 << 27) / 12);
    }

    #[test]
    fn draws_get_consecutive_workgroups_within_the_capacity() {
        assert_eq!(draw_groups([64, 1, 65, 0].into_iter(), 100), (vec![0, 1, 2, 4], 4, 0));
        assert_eq!(draw_groups([640, 64, 1].into_iter(), 10), (vec![0], 10, 65));
        assert_eq!(draw_groups(std::iter::empty(), 1), (vec![], 0, 0));
    }
}
