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

/// What the view needs this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position in world metres.
    pub eye: DVec3,
    /// Image-space size of one pixel at 1 m: `2·tan(fov_y/2)/rows`
    /// (see [`View::pixel_footprint_for`]).
    pub pixel_footprint: f64,
    /// World planes `(n, d)` with `n·x + d ≥ 0` inside; `None`: no culling.
    pub frustum: Option<[DVec4; 6]>,
}

impl View {
    /// The pixel footprint `2·tan(fov_y/2)/rows` of a pinhole camera with
    /// vertical field of view `fov_y` (radians) and `rows` image rows.
    pub fn pixel_footprint_for(fov_y: f64, rows: u32) -> f64 {
        2.0 * (fov_y / 2.0).tan() / f64::from(rows.max(1))
    }
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
pub fn select_tiles(
    extent: DVec2,
    view: &View,
    settings: &QuadtreeSettings,
    bounds: &dyn Fn(NodeId) -> NodeBounds,
) -> Result<Vec<NeededTile>> {
    select_tiles_for_views(extent, std::slice::from_ref(view), settings, bounds)
}

/// Checks a view: finite eye, finite positive footprint, finite planes.
fn check_view(view: &View) -> Result<()> {
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
/// selected twice. Errors on an empty `views`, invalid settings, a
/// non-finite or non-positive extent, a bad view, or bounds that are not
/// finite with `z_min ≤ z_max` and `geometric_error ≥ 0`.
pub fn select_tiles_for_views(
    extent: DVec2,
    views: &[View],
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
    let upper = settings.upper_tile();
    let border2 = 2.0 * f64::from(settings.border);
    let mut leaves = Vec::new();
    let mut stack = vec![NodeId::ROOT];
    let mut seen: Vec<Measure> = Vec::with_capacity(views.len());
    while let Some(node) = stack.pop() {
        let b = bounds(node);
        let error_ok = b.geometric_error.is_finite() && b.geometric_error >= 0.0;
        if !(b.z_min.is_finite() && b.z_max.is_finite() && b.z_min <= b.z_max && error_ok) {
            return Err(Error::invalid(
                "texture node bounds",
                format!("{b:?} for node {node:?}"),
            ));
        }
        let (lo, hi) = node.rect(extent);
        let box_min = lo.extend(f64::from(b.z_min));
        let box_max = hi.extend(f64::from(b.z_max));
        seen.clear();
        for view in views {
            let outside = |p: &DVec4| box_outside(p, box_min, box_max);
            if view.frustum.is_some_and(|planes| planes.iter().any(outside)) {
                continue;
            }
            let distance = view.eye.clamp(box_min, box_max).distance(view.eye).max(MIN_DISTANCE);
            let per_metre = 1.0 / (view.pixel_footprint * distance);
            seen.push(Measure {
                distance,
                needed: (hi - lo).max_element() * per_metre,
                error_pixels: f64::from(b.geometric_error) * per_metre,
            });
        }
        if seen.is_empty() {
            continue;
        }
        let coarse = seen.iter().any(|m| {
            m.needed + border2 > f64::from(settings.aim_texels) || m.error_pixels > f64::from(settings.pixel_error)
        });
        if node.level < settings.max_depth && coarse {
            stack.extend(node.children());
            continue;
        }
        let at_max_depth = node.level == settings.max_depth;
        let largest = if at_max_depth { settings.max_tile } else { upper };
        let fit = |w: f64| (w as u32).next_power_of_two().clamp(settings.min_tile, largest);
        let size_for = |m: &Measure| {
            let want = m.needed.ceil() + border2;
            if want >= f64::from(largest) {
                largest
            } else {
                fit(want)
            }
        };
        let size = seen.iter().map(size_for).max().unwrap_or(settings.min_tile);
        let distance = seen.iter().map(|m| m.distance).fold(f64::INFINITY, f64::min);
        leaves.push(NeededTile { node, size, distance });
    }
    leaves.sort_by(selection_order);
    Ok(leaves)
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
mod tests {
    use std::collections::HashSet;

    use super::*;

    const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

    fn flat(_: NodeId) -> NodeBounds {
        NodeBounds {
            z_min: 0.0,
            z_max: 100.0,
            geometric_error: 0.0,
        }
    }

    fn view(eye: DVec3) -> View {
        View {
            eye,
            pixel_footprint: View::pixel_footprint_for(1.0, 1080),
            frustum: None,
        }
    }

    fn select(eye: DVec3) -> Vec<NeededTile> {
        select_tiles(EXTENT, &view(eye), &QuadtreeSettings::default(), &flat).unwrap()
    }

    #[test]
    fn leaves_partition_the_rectangle() {
        let n = 1u32 << 10;
        for eye in [
            DVec3::new(100.0, 200.0, 50.0),
            DVec3::new(7999.0, 3999.0, 10.0),
            DVec3::new(4000.0, 2000.0, 3e3),
        ] {
            let tiles = select(eye);
            let mut cover = vec![0u8; (n * n) as usize];
            for t in &tiles {
                let k = n >> t.node.level;
                for y in t.node.y * k..(t.node.y + 1) * k {
                    for x in t.node.x * k..(t.node.x + 1) * k {
                        cover[(y * n + x) as usize] += 1;
                    }
                }
            }
            assert!(cover.iter().all(|&c| c == 1), "eye {eye}: {} tiles", tiles.len());
            assert!(tiles.windows(2).all(|w| selection_order(&w[0], &w[1]).is_lt()));
        }
    }

    #[test]
    fn nearer_nodes_are_finer_and_sizes_in_bounds() {
        let s = QuadtreeSettings::default();
        let tiles = select(DVec3::new(100.0, 100.0, 20.0));
        let near = tiles.iter().min_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
        let far = tiles.iter().max_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
        assert!(near.node.level > far.node.level);
        assert!(near.node.rect(EXTENT).0.x < 1000.0 && near.node.level == s.max_depth);
        for t in &tiles {
            assert!(t.size.is_power_of_two() && (s.min_tile..=s.max_tile).contains(&t.size));
            assert!(t.node.level == s.max_depth || t.size <= 256, "{t:?}");
        }
        // Texels per metre fall off with distance.
        let density = |t: &NeededTile| f64::from(t.size - 2 * s.border) / (EXTENT.x / f64::from(1u32 << t.node.level));
        assert!(density(near) > density(far));
    }

    #[test]
    fn far_eye_gives_the_root_only() {
        let tiles = select(DVec3::new(4000.0, 2000.0, 1e7));
        assert_eq!(tiles.len(), 1);
        assert_eq!((tiles[0].node, tiles[0].size), (NodeId::ROOT, 16));
    }

    #[test]
    fn geometric_error_forces_splits() {
        let rough = |n: NodeId| NodeBounds {
            z_min: 0.0,
            z_max: 100.0,
            geometric_error: 500.0 / (1u32 << n.level) as f32,
        };
        let settings = QuadtreeSettings::default();
        let v = view(DVec3::new(4000.0, 2000.0, 1e5));
        assert_eq!(select_tiles(EXTENT, &v, &settings, &flat).unwrap().len(), 1);
        let tiles = select_tiles(EXTENT, &v, &settings, &rough).unwrap();
        assert_eq!(tiles.len(), 64, "splits to level 3 where the error is 0.6 px");
    }

    #[test]
    fn frustum_drops_nodes_behind_the_camera() {
        let eye = DVec3::new(4000.0, 2000.0, 50.0);
        // Looking east: keep x ≥ eye.x (plus five planes that keep everything).
        let keep = DVec4::new(0.0, 0.0, 0.0, 1.0);
        let mut v = view(eye);
        v.frustum = Some([DVec4::new(1.0, 0.0, 0.0, -eye.x), keep, keep, keep, keep, keep]);
        let all = select(eye);
        let culled = select_tiles(EXTENT, &v, &QuadtreeSettings::default(), &flat).unwrap();
        assert!(!culled.is_empty() && culled.len() < all.len());
        assert!(culled.iter().all(|t| t.node.rect(EXTENT).1.x >= eye.x));
    }

    /// Texel density (texels per metre) of the leaf over each cell of the
    /// finest grid (`max_depth` 10), None where no leaf is; panics where
    /// leaves overlap.
    fn density_map(tiles: &[NeededTile]) -> Vec<Option<f64>> {
        const GRID: u32 = 10;
        let n = 1u32 << GRID;
        let mut cover = vec![None; (n * n) as usize];
        for t in tiles {
            let k = n >> t.node.level;
            let density = f64::from(t.size - 8) / (EXTENT.x / f64::from(1u32 << t.node.level));
            for y in t.node.y * k..(t.node.y + 1) * k {
                for x in t.node.x * k..(t.node.x + 1) * k {
                    let cell = &mut cover[(y * n + x) as usize];
                    assert!(cell.is_none(), "{t:?} overlaps another leaf");
                    *cell = Some(density);
                }
            }
        }
        cover
    }

    #[test]
    fn views_looking_apart_get_the_union_finest_first() {
        let eye = DVec3::new(4000.0, 2000.0, 50.0);
        let keep = DVec4::new(0.0, 0.0, 0.0, 1.0);
        let facing = |sign: f64| View {
            frustum: Some([DVec4::new(sign, 0.0, 0.0, -sign * eye.x), keep, keep, keep, keep, keep]),
            ..view(eye)
        };
        // East looks from the eye, west from 500 m west of it: different needs.
        let (east, west) = (
            facing(1.0),
            View {
                eye: eye - DVec3::new(500.0, 0.0, 0.0),
                ..facing(-1.0)
            },
        );
        let s = QuadtreeSettings::default();
        let one = |v: &View| select_tiles(EXTENT, v, &s, &flat).unwrap();
        let (a, b) = (density_map(&one(&east)), density_map(&one(&west)));
        let both = select_tiles_for_views(EXTENT, &[east, west], &s, &flat).unwrap();
        let union = density_map(&both);
        let keys: HashSet<NodeId> = both.iter().map(|t| t.node).collect();
        assert_eq!(keys.len(), both.len(), "a node selected twice");
        let (mut only_a, mut only_b) = (0, 0);
        for ((u, a), b) in union.iter().zip(&a).zip(&b) {
            assert_eq!(u.is_some(), a.is_some() || b.is_some(), "cover is not the union");
            only_a += usize::from(a.is_some() && b.is_none());
            only_b += usize::from(b.is_some() && a.is_none());
        }
        assert!(
            only_a > 0 && only_b > 0,
            "the views must each see something the other does not"
        );
        // Every leaf has the texels each view that sees it needs (rule 2),
        // unless clamped to the largest size.
        for t in &both {
            let (lo, hi) = t.node.rect(EXTENT);
            let (min, max) = (lo.extend(0.0), hi.extend(100.0));
            for v in [&east, &west] {
                if v.frustum.unwrap().iter().any(|p| box_outside(p, min, max)) {
                    continue;
                }
                let distance = v.eye.clamp(min, max).distance(v.eye).max(MIN_DISTANCE);
                let needed = (hi - lo).max_element() / (v.pixel_footprint * distance);
                let inner = f64::from(t.size - 2 * s.border);
                assert!(inner >= needed || t.size == s.max_tile, "{t:?}: {needed} texels needed");
            }
        }
        assert!(both.len() > one(&east).len().max(one(&west).len()));
    }

    #[test]
    fn overlapping_views_do_not_duplicate_tiles() {
        let s = QuadtreeSettings::default();
        let v = view(DVec3::new(1000.0, 1000.0, 300.0));
        let single = select_tiles(EXTENT, &v, &s, &flat).unwrap();
        let twice = select_tiles_for_views(EXTENT, &[v, v], &s, &flat).unwrap();
        assert_eq!(single, twice);
        // A view a little to the side shares most of the tiles.
        let near = View {
            eye: v.eye + DVec3::new(50.0, 0.0, 0.0),
            ..v
        };
        let pair = select_tiles_for_views(EXTENT, &[v, near], &s, &flat).unwrap();
        density_map(&pair);
        assert!(pair.len() < single.len() * 3 / 2, "{} vs {}", pair.len(), single.len());
        assert!(select_tiles_for_views(EXTENT, &[], &s, &flat).is_err());
    }

    #[test]
    fn invalid_settings_and_inputs_are_errors() {
        let d = QuadtreeSettings::default();
        let bad = [
            QuadtreeSettings { min_tile: 24, ..d },
            QuadtreeSettings { min_tile: 1024, ..d },
            QuadtreeSettings { border: 8, ..d },
            QuadtreeSettings { max_depth: 16, ..d },
            QuadtreeSettings { aim_texels: 4, ..d },
            QuadtreeSettings {
                pixel_error: f32::NAN,
                ..d
            },
        ];
        for s in bad {
            assert!(s.validate().is_err(), "{s:?}");
            assert!(select_tiles(EXTENT, &view(DVec3::ZERO), &s, &flat).is_err());
        }
        let v = View {
            pixel_footprint: 0.0,
            ..view(DVec3::ZERO)
        };
        assert!(select_tiles(EXTENT, &v, &d, &flat).is_err());
        assert!(select_tiles(DVec2::new(0.0, 1.0), &view(DVec3::ZERO), &d, &flat).is_err());
        let nan = |_: NodeId| NodeBounds {
            z_min: f32::NAN,
            z_max: 0.0,
            geometric_error: 0.0,
        };
        assert!(select_tiles(EXTENT, &view(DVec3::ZERO), &d, &nan).is_err());
    }

    #[test]
    fn node_ids_relate() {
        let n = NodeId { level: 3, x: 5, y: 2 };
        assert_eq!(n.parent(), Some(NodeId { level: 2, x: 2, y: 1 }));
        assert_eq!(NodeId::ROOT.parent(), None);
        assert!(n.children().iter().all(|c| c.parent() == Some(n) && n.contains(c)));
        assert!(NodeId::ROOT.contains(&n) && n.contains(&n) && !n.contains(&NodeId::ROOT));
        assert!(!NodeId { level: 2, x: 1, y: 1 }.contains(&n));
        assert_eq!(n.rect(EXTENT), (DVec2::new(5000.0, 1000.0), DVec2::new(6000.0, 1500.0)));
    }
}
