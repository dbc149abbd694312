// Aerial perspective (§6.3 eq. 6.16, 6.17; §9.1; ALGORITHMS.md §6). GPU twin
// of src/lighting/aerial.rs, whose documentation derives it:
//   L = L0 e^(−τ) + (1 − e^(−τ)) L_∞,   τ = (β_R ρ_R + β_M ρ_M) s,
// β at the ground (rayleigh.rgb, mie.rgb), ρ the mean density along the ray,
// where single scattering of the sun alone would give L_∞ = E_sun β(θ)/β;
// instead L_∞ is the sky's radiance (sky_radiance, by model) in the view
// direction with its elevation clamped into the horizon band, so a distant
// mountain fades into exactly the sky behind it. Single scattering (Rayleigh
// and Henyey–Greenstein with g = rayleigh.w) only where the sky gives nothing.
#ifndef ALPENGLOW_AERIAL_PERSPECTIVE_GLSL
#define ALPENGLOW_AERIAL_PERSPECTIVE_GLSL

#include "sky.glsl"

const float AERIAL_HORIZON_BAND_SIN = 0.17364818;  // sin 10°
const float AERIAL_PI = 3.14159265358979;

// `d` with its elevation clamped into the horizon band, azimuth kept
// (straight up or down: north). Twin of aerial::horizon_band_direction.
vec3 aerial_sky_direction(vec3 d) {
    float len = length(d);
    d = len > 0.0 ? d / len : vec3(0.0, 1.0, 0.0);
    float z = clamp(d.z, PREETHAM_COS_THETA_MIN, AERIAL_HORIZON_BAND_SIN);
    float h = length(d.xy);
    vec2 xy = h > 1e-6 ? d.xy / h : vec2(0.0, 1.0);
    return vec3(xy * sqrt(1.0 - z * z), z);
}

// Single-scattering radiance of an infinitely long ray towards `d`:
// E_sun (β_R P_R + β_M P_HG) / β.
vec3 aerial_single_scattering(uint lighting, vec3 d) {
    vec4 rayleigh = g_lighting[lighting].f.rayleigh;
    vec3 mie = g_lighting[lighting].f.mie.rgb;
    float mu = clamp(dot(d, g_lighting[lighting].f.sun.xyz), -1.0, 1.0);
    float g = rayleigh.w;
    float p_r = 3.0 / (16.0 * AERIAL_PI) * (1.0 + mu * mu);
    float p_m = (1.0 - g * g) / (4.0 * AERIAL_PI * pow(1.0 + g * g - 2.0 * g * mu, 1.5));
    vec3 beta = max(rayleigh.rgb + mie, vec3(1e-12));
    return g_lighting[lighting].f.sun_irradiance.rgb * (rayleigh.rgb * p_r + mie * p_m) / beta;
}

// Mean density along a straight ray between heights z0 and z1 above the
// ground, relative to the ground's, for scale height h (m): ∫e^(−z/h) dz/Δz.
// Twin of aerial::mean_density.
float aerial_mean_density(float z0, float z1, float h) {
    if (!(h > 0.0)) {
        return 1.0;
    }
    float a = max(z0, 0.0) / h;
    float b = max(z1, 0.0) / h;
    float d = b - a;
    if (abs(d) < 1e-3) {
        return exp(-0.5 * (a + b));
    }
    return (exp(-a) - exp(-b)) / d;
}

// `color` seen from `eye` at world point `point`: the ground coefficients
// scaled by the mean density of Rayleigh and Mie along the ray (scale
// heights LightingFrame.planet.zw above the ground LightingFrame.mie.w).
vec3 aerial_perspective(uint lighting, vec3 color, vec3 eye, vec3 point) {
    vec3 v = point - eye;
    float s = length(v);
    if (!(s > 0.0)) {
        return color;
    }
    float ground = g_lighting[lighting].f.mie.w;
    vec4 planet = g_lighting[lighting].f.planet;
    float rho_r = aerial_mean_density(eye.z - ground, point.z - ground, planet.z);
    float rho_m = aerial_mean_density(eye.z - ground, point.z - ground, planet.w);
    vec3 tau = (g_lighting[lighting].f.rayleigh.rgb * rho_r + g_lighting[lighting].f.mie.rgb * rho_m) * s;
    vec3 t = exp(-tau);
    vec3 d = aerial_sky_direction(v / s);
    vec3 l_inf = sky_radiance(lighting, d);
    if (max(l_inf.r, max(l_inf.g, l_inf.b)) <= 0.0) {
        l_inf = aerial_single_scattering(lighting, d);
    }
    return color * t + (1.0 - t) * l_inf;
}

#endif
