// A simple analytic sky and constant-density haze, shared by the sky and the
// terrain shading. Placeholder for the Preetham sky and aerial perspective of
// §9 (ALGORITHMS.md §6), which a later issue implements.
#ifndef ALPENGLOW_ATMOSPHERE_GLSL
#define ALPENGLOW_ATMOSPHERE_GLSL

const vec3 SKY_ZENITH = vec3(0.16, 0.32, 0.75);
const vec3 SKY_HORIZON = vec3(0.62, 0.74, 0.90);
const vec3 SUN_RADIANCE = vec3(1.00, 0.95, 0.85) * 2.2;

// Sky radiance seen along the unit direction `dir` (+Z up) with the sun at `sun`.
vec3 sky_radiance(vec3 dir, vec3 sun) {
    float up = clamp(dir.z, -1.0, 1.0);
    float t = pow(clamp(1.0 - max(up, 0.0), 0.0, 1.0), 4.0);
    vec3 sky = mix(SKY_ZENITH, SKY_HORIZON, t);
    if (up < 0.0) {
        sky = mix(SKY_HORIZON, SKY_HORIZON * 0.55, clamp(-up * 4.0, 0.0, 1.0));
    }
    float cos_gamma = clamp(dot(dir, sun), -1.0, 1.0);
    float glow = pow(max(cos_gamma, 0.0), 64.0) * 0.6 + pow(max(cos_gamma, 0.0), 8.0) * 0.15;
    float disk = smoothstep(0.99985, 0.99995, cos_gamma) * 40.0;
    return sky + SUN_RADIANCE * (glow + disk) * step(0.0, up + 0.02);
}

// Haze over distance `dist` (metres) towards `dir`: exponential extinction and
// in-scattered horizon light.
vec3 apply_haze(vec3 color, float dist, vec3 dir, vec3 sun) {
    float extinction = exp(-dist * 1.2e-5);
    vec3 inscatter = sky_radiance(normalize(vec3(dir.xy, max(dir.z, 0.02))), sun) * 0.75;
    return color * extinction + inscatter * (1.0 - extinction);
}

#endif
