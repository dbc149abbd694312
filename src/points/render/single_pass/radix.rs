//! The radix sort of the compute backend's tile entries (dissertation
//! §10.4; [`super::tiles`]): a stable LSD sort of the entries' keys
//! (tile index high, quantised reach low: [`key_bits`], the tile index and
//! at least 12 bits of reach in whole bytes) on the device, in one of two
//! variants ([`RadixSort`], chosen by device type) that give the same
//! sorted entries, each pass a few graph passes in the frame's one
//! dispatch chain:
//!
//! * [`RadixSort::SerialBlocks`] (CPU drivers), passes of at most
//!   [`SERIAL_BITS`] (two of 12 bits at 512²):
//!   `points.single_pass.radix_serial<k>.count` (one invocation per block
//!   of [`RADIX_BLOCK`] entries: its row of digit counts), `.scan` (one
//!   invocation per digit: the digit's entries of the earlier blocks, and
//!   its total), `.starts` (one workgroup: each digit's first output
//!   position) and `.scatter` (one invocation per block: its entries to
//!   their positions, in order); shaders
//!   `glsl/points/single_pass_radix_{count,scan,starts,scatter}.comp`;
//! * [`RadixSort::SharedRuns`] (GPUs), passes of [`RUNS_BITS`] (three at
//!   512²): `points.single_pass.radix_runs<k>.count` (a workgroup per
//!   block: its digit counts, digit-major), `.scan` (one workgroup: each
//!   (digit, block)'s first output position) and `.scatter` (a workgroup
//!   per block, each invocation ranking a run of 64 entries in shared
//!   counters); shaders
//!   `glsl/points/single_pass_radix_runs_{count,scan,scatter}.comp`.
//!
//! Both with `glsl/include/single_pass_radix.glsl`. The passes alternate
//! between the entry buffer and the scratch buffer; the merge reads the
//! last pass's. Every dispatch is sized by the capacity; the invocations
//! past the frame's entries (`points.single_pass.prefix` wrote how many)
//! return at once, so nothing waits on the CPU.

use std::sync::Arc;

use super::super::PointsFrame;
use super::tiles::TileBins;
use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, RenderGraph, Stage};
use crate::shaders;
use crate::view::{Frame, Provides};
use crate::vulkan::{ComputePipeline, Context};

/// The widest digit of the serial-blocks sort (`RADIX_BITS` in
/// glsl/include/single_pass_radix.glsl).
const SERIAL_BITS: u32 = 12;
/// The digit of the shared-runs sort (`RADIX_BITS` with `RADIX_SHARED_RUNS`).
const RUNS_BITS: u32 = 8;
/// Entries of a block (`RADIX_BLOCK`), both sorts.
pub(super) const RADIX_BLOCK: u32 = 2048;
/// Blocks (one invocation each) per workgroup of the serial-blocks sort's
/// count and scatter steps (`RADIX_LANES`).
const RADIX_LANES: u32 = 8;
/// Invocations per workgroup of the serial-blocks sort's scan step (one per digit value).
const SCAN_WORKGROUP: u32 = 64;
/// The key's granularity: its bits are whole bytes (what fixes the reach's
/// quantisation, and with it the order of the sorted lists; whole digits
/// of the shared-runs sort).
const KEY_BYTE: u32 = 8;
/// The fewest bits of the key's reach (the quantised depth order within a
/// tile): 2¹² levels over the frame's reach range.
const MIN_REACH_BITS: u32 = 12;
/// Most workgroups per dispatch row.
const MAX_GROUPS_X: u32 = 65535;

/// Which radix sort orders a view's tile entries. Both are stable LSD
/// sorts of the same keys, so they give the same sorted entries and the
/// same image to the byte; they differ in how the work spreads over the
/// device. The pass names tell which one ran (`radix_serial<k>` or
/// `radix_runs<k>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RadixSort {
    /// Digits of up to 12 bits (two passes at 512²), one invocation per
    /// block of [`RADIX_BLOCK`] entries counting and scattering them
    /// serially: no shared memory, no barrier (a CPU driver runs a shader
    /// with one as coroutines). The sort of a CPU device (lavapipe,
    /// llvmpipe): about 3× cheaper there than [`RadixSort::SharedRuns`]
    /// (docs/PERFORMANCE.md). On a GPU it would keep a few hundred
    /// invocations busy with 2048 dependent steps each.
    SerialBlocks,
    /// 8-bit digits (three passes at 512²), a workgroup per block whose 32
    /// invocations each rank a run of 64 entries in shared counters: the
    /// sort of every other device (unmeasured on a GPU).
    SharedRuns,
}

