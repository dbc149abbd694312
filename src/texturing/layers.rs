//! The surface-layer tree of cached procedural textures (dissertation §8.2,
//! Table 8.1; `ALGORITHMS.md` §4): materials layered over the height field,
//! each covering its parent where its constraints hold.
//!
//! Every layer has a colour, a roughness B_S with displacement noise D_S, a
//! coverage noise N ∈ [−1, 1] with bias c_S and scale n_S, and constraints
//! on altitude (metres, or `elevation`: relative to the height field's lowest
//! (0) and highest (1) sample, so one tree suits any terrain), slope and
//! optional extra input maps registered to the height
//! field (rainfall, radiation, temperature), each a hat function with range
//! [min, max] and fuzziness f:
//!
//! ```text
//! f1(a) = (a − (min − f)) / (2f),  f2(a) = ((max + f) − a) / (2f)
//! F(a)  = clamp(min(f1, f2), 0, 1)            (f = 0: 1 inside [min, max], else 0)
//! C     = clamp((c_S + n_S·N(x)) · Π F_i, 0, 1)
//! C_S   = C · C_parent                        (coverage feeds the children)
//! RGB   = (1 − C_S)·RGB_in + C_S·RGB_S
//! h'    = h + C_S·B_S·D_S(x)                  (the next layer's altitude)
//! ```
//!
//! The tree is evaluated depth-first: RGB_in and h are what the layers before
//! this one (in depth-first order) produced. The root is the base material:
//! it has no constraints and covers everything (C = 1 whatever its noise).
//!
//! Decisions where the text leaves room:
//! * **Slope** is the angle in degrees of the base surface (the height field
//!   upsampled with the cubic B-spline, analytic gradient), not of the
//!   modified height: the modified height is a per-point quantity, so the
//!   per-pixel reference (`--texturing direct`) and the atlas tiles evaluate
//!   exactly the same function. Modified heights reach the next layers
//!   through the altitude.
//! * **Normals** come from the analytic gradient of the final height: the
//!   base gradient plus Σ C_S·B_S·∇D_S (the coverage's own gradient is
//!   ignored), so lighting stays dynamic and tiles of any resolution agree.
//! * **Noise**: N and D_S are fractional Brownian motion of the project's
//!   wavelet noise (three octaves, lacunarity 2, gain 0.5, normalised to
//!   about [−1, 1]) at the layer's wavelengths, decorrelated per layer.
//! * Colours are linear albedo in [0, 1].
//!
//! The file format is TOML: `[root]` and nested `[[….children]]` tables (see
//! [`DEFAULT_LAYERS`]); errors name the file and line.

use std::path::Path;

use glam::{DVec2, Vec3};
use serde::Deserialize;

use crate::error::{Error, Result};

/// Deepest tree level (root 0): the GPU keeps one coverage per level.
pub const MAX_LEVEL: usize = 3;
/// Most layers in a tree.
pub const MAX_LAYERS: usize = 32;
/// The extra input maps a layer can be constrained by, in GPU order.
pub const INPUT_NAMES: [&str; 3] = ["rainfall", "radiation", "temperature"];

/// The built-in tree: rock root; grass with dark, dry and light grass; sand; snow.
pub const DEFAULT_LAYERS: &str = include_str!("default_layers.toml");

/// A hat function over an attribute (§8.2): 1 inside [min, max], ramps of
/// half-width `fuzz` around the ends.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hat {
    pub min: f32,
    pub max: f32,
    #[serde(default)]
    pub fuzz: f32,
}

impl Hat {
    /// F(a) (module docs); 0 for NaN (an absent input).
    pub fn eval(&self, a: f32) -> f32 {
        if a.is_nan() {
            return 0.0;
        }
        if self.fuzz <= 0.0 {
            return if a >= self.min && a <= self.max { 1.0 } else { 0.0 };
        }
        let f1 = (a - (self.min - self.fuzz)) / (2.0 * self.fuzz);
        let f2 = ((self.max + self.fuzz) - a) / (2.0 * self.fuzz);
        f1.min(f2).clamp(0.0, 1.0)
    }

    fn validate(&self) -> std::result::Result<(), String> {
        if !(self.min.is_finite() && self.max.is_finite() && self.fuzz.is_finite()) {
            return Err("range and fuzz must be finite".into());
        }
        if self.min > self.max {
            return Err(format!("min {} is above max {}", self.min, self.max));
        }
        if self.fuzz < 0.0 {
            return Err(format!("fuzz {} is negative", self.fuzz));
        }
        Ok(())
    }
}

