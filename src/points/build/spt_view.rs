//! The view-dependent error of sequential point trees (dissertation §10.1.4,
//! §10.1.7; `ALGORITHMS.md` §7).
//!
//! The geometric error `e_g = sqrt(e_p² + e_t²)` is the maximum over the
//! view angle of the text's split error `e_p·sin α + e_t·cos α` (Eq. 10.4;
//! α = ∠(v, n), v the view vector to the node, n its normal): the
//! perpendicular error projects with sin α (it shows at silhouettes), the
//! tangential one with cos α (it shrinks with foreshortening). §10.1.7: since
//! `e_g` bounds the split error, the CPU's prefix (sorted by the isotropic
//! `r_max`) stays valid and only the vertex stage's interval test changes.
//!
//! # The test (derived)
//!
//! With the split error a node's distances depend on the view: `r_min'(v) =
//! r_min(v)·ρ(v)` with `ρ = (e_p·sin α + e_t·cos α)/e_g ∈ [0, 1]` evaluated
//! at the node's own centre and normal, and `r_max'(c) = r_min'(v) + |p_c −
//! p_v|` for a child c of v (the root's stays ∞); a node is drawn iff
//! `r_min' ≤ r < r_max'`. The vertex stage reads the parent's record (its
//! index is stored with the node) to get `r_min'(parent)`. The hole-freeness
//! argument of the overlap term (`spt.rs`, "The overlap term") carries over
//! unchanged: it only uses `r_max'(c) = r_min'(v) + |p_c − p_v|`, leaves
//! with `r_min' = 0` and a root with `r_max' = ∞`, whatever `r_min'` is. As
//! `ρ ≤ 1`, `r_max' ≤ r_max`, so every node the test draws lies in the
//! isotropic prefix (§10.1.7's binary search is unchanged).
//!
//! # Isotropic nodes
//!
//! The colour term of §10.1.9 raises `e_g` to the diameter where the
//! children's colours differ; that error does not depend on the view. Such
//! nodes are recognised by `e_g > sqrt(e_p² + e_t²)` (the monotone clamp of
//! the build carries a descendant's colour floor up to every ancestor, and
//! it is the only way `e_g` can exceed the hypotenuse of the clamped `e_p`
//! and `e_t`), and keep the stored `r_min` and `r_max` (ρ = 1; their parent
//! is isotropic too, so the stored `r_max` is `r_min'(parent) + |p − p_parent|`).
//! The nodes of hybrid objects (§10.1.8), whose `r_min` carry the triangles'
//! floors, are all isotropic.
//!
//! # Encoding
//!
//! `ρ`'s two coefficients `a = e_p/e_g`, `b = e_t/e_g` (scaled so that
//! `a² + b² ≤ 1`) are rounded down to 15 bits each and packed with an
//! isotropic flag into one u32 ([`view_error_bits`]): bits 0–14 a, bits
//! 15–29 b, bit 31 isotropic (bit 30 stays 0, so as f32 bits the word is
//! never an infinity or NaN). Rounding down keeps `a·sin α + b·cos α ≤ 1`.

use glam::Vec3;

use super::spt::{SequentialPointTree, SptNode, NO_PARENT, ROOT_R_MAX};

/// Bit of [`view_error_bits`] for a node that keeps its stored interval.
pub const ISOTROPIC_BIT: u32 = 1 << 31;

/// Steps of a 15-bit coefficient.
const STEPS: f32 = 32767.0;

/// Relative margin by which `e_g` must exceed `sqrt(e_p² + e_t²)` to count
/// as raised by the colour term (the stored f32 values differ by rounding).
const COLOUR_MARGIN: f64 = 1e-6;

/// Whether `node` keeps its stored interval under the view-dependent test
/// (colour-raised error; see "Isotropic nodes").
pub fn is_isotropic(node: &SptNode) -> bool {
    let hypot = f64::from(node.e_p).hypot(f64::from(node.e_t));
    f64::from(node.e_g) > hypot * (1.0 + COLOUR_MARGIN)
}

