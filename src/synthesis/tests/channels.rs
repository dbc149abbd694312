//! The synthesis channels as images (dissertation §7.3.3, Fig. 7.3: "in
//! addition to the height values, the synthesis accounts also for
//! horizontal and vertical derivatives, scaled and biased to be
//! represented as gray-scale image") on the 128² Jacksboro crop of
//! `super::fill`.
//!
//! The derivative images show the normalised slopes the search compares
//! (`synthesis::exemplar`): grey `128 + 32·t`, `t` = ∂h/∂x or ∂h/∂y in
//! units of the RMS slope, clamped to 0–255; the height image spans the
//! field's range (the normalised height, in units of one step between
//! neighbours, spans hundreds of units). The check against an
//! independent reference: every interior pixel of the derivative images
//! decodes to the central difference of the heights, divided by the
//! spacing and the RMS of those differences (computed here, not by
//! `exemplar`), within the 8-bit rounding.
//!
//! With `ALPENGLOW_DUMP=DIR`: `N-channels.png`, height, ∂h/∂x, ∂h/∂y and
//! a hillshade side by side.

use super::fill::{crop, hillshade};
use crate::io::heightmap::HeightField;
use crate::synthesis::exemplar::{slopes, texels, Normalisation};

/// Grey of one normalised value: scaled by 32 and biased by 128.
fn grey(t: f32) -> u8 {
    (128.0 + 32.0 * t).round().clamp(0.0, 255.0) as u8
}

/// The three channel images of `field` (all samples known), as grey bytes.
fn channel_images(field: &HeightField) -> [Vec<u8>; 3] {
    let unknown = vec![false; field.heights.len()];
    let s = slopes(field, &unknown);
    let norm = Normalisation::of(field, &unknown, &s);
    let t = texels(field, &unknown, &s, &norm);
    let (lo, hi) = t.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x[0]), hi.max(x[0]))
    });
    let heights = t
        .iter()
        .map(|x| ((x[0] - lo) / (hi - lo) * 255.0).round() as u8)
        .collect();
    let slope = |k: usize| t.iter().map(|texel| grey(texel[k])).collect();
    [heights, slope(1), slope(2)]
}

#[test]
fn derivative_images_are_scaled_central_differences() {
    let field = crop();
    let images = channel_images(&field);
    let (w, h) = (field.columns, field.rows);

    // The reference: central differences and their RMS over the interior
    // and one-sided ones on the border, as the text's "differences of
    // neighbouring height values".
    let at = |c: u32, r: u32| f64::from(field.height(c, r));
    let dx = |c: u32, r: u32| match c {
        0 => (at(1, r) - at(0, r)) / field.spacing.x,
        c if c == w - 1 => (at(c, r) - at(c - 1, r)) / field.spacing.x,
        c => (at(c + 1, r) - at(c - 1, r)) / (2.0 * field.spacing.x),
    };
    let dy = |c: u32, r: u32| match r {
        0 => (at(c, 1) - at(c, 0)) / field.spacing.y,
        r if r == h - 1 => (at(c, r) - at(c, r - 1)) / field.spacing.y,
        r => (at(c, r + 1) - at(c, r - 1)) / (2.0 * field.spacing.y),
    };
    let samples = || (0..h).flat_map(move |r| (0..w).map(move |c| (c, r)));
    let rms =
        (samples().map(|(c, r)| dx(c, r).powi(2) + dy(c, r).powi(2)).sum::<f64>() / (2.0 * f64::from(w * h))).sqrt();
    let decode = |g: u8| (f64::from(g) - 128.0) / 32.0;
    let mut worst = 0.0f64;
    let mut clamped = 0;
    for (c, r) in samples() {
        let i = (r * w + c) as usize;
        for (image, want) in [(&images[1], dx(c, r) / rms), (&images[2], dy(c, r) / rms)] {
            if want.abs() >= 3.9 {
                clamped += 1;
                assert!(image[i] == 0 || image[i] == 255, "({c}, {r}): {want} not clamped");
                continue;
            }
            worst = worst.max((decode(image[i]) - want).abs());
        }
    }
    eprintln!("channels: worst decoded slope error {worst:.4} RMS slopes, {clamped} clamped");
    assert!(worst <= 0.5 / 32.0 + 1e-4, "worst error {worst}");
    assert!(clamped < (w * h / 50) as usize, "{clamped} samples clamped");
    // The images are not flat: each channel spans most of the grey range.
    for (k, image) in images.iter().enumerate() {
        let (lo, hi) = (image.iter().min().unwrap(), image.iter().max().unwrap());
        assert!(hi - lo > 128, "channel {k} spans only {lo}..{hi}");
    }

    let rgba = |g: &Vec<u8>| -> Vec<u8> { g.iter().flat_map(|&v| [v, v, v, 255]).collect() };
    let panels = [rgba(&images[0]), rgba(&images[1]), rgba(&images[2]), hillshade(&field)];
    let strip = crate::test_support::side_by_side(&panels, w);
    crate::test_support::dump_pngs(&[("channels", &strip)], 4 * w, h);
}