/// One layer (Table 8.1).
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub name: String,
    /// Linear albedo.
    pub color: Vec3,
    /// B_S: amplitude of the displacement noise (metres).
    pub roughness: f32,
    /// Wavelength of the displacement noise D_S (metres).
    pub roughness_wavelength: f32,
    /// c_S.
    pub noise_bias: f32,
    /// n_S.
    pub noise_scale: f32,
    /// Wavelength of the coverage noise N (metres).
    pub noise_wavelength: f32,
    /// Altitude constraint (metres).
    pub altitude: Option<Hat>,
    /// Elevation constraint: altitude relative to the height field's range (0 lowest, 1 highest).
    pub elevation: Option<Hat>,
    /// Slope constraint (degrees).
    pub slope: Option<Hat>,
    /// Constraints on the extra inputs, in [`INPUT_NAMES`] order.
    pub inputs: [Option<Hat>; 3],
}

/// A layer in depth-first order with its place in the tree.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatLayer {
    pub layer: Layer,
    /// Tree level (root 0).
    pub level: usize,
    /// Index of the parent in the flat list (None for the root).
    pub parent: Option<usize>,
}

/// The surface-layer tree, flattened depth-first (the order of evaluation).
#[derive(Clone, Debug, PartialEq)]
pub struct LayerTree {
    pub layers: Vec<FlatLayer>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TreeFile {
    root: toml::Spanned<LayerFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerFile {
    name: String,
    color: [f32; 3],
    #[serde(default)]
    roughness: f32,
    #[serde(default = "default_wavelength")]
    roughness_wavelength: f32,
    #[serde(default = "one")]
    noise_bias: f32,
    #[serde(default)]
    noise_scale: f32,
    #[serde(default = "default_wavelength")]
    noise_wavelength: f32,
    altitude: Option<Hat>,
    elevation: Option<Hat>,
    slope: Option<Hat>,
    rainfall: Option<Hat>,
    radiation: Option<Hat>,
    temperature: Option<Hat>,
    #[serde(default)]
    children: Vec<toml::Spanned<LayerFile>>,
}

fn default_wavelength() -> f32 {
    8.0
}

fn one() -> f32 {
    1.0
}

/// 1-based line of byte offset `at` in `text`.
fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

impl LayerTree {
    /// The built-in tree ([`DEFAULT_LAYERS`]).
    pub fn default_tree() -> LayerTree {
        // The built-in file is tested to parse.
        LayerTree::parse(DEFAULT_LAYERS, "built-in layers").unwrap_or_else(|_| LayerTree { layers: Vec::new() })
    }

    /// Reads a tree from a TOML file; errors name the file and line.
    pub fn load(path: &Path) -> Result<LayerTree> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::invalid(path.display().to_string(), format!("cannot read: {e}")))?;
        LayerTree::parse(&text, &path.display().to_string())
    }

    /// Parses TOML `text`; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<LayerTree> {
        let file: TreeFile = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| format!("line {}: ", line_of(text, s.start)))
                .unwrap_or_default();
            Error::invalid(origin, format!("{line}{}", e.message().trim()))
        })?;
        let mut layers = Vec::new();
        flatten(text, origin, file.root, 0, None, &mut layers)?;
        Ok(LayerTree { layers })
    }

    /// The root layer.
    pub fn root(&self) -> Option<&Layer> {
        self.layers.first().map(|l| &l.layer)
    }

    /// Whether any layer is constrained by input map `k` ([`INPUT_NAMES`]).
    pub fn uses_input(&self, k: usize) -> bool {
        self.layers
            .iter()
            .any(|l| l.layer.inputs.get(k).is_some_and(|h| h.is_some()))
    }
}

