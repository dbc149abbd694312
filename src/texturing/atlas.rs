//! Tile slots in texture atlases, reuse from frame to frame and the page
//! table (dissertation §8.2).
//!
//! # Atlases
//!
//! Tiles live in the layers of an array texture of `size × size` texels.
//! Every layer holds tiles of one size: layer `k` holds tiles of
//! `min_tile·2^k` texels (border included), packed row-major into
//! `(size/tile)²` slots.
//!
//! # Frame plan rules ([`TileCache::plan_frame`])
//!
//! A tile is keyed by `(node, size)`; it is generated again only when the
//! needed size changes (a different key) or after it was evicted.
//!
//! 1. **Root first.** A root tile ([`NodeId::ROOT`]) must always be resident
//!    so every needed tile has a fallback. If the root is needed and not
//!    resident at its needed size, it is scheduled first and counts against
//!    the cap. If no root tile is resident at all, one is generated even
//!    when the cap is 0 (at its needed size, or `min_tile` when the view does
//!    not need the root), so a plan may then hold `cap + 1` tiles. The last
//!    resident root tile is never evicted.
//! 2. **Hits.** Needed tiles already resident at their needed size are used.
//! 3. **Misses** are ordered coarse levels first, then nearer, then by node
//!    id, and the first tiles within the cap are generated. The resident
//!    fallbacks of the tiles over the cap are marked used first, so
//!    generation does not evict what they will be drawn from.
//! 4. **Slots.** A tile takes the lowest free slot of its layer, else the
//!    slot of the least recently used tile (ties: lowest slot) that was not
//!    used (drawn or generated) in this frame. A layer full of tiles used in
//!    this frame defers the tile instead.
//! 5. **Fallback.** A needed tile that is not resident is drawn from a
//!    resident tile of the same node at another size, else from the nearest
//!    resident ancestor; among several sizes the largest is taken. Such
//!    tiles count as `deferred`.
//!
//! Needed sizes outside `[min_tile, max_tile]` or not powers of two are
//! clamped to the range and rounded up to a power of two. Frame numbers must
//! increase from call to call; a tile "used in this frame" is one whose last
//! use carries the current frame number.

use std::collections::{HashMap, HashSet};

use bytemuck::Zeroable as _;

use glam::DVec2;

use crate::error::{Error, Result};
use crate::texturing::quadtree::{NeededTile, NodeId, QuadtreeSettings};

/// Deepest page table [`page_table`] builds: `4096²` cells (512 MiB).
pub const MAX_TABLE_DEPTH: u32 = 12;

/// Atlas size and the range of tile sizes it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasSettings {
    /// Width and height of every atlas layer in texels (power of two).
    pub size: u32,
    /// Texels of border on each side of a tile.
    pub border: u32,
    /// Smallest tile size, border included (power of two).
    pub min_tile: u32,
    /// Largest tile size, border included (power of two, ≤ `size`).
    pub max_tile: u32,
}

impl Default for AtlasSettings {
    fn default() -> Self {
        AtlasSettings {
            size: 1024,
            border: 4,
            min_tile: 16,
            max_tile: 512,
        }
    }
}

impl AtlasSettings {
    /// Atlases of 1024² texels (larger if `max_tile` is) for the tiles of
    /// `quadtree`.
    pub fn for_quadtree(quadtree: &QuadtreeSettings) -> AtlasSettings {
        AtlasSettings {
            size: quadtree.max_tile.max(1024),
            border: quadtree.border,
            min_tile: quadtree.min_tile,
            max_tile: quadtree.max_tile,
        }
    }

    /// Checks: all sizes are powers of two, `min_tile ≤ max_tile ≤ size`,
    /// `2·border < min_tile`.
    pub fn validate(&self) -> Result<()> {
        let (size, min, max, border) = (self.size, self.min_tile, self.max_tile, self.border);
        let why = if ![size, min, max].iter().all(|v| v.is_power_of_two()) {
            format!("sizes {size}, {min}, {max} must be powers of two")
        } else if min > max || max > size {
            format!("need min_tile {min} ≤ max_tile {max} ≤ size {size}")
        } else if u64::from(border) * 2 >= u64::from(min) {
            format!("border {border} leaves no inner texels in min_tile {min}")
        } else {
            return Ok(());
        };
        Err(Error::invalid("texture atlas settings", why))
    }

