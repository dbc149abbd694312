//! The surface-layer hierarchy of the estimated classes (§8.3, "Surface
//! Layer Hierarchy"), written in the layer tree's TOML format
//! (`crate::surface::layers`).
//!
//! Decisions (the text's simple heuristic, its "fixed values for further
//! surface parameters" chosen here):
//! * **Root**: the class with the most counted pixels, its mean colour, no
//!   constraints.
//! * **Level 1**: every other class with counted pixels, most pixels first
//!   (so the rarer, more specific classes blend over the common ones), its
//!   mean colour (the image's sRGB converted to linear albedo and averaged;
//!   the text notes such colours carry the atmosphere's blue shift — kept),
//!   and its sampled functions: `altitude` (metres, the field's range),
//!   `slope` (degrees) and every given input map.
//! * **Noise**: coverage noise of bias [`NOISE_BIAS`] and scale
//!   [`NOISE_SCALE`] at a wavelength of [`NOISE_CELLS`] sample spacings, so
//!   borders between classes fray at the scale of the image's own texture;
//!   no roughness (the altitude the functions read stays the surface's).
//! * **Level 2** (with `--level2`, `super::level2`): after each refined
//!   level-1 layer its sub-classes' layers, most pixels first, with their
//!   own mean colours and sampled functions and the level-1 noise. The
//!   level-1 order counts a class's sub-classes with it.

use std::fmt::Write as _;

use glam::{DVec2, Vec3};

use super::classify::Classification;
use super::distributions::{map_name, Distributions};
use super::{ClassCount, FromImageOptions};
use crate::surface::layers::{LayerTree, SampledFunction};

/// c_S of every level-1 layer.
pub const NOISE_BIAS: f32 = 1.0;
/// n_S of every level-1 layer.
pub const NOISE_SCALE: f32 = 0.5;
/// Coverage-noise wavelength in sample spacings.
pub const NOISE_CELLS: f64 = 3.0;

/// What the header of the file records.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    pub options: FromImageOptions,
    pub snow_min_altitude: f32,
    pub spacing: DVec2,
}

/// One layer of the generated tree.
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratedLayer {
    /// Index of its class in the classification.
    pub class: usize,
    /// 0 for the root, 1 or 2.
    pub level: usize,
    pub name: String,
    /// Linear albedo.
    pub color: Vec3,
    pub noise_bias: f32,
    pub noise_scale: f32,
    pub noise_wavelength: f32,
    /// altitude, slope, then the input maps by name (none for the root).
    pub constraints: Vec<(&'static str, SampledFunction)>,
}

/// The result of [`super::build_layers`].
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratedLayers {
    pub classification: Classification,
    pub distributions: Distributions,
    /// Depth-first: root first, then the level-1 children in order, each
    /// followed by its level-2 children.
    pub layers: Vec<GeneratedLayer>,
    /// Comment lines of the file's header (without `# `).
    pub header: Vec<String>,
    /// Share of the terrain each layer is predicted to dominate in a render
    /// ([`super::calibrate`]; empty without calibration).
    pub predicted: Vec<f64>,
}

/// The layer tree of `classification` with `distributions` (module docs).
pub fn build(
    classification: &Classification,
    distributions: &Distributions,
    provenance: &Provenance,
) -> GeneratedLayers {
    let classes = &classification.classes;
    let whole = |c: usize| -> usize {
        (classes.iter())
            .filter(|k| k.parent == Some(c))
            .map(|k| k.counted)
            .sum::<usize>()
            + classes[c].counted
    };
    let mut level1: Vec<usize> = (0..classes.len())
        .filter(|&c| classes[c].parent.is_none() && whole(c) > 0)
        .collect();
    level1.sort_by_key(|&c| std::cmp::Reverse(whole(c)));
    let mut order: Vec<(usize, usize)> = Vec::new();
    for (rank, &c) in level1.iter().enumerate() {
        order.push((c, usize::from(rank > 0)));
        let mut children: Vec<usize> = (0..classes.len())
            .filter(|&k| classes[k].parent == Some(c) && classes[k].counted > 0)
            .collect();
        children.sort_by_key(|&k| std::cmp::Reverse(classes[k].counted));
        order.extend(children.into_iter().map(|k| (k, 2)));
    }
    let wavelength = (NOISE_CELLS * provenance.spacing.max_element()) as f32;
    let layers = order
        .iter()
        .map(|&(c, level)| {
            let class = &classes[c];
            let functions = &distributions.classes[c];
            let mut constraints = Vec::new();
            if level > 0 {
                constraints.push(("altitude", functions.altitude.clone()));
                constraints.push(("slope", functions.slope.clone()));
                for (k, map) in functions.maps.iter().enumerate() {
                    if let Some(f) = map {
                        constraints.push((map_name(k), f.clone()));
                    }
                }
            }
            GeneratedLayer {
                class: c,
                level,
                name: class.name.clone(),
                color: class.linear.clamp(Vec3::ZERO, Vec3::ONE),
                noise_bias: if level > 0 { NOISE_BIAS } else { 1.0 },
                noise_scale: if level > 0 { NOISE_SCALE } else { 0.0 },
                noise_wavelength: wavelength.clamp(1e-3, 1e6),
                constraints,
            }
        })
        .collect();
    GeneratedLayers {
        header: header(classification, provenance),
        classification: classification.clone(),
        distributions: distributions.clone(),
        layers,
        predicted: Vec::new(),
    }
}

fn percent(part: usize, whole: usize) -> f64 {
    100.0 * part as f64 / whole.max(1) as f64
}

/// The header's comment lines.
fn header(classification: &Classification, provenance: &Provenance) -> Vec<String> {
    use super::classify::{PixelStatus, DARK_VALUE, GREY_SATURATION, SHADE_LIGHT};
    let o = &provenance.options;
    let n = classification.labels.len();
    let choice = match o.classes {
        ClassCount::Fixed(k) => format!("k = {k} given"),
        ClassCount::Auto => {
            let tried: Vec<String> = (classification.silhouettes.iter())
                .map(|(k, s)| format!("{k}: {s:.3}"))
                .collect();
            format!(
                "k = {} of the largest silhouette ({})",
                classification.k,
                tried.join(", ")
            )
        }
    };
    let shade = if o.shade_handling {
        format!(
            "dark pixels (V < {DARK_VALUE}) where the height field's modelled direct light (sun azimuth {}°, \
             elevation {}°, cast shadows) is below {SHADE_LIGHT} of flat ground's: {:.1} % of the pixels, \
             not counted, filled from the nearest counted pixel",
            o.sun_azimuth_deg,
            o.sun_elevation_deg,
            percent(classification.count(PixelStatus::Shade), n)
        )
    } else {
        "not handled (--no-shade-handling)".to_string()
    };
    let fractions: Vec<String> = (classification.classes.iter())
        .zip(classification.fractions())
        .map(|(c, f)| format!("{} {:.1} %", c.name, 100.0 * f))
        .collect();
    let mut lines = vec![
        "Surface layers estimated from a real image (alpenglow layers from-image; dissertation §8.3).".into(),
        format!(
            "Classes: k-means in the hue-saturation(-value, weight {}) histogram, {choice}; near-grey pixels \
             (saturation <= {GREY_SATURATION}) in reserved classes rock and snow (by shade-normalised value).",
            o.value_weight
        ),
        format!("Shade: {shade}."),
        format!(
            "Cloud: snow below {:.0} m not counted: {:.2} % of the pixels.",
            provenance.snow_min_altitude,
            percent(classification.count(PixelStatus::Cloud), n)
        ),
        format!("Area of the image per class: {}.", fractions.join(", ")),
        format!(
            "Constraints: histograms where each class occurs ({} bins) scaled to mean 0.5, clamped; colours linear.",
            o.bins
        ),
    ];
    if let Some(k) = o.level2 {
        lines.push(format!(
            "Level 2: chromatic level-1 classes with at least {:.0} % of the counted pixels split by k-means (k = {k}) \
             inside the class; the class keeps its largest sub-class's colour, the others are its children.",
            100.0 * super::level2::MIN_SHARE
        ));
    }
    if o.exclude.is_some() {
        lines.push(format!(
            "Mask: {:.1} % of the pixels excluded (not clustered, not counted, not in the class areas).",
            percent(classification.count(PixelStatus::Masked), n)
        ));
    }
    lines
}

fn float(v: f32) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    }
}