fn flatten(
    text: &str,
    origin: &str,
    spanned: toml::Spanned<LayerFile>,
    level: usize,
    parent: Option<usize>,
    out: &mut Vec<FlatLayer>,
) -> Result<()> {
    let line = line_of(text, spanned.span().start);
    let at = |why: String| Error::invalid(origin, format!("line {line}: {why}"));
    let f = spanned.into_inner();
    let name = f.name.clone();
    let bad = |why: String| at(format!("layer '{name}': {why}"));
    if level > MAX_LEVEL {
        return Err(bad(format!("deeper than {MAX_LEVEL} levels below the root")));
    }
    if out.len() >= MAX_LAYERS {
        return Err(bad(format!("more than {MAX_LAYERS} layers")));
    }
    if f.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(bad(format!("color {:?} is not linear albedo in [0, 1]", f.color)));
    }
    for (what, v) in [
        ("roughness", f.roughness),
        ("noise_bias", f.noise_bias),
        ("noise_scale", f.noise_scale),
    ] {
        if !v.is_finite() {
            return Err(bad(format!("{what} is not finite")));
        }
    }
    if f.roughness < 0.0 {
        return Err(bad(format!("roughness {} is negative", f.roughness)));
    }
    for (what, v) in [
        ("roughness_wavelength", f.roughness_wavelength),
        ("noise_wavelength", f.noise_wavelength),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(format!("{what} {v} is not positive")));
        }
    }
    let hats = [
        ("altitude", f.altitude),
        ("elevation", f.elevation),
        ("slope", f.slope),
        ("rainfall", f.rainfall),
        ("radiation", f.radiation),
        ("temperature", f.temperature),
    ];
    for (what, hat) in &hats {
        if let Some(h) = hat {
            h.validate().map_err(|why| bad(format!("{what}: {why}")))?;
        }
    }
    if level == 0 && hats.iter().any(|(_, h)| h.is_some()) {
        return Err(bad("the root is the base material and takes no constraints".into()));
    }
    let index = out.len();
    out.push(FlatLayer {
        layer: Layer {
            name: f.name,
            color: Vec3::from(f.color),
            roughness: f.roughness,
            roughness_wavelength: f.roughness_wavelength,
            noise_bias: f.noise_bias,
            noise_scale: f.noise_scale,
            noise_wavelength: f.noise_wavelength,
            altitude: f.altitude,
            elevation: f.elevation,
            slope: f.slope,
            inputs: [f.rainfall, f.radiation, f.temperature],
        },
        level,
        parent,
    });
    for child in f.children {
        flatten(text, origin, child, level + 1, Some(index), out)?;
    }
    Ok(())
}

/// What a layer sees at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerInputs {
    /// Altitude (metres): the height modified by the layers before.
    pub altitude: f32,
    /// The same relative to the height field's range (0 lowest, 1 highest sample).
    pub elevation: f32,
    /// Slope of the base surface (degrees).
    pub slope: f32,
    /// The extra input maps ([`INPUT_NAMES`]); NaN where a map is absent.
    pub maps: [f32; 3],
}

/// C of a layer (module docs) for coverage noise value `noise` ∈ [−1, 1].
pub fn coverage(layer: &Layer, inputs: &LayerInputs, noise: f32) -> f32 {
    let mut product = 1.0;
    if let Some(h) = layer.altitude {
        product *= h.eval(inputs.altitude);
    }
    if let Some(h) = layer.elevation {
        product *= h.eval(inputs.elevation);
    }
    if let Some(h) = layer.slope {
        product *= h.eval(inputs.slope);
    }
    for (hat, value) in layer.inputs.iter().zip(inputs.maps) {
        if let Some(h) = hat {
            product *= h.eval(value);
        }
    }
    ((layer.noise_bias + layer.noise_scale * noise) * product).clamp(0.0, 1.0)
}

/// The surface a tree produces at one point.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Linear albedo.
    pub color: Vec3,
    /// Final height (metres).
    pub height: f32,
    /// Gradient of the final height (module docs).
    pub gradient: DVec2,
    /// C_S of every layer, depth-first.
    pub coverage: Vec<f32>,
}

impl Surface {
    /// Unit normal of the final height.
    pub fn normal(&self) -> Vec3 {
        Vec3::new(-self.gradient.x as f32, -self.gradient.y as f32, 1.0).normalize()
    }
}

/// Noise of a layer at a point: `(layer index, world xy, wavelength)` →
/// value in about [−1, 1] and its gradient. `coverage` selects N (true) or
/// D_S (false).
pub type LayerNoise<'a> = dyn Fn(usize, bool, DVec2, f32) -> (f32, DVec2) + 'a;

