//! The radix sort of the compute backend's tile entries (dissertation
//! §10.4; [`super::tiles`]): a stable LSD sort of the entries' keys
//! (tile index high, quantised reach low: [`key_bits`], the tile index and
//! at least 12 bits of reach in whole digits) on the GPU, [`RADIX_BITS`] a pass,
//! each pass three graph passes in the frame's one dispatch chain:
//! `points.single_pass.radix<k>.count` (per block of [`RADIX_BLOCK`]
//! entries, its digit counts), `.scan` (one workgroup: each (digit, block)'s
//! first output position) and `.scatter` (each block's entries to their
//! positions, in order). The passes alternate between the entry buffer and
//! the scratch buffer; the merge reads the last pass's. Every dispatch is sized by the capacity; the workgroups past
//! the frame's entries (`points.single_pass.prefix` wrote how many) return
//! at once, so nothing waits on the CPU. Shaders:
//! `glsl/points/single_pass_radix_{count,scan,scatter}.comp` with
//! `glsl/include/single_pass_radix.glsl`.

use std::sync::Arc;

use super::super::PointsFrame;
use super::tiles::TileBins;
use crate::error::Result;
use crate::graph::{BufferAccess, BufferId, RenderGraph, Stage};
use crate::shaders;
use crate::view::{Frame, Provides};
use crate::vulkan::{ComputePipeline, Context};

/// Key bits a pass sorts by (`RADIX_BITS` in glsl/include/single_pass_radix.glsl).
const RADIX_BITS: u32 = 8;
/// Values of a digit.
pub(super) const DIGITS: u64 = 1 << RADIX_BITS;
/// Entries of a block (`RADIX_BLOCK`).
pub(super) const RADIX_BLOCK: u32 = 2048;
/// The fewest bits of the key's reach (the quantised depth order within a
/// tile): 2¹² levels over the frame's reach range.
const MIN_REACH_BITS: u32 = 12;
/// Most workgroups per dispatch row.
const MAX_GROUPS_X: u32 = 65535;

/// The sort's pipelines.
struct Pipelines {
    count: ComputePipeline,
    scan: ComputePipeline,
    scatter: ComputePipeline,
}

/// The bits of a tile index among `tiles` (at least 1; `tile_bits` in
/// glsl/include/single_pass_tiles.glsl).
fn tile_bits(tiles: u32) -> u32 {
    (u32::BITS - tiles.saturating_sub(1).leading_zeros()).max(1)
}

/// Radix passes of the sort of `tiles`' keys: the tile index and at least
/// [`MIN_REACH_BITS`] of reach, in whole digits (3 at 512² with 8×8 tiles:
/// 12 + 12 bits; 4, all 32 bits, from 2¹³ tiles on).
pub(super) fn passes(tiles: u32) -> u32 {
    (tile_bits(tiles) + MIN_REACH_BITS)
        .div_ceil(RADIX_BITS)
        .min(32 / RADIX_BITS)
}

/// The bits of the sort keys of `tiles` (`passes` digits).
pub(super) fn key_bits(tiles: u32) -> u32 {
    passes(tiles) * RADIX_BITS
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
        scatter: ComputePipeline::new(ctx, shaders::SPLAT_SINGLE_PASS_RADIX_SCATTER)?,
    });
    let passes = passes(tiles.tiles());
    for k in 0..passes {
        let (source, destination) = match k % 2 {
            0 => (tiles.entries, tiles.scratch),
            _ => (tiles.scratch, tiles.entries),
        };
        let shift = k * RADIX_BITS;
        let pass = |what: &str| name(&format!("points.single_pass.radix{k}.{what}"));
        let io = (source, destination, shift);
        declare_step(graph, &pass("count"), Step::Count, (tiles, io), pipelines.clone());
        declare_step(graph, &pass("scan"), Step::Scan, (tiles, io), pipelines.clone());
        declare_step(graph, &pass("scatter"), Step::Scatter, (tiles, io), pipelines.clone());
    }
    Ok(match passes % 2 {
        0 => tiles.entries,
        _ => tiles.scratch,
    })
}

/// One of a radix pass's three steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    Count,
    Scan,
    Scatter,
}

/// Workgroups for one per radix block of the capacity: (per row, rows).
pub(super) fn block_groups(blocks: u32) -> [u32; 3] {
    let rows = blocks.div_ceil(MAX_GROUPS_X).max(1);
    [blocks.div_ceil(rows).max(1), rows, 1]
}

/// The graph pass of `step` of the radix pass reading `source`, writing
/// `destination`, sorting by the digit at bit `shift`. Push constants:
/// (bins, tiles, source, destination), (digits, blocks of the capacity, shift, 0).
fn declare_step<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    step: Step,
    (tiles, (source, destination, shift)): (TileBins, (BufferId, BufferId, u32)),
    pipelines: Arc<Pipelines>,
) {
    let compute = Stage::Compute;
    let mut pass = graph.pass(name);
    let bins = pass.storage_buffer(tiles.bins, BufferAccess::StorageRead(compute));
    let digits_access = match step {
        Step::Count => BufferAccess::StorageWrite(compute),
        Step::Scan => BufferAccess::StorageReadWrite(compute),
        Step::Scatter => BufferAccess::StorageRead(compute),
    };
    let digits = pass.storage_buffer(tiles.digits, digits_access);
    let source = (step != Step::Scan).then(|| pass.storage_buffer(source, BufferAccess::StorageRead(compute)));
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
            [ctx.handle(digits)?, blocks, shift, 0],
        ];
        let (pipeline, groups) = match step {
            Step::Count => (&pipelines.count, block_groups(blocks)),
            Step::Scan => (&pipelines.scan, [1, 1, 1]),
            Step::Scatter => (&pipelines.scatter, block_groups(blocks)),
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
        // 512² in 8×8 tiles: 4096 tiles, 12 bits + 12 of reach.
        assert_eq!((passes(4096), key_bits(4096)), (3, 24));
        assert_eq!(passes(4097), 4);
        assert_eq!(passes(1), 2);
        for tiles in [1, 2, 4096, 4097, 14_400, 1 << 20, u32::MAX] {
            let reach = key_bits(tiles) - tile_bits(tiles);
            assert!(reach >= MIN_REACH_BITS.min(32 - tile_bits(tiles)), "{tiles}: {reach}");
            assert!(key_bits(tiles) <= 32);
        }
    }
}
