//! The simulator AOVs of a view (camera sensors in the manner of CARLA's:
//! depth, semantic and instance segmentation, normals, optical flow), held
//! in [`super::SceneTargets`] next to the radiance:
//!
//! | target | format | what | written by |
//! |---|---|---|---|
//! | `normal` | RGBA16F | world-space shading normal, w = 1; 0 for sky | `sky`, `terrain.draw`, points passes |
//! | `ids` | RG32UI | semantic class, instance id | `sky`, `terrain.draw`, points passes |
//! | `motion` | RG32F | pixels from the previous frame's position | `aovs` |
//! | `distance` | R32F | metres from the eye along the pixel's ray, +inf for sky | `aovs` |
//!
//! Semantic classes (this table is also `glsl/include/aov.glsl` and the
//! README's "AOVs"):
//!
//! | class | what |
//! |---|---|
//! | 0 | sky (exactly where view depth is +inf) |
//! | 1 | terrain whose surface layer is unknown: a debug view (`--view importance` …), or no atlas tile resident yet |
//! | 2 | rock (the procedural boulders, §6.1.4) |
//! | 3 | scan: any other point object (PLY, OBJ, SPT files) |
//! | 4 | vegetation (the procedural plants, `crate::points::vegetation`) |
//! | 10 + k | terrain whose dominant surface layer is layer k of the depth-first layer tree (§8.2) |
//!
//! The dominant layer of a point is the one with the largest final share
//! of its colour: layer k of the depth-first walk contributes
//! `C_k · Π_{j>k} (1 − C_j)` (the later layers blend over it), and the
//! first of equal shares wins. Atlas texturing stores it per texel in the
//! normal texture's alpha (read with nearest filtering); direct texturing
//! evaluates it per pixel (`crate::surface::dominant`). Classic
//! texturing (§7.4.3) has four surface types, reported as the same-named
//! layers of the built-in tree (`crate::terrain::shading::CLASSIC_LAYERS`)
//! so that classes mean the same in every mode.
//!
//! Instance ids: the 1-based index of a point instance in the scene's
//! `PointScene::instances` (one per `--points`
//! file; one per boulder; one per plant), 0 for terrain and sky. Point objects blended by
//! EWA splatting never average ids: they are written by `points.visibility`,
//! where the nearest surfel wins.

/// Class of sky pixels.
pub const CLASS_SKY: u32 = 0;
/// Class of terrain pixels whose surface layer is unknown.
pub const CLASS_TERRAIN: u32 = 1;
/// Class of procedural rocks.
pub const CLASS_ROCK: u32 = 2;
/// Class of other point objects (scans, meshes).
pub const CLASS_SCAN: u32 = 3;
/// Class of procedural plants.
pub const CLASS_VEGETATION: u32 = 4;
/// Class of terrain whose dominant layer is layer 0; layer k is this + k.
pub const CLASS_LAYER_BASE: u32 = 10;
