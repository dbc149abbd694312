//! Importance-driven geometry image warping on the CPU (dissertation §7.4.2,
//! "Mapping Function" and "Warping", Fig. 7.10–7.12; `ALGORITHMS.md` §3
//! item 4).
//!
//! A sketch map is an `n×n` geometry image: each texel holds a world point
//! `(x, y, h)`. Warping moves the samples along the surface so that the mesh
//! gets dense where the importance map ([`crate::terrain::importance`]) is
//! high; it changes resolution, not shape. Two separable passes: the first
//! warps every line (row) by its own importance and carries the importance
//! along as a fourth channel (the text: "the importance map is resampled in
//! the same way"); the second pass warps the other direction using that
//! resampled importance ([`ColumnImportance`]).
//!
//! # One line (the corrected Fig. 7.11)
//!
//! A line `p[0..n]` with importance `I[0..n]` is a piecewise-linear function
//! of the whole `(x, y, h)` triple. Decisions the text leaves open:
//!
//! * **Segment lengths.** Segment `j` (from `p[j−1]` to `p[j]`, `j = 1..n`)
//!   gets the warped length `w_j = ½(I[j−1] + I[j]) · |xy_j − xy_{j−1}|`,
//!   the trapezoid-rule integral of the importance along the segment, i.e.
//!   the number of samples it demands. On a uniform sketch map the planar
//!   length is the same for every segment and this is the text's "segment
//!   gets length I" (with the n values averaged onto the n − 1 segments);
//!   the length factor keeps the warp correct on non-uniform input (e.g. a
//!   warped image warped again, which the text suggests for refinement).
//! * **Floor.** Non-finite or negative importance counts as 0; every `w_j`
//!   is then lifted to at least [`MIN_SEGMENT_FRACTION`] of the mean
//!   segment length, so zero-importance runs (and repeated points) shrink to
//!   almost nothing instead of dividing by zero. A line without any positive
//!   length is warped uniformly (identity on a regular grid).
//! * **Output positions and border.** The `n` outputs sit at
//!   `u_i = i·Δ`, `Δ = Σw / (n − 1)`, so the first and last sample stay
//!   exactly at `p[0]` and `p[n−1]`: the border stays the border. With
//!   [`WarpFilter::Box`] (the text's resampling) an inner output is the
//!   mean of the function over its cell `[u_i − Δ/2, u_i + Δ/2]`
//!   (trapezoid rule, the loop of Fig. 7.11 consuming `Δ` per output; the
//!   first half cell is skipped); the border samples are point samples,
//!   which equals the box mean of the function continued by point
//!   reflection about the end point. [`WarpFilter::Point`] samples the
//!   function at `u_i` instead.
//! * **End of line.** Rounding can leave the consumed length a few ulps
//!   short of or beyond `Σw`; the walk never steps past the last segment
//!   and clamps its interpolation parameter to 1.
//!
//! Every inner box output is a convex combination of the input points of
//! the segments its cell touches, so its height lies between theirs. The
//! box filter smooths: even a uniform importance map maps an inner sample to
//! `(p[i−1] + 6 p[i] + p[i+1]) / 8` (exact for x and y of a regular grid,
//! and for linear heights), as the text notes for Fig. 7.10 (bottom left).
//! That is why the GPU stage re-samples heights from the atlas at the warped
//! `(x, y)` (`ALGORITHMS.md` §3 item 5).
//!
//! # The second pass
//!
//! Taken literally (every column follows its own resampled importance,
//! [`ColumnImportance::PerColumn`]) the second pass folds the mesh over:
//! neighbouring columns then pick their samples from different rows, and
//! after the first pass the columns are strongly bent (rows behind the eye
//! stay uniform, rows in the frustum crowd into it), so `x` stops increasing
//! along rows — 1600–3200 of the 16 129 quads of a 128² map fold over in
//! our tests (`src/terrain/tests/warp.rs`), and the density also comes out worse. The
//! default, [`ColumnImportance::RowDemand`], warps all columns alike by the
//! demand of each row, `J = ∫ I² ds` along the row: an isotropic density
//! `k·I` needs `k²∫I² ds` samples per unit width of the strip a row stands
//! for, and each row carries `n` of them. `J` is computed from the
//! resampled importance, `J = (Σ w) · mean_c Ĩ`, which equals `∫ I² ds` for
//! the box filter (the mean of `Ĩ` over a cell is `∫ I² ds / Δ`). With
//! equal column weights every output is the same convex combination of
//! first-pass rows in every column, so the first pass's order (x increasing
//! along every row of an axis-aligned map) carries over to the output and
//! no quad can fold over; output rows stay straight. The price is
//! that the second direction's density varies per row only; measured
//! obtained/demanded densities are in the tests (`src/terrain/tests/warp.rs`).
//!
//! Which direction goes first matters: the first pass adapts per line, so it
//! should run across the view (lateral), the shared pass along it
//! ([`PassOrder::for_view`]).

