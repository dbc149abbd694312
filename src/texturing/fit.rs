//! Fitting a frame's needed tiles into the atlas (dissertation §8.2.4: the
//! atlas textures are allocated once, so a frame's need must fit them).
//!
//! The quadtree selects what the views need ([`super::quadtree`]); the
//! atlas holds a fixed number of tiles of each size. When the views need
//! more tiles of a size than the atlas can hold, the cache could never place
//! them all and the frame would never settle. [`fit_to_atlas`] coarsens the
//! selection until it fits, so every legal view settles, slightly blurrier:
//!
//! 1. **Halve.** From the largest size down, the tiles over a size's
//!    capacity drop to half their size (half the texels across: the next
//!    smaller size), farthest first (ties: the larger node id). A size's
//!    capacity is its slots less one, kept for a root tile the view does not
//!    need (the cache keeps one resident as the fallback of last resort).
//! 2. **Merge.** If the smallest size still overflows, or there are more
//!    tiles than `max_tiles` (the page table's capacity), the deepest level's
//!    leaves are replaced by their parents (the largest of the children's
//!    sizes, the nearest distance), and step 1 runs again. The leaves still
//!    partition what the views see: a parent covers its culled children too.
//!
//! The result keeps the selection's order (coarse to fine, nearest first,
//! then by node id). A selection that fits comes back unchanged.

use std::collections::BTreeMap;

use glam::DVec2;

use crate::error::Result;
use crate::texturing::atlas::AtlasSettings;
use crate::texturing::generation::PAGE_TABLE_WORDS;
use crate::texturing::page_table::PageTable;
use crate::texturing::quadtree::{select_tiles_for_views, selection_order, HeightBounds, NeededTile, NodeId};
use crate::texturing::streaming::TextureStreaming;
use crate::view::Footprint;

/// What fitting did to a selection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Coarsening {
    /// Halvings of a tile's size (a tile halved twice counts twice).
    pub halved: usize,
    /// Leaves replaced by their parents.
    pub merged: usize,
}

impl Coarsening {
    /// Whether the selection was changed.
    #[cfg(test)]
    pub fn any(&self) -> bool {
        self.halved + self.merged > 0
    }
}

/// Tiles of each size the atlas can hold for a frame's need: the slots of
/// the size less one for a root tile (module documentation).
pub fn capacities(atlas: &AtlasSettings) -> Vec<usize> {
    (0..atlas.sizes())
        .map(|k| {
            let size = atlas.tile_size(k);
            let slots = u64::from(atlas.slots_per_texture(size)) * u64::from(atlas.textures_of(size));
            (slots.saturating_sub(1)).min(usize::MAX as u64) as usize
        })
        .collect()
}

/// Coarsens `needed` (from the quadtree) until every size fits `atlas`
/// and there are at most `max_tiles` tiles, by the rules of the module
/// documentation.
pub fn fit_to_atlas(needed: &mut Vec<NeededTile>, atlas: &AtlasSettings, max_tiles: usize) -> Coarsening {
    let capacity = capacities(atlas);
    let class = |size: u32| atlas.size_index(size.clamp(atlas.min_tile, atlas.max_tile).next_power_of_two());
    let mut done = Coarsening::default();
    loop {
        let mut counts = vec![0usize; capacity.len()];
        for t in needed.iter_mut() {
            let k = class(t.size).unwrap_or(0);
            t.size = atlas.tile_size(k);
            counts[k as usize] += 1;
        }
        for k in (1..capacity.len()).rev() {
            let excess = counts[k].saturating_sub(capacity[k]);
            if excess == 0 {
                continue;
            }
            let size = atlas.tile_size(k as u32);
            let mut of_size: Vec<&mut NeededTile> = needed.iter_mut().filter(|t| t.size == size).collect();
            of_size.sort_by(|a, b| b.distance.total_cmp(&a.distance).then(b.node.cmp(&a.node)));
            for t in of_size.into_iter().take(excess) {
                t.size = size / 2;
            }
            (counts[k], counts[k - 1]) = (counts[k] - excess, counts[k - 1] + excess);
            done.halved += excess;
        }
        let fits = counts.first().map_or(true, |&c| c <= capacity[0]) && needed.len() <= max_tiles.max(1);
        if fits || !merge_deepest(needed, &mut done) {
            break;
        }
    }
    needed.sort_by(selection_order);
    done
}

/// What the texture atlas draws from for `views` of a field of `extent`
/// with `bounds` (on the CPU, each frame before recording): the quadtree's
/// selection ([`select_tiles_for_views`]) fitted to `streaming`'s atlas and
/// to the page table's [`PAGE_TABLE_WORDS`] (at most a third of them in
/// tiles, halved until the table fits).
pub fn select_to_fit(
    extent: DVec2,
    views: &[Footprint],
    streaming: &TextureStreaming,
    bounds: &HeightBounds,
) -> Result<(Vec<NeededTile>, Coarsening)> {
    let bounds = |n| bounds.bounds(n);
    let mut needed = select_tiles_for_views(extent, views, &streaming.quadtree, &bounds)?;
    // Entries take two words, inner nodes one: start at a third.
    let mut max_tiles = PAGE_TABLE_WORDS / 3;
    let mut done = fit_to_atlas(&mut needed, &streaming.atlas, max_tiles);
    while PageTable::words_for(needed.iter().map(|t| t.node)) > PAGE_TABLE_WORDS && max_tiles > 1 {
        max_tiles /= 2;
        let more = fit_to_atlas(&mut needed, &streaming.atlas, max_tiles);
        (done.halved, done.merged) = (done.halved + more.halved, done.merged + more.merged);
    }
    Ok((needed, done))
}

