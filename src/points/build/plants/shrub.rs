//! A broadleaf shrub as a small bracketed L-system (Prusinkiewicz and
//! Lindenmayer 1990; dissertation §6.2.1): the axiom `S` is 4–6 stems
//! leaning 12–40° out of the ground; the production
//! `B(l) → F(l) [+B(0.62·l)] [−B(0.62·l)] B(0.7·l)` (a segment, two side
//! branches rolled at random about the parent and pitched 30–50° out, and
//! a continuation bent up to 15°) is applied twice, and every terminal
//! branch carries 7–11 leaves (diamonds 0.16 × 0.09 m, drawn two-sided).
//! Height about 1.8 m at scale 1.

use glam::{Quat, Vec3};

use super::mesh::{perpendiculars, vary, MeshBuilder};
use crate::points::TriangleMesh;
use crate::random::SplitMix64;

/// Nominal height in metres (scale 1).
pub const HEIGHT: f32 = 1.8;

const STEM: [u8; 3] = [120, 98, 76];
const LEAF: [u8; 3] = [84, 122, 52];
const LEAF_LIGHT: [u8; 3] = [126, 154, 62];

/// Rewriting steps of the production.
const DEPTH: u32 = 2;

/// The shrub of `seed` (module docs): base at the origin, growing up +z.
pub fn shrub(seed: u64) -> TriangleMesh {
    let mut rng = SplitMix64(seed);
    let stems = 4 + (rng.next_u64() % 3) as u32;
    let mut b = MeshBuilder::default();
    let phase = rng.next_f64() as f32 * std::f32::consts::TAU;
    for k in 0..stems {
        let azimuth = phase + (k as f32 + 0.5 * rng.next_f64() as f32) / stems as f32 * std::f32::consts::TAU;
        let lean = (12.0 + 28.0 * rng.next_f64() as f32).to_radians();
        let dir = Vec3::new(azimuth.cos() * lean.sin(), azimuth.sin() * lean.sin(), lean.cos());
        let length = 0.75 * (0.8 + 0.4 * rng.next_f64() as f32);
        let base = Vec3::new(0.0, 0.0, -0.1);
        branch(&mut b, base, dir, length, DEPTH, &mut rng);
    }
    b.finish()
}

/// One `B(length)` at `base` along unit `dir`, rewritten `depth` more times.
fn branch(b: &mut MeshBuilder, base: Vec3, dir: Vec3, length: f32, depth: u32, rng: &mut SplitMix64) {
    let tip = base + dir * length;
    let radius = 0.012 * length + 0.004;
    b.tube(&[base, tip], &[radius, 0.7 * radius], 3, STEM);
    if depth == 0 {
        leaves(b, base, dir, length, rng);
        return;
    }
    let (u, v) = perpendiculars(dir);
    for side in [1.0f32, -1.0] {
        let roll = rng.next_f64() as f32 * std::f32::consts::TAU;
        let axis = u * roll.cos() + v * roll.sin();
        let pitch = side * (30.0 + 20.0 * rng.next_f64() as f32).to_radians();
        let child = (Quat::from_axis_angle(axis, pitch) * dir).normalize();
        // Side branches start along the segment.
        let at = base + dir * (length * (0.45 + 0.4 * rng.next_f64() as f32));
        branch(b, at, child, 0.62 * length, depth - 1, rng);
    }
    let bend_axis = dir.cross(Vec3::Z).normalize_or(u);
    let bend = (15.0 * (rng.next_f64() as f32 * 2.0 - 1.0)).to_radians();
    let next = (Quat::from_axis_angle(bend_axis, bend) * dir).normalize();
    branch(b, tip, next, 0.7 * length, depth - 1, rng);
}

/// The leaves of a terminal branch: along its outer 60 %, pointing out at random.
fn leaves(b: &mut MeshBuilder, base: Vec3, dir: Vec3, length: f32, rng: &mut SplitMix64) {
    let count = 7 + (rng.next_u64() % 5) as u32;
    let (u, v) = perpendiculars(dir);
    for i in 0..count {
        let at = base + dir * (length * (0.4 + 0.6 * (i as f32 + 0.5) / count as f32));
        let roll = rng.next_f64() as f32 * std::f32::consts::TAU;
        let out = u * roll.cos() + v * roll.sin();
        let leaf_dir = (dir * 0.6 + out + Vec3::Z * 0.3).normalize();
        let side = out.cross(leaf_dir).normalize_or(u);
        let size = 0.85 + 0.3 * rng.next_f64() as f32;
        let color = if rng.next_f64() < 0.3 { LEAF_LIGHT } else { LEAF };
        let color = vary(color, 0.18, rng);
        b.leaf(at, leaf_dir, side, (0.16 * size, 0.09 * size), color);
    }
}
