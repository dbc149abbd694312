//! Which texture tiles the view needs this frame (dissertation §8.2): a
//! quadtree over the height field's rectangle, refined towards the eye.
//!
//! # Nodes
//!
//! The terrain covers the world rectangle `[0, extent.x] × [0, extent.y]`
//! (x east, y north, z up). Node `(level l, x, y)` covers
//! `[x·extent.x/2^l, (x+1)·extent.x/2^l] × [y·extent.y/2^l, (y+1)·extent.y/2^l]`,
//! so nodes are rectangles when the extent is not square. Every selected node
//! gets one texture tile of a power-of-two size `size` that includes a border
//! of `border` texels on each side, shared with the neighbours; the inner
//! `size − 2·border` texels cover the node's rectangle exactly.
//!
//! # Selection rules ([`select_tiles`])
//!
//! Starting at the root, each node is
//!
//! 1. **culled** when its box (rectangle × `[z_min, z_max]` from
//!    [`NodeBounds`]) lies entirely on the outer side of one frustum plane;
//! 2. measured: `distance` is the Euclidean distance from the eye to the
//!    box (0 inside it), clamped to at least [`MIN_DISTANCE`]; the node
//!    needs `needed = max(width, height) / (pixel_footprint · distance)`
//!    texels across, and its geometric error projects to
//!    `geometric_error / (pixel_footprint · distance)` pixels;
//! 3. **split** into its four children while `level < max_depth` and
//!    `needed + 2·border > aim_texels` (the aim is the tile size, border
//!    included) or the projected error exceeds `pixel_error`;
//! 4. otherwise a **leaf** with size
//!    `clamp(next_pow2(ceil(needed) + 2·border), min_tile, upper)`, where
//!    `upper = max_tile` at `max_depth` and
//!    `min(next_pow2(aim_texels), max_tile)` above it.
//!
//! The leaves partition the visible part of the rectangle exactly (no
//! overlaps, no gaps except culled nodes) and are returned coarse to fine,
//! then nearest first, then by node id, so the order is deterministic.
//! Several views of one frame select together
//! ([`select_tiles_for_views`]): one partition of everything any of them
//! sees, each node as fine as the view that needs it finest.
//!
//! [`HeightBounds`] supplies the bounds from a height field: a min/max
//! pyramid built once, with `geometric_error = (z_max − z_min)/2`.

use glam::{DVec2, DVec3, DVec4};

use crate::error::{Error, Result};
pub use crate::texturing::bounds::HeightBounds;
use crate::view::Footprint;

/// Smallest eye-to-node distance in metres, so nodes around the eye need a
/// finite number of texels.
pub const MIN_DISTANCE: f64 = 1e-3;

/// Deepest level of the [`HeightBounds`] pyramid; deeper nodes are measured
/// from the samples directly (at most `4^10` ≈ 1 M nodes, about 11 MB).
pub const MAX_PYRAMID_DEPTH: u32 = 10;

/// How finely the quadtree refines and how large its tiles are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadtreeSettings {
    /// Split a node while its tile (border included) would need more
    /// texels across than this.
    pub aim_texels: u32,
    /// Smallest tile size in texels, border included (power of two).
    pub min_tile: u32,
    /// Largest tile size in texels, border included (power of two); only
    /// nodes at `max_depth` reach it.
    pub max_tile: u32,
    /// Texels of shared border on each side of a tile.
    pub border: u32,
    /// Deepest quadtree level (at most 15).
    pub max_depth: u32,
    /// Also split while a node's geometric error projects to more pixels
    /// than this.
    pub pixel_error: f32,
}

impl Default for QuadtreeSettings {
    fn default() -> Self {
        QuadtreeSettings {
            aim_texels: 128,
            min_tile: 16,
            max_tile: 512,
            border: 4,
            max_depth: 10,
            pixel_error: 1.0,
        }
    }
}

