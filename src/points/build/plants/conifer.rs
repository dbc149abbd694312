//! A conifer (spruce/fir) after the parametric tree model of Weber and Penn
//! (1995), reduced to what a point tree needs: a tapered trunk, whorls of
//! drooping branches whose length follows a conical crown envelope, and
//! along each branch needle tufts every 0.3 m: three small sheets (open,
//! drawn two-sided) rolled 120° apart, 0.8 m long at the branch base,
//! 0.45 m at its tip, pointing out and down.
//!
//! Parameters, all drawn from the seed: height H = 12 m · (0.85…1.15);
//! crown base at (0.12…0.25)·H; crown radius (0.22…0.30)·H; 12–16 whorls
//! of 5–7 branches from the crown base to 0.95·H. A whorl at relative crown
//! height t has branches of length `R·(1 − t)^0.85·(0.85…1.15)` (the cone
//! of Weber–Penn's shape 0), pitched down by 10–25° less 20°·t (upper
//! branches rise). The trunk reaches 0.5 m below the ground so that a plant
//! on a slope does not float.

use glam::Vec3;

use super::mesh::{mix, perpendiculars, vary, MeshBuilder};
use crate::points::TriangleMesh;
use crate::random::SplitMix64;

/// Nominal height in metres (scale 1).
pub const HEIGHT: f32 = 12.0;

const BARK: [u8; 3] = [112, 86, 64];
const NEEDLES: [u8; 3] = [58, 92, 50];
const NEEDLE_TIPS: [u8; 3] = [96, 128, 60];
/// Spacing of the needle tufts along a branch (metres).
const TUFT_SPACING: f32 = 0.3;

/// The conifer of `seed` (module docs): base at the origin, growing up +z.
pub fn conifer(seed: u64) -> TriangleMesh {
    let mut rng = SplitMix64(seed);
    let mut uniform = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f64() as f32;
    let height = HEIGHT * uniform(0.85, 1.15);
    let crown_base = height * uniform(0.12, 0.25);
    let crown_radius = height * uniform(0.22, 0.30);
    let whorls = uniform(12.0, 17.0) as u32;
    let mut b = MeshBuilder::default();
    b.tube(
        &[
            Vec3::new(0.0, 0.0, -0.5),
            Vec3::new(0.0, 0.0, crown_base),
            Vec3::new(0.0, 0.0, height),
        ],
        &[0.022 * height, 0.016 * height, 0.0],
        6,
        BARK,
    );
    let mut rng = SplitMix64(seed ^ 0x636f_6e69_6665_7221);
    for w in 0..whorls {
        let t = (w as f32 + rng.next_f64() as f32 * 0.5) / whorls as f32;
        let z = crown_base + t * (0.95 * height - crown_base);
        let branches = 5 + (rng.next_u64() % 3) as u32;
        let phase = rng.next_f64() as f32 * std::f32::consts::TAU;
        for k in 0..branches {
            let azimuth = phase + (k as f32 + 0.3 * rng.next_f64() as f32) / branches as f32 * std::f32::consts::TAU;
            let length = crown_radius * (1.0 - t).powf(0.85) * (0.85 + 0.3 * rng.next_f64() as f32);
            let pitch = (-(10.0 + 15.0 * rng.next_f64() as f32) + 20.0 * t).to_radians();
            let dir = Vec3::new(azimuth.cos() * pitch.cos(), azimuth.sin() * pitch.cos(), pitch.sin());
            let base = Vec3::new(0.0, 0.0, z);
            let tip = base + dir * length + Vec3::new(0.0, 0.0, -0.08 * length);
            b.tube(&[base, tip], &[0.012 * length + 0.01, 0.004], 3, BARK);
            needle_tufts(&mut b, (base + dir * (0.08 * length), tip), &mut rng);
        }
    }
    // The leader: a small spray at the top.
    let top = Vec3::new(0.0, 0.0, height);
    let shade = vary(NEEDLE_TIPS, 0.1, &mut rng);
    b.strip(
        &[top - Vec3::Z * (0.08 * height), top],
        &[0.03 * height, 0.0],
        Vec3::X,
        &[NEEDLES, shade],
    );
    b.finish()
}

/// Needle tufts along a branch from `from` to `to` (module docs).
fn needle_tufts(b: &mut MeshBuilder, (from, to): (Vec3, Vec3), rng: &mut SplitMix64) {
    let along = to - from;
    let length = along.length();
    let dir = along.normalize_or_zero();
    if dir == Vec3::ZERO {
        return;
    }
    let (u, v) = perpendiculars(dir);
    let count = ((length / TUFT_SPACING).ceil() as u32).max(1);
    for i in 0..count {
        let t = (i as f32 + 0.5) / count as f32;
        let at = from + along * t;
        let size = 0.8 - 0.35 * t;
        let base_color = vary(NEEDLES, 0.15, rng);
        let color = mix(base_color, NEEDLE_TIPS, t * 0.8);
        for k in 0..3 {
            let roll = (rng.next_f64() as f32 / 3.0 + k as f32 / 3.0) * std::f32::consts::TAU;
            let out = u * roll.cos() + v * roll.sin();
            let tuft_dir = (dir + out * 0.8 - Vec3::Z * 0.3).normalize_or(dir);
            b.leaf(at, tuft_dir, out.cross(tuft_dir), (size, 0.4 * size), color);
        }
    }
}
