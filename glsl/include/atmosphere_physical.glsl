// The physical atmosphere (Hillaire 2020, "A Scalable and Production Ready
// Sky and Atmosphere Rendering Technique"; Bruneton 2017's Earth): Rayleigh,
// Mie and ozone; the lookup-table parameterisations shared by the passes
// that fill the tables (glsl/lighting/atmosphere_*.comp) and the shaders
// that sample them (sky_physical.glsl, aerial perspective, sky light).
// src/lighting/atmosphere/ is the CPU side and twin. The dissertation's
// sky is Preetham's (§6.3, §9.1); this model is beyond the text.
//
// Units: the LightingFrame and the push constants hold metres and 1/m;
// the marching works in kilometres (planet radii of 6360 km squared lose
// too much in f32 when in metres). The bottom of the atmosphere is the
// terrain's ground level (world altitude LightingFrame.mie.w); the camera
// altitude above it (m) is LightingFrame.atmosphere.w as float bits.
#ifndef ALPENGLOW_ATMOSPHERE_PHYSICAL_GLSL
#define ALPENGLOW_ATMOSPHERE_PHYSICAL_GLSL

#include "lighting.glsl"

const float ATMO_PI = 3.14159265358979;
// Lowest camera / sample altitude (km) and margin below the top (km).
const float ATMO_MIN_ALTITUDE = 0.01;

#ifdef ATMOSPHERE_LUT_PASS
// Push constants of the three table passes (src/lighting/atmosphere/passes.rs, AtmospherePush).
layout(push_constant) uniform AtmospherePush {
    uvec4 handles;  // x: LightingFrame (storage), y: output (storage rgba32f), z: transmittance (sampled), w: multiple scattering (sampled)
    uvec4 size;     // xy: output size (texels)
    vec4 ozone;     // rgb: ozone absorption at the peak (1/m); w: altitude of the peak (m)
    vec4 albedo;    // rgb: ground albedo; w: half-width of the ozone tent (m)
    vec4 sun;       // rgb: solar irradiance at the top of the atmosphere; w: Mie extinction / scattering
} pc;
#endif

// The atmosphere in kilometres.
struct Atmosphere {
    float bottom;              // km
    float top;                 // km
    float rayleigh_height;     // km
    float mie_height;          // km
    vec3 rayleigh_scattering;  // 1/km
    vec3 mie_scattering;       // 1/km
    vec3 mie_extinction;       // 1/km
    vec3 ozone_absorption;     // 1/km at the peak
    float ozone_center;        // km
    float ozone_half_width;    // km
    float mie_g;
};

// The atmosphere of LightingFrame `lighting`; ozone and the Mie absorption
// are not in the LightingFrame (`ozone`: rgb 1/m, w peak m; `mie_ratio`:
// extinction over scattering).
Atmosphere atmosphere_of(uint lighting, vec4 ozone, float ozone_half_width, float mie_ratio) {
    LightingFrame f = g_lighting[lighting].f;
    Atmosphere a;
    a.bottom = f.planet.x * 1e-3;
    a.top = max(f.planet.y * 1e-3, a.bottom + 1.0);
    a.rayleigh_height = max(f.planet.z * 1e-3, 1e-3);
    a.mie_height = max(f.planet.w * 1e-3, 1e-3);
    a.rayleigh_scattering = max(f.rayleigh.rgb, vec3(0.0)) * 1e3;
    a.mie_scattering = max(f.mie.rgb, vec3(0.0)) * 1e3;
    a.mie_extinction = a.mie_scattering * max(mie_ratio, 1.0);
    a.ozone_absorption = max(ozone.rgb, vec3(0.0)) * 1e3;
    a.ozone_center = ozone.w * 1e-3;
    a.ozone_half_width = max(ozone_half_width * 1e-3, 1e-3);
    a.mie_g = clamp(f.rayleigh.w, -0.999, 0.999);
    return a;
}