impl QuadtreeSettings {
    /// Checks: tile sizes are powers of two with `min_tile ≤ max_tile`,
    /// `2·border < min_tile`, `max_depth ≤ 15`, `aim_texels ≥ min_tile`
    /// and a finite positive `pixel_error`.
    pub fn validate(&self) -> Result<()> {
        let (min, max, border2) = (self.min_tile, self.max_tile, 2 * u64::from(self.border));
        let why = if !min.is_power_of_two() || !max.is_power_of_two() {
            format!("tile sizes {min} and {max} must be powers of two")
        } else if min > max {
            format!("min_tile {min} exceeds max_tile {max}")
        } else if border2 >= u64::from(min) {
            format!("2·border {border2} leaves no inner texels in min_tile {min}")
        } else if self.max_depth > 15 {
            format!("max_depth {} exceeds 15", self.max_depth)
        } else if self.aim_texels < min {
            format!("aim_texels {} is below min_tile {min}", self.aim_texels)
        } else if !(self.pixel_error.is_finite() && self.pixel_error > 0.0) {
            format!("pixel_error {} must be finite and positive", self.pixel_error)
        } else {
            return Ok(());
        };
        Err(Error::invalid("texture quadtree settings", why))
    }

    /// The largest tile a node above `max_depth` can get.
    fn upper_tile(&self) -> u32 {
        self.aim_texels.next_power_of_two().min(self.max_tile)
    }
}

/// A quadtree node: `level` 0 is the whole rectangle, level `l` has
/// `2^l × 2^l` nodes indexed by `x` (east) and `y` (north). Meaningful for
/// levels below 32 (the quadtree never exceeds 15); arithmetic saturates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId {
    /// Depth in the tree, 0 at the root.
    pub level: u32,
    /// Column among the `2^level` nodes of the level.
    pub x: u32,
    /// Row among the `2^level` nodes of the level.
    pub y: u32,
}

impl NodeId {
    /// The node covering the whole rectangle.
    pub const ROOT: NodeId = NodeId { level: 0, x: 0, y: 0 };

    /// The node one level up, `None` for the root.
    pub fn parent(&self) -> Option<NodeId> {
        let level = self.level.checked_sub(1)?;
        Some(NodeId {
            level,
            x: self.x / 2,
            y: self.y / 2,
        })
    }

    /// The four children: south-west, south-east, north-west, north-east.
    pub fn children(&self) -> [NodeId; 4] {
        let level = self.level.saturating_add(1);
        let (x, y) = (self.x.saturating_mul(2), self.y.saturating_mul(2));
        let (x1, y1) = (x.saturating_add(1), y.saturating_add(1));
        [(x, y), (x1, y), (x, y1), (x1, y1)].map(|(x, y)| NodeId { level, x, y })
    }

    /// The node's world rectangle `(min, max)` within `[0, extent]`.
    pub fn rect(&self, extent: DVec2) -> (DVec2, DVec2) {
        let size = extent * (-f64::from(self.level)).exp2();
        let min = DVec2::new(f64::from(self.x), f64::from(self.y)) * size;
        (min, min + size)
    }

    /// Whether `other` is this node or one of its descendants.
    pub fn contains(&self, other: &NodeId) -> bool {
        let Some(down) = other.level.checked_sub(self.level) else {
            return false;
        };
        let up = |v: u32| v.checked_shr(down).unwrap_or(0);
        up(other.x) == self.x && up(other.y) == self.y
    }
}

/// A selected leaf: the node, its tile size and its distance to the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeededTile {
    /// The node to texture.
    pub node: NodeId,
    /// Tile size in texels, border included (power of two).
    pub size: u32,
    /// Distance from the eye to the node's box in metres (≥ [`MIN_DISTANCE`]).
    pub distance: f64,
}

/// Height range and error of one node's terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeBounds {
    /// Lowest height over the node in metres.
    pub z_min: f32,
    /// Highest height over the node in metres.
    pub z_max: f32,
    /// How far the node's coarse surface may be from the true one, metres (≥ 0).
    pub geometric_error: f32,
}

