// The sort of single-pass splatting's tile entries (dissertation §10.4;
// glsl/include/single_pass_tiles.glsl), in two variants picked by device
// type (src/points/render/single_pass/radix.rs: RadixSort; the shared-runs
// one, for GPUs, below with RADIX_SHARED_RUNS): a stable LSD radix sort of the
// entries' keys (tile index high, quantised reach low), from the lowest
// digit up, digits of at most RADIX_BITS (two passes of 12 bits for the
// 24-bit keys of a 512² view), each pass four dispatches with no CPU in
// between (src/points/render/single_pass/radix.rs):
//   count   (single_pass_radix_count.comp): one invocation per block of
//           RADIX_BLOCK consecutive entries counts how many hold each digit
//           into its block's row of the digit counts (block-major);
//   scan    (single_pass_radix_scan.comp): one invocation per digit turns
//           its column into each (block, digit)'s entries of that digit in
//           the earlier blocks, and the digit's total;
//   starts  (single_pass_radix_starts.comp): one workgroup turns the totals
//           into each digit's first output position;
//   scatter (single_pass_radix_scatter.comp): one invocation per block
//           walks its entries in order and writes each at its digit's start
//           + the digit's entries of the earlier blocks + those before it in
//           the block.
// Stable at every pass, so entries of equal keys keep the binning's order
// and the sorted entries are the same on every run. No atomics, no shared
// memory but the starts' scan, and every invocation of count and scatter
// owns its block's row: no barrier (a CPU driver runs a shader with one as
// coroutines), and wide digits need no per-invocation rank columns.
//
// The bins buffer's sort state (words after the T tile counts):
//   T + 0    ~(least reach bits) (atomicMax of the complement; 0 when cleared)
//   T + 1    greatest reach bits
//   T + 2    entries of the frame, N (points.single_pass.prefix)
//   T + 3    entries sorted, M = min(N, capacity)
//   T + 4    depth shift: the key holds (reach bits − least) >> shift
//   T + 5    least reach bits
//   T + 6    the reach's bits in the key (the key's bits − the tile index's)
//   T + 7    radix blocks: ceil(M / RADIX_BLOCK)
// then, from T + STATE_WORDS, each tile's slice [first, end) of the sorted
// entries (two words a tile; (0, 0): empty), points.single_pass.ranges.
// Layouts: src/points/render/single_pass/tiles.rs.
#ifndef ALPENGLOW_SINGLE_PASS_RADIX_GLSL
#define ALPENGLOW_SINGLE_PASS_RADIX_GLSL

#include "heap.glsl"

#define STATE_LEAST_COMPLEMENT 0u
#define STATE_GREATEST 1u
#define STATE_ENTRIES 2u
#define STATE_SORTED 3u
#define STATE_SHIFT 4u
#define STATE_LEAST 5u
#define STATE_DEPTH_BITS 6u
#define STATE_BLOCKS 7u
#define STATE_WORDS 8u
// No tile: a tile index is below 2³¹ (the key holds at least one bit of reach).
#define NO_TILE 0xffffffffu

// Entries of a block (both sorts).
#define RADIX_BLOCK 2048u
#ifdef RADIX_SHARED_RUNS
// The shared-runs sort (RadixSort::SharedRuns, the sort of a GPU):
// single_pass_radix_runs_{count,scan,scatter}.comp, 8-bit digits, three
// dispatches a pass: count (a workgroup per block, shared atomic counters,
// digit-major counts[digit × blocks + block]), scan (one workgroup: each
// (digit, block)'s first output position), scatter (a workgroup per block,
// each of RADIX_SCATTER_INVOCATIONS invocations ranking a run of
// RADIX_ITEMS entries in 16-bit shared counters). The digits buffer holds
// RADIX_DIGITS words per block.
#define RADIX_BITS 8u
#define RADIX_DIGITS 256u
// Entries of a block: RADIX_SCATTER_INVOCATIONS × RADIX_ITEMS.
#define RADIX_SCATTER_INVOCATIONS 32u
#define RADIX_ITEMS 64u
#else
// The serial-blocks sort (RadixSort::SerialBlocks, the sort of a CPU
// driver; the steps above). The widest digit and its values: the digits
// buffer holds RADIX_DIGITS words per block of the capacity (the block's
// row), then RADIX_DIGITS words: each digit's total, then its first output
// position.
#define RADIX_BITS 12u
#define RADIX_DIGITS 4096u
// Blocks (one invocation each) per workgroup of count and scatter: one SIMD
// row of a CPU driver, so the frame's few blocks spread over its cores.
#define RADIX_LANES 8u
#endif

layout(set = 0, binding = 2, std430) buffer TileBins { uint w[]; } g_tile_bins[];

// One entry: the sort key (tile index << depth bits | quantised reach), the
// splat's slot among the binned splats (glsl/include/single_pass_tiles.glsl)
// and the tile's 4×2-pixel blocks its bounding box touches (bit per block).
struct TileEntry {
    uint key;
    uint slot;
    uint blocks;
};
layout(set = 0, binding = 2, std430) buffer TileEntries { TileEntry e[]; } g_tile_entries[];

#endif