// Camera altitude (km) above the bottom for the sky-view table, clamped
// into the atmosphere.
float atmosphere_camera_altitude(uint lighting, Atmosphere a) {
    float h = uintBitsToFloat(g_lighting[lighting].f.atmosphere.w) * 1e-3;
    if (!(h == h) || isinf(h)) {
        h = ATMO_MIN_ALTITUDE;
    }
    return clamp(h, ATMO_MIN_ALTITUDE, a.top - a.bottom - ATMO_MIN_ALTITUDE);
}

// Distance (km) from radius r along zenith cosine mu to the top (0 above it).
float atmosphere_distance_to_top(Atmosphere a, float r, float mu) {
    float discriminant = (a.top - r) * (a.top + r) + r * r * mu * mu;
    return max(-r * mu + sqrt(max(discriminant, 0.0)), 0.0);
}

// Whether the ray from radius r along zenith cosine mu meets the ground.
bool atmosphere_hits_ground(Atmosphere a, float r, float mu) {
    return mu < 0.0 && (a.bottom - r) * (a.bottom + r) + r * r * mu * mu >= 0.0;
}

// Distance (km) from radius r along zenith cosine mu to the ground (the ray hits it).
float atmosphere_distance_to_ground(Atmosphere a, float r, float mu) {
    float discriminant = (a.bottom - r) * (a.bottom + r) + r * r * mu * mu;
    return max(-r * mu - sqrt(max(discriminant, 0.0)), 0.0);
}

// Extinction-relevant densities at altitude h (km): x Rayleigh, y Mie, z ozone.
vec3 atmosphere_densities(Atmosphere a, float h) {
    return vec3(exp(-h / a.rayleigh_height), exp(-h / a.mie_height),
                max(1.0 - abs(h - a.ozone_center) / a.ozone_half_width, 0.0));
}

vec3 atmosphere_extinction(Atmosphere a, vec3 d) {
    return a.rayleigh_scattering * d.x + a.mie_extinction * d.y + a.ozone_absorption * d.z;
}

// Rayleigh phase function (1/sr) of the cosine nu between view and sun.
float rayleigh_phase(float nu) {
    return 3.0 / (16.0 * ATMO_PI) * (1.0 + nu * nu);
}

// Cornette–Shanks phase function (1/sr), Mie.
float cornette_shanks_phase(float g, float nu) {
    float g2 = g * g;
    float denom = max(1.0 + g2 - 2.0 * g * nu, 1e-6);
    return 3.0 / (8.0 * ATMO_PI) * (1.0 - g2) * (1.0 + nu * nu) / ((2.0 + g2) * denom * sqrt(denom));
}

// Texel-centre mapping: unit x in 0..1 over `n` texels whose first and
// last centres are x = 0 and x = 1.
float atmosphere_unit_to_uv(float x, float n) {
    return (0.5 + x * (n - 1.0)) / n;
}

// Transmittance table (Bruneton 2017): (r, mu) ↔ unit (x_mu, x_r).
vec2 atmosphere_transmittance_unit(Atmosphere a, float r, float mu) {
    float h = sqrt(max(a.top * a.top - a.bottom * a.bottom, 0.0));
    float rho = sqrt(max(r * r - a.bottom * a.bottom, 0.0));
    float d = atmosphere_distance_to_top(a, r, mu);
    float d_min = a.top - r;
    float d_max = rho + h;
    float x_mu = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
    return clamp(vec2(x_mu, rho / h), 0.0, 1.0);
}