    /// Number of atlas layers: one per tile size from `min_tile` to `max_tile`.
    pub fn layers(&self) -> u32 {
        let (min, max) = (self.min_tile.trailing_zeros(), self.max_tile.trailing_zeros());
        max.saturating_sub(min) + 1
    }

    /// The layer holding tiles of `tile_size`, `None` for a size not in the atlas.
    pub fn layer_of(&self, tile_size: u32) -> Option<u32> {
        let fits = tile_size.is_power_of_two() && (self.min_tile..=self.max_tile).contains(&tile_size);
        fits.then(|| tile_size.trailing_zeros() - self.min_tile.trailing_zeros())
    }

    /// Slots of one layer for tiles of `tile_size`, 0 for a size not in the atlas.
    pub fn slots_per_layer(&self, tile_size: u32) -> u32 {
        match self.layer_of(tile_size) {
            Some(_) => (self.size / tile_size).pow(2),
            None => 0,
        }
    }

    /// `tile_size` clamped to the atlas's range and rounded up to a power of two.
    fn fit(&self, tile_size: u32) -> u32 {
        tile_size.clamp(self.min_tile, self.max_tile).next_power_of_two()
    }
}

/// Where a tile lies: atlas layer and texel origin of the tile (border
/// included) in the layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileSlot {
    /// Atlas layer (one per tile size).
    pub layer: u32,
    /// Texel column of the tile's first texel.
    pub x: u32,
    /// Texel row of the tile's first texel.
    pub y: u32,
    /// Tile size in texels, border included.
    pub size: u32,
}

/// What a frame generates and draws.
#[derive(Clone, Debug, PartialEq)]
pub struct TilePlan {
    /// Tiles to generate this frame, in priority order (≤ cap, see the module
    /// documentation for the root exception).
    pub generate: Vec<(NodeId, TileSlot)>,
    /// One entry per needed tile that has a resident source (all of them
    /// unless no root tile could be placed), in the order of `needed`.
    pub draw: Vec<DrawTile>,
    /// Counters of the frame.
    pub stats: TileStats,
    /// The largest resident root tile after this frame, if any.
    pub root: Option<TileSlot>,
    /// Texels of border on each side of a tile.
    pub border: u32,
}

/// How one needed node is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawTile {
    /// The node the view needs.
    pub needed: NodeId,
    /// The node whose tile is sampled: `needed` itself, or the nearest
    /// resident ancestor while the finer tile is not ready.
    pub source: NodeId,
    /// Where the source tile lies.
    pub slot: TileSlot,
}

/// Counters of one planned frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TileStats {
    /// Needed tiles.
    pub visible: usize,
    /// Needed tiles already resident at their needed size.
    pub hits: usize,
    /// Tiles generated this frame.
    pub generated: usize,
    /// Tiles evicted this frame.
    pub evicted: usize,
    /// Needed tiles drawn from another tile (over the cap or no free slot).
    pub deferred: usize,
    /// Resident tiles after the frame.
    pub resident: usize,
}

impl TileStats {
    /// `hits / visible`, 1 when nothing is visible.
    pub fn hit_rate(&self) -> f64 {
        if self.visible == 0 {
            1.0
        } else {
            self.hits as f64 / self.visible as f64
        }
    }
}

/// A resident tile: its node and the last frame it was used in.
#[derive(Clone, Copy, Debug)]
struct Resident {
    node: NodeId,
    last_used: u64,
}

/// The resident tiles of all atlas layers and their reuse across frames.
#[derive(Clone, Debug)]
pub struct TileCache {
    settings: AtlasSettings,
    /// `slots[layer][slot index]`: the tile there, if any.
    slots: Vec<Vec<Option<Resident>>>,
    /// `(node, size)` → (layer, slot index).
    index: HashMap<(NodeId, u32), (u32, u32)>,
}

impl TileCache {
    /// An empty cache; errors on invalid settings.
    pub fn new(settings: AtlasSettings) -> Result<TileCache> {
        settings.validate()?;
        let sizes = (0..settings.layers()).map(|k| settings.min_tile << k);
        let layer = |s| vec![None; settings.slots_per_layer(s) as usize];
        let slots = sizes.map(layer).collect();
        Ok(TileCache {
            settings,
            slots,
            index: HashMap::new(),
        })
    }

