// Real spherical harmonics of the first five bands (l < 5, 25 functions),
// the basis of precomputed radiance transfer (§9.3; ALGORITHMS.md §6), the
// same as src/lighting/sh.rs: y_l^m = √2 K_l^m P_l^m(cos θ) cos(mφ) (m > 0),
// √2 K P_l^|m| sin(|m|φ) (m < 0), K P_l^0 (m = 0), Condon–Shortley phase in
// P_m^m = (−1)^m (2m−1)!! (1−z²)^(m/2); coefficient i = l(l+1) + m.
// Evaluated as polynomials: reduced Legendre P̃ = P / (1−z²)^(m/2) times
// (Re, Im) (x + i y)^m = sin^m θ (cos mφ, sin mφ).
#ifndef ALPENGLOW_SH_GLSL
#define ALPENGLOW_SH_GLSL

const float SH_PI = 3.14159265358979;
const float SH_SQRT2 = 1.41421356237310;

// K_l^m for m >= 0, at l(l+1)/2 + m.
const float SH_K[15] = float[15](0.282094792, 0.488602512, 0.345494149, 0.630783131, 0.257516135, 0.128758067,
                                 0.746352665, 0.215453456, 0.068132365, 0.027814922, 0.846284375, 0.189234939,
                                 0.044603103, 0.011920681, 0.004214597);

// All 25 basis functions at unit direction d.
void sh_basis(vec3 d, out float y[25]) {
    vec2 power = vec2(1.0, 0.0);
    float pmm = 1.0;
    for (int m = 0; m < 5; ++m) {
        if (m > 0) {
            power = vec2(power.x * d.x - power.y * d.y, power.x * d.y + power.y * d.x);
            pmm *= -float(2 * m - 1);
        }
        float prev2 = 0.0;
        float prev1 = 0.0;
        for (int l = m; l < 5; ++l) {
            float p;
            if (l == m) {
                p = pmm;
            } else if (l == m + 1) {
                p = d.z * float(2 * m + 1) * pmm;
            } else {
                p = (d.z * float(2 * l - 1) * prev1 - float(l + m - 1) * prev2) / float(l - m);
            }
            prev2 = prev1;
            prev1 = p;
            float k = SH_K[l * (l + 1) / 2 + m] * p;
            int c = l * (l + 1);
            if (m == 0) {
                y[c] = k;
            } else {
                y[c + m] = SH_SQRT2 * k * power.x;
                y[c - m] = SH_SQRT2 * k * power.y;
            }
        }
    }
}

// Band l of coefficient i.
int sh_band(int i) {
    return i < 1 ? 0 : (i < 4 ? 1 : (i < 9 ? 2 : (i < 16 ? 3 : 4)));
}

// Â_l / π: the clamped cosine convolved with band l, over π
// (1, 2/3, 1/4, 0, −1/24): irradiance / π = Σ Â_l/π c_lm y_lm(n).
float sh_clamped_cosine_over_pi(int l) {
    const float a[5] = float[5](1.0, 2.0 / 3.0, 0.25, 0.0, -1.0 / 24.0);
    return a[l];
}

#endif
