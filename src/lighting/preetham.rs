//! The Preetham sky and the transmitted sun (§6.3 "Analytic Models", §9.5
//! Fig. 9.3; `ALGORITHMS.md` §6): Preetham, Shirley and Smits 1999, "A
//! practical analytic model for daylight" (SIGGRAPH 99), sections 3.2 and
//! appendices A.1, A.2.
//!
//! Sky luminance and chromaticity follow the Perez distribution
//! `F(θ,γ) = (1 + A·e^(B/cos θ))·(1 + C·e^(D·γ) + E·cos²γ)` (eq. 6.20),
//! normalised at the zenith: `Y(θ,γ) = Y_z·F(θ,γ)/F(0,θ_s)` and likewise for
//! the chromaticities x and y, with A..E linear in the turbidity T
//! (Preetham's table of appendix A.2). Y,x,y become CIE XYZ and then linear
//! sRGB (D65), so the luminance `0.2126 R + 0.7152 G + 0.0722 B` of a
//! radiance is in cd/m². `glsl/include/sky_preetham.glsl` is the GPU twin of
//! [`PreethamSky::radiance`]; both read the constants [`PreethamSky::fill`]
//! writes into [`LightingFrame`].
//!
//! Choices beyond the paper (the model is fitted for a sun above the horizon
//! and views above it):
//! * View directions: `cos θ` is clamped to [`COS_THETA_MIN`] (θ ≈ 89.4°)
//!   because `e^(B/cos θ)` blows up for `cos θ ≤ 0`; γ stays the true angle
//!   to the sun, so the result is continuous. Below the horizon the clamped
//!   (horizon) value is darkened smoothly, to [`GROUND_FLOOR`] of it at
//!   `sin(depression) ≥` [`GROUND_FADE`] (a stand-in for the ground, not a
//!   model of it).
//! * A sun below the horizon: the formulas use the sun moved onto the horizon
//!   at its azimuth (θ_s = 90°), and the zenith luminance fades smoothly
//!   (log-linear, smoothstep weight) from its sunset value to
//!   [`TWILIGHT_ZENITH_LUMINANCE`] at [`TWILIGHT_END_DEG`] and stays there.
//!   Never negative or NaN.
//! * Sun: [`transmitted_sun`] (`solar`): the extraterrestrial disc times
//!   the transmittances of Preetham's appendix A.1; its centre radiance and
//!   irradiance under the limb-darkening profile here.
//!
//! The CIE skies of §6.3 ([`PreethamSky::cie_clear`],
//! [`PreethamSky::cie_overcast`]) are evaluated by the same code:
//! * clear (eq. 6.18): `Y = Y_z (0.91 + 10 e^(−3γ) + 0.45 cos²γ)(1 −
//!   e^(−0.32/cos θ)) / ((0.91 + 10 e^(−3θ_s) + 0.45 cos²θ_s)(1 − e^(−0.32)))`
//!   is the Perez distribution with A = −1, B = −0.32, C = 10/0.91, D = −3,
//!   E = 0.45/0.91 (the factor 0.91 cancels in the ratio), so only the
//!   luminance coefficients change; zenith luminance and the chromaticities
//!   stay Preetham's at the turbidity (the CIE model gives luminance only;
//!   the text points to tables for `Y_z`);
//! * overcast (eq. 6.19): `Y = Y_z (1 + 2 cos θ) / 3`, flagged to the
//!   shader by `perez_norm.w = 1`; `Y_z = 123 + 8600 sin h` cd/m² for a sun
//!   at elevation h (Krochmann and Seidl's overcast zenith luminance), the
//!   twilight fade below the horizon as above; chromaticity constant (D65
//!   white); the sun is hidden (no disc, no direct light: everything is sky
//!   light).

use glam::Vec3;

use super::constants::{LightingFrame, SUN_ANGULAR_RADIUS};
use super::solar::transmitted_sun;
use crate::error::{Error, Result};

