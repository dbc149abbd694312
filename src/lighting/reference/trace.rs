//! Exact ray casting of the height field as bilinear patches (§9.2), the
//! CPU twin of `glsl/include/heightfield_trace.glsl`: a cell-by-cell walk
//! (Amanatides & Woo) with an exact crossing test per cell. The GPU skips
//! empty space with a max-mip pyramid; both find the same first crossing.
//!
//! Along a ray, the bilinear patch `h = a + b·u + c·v + d·u·v` of a cell is
//! a quadratic in `t`, so `f(t) = z(t) − h(t)` splits into at most two
//! monotone pieces per cell (at the vertex of the parabola); a crossing from
//! `f ≥ 0` to `f < 0` is bracketed exactly and refined by bisection and a
//! final secant step.

use glam::{DVec2, DVec3};

use super::validate_field;
use crate::error::Result;
use crate::io::heightmap::HeightField;

/// Bisection steps of a bracketed crossing.
const BISECTIONS: u32 = 10;

/// Heights of a cell's corners: `[h00, h10, h01, h11]`.
pub(crate) type Corners = [f64; 4];

/// The crossing test of one cell for the ray piece `t ∈ [ta, tb]`:
/// `ua, va` the cell-local coordinates and `za` the height of the ray at
/// `ta`, `du, dv, dz` their rates per unit `t`. `above` carries whether the
/// ray was last on or above the surface; returns the `t` of the first
/// crossing from above to below.
#[allow(clippy::too_many_arguments)]
pub(crate) fn cell_crossing(
    h: Corners,
    (ua, va, za): (f64, f64, f64),
    (du, dv, dz): (f64, f64, f64),
    ta: f64,
    tb: f64,
    above: &mut bool,
) -> Option<f64> {
    let [h00, h10, h01, h11] = h;
    let (b, c, d) = (h10 - h00, h01 - h00, h00 - h10 - h01 + h11);
    // f(s) = A s² + B s + C for s = t − ta.
    let qa = -d * du * dv;
    let qb = dz - (b * du + c * dv + d * (ua * dv + va * du));
    let qc = za - (h00 + b * ua + c * va + d * ua * va);
    let f = |s: f64| (qa * s + qb) * s + qc;
    let len = tb - ta;
    let mut prev = 0.0;
    let f0 = f(0.0);
    if *above && f0 < 0.0 {
        return Some(ta);
    }
    *above = f0 >= 0.0;
    let vertex = if qa != 0.0 { -qb / (2.0 * qa) } else { -1.0 };
    let ends = [if vertex > 0.0 && vertex < len { vertex } else { -1.0 }, len];
    for end in ends {
        if end < 0.0 {
            continue;
        }
        let fe = f(end);
        if *above && fe < 0.0 {
            return Some(ta + refine(f, prev, end));
        }
        *above = fe >= 0.0;
        prev = end;
    }
    None
}

/// The crossing of `f` in `[lo, hi]` (`f(lo) ≥ 0 > f(hi)`).
fn refine(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (fl, fh) = (f(lo), f(hi));
    if fl >= 0.0 && fh < 0.0 {
        lo + (hi - lo) * (fl / (fl - fh))
    } else {
        0.5 * (lo + hi)
    }
}

/// A hit of [`HeightFieldTracer::trace`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceHit {
    /// Ray parameter (units of the direction).
    pub t: f64,
    /// World position of the hit.
    pub position: DVec3,
    /// Sample coordinates `(x/dx, y/dy)` of the hit.
    pub grid: DVec2,
}

/// Exact ray casting of a height field's bilinear patches (§9.2).
#[derive(Clone, Debug)]
pub struct HeightFieldTracer<'a> {
    field: &'a HeightField,
    zmin: f64,
    zmax: f64,
}

impl<'a> HeightFieldTracer<'a> {
    /// Errors for a field smaller than 2×2, with the wrong number of heights,
    /// a non-positive spacing or a non-finite height.
    pub fn new(field: &'a HeightField) -> Result<Self> {
        validate_field(field)?;
        let (lo, hi) = field.min_max();
        Ok(HeightFieldTracer {
            field,
            zmin: f64::from(lo),
            zmax: f64::from(hi),
        })
    }

