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
//! [min, max] and fuzziness f, or a sampled function (§8.3; [`constraint`]
//! has the formula: samples at the centres of equal bins over [min, max],
//! linear in between, 0 outside), which replaces the hat in the product:
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
//! * **`height_blur = R`** (metres, (0, [`MAX_HEIGHT_BLUR`]], at most
//!   [`MAX_BLUR_RADII`] distinct radii per tree; not on the root): §8.2.3
//!   simulates snow "deposited in furrows by wind ... when a blurred
//!   elevation data serves as input for the slope constraint evaluation".
//!   Such a layer's constraints read the height field blurred with a
//!   Gaussian of σ = R ([`crate::surface::blurred_height`]), upsampled
//!   with the same cubic B-spline as the base: its slope is that of the
//!   blurred surface (as the text says), and its altitude and elevation are
//!   the blurred height plus the displacement the layers before added
//!   (h − H + H_R), so snow fills furrows — high on the smoothed surface and
//!   gentle there — and thins on narrow ridges. Other layers are unchanged.
//! * Colours are linear albedo in [0, 1], exactly 3 components.
//! * Ranges (errors otherwise): roughness in [0, [`MAX_ROUGHNESS`]] m,
//!   wavelengths in [`WAVELENGTH_RANGE`] m, noise bias and scale within
//!   ±[`MAX_NOISE_TERM`], constraint values within ±[`MAX_HAT_VALUE`];
//!   unknown keys are errors.
//! * **`[[….vegetation]]`** (an array of tables per layer): procedural
//!   plants that grow where the layer shows ([`vegetation`]); the texture
//!   does not read it.
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

pub mod constraint;
pub mod vegetation;
use constraint::ConstraintFile;
#[cfg(test)]
pub use constraint::Hat;
pub use constraint::{Constraint, SampledFunction, MAX_SAMPLES};
pub use vegetation::Vegetation;
use vegetation::VegetationFile;

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
    pub altitude: Option<Constraint>,
    /// Elevation constraint: altitude relative to the height field's range (0 lowest, 1 highest).
    pub elevation: Option<Constraint>,
    /// Slope constraint (degrees).
    pub slope: Option<Constraint>,
    /// Constraints on the extra inputs, in [`INPUT_NAMES`] order.
    pub inputs: [Option<Constraint>; 3],
    /// `height_blur` (metres, module docs): the altitude, elevation and
    /// slope constraints read the height field blurred with a Gaussian of
    /// this standard deviation.
    pub height_blur: Option<f32>,
    /// Plants growing where the layer shows ([`vegetation`]).
    pub vegetation: Vec<Vegetation>,
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
    color: toml::Spanned<Vec<f32>>,
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
    altitude: Option<ConstraintFile>,
    elevation: Option<ConstraintFile>,
    slope: Option<ConstraintFile>,
    rainfall: Option<ConstraintFile>,
    radiation: Option<ConstraintFile>,
    temperature: Option<ConstraintFile>,
    height_blur: Option<f32>,
    #[serde(default)]
    vegetation: Vec<VegetationFile>,
    #[serde(default)]
    children: Vec<toml::Spanned<LayerFile>>,
}

fn default_wavelength() -> f32 {
    8.0
}

fn one() -> f32 {
    1.0
}

/// Largest roughness B_S (metres).
pub const MAX_ROUGHNESS: f32 = 1e4;
/// Wavelengths of the noises (metres) lie in this range.
pub const WAVELENGTH_RANGE: std::ops::RangeInclusive<f32> = 1e-3..=1e6;
/// Largest `height_blur` (metres).
pub const MAX_HEIGHT_BLUR: f32 = 1e5;
/// Most distinct `height_blur` radii in a tree (one blurred height field each).
pub const MAX_BLUR_RADII: usize = 2;
/// Largest magnitude of the noise bias c_S and scale n_S.
pub const MAX_NOISE_TERM: f32 = 1e3;

