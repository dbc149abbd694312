// The splat loop of three-pass EWA splatting in compute (dissertation
// §10.2.2–10.2.3, Table 10.1 passes 1 and 2; src/points/render/compute.rs):
// one dispatch for all the view's draws: invocation i finds its draw in the
// draw table (the first splat of each draw, ascending; a binary search),
// gets the perspective-accurate EWA set-up of glsl/include/splat_setup.glsl
// (the same kernels as every other mode) and visits the pixel centres of the
// splat's bounding box with `splat_pixel`, which the including shader
// defines; `splat_record` is then the splat's instance record.
// Splats whose box exceeds LARGE_SPLAT_PIXELS pixels are left to the whole
// workgroup after the small ones (64 invocations share their pixels), so one
// invocation does not walk thousands of pixels alone. Draws larger than the
// dispatch stride over their splats (grid-stride, workgroup-uniform).
#ifndef ALPENGLOW_SPLAT_COMPUTE_GLSL
#define ALPENGLOW_SPLAT_COMPUTE_GLSL

#define SPLAT_COMPUTE
#include "splat_compute_state.glsl"
#include "splat_setup.glsl"
#include "splat_draw_table.glsl"

#define WORKGROUP_SIZE 64u
#define LARGE_SPLAT_PIXELS 256u

layout(local_size_x = 64) in;

shared uint s_large[WORKGROUP_SIZE];
shared uint s_large_count;

// The pixel's index in the per-pixel buffers.
uint splat_pixel_index(uvec2 pixel) {
    return pixel.y * uint(g_point_frame[pc.handles.y].viewport.x) + pixel.x;
}

// The pixels whose centres the splat's bounding box holds: [lo, hi).
void splat_box(SplatSetup v, out uvec2 lo, out uvec2 hi) {
    vec2 size = g_point_frame[pc.handles.y].viewport.xy;
    vec2 first = clamp(ceil(v.centre.xy - v.half_extent - 0.5), vec2(0.0), size);
    vec2 last = clamp(floor(v.centre.xy + v.half_extent - 0.5), vec2(-1.0), size - 1.0);
    lo = uvec2(first);
    hi = uvec2(max(last + 1.0, first));
}

void splat_pixel(SplatSetup v, uvec2 pixel);

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
    uint count = pc.raster.w;
    for (uint base = gl_WorkGroupID.x * WORKGROUP_SIZE; base < count; base += gl_NumWorkGroups.x * WORKGROUP_SIZE) {
        if (gl_LocalInvocationIndex == 0u) {
            s_large_count = 0u;
        }
        barrier();
        uint index = base + gl_LocalInvocationIndex;
        SplatSetup v;
        uint setup = index < count ? frame_splat_setup(index, v) : SPLAT_SETUP_OUTSIDE_INTERVAL;
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
            frame_splat_setup(s_large[k], big);
            splat_pixels(big, gl_LocalInvocationIndex, WORKGROUP_SIZE);
        }
        barrier();
    }
}

#endif