use std::ops::{Add, Mul, Sub};

use glam::{DVec2, DVec3, DVec4};

#[cfg(test)]
use crate::error::Error;
use crate::error::Result;
use crate::terrain::importance::check_grid;

mod density;

pub use density::density_ratio;
#[cfg(test)]
pub use density::{fraction_within, histogram};

/// Smallest warped segment length as a fraction of the mean segment length.
pub const MIN_SEGMENT_FRACTION: f64 = 1e-6;

/// How the warped piecewise-linear function is resampled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WarpFilter {
    /// Mean over the output cell (the text's resampling; smooths heights).
    #[default]
    Box,
    /// Value at the output position: exactly on the input polyline.
    Point,
}

/// Which importance the second (column) pass follows; see the module
/// documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColumnImportance {
    /// All columns warped alike by each row's demand `∫ I² ds` (from the
    /// resampled importance): never folds over.
    #[default]
    RowDemand,
    /// Each column follows its own resampled importance (the text taken
    /// literally): can follow importance that varies across columns, but
    /// folds the mesh over where neighbouring columns differ (for
    /// comparison; not recommended).
    PerColumn,
}

/// Which direction the first pass runs along.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PassOrder {
    /// Rows (along `x` of an axis-aligned sketch map), then columns.
    #[default]
    RowsFirst,
    /// Columns, then rows (same as transposing the image, warping rows
    /// first and transposing back).
    ColumnsFirst,
}

impl PassOrder {
    /// For an axis-aligned sketch map (rows along x, columns along y) and a
    /// camera looking along `forward`: the first pass should run across the
    /// view, so rows first when the view is closer to the y axis.
    pub fn for_view(forward: DVec3) -> PassOrder {
        if forward.y.abs() >= forward.x.abs() {
            PassOrder::RowsFirst
        } else {
            PassOrder::ColumnsFirst
        }
    }
}

/// Options of [`warp_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WarpOptions {
    /// Resampling filter of both passes.
    pub filter: WarpFilter,
    /// Importance of the second pass.
    pub columns: ColumnImportance,
    /// Pass order.
    pub order: PassOrder,
}

/// The result of [`warp`]: `n×n` row-major images.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WarpResult {
    /// Warped `(x, y, h)` after both passes: the warping function `Φ(s, t)`
    /// in x and y, and box-filtered heights.
    pub positions: Vec<DVec3>,
    /// The importance map resampled by the first pass (the row pass, or the
    /// column pass with [`PassOrder::ColumnsFirst`]): what the second pass
    /// used.
    pub importance_after_first_pass: Vec<f64>,
    /// Positions after the first pass only.
    pub positions_after_first_pass: Vec<DVec3>,
}

/// What a line sample can be: `(x, y, h)` or `(x, y, h, I)`.
pub(crate) trait Sample: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self> {}
impl<T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f64, Output = T>> Sample for T {}

