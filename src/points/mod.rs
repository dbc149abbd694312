//! Points: sequential point trees and EWA splatting (dissertation §10.1–10.3;
//! `ALGORITHMS.md` §7–8) for vegetation, rocks and scans. Files follow the
//! pipeline of chapter 10, in two folders: [`build`] is the offline
//! preparation (inputs (PLY, OBJ) → surface samples (surfels) → normals and
//! radii → SPT build and file; rocks, plants, hybrid meshes, normal clusters), run
//! once at load or by `alpenglow spt build`; [`render`] is the per-frame
//! part (selection in `prepare`, then the splatting passes); [`vegetation`]
//! scatters plant prototypes over a terrain by its surface layers.

pub mod build;
pub mod render;
pub mod scene;
pub mod vegetation;

use glam::Vec3;

use build::clip::ClipLines;

/// A surface sample: an oriented disk with a colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surfel {
    pub position: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Disk radius (world units, > 0).
    pub radius: f32,
    /// sRGB colour.
    pub color: [u8; 3],
    /// Clip lines for sharp features (§10.2.4), in the tangent frame
    /// `build::clip::tangent_frame` of `normal`; [`ClipLines::NONE`] for none.
    pub clip: ClipLines,
}

/// An indexed triangle mesh as read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    /// Per-vertex normals, when the file had them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex sRGB colours, when the file had them.
    pub colors: Option<Vec<[u8; 3]>>,
    /// Counter-clockwise triangles (polygons are fanned, strips unrolled).
    pub triangles: Vec<[u32; 3]>,
}

/// Points as read from a file, attributes optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub colors: Option<Vec<[u8; 3]>>,
    pub radii: Option<Vec<f32>>,
    /// Per-point clip lines (§10.2.4), when the file had them.
    pub clip: Option<Vec<ClipLines>>,
}

#[cfg(test)]
mod tests;