/// The packed coefficients of `node` (see "Encoding"); `isotropic` forces the flag.
pub fn view_error_bits(node: &SptNode, isotropic: bool) -> u32 {
    if isotropic || is_isotropic(node) {
        return ISOTROPIC_BIT;
    }
    if node.e_g <= 0.0 || node.e_g.is_nan() {
        return 0;
    }
    let (a, b) = (
        f64::from(node.e_p) / f64::from(node.e_g),
        f64::from(node.e_t) / f64::from(node.e_g),
    );
    let norm = a.hypot(b).max(1.0);
    let q = |x: f64| ((x / norm) * f64::from(STEPS)).floor().clamp(0.0, f64::from(STEPS)) as u32;
    q(a) | q(b) << 15
}

/// `ρ = a·sin α + b·cos α` of packed `bits` for a node with unit normal `n`
/// seen along `v` (node centre − eye; any space with a uniform scale), as the
/// shaders compute it (`spt_view_ratio` in glsl/include/spt_interval.glsl);
/// 1 for isotropic nodes.
pub fn view_ratio(bits: u32, n: Vec3, v: Vec3) -> f32 {
    if bits & ISOTROPIC_BIT != 0 {
        return 1.0;
    }
    let a = (bits & 0x7fff) as f32 / STEPS;
    let b = ((bits >> 15) & 0x7fff) as f32 / STEPS;
    let c = (n.dot(v).abs() / v.length()).min(1.0);
    let s = (1.0 - c * c).max(0.0).sqrt();
    a * s + b * c
}

impl SequentialPointTree {
    /// CPU reference of the view-dependent vertex-stage test (see the module
    /// documentation): the indices of the nodes with `r_min' ≤ r < r_max'`
    /// for the eye at `eye` (object space, r the Euclidean eye distance), in
    /// list order. `isotropic` marks every node isotropic (hybrid objects).
    pub fn select_view_dependent(&self, eye: Vec3, isotropic: bool) -> Vec<usize> {
        let bits: Vec<u32> = self.nodes.iter().map(|n| view_error_bits(n, isotropic)).collect();
        let r_min = |i: usize| {
            let n = &self.nodes[i];
            n.r_min * view_ratio(bits[i], n.normal, n.position - eye)
        };
        (0..self.nodes.len())
            .filter(|&i| {
                let n = &self.nodes[i];
                let r = (n.position - eye).length();
                interval_contains(n, bits[i], r_min(i), r, |p| (r_min(p), self.nodes[p].position))
            })
            .collect()
    }
}