/// Checks a layer's numbers against the documented ranges.
fn check_numbers(f: &LayerFile) -> std::result::Result<(), String> {
    for (what, v) in [("noise_bias", f.noise_bias), ("noise_scale", f.noise_scale)] {
        if !(v.is_finite() && v.abs() <= MAX_NOISE_TERM) {
            return Err(format!("{what} {v} is not finite within ±{MAX_NOISE_TERM}"));
        }
    }
    if !(0.0..=MAX_ROUGHNESS).contains(&f.roughness) {
        return Err(format!("roughness {} is not in [0, {MAX_ROUGHNESS}] m", f.roughness));
    }
    for (what, v) in [
        ("roughness_wavelength", f.roughness_wavelength),
        ("noise_wavelength", f.noise_wavelength),
    ] {
        if !WAVELENGTH_RANGE.contains(&v) {
            return Err(format!(
                "{what} {v} is not in [{}, {}] m",
                WAVELENGTH_RANGE.start(),
                WAVELENGTH_RANGE.end()
            ));
        }
    }
    if let Some(r) = f.height_blur {
        if !(r > 0.0 && r <= MAX_HEIGHT_BLUR) {
            return Err(format!("height_blur {r} is not in (0, {MAX_HEIGHT_BLUR}] m"));
        }
    }
    Ok(())
}

/// 1-based line of byte offset `at` in `text`.
fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

impl LayerTree {
    /// The built-in tree (`DEFAULT_LAYERS`).
    pub fn default_tree() -> LayerTree {
        // The built-in file is tested to parse.
        LayerTree::parse(DEFAULT_LAYERS, "built-in layers").unwrap_or_else(|_| LayerTree { layers: Vec::new() })
    }

    /// Reads a tree from a TOML file; errors name the file and line.
    pub fn load(path: &Path) -> Result<LayerTree> {
        let bytes = crate::io::read_input(path)?;
        let text = String::from_utf8(bytes).map_err(|_| Error::input(path, "not UTF-8 text"))?;
        LayerTree::parse(&text, &path.display().to_string())
    }

