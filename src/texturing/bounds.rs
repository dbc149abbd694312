//! Per-node height bounds of a height field for the texture quadtree
//! (dissertation §8.2): a min/max pyramid built once, read by
//! [`crate::texturing::quadtree::select_tiles`] to cull nodes and measure
//! their geometric error.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::texturing::quadtree::{NodeBounds, NodeId, MAX_PYRAMID_DEPTH};

/// Per-node height bounds of a height field: a min/max pyramid built once
/// down to `min(max_depth, MAX_PYRAMID_DEPTH)`; deeper nodes are measured
/// from the samples. A node covers the samples whose positions lie in its
/// closed rectangle, widened to the enclosing sample cells (so edge samples
/// count for both neighbours). `geometric_error = (z_max − z_min)/2`: the
/// largest deviation of the node's mid-height plane from its samples. This
/// upper bound is very conservative: on rough terrain with `pixel_error = 1`
/// it refines most visible nodes down to `max_depth`. Callers whose terrain
/// mesh knows its own per-node error should pass that instead, or set the
/// error to 0 to refine by texel density alone.
///
/// A node narrower than a sample cell still covers a whole cell's samples,
/// so its range would not shrink as it splits, and on a field of a few
/// samples every visible node would refine down to `max_depth` (millions of
/// nodes). Within a cell the surface's slope along an axis is at most the
/// cell's range over the cell's size, so such a node's error is the range
/// scaled by its width in cells, `(w_x + w_y)`, where that sum is below 1
/// ([`HeightBounds::bounds`]).
#[derive(Clone, Debug)]
pub struct HeightBounds {
    /// Width of a level-0 node in sample cells: `(columns − 1, rows − 1)`.
    cells: (f64, f64),
    columns: u32,
    rows: u32,
    heights: Vec<f32>,
    /// `pyramid[l][y·2^l + x]` = (z_min, z_max) of node (l, x, y).
    pyramid: Vec<Vec<(f32, f32)>>,
}

impl HeightBounds {
    /// Builds the pyramid; errors on a height field that fails
    /// [`HeightField::validate`] or `max_depth > 15`.
    pub fn new(field: &HeightField, max_depth: u32) -> Result<HeightBounds> {
        field.validate(std::path::Path::new("height field for texture bounds"))?;
        if max_depth > 15 {
            return Err(Error::invalid(
                "texture bounds depth",
                format!("{max_depth} exceeds 15"),
            ));
        }
        let mut bounds = HeightBounds {
            cells: (f64::from(field.columns - 1), f64::from(field.rows - 1)),
            columns: field.columns,
            rows: field.rows,
            heights: field.heights.clone(),
            pyramid: Vec::new(),
        };
        let depth = max_depth.min(MAX_PYRAMID_DEPTH);
        let n = 1u32 << depth;
        let mut level: Vec<(f32, f32)> = Vec::with_capacity((n as usize).pow(2));
        for y in 0..n {
            for x in 0..n {
                level.push(bounds.sample_range(NodeId { level: depth, x, y }));
            }
        }
        let mut levels = vec![level];
        for l in (0..depth).rev() {
            let (fine, n) = (&levels[levels.len() - 1], 1usize << l);
            let mut coarse = Vec::with_capacity(n * n);
            for y in 0..n {
                for x in 0..n {
                    let at = |dx: usize, dy: usize| fine[(2 * y + dy) * 2 * n + 2 * x + dx];
                    let kids = [at(0, 0), at(1, 0), at(0, 1), at(1, 1)];
                    coarse.push(
                        kids.iter()
                            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &(a, b)| {
                                (lo.min(a), hi.max(b))
                            }),
                    );
                }
            }
            levels.push(coarse);
        }
        levels.reverse();
        bounds.pyramid = levels;
        Ok(bounds)
    }

    /// The bounds of `node`; nodes outside the tree are clamped to its edge.
    /// The geometric error is `(z_max − z_min)/2`, times `w_x + w_y` (the
    /// node's width in sample cells along each axis) where that is below 1
    /// (type documentation).
    pub fn bounds(&self, node: NodeId) -> NodeBounds {
        let side = 1u64.checked_shl(node.level).unwrap_or(0);
        let pyramid = self.pyramid.get(node.level as usize);
        let inside = u64::from(node.x) < side && u64::from(node.y) < side;
        let (z_min, z_max) = match pyramid {
            Some(level) if inside => level[(u64::from(node.y) * side + u64::from(node.x)) as usize],
            _ => self.sample_range(node),
        };
        let scale = (-f64::from(node.level)).exp2();
        let width_in_cells = (self.cells.0 + self.cells.1) * scale;
        NodeBounds {
            z_min,
            z_max,
            geometric_error: (z_max - z_min) / 2.0 * width_in_cells.min(1.0) as f32,
        }
    }

    /// (z_min, z_max) over the samples `node` covers.
    fn sample_range(&self, node: NodeId) -> (f32, f32) {
        let (c0, c1) = sample_span(node.x, node.level, self.columns);
        let (r0, r1) = sample_span(node.y, node.level, self.rows);
        let mut range = (f32::INFINITY, f32::NEG_INFINITY);
        for r in r0..=r1 {
            let row = &self.heights[r as usize * self.columns as usize..][..self.columns as usize];
            for &h in &row[c0 as usize..=c1 as usize] {
                range = (range.0.min(h), range.1.max(h));
            }
        }
        range
    }
}

