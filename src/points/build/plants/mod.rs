//! Procedural plants as sequential point trees (dissertation chapter 10
//! introduction and Fig. 10.12: "the Sequential Point Tree data structure is
//! used for the point-based rendering of the shrubs"; plant models §6.2.1):
//! each model is generated as a triangle mesh with per-vertex colours
//! (bark, needles, leaves, grass), sampled into surfels and built into a
//! point tree (§10.1), optionally hybrid (§10.1.8: leaves and blades that
//! are large in the image stay triangles).
//!
//! Models ([`PlantModel`]): a [`conifer`] after Weber and Penn's parametric
//! tree, a [`shrub`] from a bracketed L-system, a [`grass`] tuft of bending
//! blades. Leaves, needle sprays and blades are open sheets, so plant
//! objects are drawn two-sided. Everything is deterministic per seed.
//!
//! [`scatter`] places plants over a terrain by the surface-layer tree.

pub mod conifer;
pub mod grass;
pub mod mesh;
pub mod scatter;
pub mod shrub;

use super::hybrid::build_hybrid;
use super::sampling::{sample_mesh, SamplingMethod, SamplingOptions};
use super::spt::{build_spt, SequentialPointTree, SptOptions};
use crate::error::{Error, Result};
use crate::points::build::hybrid::HybridMesh;
use crate::points::TriangleMesh;
use crate::surface::plants::PlantModel;

impl PlantModel {
    /// Height in metres at scale 1.
    pub fn nominal_height(self) -> f32 {
        match self {
            PlantModel::Conifer => conifer::HEIGHT,
            PlantModel::Shrub => shrub::HEIGHT,
            PlantModel::GrassTuft => grass::HEIGHT,
        }
    }

    /// Surfels sampled per prototype by default: enough for a hole-free
    /// plant a few hundred pixels tall (trees have more surface).
    pub fn default_samples(self) -> usize {
        match self {
            PlantModel::Conifer => 12_000,
            PlantModel::Shrub => 6_000,
            PlantModel::GrassTuft => 2_000,
        }
    }
}

/// The mesh of `model` for `seed`: base at the origin (stems reach a little
/// below it), up +z, counter-clockwise triangles with vertex normals and
/// sRGB vertex colours.
pub fn generate_plant(model: PlantModel, seed: u64) -> TriangleMesh {
    match model {
        PlantModel::Conifer => conifer::conifer(seed),
        PlantModel::Shrub => shrub::shrub(seed),
        PlantModel::GrassTuft => grass::grass_tuft(seed),
    }
}

/// A plant's point tree, and its triangles when built hybrid (§10.1.8).
pub struct PlantTree {
    pub tree: SequentialPointTree,
    pub hybrid: Option<HybridMesh>,
}

/// Samples the plant `model` of `seed` into `samples` surfels (stratified)
/// and builds its point tree with `spt`, hybrid when `hybrid`.
pub fn build_plant_tree(
    model: PlantModel,
    seed: u64,
    samples: usize,
    hybrid: bool,
    spt: &SptOptions,
) -> Result<PlantTree> {
    let mesh = generate_plant(model, seed);
    let in_model = |e: Error| Error::invalid(format!("plant {}", model.name()), e.to_string());
    let sampling = SamplingOptions {
        count: samples,
        method: SamplingMethod::Stratified,
        seed,
    };
    if hybrid {
        let (tree, mesh) = build_hybrid(&mesh, &sampling, spt, &mut |_| {}).map_err(in_model)?;
        return Ok(PlantTree {
            tree,
            hybrid: Some(mesh),
        });
    }
    let surfels = sample_mesh(&mesh, &sampling).map_err(in_model)?;
    let tree = build_spt(&surfels, spt, &mut |_| {}).map_err(in_model)?;
    Ok(PlantTree { tree, hybrid: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn bounds(mesh: &TriangleMesh) -> (Vec3, Vec3) {
        mesh.positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            })
    }

    #[test]
    fn models_are_deterministic_sized_and_coloured() {
        for model in PlantModel::ALL {
            assert_eq!(PlantModel::from_name(model.name()), Some(model));
            let a = generate_plant(model, 7);
            assert_eq!(a, generate_plant(model, 7), "{model:?}");
            assert_ne!(a.positions, generate_plant(model, 8).positions, "{model:?}");
            let (lo, hi) = bounds(&a);
            let h = model.nominal_height();
            assert!(hi.z > 0.6 * h && hi.z < 1.4 * h, "{model:?}: top {}", hi.z);
            assert!(lo.z < 0.0 && lo.z > -0.6, "{model:?}: bottom {}", lo.z);
            // Roughly centred on the z axis.
            let mid = (lo + hi) * 0.5;
            assert!(mid.x.abs() < 0.3 * h && mid.y.abs() < 0.3 * h, "{model:?}: {mid}");
            let colors = a.colors.as_ref().unwrap();
            assert_eq!(colors.len(), a.positions.len());
            // Mostly green: more green than blue and red on most vertices.
            let green = colors.iter().filter(|c| c[1] > c[2] && c[1] >= c[0]).count();
            assert!(green * 2 > colors.len(), "{model:?}: {green} of {}", colors.len());
            assert!(a.positions.iter().all(|p| p.is_finite()));
        }
        assert_eq!(PlantModel::from_name("oak"), None);
    }

    #[test]
    fn plant_trees_build_points_only_and_hybrid() {
        let spt = SptOptions::default();
        let plain = build_plant_tree(PlantModel::GrassTuft, 3, 800, false, &spt).unwrap();
        assert!(plain.hybrid.is_none() && plain.tree.nodes.len() >= 800);
        let hybrid = build_plant_tree(PlantModel::Shrub, 3, 1500, true, &spt).unwrap();
        assert!(hybrid.hybrid.as_ref().is_some_and(|h| !h.triangles.is_empty()));
        assert!(build_plant_tree(PlantModel::Shrub, 3, 0, false, &spt).is_err());
    }
}