/// Bilinear interpolation of an `n×n` row-major grid (`n ≥ 2`) at grid
/// coordinate `g` (column, row), clamped to the grid.
pub(crate) fn bilinear<T: Sample>(values: &[T], n: usize, g: DVec2) -> T {
    let g = g.clamp(DVec2::ZERO, DVec2::splat((n - 1) as f64));
    let (c0, r0) = ((g.x.floor() as usize).min(n - 2), (g.y.floor() as usize).min(n - 2));
    let (fx, fy) = (g.x - c0 as f64, g.y - r0 as f64);
    let at = |r: usize, c: usize| values[r * n + c];
    let top = at(r0, c0) + (at(r0, c0 + 1) - at(r0, c0)) * fx;
    let bottom = at(r0 + 1, c0) + (at(r0 + 1, c0 + 1) - at(r0 + 1, c0)) * fx;
    top + (bottom - top) * fy
}

/// Non-finite or non-positive importance counts as 0.
pub(crate) fn clean(i: f64) -> f64 {
    if i.is_finite() && i > 0.0 {
        i
    } else {
        0.0
    }
}

/// Warped segment lengths of a line of `(x, y, h, I)` samples (see the
/// module documentation): `w[j − 1]` for segment `j`.
fn segment_lengths(line: &[DVec4], w: &mut [f64]) {
    let mut total = 0.0;
    for (wj, pair) in w.iter_mut().zip(line.windows(2)) {
        let (a, b) = (pair[0], pair[1]);
        let len = DVec2::new(b.x - a.x, b.y - a.y).length();
        let v = 0.5 * (clean(a.w) + clean(b.w)) * len;
        *wj = if v.is_finite() { v } else { 0.0 };
        total += *wj;
    }
    if !(total.is_finite() && total > 0.0) {
        w.fill(1.0);
        return;
    }
    let floor = MIN_SEGMENT_FRACTION * total / w.len() as f64;
    for wj in w.iter_mut() {
        *wj = wj.max(floor);
    }
}

/// The row warp of Fig. 7.11 (corrected, see the module documentation) on
/// one line `p` with `w.len() == p.len() − 1 ≥ 1` positive segment lengths.
fn warp_line<T: Sample>(p: &[T], w: &[f64], out: &mut [T], filter: WarpFilter) {
    let n = p.len();
    let step = w.iter().sum::<f64>() / (n - 1) as f64;
    out[0] = p[0];
    out[n - 1] = p[n - 1];
    let mut walk = Walk {
        p,
        w,
        j: 0,
        rem: w[0],
        prev: p[0],
    };
    match filter {
        WarpFilter::Box => {
            walk.consume::<false>(0.5 * step);
            for o in &mut out[1..n - 1] {
                *o = walk.consume::<true>(step) * (1.0 / step);
            }
        }
        WarpFilter::Point => {
            for o in &mut out[1..n - 1] {
                walk.consume::<false>(step);
                *o = walk.prev;
            }
        }
    }
}

/// The state of the loop of Fig. 7.11: inside segment `j` (from `p[j]` to
/// `p[j + 1]`), `rem` of its warped length left, function value `prev`.
struct Walk<'a, T> {
    p: &'a [T],
    w: &'a [f64],
    j: usize,
    rem: f64,
    prev: T,
}

impl<T: Sample> Walk<'_, T> {
    /// Consumes warped length `len`; returns the integral over it (trapezoid
    /// rule, exact for the piecewise-linear function) if `INTEGRATE`, else
    /// zero. Never steps past the last segment (end-of-line guard).
    #[inline(always)]
    fn consume<const INTEGRATE: bool>(&mut self, mut len: f64) -> T {
        let last = self.w.len() - 1;
        let mut acc = self.prev * 0.0;
        while self.rem < len && self.j < last {
            if INTEGRATE {
                acc = acc + (self.prev + self.p[self.j + 1]) * (0.5 * self.rem);
            }
            len -= self.rem;
            self.j += 1;
            self.prev = self.p[self.j];
            self.rem = self.w[self.j];
        }
        let t = if self.rem > len { len / self.rem } else { 1.0 };
        let clip = self.prev + (self.p[self.j + 1] - self.prev) * t;
        if INTEGRATE {
            acc = acc + (self.prev + clip) * (0.5 * len);
        }
        self.rem = (self.rem - len).max(0.0);
        self.prev = clip;
        acc
    }
}

