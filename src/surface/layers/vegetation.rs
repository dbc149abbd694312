//! The `vegetation` array of a surface layer (dissertation §8.2 layers, §10
//! point-based plants): which procedural plants grow where the layer shows,
//! how densely and how large.
//!
//! ```toml
//! [[root.children.vegetation]]
//! model = "conifer"        # conifer | shrub | grass_tuft
//! density = 0.0002         # plants per m² where the layer covers everything
//! scale = [0.6, 1.5]       # uniform scale range (× the model's nominal height)
//! ```
//!
//! Ranges (one-line errors naming the key otherwise): `density` in [0,
//! [`MAX_DENSITY`]], `scale` two numbers `0 < min ≤ max ≤` [`MAX_SCALE`]
//! (default `[1, 1]`); unknown keys and models are errors.
//!
//! Where a layer "shows" ([`subtree_shares`]): the share of the final
//! colour that comes from the layer or one of its sub-layers (a grass
//! layer's dark and dry grass children are still grass), i.e. the sum of
//! `C_k · Π_{j>k} (1 − C_j)` over the layer's subtree
//! ([`crate::surface::dominant::layer_shares`]).

use serde::Deserialize;

use super::LayerTree;
use crate::surface::dominant::layer_shares;
use crate::surface::plants::PlantModel;

/// Largest `density` in plants per m².
pub const MAX_DENSITY: f64 = 100.0;
/// Largest scale factor.
pub const MAX_SCALE: f64 = 100.0;

/// Plants of one model growing on a layer.
#[derive(Clone, Debug, PartialEq)]
pub struct Vegetation {
    pub model: PlantModel,
    /// Plants per m² where the layer's share is 1.
    pub density: f64,
    /// Uniform scale range [min, max].
    pub scale: (f64, f64),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VegetationFile {
    model: String,
    density: f64,
    scale: Option<Vec<f64>>,
}

impl VegetationFile {
    /// The checked entry; errors say which key is wrong (without the layer).
    pub(super) fn into_vegetation(self, index: usize) -> std::result::Result<Vegetation, String> {
        let at = |key: &str| format!("vegetation[{index}].{key}");
        let model = PlantModel::from_name(&self.model).ok_or_else(|| {
            let names: Vec<&str> = PlantModel::ALL.iter().map(|m| m.name()).collect();
            format!("{} '{}' is not one of {}", at("model"), self.model, names.join(", "))
        })?;
        if !(0.0..=MAX_DENSITY).contains(&self.density) {
            return Err(format!(
                "{} {} is not in [0, {MAX_DENSITY}] plants per m²",
                at("density"),
                self.density
            ));
        }
        let scale = match self.scale.as_deref() {
            None => (1.0, 1.0),
            Some(&[lo, hi]) if lo > 0.0 && lo <= hi && hi <= MAX_SCALE => (lo, hi),
            Some(other) => {
                return Err(format!(
                    "{} {other:?} is not [min, max] with 0 < min ≤ max ≤ {MAX_SCALE}",
                    at("scale")
                ))
            }
        };
        Ok(Vegetation {
            model,
            density: self.density,
            scale,
        })
    }
}

/// The share of each layer and its sub-layers in the final colour, for the
/// coverages `coverage` of the depth-first layers of `tree` (module docs).
pub fn subtree_shares(tree: &LayerTree, coverage: &[f32]) -> Vec<f32> {
    let own = layer_shares(coverage);
    let n = own.len().min(tree.layers.len());
    (0..n)
        .map(|i| {
            let level = tree.layers[i].level;
            let end = (i + 1..n).find(|&j| tree.layers[j].level <= level).unwrap_or(n);
            own[i..end].iter().sum()
        })
        .collect()
}

impl LayerTree {
    /// Whether any layer grows plants.
    pub fn has_vegetation(&self) -> bool {
        self.layers.iter().any(|l| !l.layer.vegetation.is_empty())
    }
}

#[cfg(test)]
mod tests {
    use crate::surface::layers::LayerTree;

