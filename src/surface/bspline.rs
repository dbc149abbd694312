//! Uniform cubic B-spline sampling of a height field: the "sketch atlas"
//! resampling of geometry image warping (dissertation §7.4;
//! `ALGORITHMS.md` §3 item 5).
//!
//! The warped geometry image looks the terrain up at arbitrary (non-grid)
//! positions. A uniform cubic B-spline through the height samples gives a
//! C² surface, so zooming into the sketch atlas shows no grid-aligned
//! creases. The B-spline *approximates* the samples (it does not pass
//! through them) but reproduces constant and linear height fields exactly.
//!
//! # Convention (shared with the GPU)
//!
//! The GPU shader `glsl/terrain/warp_zoom.comp` uses exactly the same
//! convention, so CPU and GPU surfaces agree to floating-point rounding:
//!
//! 1. World position `(x, y)` in metres becomes the sample coordinate
//!    `g = (x / dx, y / dy)` (sample `(c, r)` lies at `(c·dx, r·dy)`, see
//!    [`crate::io::heightmap`]).
//! 2. `g` is clamped to `[0, columns−1] × [0, rows−1]`: outside the terrain
//!    rectangle the surface continues as the value on its edge.
//! 3. Per axis, `i = floor(g)` and `t = g − i ∈ [0, 1)` (at the upper edge
//!    `g = n−1`, `i = n−1` and `t = 0`).
//! 4. The four taps are the samples `i−1, i, i+1, i+2`, each index clamped
//!    into `[0, n−1]` (clamp-to-edge), weighted by
//!    [`cubic_bspline_weights`]`(t)`.
//! 5. The height is the tensor product `Σ_j wy[j] · Σ_i wx[i] · h(cx[i], ry[j])`
//!    over the 4×4 taps.

use glam::DVec2;

use crate::io::heightmap::HeightField;

/// Uniform cubic B-spline weights of the four taps `i−1, i, i+1, i+2` at
/// fractional position `t ∈ [0, 1)` past sample `i` (§7.4):
///
/// ```text
/// w0 = (1 − t)³ / 6
/// w1 = (3t³ − 6t² + 4) / 6
/// w2 = (−3t³ + 3t² + 3t + 1) / 6
/// w3 = t³ / 6
/// ```
///
/// The weights are non-negative on `[0, 1]` and sum to one.
pub fn cubic_bspline_weights(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

/// Derivatives `dw/dt` of [`cubic_bspline_weights`] (§7.4):
///
/// ```text
/// w0' = −(1 − t)² / 2
/// w1' = (3t² − 4t) / 2
/// w2' = (−3t² + 2t + 1) / 2
/// w3' = t² / 2
/// ```
///
/// They sum to zero.
pub fn cubic_bspline_derivative_weights(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -0.5 * s * s,
        (1.5 * t - 2.0) * t,
        (-1.5 * t + 1.0) * t + 0.5,
        0.5 * t * t,
    ]
}

/// One axis of a B-spline look-up: the clamped tap indices, the fractional
/// position and whether the coordinate lay inside `[0, n−1]` (before the
/// clamp), which decides whether the derivative along this axis is zero.
struct Axis {
    taps: [u32; 4],
    t: f64,
    inside: bool,
}

impl Axis {
    /// `coord` in metres, `spacing` metres per sample, `samples` samples
    /// along the axis. NaN coordinates propagate to a NaN `t`.
    fn new(coord: f64, spacing: f64, samples: u32) -> Self {
        let last = samples.saturating_sub(1);
        let g = coord / spacing;
        let inside = g >= 0.0 && g <= f64::from(last);
        // `f64::clamp` keeps NaN, which then makes `t` NaN (and the result NaN).
        let g = g.clamp(0.0, f64::from(last));
        let i = g.floor();
        let t = g - i;
        // `as` saturates and maps NaN to 0, so this cannot overflow or panic.
        let i = i as i64;
        let clamp = |k: i64| k.clamp(0, i64::from(last)) as u32;
        Self {
            taps: [clamp(i - 1), clamp(i), clamp(i + 1), clamp(i + 2)],
            t,
            inside,
        }
    }
}

