//! What the points passes read on the GPU (`glsl/include/splat.glsl`): the
//! splat lists of all objects in one buffer, and per frame the camera and
//! the instances to draw.

use bytemuck::{Pod, Zeroable};
use glam::{DMat3, DMat4, DVec3};

use super::SplatSettings;
use crate::points::build::hybrid::HybridMesh;
use crate::points::build::spt::{SptNode, NO_PARENT};
use crate::points::build::spt_view::view_error_bits;
use crate::view::View;

/// One splat: an SPT node (§10.1.3) as the vertex stage reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuSplat {
    /// Object-space centre, r_min.
    pub position_rmin: [f32; 4],
    /// Object-space unit normal, r_max.
    pub normal_rmax: [f32; 4],
    /// Disk radius, sRGB colour (u32 bits `r | g << 8 | b << 16`),
    /// view-dependent error bits, parent index (u32 bits; see [`pack_nodes`]).
    pub radius_color: [f32; 4],
    /// Clip lines (`crate::points::build::clip::ClipLines::packed`).
    pub clip: [f32; 4],
}

/// The splat list of `nodes`, in list order (decreasing r_max, per normal
/// cluster when clustered). With `view_dependent = Some((first, isotropic))`
/// each record also carries its view-dependent error bits
/// ([`view_error_bits`], all isotropic for hybrid objects) and its parent's
/// index in the splat buffer (the list starts at `first`; the root's is its
/// own) for the view-dependent test (glsl/include/spt_interval.glsl);
/// otherwise those two words are 0.
pub fn pack_nodes(nodes: &[SptNode], view_dependent: Option<(u32, bool)>) -> Vec<GpuSplat> {
    nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let (bits, parent) = match view_dependent {
                // Hybrid lists may have lost parents; their isotropic nodes never read them.
                Some((_, true)) => (view_error_bits(n, true), 0),
                Some((first, false)) => {
                    let parent = if n.parent == NO_PARENT { i as u32 } else { n.parent };
                    (view_error_bits(n, false), first.saturating_add(parent))
                }
                None => (0, 0),
            };
            GpuSplat {
                position_rmin: n.position.extend(n.r_min).to_array(),
                normal_rmax: n.normal.extend(n.r_max).to_array(),
                radius_color: [
                    0.5 * n.diameter,
                    color_bits(n.color),
                    f32::from_bits(bits),
                    f32::from_bits(parent),
                ],
                clip: n.clip.packed(),
            }
        })
        .collect()
}

/// One triangle of a hybrid object (§10.1.8; `HybridTriangle` in glsl/include/hybrid.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuTriangle {
    /// Object-space corners; w: `r_max = s/ε`, the surfel radius, 0.
    pub positions: [[f32; 4]; 3],
    /// Object-space unit vertex normals; w: sRGB colour (u32 bits `r | g << 8 | b << 16`).
    pub normals: [[f32; 4]; 3],
}

fn color_bits([r, g, b]: [u8; 3]) -> f32 {
    f32::from_bits(u32::from(r) | u32::from(g) << 8 | u32::from(b) << 16)
}

/// The triangle list of a hybrid object at threshold `epsilon`, in its
/// order (decreasing `r_max`).
pub fn pack_triangles(hybrid: &HybridMesh, epsilon: f32) -> Vec<GpuTriangle> {
    hybrid
        .triangles
        .iter()
        .map(|t| {
            let w = [HybridMesh::triangle_r_max(t, epsilon), hybrid.surfel_radius, 0.0];
            GpuTriangle {
                positions: [0, 1, 2].map(|i| t.positions[i].extend(w[i]).to_array()),
                normals: [0, 1, 2].map(|i| t.normals[i].extend(color_bits(t.colors[i])).to_array()),
            }
        })
        .collect()
}

/// Per-frame constants (`PointFrame` in splat.glsl, before the instances).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameHeader {
    /// Rows of K (camera → homogeneous pixel coordinates, pixel (0, 0) the
    /// top-left corner of the image).
    pub k: [[f32; 4]; 3],
    /// Rows of K⁻¹.
    pub k_inv: [[f32; 4]; 3],
    /// P22, P32 (camera z → depth buffer value), visibility offset (in splat
    /// radii), kernel cut-off F_G.
    pub depth: [f32; 4],
    /// Width, height, largest point size, near plane.
    pub viewport: [f32; 4],
    /// x: storage handle of the view's lighting constants (written by the
    /// shading pass that declares them); y: 1 shaded, 0 unlit (albedo);
    /// z: the splat kernel ([`super::SplatKernel::code`]); w: the interval
    /// test ([`super::SptError::code`]).
    pub lighting: [u32; 4],
    /// Rows of the camera → world rotation.
    pub camera_to_world: [[f32; 4]; 3],
    /// World eye position; w = 1 two-sided splats, 0 back-facing splats culled.
    pub eye: [f32; 4],
}

/// One drawn instance (`Instance` in splat.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuInstance {
    /// Object → camera, column-major.
    pub model_view: [f32; 16],
    /// Scale, first splat (u32 bits), prefix length (u32 bits), first hybrid triangle (u32 bits).
    pub params: [f32; 4],
    /// Semantic class, instance id (1-based index of the scene's instance;
    /// `crate::view::aov`), 1 when the object is two-sided (drawn so
    /// whatever the frame says), 0.
    pub ids: [u32; 4],
}