/// Index of element `k` of line `l` in an `n×n` image: `(n, l, k) → index`.
type LineIndex = fn(usize, usize, usize) -> usize;

#[cfg(test)]
fn check_line(what: &str, p: usize, importance: usize, out: usize) -> Result<()> {
    if p < 2 || importance != p || out != p {
        return Err(Error::invalid(
            what,
            format!("{p} points, {importance} importance values, {out} outputs (need equal lengths ≥ 2)"),
        ));
    }
    Ok(())
}

/// Warps one row (or column) `p` with per-sample `importance` into `out`
/// with the box filter (the text's Fig. 7.11, corrected; see the module
/// documentation). Errors unless all three have the same length ≥ 2.
#[cfg(test)]
pub fn warp_row(p: &[DVec3], importance: &[f64], out: &mut [DVec3]) -> Result<()> {
    warp_row_with(p, importance, out, WarpFilter::Box)
}

/// [`warp_row`] with a choice of resampling filter.
#[cfg(test)]
pub fn warp_row_with(p: &[DVec3], importance: &[f64], out: &mut [DVec3], filter: WarpFilter) -> Result<()> {
    check_line("warp line", p.len(), importance.len(), out.len())?;
    let line: Vec<DVec4> = p.iter().zip(importance).map(|(q, &i)| q.extend(i)).collect();
    let mut w = vec![0.0; p.len() - 1];
    segment_lengths(&line, &mut w);
    warp_line(p, &w, out, filter);
    Ok(())
}

/// Warps an `n×n` geometry image (row-major `(x, y, h)` texels) by the
/// importance map (n·n values, row-major) with the default
/// [`WarpOptions`]: box filter, rows then columns, shared column warp
/// (§7.4.2; `ALGORITHMS.md` §3 item 4). Errors on wrong sizes; never
/// panics. The corners stay put; border rows and columns move only along
/// the border.
pub fn warp(grid: &[DVec3], importance: &[f64], n: usize) -> Result<WarpResult> {
    warp_with(grid, importance, n, WarpOptions::default())
}

/// [`warp`] with explicit options.
pub fn warp_with(grid: &[DVec3], importance: &[f64], n: usize, options: WarpOptions) -> Result<WarpResult> {
    let mut result = WarpResult {
        positions: Vec::new(),
        importance_after_first_pass: Vec::new(),
        positions_after_first_pass: Vec::new(),
    };
    warp_into(grid, importance, n, options, &mut result)?;
    Ok(result)
}

