//! A CPU replica of `terrain.warp` without procedural detail (dissertation
//! §7.4.2 "Warp and Zoom"): the output grid's vertex positions, for
//! measurements and tests — the projected quad area distribution of
//! warped against uniform meshes (`docs/PERFORMANCE.md`). The GPU pass
//! (`glsl/terrain/warp.comp`) performs the same bilinear interpolation of
//! `Φ` and the same cubic B-spline ([`sample_bspline`]); the depth test in
//! `src/terrain/tests/terrain.rs` checks that they agree.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::surface::bspline::sample_bspline;
use crate::terrain::warp::bilinear;
use crate::view::View;

/// Vertex positions of the `side×side` output grid: `Φ` (the `n×n` warped
/// sketch map, world `(x, y, ·)`) bilinearly interpolated, clamped onto the
/// terrain, heights from the atlas.
pub fn zoom_positions(field: &HeightField, warped: &[DVec3], n: usize, side: usize) -> Result<Vec<DVec3>> {
    if n < 2 || warped.len() != n * n || side < 2 {
        return Err(Error::invalid(
            "warp and zoom",
            format!("{} warped texels for n = {n}, output side {side}", warped.len()),
        ));
    }
    let extent = field.extent();
    let mut out = Vec::with_capacity(side * side);
    for j in 0..side {
        for i in 0..side {
            let xy = zoom_xy(warped, n, side, extent, i, j);
            out.push(DVec3::new(xy.x, xy.y, sample_bspline(field, xy.x, xy.y)));
        }
    }
    Ok(out)
}

/// World xy of output vertex `(i, j)` of the `side×side` grid (`side ≥ 2`):
/// `Φ` (the `n×n` warped sketch map, `warped.len() = n²`, `n ≥ 2`)
/// bilinearly interpolated at `(i, j)·(n−1)/(side−1)`, clamped onto the
/// terrain rectangle `[0, extent]` (`phi` in `glsl/terrain/warp.comp`).
pub fn zoom_xy(warped: &[DVec3], n: usize, side: usize, extent: DVec2, i: usize, j: usize) -> DVec2 {
    let scale = (n - 1) as f64 / (side - 1) as f64;
    let g = DVec2::new(i as f64, j as f64) * scale;
    bilinear(warped, n, g).truncate().clamp(DVec2::ZERO, extent)
}

/// Projected area in pixels of every grid quad of `positions`
/// (`side×side`) that lies wholly in front of the near plane and inside the
/// image of `view` (projected as the GPU does, [`View::view_proj`]).
pub fn projected_quad_areas(positions: &[DVec3], side: usize, view: &View) -> Vec<f64> {
    let (w, h) = (f64::from(view.width), f64::from(view.height));
    let view_proj = view.view_proj().as_dmat4();
    let project = |p: DVec3| -> Option<DVec2> {
        let clip = view_proj * p.extend(1.0);
        if clip.w <= view.camera.near {
            return None;
        }
        let ndc = clip.truncate().truncate() / clip.w;
        let px = DVec2::new((ndc.x * 0.5 + 0.5) * w, (ndc.y * 0.5 + 0.5) * h);
        (px.x >= 0.0 && px.y >= 0.0 && px.x <= w && px.y <= h).then_some(px)
    };
    let screen: Vec<Option<DVec2>> = positions.iter().map(|&p| project(p)).collect();
    let mut areas = Vec::new();
    for j in 0..side.saturating_sub(1) {
        for i in 0..side - 1 {
            let k = j * side + i;
            let (Some(a), Some(b), Some(c), Some(d)) =
                (screen[k], screen[k + 1], screen[k + side + 1], screen[k + side])
            else {
                continue;
            };
            // Shoelace formula over a, b, c, d.
            let twice = (a.perp_dot(b) + b.perp_dot(c) + c.perp_dot(d) + d.perp_dot(a)).abs();
            areas.push(0.5 * twice);
        }
    }
    areas
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::quantile;
    use crate::terrain::procedural::ProceduralTerrain;
    use crate::view::Camera;

    #[test]
    fn identity_warp_reproduces_the_sketch_grid() {
        let field = ProceduralTerrain::default().generate(33, 33, DVec2::splat(10.0));
        let n = 5;
        let warped: Vec<DVec3> = (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * 80.0, (k / n) as f64 * 80.0, 0.0))
            .collect();
        let p = zoom_positions(&field, &warped, n, 9).unwrap();
        assert_eq!(p.len(), 81);
        assert!((p[1].x - 40.0).abs() < 1e-9 && p[9].y == 40.0);
        assert_eq!(p[80].truncate(), DVec2::new(320.0, 320.0));
        assert!(zoom_positions(&field, &warped, 4, 9).is_err());
    }

    #[test]
    fn quad_areas_of_a_square_seen_from_above() {
        let camera = Camera {
            eye: DVec3::new(0.5, 0.5, 10.0),
            target: DVec3::new(0.5, 0.5, 0.0),
            up: DVec3::Y,
            fov_y_deg: 90.0,
            near: 0.1,
            far: 100.0,
        };
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        // 1 m at 10 m with a 90° field of view over 200 px: 10 px per metre.
        let areas = projected_quad_areas(&positions, 2, &View::new(camera, 200, 200));
        assert_eq!(areas.len(), 1);
        assert!((areas[0] - 100.0).abs() < 1e-6, "{}", areas[0]);
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), 2.0);
    }
}