    /// Forgets every tile (e.g. after the surface layers changed).
    pub fn clear(&mut self) {
        self.slots.iter_mut().for_each(|layer| layer.fill(None));
        self.index.clear();
    }

    /// Plans one frame: `needed` from `select_tiles`; at most `cap` tiles are
    /// (re)generated, by the rules in the module documentation.
    pub fn plan_frame(&mut self, frame: u64, needed: &[NeededTile], cap: usize) -> TilePlan {
        let mut stats = TileStats::default();
        let mut generate = Vec::new();
        let settings = self.settings;
        let key = |t: &NeededTile| (t.node, settings.fit(t.size));
        let root_size = needed.iter().find(|t| t.node == NodeId::ROOT).map(|t| key(t).1);
        let any_root = self.resident_sizes(NodeId::ROOT).next().is_some();
        let root_missing = root_size.map_or(!any_root, |s| !self.index.contains_key(&(NodeId::ROOT, s)));
        if root_missing && (cap > 0 || !any_root) {
            let size = root_size.unwrap_or(self.settings.min_tile);
            if let Some(slot) = self.place(NodeId::ROOT, size, frame, &mut stats) {
                generate.push((NodeId::ROOT, slot));
            }
        }
        let fresh_root = generate.first().map(|&(node, slot)| (node, slot.size));
        let mut missing: Vec<(NodeId, u32, f64)> = Vec::new();
        for t in needed {
            let (node, size) = key(t);
            if fresh_root == Some((node, size)) {
                continue;
            }
            if self.touch(node, size, frame) {
                stats.hits += 1;
            } else {
                missing.push((node, size, t.distance));
            }
        }
        missing.sort_by(|a, b| a.0.level.cmp(&b.0.level).then(a.2.total_cmp(&b.2)).then(a.0.cmp(&b.0)));
        let mut seen = HashSet::new();
        missing.retain(|m| seen.insert((m.0, m.1)));
        let budget = cap.saturating_sub(generate.len()).min(missing.len());
        for &(node, size, _) in &missing[budget..] {
            if let Some((source, source_size)) = self.fallback(node, size) {
                self.touch(source, source_size, frame);
            }
        }
        for &(node, size, _) in &missing[..budget] {
            if let Some(slot) = self.place(node, size, frame, &mut stats) {
                generate.push((node, slot));
            }
        }
        let mut draw = Vec::with_capacity(needed.len());
        for t in needed {
            let (node, size) = key(t);
            let source = if self.index.contains_key(&(node, size)) {
                Some((node, size))
            } else {
                stats.deferred += 1;
                self.fallback(node, size)
            };
            if let Some((source, source_size)) = source {
                self.touch(source, source_size, frame);
                let slot = self.slot(source, source_size);
                draw.push(DrawTile {
                    needed: node,
                    source,
                    slot,
                });
            }
        }
        (stats.visible, stats.generated) = (needed.len(), generate.len());
        stats.resident = self.index.len();
        let root_size = self.resident_sizes(NodeId::ROOT).last();
        TilePlan {
            generate,
            draw,
            stats,
            root: root_size.map(|s| self.slot(NodeId::ROOT, s)),
            border: self.settings.border,
        }
    }

    /// Resident tiles in all layers.
    pub fn resident(&self) -> usize {
        self.index.len()
    }

    /// GPU memory of all atlas layers at `bytes_per_texel`.
    pub fn memory_bytes(&self, bytes_per_texel: u64) -> u64 {
        let texels = u64::from(self.settings.size).pow(2) * u64::from(self.settings.layers());
        texels.saturating_mul(bytes_per_texel)
    }

