//! The height field a sky-light bake runs on (§9.3–9.5 bake per texel of
//! the field): the field itself when the device holds its per-texel
//! buffers, else an area-averaged copy over the same extent with as many
//! samples as it holds. Sky light varies slowly across the terrain (the
//! text bakes 1025² fields), so a coarser bake of a huge DEM loses little,
//! while the alternative is no sky light at all: lavapipe's storage
//! buffers hold 128 MiB, about 660² texels of a 5-band transfer.

use std::borrow::Cow;

use super::bake::BakeSettings;
use super::SURFACE_FLOATS;
use crate::io::heightmap::HeightField;

/// The most texels per side and in all a bake may have on a device whose
/// storage buffers hold `buffer_bytes` and whose 2D images have at most
/// `image_side` texels per side (the horizon map is 2·columns × 2·rows).
pub fn bake_capacity(settings: &BakeSettings, buffer_bytes: u64, image_side: u32) -> (u32, u64) {
    let per_texel = [settings.azimuths, SURFACE_FLOATS, settings.stride()]
        .into_iter()
        .max()
        .unwrap_or(1)
        .max(1);
    (image_side / 2, buffer_bytes / (u64::from(per_texel) * 4))
}

/// `field`, or its area average over the same extent at the largest size
/// within `capacity` (see [`bake_capacity`]) with the field's aspect.
pub fn bake_field(field: &HeightField, capacity: (u32, u64)) -> Cow<'_, HeightField> {
    let (max_side, max_texels) = capacity;
    let texels = u64::from(field.columns) * u64::from(field.rows);
    if texels <= max_texels && field.columns <= max_side && field.rows <= max_side {
        return Cow::Borrowed(field);
    }
    // Shrink both sides by one factor until the grid fits.
    let mut scale = (max_texels as f64 / texels as f64).sqrt().min(1.0);
    scale = scale.min(f64::from(max_side) / f64::from(field.columns.max(field.rows)));
    loop {
        let side = |n: u32| ((f64::from(n - 1) * scale).floor() as u32 + 1).max(2);
        let (columns, rows) = (side(field.columns), side(field.rows));
        if u64::from(columns) * u64::from(rows) <= max_texels && columns.max(rows) <= max_side || scale < 1e-6 {
            return Cow::Owned(area_resample(field, columns, rows));
        }
        scale *= 0.99;
    }
}

/// `field` resampled to `columns` × `rows` samples over the same extent:
/// each new sample is the mean of the old samples within half a new
/// spacing of it (a separable box filter; at least the nearest sample).
pub fn area_resample(field: &HeightField, columns: u32, rows: u32) -> HeightField {
    let (n_c, n_r) = (field.columns as usize, field.rows as usize);
    // Along rows: n_r × columns.
    let along = |n_old: usize, n_new: u32, i: usize| -> (usize, usize) {
        let step = (n_old - 1) as f64 / f64::from(n_new - 1).max(1.0);
        let x = i as f64 * step;
        let lo = (x - step / 2.0).ceil().max(0.0) as usize;
        let hi = ((x + step / 2.0).floor() as usize).min(n_old - 1);
        if lo > hi {
            let nearest = (x.round() as usize).min(n_old - 1);
            (nearest, nearest)
        } else {
            (lo, hi)
        }
    };
    let mut rows_done = vec![0f32; n_r * columns as usize];
    for c in 0..columns as usize {
        let (lo, hi) = along(n_c, columns, c);
        for r in 0..n_r {
            let row = &field.heights[r * n_c..(r + 1) * n_c];
            let sum: f64 = row[lo..=hi].iter().map(|&h| f64::from(h)).sum();
            rows_done[r * columns as usize + c] = (sum / (hi - lo + 1) as f64) as f32;
        }
    }
    let mut heights = vec![0f32; rows as usize * columns as usize];
    for r in 0..rows as usize {
        let (lo, hi) = along(n_r, rows, r);
        for c in 0..columns as usize {
            let sum: f64 = (lo..=hi).map(|k| f64::from(rows_done[k * columns as usize + c])).sum();
            heights[r * columns as usize + c] = (sum / (hi - lo + 1) as f64) as f32;
        }
    }
    let extent = field.extent();
    HeightField {
        columns,
        rows,
        spacing: glam::DVec2::new(extent.x / f64::from(columns - 1), extent.y / f64::from(rows - 1)),
        heights,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn field(columns: u32, rows: u32) -> HeightField {
        HeightField::from_fn(columns, rows, DVec2::new(3.0, 2.0), |c, r| (c * 2 + r * 5) as f32)
    }

    #[test]
    fn a_field_that_fits_is_used_as_it_is() {
        let f = field(65, 33);
        assert!(matches!(bake_field(&f, (1024, 65 * 33)), Cow::Borrowed(_)));
    }

    /// A plane stays the same plane over the same extent (the box filter
    /// of a linear function at its centre is the function), within the
    /// capacity and the device's image side.
    #[test]
    fn a_large_field_is_averaged_over_the_same_extent() {
        let f = field(1001, 601);
        let capacity = (256, 40_000);
        let fit = bake_field(&f, capacity);
        assert!(u64::from(fit.columns) * u64::from(fit.rows) <= capacity.1);
        assert!(fit.columns <= capacity.0 && fit.rows <= capacity.0);
        assert!(fit.columns > 200, "{}×{}: too coarse", fit.columns, fit.rows);
        assert!((fit.extent() - f.extent()).abs().max_element() < 1e-6);
        for (c, r) in [(0, 0), (fit.columns - 1, fit.rows - 1), (fit.columns / 3, fit.rows / 2)] {
            let world = DVec2::new(f64::from(c) * fit.spacing.x, f64::from(r) * fit.spacing.y);
            let plane = 2.0 * world.x / 3.0 + 5.0 * world.y / 2.0;
            let got = f64::from(fit.height(c, r));
            // Edge samples average a one-sided window: half a source step off at most.
            assert!(
                (got - plane).abs() <= 0.5 * 2.0 * fit.spacing.x / 3.0 + 0.5 * 5.0 * fit.spacing.y / 2.0 + 1e-3,
                "({c},{r}) {got} vs {plane}"
            );
        }
        let interior = (fit.columns / 3, fit.rows / 2);
        let world = DVec2::new(
            f64::from(interior.0) * fit.spacing.x,
            f64::from(interior.1) * fit.spacing.y,
        );
        let plane = 2.0 * world.x / 3.0 + 5.0 * world.y / 2.0;
        assert!(
            (f64::from(fit.height(interior.0, interior.1)) - plane).abs() < 2.0,
            "interior"
        );
    }

    /// lavapipe's 128 MiB storage buffers and a 5-band transfer (89 floats
    /// per texel): about 610² texels.
    #[test]
    fn lavapipe_capacity_of_the_default_bake() {
        let (side, texels) = bake_capacity(&BakeSettings::default(), 128 << 20, 16384);
        assert_eq!(side, 8192);
        let per_texel = BakeSettings::default().stride().max(32) as u64 * 4;
        assert_eq!(texels, (128 << 20) / per_texel);
        assert!((300_000..500_000).contains(&texels), "{texels}");
    }
}