/// Where the tree is evaluated: a point of the base surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasePoint {
    /// World xy (metres).
    pub xy: DVec2,
    /// Base height (metres) and its gradient.
    pub height: f32,
    pub gradient: DVec2,
    /// The height field's lowest and highest sample (for `elevation`).
    pub range: (f32, f32),
    /// Extra inputs ([`INPUT_NAMES`]); NaN where a map is absent.
    pub maps: [f32; 3],
}

/// CPU reference of the tree at `base`.
pub fn evaluate(tree: &LayerTree, base: &BasePoint, noise: &LayerNoise) -> Surface {
    let BasePoint {
        xy,
        height,
        gradient,
        range: (lo, hi),
        maps,
    } = *base;
    let slope = gradient.length().atan().to_degrees() as f32;
    let mut surface = Surface {
        color: Vec3::ZERO,
        height,
        gradient,
        coverage: Vec::with_capacity(tree.layers.len()),
    };
    for (i, flat) in tree.layers.iter().enumerate() {
        let layer = &flat.layer;
        let c_s = match flat.parent {
            None => 1.0,
            Some(p) => {
                let inputs = LayerInputs {
                    altitude: surface.height,
                    elevation: (surface.height - lo) / (hi - lo).max(1e-6),
                    slope,
                    maps,
                };
                let (n, _) = noise(i, true, xy, layer.noise_wavelength);
                coverage(layer, &inputs, n) * surface.coverage[p]
            }
        };
        surface.coverage.push(c_s);
        surface.color = surface.color * (1.0 - c_s) + layer.color * c_s;
        if layer.roughness > 0.0 && c_s > 0.0 {
            let (d, grad) = noise(i, false, xy, layer.roughness_wavelength);
            let amplitude = c_s * layer.roughness;
            surface.height += amplitude * d;
            surface.gradient += f64::from(amplitude) * grad;
        }
    }
    surface
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hat(min: f32, max: f32, fuzz: f32) -> Hat {
        Hat { min, max, fuzz }
    }

    #[test]
    fn hat_functions_ramp_over_twice_the_fuzz() {
        let h = hat(100.0, 200.0, 10.0);
        assert_eq!(h.eval(50.0), 0.0);
        assert_eq!(h.eval(90.0), 0.0);
        assert_eq!(h.eval(100.0), 0.5);
        assert_eq!(h.eval(110.0), 1.0);
        assert_eq!(h.eval(150.0), 1.0);
        assert_eq!(h.eval(200.0), 0.5);
        assert_eq!(h.eval(210.0), 0.0);
        assert!((h.eval(95.0) - 0.25).abs() < 1e-6);
        // No fuzz: a box.
        let b = hat(0.0, 1.0, 0.0);
        assert_eq!(
            (b.eval(-0.1), b.eval(0.0), b.eval(1.0), b.eval(1.1)),
            (0.0, 1.0, 1.0, 0.0)
        );
        // A range narrower than the ramps peaks below 1.
        let narrow = hat(0.0, 0.0, 10.0);
        assert_eq!(narrow.eval(0.0), 0.5);
    }

    fn leaf(name: &str, color: [f32; 3]) -> Layer {
        Layer {
            name: name.into(),
            color: Vec3::from(color),
            roughness: 0.0,
            roughness_wavelength: 1.0,
            noise_bias: 1.0,
            noise_scale: 0.0,
            noise_wavelength: 1.0,
            altitude: None,
            elevation: None,
            slope: None,
            inputs: [None; 3],
        }
    }

    #[test]
    fn coverage_multiplies_constraints_and_clamps_noise() {
        let mut l = leaf("snow", [1.0; 3]);
        l.altitude = Some(hat(1000.0, 5000.0, 100.0));
        l.slope = Some(hat(0.0, 30.0, 5.0));
        l.noise_bias = 0.5;
        l.noise_scale = 1.0;
        let at = |altitude, slope| LayerInputs {
            altitude,
            elevation: 0.5,
            slope,
            maps: [f32::NAN; 3],
        };
        assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.5), 1.0);
        assert_eq!(coverage(&l, &at(2000.0, 10.0), -0.5), 0.0);
        assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.0), 0.5);
        // 0.5 (altitude ramp) × 1 × (0.5 + 0.5) = 0.5.
        assert_eq!(coverage(&l, &at(1000.0, 10.0), 0.5), 0.5);
        // Product of two half ramps.
        assert_eq!(coverage(&l, &at(1000.0, 30.0), 0.5), 0.25);
        assert_eq!(coverage(&l, &at(500.0, 10.0), 1.0), 0.0);
        // Input maps: an absent map (NaN) fails its constraint.
        l.inputs[0] = Some(hat(0.0, 1.0, 0.5));
        assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.5), 0.0);
        let mut with_map = at(2000.0, 10.0);
        with_map.maps[0] = 0.5;
        assert_eq!(coverage(&l, &with_map, 0.5), 1.0);
    }

    #[test]
    fn evaluation_blends_depth_first_and_coverage_feeds_children_only() {
        let text = r#"
            [root]
            name = "rock"
            color = [0.2, 0.2, 0.2]
            [[root.children]]
            name = "grass"
            color = [0.0, 1.0, 0.0]
            noise_bias = 0.5
            roughness = 2.0
            [[root.children.children]]
            name = "dry"
            color = [1.0, 1.0, 0.0]
            noise_bias = 0.5
            [[root.children]]
            name = "snow"
            color = [1.0, 1.0, 1.0]
            altitude = { min = 101.0, max = 1e6 }
        "#;
        let tree = LayerTree::parse(text, "test").unwrap();
        let names: Vec<&str> = tree.layers.iter().map(|l| l.layer.name.as_str()).collect();
        assert_eq!(names, ["rock", "grass", "dry", "snow"]);
        assert_eq!(tree.layers[2].parent, Some(1));
        assert_eq!(tree.layers[3].level, 1);
        // D_S = 1 everywhere: grass (C_S = 0.5) lifts the height by 0.5·2 = 1,
        // which brings it above the snow line.
        let noise = |_: usize, _: bool, _: DVec2, _: f32| (1.0f32, DVec2::new(0.1, 0.0));
        let at = |height| BasePoint {
            xy: DVec2::ZERO,
            height,
            gradient: DVec2::ZERO,
            range: (0.0, 200.0),
            maps: [f32::NAN; 3],
        };
        let s = evaluate(&tree, &at(100.5), &noise);
        assert_eq!(s.coverage, vec![1.0, 0.5, 0.25, 1.0]);
        assert_eq!(s.height, 101.5);
        assert!((s.gradient.x - 0.1).abs() < 1e-9, "{:?}", s.gradient);
        assert_eq!(s.color, Vec3::ONE);
        // Below the snow line: rock 0.2 → grass half → dry a quarter.
        let s = evaluate(&tree, &at(90.0), &noise);
        let expected =
            (Vec3::splat(0.2) * 0.5 + Vec3::new(0.0, 1.0, 0.0) * 0.5) * 0.75 + Vec3::new(1.0, 1.0, 0.0) * 0.25;
        assert!((s.color - expected).length() < 1e-6, "{} vs {expected}", s.color);
    }

    #[test]
    fn the_default_tree_parses_with_the_issue_layers() {
        let tree = LayerTree::parse(DEFAULT_LAYERS, "built-in").unwrap();
        let names: Vec<&str> = tree.layers.iter().map(|l| l.layer.name.as_str()).collect();
        for name in [
            "rock",
            "grass",
            "dark grass",
            "dry grass",
            "light grass",
            "sand",
            "snow",
        ] {
            assert!(names.contains(&name), "{name} missing from {names:?}");
        }
        assert_eq!(tree.layers[0].layer.name, "rock");
        assert_eq!(LayerTree::default_tree(), tree);
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            ("[root]\nname = \"r\"\ncolor = [0.1, 0.1]\n", "line 3"),
            ("[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nbogus = 1\n", "line 4"),
            (
                "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\n\n[[root.children]]\nname = \"c\"\ncolor = [0.5, 0.5, 0.5]\nslope = { min = 40.0, max = 10.0 }\n",
                "line 5",
            ),
            ("[root]\nname = \"r\"\ncolor = [2.0, 0.1, 0.1]\n", "line 1"),
            (
                "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\naltitude = { min = 0.0, max = 1.0 }\n",
                "takes no constraints",
            ),
            ("[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nroughness = -1.0\n", "negative"),
        ];
        for (text, needle) in cases {
            let err = LayerTree::parse(text, "layers.toml").unwrap_err().to_string();
            assert!(
                err.contains("layers.toml") && err.contains(needle),
                "{err:?} lacks {needle:?}"
            );
            assert!(!err.contains('\n'), "one line: {err:?}");
        }
    }
}
