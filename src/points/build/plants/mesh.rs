//! The pieces procedural plants are made of (dissertation §10.1's "meshes
//! sampled into point trees"; plant models of §6.2.1): tapered tubes for
//! trunks, stems and branches, and open two-sided sheets for leaves, needle
//! sprays and grass blades, each with a per-vertex sRGB colour.

use glam::Vec3;

use crate::points::TriangleMesh;
use crate::random::SplitMix64;

/// A mesh under construction: positions, unit normals, sRGB colours and
/// counter-clockwise triangles.
#[derive(Default)]
pub struct MeshBuilder {
    mesh: TriangleMesh,
    normals: Vec<Vec3>,
    colors: Vec<[u8; 3]>,
}

/// Two unit vectors perpendicular to unit `axis` and to each other.
pub fn perpendiculars(axis: Vec3) -> (Vec3, Vec3) {
    let helper = if axis.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
    let u = axis.cross(helper).normalize();
    (u, axis.cross(u))
}

/// `color` with each channel moved by up to ±`amount` (same offset for all
/// three, so hue stays), clamped to 8 bits.
pub fn vary(color: [u8; 3], amount: f64, rng: &mut SplitMix64) -> [u8; 3] {
    let offset = (rng.next_f64() * 2.0 - 1.0) * amount;
    color.map(|c| (f64::from(c) * (1.0 + offset)).round().clamp(0.0, 255.0) as u8)
}

/// Linear blend of two sRGB colours (t in [0, 1]).
pub fn mix(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|i| (f32::from(a[i]) * (1.0 - t) + f32::from(b[i]) * t).round() as u8)
}

impl MeshBuilder {
    fn vertex(&mut self, p: Vec3, n: Vec3, color: [u8; 3]) -> u32 {
        self.mesh.positions.push(p);
        self.normals.push(n.normalize_or_zero());
        self.colors.push(color);
        (self.mesh.positions.len() - 1) as u32
    }

    /// A tube along the polyline `points` with radii `radii` (one per point;
    /// at least two points), `sides` around, closed by a cone tip where the
    /// last radius is 0. Outward normals.
    pub fn tube(&mut self, points: &[Vec3], radii: &[f32], sides: u32, color: [u8; 3]) {
        if points.len() < 2 || radii.len() != points.len() || sides < 3 {
            return;
        }
        let first = self.mesh.positions.len() as u32;
        for (i, (&p, &r)) in points.iter().zip(radii).enumerate() {
            let axis = if i + 1 < points.len() {
                points[i + 1] - p
            } else {
                p - points[i - 1]
            }
            .normalize_or_zero();
            if axis == Vec3::ZERO {
                return;
            }
            let (u, v) = perpendiculars(axis);
            for k in 0..sides {
                let angle = k as f32 / sides as f32 * std::f32::consts::TAU;
                let n = u * angle.cos() + v * angle.sin();
                self.vertex(p + n * r, n, color);
            }
        }
        for i in 0..points.len() as u32 - 1 {
            for k in 0..sides {
                let a = first + i * sides + k;
                let b = first + i * sides + (k + 1) % sides;
                let (c, d) = (a + sides, b + sides);
                self.mesh.triangles.push([a, b, d]);
                self.mesh.triangles.push([a, d, c]);
            }
        }
    }

    /// An open sheet along the polyline `spine` with half widths `half_widths`
    /// (one per point) across `side`, a unit vector: a strip of quads, both
    /// faces of which are the surface (drawn two-sided). `colors` per point.
    pub fn strip(&mut self, spine: &[Vec3], half_widths: &[f32], side: Vec3, colors: &[[u8; 3]]) {
        let n = spine.len();
        if n < 2 || half_widths.len() != n || colors.len() != n {
            return;
        }
        let first = self.mesh.positions.len() as u32;
        for i in 0..n {
            let along = if i + 1 < n {
                spine[i + 1] - spine[i]
            } else {
                spine[i] - spine[i - 1]
            };
            let normal = along.cross(side);
            let w = side * half_widths[i];
            self.vertex(spine[i] - w, normal, colors[i]);
            self.vertex(spine[i] + w, normal, colors[i]);
        }
        for i in 0..n as u32 - 1 {
            let (a, b, c, d) = (first + 2 * i, first + 2 * i + 1, first + 2 * i + 2, first + 2 * i + 3);
            self.mesh.triangles.push([a, b, d]);
            self.mesh.triangles.push([a, d, c]);
        }
    }

    /// A leaf: a diamond of two triangles from `base` along unit `direction`,
    /// `length` long and `width` wide, its blade spanned with `side`.
    pub fn leaf(&mut self, base: Vec3, direction: Vec3, side: Vec3, (length, width): (f32, f32), color: [u8; 3]) {
        let side = (side - direction * side.dot(direction)).normalize_or_zero();
        if side == Vec3::ZERO {
            return;
        }
        let normal = direction.cross(side);
        let mid = base + direction * (0.45 * length);
        let a = self.vertex(base, normal, color);
        let b = self.vertex(mid + side * (0.5 * width), normal, color);
        let c = self.vertex(base + direction * length, normal, color);
        let d = self.vertex(mid - side * (0.5 * width), normal, color);
        self.mesh.triangles.push([a, d, c]);
        self.mesh.triangles.push([a, c, b]);
    }

    /// The finished mesh (with vertex normals and colours).
    pub fn finish(mut self) -> TriangleMesh {
        self.mesh.normals = Some(self.normals);
        self.mesh.colors = Some(self.colors);
        self.mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_have_matching_attributes_and_valid_indices() {
        let mut b = MeshBuilder::default();
        b.tube(
            &[Vec3::ZERO, Vec3::Z, Vec3::new(0.0, 0.3, 2.0)],
            &[0.1, 0.08, 0.0],
            5,
            [90, 60, 40],
        );
        b.strip(
            &[Vec3::ZERO, Vec3::X],
            &[0.1, 0.0],
            Vec3::Y,
            &[[0, 100, 0], [50, 150, 0]],
        );
        b.leaf(Vec3::ZERO, Vec3::X, Vec3::Y, (0.2, 0.1), [0, 120, 0]);
        // Degenerate input adds nothing.
        b.tube(&[Vec3::ZERO], &[0.1], 5, [0; 3]);
        b.leaf(Vec3::ZERO, Vec3::X, Vec3::X, (0.2, 0.1), [0; 3]);
        let mesh = b.finish();
        let n = mesh.positions.len();
        assert_eq!(n, 15 + 4 + 4);
        assert_eq!(mesh.triangles.len(), 20 + 2 + 2);
        assert_eq!(mesh.normals.as_ref().map(Vec::len), Some(n));
        assert_eq!(mesh.colors.as_ref().map(Vec::len), Some(n));
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
        // Tube normals point away from the axis.
        let normals = mesh.normals.as_ref().unwrap();
        for (n, p) in normals.iter().zip(&mesh.positions).take(5) {
            assert!(n.dot(*p) > 0.0 && (n.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn colour_helpers_stay_in_range() {
        let mut rng = SplitMix64(3);
        for _ in 0..100 {
            let c = vary([250, 10, 128], 0.3, &mut rng);
            assert!(c[0] >= 175 && c[1] <= 13);
        }
        assert_eq!(mix([0, 0, 0], [200, 100, 50], 0.5), [100, 50, 25]);
        assert_eq!(mix([0, 0, 0], [200, 100, 50], 2.0), [200, 100, 50]);
    }
}
