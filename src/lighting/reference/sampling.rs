//! The random numbers and sample warps of the Monte Carlo reference (§9.2),
//! shared bit for bit with `glsl/lighting/reference.comp`: the PCG hash
//! (Jarzynski & Olano 2020), a per-texel key, stratified Hammersley points
//! with a per-texel Cranley–Patterson rotation, cosine-weighted hemisphere
//! and uniform sun-disc directions.

use glam::Vec3;

/// The "sample" index of the per-texel rotations.
const ROTATION_SAMPLE: u32 = 0x0FFF_FFFF;
/// Largest f32 below 1.
const ONE_MINUS_ULP: f32 = 0.999_999_94;

/// Random dimensions of a path: Hammersley pair 0 is the first direction,
/// pair 1 the disc point of the shadow ray at `x`; at bounce vertex `k`
/// (1, 2) the hashed dimensions `4k, 4k+1` pick the next direction and
/// `4k+2, 4k+3` the disc point of its shadow ray.
pub const fn bounce_dimension(vertex: u32) -> u32 {
    4 * vertex
}

/// PCG-RXS-M-XS hash of 32 bits.
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The key of texel `(c, r)` under `seed`.
pub fn texel_key(seed: u32, c: u32, r: u32) -> u32 {
    pcg_hash(pcg_hash(pcg_hash(seed) ^ c) ^ r)
}

/// Uniform in `[0, 1)` (24 bits): dimension `dim` of sample `sample`.
pub fn random(key: u32, sample: u32, dim: u32) -> f32 {
    let x = pcg_hash(key ^ pcg_hash(sample.wrapping_mul(16).wrapping_add(dim)));
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

fn fract(x: f32) -> f32 {
    x - x.floor()
}

/// Point `i` of the `n`-point Hammersley set, `((i + ½)/n, φ₂(i))`,
/// rotated toroidally by the texel's random offset number `pair`.
pub fn hammersley(key: u32, i: u32, n: u32, pair: u32) -> [f32; 2] {
    let a = (i as f32 + 0.5) / n as f32;
    let b = (i.reverse_bits() as f32 * 2.328_306_4e-10).min(ONE_MINUS_ULP);
    let ra = random(key, ROTATION_SAMPLE, 2 * pair);
    let rb = random(key, ROTATION_SAMPLE, 2 * pair + 1);
    [fract(a + ra).min(ONE_MINUS_ULP), fract(b + rb).min(ONE_MINUS_ULP)]
}

/// An orthonormal basis `(t, b)` completing unit `n` (Duff et al. 2017).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Cosine-weighted direction about unit `n` for `u ∈ [0, 1)²` (Malley):
/// density `max(0, n·ω)/π`.
pub fn cosine_direction(n: Vec3, u: [f32; 2]) -> Vec3 {
    let r = u[0].sqrt();
    let phi = std::f32::consts::TAU * u[1];
    let (t, b) = basis(n);
    let z = (1.0 - u[0]).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// A direction towards a point spread uniformly over the disc of angular
/// radius `radius` about unit `s` (small-angle: a uniform point on the
/// tangent disc).
pub fn disc_direction(s: Vec3, radius: f32, u: [f32; 2]) -> Vec3 {
    let r = radius * u[0].sqrt();
    let phi = std::f32::consts::TAU * u[1];
    let (t, b) = basis(s);
    (s + t * (r * phi.cos()) + b * (r * phi.sin())).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg_hash_known_values() {
        // Reference values of the published pcg_hash.
        assert_eq!(pcg_hash(0), 129_708_002);
        assert_ne!(pcg_hash(1), pcg_hash(2));
    }

    #[test]
    fn hammersley_is_stratified_in_both_axes() {
        let n = 64;
        let key = texel_key(7, 3, 4);
        let mut a = vec![false; n as usize];
        let mut b = vec![false; n as usize];
        for i in 0..n {
            let [u, v] = hammersley(key, i, n, 0);
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
            a[(u * n as f32) as usize] = true;
            b[(v * n as f32) as usize] = true;
        }
        assert!(a.iter().all(|&x| x) && b.iter().all(|&x| x));
    }

    #[test]
    fn cosine_directions_have_mean_cosine_two_thirds() {
        let n = Vec3::new(0.3, -0.2, 0.9).normalize();
        let key = texel_key(1, 2, 3);
        let count = 4096;
        let mean: f32 = (0..count)
            .map(|i| {
                let d = cosine_direction(n, hammersley(key, i, count, 0));
                assert!((d.length() - 1.0).abs() < 1e-5);
                d.dot(n)
            })
            .sum::<f32>()
            / count as f32;
        // E[cos θ] under the density cos θ/π is 2/3.
        assert!((mean - 2.0 / 3.0).abs() < 2e-3, "{mean}");
    }

    #[test]
    fn disc_directions_stay_on_the_disc() {
        let s = Vec3::new(0.5, 0.5, 0.7).normalize();
        for i in 0..64 {
            let d = disc_direction(s, 0.01, [random(1, i, 0), random(1, i, 1)]);
            assert!(d.dot(s) >= (0.0101f32).cos());
        }
    }
}
