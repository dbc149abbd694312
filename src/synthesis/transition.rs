//! Growing a transition between two height fields (dissertation §7.3.3,
//! "Merging Terrains with Different Features"; Fig. 7.5, 7.6).
//!
//! # Geometry
//!
//! `A` and `B` have the same size and spacing. The output keeps `A` on the
//! low side of the axis (columns, or rows with [`Axis::Y`]) and `B` on the
//! high side; between them lies a band of `k = round(W / spacing)`
//! samples, `W` the band width in metres, starting at sample
//! `⌊(L − k)/2⌋` of the `L` along the axis (centred on the middle). The
//! band is unknown and grown from both edges towards the middle by pixel
//! growing ([`crate::synthesis::fill`]) whose candidates are the fully
//! known windows of the composed field: `A`'s part and `B`'s part.
//!
//! The text asks for a more randomised choice here, a larger ε, so that
//! features of either terrain can start to grow into the band; its example
//! uses a window of 19. The defaults ([`TransitionParams::default`]) are a
//! window of 11 and ε = 0.5. The noise this leaves is removed as the text
//! does, by a blur of the grown band: a separable Gaussian of radius `R`
//! samples (σ = R/2, weights normalised, edges clamped), `R = 2` by
//! default, written to band samples only — `A`'s and `B`'s samples stay
//! exactly as given.
//!
//! One departure from the text: the band grows on the residual over a
//! smooth base ([`plan_transition`]), so that fields at different heights
//! meet without a cliff.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::synthesis::fill::{plan_hole_fill, FillParams, Growth};
use crate::synthesis::search::{CpuSearch, NeighbourhoodSearch};

/// The axis across which the fields are joined.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Axis {
    /// `A` west (low columns), `B` east; the band is a range of columns.
    #[default]
    X,
    /// `A` south (low rows), `B` north; the band is a range of rows.
    Y,
}

/// Parameters of transition growing (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransitionParams {
    /// Pixel growing.
    pub grow: FillParams,
    /// Band width W in metres, `--band`.
    pub band_metres: f64,
    /// The axis across which A and B are joined, `--axis`.
    pub axis: Axis,
    /// Radius R of the blur of the grown band in samples (0: none), `--blur`.
    pub blur_radius: u32,
}

impl Default for TransitionParams {
    /// Window 11, ε = 0.5 (otherwise [`FillParams::default`]), a band of
    /// 0 m (must be set), axis x, blur radius 2.
    fn default() -> Self {
        TransitionParams {
            grow: FillParams {
                window: 11,
                epsilon: 0.5,
                ..FillParams::default()
            },
            band_metres: 0.0,
            axis: Axis::X,
            blur_radius: 2,
        }
    }
}

/// Where the band lies: samples `start..start + width` along the axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Band {
    pub axis: Axis,
    pub start: u32,
    pub width: u32,
}

impl Band {
    /// Whether sample (column `c`, row `r`) lies in the band.
    pub fn contains(&self, c: u32, r: u32) -> bool {
        let along = if self.axis == Axis::X { c } else { r };
        (self.start..self.start + self.width).contains(&along)
    }
}

/// The band between two `columns`×`rows` fields of `spacing` (module
/// docs), checked against their size; nothing is allocated, so callers can
/// estimate the growth's cost (`crate::synthesis::cost`) first.
pub fn band_of(columns: u32, rows: u32, spacing: glam::DVec2, params: &TransitionParams) -> Result<Band> {
    let (length, spacing) = match params.axis {
        Axis::X => (columns, spacing.x),
        Axis::Y => (rows, spacing.y),
    };
    let w = params.band_metres;
    let samples = (w / spacing).round();
    if !(w.is_finite() && w > 0.0 && samples >= 1.0) {
        return Err(Error::invalid(
            "--band",
            format!("{w} m: the band must be at least one sample ({spacing} m) wide"),
        ));
    }
    if samples > f64::from(length) - 2.0 {
        return Err(Error::invalid(
            "--band",
            format!(
                "{w} m is {samples} samples, but the fields are {length} samples across (at most {} for the band)",
                length.saturating_sub(2)
            ),
        ));
    }
    Ok(Band {
        axis: params.axis,
        start: (length - samples as u32) / 2,
        width: samples as u32,
    })
}

/// Checks that `a` and `b` can be joined: the same size and spacing.
pub fn check_fields(a: &HeightField, b: &HeightField) -> Result<()> {
    if (a.columns, a.rows) != (b.columns, b.rows) {
        return Err(Error::invalid(
            "B",
            format!(
                "is {}×{} samples, A is {}×{}; the fields must be the same size",
                b.columns, b.rows, a.columns, a.rows
            ),
        ));
    }
    if a.spacing != b.spacing {
        return Err(Error::invalid(
            "B",
            format!(
                "has a spacing of ({}, {}) m, A of ({}, {}) m; the fields must have the same spacing",
                b.spacing.x, b.spacing.y, a.spacing.x, a.spacing.y
            ),
        ));
    }
    Ok(())
}

