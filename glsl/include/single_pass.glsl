// points.single_pass (dissertation §10.4; ALGORITHMS.md §8): single-pass
// EWA splatting with a fuzzy depth test, in compute. One invocation per splat
// of the draw: the EWA set-up of glsl/include/splat_setup.glsl, then every
// pixel centre of the splat's bounding box gets the same kernel, clip lines
// and ray–plane depth as the three-pass mode, is tested against the depth
// buffer (terrain, hybrid triangles), and merged into the pixel's state with
// the text's operator (fragment (C_s, A_s, z_s), stored (C_d, A_d, z_d)):
//   z_s < z_d − z_f:        C_d = C_s, A_d = A_s, z_d = z_s    (nearer: replaces)
//   z_s < z_d + z_f:        C_d = (A_d·C_d + A_s·C_s)/(A_d + A_s), A_d += A_s
//                            (same surface: blends; z_d is kept, so it only decreases)
//   otherwise:              rejected (behind).
// The state keeps the sums A_d·C_d and A_d (and A·normal, A·view depth),
// which is the same operator; points.single_pass.resolve divides and shades.
// z is the distance along the view ray and z_f = ε·r_k, with r_k the
// incoming splat's radius (camera units) and ε the visibility offset in
// splat radii: the push-back of the three-pass visibility pass (§10.2.3),
// derived from the splat size, not tuned per scene.
//
// The per-pixel read-modify-write is a critical section:
// - SINGLE_PASS_INT64 (shaderInt64 + shaderBufferInt64Atomics): one 64-bit
//   word per pixel, z_d's bits << 32 | lock bit. A fragment with
//   z_s ≥ z_d + z_f is rejected lock-free from an atomic load (z_d only
//   decreases, so a stale z_d is conservative); acquiring is one
//   atomicCompSwap, writing z_d and releasing one atomicExchange.
// - otherwise (32-bit atomics only): a lock word and a z_d word per pixel
//   (the same 8 bytes: the lock is the 64-bit word's low half); the same
//   lock-free rejection from an atomic load of z_d, CAS on the lock word.
// The critical section sits inside the successful-CAS branch of the retry
// loop, the shape that cannot deadlock on SIMT/SIMD hardware (an invocation
// that owns the lock never waits for one of its subgroup that spins).
// The operator is not commutative: the invocation order decides merges at
// fuzzy boundaries, so results can differ slightly from run to run.
//
// Splats whose bounding box exceeds LARGE_SPLAT_PIXELS pixels are left to the
// whole workgroup after the small ones: 64 invocations share their pixels,
// so one invocation does not loop over thousands of pixels alone.
#ifndef ALPENGLOW_SINGLE_PASS_GLSL
#define ALPENGLOW_SINGLE_PASS_GLSL

#ifndef SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS
#endif
#include "single_pass_merge.glsl"

#ifdef SINGLE_PASS_INT64
layout(set = 0, binding = 2, std430) coherent buffer PixelWords64 { uint64_t w[]; } g_pixel_words64[];
#endif

#define WORKGROUP_SIZE 64u
#define LARGE_SPLAT_PIXELS 256u
// A safety bound on lock attempts per fragment (never reached unless a
// driver starves an invocation; the fragment is then dropped, not hung).
#define MAX_LOCK_ATTEMPTS 1000000u

layout(local_size_x = 64) in;

shared uint s_large[WORKGROUP_SIZE];
shared uint s_large_count;

