//! The radix sort of the compute backend's tile entries (dissertation
//! §10.4; [`super::tiles`]): a stable LSD sort of the entries' keys
//! (tile index high, quantised reach low: [`key_bits`], the tile index and
//! at least 12 bits of reach in whole bytes) on the GPU, in [`digit_bits`]
//! passes of at most [`RADIX_BITS`] (two of 12 bits at 512²), each pass four
//! graph passes in the frame's one dispatch chain:
//! `points.single_pass.radix<k>.count` (one invocation per block of
//! [`RADIX_BLOCK`] entries: its row of digit counts), `.scan` (one
//! invocation per digit: the digit's entries of the earlier blocks, and its
//! total), `.starts` (one workgroup: each digit's first output position) and
//! `.scatter` (one invocation per block: its entries to their positions, in
//! order). The passes alternate between the entry buffer and the scratch
//! buffer; the merge reads the last pass's. Every dispatch is sized by the
//! capacity; the invocations past the frame's entries
//! (`points.single_pass.prefix` wrote how many) return at once, so nothing
//! waits on the CPU. Shaders:
//! `glsl/points/single_pass_radix_{count,scan,starts,scatter}.comp` with
//! `glsl/include/single_pass_radix.glsl`.

use std::sync::Arc;

use super::super::PointsFrame;
use super::tiles::TileBins;
use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, RenderGraph, Stage};
use crate::shaders;
use crate::view::{Frame, Provides};
use crate::vulkan::{ComputePipeline, Context};

/// The widest digit a pass sorts by (`RADIX_BITS` in glsl/include/single_pass_radix.glsl).
const RADIX_BITS: u32 = 12;
/// Values of the widest digit: the words of a block's row of digit counts.
pub(super) const DIGITS: u64 = 1 << RADIX_BITS;
/// Entries of a block (`RADIX_BLOCK`).
pub(super) const RADIX_BLOCK: u32 = 2048;
/// Blocks (one invocation each) per workgroup of the count and scatter
/// steps (`RADIX_LANES`).
const RADIX_LANES: u32 = 8;
/// Invocations per workgroup of the scan step (one per digit value).
const SCAN_WORKGROUP: u32 = 64;
/// The key's granularity: its bits are whole bytes (what fixes the reach's
/// quantisation, and with it the order of the sorted lists).
const KEY_BYTE: u32 = 8;
/// The fewest bits of the key's reach (the quantised depth order within a
/// tile): 2¹² levels over the frame's reach range.
const MIN_REACH_BITS: u32 = 12;
/// Most workgroups per dispatch row.
const MAX_GROUPS_X: u32 = 65535;

/// The sort's pipelines.
struct Pipelines {
    count: ComputePipeline,
    scan: ComputePipeline,
    starts: ComputePipeline,
    scatter: ComputePipeline,
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

/// The digits of the sort of `tiles`' keys, lowest first: the fewest passes
/// of at most [`RADIX_BITS`] that cover [`key_bits`], as even as they go
/// (12 + 12 at 512², 11 + 11 + 10 for 32-bit keys).
pub(super) fn digit_bits(tiles: u32) -> Vec<u32> {
    let bits = key_bits(tiles);
    let passes = bits.div_ceil(RADIX_BITS);
    (0..passes)
        .map(|k| bits / passes + u32::from(k < bits % passes))
        .collect()
}

/// The radix sort's passes over `tiles`' entries (see the module doc);
/// `name` gives a pass's name for the view. Returns the buffer that holds
/// the sorted entries (the entry buffer after an even number of passes,
/// else the scratch buffer).
pub(super) fn declare<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    tiles: TileBins,
) -> Result<BufferId> {
    let pipelines = Arc::new(Pipelines {
        count: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RADIX_COUNT)?,
        scan: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RADIX_SCAN)?,
        starts: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RADIX_STARTS)?,
        scatter: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RADIX_SCATTER)?,
    });
    let digits = digit_bits(tiles.tiles());
    let mut shift = 0;
    for (k, &bits) in digits.iter().enumerate() {
        let (source, destination) = match k % 2 {
            0 => (tiles.entries, tiles.scratch),
            _ => (tiles.scratch, tiles.entries),
        };
        let pass = |what: &str| name(&format!("points.single_pass.radix{k}.{what}"));
        let io = (source, destination, [shift, bits]);
        for step in [Step::Count, Step::Scan, Step::Starts, Step::Scatter] {
            declare_step(graph, &pass(step.name()), step, (tiles, io), pipelines.clone());
        }
        shift += bits;
    }
    Ok(match digits.len() % 2 {
        0 => tiles.entries,
        _ => tiles.scratch,
    })
}

/// One of a radix pass's four steps.
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

/// The graph pass of `step` of the radix pass reading `source`, writing
/// `destination`, sorting by the digit of `bits` bits at bit `shift`. Push
/// constants: (bins, tiles, source, destination), (digits, blocks of the
/// capacity, shift, bits).
fn declare_step<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    step: Step,
    (tiles, (source, destination, [shift, bits])): (TileBins, (BufferId, BufferId, [u32; 2])),
    pipelines: Arc<Pipelines>,
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bins = pass.storage_buffer(tiles.bins, BufferAccess::StorageRead(compute));
    // Every step reads what it or an earlier step wrote (count its own row's counts).
    let digits = pass.storage_buffer(tiles.digits, BufferAccess::StorageReadWrite(compute));
    let reads_entries = matches!(step, Step::Count | Step::Scatter);
    let source = reads_entries.then(|| pass.storage_buffer(source, BufferAccess::StorageRead(compute)));
    let destination =
        (step == Step::Scatter).then(|| pass.storage_buffer(destination, BufferAccess::StorageWrite(compute)));
    let blocks = tiles.blocks();
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
        let lanes = block_groups(blocks.div_ceil(RADIX_LANES));
        let (pipeline, groups) = match step {
            Step::Count => (&pipelines.count, lanes),
            Step::Scan => (&pipelines.scan, [(DIGITS as u32).div_ceil(SCAN_WORKGROUP), 1, 1]),
            Step::Starts => (&pipelines.starts, [1, 1, 1]),
            Step::Scatter => (&pipelines.scatter, lanes),
        };
        ctx.dispatch(pipeline, &push, groups)
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
        // 512² in 8×8 tiles: 4096 tiles, 12 bits + 12 of reach, two 12-bit digits.
        assert_eq!((key_bits(4096), digit_bits(4096)), (24, vec![12, 12]));
        assert_eq!((key_bits(4097), digit_bits(4097)), (32, vec![11, 11, 10]));
        assert_eq!((key_bits(1), digit_bits(1)), (16, vec![8, 8]));
        for tiles in [1, 2, 4096, 4097, 14_400, 1 << 20, u32::MAX] {
            let reach = key_bits(tiles) - tile_bits(tiles);
            assert!(reach >= MIN_REACH_BITS.min(32 - tile_bits(tiles)), "{tiles}: {reach}");
            assert!(key_bits(tiles) <= 32);
            let digits = digit_bits(tiles);
            assert_eq!(digits.iter().sum::<u32>(), key_bits(tiles), "{tiles}");
            assert!(digits.iter().all(|&d| d > 0 && d <= RADIX_BITS), "{tiles}: {digits:?}");
        }
    }
}
