//! The distribution histograms as an image (§8.3, Fig. 8.13; `layers
//! from-image --histograms PNG`): one row a class, one panel per input
//! quantity (altitude, slope, then the extra input maps present), each
//! sample of the class's [`SampledFunction`] a bar [`BAR`] pixels wide and
//! `round(F · PANEL_HEIGHT)` pixels high in the class's colour, on white,
//! with a grey baseline; a swatch of the class colour opens each row.
//! The panels have no axis labels: a panel spans its quantity's domain
//! (the `min`/`max` of the written layer file), bars bottom-up from 0 to 1.
//! Also the hue–saturation histogram of Fig. 8.12 ([`plot_hue_saturation`]).

use glam::Vec3;

use super::distributions::{ClassFunctions, Distributions};
use crate::surface::layers::SampledFunction;
use crate::texturing::reference::srgb8;

/// Width of one bar (one sample), pixels.
pub const BAR: u32 = 4;
/// Height of a panel's plot area (F = 1), pixels.
pub const PANEL_HEIGHT: u32 = 64;
/// Margin around and between the panels, pixels.
pub const MARGIN: u32 = 8;
const BACKGROUND: [u8; 4] = [255, 255, 255, 255];
const BASELINE: [u8; 4] = [160, 160, 160, 255];