/// The view-dependent test of `node` (packed `bits`, view-dependent
/// `r_min`) at eye distance `r`; `parent(i)` gives the parent's `r_min'` and
/// centre.
fn interval_contains(node: &SptNode, bits: u32, r_min: f32, r: f32, parent: impl Fn(usize) -> (f32, Vec3)) -> bool {
    if bits & ISOTROPIC_BIT != 0 || node.parent == NO_PARENT || node.r_max >= ROOT_R_MAX {
        return node.r_min <= r && r < node.r_max;
    }
    let (parent_r_min, parent_position) = parent(node.parent as usize);
    r_min <= r && r < parent_r_min + (node.position - parent_position).length()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::points::build::clip::ClipLines;
    use crate::points::build::spt::{build_spt, SptOptions};
    use crate::points::Surfel;

    /// A wavy 1 × 1 sheet in the xy plane, jittered (the test scene of the GPU check too).
    pub(crate) fn wavy_sheet(count: usize) -> Vec<Surfel> {
        let side = (count as f64).sqrt().ceil() as usize;
        let spacing = 1.0 / side as f32;
        let mut rng = crate::random::SplitMix64(7);
        (0..side * side)
            .map(|i| {
                let (x, y) = ((i % side) as f32 + 0.5, (i / side) as f32 + 0.5);
                let jitter = |r: &mut crate::random::SplitMix64| (r.next_f64() as f32 - 0.5) * 0.3;
                let (x, y) = (
                    (x + jitter(&mut rng)) * spacing - 0.5,
                    (y + jitter(&mut rng)) * spacing - 0.5,
                );
                let z = 0.01 * (9.0 * x).sin() * (7.0 * y).cos();
                let n = Vec3::new(
                    -0.09 * (9.0 * x).cos() * (7.0 * y).cos(),
                    0.07 * (9.0 * x).sin() * (7.0 * y).sin(),
                    1.0,
                );
                Surfel {
                    position: Vec3::new(x, y, z),
                    normal: n.normalize(),
                    radius: 0.9 * spacing,
                    color: [128, 128, 128],
                    clip: ClipLines::NONE,
                }
            })
            .collect()
    }

    fn tree() -> SequentialPointTree {
        let options = SptOptions {
            epsilon: 0.004,
            ..SptOptions::default()
        };
        build_spt(&wavy_sheet(4096), &options, &mut |_| {}).unwrap()
    }

    fn leaves_covered(tree: &SequentialPointTree, selected: &[usize]) -> bool {
        let mut covered = vec![false; tree.nodes.len()];
        for &i in selected {
            covered[i] = true;
        }
        (0..tree.nodes.len()).filter(|&i| tree.nodes[i].is_leaf).all(|leaf| {
            let mut i = leaf;
            loop {
                if covered[i] {
                    return true;
                }
                if tree.nodes[i].parent == NO_PARENT {
                    return false;
                }
                i = tree.nodes[i].parent as usize;
            }
        })
    }

    #[test]
    fn ratios_are_bounded_and_exact_at_the_axes() {
        let tree = tree();
        for n in tree.nodes.iter().filter(|n| !n.is_leaf) {
            let bits = view_error_bits(n, false);
            assert_eq!(bits & (1 << 30), 0);
            assert!(f32::from_bits(bits).is_finite());
            for k in 0..=16 {
                let alpha = std::f32::consts::FRAC_PI_2 * k as f32 / 16.0;
                let v = alpha.sin() * Vec3::X.any_orthonormal_vector() + alpha.cos() * Vec3::X;
                let nrm = Vec3::X;
                let rho = view_ratio(bits, nrm, v);
                assert!(rho <= 1.0 + 1e-6, "{rho}");
            }
            if !is_isotropic(n) && n.e_g > 0.0 {
                // Face-on: ρ = e_t/e_g; edge-on: ρ = e_p/e_g (to the 15-bit step).
                let face_on = view_ratio(bits, Vec3::Z, Vec3::Z);
                let edge_on = view_ratio(bits, Vec3::Z, Vec3::X);
                assert!((face_on - n.e_t / n.e_g).abs() < 1e-4, "{face_on} vs {}", n.e_t / n.e_g);
                assert!((edge_on - n.e_p / n.e_g).abs() < 1e-4, "{edge_on} vs {}", n.e_p / n.e_g);
            }
        }
        assert_eq!(view_error_bits(&tree.nodes[0], true), ISOTROPIC_BIT);
    }

    /// The view-dependent selection leaves no leaf uncovered at any eye
    /// (the overlap argument), draws fewer nodes than the isotropic one at a
    /// grazing view, and stays inside the isotropic prefix.
    #[test]
    fn view_dependent_selection_covers_every_leaf_and_saves_at_grazing() {
        let tree = tree();
        let eyes = [
            Vec3::new(0.0, 0.0, 1.5),
            Vec3::new(0.0, -2.0, 0.15),
            Vec3::new(1.0, -1.0, 0.05),
            Vec3::new(0.2, 0.1, 0.3),
        ];
        for eye in eyes {
            let iso = tree.select(|p| (p - eye).length());
            let vd = tree.select_view_dependent(eye, false);
            assert!(leaves_covered(&tree, &vd), "eye {eye}: a leaf is uncovered");
            assert!(leaves_covered(&tree, &iso));
            let prefix = tree.prefix_len(tree.min_eye_distance(eye));
            assert!(vd.iter().all(|&i| i < prefix), "eye {eye}: outside the prefix");
            assert!(vd.len() <= iso.len(), "eye {eye}: {} > {}", vd.len(), iso.len());
            // Marked isotropic, the test is the stored one.
            assert_eq!(tree.select_view_dependent(eye, true), iso);
        }
        let grazing = Vec3::new(0.0, -2.0, 0.15);
        let (iso, vd) = (
            tree.select(|p| (p - grazing).length()).len(),
            tree.select_view_dependent(grazing, false).len(),
        );
        assert!((vd as f64) < 0.8 * iso as f64, "grazing: {vd} of {iso}");
    }
}