#[cfg(test)]
thread_local! {
    static SORT_OVERRIDE: std::cell::Cell<Option<RadixSort>> = const { std::cell::Cell::new(None) };
}

/// Runs `f` with every view this thread declares sorting its tile entries
/// with `sort` whatever the device (tests comparing the sorts).
#[cfg(test)]
pub(crate) fn with_radix_sort<R>(sort: RadixSort, f: impl FnOnce() -> R) -> R {
    super::with_override(&SORT_OVERRIDE, sort, f)
}

impl RadixSort {
    /// The sort for `ctx`'s device: [`RadixSort::SerialBlocks`] on a CPU,
    /// else [`RadixSort::SharedRuns`].
    pub(super) fn for_device(ctx: &Context) -> RadixSort {
        #[cfg(test)]
        if let Some(sort) = SORT_OVERRIDE.with(|s| s.get()) {
            return sort;
        }
        match ctx.is_cpu() {
            true => RadixSort::SerialBlocks,
            false => RadixSort::SharedRuns,
        }
    }

    /// The prefix of its passes' names.
    fn pass_prefix(self) -> &'static str {
        match self {
            RadixSort::SerialBlocks => "points.single_pass.radix_serial",
            RadixSort::SharedRuns => "points.single_pass.radix_runs",
        }
    }

    /// The digits of the sort of `tiles`' keys, lowest first: for the
    /// serial blocks the fewest passes of at most [`SERIAL_BITS`] that
    /// cover [`key_bits`], as even as they go (12 + 12 at 512², 11 + 11 +
    /// 10 for 32-bit keys); for the shared runs bytes.
    pub(super) fn digit_bits(self, tiles: u32) -> Vec<u32> {
        let bits = key_bits(tiles);
        match self {
            RadixSort::SerialBlocks => {
                let passes = bits.div_ceil(SERIAL_BITS);
                (0..passes)
                    .map(|k| bits / passes + u32::from(k < bits % passes))
                    .collect()
            }
            RadixSort::SharedRuns => vec![RUNS_BITS; (bits / RUNS_BITS) as usize],
        }
    }

    /// Words of the digits buffer for `blocks` radix blocks: the serial
    /// blocks' row of 2¹² counts per block and the digits' totals (8 bytes
    /// per entry of the capacity, 80 MB at 10⁷ entries), the shared runs'
    /// 2⁸ counts per block (0.5 bytes per entry, 5 MB at 10⁷).
    pub(super) fn digit_words(self, blocks: u64) -> u64 {
        match self {
            RadixSort::SerialBlocks => (1 << SERIAL_BITS) * (blocks + 1),
            RadixSort::SharedRuns => (1 << RUNS_BITS) * blocks,
        }
    }

    /// Its steps of a pass, each with its pipeline.
    fn steps(self, ctx: &Context) -> Result<Vec<(Step, ComputePipeline)>> {
        let shaders = match self {
            RadixSort::SerialBlocks => vec![
                (Step::Count, shaders::SPLAT_SINGLE_PASS_RADIX_COUNT),
                (Step::Scan, shaders::SPLAT_SINGLE_PASS_RADIX_SCAN),
                (Step::Starts, shaders::SPLAT_SINGLE_PASS_RADIX_STARTS),
                (Step::Scatter, shaders::SPLAT_SINGLE_PASS_RADIX_SCATTER),
            ],
            RadixSort::SharedRuns => vec![
                (Step::Count, shaders::SPLAT_SINGLE_PASS_RADIX_RUNS_COUNT),
                (Step::Scan, shaders::SPLAT_SINGLE_PASS_RADIX_RUNS_SCAN),
                (Step::Scatter, shaders::SPLAT_SINGLE_PASS_RADIX_RUNS_SCATTER),
            ],
        };
        (shaders.into_iter())
            .map(|(step, shader)| Ok((step, ComputePipeline::new(ctx, shader)?)))
            .collect()
    }
}

/// The bits of a tile index among `tiles` (at least 1; `tile_bits` in
/// glsl/include/single_pass_tiles.glsl).
fn tile_bits(tiles: u32) -> u32 {
    (u32::BITS - tiles.saturating_sub(1).leading_zeros()).max(1)
}