/// [`warp_with`] into the buffers of an earlier result (resized as
/// needed): no large allocation per frame once the buffers have grown,
/// which matters at this size (fresh ~1 MB buffers cost page faults
/// comparable to the warp itself).
pub fn warp_into(
    grid: &[DVec3],
    importance: &[f64],
    n: usize,
    options: WarpOptions,
    result: &mut WarpResult,
) -> Result<()> {
    check_grid("geometry image", grid.len(), n)?;
    check_grid("importance map", importance.len(), n)?;
    // Index of element `k` of line `l` in the first and the second pass.
    let (first, second): (LineIndex, LineIndex) = match options.order {
        PassOrder::RowsFirst => (|n, l, k| l * n + k, |n, l, k| k * n + l),
        PassOrder::ColumnsFirst => (|n, l, k| k * n + l, |n, l, k| l * n + k),
    };
    let filter = options.filter;
    let WarpResult {
        positions,
        importance_after_first_pass: mid_importance,
        positions_after_first_pass: mid_positions,
    } = result;
    for v in [&mut *positions, &mut *mid_positions] {
        v.clear();
        v.resize(n * n, DVec3::ZERO);
    }
    mid_importance.clear();
    mid_importance.resize(n * n, 0.0);
    let mut line = vec![DVec4::ZERO; n];
    let mut out = vec![DVec4::ZERO; n];
    let mut w = vec![0.0; n - 1];
    let mut demand = Vec::with_capacity(n);
    for l in 0..n {
        for (k, v) in line.iter_mut().enumerate() {
            let i = first(n, l, k);
            *v = grid[i].extend(importance[i]);
        }
        segment_lengths(&line, &mut w);
        warp_line(&line, &w, &mut out, filter);
        for (k, v) in out.iter().enumerate() {
            let i = first(n, l, k);
            mid_positions[i] = v.truncate();
            mid_importance[i] = v.w;
        }
        // The line's demand J = (Σw)·mean(Ĩ) = ∫I² ds (module documentation).
        let mean = out.iter().map(|v| clean(v.w)).sum::<f64>() / n as f64;
        demand.push(w.iter().sum::<f64>() * mean);
    }
    let shared = options.columns == ColumnImportance::RowDemand;
    if shared {
        // One set of segment lengths for all second-pass lines: the
        // first-pass lines' demand over the distances between their first
        // samples (a pinned border: the sketch map's own line spacing).
        for (l, v) in line.iter_mut().enumerate() {
            *v = grid[first(n, l, 0)].extend(demand[l]);
        }
        segment_lengths(&line, &mut w);
    }
    for l in 0..n {
        for (k, v) in line.iter_mut().enumerate() {
            let i = second(n, l, k);
            *v = mid_positions[i].extend(mid_importance[i]);
        }
        if !shared {
            segment_lengths(&line, &mut w);
        }
        warp_line(&line, &w, &mut out, filter);
        for (k, v) in out.iter().enumerate() {
            positions[second(n, l, k)] = v.truncate();
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(n: usize) -> Vec<DVec3> {
        (0..n).map(|i| DVec3::new(i as f64, 0.0, (i * i) as f64)).collect()
    }

    #[test]
    fn uniform_importance_keeps_x_and_box_filters_h() {
        let p = row(6);
        let mut out = vec![DVec3::ZERO; 6];
        warp_row(&p, &[2.0; 6], &mut out).unwrap();
        for i in 0..6 {
            assert!((out[i].x - p[i].x).abs() < 1e-12);
        }
        assert_eq!((out[0], out[5]), (p[0], p[5]));
        for i in 1..5 {
            let filtered = (p[i - 1].z + 6.0 * p[i].z + p[i + 1].z) / 8.0;
            assert!((out[i].z - filtered).abs() < 1e-12, "{i}: {} vs {filtered}", out[i].z);
        }
        warp_row_with(&p, &[2.0; 6], &mut out, WarpFilter::Point).unwrap();
        for i in 0..6 {
            assert!((out[i] - p[i]).length() < 1e-12);
        }
    }

    #[test]
    fn samples_move_to_high_importance() {
        let p = row(11);
        let mut imp = [1.0; 11];
        imp[8] = 20.0;
        let mut out = vec![DVec3::ZERO; 11];
        warp_row(&p, &imp, &mut out).unwrap();
        let near = out.iter().filter(|q| (q.x - 8.0).abs() <= 1.0).count();
        assert!(near >= 5, "{out:?}");
        assert!(out.windows(2).all(|w| w[1].x > w[0].x));
        assert_eq!((out[0], out[10]), (p[0], p[10]));
    }

    #[test]
    fn zero_nan_runs_and_two_points() {
        let p = row(8);
        let imp = [1.0, 0.0, 0.0, f64::NAN, -3.0, 0.0, 1.0, 1.0];
        let mut out = vec![DVec3::ZERO; 8];
        warp_row(&p, &imp, &mut out).unwrap();
        assert!(out.iter().all(|q| q.is_finite()));
        assert!(out.windows(2).all(|w| w[1].x > w[0].x), "{out:?}");
        warp_row(&p, &[0.0; 8], &mut out).unwrap();
        assert!((out[3].x - 3.0).abs() < 1e-12, "all-zero importance: uniform");
        let mut two = [DVec3::ZERO; 2];
        warp_row(&p[..2], &[1.0, 5.0], &mut two).unwrap();
        assert_eq!(two, [p[0], p[1]]);
    }

    #[test]
    fn bad_sizes_are_errors() {
        let p = row(4);
        let mut out = vec![DVec3::ZERO; 4];
        assert!(warp_row(&p, &[1.0; 3], &mut out).is_err());
        assert!(warp_row(&p[..1], &[1.0], &mut out[..1]).is_err());
        assert!(warp(&p, &[1.0; 4], 3).is_err());
        assert!(warp(&p, &[1.0; 3], 2).is_err());
        assert!(density_ratio(&p, &p, &[0.0; 4], 2).is_err());
    }

    fn grid(n: usize) -> Vec<DVec3> {
        (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * 3.0, (k / n) as f64 * 2.0, ((k * 7919) % 13) as f64))
            .collect()
    }

    /// Deterministic rough importance in [0.001, 1): a harsh test map.
    fn rough(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n * n)
            .map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64).powi(3).max(0.001)
            })
            .collect()
    }

    fn folds(p: &[DVec3], n: usize) -> usize {
        (0..n)
            .flat_map(|r| (1..n).map(move |c| (r, c)))
            .filter(|&(r, c)| p[r * n + c].x <= p[r * n + c - 1].x || p[c * n + r].y <= p[(c - 1) * n + r].y)
            .count()
    }

    #[test]
    fn shared_column_warp_never_folds() {
        let n = 24;
        let g = grid(n);
        for seed in 0..20 {
            let imp = rough(n, seed);
            for order in [PassOrder::RowsFirst, PassOrder::ColumnsFirst] {
                let o = WarpOptions {
                    order,
                    ..Default::default()
                };
                let w = warp_with(&g, &imp, n, o).unwrap();
                assert_eq!(folds(&w.positions, n), 0, "seed {seed}, {order:?}");
                // The shared pass keeps its lines straight: one y per output
                // row (rows first) or one x per output column.
                for r in 0..n {
                    let at = |k: usize| match order {
                        PassOrder::RowsFirst => w.positions[r * n + k].y,
                        PassOrder::ColumnsFirst => w.positions[k * n + r].x,
                    };
                    assert!((0..n).all(|k| (at(k) - at(0)).abs() < 1e-9), "seed {seed}, {order:?}");
                }
            }
            let literal = WarpOptions {
                columns: ColumnImportance::PerColumn,
                ..Default::default()
            };
            let w = warp_with(&g, &imp, n, literal).unwrap();
            assert_eq!(w.positions[n * n - 1], g[n * n - 1]);
        }
    }

    #[test]
    fn columns_first_is_the_transposed_warp() {
        let n = 10;
        let g = grid(n);
        let imp = rough(n, 3);
        let columns_first = WarpOptions {
            order: PassOrder::ColumnsFirst,
            ..Default::default()
        };
        let a = warp_with(&g, &imp, n, columns_first).unwrap();
        let transpose = |v: &[DVec3]| (0..n * n).map(|k| v[(k % n) * n + k / n]).collect::<Vec<_>>();
        let imp_t: Vec<f64> = (0..n * n).map(|k| imp[(k % n) * n + k / n]).collect();
        let b = warp(&transpose(&g), &imp_t, n).unwrap();
        assert_eq!(a.positions, transpose(&b.positions));
        let mut again = b.clone();
        warp_into(&g, &imp, n, columns_first, &mut again).unwrap();
        assert_eq!(again, a, "warp_into reuses buffers with the same result");
        assert_eq!(PassOrder::for_view(DVec3::new(0.2, -1.0, -0.3)), PassOrder::RowsFirst);
        assert_eq!(PassOrder::for_view(DVec3::new(-2.0, 1.0, 0.0)), PassOrder::ColumnsFirst);
    }
}