    /// The sizes at which `node` is resident, smallest first.
    fn resident_sizes(&self, node: NodeId) -> impl Iterator<Item = u32> + '_ {
        let sizes = (0..self.slots.len()).map(|k| self.settings.min_tile << k);
        sizes.filter(move |&s| self.index.contains_key(&(node, s)))
    }

    /// Where the resident tile `(node, size)` lies (callers check residency).
    fn slot(&self, node: NodeId, size: u32) -> TileSlot {
        let (layer, index) = self.index.get(&(node, size)).copied().unwrap_or((0, 0));
        let per_row = (self.settings.size / size).max(1);
        let (x, y) = (index % per_row * size, index / per_row * size);
        TileSlot { layer, x, y, size }
    }

    /// Marks `(node, size)` used in `frame`; whether it is resident.
    fn touch(&mut self, node: NodeId, size: u32, frame: u64) -> bool {
        let Some(&(layer, index)) = self.index.get(&(node, size)) else {
            return false;
        };
        if let Some(Some(r)) = self.slots[layer as usize].get_mut(index as usize) {
            r.last_used = frame;
        }
        true
    }

    /// The tile a non-resident `(node, size)` is drawn from: the node at its
    /// largest other resident size, else the nearest resident ancestor.
    fn fallback(&self, node: NodeId, size: u32) -> Option<(NodeId, u32)> {
        let own = self.resident_sizes(node).filter(|&s| s != size).last();
        if let Some(s) = own {
            return Some((node, s));
        }
        std::iter::successors(node.parent(), NodeId::parent).find_map(|a| self.resident_sizes(a).last().map(|s| (a, s)))
    }

    /// Gives `(node, size)` a slot (the lowest free one, else that of the
    /// least recently used tile not used in `frame`), marked used in
    /// `frame`; `None` if every slot holds a tile used in `frame`.
    fn place(&mut self, node: NodeId, size: u32, frame: u64, stats: &mut TileStats) -> Option<TileSlot> {
        let layer = self.settings.layer_of(size)?;
        let last_root = self.resident_sizes(NodeId::ROOT).count() <= 1;
        let evictable = |r: Resident| r.last_used < frame && !(last_root && r.node == NodeId::ROOT);
        let slots = &mut self.slots[layer as usize];
        // `None` (a free slot) orders before every last use.
        let (index, old) = (slots.iter().enumerate())
            .filter(|(_, r)| r.map_or(true, evictable))
            .min_by_key(|(i, r)| (r.map(|r| r.last_used), *i))?;
        if let Some(old) = *old {
            self.index.remove(&(old.node, size));
            stats.evicted += 1;
        }
        slots[index] = Some(Resident { node, last_used: frame });
        self.index.insert((node, size), (layer, index as u32));
        Some(self.slot(node, size))
    }
}

/// One page-table cell: where the tile covering the cell lies. 32 bytes,
/// laid out like the std430 struct
/// `{ vec2 node_min; vec2 node_size; vec2 atlas_origin; float inner_texels; uint layer; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable, PartialEq)]
pub struct PageEntry {
    /// World corner (min x, min y) of the source node's rectangle, metres.
    pub node_min: [f32; 2],
    /// World size of the source node's rectangle, metres.
    pub node_size: [f32; 2],
    /// Texel coordinates in the layer of the inner region's corner (slot
    /// origin + border).
    pub atlas_origin: [f32; 2],
    /// Inner texels across the tile: `size − 2·border`.
    pub inner_texels: f32,
    /// Atlas layer of the tile.
    pub layer: u32,
}

impl PageEntry {
    /// The entry of the tile of `node` in `slot`.
    fn new(node: NodeId, slot: TileSlot, extent: DVec2, border: u32) -> PageEntry {
        let (min, max) = node.rect(extent);
        PageEntry {
            node_min: min.as_vec2().to_array(),
            node_size: (max - min).as_vec2().to_array(),
            atlas_origin: [(slot.x + border) as f32, (slot.y + border) as f32],
            inner_texels: slot.size.saturating_sub(2 * border) as f32,
            layer: slot.layer,
        }
    }
}