/// The composed field (A, an empty band, B), its unknown mask and the band.
pub fn compose(a: &HeightField, b: &HeightField, params: &TransitionParams) -> Result<(HeightField, Vec<bool>, Band)> {
    check_fields(a, b)?;
    let band = band_of(a.columns, a.rows, a.spacing, params)?;
    let mut unknown = Vec::with_capacity(a.heights.len());
    let mut composed = a.clone();
    for r in 0..a.rows {
        for c in 0..a.columns {
            let i = (r * a.columns + c) as usize;
            let inside = band.contains(c, r);
            let along = if params.axis == Axis::X { c } else { r };
            composed.heights[i] = if inside {
                0.0
            } else if along < band.start {
                a.heights[i]
            } else {
                b.heights[i]
            };
            unknown.push(inside);
        }
    }
    Ok((composed, unknown, band))
}

/// A prepared transition: the band, the composed field (A, B and a
/// linear ramp across the band) and its smooth base (module docs).
pub struct Transition {
    pub band: Band,
    composed: HeightField,
    base: Vec<f64>,
}

impl Transition {
    /// The joined field from the grown residual: band samples `base +
    /// residual`, blurred with radius `blur`; A's and B's samples exactly
    /// as given.
    pub fn finish(&self, residual: &HeightField, blur: u32) -> HeightField {
        let mut out = self.composed.clone();
        for r in 0..out.rows {
            for c in 0..out.columns {
                if self.band.contains(c, r) {
                    let i = (r * out.columns + c) as usize;
                    out.heights[i] = (self.base[i] + f64::from(residual.heights[i])) as f32;
                }
            }
        }
        blur_band(&out, &self.band, blur)
    }

    /// An intermediate step of the growth (Fig. 7.6): the band's grown
    /// samples `base + residual`, its unknown ones the smooth base (the
    /// blurred ramp), unblurred; A's and B's samples as given.
    pub fn partial(&self, residual: &HeightField, unknown: &[bool]) -> HeightField {
        let mut out = self.composed.clone();
        for r in 0..out.rows {
            for c in 0..out.columns {
                if self.band.contains(c, r) {
                    let i = (r * out.columns + c) as usize;
                    let grown = if unknown[i] {
                        0.0
                    } else {
                        f64::from(residual.heights[i])
                    };
                    out.heights[i] = (self.base[i] + grown) as f32;
                }
            }
        }
        out
    }
}

/// Prepares growing the transition between `a` and `b`: the growth of the
/// residual's band and the `Transition` that turns the grown residual
/// into the joined field.
///
/// The band is grown on the residual over a smooth base, not on absolute
/// heights: the base is the composed field with each line across the band
/// a linear ramp between the band's two edge samples, blurred with a
/// Gaussian of radius n (the window side; σ = n/2); the residual, height
/// minus base, of A's and B's samples is the exemplar and the grown band's
/// height is base + residual. Copying absolute heights, as the text does,
/// leaves a cliff in the band where the fronts from A and from B meet
/// whenever the two fields lie at different heights.
pub fn plan_transition(a: &HeightField, b: &HeightField, params: &TransitionParams) -> Result<(Growth, Transition)> {
    let (mut composed, unknown, band) = compose(a, b, params)?;
    let (w, h) = (composed.columns, composed.rows);
    let across = if band.axis == Axis::X { h } else { w };
    for line in 0..across {
        let index = |along: u32| {
            let (c, r) = if band.axis == Axis::X {
                (along, line)
            } else {
                (line, along)
            };
            (r * w + c) as usize
        };
        let (lo, hi) = (band.start - 1, band.start + band.width);
        let (h_lo, h_hi) = (
            f64::from(composed.heights[index(lo)]),
            f64::from(composed.heights[index(hi)]),
        );
        for along in band.start..hi {
            let t = f64::from(along - lo) / f64::from(hi - lo);
            composed.heights[index(along)] = (h_lo + t * (h_hi - h_lo)) as f32;
        }
    }
    let base = gaussian_blur(&composed, params.grow.window);
    let mut residual = composed.clone();
    for (i, v) in residual.heights.iter_mut().enumerate() {
        *v = if unknown[i] {
            0.0
        } else {
            (f64::from(*v) - base[i]) as f32
        };
    }
    let growth = plan_hole_fill(&residual, &unknown, &params.grow)?;
    Ok((growth, Transition { band, composed, base }))
}

