//! Vegetation as point trees (dissertation chapter 10 introduction and
//! Fig. 10.12: shrubs drawn from sequential point trees on an artificial
//! terrain): plant prototypes built once ([`crate::points::build::plants`]:
//! mesh → surfels → SPT, hybrid where leaves are large, §10.1.8) and drawn
//! as many instances, placed by [`crate::points::build::plants::scatter`].
//!
//! Each model used gets [`VegetationOptions::variants`] prototypes (seeds
//! from the scene seed); a plant is an instance of one of them, standing at
//! the ground's height with its scale and yaw. Plant objects are two-sided
//! (leaves, needles and blades are open sheets), of class
//! [`PointClass::Vegetation`], and thinned where they are smaller than a
//! few pixels ([`crate::points::render::selection`]), so a hillside of tens
//! of thousands of plants costs the draws of those that are visible.

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::{DQuat, DVec2, DVec3};

use super::build::plants::build_plant_tree;
use super::build::plants::scatter::{Scatter, ScatterRule};
use super::build::spt::{epsilon_from_pixels, SptOptions};
use super::scene::{PointClass, PointInstance, PointObject, PointScene, PointTransform};
use crate::error::{Error, Result};
use crate::random::SplitMix64;
use crate::surface::plants::PlantModel;

/// Most plants a scene gets by default (`VegetationOptions::max_plants`).
pub const DEFAULT_MAX_PLANTS: usize = 60_000;

/// How vegetation is built.
#[derive(Clone, Debug, PartialEq)]
pub struct VegetationOptions {
    /// Multiplier of every layer's density (≥ 0; the CLI's `--vegetation-density`).
    pub density: f64,
    /// Seed of the placements and the prototypes.
    pub seed: u64,
    /// Prototypes per plant model (≥ 1).
    pub variants: usize,
    /// Surfels per prototype as a fraction of `PlantModel::default_samples` (> 0).
    pub samples: f64,
    /// Keep the triangles of leaves and blades for hybrid rendering (§10.1.8).
    pub hybrid: bool,
    /// Most plants; beyond it they are thinned uniformly, with a warning.
    pub max_plants: usize,
    /// Point tree options of the prototypes.
    pub spt: SptOptions,
}

impl Default for VegetationOptions {
    /// Density 1, three variants per model at full sampling, hybrid, at
    /// most `DEFAULT_MAX_PLANTS`, trees for a one-pixel error at 50° and
    /// 720 rows.
    fn default() -> Self {
        VegetationOptions {
            density: 1.0,
            seed: 0x7EE5,
            variants: 3,
            samples: 1.0,
            hybrid: true,
            max_plants: DEFAULT_MAX_PLANTS,
            spt: SptOptions {
                epsilon: epsilon_from_pixels(1.0, 50f32.to_radians(), 720).unwrap_or(SptOptions::default().epsilon),
                ..SptOptions::default()
            },
        }
    }
}

impl VegetationOptions {
    /// Checks the numbers; errors name the option.
    pub fn validate(&self) -> Result<()> {
        if !(self.density.is_finite() && self.density >= 0.0) {
            return Err(Error::invalid(
                "vegetation density",
                format!("{} is not a finite number ≥ 0", self.density),
            ));
        }
        if self.variants == 0 || self.variants > 64 {
            return Err(Error::invalid(
                "vegetation variants",
                format!("{} is outside 1..=64", self.variants),
            ));
        }
        if !(self.samples.is_finite() && self.samples > 0.0 && self.samples <= 16.0) {
            return Err(Error::invalid(
                "vegetation samples",
                format!("{} is outside (0, 16]", self.samples),
            ));
        }
        Ok(())
    }
}

/// What `plant_scene` made, for logs and benchmarks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VegetationReport {
    /// Plants per model.
    pub plants: BTreeMap<PlantModel, usize>,
    /// Scatter candidates evaluated.
    pub candidates: usize,
    /// Plants left out by the cap.
    pub thinned: usize,
    /// Prototype objects built.
    pub prototypes: usize,
    /// Splats over all prototypes.
    pub prototype_splats: usize,
}

impl VegetationReport {
    /// All plants.
    pub fn total(&self) -> usize {
        self.plants.values().sum()
    }
}

/// The mesh seed of prototype `variant` of `model` (from the options' seed).
pub fn prototype_seed(model: PlantModel, variant: usize, options: &VegetationOptions) -> u64 {
    SplitMix64(options.seed ^ ((model as u64) << 32) ^ variant as u64).next_u64()
}

