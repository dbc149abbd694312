// The Preetham/Perez sky (§6.3; ALGORITHMS.md §6): Preetham, Shirley and
// Smits 1999, "A practical analytic model for daylight", and the CIE clear
// (Perez coefficients of eq. 6.18) and overcast (perez_norm.w = 1: the
// luminance Y_z (1 + 2 cos θ) / 3 of eq. 6.19) skies. GPU twin of
// PreethamSky::radiance (src/lighting/preetham.rs), with the same clamps;
// the CPU writes the constants (perez, zenith, perez_norm, sun).
//   Y(θ,γ) = Y_z · F(θ,γ) / F(0,θ_s), likewise x and y, with the Perez
//   F(θ,γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos²γ);
// Y,x,y → CIE XYZ → linear sRGB (D65): luminance in cd/m².
// Clamps: cos θ ≥ PREETHAM_COS_THETA_MIN (e^(B/cos θ) blows up at the
// horizon), γ the true angle to the sun; below the horizon the horizon value
// darkens smoothly to PREETHAM_GROUND_FLOOR of it. A sun below the horizon is
// moved onto it at its azimuth for γ (the CPU did the same for θ_s, and
// faded Y_z to twilight).
#ifndef ALPENGLOW_SKY_PREETHAM_GLSL
#define ALPENGLOW_SKY_PREETHAM_GLSL

#include "lighting.glsl"

const float PREETHAM_COS_THETA_MIN = 0.01;
const float PREETHAM_GROUND_FLOOR = 0.3;
const float PREETHAM_GROUND_FADE = 0.2;

// The Perez function for Y, x, y at once.
vec3 preetham_perez(uint lighting, float cos_theta, float gamma) {
    vec3 a = g_lighting[lighting].f.perez[0].xyz;
    vec3 b = g_lighting[lighting].f.perez[1].xyz;
    vec3 c = g_lighting[lighting].f.perez[2].xyz;
    vec3 d = g_lighting[lighting].f.perez[3].xyz;
    vec3 e = g_lighting[lighting].f.perez[4].xyz;
    float cos_gamma = cos(gamma);
    return (1.0 + a * exp(b / cos_theta)) * (1.0 + c * exp(d * gamma) + e * cos_gamma * cos_gamma);
}

// CIE xyY → linear sRGB (IEC 61966-2-1, D65); may be negative out of gamut.
vec3 preetham_xyy_to_srgb(float luminance, float x, float y) {
    y = max(y, 1e-4);
    vec3 xyz = vec3(x / y * luminance, luminance, (1.0 - x - y) / y * luminance);
    return vec3(dot(vec3(3.2406, -1.5372, -0.4986), xyz),
                dot(vec3(-0.9689, 1.8758, 0.0415), xyz),
                dot(vec3(0.0557, -0.2040, 1.0570), xyz));
}

// Darkening of directions below the horizon (1 above it).
float preetham_ground_factor(float dir_z) {
    return 1.0 - (1.0 - PREETHAM_GROUND_FLOOR) * smoothstep(0.0, PREETHAM_GROUND_FADE, -dir_z);
}

// The sun the formulas use: below the horizon, moved onto it.
vec3 preetham_formula_sun(vec3 sun) {
    if (sun.z >= 0.0) {
        return sun;
    }
    float h = length(sun.xy);
    return h > 1e-6 ? vec3(sun.xy / h, 0.0) : vec3(0.0, 1.0, 0.0);
}

// Sky radiance along `dir` (+Z up), without the sun disc.
vec3 preetham_sky(uint lighting, vec3 dir) {
    float len = length(dir);
    dir = len > 0.0 ? dir / len : vec3(0.0, 0.0, 1.0);
    vec3 sun = preetham_formula_sun(g_lighting[lighting].f.sun.xyz);
    float cos_theta = max(dir.z, PREETHAM_COS_THETA_MIN);
    float gamma = acos(clamp(dot(dir, sun), -1.0, 1.0));
    vec3 yxy = g_lighting[lighting].f.zenith.xyz * preetham_perez(lighting, cos_theta, gamma) *
               g_lighting[lighting].f.perez_norm.xyz;
    if (g_lighting[lighting].f.perez_norm.w > 0.5) {
        // The CIE overcast sky (eq. 6.19), Moon and Spencer.
        yxy.x = g_lighting[lighting].f.zenith.x * (1.0 + 2.0 * cos_theta) / 3.0;
    }
    return max(preetham_xyy_to_srgb(yxy.x, yxy.y, yxy.z), vec3(0.0)) * preetham_ground_factor(dir.z);
}

#endif