/// One axis of [`sample_bspline`]'s look-up for samples held elsewhere
/// (a streamed pyramid level): the four clamped tap indices, the
/// fractional position `t` and whether `coord` lay inside `[0, n−1]`
/// samples (else the derivative along the axis is zero).
pub(crate) fn bspline_axis(coord: f64, spacing: f64, samples: u32) -> ([u32; 4], f64, bool) {
    let a = Axis::new(coord, spacing, samples);
    (a.taps, a.t, a.inside)
}

/// Tensor product `Σ_j wy[j] Σ_i wx[i] h(cx[i], ry[j])`.
fn tensor(field: &HeightField, ax: &Axis, wx: &[f64; 4], ay: &Axis, wy: &[f64; 4]) -> f64 {
    let mut sum = 0.0;
    for (&r, &wr) in ay.taps.iter().zip(wy) {
        let mut row = 0.0;
        for (&c, &wc) in ax.taps.iter().zip(wx) {
            row += wc * f64::from(field.height(c, r));
        }
        sum += wr * row;
    }
    sum
}

/// Height of the uniform cubic B-spline surface of `field` at world
/// position `(x, y)` in metres (§7.4; convention in the module docs,
/// identical to `glsl/terrain/warp_zoom.comp`).
///
/// Positions outside the terrain rectangle `[0, (columns−1)·dx] ×
/// [0, (rows−1)·dy]` are clamped onto it. Never panics: NaN coordinates, a
/// degenerate spacing or a field whose `heights` is too short (see
/// [`HeightField::validate`]) give NaN.
pub fn sample_bspline(field: &HeightField, x: f64, y: f64) -> f64 {
    let ax = Axis::new(x, field.spacing.x, field.columns);
    let ay = Axis::new(y, field.spacing.y, field.rows);
    tensor(
        field,
        &ax,
        &cubic_bspline_weights(ax.t),
        &ay,
        &cubic_bspline_weights(ay.t),
    )
}

/// Gradient `(∂h/∂x, ∂h/∂y)` of [`sample_bspline`] in metres per metre
/// (§7.4): the derivative weights along one axis, divided by that axis's
/// spacing.
///
/// Outside the terrain rectangle the surface is constant along the clamped
/// axis, so that component is zero there; on the edge itself the one-sided
/// derivative from inside is returned.
pub fn sample_bspline_gradient(field: &HeightField, x: f64, y: f64) -> DVec2 {
    let ax = Axis::new(x, field.spacing.x, field.columns);
    let ay = Axis::new(y, field.spacing.y, field.rows);
    let (wx, wy) = (cubic_bspline_weights(ax.t), cubic_bspline_weights(ay.t));
    let dx = if ax.inside {
        let dwx = cubic_bspline_derivative_weights(ax.t);
        tensor(field, &ax, &dwx, &ay, &wy) / field.spacing.x
    } else {
        0.0
    };
    let dy = if ay.inside {
        let dwy = cubic_bspline_derivative_weights(ay.t);
        tensor(field, &ax, &wx, &ay, &dwy) / field.spacing.y
    } else {
        0.0
    };
    DVec2::new(dx, dy)
}