vec2 atmosphere_transmittance_r_mu(Atmosphere a, vec2 unit) {
    float h = sqrt(max(a.top * a.top - a.bottom * a.bottom, 0.0));
    float rho = h * unit.y;
    float r = sqrt(rho * rho + a.bottom * a.bottom);
    float d_min = a.top - r;
    float d_max = rho + h;
    float d = d_min + unit.x * (d_max - d_min);
    float mu = d <= 0.0 ? 1.0 : clamp((h * h - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
    return vec2(r, mu);
}

// Transmittance from radius r (km) along zenith cosine mu to the top,
// from the table `handle` (ignores the ground).
vec3 atmosphere_sample_transmittance(uint handle, Atmosphere a, float r, float mu) {
    vec2 size = vec2(textureSize(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), 0));
    vec2 x = atmosphere_transmittance_unit(a, r, mu);
    vec2 uv = vec2(atmosphere_unit_to_uv(x.x, size.x), atmosphere_unit_to_uv(x.y, size.y));
    return textureLod(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0).rgb;
}

// Transmittance of sunlight at radius r (km) with the sun at zenith cosine
// mu_s: 0 when the planet hides it.
vec3 atmosphere_sun_transmittance(uint handle, Atmosphere a, float r, float mu_s) {
    if (atmosphere_hits_ground(a, r, mu_s)) {
        return vec3(0.0);
    }
    return atmosphere_sample_transmittance(handle, a, r, mu_s);
}

// Multiple-scattering table (Hillaire 2020 §5.5): u = mu_s / 2 + 1/2,
// v = altitude / thickness. Stores Ψ_ms per unit solar irradiance (1/sr).
vec3 atmosphere_sample_multiscattering(uint handle, Atmosphere a, float r, float mu_s) {
    vec2 size = vec2(textureSize(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), 0));
    vec2 x = clamp(vec2(0.5 + 0.5 * mu_s, (r - a.bottom) / (a.top - a.bottom)), 0.0, 1.0);
    vec2 uv = vec2(atmosphere_unit_to_uv(x.x, size.x), atmosphere_unit_to_uv(x.y, size.y));
    return textureLod(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0).rgb;
}

// Sky-view table (Hillaire 2020 §5.3): x = sqrt(φ / π), φ the azimuth from
// the sun's (the sky is symmetric about the sun's vertical plane); y the
// zenith angle θ with the non-linear horizon mapping: above the horizon
// (y < 1/2) θ = θ_h (1 − (1 − 2y)²), below it θ = θ_h + β (2y − 1)²,
// θ_h = π − β the zenith angle of the horizon seen from radius r,
// cos β = sqrt(r² − R²) / r. Both halves are densest at the horizon.
vec2 atmosphere_sky_view_angles(Atmosphere a, float r, vec2 unit) {
    float cos_beta = sqrt(max(r * r - a.bottom * a.bottom, 0.0)) / r;
    float beta = acos(clamp(cos_beta, -1.0, 1.0));
    float horizon = ATMO_PI - beta;
    float theta;
    if (unit.y < 0.5) {
        float c = 1.0 - 2.0 * unit.y;
        theta = horizon * (1.0 - c * c);
    } else {
        float c = 2.0 * unit.y - 1.0;
        theta = horizon + beta * c * c;
    }
    return vec2(ATMO_PI * unit.x * unit.x, theta);
}

vec2 atmosphere_sky_view_unit(Atmosphere a, float r, float phi, float theta) {
    float cos_beta = sqrt(max(r * r - a.bottom * a.bottom, 0.0)) / r;
    float beta = acos(clamp(cos_beta, -1.0, 1.0));
    float horizon = ATMO_PI - beta;
    float y;
    if (theta < horizon) {
        y = 0.5 * (1.0 - sqrt(max(1.0 - theta / horizon, 0.0)));
    } else {
        y = 0.5 + 0.5 * sqrt(clamp((theta - horizon) / max(beta, 1e-6), 0.0, 1.0));
    }
    return clamp(vec2(sqrt(clamp(phi / ATMO_PI, 0.0, 1.0)), y), 0.0, 1.0);
}

// Transmittance of sunlight from direction `sun_dir` to world altitude
// `world_z` (m) in the LightingFrame `lighting`'s physical atmosphere, from
// its table (0 when the planet hides the sun's centre).
vec3 physical_sun_transmittance(uint lighting, float world_z, vec3 sun_dir) {
    LightingFrame f = g_lighting[lighting].f;
    float bottom = f.planet.x * 1e-3;
    float top = max(f.planet.y * 1e-3, bottom + 1.0);
    Atmosphere a;
    a.bottom = bottom;
    a.top = top;
    float r = bottom + clamp((world_z - f.mie.w) * 1e-3, 0.0, top - bottom);
    float mu_s = clamp(sun_dir.z / max(length(sun_dir), 1e-20), -1.0, 1.0);
    return atmosphere_sun_transmittance(f.atmosphere.x, a, r, mu_s);
}