    /// Parses TOML `text`; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<LayerTree> {
        let file: TreeFile = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| format!("line {}: ", line_of(text, s.start)))
                .unwrap_or_default();
            let message = e.message().trim().replace('\n', "; ");
            Error::invalid(origin, format!("{line}{message}"))
        })?;
        let mut layers = Vec::new();
        flatten(text, origin, file.root, 0, None, &mut layers)?;
        let tree = LayerTree { layers };
        if tree.blur_radii().len() > MAX_BLUR_RADII {
            let radii = tree.blur_radii();
            return Err(Error::invalid(
                origin,
                format!(
                    "{} distinct height_blur radii {radii:?}; a tree has at most {MAX_BLUR_RADII}",
                    radii.len()
                ),
            ));
        }
        Ok(tree)
    }

    /// The root layer.
    pub fn root(&self) -> Option<&Layer> {
        self.layers.first().map(|l| &l.layer)
    }

    /// The distinct `height_blur` radii (metres), in depth-first order of
    /// first use: index k is the blurred height field k.
    pub fn blur_radii(&self) -> Vec<f32> {
        let mut radii: Vec<f32> = Vec::new();
        for r in self.layers.iter().filter_map(|l| l.layer.height_blur) {
            if !radii.contains(&r) {
                radii.push(r);
            }
        }
        radii
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
    let color: [f32; 3] = f.color.get_ref().as_slice().try_into().map_err(|_| {
        let line = line_of(text, f.color.span().start);
        let n = f.color.get_ref().len();
        Error::invalid(
            origin,
            format!("line {line}: layer '{name}': color must have 3 components, has {n}"),
        )
    })?;
    if color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(bad(format!("color {color:?} is not linear albedo in [0, 1]")));
    }
    check_numbers(&f).map_err(bad)?;
    let constrained = [
        &f.altitude,
        &f.elevation,
        &f.slope,
        &f.rainfall,
        &f.radiation,
        &f.temperature,
    ];
    if level == 0 && (constrained.iter().any(|c| c.is_some()) || f.height_blur.is_some()) {
        return Err(bad("the root is the base material and takes no constraints".into()));
    }
    let parse = |what: &str, file: Option<ConstraintFile>| {
        (file.map(|c| c.into_constraint(what)).transpose()).map_err(|why| bad(format!("{what}: {why}")))
    };
    let altitude = parse("altitude", f.altitude)?;
    let elevation = parse("elevation", f.elevation)?;
    let slope = parse("slope", f.slope)?;
    let inputs = [
        parse("rainfall", f.rainfall)?,
        parse("radiation", f.radiation)?,
        parse("temperature", f.temperature)?,
    ];
    let vegetation = (f.vegetation.into_iter().enumerate())
        .map(|(k, v)| v.into_vegetation(k))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(bad)?;
    let index = out.len();
    out.push(FlatLayer {
        layer: Layer {
            name: f.name,
            color: Vec3::from(color),
            roughness: f.roughness,
            roughness_wavelength: f.roughness_wavelength,
            noise_bias: f.noise_bias,
            noise_scale: f.noise_scale,
            noise_wavelength: f.noise_wavelength,
            altitude,
            elevation,
            slope,
            inputs,
            height_blur: f.height_blur,
            vegetation,
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
    if let Some(h) = &layer.altitude {
        product *= h.eval(inputs.altitude);
    }
    if let Some(h) = &layer.elevation {
        product *= h.eval(inputs.elevation);
    }
    if let Some(h) = &layer.slope {
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

impl Surface {}

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
    /// Height and gradient of the blurred height fields, in
    /// [`LayerTree::blur_radii`] order (unused entries: anything).
    pub blurred: [(f32, DVec2); MAX_BLUR_RADII],
}

/// CPU reference of the tree at `base`.
pub fn evaluate(tree: &LayerTree, base: &BasePoint, noise: &LayerNoise) -> Surface {
    let (lo, hi) = base.range;
    let slope = base.gradient.length().atan().to_degrees() as f32;
    let radii = tree.blur_radii();
    let mut surface = Surface {
        color: Vec3::ZERO,
        height: base.height,
        gradient: base.gradient,
        coverage: Vec::with_capacity(tree.layers.len()),
    };
    for (i, flat) in tree.layers.iter().enumerate() {
        let layer = &flat.layer;
        let c_s = match flat.parent {
            None => 1.0,
            Some(p) => {
                let mut inputs = LayerInputs {
                    altitude: surface.height,
                    elevation: 0.0,
                    slope,
                    maps: base.maps,
                };
                let blurred = (layer.height_blur)
                    .and_then(|r| radii.iter().position(|&q| q == r))
                    .and_then(|k| base.blurred.get(k));
                if let Some(&(height, gradient)) = blurred {
                    // The blurred surface plus what the layers before added.
                    inputs.altitude = height + (surface.height - base.height);
                    inputs.slope = gradient.length().atan().to_degrees() as f32;
                }
                inputs.elevation = (inputs.altitude - lo) / (hi - lo).max(1e-6);
                let (n, _) = noise(i, true, base.xy, layer.noise_wavelength);
                coverage(layer, &inputs, n) * surface.coverage[p]
            }
        };
        surface.coverage.push(c_s);
        surface.color = surface.color * (1.0 - c_s) + layer.color * c_s;
        if layer.roughness > 0.0 && c_s > 0.0 {
            let (d, grad) = noise(i, false, base.xy, layer.roughness_wavelength);
            let amplitude = c_s * layer.roughness;
            surface.height += amplitude * d;
            surface.gradient += f64::from(amplitude) * grad;
        }
    }
    surface
}

#[cfg(test)]
mod tests;
