//! Offline preparation of point objects (dissertation §10.1; `ALGORITHMS.md`
//! §7): everything that runs once, at load or in `alpenglow spt build`, and
//! never per frame. The files follow chapter 10's pipeline: inputs (PLY,
//! OBJ) → surfels (even mesh sampling, clip lines at creases; PCA normals and
//! neighbour radii for clouds) → sequential point tree and its file; beside
//! it procedural rocks (§6.1.4) and plants (chapter 10 introduction,
//! Fig. 10.12), hybrid point–polygon meshes (§10.1.8) and normal clusters
//! (§10.1.10). [`plan`] checks an input and estimates a build's cost before
//! any sampling.

pub mod clip;
pub mod clusters;
pub mod estimate;
pub mod hybrid;
pub mod input;
pub mod mesh_out;
pub mod plan;
pub mod plants;
pub mod rocks;
pub mod sampling;
pub mod spt;
pub mod spt_file;
pub mod spt_view;