/// The bits of the sort keys of `tiles`: the tile index and at least
/// [`MIN_REACH_BITS`] of reach, in whole bytes (24 at 512² with 8×8 tiles:
/// 12 + 12 bits; 32 from 2¹³ tiles on).
pub(super) fn key_bits(tiles: u32) -> u32 {
    (tile_bits(tiles) + MIN_REACH_BITS)
        .div_ceil(KEY_BYTE)
        .min(32 / KEY_BYTE)
        * KEY_BYTE
}

/// The radix sort's passes over `tiles`' entries with `tiles.sort` (see
/// the module doc); `name` gives a pass's name for the view. Returns the
/// buffer that holds the sorted entries (the entry buffer after an even
/// number of passes, else the scratch buffer).
pub(super) fn declare<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    tiles: TileBins,
) -> Result<BufferId> {
    let sort = tiles.sort;
    let steps: Vec<Arc<(Step, ComputePipeline)>> = sort.steps(ctx)?.into_iter().map(Arc::new).collect();
    let digits = sort.digit_bits(tiles.tiles());
    let mut shift = 0;
    for (k, &bits) in digits.iter().enumerate() {
        let (source, destination) = match k % 2 {
            0 => (tiles.entries, tiles.scratch),
            _ => (tiles.scratch, tiles.entries),
        };
        let pass = |what: &str| name(&format!("{}{k}.{what}", sort.pass_prefix()));
        let io = (source, destination, [shift, bits]);
        for step in &steps {
            declare_step(graph, &pass(step.0.name()), (tiles, io), step.clone());
        }
        shift += bits;
    }
    Ok(match digits.len() % 2 {
        0 => tiles.entries,
        _ => tiles.scratch,
    })
}

/// One of a radix pass's steps (`Starts` only in the serial blocks').
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    Count,
    Scan,
    Starts,
    Scatter,
}

impl Step {
    /// The step's name in the pass's.
    fn name(self) -> &'static str {
        match self {
            Step::Count => "count",
            Step::Scan => "scan",
            Step::Starts => "starts",
            Step::Scatter => "scatter",
        }
    }
}

/// Workgroups for one per radix block of the capacity: (per row, rows).
pub(super) fn block_groups(blocks: u32) -> [u32; 3] {
    let rows = blocks.div_ceil(MAX_GROUPS_X).max(1);
    [blocks.div_ceil(rows).max(1), rows, 1]
}

