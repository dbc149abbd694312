#version 460
// synthesis.distance (§7.3, ALGORITHMS.md §2): s(c) for every (query,
// candidate) of the batch, and per query the smallest s (atomicMin on the
// order-preserving key). One workgroup per query (y) and block of 256
// candidates (x, 4 per invocation; blocks beyond the dispatch loop). The
// query's taps pass through shared memory 256 at a time; each invocation
// adds its terms tap by tap in the CPU twin's order, every operation
// `precise` (no contraction), so s is bit for bit `weighted_mismatch`.
#extension GL_EXT_control_flow_attributes : require
#include "../include/synthesis_search.glsl"

#define GROUP 64u
#define PER_INVOCATION 4u
#define BLOCK (GROUP * PER_INVOCATION)
#define TAP_CHUNK 256u

layout(local_size_x = 64) in;

shared vec4 s_taps[TAP_CHUNK];
// Per tap of the chunk: its texel offset from the window centre.
shared int s_offsets[TAP_CHUNK];
shared uint s_best;

void main() {
    uint q = gl_WorkGroupID.y;
    uint lane = gl_LocalInvocationID.x;
    uint candidates = pc.sizes.y;
    uint n = pc.sizes.z;
    int r = int(n / 2u);
    int width = int(pc.sizes.w);
    uint taps = n * n;
    float lambda = uintBitsToFloat(pc.rule.y);
    uint blocks = (candidates + BLOCK - 1u) / BLOCK;
    for (uint block = gl_WorkGroupID.x; block < blocks; block += gl_NumWorkGroups.x) {
        if (lane == 0u) {
            s_best = SYNTHESIS_KEY_INFINITY;
        }
        int centre[PER_INVOCATION];
        float sum[PER_INVOCATION];
        [[unroll]] for (uint k = 0u; k < PER_INVOCATION; ++k) {
            uint c = block * BLOCK + k * GROUP + lane;
            centre[k] = c < candidates ? int(g_synthesis_uints[pc.inputs.y].u[c]) : -1;
            sum[k] = 0.0;
        }
        for (uint first = 0u; first < taps; first += TAP_CHUNK) {
            uint count = min(TAP_CHUNK, taps - first);
            barrier();
            for (uint t = lane; t < count; t += GROUP) {
                s_taps[t] = g_synthesis_taps[pc.inputs.z].t[q * taps + first + t];
                s_offsets[t] = (int((first + t) / n) - r) * width + int((first + t) % n) - r;
            }
            barrier();
            for (uint i = 0u; i < count; ++i) {
                vec4 tap = s_taps[i];
                if (tap.w == 0.0) {
                    continue;
                }
                int offset = s_offsets[i];
                [[unroll]] for (uint k = 0u; k < PER_INVOCATION; ++k) {
                    if (centre[k] < 0) {
                        continue;
                    }
                    vec3 texel = g_synthesis_texels[pc.inputs.x].t[centre[k] + offset].xyz;
                    precise float dh = tap.x - texel.x;
                    precise float dhx = tap.y - texel.y;
                    precise float dhy = tap.z - texel.z;
                    precise float slopes = dhx * dhx + dhy * dhy;
                    // lambda = +inf: slopes only (Fig. 7.4's "no height criterion").
                    precise float mismatch = isinf(lambda) ? slopes : dh * dh + lambda * slopes;
                    precise float term = tap.w * mismatch;
                    precise float next = sum[k] + term;
                    sum[k] = next;
                }
            }
        }
        uint best = SYNTHESIS_KEY_INFINITY;
        [[unroll]] for (uint k = 0u; k < PER_INVOCATION; ++k) {
            uint c = block * BLOCK + k * GROUP + lane;
            if (centre[k] >= 0) {
                g_synthesis_sums[pc.outputs.x].s[q * candidates + c] = sum[k];
                best = min(best, float_key(sum[k]));
            }
        }
        atomicMin(s_best, best);
        barrier();
        if (lane == 0u) {
            atomicMin(g_synthesis_results[pc.outputs.y].r[q].x, s_best);
        }
    }
}
