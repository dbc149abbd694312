//! The light baked into the image, modelled from the height field (§8.3
//! step "identification and classification"): a satellite image shows
//! albedo times irradiance, so walls facing away from the sun are dark
//! whatever they are made of. The text relies on hue and saturation
//! ignoring shading; where a wall is nearly black, hue and saturation are
//! noise and it would cluster with water or dark rock. So the sun's direct
//! light is modelled here and [`super::classify`] sets dark pixels in
//! modelled shadow aside.
//!
//! Decisions:
//! * The surface is the height field's cubic B-spline (the surface the
//!   renderer draws), its normal from the analytic gradient; world +y is
//!   north (load north-up rasters with `RowOrder::NorthUp`).
//! * Direct light relative to flat ground: `R = max(0, n·s) / sin(e)` for
//!   the sun direction `s` of azimuth `A` (clockwise from north) and
//!   elevation `e`: 1 on flat ground, 0 facing away, up to `1 / sin(e)`.
//! * Cast shadow: `R = 0` where the terrain rises above the ray towards
//!   the sun (marched in steps of half the smaller sample spacing up to
//!   the height of the field's highest sample, 1 m tolerance).

use glam::DVec2;

use crate::io::heightmap::HeightField;
use crate::surface::bspline::{sample_bspline, sample_bspline_gradient};

/// Direction towards the sun (east, north, up) for azimuth and elevation in degrees.
pub fn sun_direction(azimuth_deg: f64, elevation_deg: f64) -> glam::DVec3 {
    let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    glam::DVec3::new(a.sin() * e.cos(), a.cos() * e.cos(), e.sin())
}

/// Direct light at `xy` relative to flat ground, without cast shadow.
pub fn hillshade(field: &HeightField, xy: DVec2, sun: glam::DVec3) -> f64 {
    let g = sample_bspline_gradient(field, xy.x, xy.y);
    let n = glam::DVec3::new(-g.x, -g.y, 1.0).normalize();
    n.dot(sun).max(0.0) / sun.z
}

/// Whether the terrain hides the sun from `xy` (module docs).
pub fn in_cast_shadow(field: &HeightField, xy: DVec2, sun: glam::DVec3, top: f64) -> bool {
    let horizontal = DVec2::new(sun.x, sun.y);
    let length = horizontal.length();
    if length < 1e-9 {
        return false;
    }
    let (dir, rise) = (horizontal / length, sun.z / length);
    let step = 0.5 * field.spacing.min_element();
    let start = sample_bspline(field, xy.x, xy.y);
    let extent = field.extent();
    let mut t = step;
    loop {
        let ray = start + t * rise;
        if ray > top {
            return false;
        }
        let p = xy + dir * t;
        if p.x < 0.0 || p.y < 0.0 || p.x > extent.x || p.y > extent.y {
            return false;
        }
        if sample_bspline(field, p.x, p.y) > ray + 1.0 {
            return true;
        }
        t += step;
    }
}

/// `R` (module docs) at every position.
pub fn relative_illumination(
    field: &HeightField,
    positions: &[DVec2],
    azimuth_deg: f64,
    elevation_deg: f64,
) -> Vec<f32> {
    let sun = sun_direction(azimuth_deg, elevation_deg);
    let top = f64::from(field.min_max().1);
    positions
        .iter()
        .map(|&xy| {
            let direct = hillshade(field, xy, sun);
            if direct <= 0.0 || in_cast_shadow(field, xy, sun, top) {
                0.0
            } else {
                direct as f32
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(slope_x: f32) -> HeightField {
        HeightField::from_fn(32, 32, DVec2::splat(10.0), |c, _| c as f32 * 10.0 * slope_x)
    }

    #[test]
    fn flat_ground_is_one_and_walls_away_from_the_sun_are_dark() {
        let sun = sun_direction(150.0, 30.0);
        assert!((hillshade(&ramp(0.0), DVec2::splat(150.0), sun) - 1.0).abs() < 1e-9);
        // Rising to the east (facing west) at 45°: the sun from the south-east hits it less.
        let west_facing = hillshade(&ramp(1.0), DVec2::splat(150.0), sun);
        let n = glam::DVec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((west_facing - n.dot(sun).max(0.0) / 0.5).abs() < 1e-6);
        // Facing west at 80°: away from a sun in the east.
        assert_eq!(
            hillshade(&ramp(6.0), DVec2::splat(150.0), sun_direction(90.0, 10.0)),
            0.0
        );
    }

    #[test]
    fn a_wall_casts_a_shadow_away_from_the_sun() {
        // A 100 m wall along x = 160 m; the sun low in the east.
        let field = HeightField::from_fn(32, 32, DVec2::splat(10.0), |c, _| if c == 16 { 100.0 } else { 0.0 });
        let sun = sun_direction(90.0, 20.0);
        let light = relative_illumination(
            &field,
            &[DVec2::new(120.0, 150.0), DVec2::new(250.0, 150.0)],
            90.0,
            20.0,
        );
        assert!(in_cast_shadow(&field, DVec2::new(120.0, 150.0), sun, 100.0));
        assert_eq!(light[0], 0.0, "west of the wall");
        assert!(light[1] > 0.9, "east of the wall: {}", light[1]);
    }
}