/// Smallest `cos θ` (view zenith angle) the Perez formula is evaluated at.
#[cfg(test)]
pub const COS_THETA_MIN: f32 = 0.01;
/// Fraction of the horizon radiance left for directions well below it.
#[cfg(test)]
pub const GROUND_FLOOR: f32 = 0.3;
/// `sin` of the depression below the horizon where the darkening is complete.
#[cfg(test)]
pub const GROUND_FADE: f32 = 0.2;
/// Zenith luminance (cd/m²) once the sun is [`TWILIGHT_END_DEG`] below the
/// horizon (end of civil twilight).
pub const TWILIGHT_ZENITH_LUMINANCE: f32 = 2.0;
/// Sun elevation (degrees) where the twilight fade ends.
pub const TWILIGHT_END_DEG: f32 = -6.0;
/// Limb darkening u of the sun's disc: `I(r) = 1 − u·(1 − sqrt(1 − r²))`.
pub const LIMB_DARKENING: f32 = 0.6;

/// Perez A..E for Y, x, y: `[slope, intercept]` of `slope·T + intercept`
/// (Preetham 1999, appendix A.2).
const PEREZ: [[[f32; 2]; 5]; 3] = [
    [
        [0.1787, -1.4630],
        [-0.3554, 0.4275],
        [-0.0227, 5.3251],
        [0.1206, -2.5771],
        [-0.0670, 0.3703],
    ],
    [
        [-0.0193, -0.2592],
        [-0.0665, 0.0008],
        [-0.0004, 0.2125],
        [-0.0641, -0.8989],
        [-0.0033, 0.0452],
    ],
    [
        [-0.0167, -0.2608],
        [-0.0950, 0.0092],
        [-0.0079, 0.2102],
        [-0.0441, -1.6537],
        [-0.0109, 0.0529],
    ],
];
/// Zenith chromaticity: rows for T², T, 1; columns for θ_s³, θ_s², θ_s, 1
/// (appendix A.2).
const ZENITH_X: [[f32; 4]; 3] = [
    [0.00166, -0.00375, 0.00209, 0.0],
    [-0.02903, 0.06377, -0.03202, 0.00394],
    [0.11693, -0.21196, 0.06052, 0.25886],
];
const ZENITH_Y: [[f32; 4]; 3] = [
    [0.00275, -0.00610, 0.00317, 0.0],
    [-0.04214, 0.08970, -0.04153, 0.00516],
    [0.15346, -0.26756, 0.06670, 0.26688],
];

/// Perez A..E of the CIE clear sky's luminance (eq. 6.18; see the module).
const CIE_CLEAR: [f32; 5] = [-1.0, -0.32, 10.0 / 0.91, -3.0, 0.45 / 0.91];
/// Chromaticity of the CIE overcast sky: D65 white.
const OVERCAST_CHROMATICITY: (f32, f32) = (0.3127, 0.3290);

/// Zenith luminance (cd/m²) of an overcast sky for a sun at elevation
/// `sin_h` (sine): Krochmann and Seidl, `123 + 8600 sin h`.
pub fn overcast_zenith_luminance(sin_h: f32) -> f32 {
    123.0 + 8600.0 * sin_h.max(0.0)
}

/// Checks a turbidity against the range the fit was made for.
pub fn check_turbidity(turbidity: f32) -> Result<()> {
    if !(1.7..=10.0).contains(&turbidity) {
        return Err(Error::invalid(
            "lighting.turbidity",
            format!("{turbidity}; must be in 1.7..=10"),
        ));
    }
    Ok(())
}

/// Perez coefficients A..E at turbidity `t`; x, y, z of each for Y, x, y.
pub fn perez_coefficients(t: f32) -> [Vec3; 5] {
    std::array::from_fn(|i| Vec3::from_array(std::array::from_fn(|c| PEREZ[c][i][0] * t + PEREZ[c][i][1])))
}

/// The Perez function `F(θ,γ)` for Y, x, y at once.
pub fn perez(c: &[Vec3; 5], cos_theta: f32, gamma: f32) -> Vec3 {
    let cos_gamma = gamma.cos();
    (Vec3::ONE + c[0] * (c[1] / cos_theta).exp())
        * (Vec3::ONE + c[2] * (c[3] * gamma).exp() + c[4] * cos_gamma * cos_gamma)
}