fn write_layer(out: &mut String, layer: &GeneratedLayer) {
    let c = layer.color;
    let _ = writeln!(out, "name = \"{}\"", layer.name.replace('"', "'"));
    let _ = writeln!(out, "color = [{}, {}, {}]", float(c.x), float(c.y), float(c.z));
    for (name, f) in &layer.constraints {
        let samples: Vec<String> = f.samples.iter().map(|&s| float(s)).collect();
        let _ = writeln!(
            out,
            "{name} = {{ samples = [{}], min = {}, max = {} }}",
            samples.join(", "),
            float(f.min),
            float(f.max)
        );
    }
    if layer.constraints.is_empty() {
        return;
    }
    let _ = writeln!(out, "noise_bias = {}", float(layer.noise_bias));
    let _ = writeln!(out, "noise_scale = {}", float(layer.noise_scale));
    let _ = writeln!(out, "noise_wavelength = {}", float(layer.noise_wavelength));
}

/// `layers` (root first) as TOML tables.
pub fn layers_toml(layers: &[GeneratedLayer]) -> String {
    let mut out = String::new();
    for layer in layers {
        out.push_str(match layer.level {
            0 => "\n[root]\n",
            1 => "\n[[root.children]]\n",
            _ => "\n[[root.children.children]]\n",
        });
        write_layer(&mut out, layer);
    }
    out
}

/// `layers` (root first) as a tree.
pub fn layer_tree(layers: &[GeneratedLayer]) -> crate::error::Result<LayerTree> {
    LayerTree::parse(&layers_toml(layers), "generated layers")
}

impl GeneratedLayers {
    /// The tree ([`GeneratedLayers::to_toml`] parsed).
    pub fn tree(&self) -> crate::error::Result<LayerTree> {
        layer_tree(&self.layers)
    }

    /// The tree as TOML: `sources` (e.g. the input files) and the header
    /// as comments, then `[root]`, its `[[root.children]]` and theirs.
    pub fn to_toml(&self, sources: &[String]) -> String {
        let mut out = String::new();
        for line in sources.iter().chain(&self.header) {
            let _ = writeln!(out, "# {}", line.replace('\n', " "));
        }
        out + &layers_toml(&self.layers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_are_toml_floats() {
        assert_eq!(float(1.0), "1.0");
        assert_eq!(float(0.25), "0.25");
        assert_eq!(float(2281.0), "2281.0");
        assert_eq!(float(0.123456), "0.1235");
        assert_eq!(float(0.0), "0.0");
    }
}
