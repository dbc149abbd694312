// Ray casting of the height field as bilinear patches (§9.2 references by
// Monte Carlo ray tracing; src/lighting/reference/trace.rs is the CPU twin):
// a max-mip quadtree walk (Tevs et al. 2008) over the cells, skipping every
// node the ray passes entirely above, and an exact crossing test per cell
// (along a ray a bilinear patch is a quadratic in t). The buffer layout is
// written by src/lighting/reference/pyramid.rs.
#ifndef ALPENGLOW_HEIGHTFIELD_TRACE_GLSL
#define ALPENGLOW_HEIGHTFIELD_TRACE_GLSL

#include "heap.glsl"

#define HF_MAX_LEVELS 16

// header[0]: columns, rows, levels; header[1]: f32 bits of min and max
// height; header[2 + L]: level L's offset into v, width, height (nodes).
// v: the heights (row-major), then the max-mip levels.
layout(set = 0, binding = 2, std430) readonly buffer HeightfieldData {
    uvec4 header[HF_MAX_LEVELS + 2];
    float v[];
} g_heightfields[];

struct Heightfield {
    uint buf;
    ivec2 dims;     // samples
    vec2 spacing;   // metres between samples
    float zmin;
    float zmax;
    int levels;
};

Heightfield hf_load(uint buf, vec2 spacing) {
    uvec4 h0 = g_heightfields[buf].header[0];
    uvec4 h1 = g_heightfields[buf].header[1];
    return Heightfield(buf, ivec2(h0.xy), spacing, uintBitsToFloat(h1.x), uintBitsToFloat(h1.y), int(h0.z));
}

float hf_height(Heightfield f, ivec2 q) {
    q = clamp(q, ivec2(0), f.dims - 1);
    return g_heightfields[f.buf].v[q.y * f.dims.x + q.x];
}

// Unit normal of sample q from central differences (one-sided at the border).
vec3 hf_vertex_normal(Heightfield f, ivec2 q) {
    ivec2 lo = max(q - 1, ivec2(0));
    ivec2 hi = min(q + 1, f.dims - 1);
    float gx = (hf_height(f, ivec2(hi.x, q.y)) - hf_height(f, ivec2(lo.x, q.y))) / (float(hi.x - lo.x) * f.spacing.x);
    float gy = (hf_height(f, ivec2(q.x, hi.y)) - hf_height(f, ivec2(q.x, lo.y))) / (float(hi.y - lo.y) * f.spacing.y);
    return normalize(vec3(-gx, -gy, 1.0));
}

// Shading normal at sample coordinates g: bilinear blend of the cell's corner normals.
vec3 hf_normal(Heightfield f, vec2 g) {
    vec2 cell = clamp(floor(g), vec2(0.0), vec2(f.dims - 2));
    vec2 uv = clamp(g - cell, 0.0, 1.0);
    ivec2 q = ivec2(cell);
    vec3 n = hf_vertex_normal(f, q) * ((1.0 - uv.x) * (1.0 - uv.y)) + hf_vertex_normal(f, q + ivec2(1, 0)) * (uv.x * (1.0 - uv.y))
           + hf_vertex_normal(f, q + ivec2(0, 1)) * ((1.0 - uv.x) * uv.y) + hf_vertex_normal(f, q + ivec2(1, 1)) * (uv.x * uv.y);
    return normalize(n);
}

float hf_quadratic(vec3 q, float s) {
    return (q.x * s + q.y) * s + q.z;
}

