//! The CPU twin of the GPU's layer evaluation (dissertation §8.2): the
//! tree of [`crate::surface::layers`] evaluated with the same base
//! surface (the height field's cubic B-spline), the same band-limited
//! wavelet-noise fBm, the same per-layer noise offsets and the same input
//! map sampling as `glsl/include/surface_layers.glsl`, in f64, and the same
//! blurred height fields for `height_blur` layers
//! ([`crate::surface::blurred_height`]). Tests compare the atlas's texels
//! with it.

use glam::{DVec2, Vec3};

use crate::error::Result;
use crate::io::heightmap::HeightField;
use crate::surface::blurred_height::blurred_height;
use crate::surface::bspline::{sample_bspline, sample_bspline_gradient};
use crate::surface::layers::{evaluate, BasePoint, LayerTree, Surface, MAX_BLUR_RADII};
use crate::surface::wavelet_noise::NOISE_TILE;
use crate::surface::wavelet_noise::{evaluate_gradient, noise_tile};

/// Offsets of the coverage noise N and the displacement noise D of layer
/// `i`, per octave `k` multiplied by `k + 1` (as in the shader).
fn noise_offset(i: usize, coverage: bool) -> DVec2 {
    let base = if coverage {
        DVec2::new(17.3, 41.9)
    } else {
        DVec2::new(29.1, 7.7)
    };
    base * (i as f64 + 1.0)
}

/// Everything the layer evaluation reads.
pub struct ReferenceSurface<'a> {
    pub field: &'a HeightField,
    pub tree: &'a LayerTree,
    pub maps: &'a [Option<HeightField>; 3],
    tile: Vec<f32>,
    /// The height field blurred for each of the tree's `height_blur` radii.
    blurred: Vec<HeightField>,
    /// The height field's lowest and highest sample (computed once: a
    /// scan of the whole field per evaluation would dominate its cost).
    range: (f32, f32),
}

impl<'a> ReferenceSurface<'a> {
    /// With the wavelet noise tile of `noise_seed` (the terrain settings'
    /// `noise_seed`).
    pub fn new(
        field: &'a HeightField,
        tree: &'a LayerTree,
        maps: &'a [Option<HeightField>; 3],
        noise_seed: u64,
    ) -> Result<ReferenceSurface<'a>> {
        Ok(ReferenceSurface {
            field,
            tree,
            maps,
            tile: noise_tile(noise_seed, NOISE_TILE)?,
            range: field.min_max(),
            blurred: (tree.blur_radii().into_iter().take(MAX_BLUR_RADII))
                .map(|r| blurred_height(field, r, "height_blur"))
                .collect::<Result<_>>()?,
        })
    }

    /// `layer_noise` of the shader: three octaves of wavelet noise from
    /// wavelength `wavelength` down, each weighted by
    /// `clamp(λ/(2·footprint) − 1, 0, 1)`; value and world gradient.
    pub fn layer_noise(&self, xy: DVec2, wavelength: f64, offset: DVec2, footprint: f64) -> (f64, DVec2) {
        let mut freq = 3.0 / wavelength;
        let mut amplitude = 0.87;
        let (mut value, mut grad) = (0.0, DVec2::ZERO);
        for k in 0..3 {
            let lambda = wavelength * (-(k as f64)).exp2();
            let weight = if footprint > 0.0 {
                (lambda / (2.0 * footprint) - 1.0).clamp(0.0, 1.0)
            } else {
                1.0
            };
            if weight <= 0.0 {
                break;
            }
            let p = xy * freq + offset * (k as f64 + 1.0);
            let (n, g) = evaluate_gradient(&self.tile, NOISE_TILE, p.x, p.y);
            value += weight * amplitude * n;
            grad += weight * amplitude * g * freq;
            freq *= 2.0;
            amplitude *= 0.5;
        }
        (value, grad)
    }

    /// Input map `k` at world `xy`: bilinear over its grid spanning the
    /// terrain rectangle; NaN when absent.
    pub fn input_map(&self, k: usize, xy: DVec2) -> f32 {
        let Some(map) = self.maps.get(k).and_then(Option::as_ref) else {
            return f32::NAN;
        };
        if map.columns < 2 || map.rows < 2 || map.heights.len() < (map.columns * map.rows) as usize {
            return f32::NAN;
        }
        let uv = (xy / self.field.extent()).clamp(DVec2::ZERO, DVec2::ONE);
        let g = uv * DVec2::new(f64::from(map.columns - 1), f64::from(map.rows - 1));
        let (c0, r0) = (
            g.x.floor().min(f64::from(map.columns - 2)),
            g.y.floor().min(f64::from(map.rows - 2)),
        );
        let (fx, fy) = (g.x - c0, g.y - r0);
        let at = |c: f64, r: f64| f64::from(map.height(c as u32, r as u32));
        let top = at(c0, r0) * (1.0 - fx) + at(c0 + 1.0, r0) * fx;
        let bottom = at(c0, r0 + 1.0) * (1.0 - fx) + at(c0 + 1.0, r0 + 1.0) * fx;
        (top * (1.0 - fy) + bottom * fy) as f32
    }

    /// The tree at world `xy`, noise band-limited to `footprint` metres.
    pub fn evaluate(&self, xy: DVec2, footprint: f64) -> Surface {
        let base = BasePoint {
            xy,
            height: sample_bspline(self.field, xy.x, xy.y) as f32,
            gradient: sample_bspline_gradient(self.field, xy.x, xy.y),
            range: self.range,
            maps: [0, 1, 2].map(|k| self.input_map(k, xy)),
            blurred: std::array::from_fn(|k| match self.blurred.get(k) {
                Some(b) => (
                    sample_bspline(b, xy.x, xy.y) as f32,
                    sample_bspline_gradient(b, xy.x, xy.y),
                ),
                None => (0.0, DVec2::ZERO),
            }),
        };
        let noise = |i: usize, coverage: bool, p: DVec2, wavelength: f32| {
            let (v, g) = self.layer_noise(p, f64::from(wavelength), noise_offset(i, coverage), footprint);
            (v as f32, g)
        };
        evaluate(self.tree, &base, &noise)
    }
}

/// Linear → sRGB-encoded 8-bit, as `texturing.finish` stores colour.
pub fn srgb8(c: Vec3) -> [u8; 3] {
    let encode = |v: f32| {
        let v = v.clamp(0.0, 1.0);
        let s = if v > 0.003_130_8 {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        } else {
            v * 12.92
        };
        (s * 255.0).round() as u8
    };
    [encode(c.x), encode(c.y), encode(c.z)]
}