/// Bytes of [`FrameHeader`].
pub const HEADER_BYTES: u64 = std::mem::size_of::<FrameHeader>() as u64;
/// Bytes of [`GpuInstance`].
pub const INSTANCE_BYTES: u64 = std::mem::size_of::<GpuInstance>() as u64;

/// Entries of the Gaussian lookup table (`GAUSSIAN_TABLE_SIZE` in splat.glsl).
pub const GAUSSIAN_TABLE_SIZE: usize = 256;

/// `exp(−r²/2)` at `r² = F_G²·i/(n−1)`, i = 0..n (§10.2.2: the weight comes
/// from a lookup table).
pub fn gaussian_table(cutoff: f32) -> Vec<f32> {
    let n = GAUSSIAN_TABLE_SIZE;
    (0..n)
        .map(|i| (-0.5 * f64::from(cutoff * cutoff) * i as f64 / (n - 1) as f64).exp() as f32)
        .collect()
}

/// The view's view matrix (world → camera, right-handed, looking down −z)
/// and its pinhole intrinsics K, both in f64.
pub fn view_and_intrinsics(view: &View) -> (DMat4, DMat3) {
    let camera = &view.camera;
    let matrix = DMat4::look_at_rh(camera.eye, camera.target, camera.up);
    let k = view.intrinsics();
    // Continuous pixel position (the image spans 0..w; OpenCV's pixel
    // centres are at integers): x = cx + ½ + fx·X/(−Z), y = cy + ½ − fy·Y/(−Z).
    let k = DMat3::from_cols(
        DVec3::new(k.fx, 0.0, 0.0),
        DVec3::new(0.0, -k.fy, 0.0),
        DVec3::new(-(k.cx + 0.5), -(k.cy + 0.5), -1.0),
    );
    (matrix, k)
}

/// The header of a frame (without the lighting constants' handle), and
/// the world → camera matrix it was built from.
pub fn frame_header(view: &View, settings: &SplatSettings, max_point_size: f32) -> (FrameHeader, DMat4) {
    let (camera, width, height) = (&view.camera, view.width, view.height);
    let (view, k) = view_and_intrinsics(view);
    let k_inv = k.inverse();
    let rows = |m: DMat3| {
        let t = m.transpose();
        [t.x_axis, t.y_axis, t.z_axis].map(|r| r.as_vec3().extend(0.0).to_array())
    };
    let view3 = DMat3::from_mat4(view);
    let near = camera.near;
    // Reversed depth (crate::view::depth): depth = (p22·z + p32) / −z.
    let (p22, p32) = crate::view::depth::depth_row(camera.near, camera.far);
    let header = FrameHeader {
        k: rows(k),
        k_inv: rows(k_inv),
        depth: [p22 as f32, p32 as f32, settings.visibility_offset, settings.cutoff],
        viewport: [width as f32, height as f32, max_point_size, near as f32],
        lighting: [0, settings.shaded as u32, settings.kernel.code(), settings.error.code()],
        camera_to_world: rows(view3.transpose()),
        eye: camera
            .eye
            .as_vec3()
            .extend(if settings.two_sided { 1.0 } else { 0.0 })
            .to_array(),
    };
    (header, view)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::Camera;

    #[test]
    fn intrinsics_agree_with_the_view_projection() {
        let camera = Camera {
            eye: DVec3::new(10.0, -20.0, 30.0),
            target: DVec3::new(100.0, 50.0, 0.0),
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 0.5,
            far: 5000.0,
        };
        let (w, h) = (640, 360);
        let v = View::new(camera, w, h);
        let (view, k) = view_and_intrinsics(&v);
        let clip_of = v.view_proj_f64();
        for p in [DVec3::new(120.0, 40.0, 5.0), DVec3::new(90.0, 80.0, 10.0)] {
            let c = clip_of * p.extend(1.0);
            let ndc = c.truncate() / c.w;
            let expected = ((ndc.x + 1.0) * 0.5 * w as f64, (ndc.y + 1.0) * 0.5 * h as f64);
            let x = k * view.transform_point3(p);
            let got = (x.x / x.z, x.y / x.z);
            assert!((got.0 - expected.0).abs() < 1e-3 && (got.1 - expected.1).abs() < 1e-3);
            let z = view.transform_point3(p).z;
            let (header, _) = frame_header(&v, &SplatSettings::default(), 64.0);
            let depth = (f64::from(header.depth[0]) * z + f64::from(header.depth[1])) / -z;
            assert!((depth - ndc.z).abs() < 1e-5, "{depth} vs {}", ndc.z);
        }
    }

    #[test]
    fn gaussian_table_spans_the_cutoff() {
        let t = gaussian_table(1.5);
        assert_eq!(t.len(), GAUSSIAN_TABLE_SIZE);
        assert_eq!(t[0], 1.0);
        assert!((t[GAUSSIAN_TABLE_SIZE - 1] - (-1.125f32).exp()).abs() < 1e-6);
    }
}
