// The interval test of sequential point trees (dissertation §10.1.6–10.1.7;
// ALGORITHMS.md §7), isotropic or view-dependent (§10.1.4, §10.1.7: the
// split error e_p·sin α + e_t·cos α instead of e_g). CPU reference and
// derivation: src/points/build/spt_view.rs. Shared by the points passes
// (glsl/include/splat_setup.glsl) and the shadow casters
// (glsl/include/shadow_points.glsl); include it after `g_splats`.
//
// A splat record's radius_color.z holds the packed coefficients a = e_p/e_g,
// b = e_t/e_g (bits 0–14, 15–29; bit 31: isotropic node, keeps its stored
// interval), radius_color.w the parent's index in the splat buffer.
#ifndef ALPENGLOW_SPT_INTERVAL_GLSL
#define ALPENGLOW_SPT_INTERVAL_GLSL

#define SPT_ERROR_ISOTROPIC 0u
#define SPT_ERROR_VIEW_DEPENDENT 1u

#define SPT_ISOTROPIC_BIT 0x80000000u
#define SPT_ROOT_R_MAX 3.4028235e38

// ρ = a·sin α + b·cos α, α = ∠(v, n) (n unit); 1 for isotropic nodes.
float spt_view_ratio(uint bits, vec3 n, vec3 v) {
    if ((bits & SPT_ISOTROPIC_BIT) != 0u) {
        return 1.0;
    }
    float a = float(bits & 0x7fffu) / 32767.0;
    float b = float((bits >> 15) & 0x7fffu) / 32767.0;
    float c = min(abs(dot(n, v)) / length(v), 1.0);
    float s = sqrt(max(1.0 - c * c, 0.0));
    return a * s + b * c;
}

// Whether splat `index` of splat buffer `splats` is drawn at eye distance r
// (object units): r_min ≤ r < r_max, or with `mode` view-dependent
// r_min·ρ ≤ r < r_min(parent)·ρ(parent) + |p − p_parent|. `to_space` maps
// object coordinates to a space with the eye at `eye` (a rigid motion times
// a uniform scale; ρ depends only on directions).
bool spt_interval(uint splats, uint index, float r, uint mode, mat4 to_space, vec3 eye) {
    vec4 position_rmin = g_splats[splats].s[index].position_rmin;
    vec4 normal_rmax = g_splats[splats].s[index].normal_rmax;
    if (mode != SPT_ERROR_VIEW_DEPENDENT) {
        return position_rmin.w <= r && r < normal_rmax.w;
    }
    uint bits = floatBitsToUint(g_splats[splats].s[index].radius_color.z);
    if ((bits & SPT_ISOTROPIC_BIT) != 0u || normal_rmax.w >= SPT_ROOT_R_MAX) {
        return position_rmin.w <= r && r < normal_rmax.w;
    }
    mat3 m = mat3(to_space);
    vec3 v = (to_space * vec4(position_rmin.xyz, 1.0)).xyz - eye;
    float r_min = position_rmin.w * spt_view_ratio(bits, normalize(m * normal_rmax.xyz), v);
    if (!(r_min <= r)) {
        return false;
    }
    uint parent = floatBitsToUint(g_splats[splats].s[index].radius_color.w);
    vec4 parent_position = g_splats[splats].s[parent].position_rmin;
    vec3 parent_normal = g_splats[splats].s[parent].normal_rmax.xyz;
    uint parent_bits = floatBitsToUint(g_splats[splats].s[parent].radius_color.z);
    vec3 vp = (to_space * vec4(parent_position.xyz, 1.0)).xyz - eye;
    float parent_r_min = parent_position.w * spt_view_ratio(parent_bits, normalize(m * parent_normal), vp);
    return r < parent_r_min + length(position_rmin.xyz - parent_position.xyz);
}

#endif