// Radiance (per unit solar irradiance) in-scattered along a ray through the
// atmosphere and its transmittance (Hillaire 2020 §5, eq. 1–5), marched in
// `steps` segments from `origin` (km, planet centre at 0) along unit `dir`
// with the sun along unit `sun`. Each segment integrates the in-scattering
// analytically over its constant extinction (Hillaire 2015).
// `multiscattering_pass`: the multiple-scattering table's integrals
// (isotropic phase, no Ψ_ms, the lit ground added, and f_ms the radiance
// for uniform unit illumination); otherwise the sky's (Rayleigh and
// Cornette–Shanks phases, Ψ_ms from `luts.y`). `quadratic`: segments
// growing with the square of the distance (denser near the origin).
struct AtmosphereMarch {
    vec3 radiance;
    vec3 f_ms;
    vec3 transmittance;
};

AtmosphereMarch atmosphere_march(Atmosphere a, uvec2 luts, vec3 origin, vec3 dir, vec3 sun, uint steps,
                                 bool multiscattering_pass, bool quadratic, vec3 ground_albedo) {
    AtmosphereMarch m;
    m.radiance = vec3(0.0);
    m.f_ms = vec3(0.0);
    m.transmittance = vec3(1.0);
    float r = length(origin);
    float mu = dot(origin, dir) / r;
    bool ground = atmosphere_hits_ground(a, r, mu);
    float t_max = ground ? atmosphere_distance_to_ground(a, r, mu) : atmosphere_distance_to_top(a, r, mu);
    if (!(t_max > 0.0)) {
        return m;
    }
    float nu = dot(dir, sun);
    float rayleigh_phase_value = rayleigh_phase(nu);
    float mie_phase_value = cornette_shanks_phase(a.mie_g, nu);
    const float isotropic = 1.0 / (4.0 * ATMO_PI);
    float n = float(steps);
    float t0 = 0.0;
    for (uint i = 0u; i < steps; ++i) {
        float s = float(i + 1u) / n;
        float t1 = t_max * (quadratic ? s * s : s);
        float dt = t1 - t0;
        vec3 p = origin + dir * (0.5 * (t0 + t1));
        t0 = t1;
        float rp = length(p);
        vec3 up = p / rp;
        float mu_s = dot(up, sun);
        vec3 d = atmosphere_densities(a, rp - a.bottom);
        vec3 rayleigh = a.rayleigh_scattering * d.x;
        vec3 mie = a.mie_scattering * d.y;
        vec3 extinction = max(atmosphere_extinction(a, d), vec3(1e-9));
        vec3 segment = exp(-extinction * dt);
        vec3 sun_t = atmosphere_sun_transmittance(luts.x, a, rp, mu_s);
        vec3 scattering = rayleigh + mie;
        vec3 source;
        if (multiscattering_pass) {
            source = scattering * isotropic * sun_t;
            m.f_ms += m.transmittance * scattering * (1.0 - segment) / extinction;
        } else {
            vec3 psi = atmosphere_sample_multiscattering(luts.y, a, rp, mu_s);
            source = (rayleigh * rayleigh_phase_value + mie * mie_phase_value) * sun_t + scattering * psi;
        }
        m.radiance += m.transmittance * source * (1.0 - segment) / extinction;
        m.transmittance *= segment;
    }
    if (multiscattering_pass && ground) {
        vec3 p = origin + dir * t_max;
        vec3 up = normalize(p);
        float mu_s = dot(up, sun);
        vec3 sun_t = atmosphere_sun_transmittance(luts.x, a, a.bottom, mu_s);
        m.radiance += m.transmittance * sun_t * max(mu_s, 0.0) * ground_albedo / ATMO_PI;
    }
    return m;
}

#endif