/// Zenith luminance (cd/m²) of Preetham's appendix A.2 for a sun at zenith
/// angle `theta_s` ≤ π/2 (rad): `Y_z = (4.0453T − 4.9710)·tan χ − 0.2155T +
/// 2.4192` kcd/m², `χ = (4/9 − T/120)(π − 2θ_s)`.
pub fn zenith_luminance_formula(theta_s: f32, t: f32) -> f32 {
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * theta_s);
    1000.0 * ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192)
}

/// Zenith chromaticity (x_z, y_z): `[T² T 1]·M·[θ_s³ θ_s² θ_s 1]ᵀ`.
pub fn zenith_chromaticity_formula(theta_s: f32, t: f32) -> (f32, f32) {
    let eval = |m: &[[f32; 4]; 3]| {
        let row = |r: &[f32; 4]| ((r[0] * theta_s + r[1]) * theta_s + r[2]) * theta_s + r[3];
        t * t * row(&m[0]) + t * row(&m[1]) + row(&m[2])
    };
    (eval(&ZENITH_X), eval(&ZENITH_Y))
}

/// CIE xyY → linear sRGB (IEC 61966-2-1, D65); components may be negative
/// for colours outside the gamut.
#[cfg(test)]
pub fn xyy_to_linear_srgb(luminance: f32, x: f32, y: f32) -> Vec3 {
    let y = y.max(1e-4);
    let xyz = Vec3::new(x / y * luminance, luminance, (1.0 - x - y) / y * luminance);
    Vec3::new(
        3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
        -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
        0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z,
    )
}

/// Luminance (cd/m² for this crate's radiance) of a linear sRGB colour.
#[cfg(test)]
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The factor below-horizon directions are darkened by (1 above it); the
/// GPU twin is `preetham_ground_factor`.
#[cfg(test)]
pub fn ground_factor(dir_z: f32) -> f32 {
    1.0 - (1.0 - GROUND_FLOOR) * smoothstep(0.0, GROUND_FADE, -dir_z)
}

/// The sun direction the formulas use: a sun below the horizon moved onto
/// it at its azimuth (straight down: north).
pub fn horizon_clamped_sun(sun: Vec3) -> Vec3 {
    if sun.z >= 0.0 {
        return sun;
    }
    let h = sun.truncate().length();
    if h > 1e-6 {
        (sun.truncate() / h).extend(0.0)
    } else {
        Vec3::Y
    }
}

/// The Preetham sky for one sun and turbidity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreethamSky {
    /// Unit vector towards the true sun.
    sun: Vec3,
    /// The sun the formulas use ([`horizon_clamped_sun`]).
    sun_formula: Vec3,
    turbidity: f32,
    coefficients: [Vec3; 5],
    /// Y_z (cd/m², twilight fade applied), x_z, y_z.
    zenith: Vec3,
    /// `1 / F(0, θ_s)` for Y, x, y.
    norm: Vec3,
    /// The CIE overcast sky: Moon–Spencer luminance, no sun.
    overcast: bool,
}

impl PreethamSky {
    /// The sky for a sun along `sun` (any length; +Z up) at turbidity
    /// `turbidity` (1.7..=10).
    pub fn new(sun: Vec3, turbidity: f32) -> Result<PreethamSky> {
        check_turbidity(turbidity)?;
        if !sun.is_finite() || sun.length() < 1e-6 {
            return Err(Error::invalid(
                "lighting.sun",
                format!("{sun}; must be a finite non-zero vector"),
            ));
        }
        let sun = sun.normalize();
        let sun_formula = horizon_clamped_sun(sun);
        let theta_s = sun_formula.z.clamp(0.0, 1.0).acos();
        let coefficients = perez_coefficients(turbidity);
        let (x_z, y_z) = zenith_chromaticity_formula(theta_s, turbidity);
        let mut y_zenith = zenith_luminance_formula(theta_s, turbidity).max(TWILIGHT_ZENITH_LUMINANCE);
        if sun.z < 0.0 {
            let elevation = sun.z.clamp(-1.0, 0.0).asin().to_degrees();
            let w = smoothstep(TWILIGHT_END_DEG, 0.0, elevation);
            let (lo, hi) = (TWILIGHT_ZENITH_LUMINANCE.ln(), y_zenith.ln());
            y_zenith = (lo + (hi - lo) * w).exp();
        }
        let norm = perez(&coefficients, 1.0, theta_s).recip();
        Ok(PreethamSky {
            sun,
            sun_formula,
            turbidity,
            coefficients,
            zenith: Vec3::new(y_zenith, x_z, y_z),
            norm,
            overcast: false,
        })
    }