/// Replaces the leaves of the deepest level by their parents; false when
/// only the root is left.
fn merge_deepest(needed: &mut Vec<NeededTile>, done: &mut Coarsening) -> bool {
    let Some(deepest) = needed.iter().map(|t| t.node.level).max().filter(|&l| l > 0) else {
        return false;
    };
    let mut parents: BTreeMap<NodeId, NeededTile> = BTreeMap::new();
    let before = needed.len();
    needed.retain(|t| {
        if t.node.level != deepest {
            return true;
        }
        let node = t.node.parent().unwrap_or(NodeId::ROOT);
        let parent = parents.entry(node).or_insert(NeededTile { node, ..*t });
        parent.size = parent.size.max(t.size);
        parent.distance = parent.distance.min(t.distance);
        false
    });
    needed.extend(parents.into_values());
    done.merged += before - needed.len();
    true
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use super::*;
    use crate::texturing::quadtree::{select_tiles, NodeBounds, QuadtreeSettings};
    use crate::view::Footprint;

    const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

    /// An atlas of 256² textures, one per size from 16² to 128²: 255, 63,
    /// 15 and 3 tiles.
    fn small_atlas() -> AtlasSettings {
        AtlasSettings {
            size: 256,
            border: 4,
            min_tile: 16,
            max_tile: 128,
            textures: [1; 8],
        }
    }

    fn ground_view_tiles() -> Vec<NeededTile> {
        let view = Footprint {
            eye: DVec3::new(4000.0, 2000.0, 2.0),
            pixel_footprint: Footprint::pixel_footprint_for(1.0, 180),
            frustum: None,
        };
        let flat = |_| NodeBounds {
            z_min: 0.0,
            z_max: 1.0,
            geometric_error: 0.0,
        };
        let settings = QuadtreeSettings {
            max_tile: 128,
            ..QuadtreeSettings::default()
        };
        select_tiles(EXTENT, &view, &settings, &flat).unwrap()
    }

    /// Panics unless the leaves `b` partition what the leaves `a` cover.
    fn assert_same_cover(a: &[NeededTile], b: &[NeededTile]) {
        let area = |tiles: &[NeededTile]| tiles.iter().map(|t| 4f64.powi(-(t.node.level as i32))).sum::<f64>();
        assert!((area(a) - area(b)).abs() < 1e-12, "{} vs {}", area(a), area(b));
        for (i, t) in b.iter().enumerate() {
            let overlap = b[i + 1..]
                .iter()
                .any(|u| t.node.contains(&u.node) || u.node.contains(&t.node));
            assert!(!overlap, "{t:?} overlaps another leaf");
            assert!(
                a.iter().any(|u| t.node.contains(&u.node) || u.node.contains(&t.node)),
                "{t:?} covers nothing of the selection"
            );
        }
    }

    #[test]
    fn a_selection_that_fits_is_unchanged() {
        let mut tiles = ground_view_tiles();
        let before = tiles.clone();
        let roomy = AtlasSettings {
            size: 2048,
            textures: [8; 8],
            ..small_atlas()
        };
        assert!(!fit_to_atlas(&mut tiles, &roomy, usize::MAX).any());
        assert_eq!(tiles, before);
    }

    #[test]
    fn overflowing_sizes_halve_farthest_first_until_every_size_fits() {
        let mut tiles = ground_view_tiles();
        let before = tiles.clone();
        let count = |tiles: &[NeededTile], size| tiles.iter().filter(|t| t.size == size).count();
        assert!(count(&before, 128) > 3, "the case must overflow the 128² tiles");
        let done = fit_to_atlas(&mut tiles, &small_atlas(), usize::MAX);
        assert!(done.halved > 0, "{done:?}");
        for (size, capacity) in [16, 32, 64, 128].into_iter().zip(capacities(&small_atlas())) {
            assert!(count(&tiles, size) <= capacity, "{size}²: {}", count(&tiles, size));
        }
        assert_same_cover(&before, &tiles);
        // Nothing got finer, and the nearest tiles kept the largest size.
        if done.merged == 0 {
            for (a, b) in before.iter().zip(&tiles) {
                assert!(b.size <= a.size);
            }
        }
        let nearest = tiles.iter().min_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
        let largest = tiles.iter().map(|t| t.size).max().unwrap();
        assert_eq!(nearest.size, largest);
        assert!(tiles.windows(2).all(|w| selection_order(&w[0], &w[1]).is_lt()));
    }

    #[test]
    fn too_many_tiles_merge_into_parents() {
        let mut tiles = ground_view_tiles();
        let before = tiles.clone();
        let done = fit_to_atlas(&mut tiles, &small_atlas(), 40);
        assert!(done.merged > 0 && tiles.len() <= 40, "{done:?}: {} tiles", tiles.len());
        assert_same_cover(&before, &tiles);
        let deepest = |t: &[NeededTile]| t.iter().map(|t| t.node.level).max().unwrap();
        assert!(deepest(&tiles) < deepest(&before));
        // One tile is all an atlas must hold.
        let mut tiles = before.clone();
        fit_to_atlas(&mut tiles, &small_atlas(), 1);
        assert_eq!(tiles.len(), 1);
        assert_eq!(tiles[0].node, NodeId::ROOT);
    }
}