    /// The field this tracer was built for.
    pub fn field(&self) -> &'a HeightField {
        self.field
    }

    /// Height of sample `(c, r)`, clamped into the grid.
    pub fn height(&self, c: i64, r: i64) -> f64 {
        let c = c.clamp(0, i64::from(self.field.columns) - 1) as u32;
        let r = r.clamp(0, i64::from(self.field.rows) - 1) as u32;
        f64::from(self.field.height(c, r))
    }

    /// World position of sample `(c, r)`.
    pub fn sample_position(&self, c: u32, r: u32) -> DVec3 {
        let s = self.field.spacing;
        DVec3::new(f64::from(c) * s.x, f64::from(r) * s.y, self.height(c.into(), r.into()))
    }

    /// Unit normal of sample `(c, r)` from central differences (one-sided
    /// at the border).
    pub fn vertex_normal(&self, c: i64, r: i64) -> DVec3 {
        let (w, h) = (i64::from(self.field.columns), i64::from(self.field.rows));
        let (c0, c1) = ((c - 1).max(0), (c + 1).min(w - 1));
        let (r0, r1) = ((r - 1).max(0), (r + 1).min(h - 1));
        let s = self.field.spacing;
        let gx = (self.height(c1, r) - self.height(c0, r)) / ((c1 - c0) as f64 * s.x);
        let gy = (self.height(c, r1) - self.height(c, r0)) / ((r1 - r0) as f64 * s.y);
        DVec3::new(-gx, -gy, 1.0).normalize()
    }

    /// The shading normal at sample coordinates `g`: the bilinear blend of
    /// the normals of the cell's corners, renormalised.
    pub fn normal_at(&self, g: DVec2) -> DVec3 {
        let max = DVec2::new(f64::from(self.field.columns - 2), f64::from(self.field.rows - 2));
        let cell = g.floor().clamp(DVec2::ZERO, max);
        let (u, v) = ((g.x - cell.x).clamp(0.0, 1.0), (g.y - cell.y).clamp(0.0, 1.0));
        let (c, r) = (cell.x as i64, cell.y as i64);
        let n = self.vertex_normal(c, r) * ((1.0 - u) * (1.0 - v))
            + self.vertex_normal(c + 1, r) * (u * (1.0 - v))
            + self.vertex_normal(c, r + 1) * ((1.0 - u) * v)
            + self.vertex_normal(c + 1, r + 1) * (u * v);
        n.normalize()
    }

    fn corners(&self, c: i64, r: i64) -> Corners {
        [
            self.height(c, r),
            self.height(c + 1, r),
            self.height(c, r + 1),
            self.height(c + 1, r + 1),
        ]
    }

    /// First crossing of the ray `origin + t·dir`, `t ≥ 0`, from on-or-above
    /// to below the surface inside the rectangle; `None` when it escapes
    /// (leaves the rectangle, or rises above the highest sample). A ray
    /// that starts under the surface hits at its start.
    pub fn trace(&self, origin: DVec3, dir: DVec3) -> Option<TraceHit> {
        let s = self.field.spacing;
        let o = DVec3::new(origin.x / s.x, origin.y / s.y, origin.z);
        let d = DVec3::new(dir.x / s.x, dir.y / s.y, dir.z);
        let size = DVec2::new(f64::from(self.field.columns - 1), f64::from(self.field.rows - 1));
        let margin = 1e-6 * (1.0 + self.zmin.abs().max(self.zmax.abs()));
        let lo = DVec3::new(0.0, 0.0, self.zmin - margin);
        let hi = DVec3::new(size.x, size.y, self.zmax + margin);
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] != 0.0 {
                let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            } else if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
        }
        if t0 >= t1 || t0.is_nan() || !t1.is_finite() {
            return None;
        }
        // Amanatides–Woo over the cells from the one at t0.
        let p = o + d * t0;
        let mut cell = [0i64; 2];
        let mut next = [f64::INFINITY; 2];
        let mut delta = [f64::INFINITY; 2];
        let mut step = [0i64; 2];
        for a in 0..2 {
            let k = p[a].floor().clamp(0.0, size[a] - 1.0);
            cell[a] = k as i64;
            if d[a] > 0.0 {
                (step[a], next[a], delta[a]) = (1, (k + 1.0 - o[a]) / d[a], 1.0 / d[a]);
            } else if d[a] < 0.0 {
                (step[a], next[a], delta[a]) = (-1, (k - o[a]) / d[a], -1.0 / d[a]);
            }
        }
        let (mut t, mut above) = (t0, true);
        while t < t1 {
            let te = next[0].min(next[1]).min(t1).max(t);
            let q = o + d * t;
            let local = (q.x - cell[0] as f64, q.y - cell[1] as f64, q.z);
            let corners = self.corners(cell[0], cell[1]);
            if let Some(th) = cell_crossing(corners, local, (d.x, d.y, d.z), t, te, &mut above) {
                let g = DVec2::new(o.x + d.x * th, o.y + d.y * th);
                return Some(TraceHit {
                    t: th,
                    position: origin + dir * th,
                    grid: g,
                });
            }
            let a = if next[0] <= next[1] { 0 } else { 1 };
            cell[a] += step[a];
            next[a] += delta[a];
            t = te;
            if cell[a] < 0 || cell[a] as f64 >= size[a] {
                break;
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(w: u32, h: u32, f: impl Fn(f64, f64) -> f64) -> HeightField {
        HeightField::from_fn(w, h, DVec2::new(2.0, 3.0), |c, r| f(f64::from(c), f64::from(r)) as f32)
    }

    #[test]
    fn tilted_plane_is_hit_exactly() {
        // h = 1.5c + 0.5r + 3, i.e. h(x, y) = 0.75 x + y/6 + 3.
        let f = field(20, 16, |c, r| 1.5 * c + 0.5 * r + 3.0);
        let tracer = HeightFieldTracer::new(&f).unwrap();
        let o = DVec3::new(10.0, 12.0, 60.0);
        let d = DVec3::new(0.3, 0.2, -1.0);
        let exact = (o.z - (0.75 * o.x + o.y / 6.0 + 3.0)) / (0.75 * d.x + d.y / 6.0 - d.z);
        let hit = tracer.trace(o, d).unwrap();
        assert!((hit.t - exact).abs() < 1e-9, "{} {exact}", hit.t);
        // Upwards and away: escapes.
        assert!(tracer.trace(o, DVec3::new(0.1, 0.1, 1.0)).is_none());
    }

    #[test]
    fn bilinear_saddle_is_hit_on_the_surface() {
        let f = field(9, 9, |c, r| {
            ((c - 4.0) * (r - 4.0)).abs().sqrt() * 3.0 + (c * 1.3).sin()
        });
        let tracer = HeightFieldTracer::new(&f).unwrap();
        for k in 0..200 {
            let a = f64::from(k) * 0.37;
            let o = DVec3::new(8.0 + 3.0 * a.cos(), 12.0 + 3.0 * a.sin(), 30.0);
            let d = DVec3::new(a.sin(), (1.7 * a).cos(), -0.4 - 0.1 * f64::from(k % 5));
            let Some(hit) = tracer.trace(o, d) else {
                continue;
            };
            // The hit lies on the bilinear surface.
            let g = hit.grid;
            let (c, r) = (g.x.floor().min(7.0), g.y.floor().min(7.0));
            let (u, v) = (g.x - c, g.y - r);
            let [h00, h10, h01, h11] = tracer.corners(c as i64, r as i64);
            let h = h00 * (1.0 - u) * (1.0 - v) + h10 * u * (1.0 - v) + h01 * (1.0 - u) * v + h11 * u * v;
            assert!((hit.position.z - h).abs() < 1e-6, "ray {k}");
            // No march sample before it is under the surface.
            for i in 1..400 {
                let p = o + d * (hit.t * f64::from(i) / 400.0);
                let (gx, gy) = (p.x / 2.0, p.y / 3.0);
                if (0.0..=8.0).contains(&gx) && (0.0..=8.0).contains(&gy) {
                    let (c, r) = (gx.floor().min(7.0), gy.floor().min(7.0));
                    let (u, v) = (gx - c, gy - r);
                    let [h00, h10, h01, h11] = tracer.corners(c as i64, r as i64);
                    let h = h00 * (1.0 - u) * (1.0 - v) + h10 * u * (1.0 - v) + h01 * (1.0 - u) * v + h11 * u * v;
                    assert!(p.z >= h - 1e-9, "ray {k} under the surface before its hit");
                }
            }
        }
    }

    #[test]
    fn normals_from_central_differences() {
        let f = field(10, 10, |c, _| 2.0 * c);
        let tracer = HeightFieldTracer::new(&f).unwrap();
        // dh/dx = 2 / dx = 1: normal (−1, 0, 1)/√2 everywhere, border too.
        for (c, r) in [(0, 0), (5, 5), (9, 3)] {
            let n = tracer.vertex_normal(c, r);
            assert!((n - DVec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-12);
        }
        let n = tracer.normal_at(DVec2::new(3.3, 7.9));
        assert!((n - DVec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-12);
    }
}