    /// The CIE clear sky (§6.3 eq. 6.18): Preetham's sky with the CIE
    /// luminance distribution.
    pub fn cie_clear(sun: Vec3, turbidity: f32) -> Result<PreethamSky> {
        let mut sky = PreethamSky::new(sun, turbidity)?;
        for (c, cie) in sky.coefficients.iter_mut().zip(CIE_CLEAR) {
            c.x = cie;
        }
        let theta_s = sky.sun_formula.z.clamp(0.0, 1.0).acos();
        sky.norm = perez(&sky.coefficients, 1.0, theta_s).recip();
        Ok(sky)
    }

    /// The CIE overcast sky (§6.3 eq. 6.19): `Y_z (1 + 2 cos θ) / 3`, white,
    /// no direct sun.
    pub fn cie_overcast(sun: Vec3, turbidity: f32) -> Result<PreethamSky> {
        let mut sky = PreethamSky::new(sun, turbidity)?;
        let clear_zenith = zenith_luminance_formula(sky.sun_formula.z.clamp(0.0, 1.0).acos(), turbidity);
        // The clear sky's twilight fade, carried over to the overcast zenith.
        let fade = (sky.zenith.x / clear_zenith.max(1e-6)).min(1.0);
        let overcast = overcast_zenith_luminance(sky.sun_formula.z) * fade;
        sky.zenith = Vec3::new(
            overcast.max(TWILIGHT_ZENITH_LUMINANCE),
            OVERCAST_CHROMATICITY.0,
            OVERCAST_CHROMATICITY.1,
        );
        sky.coefficients = [Vec3::ZERO; 5];
        sky.norm = Vec3::ONE;
        sky.overcast = true;
        Ok(sky)
    }

    /// The sky of `model` for a sun along `sun` at `turbidity`; `None` for
    /// the physical model (not an analytic sky).
    pub fn for_model(model: crate::view::SkyModel, sun: Vec3, turbidity: f32) -> Result<Option<PreethamSky>> {
        use crate::view::SkyModel;
        match model {
            SkyModel::Preetham => PreethamSky::new(sun, turbidity).map(Some),
            SkyModel::CieClear => PreethamSky::cie_clear(sun, turbidity).map(Some),
            SkyModel::CieOvercast => PreethamSky::cie_overcast(sun, turbidity).map(Some),
            SkyModel::Physical => Ok(None),
        }
    }

    /// The unit vector towards the sun.
    #[cfg(test)]
    pub fn sun(&self) -> Vec3 {
        self.sun
    }

    /// Y_z (cd/m²), after the twilight fade.
    #[cfg(test)]
    pub fn zenith_luminance(&self) -> f32 {
        self.zenith.x
    }

    /// (x_z, y_z).
    #[cfg(test)]
    pub fn zenith_chromaticity(&self) -> (f32, f32) {
        (self.zenith.y, self.zenith.z)
    }

    /// Perez A..E (x, y, z for Y, x, y).
    #[cfg(test)]
    pub fn coefficients(&self) -> &[Vec3; 5] {
        &self.coefficients
    }

