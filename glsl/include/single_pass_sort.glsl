// Sorting a tile's list of single-pass splatting (dissertation §10.4;
// glsl/include/single_pass_tiles.glsl) by (depth key, record, index), a
// total order, so the sorted list is the same however the scatter pass
// ordered it. A bitonic sort by the tile's whole workgroup: in shared memory
// for lists of up to SORT_CAPACITY entries, in the entry buffer itself for
// longer ones (the tile's range belongs to this workgroup alone).
//
// The sort is the variant whose comparators all point the same way: per
// block size k = 2, 4, …, N (N the list's length rounded up to a power of
// two) a flip step pairs i with the mirrored i ^ (k − 1), then half-cleaner
// steps j = k/4, …, 1 pair i with i + j; the smaller entry goes to the lower
// index. Positions ≥ n count as +∞ and are never touched, so a list of any
// length n sorts without padding.
#ifndef ALPENGLOW_SINGLE_PASS_SORT_GLSL
#define ALPENGLOW_SINGLE_PASS_SORT_GLSL

#include "single_pass_tiles.glsl"

// 896 entries (10.5 KiB) and merge pass's batch of 32 set-ups (4.9 KiB)
// stay within the 16 KiB of shared memory every device offers.
#define SORT_CAPACITY 896u
#define SORT_INVOCATIONS 256u

shared uint s_key[SORT_CAPACITY];
shared uint s_record[SORT_CAPACITY];
shared uint s_index[SORT_CAPACITY];

bool entry_less(TileEntry a, TileEntry b) {
    if (a.key != b.key) {
        return a.key < b.key;
    }
    if (a.record != b.record) {
        return a.record < b.record;
    }
    return a.index < b.index;
}

// The sorted list's entry `i`: in shared memory when `shared_list`, else at
// `base` + i of the entry buffer.
TileEntry sorted_entry(bool shared_list, uint base, uint i) {
    if (shared_list) {
        return TileEntry(s_key[i], s_record[i], s_index[i]);
    }
    return g_tile_entries[pc.single.y].e[base + i];
}

void store_entry(bool shared_list, uint base, uint i, TileEntry e) {
    if (shared_list) {
        s_key[i] = e.key;
        s_record[i] = e.record;
        s_index[i] = e.index;
    } else {
        g_tile_entries[pc.single.y].e[base + i] = e;
    }
}

// Pair `t` of a step: block size `k`, distance `j` (0: the flip step).
uvec2 bitonic_pair(uint k, uint j, uint t) {
    if (j == 0u) {
        uint half_k = k / 2u;
        uint start = (t / half_k) * k;
        uint r = t % half_k;
        return uvec2(start + r, start + k - 1u - r);
    }
    uint i = (t / j) * 2u * j + t % j;
    return uvec2(i, i + j);
}

// The compare-exchange of positions pair.x < pair.y: the smaller entry to
// pair.x; positions ≥ n are +∞ and stay.
void compare_exchange(bool shared_list, uint base, uint n, uvec2 pair) {
    if (pair.y < n) {
        TileEntry a = sorted_entry(shared_list, base, pair.x);
        TileEntry b = sorted_entry(shared_list, base, pair.y);
        if (entry_less(b, a)) {
            store_entry(shared_list, base, pair.x, b);
            store_entry(shared_list, base, pair.y, a);
        }
    }
}

// One step of the sort over `n` entries (`padded`: n rounded up to a power
// of two) by the whole workgroup: block size `k`, distance `j` (0: the
// flip step); then a barrier.
void bitonic_step(bool shared_list, uint base, uvec2 n_padded, uvec2 kj, uint invocation) {
    for (uint t = invocation; t < n_padded.y / 2u; t += SORT_INVOCATIONS) {
        compare_exchange(shared_list, base, n_padded.x, bitonic_pair(kj.x, kj.y, t));
    }
    memoryBarrierShared();
    memoryBarrierBuffer();
    barrier();
}

// The steps of block size `k` from distance `j` down to 1 (`flip`: the flip
// step first) within each `block`-entry run of the list that this
// invocation owns (runs `invocation`, `invocation` + SORT_INVOCATIONS, …):
// distances below `block` never leave a run, so no barrier is needed
// between them; one follows.
void block_steps(bool shared_list, uint base, uvec2 n_padded, uvec3 kj_flip, uint block, uint invocation) {
    uint k = kj_flip.x;
    for (uint run = invocation; run < n_padded.y / block; run += SORT_INVOCATIONS) {
        uint first = run * block / 2u;
        if (kj_flip.z != 0u) {
            for (uint t = first; t < first + block / 2u; ++t) {
                compare_exchange(shared_list, base, n_padded.x, bitonic_pair(k, 0u, t));
            }
        }
        for (uint j = kj_flip.y; j > 0u; j >>= 1u) {
            for (uint t = first; t < first + block / 2u; ++t) {
                compare_exchange(shared_list, base, n_padded.x, bitonic_pair(k, j, t));
            }
        }
    }
    memoryBarrierShared();
    memoryBarrierBuffer();
    barrier();
}

// Sorts the tile's `n` entries at `base` of the entry buffer; a list of at
// most SORT_CAPACITY entries is loaded into shared memory first and stays
// there (read it with sorted_entry). Called by the whole workgroup. Each
// invocation first sorts runs of `block` entries alone, and every block
// size's steps of distances below `block` run within those runs: a barrier
// per step only for the longer distances.
void sort_tile_list(uint base, uint n, uint invocation) {
    bool shared_list = n <= SORT_CAPACITY;
    if (shared_list) {
        for (uint i = invocation; i < n; i += SORT_INVOCATIONS) {
            store_entry(true, base, i, g_tile_entries[pc.single.y].e[base + i]);
        }
    }
    memoryBarrierShared();
    barrier();
    uint padded = 2u;
    while (padded < n) {
        padded <<= 1u;
    }
    uvec2 n_padded = uvec2(n, padded);
    // Runs of at most 32 entries, at least 64 of them where the list is long enough.
    uint block = clamp(padded / 64u, 2u, 32u);
    for (uint k = 2u; k <= block; k <<= 1u) {
        block_steps(shared_list, base, n_padded, uvec3(k, k / 4u, 1u), block, invocation);
    }
    for (uint k = 2u * block; k <= padded; k <<= 1u) {
        bitonic_step(shared_list, base, n_padded, uvec2(k, 0u), invocation);
        for (uint j = k / 4u; j >= block; j >>= 1u) {
            bitonic_step(shared_list, base, n_padded, uvec2(k, j), invocation);
        }
        block_steps(shared_list, base, n_padded, uvec3(k, block / 2u, 0u), block, invocation);
    }
}

#endif