/// The page table: `(2^table_depth)²` cells over the rectangle, row-major
/// (cell `(i, j)` at index `j·2^table_depth + i`). Each cell holds the entry
/// of the draw whose needed node contains it; cells outside every needed node
/// (culled) hold the root tile's entry when one is resident, else zeros.
/// Errors when `table_depth` exceeds [`MAX_TABLE_DEPTH`] or is shallower than
/// the deepest needed level (each cell must lie in one needed node), or the
/// extent is not finite and positive.
pub fn page_table(plan: &TilePlan, extent: DVec2, table_depth: u32) -> Result<Vec<PageEntry>> {
    let deepest = plan.draw.iter().map(|d| d.needed.level).max().unwrap_or(0);
    let why = if table_depth > MAX_TABLE_DEPTH {
        format!("depth {table_depth} exceeds {MAX_TABLE_DEPTH}")
    } else if deepest > table_depth {
        format!("depth {table_depth} is shallower than the deepest needed level {deepest}")
    } else if !(extent.is_finite() && extent.x > 0.0 && extent.y > 0.0) {
        format!("terrain extent {extent} must be finite and positive")
    } else {
        String::new()
    };
    if !why.is_empty() {
        return Err(Error::invalid("page table", why));
    }
    let side = 1usize << table_depth;
    let root = |s| PageEntry::new(NodeId::ROOT, s, extent, plan.border);
    let fill = plan.root.map_or(PageEntry::zeroed(), root);
    let mut table = vec![fill; side * side];
    let mut draws: Vec<&DrawTile> = plan.draw.iter().collect();
    draws.sort_by_key(|d| d.needed.level);
    for d in draws {
        let cells = side >> d.needed.level;
        let (x0, y0) = (d.needed.x as usize * cells, d.needed.y as usize * cells);
        if x0 >= side || y0 >= side {
            continue;
        }
        let entry = PageEntry::new(d.source, d.slot, extent, plan.border);
        for row in table.chunks_exact_mut(side).skip(y0).take(cells) {
            row[x0..x0 + cells].fill(entry);
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::texturing::quadtree::{select_tiles, NodeBounds, View};

    const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

    fn needed_from(eye: DVec3) -> Vec<NeededTile> {
        let pixel_footprint = View::pixel_footprint_for(1.0, 1080);
        let view = View {
            eye,
            pixel_footprint,
            frustum: None,
        };
        let flat = |_| NodeBounds {
            z_min: 0.0,
            z_max: 100.0,
            geometric_error: 0.0,
        };
        select_tiles(EXTENT, &view, &QuadtreeSettings::default(), &flat).unwrap()
    }

    /// A needed tile whose distance grows with x + y.
    fn tile(level: u32, x: u32, y: u32, size: u32) -> NeededTile {
        let (node, distance) = (NodeId { level, x, y }, f64::from(x + y));
        NeededTile { node, size, distance }
    }

    fn atlas(size: u32, border: u32, min_tile: u32, max_tile: u32) -> Result<TileCache> {
        let mut settings = AtlasSettings {
            size,
            border,
            ..AtlasSettings::default()
        };
        (settings.min_tile, settings.max_tile) = (min_tile, max_tile);
        TileCache::new(settings)
    }

    fn keys(tiles: &[NeededTile]) -> HashSet<(NodeId, u32)> {
        tiles.iter().map(|t| (t.node, t.size)).collect()
    }

    #[test]
    fn identical_frames_hit_and_moving_eye_regenerates_only_changes() {
        let mut cache = atlas(8192, 4, 16, 512).unwrap();
        let a = needed_from(DVec3::new(1000.0, 1000.0, 300.0));
        let first = cache.plan_frame(1, &a, usize::MAX).stats;
        // The root is not needed but generated as the fallback of last resort.
        assert_eq!((first.hits, first.deferred, first.generated), (0, 0, a.len() + 1));
        let second = cache.plan_frame(2, &a, usize::MAX);
        assert_eq!((second.stats.hit_rate(), second.generate.len()), (1.0, 0));
        assert!(second.draw.len() == a.len() && second.draw.iter().all(|d| d.source == d.needed));
        let b = needed_from(DVec3::new(1100.0, 1000.0, 300.0));
        let moved = cache.plan_frame(3, &b, usize::MAX);
        let changed = &keys(&b) - &keys(&a);
        let generated = moved.generate.iter().map(|&(n, s)| (n, s.size)).collect();
        assert!(!changed.is_empty() && changed == generated);
        assert_eq!(moved.stats.hits + changed.len(), b.len());
        assert!(moved.stats.hit_rate() > 0.5, "{:?}", moved.stats);
    }

    #[test]
    fn cap_defers_to_resident_ancestor() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        // Cap 0 with nothing resident still generates the root.
        let first = cache.plan_frame(1, &[tile(0, 0, 0, 64)], 0);
        let root_slot = first.generate[0].1;
        assert_eq!(first.generate.len(), 1);
        assert_eq!(
            (root_slot.layer, root_slot.x, root_slot.y, root_slot.size),
            (2, 0, 0, 64)
        );
        let mut needed = vec![tile(1, 0, 0, 64), tile(1, 0, 1, 64), tile(1, 1, 1, 64)];
        let parent = NodeId { level: 1, x: 1, y: 0 };
        needed.extend(parent.children().map(|n| tile(2, n.x, n.y, 64)));
        let plan = cache.plan_frame(2, &needed, 3);
        let levels: Vec<u32> = plan.generate.iter().map(|g| g.0.level).collect();
        assert_eq!((levels, plan.stats.deferred), (vec![1, 1, 1], 4), "coarse first");
        let sources: HashSet<_> = plan.draw[3..].iter().map(|d| (d.source, d.slot)).collect();
        assert_eq!(sources, HashSet::from([(NodeId::ROOT, root_slot)]));
        // Next frame the deferred children are generated, nearest first.
        let next = cache.plan_frame(3, &needed, 3);
        let stats = next.stats;
        assert_eq!((stats.hits, stats.generated, stats.deferred), (3, 3, 1));
        assert_eq!(next.generate[0].0, NodeId { level: 2, x: 2, y: 0 });
    }

    #[test]
    fn lru_evicts_least_recently_used_unused_tile() {
        // 32-texel tiles get 4 slots in layer 1; the root lives in layer 0.
        let mut cache = atlas(64, 2, 16, 32).unwrap();
        let [a, b, c, d] = NodeId::ROOT.children().map(|n| tile(1, n.x, n.y, 32));
        let e = tile(2, 0, 0, 32);
        let b_slot = cache.plan_frame(1, &[a, b], 10).draw[1].slot;
        cache.plan_frame(2, &[c, d], 10);
        cache.plan_frame(3, &[a, c], 10);
        let plan = cache.plan_frame(4, &[e], 10);
        assert_eq!(plan.stats.evicted, 1);
        assert_eq!(plan.generate, [(e.node, b_slot)], "b was least recently used");
        // All four slots used this frame: the fifth tile is deferred, nothing evicted.
        let x = tile(2, 3, 3, 32);
        let plan = cache.plan_frame(5, &[a, c, d, e, x], 10);
        let s = plan.stats;
        assert_eq!((s.evicted, s.hits, s.deferred, s.resident), (0, 4, 1, 5));
        assert_eq!(plan.draw[4].source, d.node, "x falls back to its parent");
    }

    #[test]
    fn page_table_cells_map_to_nodes_and_atlas() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        let mut needed = vec![tile(1, 0, 0, 32), tile(1, 1, 0, 64)];
        needed.extend([tile(2, 0, 2, 16), tile(2, 1, 2, 16)]);
        let plan = cache.plan_frame(1, &needed, 10);
        assert!(page_table(&plan, EXTENT, 1).is_err());
        let table = page_table(&plan, EXTENT, 2).unwrap();
        assert_eq!((table.len(), std::mem::size_of::<PageEntry>()), (16, 32));
        let at = |i: usize, j: usize| table[j * 4 + i];
        let slot = plan.draw[1].slot;
        for (i, j) in [(2, 0), (3, 0), (2, 1), (3, 1)] {
            let e = at(i, j);
            assert_eq!((e.node_min, e.node_size), ([4000.0, 0.0], [4000.0, 2000.0]));
            assert_eq!(e.atlas_origin, [(slot.x + 4) as f32, (slot.y + 4) as f32]);
            assert_eq!((e.inner_texels, e.layer), (56.0, 2));
        }
        assert_eq!((at(1, 2).node_min, at(1, 2).inner_texels), ([2000.0, 2000.0], 8.0));
        // Cells of the culled nodes (1, 1, 1) and (2, ·, 3) hold the root.
        let root = PageEntry::new(NodeId::ROOT, plan.root.unwrap(), EXTENT, 4);
        assert_eq!((at(3, 3), at(0, 3), root.node_size), (root, root, [8000.0, 4000.0]));
    }

    #[test]
    fn settings_layers_and_memory() {
        let s = AtlasSettings::default();
        assert_eq!((s.layers(), s.layer_of(16), s.layer_of(512)), (6, Some(0), Some(5)));
        assert_eq!((s.layer_of(24), s.layer_of(1024)), (None, None));
        assert_eq!((s.slots_per_layer(256), s.slots_per_layer(16)), (16, 4096));
        assert_eq!(TileCache::new(s).unwrap().memory_bytes(4), 6 * 1024 * 1024 * 4);
        assert!(atlas(1000, 4, 16, 512).is_err() && atlas(1024, 4, 16, 2048).is_err());
        assert!(atlas(1024, 4, 1024, 512).is_err() && atlas(1024, 8, 16, 512).is_err());
        assert_eq!(TileStats::default().hit_rate(), 1.0);
    }
}