    const BASE: &str = "[root]\nname = \"rock\"\ncolor = [0.3, 0.3, 0.3]\n\n[[root.children]]\nname = \"grass\"\ncolor = [0.1, 0.3, 0.1]\n";

    #[test]
    fn tables_parse_with_defaults() {
        let text = format!(
            "{BASE}[[root.children.vegetation]]\nmodel = \"shrub\"\ndensity = 0.01\nscale = [0.5, 2]\n\n\
             [[root.children.vegetation]]\nmodel = \"grass_tuft\"\ndensity = 0.1\n"
        );
        let tree = LayerTree::parse(&text, "t.toml").unwrap();
        let v = &tree.layers[1].layer.vegetation;
        assert_eq!(v.len(), 2);
        assert_eq!((v[0].density, v[0].scale), (0.01, (0.5, 2.0)));
        assert_eq!(v[1].scale, (1.0, 1.0));
        assert!(tree.has_vegetation() && tree.layers[0].layer.vegetation.is_empty());
        assert!(!LayerTree::parse(BASE, "t.toml").unwrap().has_vegetation());
    }

    #[test]
    fn bad_tables_are_one_line_errors_naming_the_key() {
        let cases = [
            (
                "model = \"oak\"\ndensity = 0.1",
                "vegetation[0].model 'oak' is not one of conifer, shrub, grass_tuft",
            ),
            (
                "model = \"shrub\"\ndensity = -1",
                "vegetation[0].density -1 is not in [0, 100]",
            ),
            ("model = \"shrub\"\ndensity = 1e9", "vegetation[0].density"),
            ("model = \"shrub\"\ndensity = nan", "vegetation[0].density"),
            (
                "model = \"shrub\"\ndensity = 1\nscale = [2, 1]",
                "vegetation[0].scale [2.0, 1.0]",
            ),
            ("model = \"shrub\"\ndensity = 1\nscale = [0, 1]", "vegetation[0].scale"),
            ("model = \"shrub\"\ndensity = 1\nscale = [1]", "vegetation[0].scale"),
            (
                "model = \"shrub\"\ndensity = 1\nscale = [1, 1000]",
                "vegetation[0].scale",
            ),
            ("model = \"shrub\"\ndensity = 1\nsize = 3", "unknown field `size`"),
            ("model = \"shrub\"", "missing field `density`"),
        ];
        for (table, expected) in cases {
            let text = format!("{BASE}[[root.children.vegetation]]\n{table}\n");
            let e = LayerTree::parse(&text, "t.toml").unwrap_err().to_string();
            assert!(
                e.contains(expected) && e.contains("t.toml") && !e.contains('\n'),
                "{table}: {e}"
            );
            assert!(e.contains("line "), "{e}");
        }
        let root =
            "[root]\nname = \"rock\"\ncolor = [0.3, 0.3, 0.3]\n[[root.vegetation]]\nmodel = \"shrub\"\ndensity = 1\n";
        assert!(LayerTree::parse(root, "t.toml").is_ok(), "the root may grow plants");
    }

    #[test]
    fn subtree_shares_add_the_sub_layers() {
        let text = format!(
            "{BASE}[[root.children.children]]\nname = \"dark\"\ncolor = [0.0, 0.2, 0.0]\n\n\
             [[root.children]]\nname = \"snow\"\ncolor = [0.9, 0.9, 0.9]\n"
        );
        let tree = LayerTree::parse(&text, "t").unwrap();
        // rock 1, grass 0.8, dark 0.5 (of grass), snow 0.25.
        let shares = super::subtree_shares(&tree, &[1.0, 0.8, 0.5, 0.25]);
        let own = crate::surface::dominant::layer_shares(&[1.0, 0.8, 0.5, 0.25]);
        assert!((shares[0] - 1.0).abs() < 1e-6, "the root's subtree is everything");
        assert!((shares[1] - (own[1] + own[2])).abs() < 1e-6);
        // After dark grass: rock 0.1, grass 0.4, dark 0.5; snow then covers a quarter.
        assert!((shares[1] - 0.9 * 0.75).abs() < 1e-6);
        assert_eq!((shares[2], shares[3]), (own[2], own[3]));
    }
}