/// The leaves the view needs, by the rules in the module documentation:
/// [`select_tiles_for_views`] of one view.
#[cfg(test)]
pub fn select_tiles(
    extent: DVec2,
    view: &Footprint,
    settings: &QuadtreeSettings,
    bounds: &dyn Fn(NodeId) -> NodeBounds,
) -> Result<Vec<NeededTile>> {
    select_tiles_for_views(extent, std::slice::from_ref(view), settings, bounds)
}

/// Checks a view: finite eye, finite positive footprint, finite planes.
fn check_view(view: &Footprint) -> Result<()> {
    let footprint = view.pixel_footprint;
    let why = if !(view.eye.is_finite() && footprint.is_finite() && footprint > 0.0) {
        format!(
            "eye {} and pixel footprint {footprint} must be finite (footprint > 0)",
            view.eye
        )
    } else if view.frustum.is_some_and(|planes| planes.iter().any(|p| !p.is_finite())) {
        "frustum planes must be finite".to_string()
    } else {
        return Ok(());
    };
    Err(Error::invalid("texture view", why))
}

/// How one view measures a node it sees: distance to its box, texels it
/// needs across, its geometric error in pixels.
struct Measure {
    distance: f64,
    needed: f64,
    error_pixels: f64,
}

/// The leaves several views of one frame need together (rules 1–4 of the
/// module documentation, applied to all views at once): a node is culled
/// when every view culls it, split when any view that sees it would split
/// it, and a leaf gets the largest size any of those views needs and the
/// smallest distance. So the leaves partition the union of the visible
/// parts exactly, the finest need wins where views overlap, and no node is
/// selected twice. Nodes split neediest first (the most texels or error
/// pixels over the thresholds); once a split would exceed [`MAX_SELECTED`]
/// leaves the rest stay leaves, so a selection's work is bounded whatever
/// the view and the terrain. Errors on an empty `views`, invalid
/// settings, a non-finite or non-positive extent, a bad view, or bounds
/// that are not finite with `z_min ≤ z_max` and `geometric_error ≥ 0`.
pub fn select_tiles_for_views(
    extent: DVec2,
    views: &[Footprint],
    settings: &QuadtreeSettings,
    bounds: &dyn Fn(NodeId) -> NodeBounds,
) -> Result<Vec<NeededTile>> {
    settings.validate()?;
    if !(extent.is_finite() && extent.x > 0.0 && extent.y > 0.0) {
        return Err(Error::invalid(
            "texture view",
            format!("extent {extent} must be finite and positive"),
        ));
    }
    if views.is_empty() {
        return Err(Error::invalid("texture view", "no view to select tiles for"));
    }
    views.iter().try_for_each(check_view)?;
    let selector = Selector {
        extent,
        views,
        settings,
        bounds,
    };
    let mut leaves = Vec::new();
    // Nodes to split, the neediest first.
    let mut split = std::collections::BinaryHeap::new();
    let visit = |node, leaves: &mut Vec<NeededTile>, split: &mut std::collections::BinaryHeap<Candidate>| {
        match selector.visit(node)? {
            Some((tile, Some(need))) => split.push(Candidate { need, tile }),
            Some((tile, None)) => leaves.push(tile),
            None => {}
        }
        Ok::<(), Error>(())
    };
    visit(NodeId::ROOT, &mut leaves, &mut split)?;
    while let Some(c) = split.pop() {
        // A split replaces one node by (at most) four.
        if leaves.len() + split.len() + 4 > MAX_SELECTED {
            leaves.push(c.tile);
            leaves.extend(split.drain().map(|c| c.tile));
            break;
        }
        for child in c.tile.node.children() {
            visit(child, &mut leaves, &mut split)?;
        }
    }
    leaves.sort_by(selection_order);
    Ok(leaves)
}

/// A node a view would split, by how much it exceeds the split thresholds.
struct Candidate {
    need: f64,
    tile: NeededTile,
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    /// The larger need first, then the smaller node id.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.need
            .total_cmp(&other.need)
            .then(other.tile.node.cmp(&self.tile.node))
    }
}