/// The prototype of `model`, variant `variant`: the plant of
/// [`prototype_seed`] built into a point tree.
pub fn plant_prototype(model: PlantModel, variant: usize, options: &VegetationOptions) -> Result<PointObject> {
    let seed = prototype_seed(model, variant, options);
    let samples = ((model.default_samples() as f64 * options.samples).round() as usize).max(64);
    let built = build_plant_tree(model, seed, samples, options.hybrid, &options.spt)?;
    Ok(PointObject {
        class: PointClass::Vegetation,
        hybrid: built.hybrid.map(Arc::new),
        two_sided: true,
        thinning: true,
        ..PointObject::new(format!("{} {variant}", model.name()), built.tree)
    })
}

/// The point objects of the plants `scatter` placed by `rules`: prototypes
/// of the models used, one instance per plant at height `ground(xy)`.
pub fn plant_scene(
    rules: &[ScatterRule],
    scatter: &Scatter,
    ground: &mut dyn FnMut(DVec2) -> Result<f64>,
    options: &VegetationOptions,
) -> Result<(PointScene, VegetationReport)> {
    options.validate()?;
    let mut scene = PointScene::default();
    let mut report = VegetationReport {
        candidates: scatter.candidates,
        thinned: scatter.thinned,
        ..VegetationReport::default()
    };
    // First prototype of each model used.
    let mut firsts: BTreeMap<PlantModel, usize> = BTreeMap::new();
    for p in &scatter.placements {
        let rule = rules
            .get(p.rule)
            .ok_or_else(|| Error::invalid("vegetation", format!("placement of rule {} of {}", p.rule, rules.len())))?;
        let first = match firsts.get(&rule.model) {
            Some(&f) => f,
            None => {
                let f = scene.objects.len();
                for variant in 0..options.variants {
                    scene.objects.push(plant_prototype(rule.model, variant, options)?);
                }
                firsts.insert(rule.model, f);
                f
            }
        };
        let object = first + (p.variant % options.variants as u64) as usize;
        scene.instances.push(PointInstance {
            object,
            transform: PointTransform {
                translation: DVec3::new(p.xy.x, p.xy.y, ground(p.xy)?),
                rotation: DQuat::from_rotation_z(p.yaw),
                scale: p.scale,
            },
        });
        *report.plants.entry(rule.model).or_default() += 1;
    }
    report.prototypes = scene.objects.len();
    report.prototype_splats = scene.total_splats();
    Ok((scene, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::plants::scatter::{scatter, ScatterRule};

    #[test]
    fn plants_stand_on_the_ground_as_instances_of_few_prototypes() {
        let options = VegetationOptions {
            samples: 0.05,
            variants: 2,
            hybrid: false,
            ..VegetationOptions::default()
        };
        let rules = [
            ScatterRule {
                model: PlantModel::GrassTuft,
                density: 0.05,
                scale: (1.0, 2.0),
                source: 0,
            },
            ScatterRule {
                model: PlantModel::Shrub,
                density: 0.02,
                scale: (0.5, 1.0),
                source: 0,
            },
        ];
        let placed = scatter(&rules, DVec2::new(100.0, 50.0), 4, 1000, &|_| Ok(vec![1.0])).unwrap();
        let (scene, report) = plant_scene(&rules, &placed, &mut |xy| Ok(xy.x * 0.1), &options).unwrap();
        assert_eq!(scene.objects.len(), 4);
        assert_eq!(report.prototypes, 4);
        assert_eq!(scene.instances.len(), placed.placements.len());
        assert_eq!(report.total(), placed.placements.len());
        assert!(report.plants[&PlantModel::GrassTuft] > 150 && report.plants[&PlantModel::Shrub] > 50);
        scene.validate().unwrap();
        for (inst, p) in scene.instances.iter().zip(&placed.placements) {
            let t = inst.transform.translation;
            assert!((t.z - p.xy.x * 0.1).abs() < 1e-9 && t.x == p.xy.x);
            let object = &scene.objects[inst.object];
            assert!(object.two_sided && object.thinning && object.class == PointClass::Vegetation);
            assert!(object.name.starts_with(rules[p.rule].model.name()));
        }
        let bad = VegetationOptions {
            density: -1.0,
            ..options
        };
        let e = plant_scene(&rules, &placed, &mut |_| Ok(0.0), &bad).unwrap_err();
        assert!(e.to_string().contains("vegetation density"));
    }
}
