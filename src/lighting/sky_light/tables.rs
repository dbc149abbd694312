//! Elevation integrals of the SH basis for the transfer bake (§9.3).
//!
//! Along one azimuth φ the visible directions of a texel are `z ∈ [z0, 1]`
//! (`z = cos θ`, `dω = dφ dz`), and the clamped cosine there is
//! `n·ω = n_z z + n_t sqrt(1−z²)` (`n_t` = the normal's component along φ).
//! With `y_l^m = N_lm P̃_l^|m|(z) (1−z²)^(|m|/2) trig(|m|φ)` (reduced
//! Legendre `P̃`, [`crate::lighting::sh`]) the elevation integral splits into
//!
//! ```text
//! ∫_{z0}^1 n·ω y_l^m dz = N_lm trig(|m|φ) (n_z A_lm(θ0) + n_t B_lm(θ0)),
//! A_lm(θ0) = ∫_0^θ0 P̃(cos θ) sin^m θ cos θ sin θ dθ,
//! B_lm(θ0) = ∫_0^θ0 P̃(cos θ) sin^(m+1) θ sin θ dθ,        θ0 = acos z0,
//! ```
//!
//! smooth in θ0, so a table over θ0 with linear interpolation is accurate
//! (error ~1e-6). Row j (θ0 = jπ/(ENTRIES−1)) holds 32 floats: for pair
//! `p = l(l+1)/2 + m` (m ≥ 0), `N_lm A` at 2p and `N_lm B` at 2p+1, with
//! `N_lm = K_l^m` (·√2 for m > 0).

use std::f64::consts::{PI, SQRT_2};

use crate::lighting::sh::{legendre_reduced, normalisation, MAX_BANDS};

/// Rows of the table (θ0 samples over [0, π]).
pub const ENTRIES: usize = 1025;
/// Floats per row.
pub const ROW: usize = 32;

fn integrands(l: usize, m: usize, theta: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    let base = legendre_reduced(l, m, c) * s.powi(m as i32) * s;
    (base * c, base * s)
}

/// The table, row-major (`ENTRIES × ROW`).
pub fn transfer_tables() -> Vec<f32> {
    let mut table = vec![0.0f32; ENTRIES * ROW];
    let h = PI / (ENTRIES - 1) as f64;
    const SUB: usize = 16;
    for l in 0..MAX_BANDS {
        for m in 0..=l {
            let p = l * (l + 1) / 2 + m;
            let scale = normalisation(l, m) * if m > 0 { SQRT_2 } else { 1.0 };
            let (mut a, mut b) = (0.0, 0.0);
            for j in 1..ENTRIES {
                // Composite Simpson over [θ_{j−1}, θ_j].
                let t0 = (j - 1) as f64 * h;
                let dh = h / SUB as f64;
                let (mut sa, mut sb) = (0.0, 0.0);
                for k in 0..=SUB {
                    let w = if k == 0 || k == SUB {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    let (fa, fb) = integrands(l, m, t0 + k as f64 * dh);
                    sa += w * fa;
                    sb += w * fb;
                }
                a += sa * dh / 3.0;
                b += sb * dh / 3.0;
                table[j * ROW + 2 * p] = (scale * a) as f32;
                table[j * ROW + 2 * p + 1] = (scale * b) as f32;
            }
        }
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::sh::{basis_all, index};
    use glam::DVec3;

    /// The table reproduces direct quadrature of ∫_{z0}^1 max(0, n·ω) y dz.
    #[test]
    fn tables_match_direct_quadrature() {
        let table = transfer_tables();
        let n = DVec3::new(0.3, -0.2, 0.93).normalize();
        let phi: f64 = 0.7;
        let u = DVec3::new(phi.cos(), phi.sin(), 0.0);
        let n_t = n.dot(u);
        let j = 400;
        let theta0 = j as f64 * PI / (ENTRIES - 1) as f64;
        let z0 = theta0.cos();
        let steps = 20000;
        let mut direct = [0.0; 25];
        for s in 0..steps {
            let z = z0 + (1.0 - z0) * (s as f64 + 0.5) / steps as f64;
            let r = (1.0 - z * z).sqrt();
            let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let y = basis_all(d);
            for i in 0..25 {
                direct[i] += n.dot(d) * y[i] * (1.0 - z0) / steps as f64;
            }
        }
        for l in 0..MAX_BANDS {
            for m in 0..=l {
                let p = l * (l + 1) / 2 + m;
                let v = n.z * f64::from(table[j * ROW + 2 * p]) + n_t * f64::from(table[j * ROW + 2 * p + 1]);
                let want_cos = direct[index(l, m as i32)];
                let got_cos = v * if m > 0 { (m as f64 * phi).cos() } else { 1.0 };
                assert!(
                    (got_cos - want_cos).abs() < 1e-5,
                    "l {l} m {m}: {got_cos} vs {want_cos}"
                );
                if m > 0 {
                    let got_sin = v * (m as f64 * phi).sin();
                    let want_sin = direct[index(l, -(m as i32))];
                    assert!((got_sin - want_sin).abs() < 1e-5, "l {l} m -{m}");
                }
            }
        }
    }
}