    /// `(Y, x, y)` along unit `dir` after the view clamp, before the
    /// below-horizon darkening.
    #[cfg(test)]
    pub fn luminance_chromaticity(&self, dir: Vec3) -> Vec3 {
        let dir = dir.normalize_or(Vec3::Z);
        let cos_theta = dir.z.max(COS_THETA_MIN);
        let gamma = dir.dot(self.sun_formula).clamp(-1.0, 1.0).acos();
        let mut yxy = self.zenith * perez(&self.coefficients, cos_theta, gamma) * self.norm;
        if self.overcast {
            yxy.x = self.zenith.x * (1.0 + 2.0 * cos_theta) / 3.0;
        }
        yxy
    }

    /// Sky radiance along `dir` (+Z up) without the sun disc: linear sRGB,
    /// luminance in cd/m². CPU twin of `preetham_sky` (sky_preetham.glsl).
    #[cfg(test)]
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let dir = dir.normalize_or(Vec3::Z);
        let yxy = self.luminance_chromaticity(dir);
        xyy_to_linear_srgb(yxy.x, yxy.y, yxy.z).max(Vec3::ZERO) * ground_factor(dir.z)
    }

    /// Mean radiance of the sun's disc at the ground (linear sRGB, cd/m²):
    /// see [`transmitted_sun`].
    pub fn sun_mean_radiance(&self) -> Vec3 {
        if self.overcast {
            return Vec3::ZERO;
        }
        transmitted_sun(self.sun, self.turbidity)
    }

    /// Radiance of the disc centre: the mean over `1 − u/3`, the mean of the
    /// limb-darkening profile over the disc.
    pub fn sun_centre_radiance(&self) -> Vec3 {
        self.sun_mean_radiance() / (1.0 - LIMB_DARKENING / 3.0)
    }

    /// Irradiance of the whole disc on a plane facing the sun: the mean
    /// radiance × the disc's solid angle `2π(1 − cos r)`.
    pub fn sun_irradiance(&self) -> Vec3 {
        let omega = 2.0 * std::f32::consts::PI * (1.0 - SUN_ANGULAR_RADIUS.cos());
        self.sun_mean_radiance() * omega
    }

    /// Writes the sun and the Preetham constants: `sun`, `sun_radiance`,
    /// `sun_irradiance`, `perez`, `zenith`, `perez_norm`.
    pub fn fill(&self, frame: &mut LightingFrame) {
        frame.sun = self.sun.extend(SUN_ANGULAR_RADIUS).to_array();
        frame.sun_radiance = self.sun_centre_radiance().extend(LIMB_DARKENING).to_array();
        frame.sun_irradiance = self.sun_irradiance().extend(0.0).to_array();
        for (row, c) in frame.perez.iter_mut().zip(self.coefficients) {
            *row = c.extend(0.0).to_array();
        }
        frame.zenith = self.zenith.extend(self.turbidity).to_array();
        frame.perez_norm = self.norm.extend(if self.overcast { 1.0 } else { 0.0 }).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::constants::SUN_LUMINANCE_EXTRATERRESTRIAL;
    use crate::view::lighting::sun_direction;

    /// Preetham's appendix A.2 written out again in f64, independently of
    /// the tables above: (Y_z cd/m², x_z, y_z).
    fn published_zenith(elevation_deg: f64, t: f64) -> (f64, f64, f64) {
        let ts = (90.0 - elevation_deg).to_radians();
        let chi = (4.0 / 9.0 - t / 120.0) * (std::f64::consts::PI - 2.0 * ts);
        let yz = 1000.0 * ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192);
        let (t2, s2, s3) = (t * t, ts * ts, ts * ts * ts);
        let xz = t2 * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * ts)
            + t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * ts + 0.00394)
            + (0.11693 * s3 - 0.21196 * s2 + 0.06052 * ts + 0.25886);
        let yc = t2 * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * ts)
            + t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * ts + 0.00516)
            + (0.15346 * s3 - 0.26756 * s2 + 0.06670 * ts + 0.26688);
        (yz, xz, yc)
    }

    /// Perez F for luminance Y, f64, from the published A..E.
    fn published_perez_y(t: f64, theta: f64, gamma: f64) -> f64 {
        let (a, b, c) = (0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251);
        let (d, e) = (0.1206 * t - 2.5771, -0.0670 * t + 0.3703);
        (1.0 + a * (b / theta.cos()).exp()) * (1.0 + c * (d * gamma).exp() + e * gamma.cos().powi(2))
    }

    fn sky(elevation_deg: f32, azimuth_deg: f32, t: f32) -> PreethamSky {
        PreethamSky::new(sun_direction(elevation_deg, azimuth_deg), t).unwrap()
    }

    #[test]
    fn zenith_values_follow_the_published_formulas() {
        for elevation in [10.0, 30.0, 60.0, 85.0] {
            for t in [2.0, 3.0, 6.0] {
                let s = sky(elevation as f32, 120.0, t as f32);
                let (yz, xz, yc) = published_zenith(elevation, t);
                assert!(
                    ((s.zenith_luminance() as f64) / yz - 1.0).abs() < 1e-3,
                    "{elevation} {t}"
                );
                let (x, y) = s.zenith_chromaticity();
                assert!(
                    (x as f64 - xz).abs() < 2e-4 && (y as f64 - yc).abs() < 2e-4,
                    "{elevation} {t}"
                );
                let l = luminance(s.radiance(Vec3::Z)) as f64;
                assert!((l / yz - 1.0).abs() < 0.02, "radiance luminance {l} vs {yz}");
            }
        }
        // By hand for T = 2, θ_s = 60°: χ = (4/9 − 1/60)·π/3 = 0.44797, tan χ = 0.48055,
        // Y_z = 3.1196 · 0.48055 − 0.431 + 2.4192 = 3.4873 kcd/m²;
        // x_z = 0.23801, y_z = 0.24199.
        let s = sky(30.0, 0.0, 2.0);
        assert!((s.zenith_luminance() / 3487.3 - 1.0).abs() < 2e-3);
        let (x, y) = s.zenith_chromaticity();
        assert!((x - 0.23801).abs() < 5e-4 && (y - 0.24199).abs() < 5e-4, "{x} {y}");
    }

    #[test]
    fn luminance_follows_the_perez_ratio() {
        for (elevation, t) in [(15.0f32, 2.0f32), (45.0, 3.0), (70.0, 6.0)] {
            let s = sky(elevation, 200.0, t);
            let sun = s.sun().as_dvec3();
            let theta_s = (90.0 - elevation as f64).to_radians();
            for (e, a) in [
                (5.0f32, 0.0f32),
                (20.0, 180.0),
                (40.0, 210.0),
                (80.0, 90.0),
                (elevation, 200.0),
            ] {
                let d = sun_direction(e, a);
                let theta = (90.0 - e as f64).to_radians();
                let gamma = d.as_dvec3().dot(sun).clamp(-1.0, 1.0).acos();
                let expected = published_perez_y(t as f64, theta, gamma) / published_perez_y(t as f64, 0.0, theta_s);
                let got = (s.luminance_chromaticity(d).x / s.zenith_luminance()) as f64;
                assert!(
                    (got / expected - 1.0).abs() < 2e-3,
                    "{elevation} {e} {a}: {got} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn no_nan_or_negative_anywhere() {
        let mut frame = <LightingFrame as bytemuck::Zeroable>::zeroed();
        for t in [1.7, 2.1, 6.0, 10.0] {
            for sun_e in (-10..=90).map(|e| e as f32) {
                let s = sky(sun_e, 37.0, t);
                assert!(s.zenith_luminance() >= TWILIGHT_ZENITH_LUMINANCE * 0.999);
                for e in (-90..=90).step_by(5) {
                    for a in (0..360).step_by(15) {
                        let r = s.radiance(sun_direction(e as f32, a as f32));
                        assert!(r.is_finite() && r.min_element() >= 0.0, "{t} {sun_e} {e} {a}: {r}");
                    }
                }
                let sun = s.sun_centre_radiance();
                assert!(sun.is_finite() && sun.min_element() >= 0.0);
                s.fill(&mut frame);
                let floats: &[f32] = bytemuck::cast_slice(std::slice::from_ref(&frame));
                assert!(floats.iter().all(|v| v.is_finite()));
            }
        }
        assert!(sky(-90.0, 0.0, 3.0).radiance(-Vec3::Z).is_finite());
    }

    #[test]
    fn horizon_and_twilight_are_continuous() {
        let s = sky(20.0, 90.0, 3.0);
        let above = s.radiance(Vec3::new(1.0, 0.0, 1e-4));
        let below = s.radiance(Vec3::new(1.0, 0.0, -1e-4));
        assert!((above - below).length() < 1e-3 * above.length());
        assert!(luminance(s.radiance(-Vec3::Z)) < 0.31 * luminance(s.radiance(Vec3::new(0.0, -1.0, 0.0))));
        let (up, down) = (sky(0.01, 0.0, 3.0), sky(-0.01, 0.0, 3.0));
        assert!((up.zenith_luminance() / down.zenith_luminance() - 1.0).abs() < 1e-3);
        let mut last = f32::INFINITY;
        for e in (0..=80).map(|i| -0.1 * i as f32) {
            let y = sky(e, 0.0, 3.0).zenith_luminance();
            assert!(y <= last * 1.0001, "{e}");
            last = y;
        }
        assert!((last - TWILIGHT_ZENITH_LUMINANCE).abs() < 1e-3);
    }

    #[test]
    fn sun_is_redder_low_and_gone_below_the_horizon() {
        let ratio = |e: f32| {
            let c = sky(e, 0.0, 2.5).sun_mean_radiance();
            c.x / c.z
        };
        assert!(ratio(3.0) > 2.0 * ratio(60.0), "{} {}", ratio(3.0), ratio(60.0));
        assert!(ratio(20.0) > ratio(60.0) && ratio(60.0) > ratio(89.0));
        // High sun, clear air: ≈ 1.5e9 cd/m² (the classic 1.6e9 at the ground).
        let l = luminance(sky(90.0, 0.0, 2.0).sun_mean_radiance());
        assert!((1.3e9..1.7e9).contains(&l), "{l}");
        assert_eq!(sky(-1.0, 0.0, 2.0).sun_mean_radiance(), Vec3::ZERO);
        // Irradiance: mean radiance × solid angle; centre = mean / (1 − u/3).
        let s = sky(40.0, 0.0, 3.0);
        let omega = 2.0 * std::f32::consts::PI * (1.0 - SUN_ANGULAR_RADIUS.cos());
        let e = s.sun_irradiance();
        assert!(
            (e / (s.sun_centre_radiance() * (1.0 - LIMB_DARKENING / 3.0) * omega) - Vec3::ONE)
                .abs()
                .max_element()
                < 1e-4
        );
        // Extraterrestrial: 1.96e9 cd/m² × Ω ≈ 133 klx.
        assert!((SUN_LUMINANCE_EXTRATERRESTRIAL * omega / 1.334e5 - 1.0).abs() < 0.01);
    }

    #[test]
    fn fill_writes_the_constants() {
        let s = sky(25.0, 231.0, 3.0);
        let mut frame = <LightingFrame as bytemuck::Zeroable>::zeroed();
        s.fill(&mut frame);
        assert_eq!(frame.zenith[0], s.zenith_luminance());
        assert_eq!(frame.zenith[3], 3.0);
        assert_eq!(frame.sun[3], SUN_ANGULAR_RADIUS);
        assert_eq!(frame.sun_radiance[3], LIMB_DARKENING);
        assert!((Vec3::from_slice(&frame.sun[..3]) - s.sun()).length() < 1e-6);
        assert_eq!(frame.perez[1][0], -0.3554 * 3.0 + 0.4275);
        let f0 = perez(s.coefficients(), 1.0, (90.0f32 - 25.0).to_radians());
        assert!((frame.perez_norm[0] * f0.x - 1.0).abs() < 1e-4);
    }

    #[test]
    fn bad_inputs_are_named() {
        let err = PreethamSky::new(Vec3::Z, 1.0).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.turbidity"));
        let err = PreethamSky::new(Vec3::ZERO, 3.0).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.sun"));
    }
}