// The crossing test of cell `cell` for the ray piece t in [ta, tb]; `p` the
// ray at ta in sample coordinates (xy) and metres (z), `d` its rate per unit
// t. `above`: whether the ray was last on or above the surface.
bool hf_cell_crossing(Heightfield f, ivec2 cell, vec3 p, vec3 d, float ta, float tb, inout bool above, out float t_hit) {
    float h00 = hf_height(f, cell), h10 = hf_height(f, cell + ivec2(1, 0));
    float h01 = hf_height(f, cell + ivec2(0, 1)), h11 = hf_height(f, cell + ivec2(1, 1));
    float b = h10 - h00, c = h01 - h00, e = h00 - h10 - h01 + h11;
    vec2 uv = p.xy - vec2(cell);
    vec3 q = vec3(-e * d.x * d.y, d.z - (b * d.x + c * d.y + e * (uv.x * d.y + uv.y * d.x)),
                  p.z - (h00 + b * uv.x + c * uv.y + e * uv.x * uv.y));
    float len = tb - ta;
    float f0 = q.z;
    t_hit = ta;
    if (above && f0 < 0.0) {
        return true;
    }
    above = f0 >= 0.0;
    float vertex = q.x != 0.0 ? -q.y / (2.0 * q.x) : -1.0;
    float ends[2] = float[2](vertex > 0.0 && vertex < len ? vertex : -1.0, len);
    float prev = 0.0;
    for (int k = 0; k < 2; ++k) {
        float end = ends[k];
        if (end < 0.0) {
            continue;
        }
        float fe = hf_quadratic(q, end);
        if (above && fe < 0.0) {
            float lo = prev, hi = end;
            for (int i = 0; i < 10; ++i) {
                float mid = 0.5 * (lo + hi);
                if (hf_quadratic(q, mid) < 0.0) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            float fl = hf_quadratic(q, lo), fh = hf_quadratic(q, hi);
            t_hit = ta + ((fl >= 0.0 && fh < 0.0) ? lo + (hi - lo) * (fl / (fl - fh)) : 0.5 * (lo + hi));
            return true;
        }
        above = fe >= 0.0;
        prev = end;
    }
    return false;
}

// Largest height of max-mip node `node` of level `level`.
float hf_node_max(Heightfield f, int level, ivec2 node, out ivec2 size) {
    uvec4 l = g_heightfields[f.buf].header[2 + level];
    size = ivec2(l.yz);
    node = clamp(node, ivec2(0), size - 1);
    return g_heightfields[f.buf].v[l.x + uint(node.y) * l.y + uint(node.x)];
}

// First crossing of the ray o + t d (world, t ≥ 0) from on-or-above to below
// the surface inside the rectangle; false when it escapes (leaves the
// rectangle or rises above the highest sample, or after 4·(columns + rows)
// + 64 steps). g_hit: sample coordinates of the hit.
bool hf_trace(Heightfield f, vec3 o, vec3 d, out float t_hit, out vec2 g_hit) {
    t_hit = 0.0;
    g_hit = vec2(0.0);
    vec3 O = vec3(o.xy / f.spacing, o.z);
    vec3 D = vec3(d.xy / f.spacing, d.z);
    float margin = 1e-6 * (1.0 + max(abs(f.zmin), abs(f.zmax)));
    vec3 lo = vec3(0.0, 0.0, f.zmin - margin);
    vec3 hi = vec3(vec2(f.dims - 1), f.zmax + margin);
    float t0 = 0.0, t1 = POSITIVE_INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (D[a] != 0.0) {
            float ta = (lo[a] - O[a]) / D[a], tb = (hi[a] - O[a]) / D[a];
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        } else if (O[a] < lo[a] || O[a] > hi[a]) {
            return false;
        }
    }
    if (!(t0 < t1) || isinf(t1)) {
        return false;
    }
    int top = f.levels - 1;
    int level = 0;
    float t = t0;
    bool above = true;
    int steps = 4 * (f.dims.x + f.dims.y) + 64;
    for (int i = 0; i < steps && t < t1; ++i) {
        float size = float(1 << level);
        vec2 q = O.xy + D.xy * t + sign(D.xy) * 1e-4;
        ivec2 nodes;
        float node_max = hf_node_max(f, level, ivec2(floor(q / size)), nodes);
        ivec2 node = clamp(ivec2(floor(q / size)), ivec2(0), nodes - 1);
        vec2 box_lo = vec2(node) * size;
        vec2 box_hi = min(box_lo + size, hi.xy);
        float te = t1;
        for (int a = 0; a < 2; ++a) {
            if (D[a] > 0.0) {
                te = min(te, (box_hi[a] - O[a]) / D[a]);
            } else if (D[a] < 0.0) {
                te = min(te, (box_lo[a] - O[a]) / D[a]);
            }
        }
        te = max(te, t);
        float z_low = min(O.z + D.z * t, O.z + D.z * te);
        if (z_low > node_max + margin) {
            t = te;
            above = true;
            level = min(level + 1, top);
            continue;
        }
        if (level > 0) {
            --level;
            continue;
        }
        vec3 p = O + D * t;
        if (hf_cell_crossing(f, node, p, D, t, te, above, t_hit)) {
            g_hit = O.xy + D.xy * t_hit;
            return true;
        }
        t = te;
        level = min(1, top);
    }
    return false;
}

#endif
