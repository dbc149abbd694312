// The sort of single-pass splatting's tile entries (dissertation §10.4;
// glsl/include/single_pass_tiles.glsl): a stable LSD radix sort of the
// entries' 32-bit keys (tile index high, quantised reach low), RADIX_BITS a
// pass, from the lowest digit up, each pass three dispatches with no CPU in
// between (src/points/render/single_pass/radix.rs):
//   count   (single_pass_radix_count.comp): per block of RADIX_BLOCK
//           consecutive entries, how many hold each digit;
//   scan    (single_pass_radix_scan.comp): one workgroup turns the counts,
//           digit-major (every block's digit 0, then digit 1, …), into each
//           (digit, block)'s first position in the output;
//   scatter (single_pass_radix_scatter.comp): each block's entries to those
//           positions, in their order within the block.
// Stable at every pass, so entries of equal keys keep the binning's order
// and the sorted entries are the same on every run. No atomics decide a
// position, and no barrier but a few per block.
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

#define RADIX_BITS 8u
#define RADIX_DIGITS 256u
// Entries of a block: RADIX_SCATTER_INVOCATIONS × RADIX_ITEMS.
#define RADIX_BLOCK 2048u
#define RADIX_SCATTER_INVOCATIONS 32u
#define RADIX_ITEMS 64u

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
