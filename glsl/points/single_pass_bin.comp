#version 460
// points.single_pass.count (dissertation §10.4): one invocation per splat
// of the draw (one dispatch per planned draw), its bounding box's tiles
// (glsl/include/single_pass_tiles.glsl): the EWA set-up of
// glsl/include/splat_setup.glsl, kept with the splat's pixels, reach and
// the exclusive sum of the entries of the workgroup's earlier invocations
// (within the subgroup, then the earlier subgroups') as a BinnedSplat in
// its slot (points.single_pass.scatter and .merge read it instead of
// setting the splat up again, and the scatter needs no barrier); the least
// and greatest reach kept (reduced per workgroup), the workgroup's entries
// (the sum of its splats' tiles) written to its word of the group buffer;
// the splats passing the interval test and drawn are counted as in every
// mode.
#extension GL_KHR_shader_subgroup_arithmetic : require
#define SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS_BIN
#include "../include/single_pass_tiles.glsl"

layout(local_size_x = 64) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   mode.w = the draw's instance record,
//   single = (bins, -, -, splats of the draw),
//   bin = (group buffer: one word per workgroup of the frame's draws, the
//          draw's first workgroup in it, binned splats, -).

// Each invocation's entries, and each subgroup's.
shared uint s_entries[BIN_WORKGROUP_SIZE];
shared uint s_subgroup_entries[BIN_WORKGROUP_SIZE];
// Each invocation's ~(reach bits) and reach bits (0: not binned, a no-op
// for the atomicMax below), reduced once per workgroup: two atomics a
// workgroup on the frame's reach range, not two a splat.
shared uint s_least_complement[BIN_WORKGROUP_SIZE];
shared uint s_greatest[BIN_WORKGROUP_SIZE];

// The binned splat of set-up `v` (pixels [first, last], reach's bits `reach`).
BinnedSplat binned_splat(SplatSetup v, uvec2 first, uvec2 last, uint reach) {
    float zf = g_point_frame[pc.handles.y].depth.z * v.centre.z;
    vec4 clip = v.clip;
    vec3 clip0 = cos(clip.x) * v.tu.xyz + sin(clip.x) * v.tv.xyz;
    vec3 clip1 = cos(clip.z) * v.tu.xyz + sin(clip.z) * v.tv.xyz;
    return BinnedSplat(v.conic, vec4(v.centre.xy, zf, dot(v.normal.xyz, v.position.xyz)),
                       vec4(v.normal.xyz, uintBitsToFloat(pc.mode.w)), vec4(v.position.xyz, clip.y),
                       vec4(clip0, clip.w), vec4(clip1, 0.0), vec4(v.color.rgb, 0.0),
                       uvec4(first.x | first.y << 16, last.x | last.y << 16, reach, 0u));
}

// The set-up kept, the counts.
void count(uint group, uint index, uint slot) {
    uint bins = pc.single.x;
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    SplatSetup v;
    uvec2 first = uvec2(0u), last = uvec2(0u);
    bool binned = false;
    if (index < pc.single.w) {
        uint setup = splat_setup(index, v);
        if (pc.handles.z != NO_HANDLE && setup != SPLAT_SETUP_OUTSIDE_INTERVAL) {
            atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
            if (setup == SPLAT_SETUP_READY) {
                atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
            }
        }
        binned = setup == SPLAT_SETUP_READY && splat_pixels(v, first, last);
    }
    float zf = g_point_frame[pc.handles.y].depth.z * v.centre.z;
    uint reach = binned ? floatBitsToUint(splat_reach(v, first, last, zf)) : 0u;
    BinnedSplat kept = binned_splat(v, first, last, reach);
    kept.box.x = binned ? kept.box.x : NOT_BINNED;
    s_least_complement[gl_LocalInvocationIndex] = binned ? ~reach : 0u;
    s_greatest[gl_LocalInvocationIndex] = reach;
    uvec2 lo = first / TILE_SIZE, hi = last / TILE_SIZE + 1u;
    uvec2 box = binned ? hi - lo : uvec2(0u);
    uint entries = box.x * box.y;
    s_entries[gl_LocalInvocationIndex] = entries;
    uint before = subgroupExclusiveAdd(entries);
    uint subgroup_entries = subgroupAdd(entries);
    if (subgroupElect()) {
        s_subgroup_entries[gl_SubgroupID] = subgroup_entries;
    }
    barrier();
    for (uint i = 0u; i < gl_SubgroupID; ++i) {
        before += s_subgroup_entries[i];
    }
    kept.box.w = before;
    // Outside any divergent branch (a CPU driver stores every invocation's
    // words unmasked); the workgroups of the draw's last row past its
    // splats (uniform) would write into the next draw's slots.
    if (group * BIN_WORKGROUP_SIZE < pc.single.w) {
        g_binned_splats[pc.bin.z].s[slot] = kept;
    }
    if (gl_LocalInvocationIndex == 0u && group * BIN_WORKGROUP_SIZE < pc.single.w) {
        uint sum = 0u, least_complement = 0u, greatest = 0u;
        for (uint i = 0u; i < BIN_WORKGROUP_SIZE; ++i) {
            sum += s_entries[i];
            least_complement = max(least_complement, s_least_complement[i]);
            greatest = max(greatest, s_greatest[i]);
        }
        g_tile_bins[pc.bin.x].w[pc.bin.y + group] = sum;
        if (least_complement != 0u || greatest != 0u) {
            atomicMax(g_tile_bins[bins].w[tiles + STATE_LEAST_COMPLEMENT], least_complement);
            atomicMax(g_tile_bins[bins].w[tiles + STATE_GREATEST], greatest);
        }
    }
}

void main() {
    // Dispatches wider than the 65535-workgroup limit use rows of workgroups.
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint index = group * BIN_WORKGROUP_SIZE + gl_LocalInvocationIndex;
    uint slot = (pc.bin.y + group) * BIN_WORKGROUP_SIZE + gl_LocalInvocationIndex;
    count(group, index, slot);
}