#ifdef SINGLE_PASS_INT64
void merge(SplatFragment frag) {
    uint words = pc.single.x;
    uint p = frag.pixel;
    for (uint attempt = 0u; attempt < MAX_LOCK_ATTEMPTS; ++attempt) {
        uint64_t seen = atomicAdd(g_pixel_words64[words].w[p], uint64_t(0));
        float zd = uintBitsToFloat(uint(seen >> 32));
        if (!(frag.z < zd + frag.zf)) {
            return;  // behind the stored surface
        }
        if ((seen & uint64_t(1)) == uint64_t(0) &&
            atomicCompSwap(g_pixel_words64[words].w[p], seen, seen | uint64_t(1)) == seen) {
            memoryBarrierBuffer();
            float new_zd = merge_locked(frag, zd);
            memoryBarrierBuffer();
            atomicExchange(g_pixel_words64[words].w[p], uint64_t(floatBitsToUint(new_zd)) << 32);
            return;
        }
    }
}
#else
void merge(SplatFragment frag) {
    uint words = pc.single.x;
    uint lock = 2u * frag.pixel;
    uint depth = lock + 1u;
    for (uint attempt = 0u; attempt < MAX_LOCK_ATTEMPTS; ++attempt) {
        float seen = uintBitsToFloat(atomicAdd(g_pixel_words32[words].w[depth], 0u));
        if (!(frag.z < seen + frag.zf)) {
            return;  // behind the stored surface
        }
        if (atomicCompSwap(g_pixel_words32[words].w[lock], 0u, 1u) == 0u) {
            memoryBarrierBuffer();
            float zd = uintBitsToFloat(atomicAdd(g_pixel_words32[words].w[depth], 0u));
            if (frag.z < zd + frag.zf) {
                atomicExchange(g_pixel_words32[words].w[depth], floatBitsToUint(merge_locked(frag, zd)));
            }
            memoryBarrierBuffer();
            atomicExchange(g_pixel_words32[words].w[lock], 0u);
            return;
        }
    }
}
#endif

// Splat `v` at pixel `pixel`: kernel, clip lines, ray–plane depth, the depth
// buffer's test (≤, as the three-pass accumulation), then the merge.
void splat_pixel(SplatSetup v, uvec2 pixel) {
    SplatSample s;
    SplatFragment frag;
    if (splat_sample_at(vec2(pixel) + 0.5, v, s) && single_pass_fragment(v, s, pixel, frag)) {
        merge(frag);
    }
}

// The pixels whose centres the splat's bounding box holds: [lo, hi).
void splat_box(SplatSetup v, out uvec2 lo, out uvec2 hi) {
    vec2 size = g_point_frame[pc.handles.y].viewport.xy;
    vec2 first = clamp(ceil(v.centre.xy - v.half_extent - 0.5), vec2(0.0), size);
    vec2 last = clamp(floor(v.centre.xy + v.half_extent - 0.5), vec2(-1.0), size - 1.0);
    lo = uvec2(first);
    hi = uvec2(max(last + 1.0, first));
}

// Pixels `start`, `start` + `stride`, ... of the splat's box.
void splat_pixels(SplatSetup v, uint start, uint stride) {
    uvec2 lo, hi;
    splat_box(v, lo, hi);
    uint width = hi.x - lo.x;
    uint count = width * (hi.y - lo.y);
    for (uint k = start; k < count; k += stride) {
        splat_pixel(v, lo + uvec2(k % width, k / width));
    }
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        s_large_count = 0u;
    }
    barrier();
    // Dispatches wider than the 65535-workgroup limit use rows of workgroups.
    uint index = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * WORKGROUP_SIZE + gl_LocalInvocationIndex;
    SplatSetup v;
    uint setup = index < pc.single.w ? splat_setup(index, v) : SPLAT_SETUP_OUTSIDE_INTERVAL;
    if (pc.handles.z != NO_HANDLE && setup != SPLAT_SETUP_OUTSIDE_INTERVAL) {
        atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
        if (setup == SPLAT_SETUP_READY) {
            atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
        }
    }
    if (setup == SPLAT_SETUP_READY) {
        uvec2 lo, hi;
        splat_box(v, lo, hi);
        uvec2 size = hi - lo;
        if (size.x * size.y > LARGE_SPLAT_PIXELS) {
            s_large[atomicAdd(s_large_count, 1u)] = index;
        } else {
            splat_pixels(v, 0u, 1u);
        }
    }
    barrier();
    uint large = s_large_count;
    for (uint k = 0u; k < large; ++k) {
        SplatSetup big;
        splat_setup(s_large[k], big);
        splat_pixels(big, gl_LocalInvocationIndex, WORKGROUP_SIZE);
    }
}

#endif