/// An RGBA8 image.
pub struct Plot {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Plot {
    fn set(&mut self, x: u32, y: u32, colour: [u8; 4]) {
        let i = 4 * (y * self.width + x) as usize;
        self.rgba[i..i + 4].copy_from_slice(&colour);
    }
}

/// The functions of a class in panel order, present maps only.
fn panels(class: &ClassFunctions, maps: &[bool; 3]) -> Vec<Option<SampledFunction>> {
    let mut out = vec![Some(class.altitude.clone()), Some(class.slope.clone())];
    for (k, present) in maps.iter().enumerate() {
        if *present {
            out.push(class.maps[k].clone());
        }
    }
    out
}

/// The top-left pixel of panel `column` of row `row` (the plot area's
/// top, bars grow up from `y + PANEL_HEIGHT - 1`), for `panel_width`-wide
/// panels.
pub fn panel_origin(row: u32, column: u32, panel_width: u32) -> (u32, u32) {
    let swatch = PANEL_HEIGHT / 2;
    (
        MARGIN + swatch + MARGIN + column * (panel_width + MARGIN),
        MARGIN + row * (PANEL_HEIGHT + 2 + MARGIN),
    )
}

/// The histograms of every class (colours: the classes' linear albedos).
pub fn plot_distributions(distributions: &Distributions, colours: &[Vec3]) -> Plot {
    let maps = [0, 1, 2].map(|k| distributions.classes.iter().any(|c| c.maps[k].is_some()));
    let columns = 2 + maps.iter().filter(|&&m| m).count() as u32;
    let bins = (distributions.classes.iter())
        .flat_map(|c| panels(c, &maps))
        .flatten()
        .map(|f| f.samples.len() as u32)
        .max()
        .unwrap_or(1);
    let panel_width = bins * BAR;
    let rows = distributions.classes.len() as u32;
    let (right, bottom) = panel_origin(rows, columns, panel_width);
    let mut plot = Plot {
        width: right,
        height: bottom,
        rgba: BACKGROUND.repeat((right * bottom) as usize),
    };
    for (row, class) in distributions.classes.iter().enumerate() {
        let row = row as u32;
        let [r, g, b] = srgb8(colours.get(row as usize).copied().unwrap_or(Vec3::splat(0.5)));
        let colour = [r, g, b, 255];
        let (_, top) = panel_origin(row, 0, panel_width);
        let swatch = PANEL_HEIGHT / 2;
        for y in top + swatch / 2..top + swatch / 2 + swatch {
            for x in MARGIN..MARGIN + swatch {
                plot.set(x, y, colour);
            }
        }
        for (column, function) in panels(class, &maps).iter().enumerate() {
            let (x0, y0) = panel_origin(row, column as u32, panel_width);
            for x in x0..x0 + panel_width {
                plot.set(x, y0 + PANEL_HEIGHT, BASELINE);
            }
            let Some(function) = function else { continue };
            for (b, &f) in function.samples.iter().enumerate() {
                let bar = bar_height(f);
                for y in y0 + PANEL_HEIGHT - bar..y0 + PANEL_HEIGHT {
                    for x in x0 + b as u32 * BAR..x0 + (b as u32 + 1) * BAR - 1 {
                        plot.set(x, y, colour);
                    }
                }
            }
        }
    }
    plot
}

/// Hue bins (2° each) of the hue–saturation histogram.
pub const HUE_BINS: u32 = 180;
/// Saturation bins (0.01 each).
pub const SATURATION_BINS: u32 = 100;
/// The hue given to near-grey pixels in the histogram, as the text does
/// (violet, absent from landscapes).
pub const GREY_HUE: f64 = 280.0;

/// The (hue, saturation) bin of a pixel, near greys
/// ([`super::classify::GREY_SATURATION`], [`super::classify::GREY_MIN_VALUE`])
/// at [`GREY_HUE`].
pub fn hue_saturation_bin(pixel: [u8; 3]) -> (u32, u32) {
    let (hue, saturation, value) = super::classify::hsv(pixel);
    let grey = saturation <= super::classify::GREY_SATURATION && value >= super::classify::GREY_MIN_VALUE;
    let hue = if grey { GREY_HUE } else { hue };
    let h = ((hue / 360.0 * f64::from(HUE_BINS)) as u32).min(HUE_BINS - 1);
    let s = ((saturation * f64::from(SATURATION_BINS)) as u32).min(SATURATION_BINS - 1);
    (h, s)
}

/// Fig. 8.12's left half (`layers from-image --hs-histogram PNG`): the
/// hue–saturation histogram of every pixel of `image` (hue 0–360° left to
/// right, saturation 0 at the bottom to 1 at the top, one pixel a bin,
/// near greys at [`GREY_HUE`]), darker for more pixels on a log scale
/// (`1 − ln(1 + n)/ln(1 + max)` of white); beside it the colour table,
/// each bin in its hue and saturation at full value.
pub fn plot_hue_saturation(image: &image::RgbImage) -> Plot {
    let mut counts = vec![0u64; (HUE_BINS * SATURATION_BINS) as usize];
    for pixel in image.pixels() {
        let (h, s) = hue_saturation_bin(pixel.0);
        counts[(s * HUE_BINS + h) as usize] += 1;
    }
    let most = counts.iter().copied().max().unwrap_or(0).max(1) as f64;
    let (width, height) = (3 * MARGIN + 2 * HUE_BINS, 2 * MARGIN + SATURATION_BINS);
    let mut plot = Plot {
        width,
        height,
        rgba: BACKGROUND.repeat((width * height) as usize),
    };
    for s in 0..SATURATION_BINS {
        let y = MARGIN + SATURATION_BINS - 1 - s;
        for h in 0..HUE_BINS {
            let n = counts[(s * HUE_BINS + h) as usize] as f64;
            let v = (255.0 * (1.0 - (1.0 + n).ln() / (1.0 + most).ln())).round() as u8;
            plot.set(MARGIN + h, y, [v, v, v, 255]);
            let hue = (f64::from(h) + 0.5) / f64::from(HUE_BINS) * 360.0;
            let saturation = (f64::from(s) + 0.5) / f64::from(SATURATION_BINS);
            plot.set(2 * MARGIN + HUE_BINS + h, y, hsv_to_rgb8(hue, saturation));
        }
    }
    plot
}

/// sRGB code values of hue (degrees), saturation at value 1.
fn hsv_to_rgb8(hue: f64, saturation: f64) -> [u8; 4] {
    let f = |n: f64| {
        let k = (n + hue / 60.0).rem_euclid(6.0);
        1.0 - saturation * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    let c = |v: f64| (255.0 * v).round() as u8;
    [c(f(5.0)), c(f(3.0)), c(f(1.0)), 255]
}

/// The bar of a sample F in [0, 1], pixels.
pub fn bar_height(f: f32) -> u32 {
    (f.clamp(0.0, 1.0) * PANEL_HEIGHT as f32).round() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn function(samples: Vec<f32>) -> SampledFunction {
        SampledFunction {
            min: 0.0,
            max: 1.0,
            samples,
        }
    }

    /// The hue–saturation histogram of a 4-colour image: red (hue 0,
    /// saturation 1) on 60 pixels, half-saturated green (120°, 0.5) on 30,
    /// a light grey (at the violet grey hue, saturation 0) on 9 and black
    /// (hue 0, saturation 0: too dark to be grey) on 1: exactly four bins
    /// not white, the most filled black, the others as
    /// `1 − ln(1 + n)/ln(61)`; the colour table's red and green bins in
    /// their colours (HSV back to RGB, within the bin's width).
    #[test]
    fn hue_saturation_histogram_counts_the_pixels() {
        let mut image = image::RgbImage::new(10, 10);
        for (i, p) in image.pixels_mut().enumerate() {
            p.0 = match i {
                0..60 => [255, 0, 0],
                60..90 => [64, 128, 64],
                90..99 => [200, 200, 200],
                _ => [0, 0, 0],
            };
        }
        let plot = plot_hue_saturation(&image);
        crate::test_support::dump_pngs(&[("fig-8-12-hs-test", &plot.rgba)], plot.width, plot.height);
        let at = |x: u32, y: u32| {
            let i = 4 * (y * plot.width + x) as usize;
            [plot.rgba[i], plot.rgba[i + 1], plot.rgba[i + 2]]
        };
        let density = |h: u32, s: u32| at(MARGIN + h, MARGIN + SATURATION_BINS - 1 - s)[0];
        let expected = |n: f64| (255.0 * (1.0 - (1.0 + n).ln() / 61f64.ln())).round() as u8;
        let grey = (GREY_HUE / 2.0) as u32;
        let filled = [((0, 99), 60.0), ((60, 50), 30.0), ((grey, 0), 9.0), ((0, 0), 1.0)];
        for &((h, s), n) in &filled {
            assert_eq!(density(h, s), expected(n), "bin ({h}, {s})");
        }
        let white = (0..HUE_BINS)
            .flat_map(|h| (0..SATURATION_BINS).map(move |s| (h, s)))
            .filter(|&(h, s)| density(h, s) == 255)
            .count();
        assert_eq!(white, (HUE_BINS * SATURATION_BINS) as usize - 4);
        let table = |h: u32, s: u32| at(2 * MARGIN + HUE_BINS + h, MARGIN + SATURATION_BINS - 1 - s);
        let [r, g, b] = table(0, 99);
        assert!(r == 255 && g < 10 && b < 10, "red bin {:?}", [r, g, b]);
        let [r, g, b] = table(60, 50);
        assert!(
            g == 255 && r.abs_diff(126) <= 3 && b.abs_diff(126) <= 3,
            "green bin {:?}",
            [r, g, b]
        );
    }

    /// The plot against the samples it draws: in every panel each bar's
    /// height (its coloured pixels counted up from the baseline, down the
    /// bar's first column) is the sample's, and the class colours stay
    /// in their rows; an absent map leaves its panel empty.
    #[test]
    fn bars_have_the_heights_of_the_samples() {
        let wave = |phase: f32| {
            (0..16)
                .map(|b| (0.5 + 0.5 * (b as f32 * 0.7 + phase).sin()).min(1.0))
                .collect()
        };
        let distributions = Distributions {
            classes: vec![
                ClassFunctions {
                    altitude: function(wave(0.0)),
                    slope: function(wave(1.0)),
                    maps: [Some(function(wave(2.0))), None, None],
                },
                ClassFunctions {
                    altitude: function(wave(3.0)),
                    slope: function(vec![0.0; 16]),
                    maps: [None, None, None],
                },
            ],
        };
        let colours = [Vec3::new(0.05, 0.3, 0.05), Vec3::new(0.4, 0.3, 0.2)];
        let plot = plot_distributions(&distributions, &colours);
        crate::test_support::dump_pngs(&[("fig-8-13-histograms-test", &plot.rgba)], plot.width, plot.height);
        let pixel = |x: u32, y: u32| {
            let i = 4 * (y * plot.width + x) as usize;
            [plot.rgba[i], plot.rgba[i + 1], plot.rgba[i + 2], plot.rgba[i + 3]]
        };
        for (row, class) in distributions.classes.iter().enumerate() {
            let [r, g, b] = srgb8(colours[row]);
            let colour = [r, g, b, 255];
            let maps = [true, false, false];
            for (column, f) in panels(class, &maps).iter().enumerate() {
                let (x0, y0) = panel_origin(row as u32, column as u32, 16 * BAR);
                assert_eq!(pixel(x0, y0 + PANEL_HEIGHT), BASELINE, "baseline of {row}/{column}");
                let samples = f.as_ref().map_or(vec![0.0; 16], |f| f.samples.clone());
                for (bin, &s) in samples.iter().enumerate() {
                    let x = x0 + bin as u32 * BAR;
                    let drawn = (0..PANEL_HEIGHT)
                        .filter(|&dy| pixel(x, y0 + PANEL_HEIGHT - 1 - dy) == colour)
                        .count() as u32;
                    let expected = (s * PANEL_HEIGHT as f32).round() as u32;
                    assert_eq!(drawn, expected, "class {row}, panel {column}, bin {bin}: sample {s}");
                    // Bars are contiguous from the baseline.
                    if drawn > 0 {
                        assert_eq!(pixel(x, y0 + PANEL_HEIGHT - drawn), colour);
                    }
                    assert_eq!(
                        pixel(x + BAR - 1, y0 + PANEL_HEIGHT - 1),
                        BACKGROUND,
                        "gap after bar {bin}"
                    );
                }
            }
        }
    }
}