/// A separable Gaussian blur of `field` with radius `radius` samples (σ =
/// radius/2, weights normalised, edges clamped).
fn gaussian_blur(field: &HeightField, radius: u32) -> Vec<f64> {
    let heights: Vec<f64> = field.heights.iter().map(|&v| f64::from(v)).collect();
    if radius == 0 {
        return heights;
    }
    let sigma = f64::from(radius) / 2.0;
    let kernel: Vec<f64> = (-(radius as i64)..=radius as i64)
        .map(|x| (-(x * x) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let (w, h) = (field.columns as i64, field.rows as i64);
    let pass = |values: &[f64], along_x: bool| -> Vec<f64> {
        let mut out = vec![0.0; values.len()];
        for r in 0..h {
            for c in 0..w {
                let mut sum = 0.0;
                for (k, g) in kernel.iter().enumerate() {
                    let d = k as i64 - radius as i64;
                    let (cc, rr) = if along_x {
                        ((c + d).clamp(0, w - 1), r)
                    } else {
                        (c, (r + d).clamp(0, h - 1))
                    };
                    sum += g * values[(rr * w + cc) as usize];
                }
                out[(r * w + c) as usize] = sum / total;
            }
        }
        out
    };
    pass(&pass(&heights, true), false)
}

/// Blurs the band of a grown field (module docs); other samples unchanged.
pub fn blur_band(grown: &HeightField, band: &Band, radius: u32) -> HeightField {
    let blurred = gaussian_blur(grown, radius);
    let mut out = grown.clone();
    for r in 0..grown.rows {
        for c in 0..grown.columns {
            if band.contains(c, r) {
                let i = (r * grown.columns + c) as usize;
                out.heights[i] = blurred[i] as f32;
            }
        }
    }
    out
}

/// Grows the transition between `a` and `b` with `search` (which must
/// hold the exemplar of [`plan_transition`] for the same arguments) and
/// blurs the band; reports `(grown, total)` band samples.
pub fn grow_transition(
    a: &HeightField,
    b: &HeightField,
    params: &TransitionParams,
    search: &mut dyn NeighbourhoodSearch,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<HeightField> {
    let (growth, transition) = plan_transition(a, b, params)?;
    let residual = growth.grow(search, progress)?;
    Ok(transition.finish(&residual, params.blur_radius))
}

/// [`grow_transition`] with the CPU search.
pub fn grow_transition_cpu(
    a: &HeightField,
    b: &HeightField,
    params: &TransitionParams,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<HeightField> {
    let (growth, transition) = plan_transition(a, b, params)?;
    let mut search = CpuSearch {
        exemplar: growth.exemplar().clone(),
        config: growth.search_config(),
    };
    let residual = growth.grow(&mut search, progress)?;
    Ok(transition.finish(&residual, params.blur_radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn the_band_is_centred_and_grown_between_a_and_b() {
        let a = HeightField::from_fn(30, 16, DVec2::splat(10.0), |c, r| ((c * 7 + r * 3) % 5) as f32);
        let b = HeightField::from_fn(30, 16, DVec2::splat(10.0), |c, r| 100.0 + ((c * 3 + r) % 4) as f32);
        let params = TransitionParams {
            band_metres: 60.0,
            grow: FillParams {
                window: 5,
                ..TransitionParams::default().grow
            },
            ..TransitionParams::default()
        };
        let (_, unknown, band) = compose(&a, &b, &params).unwrap();
        assert_eq!((band.start, band.width), (12, 6));
        assert_eq!(unknown.iter().filter(|&&u| u).count(), 6 * 16);
        let out = grow_transition_cpu(&a, &b, &params, &mut |_, _| {}).unwrap();
        for r in 0..16 {
            for c in 0..30 {
                let i = (r * 30 + c) as usize;
                if c < 12 {
                    assert_eq!(out.heights[i].to_bits(), a.heights[i].to_bits());
                } else if c >= 18 {
                    assert_eq!(out.heights[i].to_bits(), b.heights[i].to_bits());
                } else {
                    assert!((0.0..=103.0).contains(&out.heights[i]), "{}", out.heights[i]);
                }
            }
        }
    }

    #[test]
    fn mismatched_fields_and_bands_are_errors() {
        let a = HeightField::from_fn(20, 10, DVec2::ONE, |c, _| c as f32);
        let b = HeightField::from_fn(20, 11, DVec2::ONE, |c, _| c as f32);
        let p = TransitionParams {
            band_metres: 4.0,
            ..TransitionParams::default()
        };
        assert!(compose(&a, &b, &p).unwrap_err().to_string().contains("same size"));
        let wide = TransitionParams { band_metres: 19.0, ..p };
        assert!(compose(&a, &a, &wide).unwrap_err().to_string().contains("--band"));
        let thin = TransitionParams { band_metres: 0.2, ..p };
        assert!(compose(&a, &a, &thin).unwrap_err().to_string().contains("--band"));
    }
}