/// Most leaves [`select_tiles_for_views`] returns: four times what the page
/// table holds (`crate::texturing::generation::PAGE_TABLE_WORDS`, three
/// words a tile), which [`crate::texturing::fit`] coarsens further.
pub const MAX_SELECTED: usize = 1 << 16;

/// One selection's inputs (rules 1–4 of the module documentation).
struct Selector<'a> {
    extent: DVec2,
    views: &'a [Footprint],
    settings: &'a QuadtreeSettings,
    bounds: &'a dyn Fn(NodeId) -> NodeBounds,
}

impl Selector<'_> {
    /// `None` when every view culls `node`; else its tile as a leaf and,
    /// when a view would split it, by how much the neediest view exceeds
    /// the thresholds (the larger of its texels over the aim and its error
    /// pixels over `pixel_error`).
    fn visit(&self, node: NodeId) -> Result<Option<(NeededTile, Option<f64>)>> {
        let (settings, border2) = (self.settings, 2.0 * f64::from(self.settings.border));
        let b = (self.bounds)(node);
        let error_ok = b.geometric_error.is_finite() && b.geometric_error >= 0.0;
        if !(b.z_min.is_finite() && b.z_max.is_finite() && b.z_min <= b.z_max && error_ok) {
            return Err(Error::invalid(
                "texture node bounds",
                format!("{b:?} for node {node:?}"),
            ));
        }
        let (lo, hi) = node.rect(self.extent);
        let box_min = lo.extend(f64::from(b.z_min));
        let box_max = hi.extend(f64::from(b.z_max));
        let largest = match node.level == settings.max_depth {
            true => settings.max_tile,
            false => settings.upper_tile(),
        };
        let fit = |w: f64| (w as u32).next_power_of_two().clamp(settings.min_tile, largest);
        let size_for = |m: &Measure| {
            let want = m.needed.ceil() + border2;
            if want >= f64::from(largest) {
                largest
            } else {
                fit(want)
            }
        };
        // Reduced view by view (no allocation per node): the neediest
        // view's need and size, the nearest view's distance.
        let (mut seen, mut need, mut size, mut distance) = (false, 0.0f64, settings.min_tile, f64::INFINITY);
        for view in self.views {
            let outside = |p: &DVec4| box_outside(p, box_min, box_max);
            if view.frustum.is_some_and(|planes| planes.iter().any(outside)) {
                continue;
            }
            let d = view.eye.clamp(box_min, box_max).distance(view.eye).max(MIN_DISTANCE);
            let per_metre = 1.0 / (view.pixel_footprint * d);
            let m = Measure {
                distance: d,
                needed: (hi - lo).max_element() * per_metre,
                error_pixels: f64::from(b.geometric_error) * per_metre,
            };
            let texels = (m.needed + border2) / f64::from(settings.aim_texels);
            need = need.max(texels.max(m.error_pixels / f64::from(settings.pixel_error)));
            size = if seen { size.max(size_for(&m)) } else { size_for(&m) };
            distance = distance.min(m.distance);
            seen = true;
        }
        if !seen {
            return Ok(None);
        }
        let tile = NeededTile { node, size, distance };
        let split = need > 1.0 && node.level < settings.max_depth;
        Ok(Some((tile, split.then_some(need))))
    }
}

/// The order of selected tiles: coarse to fine, then nearest first, then
/// by node id.
pub fn selection_order(a: &NeededTile, b: &NeededTile) -> std::cmp::Ordering {
    (a.node.level.cmp(&b.node.level))
        .then(a.distance.total_cmp(&b.distance))
        .then(a.node.cmp(&b.node))
}

/// Whether the box `[min, max]` lies entirely on the outer side of `plane`.
fn box_outside(plane: &DVec4, min: DVec3, max: DVec3) -> bool {
    let n = plane.truncate();
    let farthest = DVec3::select(n.cmpge(DVec3::ZERO), max, min);
    n.dot(farthest) + plane.w < 0.0
}

#[cfg(test)]
#[path = "quadtree_tests.rs"]
mod tests;
