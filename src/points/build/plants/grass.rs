//! A grass tuft: 24–40 blades from a small disc of 6 cm radius, each a
//! tapering, outward-bending sheet (drawn two-sided) 0.3–0.6 m high, dark
//! green at the base and straw-coloured at the tip. Height about 0.5 m at
//! scale 1.

use glam::Vec3;

use super::mesh::{mix, vary, MeshBuilder};
use crate::points::TriangleMesh;
use crate::random::SplitMix64;

/// Nominal height in metres (scale 1).
pub const HEIGHT: f32 = 0.5;

const BASE: [u8; 3] = [82, 108, 46];
const TIP: [u8; 3] = [176, 170, 100];
/// Spine points per blade.
const SEGMENTS: usize = 4;

/// The grass tuft of `seed` (module docs): base at the origin, growing up +z.
pub fn grass_tuft(seed: u64) -> TriangleMesh {
    let mut rng = SplitMix64(seed);
    let blades = 24 + (rng.next_u64() % 17) as u32;
    let mut b = MeshBuilder::default();
    for _ in 0..blades {
        let azimuth = rng.next_f64() as f32 * std::f32::consts::TAU;
        let out = Vec3::new(azimuth.cos(), azimuth.sin(), 0.0);
        let at = out * (0.06 * rng.next_f64().sqrt() as f32) - Vec3::Z * 0.03;
        let height = 0.3 + 0.3 * rng.next_f64() as f32;
        let bend = (0.15 + 0.45 * rng.next_f64() as f32) * height;
        let half_width = 0.006 + 0.006 * rng.next_f64() as f32;
        let base = vary(BASE, 0.2, &mut rng);
        let tip = mix(base, TIP, 0.5 + 0.5 * rng.next_f64() as f32);
        let spine: Vec<Vec3> = (0..SEGMENTS)
            .map(|i| {
                let s = i as f32 / (SEGMENTS - 1) as f32;
                at + out * (bend * s * s) + Vec3::Z * (height * s * (1.0 - 0.25 * s * s))
            })
            .collect();
        let widths: Vec<f32> = (0..SEGMENTS)
            .map(|i| half_width * (1.0 - i as f32 / (SEGMENTS - 1) as f32))
            .collect();
        let colors: Vec<[u8; 3]> = (0..SEGMENTS)
            .map(|i| mix(base, tip, i as f32 / (SEGMENTS - 1) as f32))
            .collect();
        let side = Vec3::new(-out.y, out.x, 0.0);
        b.strip(&spine, &widths, side, &colors);
    }
    b.finish()
}