/// First and last sample index (of `samples` ≥ 2) covered by node index `i`
/// at `level`: `floor(i·cells/2^level) ..= ceil((i+1)·cells/2^level)`.
fn sample_span(i: u32, level: u32, samples: u32) -> (u32, u32) {
    let cells = u128::from(samples - 1);
    let shift = level.min(64);
    let last = u128::from(samples - 1);
    let lo = (u128::from(i) * cells) >> shift;
    let hi = ((u128::from(i) + 1) * cells).div_ceil(1u128 << shift);
    (lo.min(last) as u32, hi.min(last) as u32)
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::*;

    #[test]
    fn height_bounds_match_brute_force() {
        let (columns, rows) = (13u32, 9u32);
        let heights: Vec<f32> = (0..columns * rows).map(|i| ((i * 37) % 101) as f32).collect();
        let field = HeightField {
            columns,
            rows,
            spacing: DVec2::new(10.0, 20.0),
            heights,
        };
        let hb = HeightBounds::new(&field, 4).unwrap();
        for level in 0..=5 {
            for y in 0..1 << level {
                for x in 0..1 << level {
                    let node = NodeId { level, x, y };
                    let (lo, hi) = node.rect(field.extent());
                    let mut want = (f32::INFINITY, f32::NEG_INFINITY);
                    for r in 0..rows {
                        for c in 0..columns {
                            let p = DVec2::new(f64::from(c) * 10.0, f64::from(r) * 20.0);
                            // Samples in the rectangle widened to whole cells.
                            let cell = DVec2::new(10.0, 20.0);
                            let (a, b) = ((lo / cell).floor() * cell, (hi / cell).ceil() * cell);
                            if p.cmpge(a).all() && p.cmple(b).all() {
                                let h = field.height(c, r);
                                want = (want.0.min(h), want.1.max(h));
                            }
                        }
                    }
                    let got = hb.bounds(node);
                    assert_eq!((got.z_min, got.z_max), want, "{node:?}");
                    // Nodes narrower than a cell (level 5: 12/32 + 8/32
                    // cells across) scale the error by their width.
                    let width = (12.0 + 8.0) / f64::from(1u32 << level);
                    let error = (want.1 - want.0) / 2.0 * width.min(1.0) as f32;
                    assert_eq!(got.geometric_error, error, "{node:?}");
                }
            }
        }
        let bad = HeightField {
            heights: vec![0.0; 3],
            ..field
        };
        assert!(HeightBounds::new(&bad, 4).is_err());
    }

    /// A field of 2×2 samples: every node covers all four, yet the error
    /// halves with every level below the cell, so a steep little field does
    /// not refine every visible node down to the deepest level.
    #[test]
    fn error_shrinks_below_one_sample_cell() {
        let field = HeightField::from_fn(2, 2, DVec2::splat(100.0), |c, r| (c * 13 + r * 7) as f32);
        let hb = HeightBounds::new(&field, 12).unwrap();
        let mut previous = f32::INFINITY;
        for level in 0..=12 {
            let b = hb.bounds(NodeId { level, x: 0, y: 0 });
            assert_eq!((b.z_min, b.z_max), (0.0, 20.0), "level {level}");
            let want = 10.0 * (2.0 / f64::from(1u32 << level)).min(1.0) as f32;
            assert_eq!(b.geometric_error, want, "level {level}");
            assert!(b.geometric_error <= previous);
            previous = b.geometric_error;
        }
        assert!(previous < 0.01, "{previous} m at level 12");
    }
}