/// The drawn surface at the samples: `field` with each sample replaced by
/// [`sample_bspline`] at its own position, over the same grid (§7.4; at a
/// knot the B-spline is the `[1, 4, 1] / 6` average along each axis,
/// clamp-to-edge). What is traced on the samples' bilinear patches (the
/// sky-light bake and its horizon maps, the Monte Carlo reference, §9.2–9.5)
/// sees, through this field, the surface the renderer draws rather than
/// the raw samples, whose peaks stand higher and valleys lie deeper.
pub fn knot_field(field: &HeightField) -> HeightField {
    let s = field.spacing;
    HeightField::from_fn(field.columns, field.rows, s, |c, r| {
        sample_bspline(field, f64::from(c) * s.x, f64::from(r) * s.y) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ts() -> impl Iterator<Item = f64> {
        (0..1000).map(|k| f64::from(k) / 1000.0)
    }

    #[test]
    fn weights_sum_to_one_and_are_non_negative() {
        for t in ts() {
            let w = cubic_bspline_weights(t);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14, "t = {t}: {w:?}");
            assert!(w.iter().all(|&v| v >= 0.0), "t = {t}: {w:?}");
        }
        // Known values: at t = 0 the taps are (1/6, 4/6, 1/6, 0).
        let w = cubic_bspline_weights(0.0);
        let expected = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0];
        for (a, b) in w.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    #[test]
    fn derivative_weights_sum_to_zero_and_match_finite_differences() {
        for t in ts().filter(|&t| t > 0.001 && t < 0.999) {
            let d = cubic_bspline_derivative_weights(t);
            assert!(d.iter().sum::<f64>().abs() < 1e-14, "t = {t}: {d:?}");
            let h = 1e-6;
            let (p, m) = (cubic_bspline_weights(t + h), cubic_bspline_weights(t - h));
            for k in 0..4 {
                let fd = (p[k] - m[k]) / (2.0 * h);
                assert!((fd - d[k]).abs() < 1e-8, "t = {t}, tap {k}: {fd} vs {}", d[k]);
            }
        }
    }

    #[test]
    fn constant_field_gives_constant() {
        let f = HeightField::from_fn(7, 5, DVec2::new(2.0, 3.0), |_, _| 42.5);
        for k in 0..200 {
            let x = -3.0 + f64::from(k) * 0.097;
            let y = -2.0 + f64::from(k) * 0.083;
            assert!((sample_bspline(&f, x, y) - 42.5).abs() < 1e-12);
            assert!(sample_bspline_gradient(&f, x, y).length() < 1e-12);
        }
    }

    #[test]
    fn plane_is_reproduced_in_the_interior() {
        let (a, b, k) = (2.0, -3.0, 100.0);
        let spacing = DVec2::new(1.5, 0.75);
        let f = HeightField::from_fn(12, 10, spacing, |c, r| (a * f64::from(c) + b * f64::from(r) + k) as f32);
        // Interior: at least one sample from each edge, so no tap is clamped.
        for i in 0..=40 {
            for j in 0..=40 {
                let gx = 1.0 + 9.0 * f64::from(i) / 40.0;
                let gy = 1.0 + 7.0 * f64::from(j) / 40.0;
                let (x, y) = (gx * spacing.x, gy * spacing.y);
                let h = sample_bspline(&f, x, y);
                assert!((h - (a * gx + b * gy + k)).abs() < 1e-10, "({gx}, {gy}): {h}");
                let g = sample_bspline_gradient(&f, x, y);
                assert!((g.x - a / spacing.x).abs() < 1e-10, "({gx}, {gy}): {g}");
                assert!((g.y - b / spacing.y).abs() < 1e-10, "({gx}, {gy}): {g}");
            }
        }
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let spacing = DVec2::new(2.0, 1.25);
        let f = HeightField::from_fn(9, 8, spacing, |c, r| {
            let (c, r) = (f64::from(c), f64::from(r));
            ((c * 0.9).sin() * 5.0 + (r * 1.3).cos() * 3.0 + c * r * 0.1) as f32
        });
        let e = 1e-5;
        for k in 0..100 {
            let x = 0.3 + f64::from(k) * 0.157;
            let y = 0.2 + f64::from(k) * 0.0811;
            let g = sample_bspline_gradient(&f, x, y);
            let fx = (sample_bspline(&f, x + e, y) - sample_bspline(&f, x - e, y)) / (2.0 * e);
            let fy = (sample_bspline(&f, x, y + e) - sample_bspline(&f, x, y - e)) / (2.0 * e);
            assert!(
                (g.x - fx).abs() < 1e-5 && (g.y - fy).abs() < 1e-5,
                "({x}, {y}): {g} vs ({fx}, {fy})"
            );
        }
    }

    #[test]
    fn clamps_outside_the_rectangle_and_matches_the_tap_convention() {
        let spacing = DVec2::new(1.0, 2.0);
        let f = HeightField::from_fn(5, 4, spacing, |c, r| (c * 10 + r * r) as f32);
        let ext = f.extent();
        // Outside: equal to the value on the nearest edge point, zero gradient across.
        assert_eq!(sample_bspline(&f, -5.0, 3.0), sample_bspline(&f, 0.0, 3.0));
        assert_eq!(sample_bspline(&f, ext.x + 9.0, 3.0), sample_bspline(&f, ext.x, 3.0));
        assert_eq!(sample_bspline(&f, 2.0, -1.0), sample_bspline(&f, 2.0, 0.0));
        assert_eq!(sample_bspline(&f, 2.0, ext.y + 1.0), sample_bspline(&f, 2.0, ext.y));
        assert_eq!(sample_bspline_gradient(&f, -5.0, 3.0).x, 0.0);
        assert_eq!(sample_bspline_gradient(&f, 2.0, ext.y + 1.0).y, 0.0);
        // The corner: g = (0, 0), i = 0, t = 0, taps (0, 0, 1, 2) per axis.
        let w = cubic_bspline_weights(0.0);
        let taps = [0u32, 0, 1, 2];
        let mut expected = 0.0;
        for (j, &r) in taps.iter().enumerate() {
            for (i, &c) in taps.iter().enumerate() {
                expected += w[j] * w[i] * f64::from(f.height(c, r));
            }
        }
        assert!((sample_bspline(&f, 0.0, 0.0) - expected).abs() < 1e-12);
        // An interior point by hand: g = (2.25, 1.5).
        let (wx, wy) = (cubic_bspline_weights(0.25), cubic_bspline_weights(0.5));
        let mut expected = 0.0;
        for (j, r) in (0..4u32).enumerate() {
            for (i, c) in (1..5u32).enumerate() {
                expected += wy[j] * wx[i] * f64::from(f.height(c, r));
            }
        }
        assert!((sample_bspline(&f, 2.25, 3.0) - expected).abs() < 1e-12);
    }

    #[test]
    fn bad_input_gives_nan_not_a_panic() {
        let mut f = HeightField::from_fn(4, 4, DVec2::ONE, |_, _| 1.0);
        assert!(sample_bspline(&f, f64::NAN, 1.0).is_nan());
        assert!(sample_bspline(&f, f64::INFINITY, 1.0).is_finite());
        f.heights.truncate(3);
        assert!(sample_bspline(&f, 2.0, 2.0).is_nan());
        let empty = HeightField {
            columns: 0,
            rows: 0,
            spacing: DVec2::ZERO,
            heights: Vec::new(),
        };
        assert!(sample_bspline(&empty, 1.0, 1.0).is_nan());
        let _ = sample_bspline_gradient(&empty, 1.0, 1.0);
    }

    /// At the knots the surface is the [1, 4, 1] / 6 average of the
    /// samples along each axis (clamp-to-edge), a plane stays the plane.
    #[test]
    fn knot_field_is_the_spline_at_the_samples() {
        let f = HeightField::from_fn(7, 5, DVec2::new(2.0, 3.0), |c, r| ((c * 31 + r * 17) % 13) as f32);
        let k = knot_field(&f);
        assert_eq!((k.columns, k.rows, k.spacing), (f.columns, f.rows, f.spacing));
        let h = |c: i64, r: i64| f64::from(f.height(c.clamp(0, 6) as u32, r.clamp(0, 4) as u32));
        let w = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0];
        for r in 0..5i64 {
            for c in 0..7i64 {
                let mut want = 0.0;
                for (j, wy) in w.iter().enumerate() {
                    for (i, wx) in w.iter().enumerate() {
                        want += wx * wy * h(c + i as i64 - 1, r + j as i64 - 1);
                    }
                }
                let got = f64::from(k.height(c as u32, r as u32));
                assert!((got - want).abs() < 1e-4, "({c}, {r}): {got} vs {want}");
            }
        }
        let plane = HeightField::from_fn(6, 6, DVec2::ONE, |c, r| (3 * c + 2 * r) as f32);
        let kp = knot_field(&plane);
        for r in 1..5 {
            for c in 1..5 {
                assert!((kp.height(c, r) - plane.height(c, r)).abs() < 1e-4);
            }
        }
    }
}