/// The graph pass of `step_pipeline`'s step of the radix pass reading `source`, writing
/// `destination`, sorting by the digit of `bits` bits at bit `shift`. Push
/// constants: (bins, tiles, source, destination), (digits, blocks of the
/// capacity, shift, bits).
fn declare_step<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (tiles, (source, destination, [shift, bits])): (TileBins, (BufferId, BufferId, [u32; 2])),
    step_pipeline: Arc<(Step, ComputePipeline)>,
) {
    let step = step_pipeline.0;
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bins = pass.storage_buffer(tiles.bins, BufferAccess::StorageRead(compute));
    let digits_access = match (tiles.sort, step) {
        // Every serial step reads what it or an earlier step wrote (count its own row's counts).
        (RadixSort::SerialBlocks, _) | (_, Step::Scan | Step::Starts) => BufferAccess::StorageReadWrite(compute),
        (RadixSort::SharedRuns, Step::Count) => BufferAccess::StorageWrite(compute),
        (RadixSort::SharedRuns, Step::Scatter) => BufferAccess::StorageRead(compute),
    };
    let digits = pass.storage_buffer(tiles.digits, digits_access);
    let reads_entries = matches!(step, Step::Count | Step::Scatter);
    let source = reads_entries.then(|| pass.storage_buffer(source, BufferAccess::StorageRead(compute)));
    let destination =
        (step == Step::Scatter).then(|| pass.storage_buffer(destination, BufferAccess::StorageWrite(compute)));
    let blocks = tiles.blocks();
    let serial = tiles.sort == RadixSort::SerialBlocks;
    pass.record(move |ctx, _| {
        let handle = |b: Option<crate::graph::Binding>| b.map(|b| ctx.handle(b)).transpose();
        let push = [
            [
                ctx.handle(bins)?,
                tiles.tiles(),
                handle(source)?.unwrap_or(u32::MAX),
                handle(destination)?.unwrap_or(u32::MAX),
            ],
            [ctx.handle(digits)?, blocks, shift, bits],
        ];
        // A workgroup per block (shared runs) or an invocation per block in rows of RADIX_LANES (serial).
        let per_block = match serial {
            true => block_groups(blocks.div_ceil(RADIX_LANES)),
            false => block_groups(blocks),
        };
        let scan = match serial {
            true => [(1u32 << SERIAL_BITS).div_ceil(SCAN_WORKGROUP), 1, 1],
            false => [1, 1, 1],
        };
        let groups = match step {
            Step::Count | Step::Scatter => per_block,
            Step::Scan => scan,
            Step::Starts => [1, 1, 1],
        };
        ctx.dispatch(&step_pipeline.1, &push, groups)
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_fit_the_dispatch_limit() {
        for blocks in [1, 2, 65535, 65536, 1 << 20] {
            let [x, y, _] = block_groups(blocks);
            assert!(x <= MAX_GROUPS_X && x * y >= blocks, "{blocks}: {x}×{y}");
        }
    }

    #[test]
    fn keys_hold_the_tile_index_and_enough_reach() {
        let (serial, runs) = (RadixSort::SerialBlocks, RadixSort::SharedRuns);
        // 512² in 8×8 tiles: 4096 tiles, 12 bits + 12 of reach, two 12-bit digits or three bytes.
        assert_eq!(key_bits(4096), 24);
        assert_eq!(serial.digit_bits(4096), vec![12, 12]);
        assert_eq!(runs.digit_bits(4096), vec![8, 8, 8]);
        assert_eq!((key_bits(4097), serial.digit_bits(4097)), (32, vec![11, 11, 10]));
        assert_eq!(runs.digit_bits(4097), vec![8; 4]);
        assert_eq!((key_bits(1), serial.digit_bits(1)), (16, vec![8, 8]));
        for tiles in [1, 2, 4096, 4097, 14_400, 1 << 20, u32::MAX] {
            let reach = key_bits(tiles) - tile_bits(tiles);
            assert!(reach >= MIN_REACH_BITS.min(32 - tile_bits(tiles)), "{tiles}: {reach}");
            assert!(key_bits(tiles) <= 32);
            for (sort, widest) in [(serial, SERIAL_BITS), (runs, RUNS_BITS)] {
                let digits = sort.digit_bits(tiles);
                assert_eq!(digits.iter().sum::<u32>(), key_bits(tiles), "{sort:?} {tiles}");
                assert!(
                    digits.iter().all(|&d| d > 0 && d <= widest),
                    "{sort:?} {tiles}: {digits:?}"
                );
            }
        }
    }

    /// The device picks its sort: lavapipe and llvmpipe (Mesa's CPU
    /// drivers) the serial blocks, a GPU the shared runs; an override wins.
    #[test]
    fn the_device_type_picks_the_sort() {
        let (ctx, _) = crate::test_support::validated_context();
        let name = ctx.info().name.to_lowercase();
        let mesa_cpu = name.contains("llvmpipe") || name.contains("lavapipe");
        assert_eq!(ctx.is_cpu(), ctx.info().device_type == "CPU");
        if mesa_cpu {
            assert_eq!(RadixSort::for_device(&ctx), RadixSort::SerialBlocks, "{name}");
        }
        if !ctx.is_cpu() {
            assert_eq!(RadixSort::for_device(&ctx), RadixSort::SharedRuns, "{name}");
        }
        let runs = with_radix_sort(RadixSort::SharedRuns, || RadixSort::for_device(&ctx));
        assert_eq!(runs, RadixSort::SharedRuns);
        assert_ne!(
            RadixSort::SerialBlocks.pass_prefix(),
            RadixSort::SharedRuns.pass_prefix()
        );
    }

    /// The digits buffer stays below the two entry buffers' 24 bytes per
    /// entry at every capacity up to the largest (2²⁴ entries): at 10⁷
    /// entries 80 MB for the serial blocks, 5 MB for the shared runs.
    #[test]
    fn digit_counts_stay_small_beside_the_entries() {
        for entries in [1u64, 2048, 65_536, 10_000_000, 1 << 24] {
            let blocks = entries.div_ceil(u64::from(RADIX_BLOCK));
            let serial = 4 * RadixSort::SerialBlocks.digit_words(blocks);
            let runs = 4 * RadixSort::SharedRuns.digit_words(blocks);
            assert!(
                runs <= serial && serial <= 16 * 4096 + 8 * entries.max(2048),
                "{entries}: {serial}"
            );
        }
        assert_eq!(4 * RadixSort::SerialBlocks.digit_words(4883), 80_019_456);
        assert_eq!(4 * RadixSort::SharedRuns.digit_words(4883), 5_000_192);
    }
}
