//! Tile slots in texture atlases and their reuse from frame to frame
//! (dissertation §8.2).
//!
//! # Atlases
//!
//! Tiles live in atlas textures of `size × size` texels. Every texture
//! holds tiles of one size (border included), packed row-major into
//! `(size/tile)²` slots. Each tile size from `min_tile` to `max_tile` gets
//! its own number of textures ([`AtlasSettings::textures`]; by default most
//! for the aim size, which most tiles have, §8.2.4); textures are numbered
//! size by size, smallest first, and a size's slots run through its
//! textures in order.
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
//!    id, and the first tiles within the cap are generated; a frame that
//!    generates no root generates its first miss even when it alone exceeds
//!    the texel cap (a tile larger than the cap would never be generated
//!    otherwise), so every frame with misses and a tile cap ≥ 1 makes
//!    progress. The resident
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

use glam::DVec2;

use crate::error::Result;
pub use crate::texturing::atlas_settings::AtlasSettings;
#[cfg(test)]
pub use crate::texturing::atlas_settings::MAX_TILE_SIZES;
pub use crate::texturing::pacing::GpuTimeBudget;
use crate::texturing::quadtree::{NeededTile, NodeId};

/// Where a tile lies: atlas texture and texel origin of the tile (border
/// included) in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileSlot {
    /// Atlas texture (see the module documentation for the numbering).
    pub texture: u32,
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

/// How much one frame may generate: tiles and texels (border included),
/// and GPU time. The root and first-miss exceptions of the module
/// documentation apply, so one frame generates at most
/// `max(texels, largest tile²)` texels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GenerationBudget {
    pub tiles: usize,
    pub texels: u64,
    /// GPU time of generation per frame, measured from earlier frames
    /// ([`crate::texturing::pacing`]); [`TextureAtlas`] turns it into a
    /// lower texel cap before [`TileCache::plan_frame`], which reads only
    /// the counts. None: the counts alone, so which frame generates which
    /// tile does not depend on timings (deterministic frames).
    ///
    /// [`TextureAtlas`]: crate::texturing::generation::TextureAtlas
    pub gpu_time: Option<GpuTimeBudget>,
}

impl GenerationBudget {
    /// No limit.
    pub const UNLIMITED: GenerationBudget = GenerationBudget {
        tiles: usize::MAX,
        texels: u64::MAX,
        gpu_time: None,
    };
}

impl From<usize> for GenerationBudget {
    /// At most `tiles` tiles, any size, no time limit.
    fn from(tiles: usize) -> GenerationBudget {
        GenerationBudget {
            tiles,
            texels: u64::MAX,
            gpu_time: None,
        }
    }
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
        let sizes = (0..settings.sizes()).map(|k| settings.tile_size(k));
        let slots_of = |s| vec![None; (settings.slots_per_texture(s) * settings.textures_of(s)) as usize];
        let slots = sizes.map(slots_of).collect();
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

    /// Forgets the tiles whose texels (border included) reach into the
    /// world rectangle `[lo, hi]` of a terrain of `extent`: what they show
    /// there changed (the streamed detail window moved), so the frames
    /// after generate them again.
    pub fn forget_overlapping(&mut self, extent: DVec2, (lo, hi): (DVec2, DVec2)) {
        let border = f64::from(self.settings.border);
        for (k, slots) in self.slots.iter_mut().enumerate() {
            let size = self.settings.tile_size(k as u32);
            for slot in slots.iter_mut() {
                let Some(r) = *slot else { continue };
                let (a, b) = r.node.rect(extent);
                let margin = (b - a) * border / f64::from(size - 2 * self.settings.border);
                let (a, b) = (a - margin, b + margin);
                if a.x <= hi.x && lo.x <= b.x && a.y <= hi.y && lo.y <= b.y {
                    self.index.remove(&(r.node, size));
                    *slot = None;
                }
            }
        }
    }

    /// Plans one frame: `needed` from `select_tiles`; at most `cap` tiles
    /// (a count, or a [`GenerationBudget`]) are (re)generated, by the rules
    /// in the module documentation.
    pub fn plan_frame(&mut self, frame: u64, needed: &[NeededTile], cap: impl Into<GenerationBudget>) -> TilePlan {
        let GenerationBudget { tiles: cap, texels, .. } = cap.into();
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
        let mut texels_left = texels.saturating_sub(generate.iter().map(|g| u64::from(g.1.size).pow(2)).sum());
        let mut budget = 0;
        for &(_, size, _) in missing.iter().take(cap.saturating_sub(generate.len())) {
            texels_left = match texels_left.checked_sub(u64::from(size).pow(2)) {
                Some(rest) => rest,
                // A frame's first tile goes even over the texel budget.
                None if generate.is_empty() && budget == 0 => 0,
                None => break,
            };
            budget += 1;
        }
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

    /// GPU memory of all atlas textures at `bytes_per_texel`.
    #[cfg(test)]
    pub fn memory_bytes(&self, bytes_per_texel: u64) -> u64 {
        let textures = self.settings.texture_tile_sizes().len() as u64;
        let texels = u64::from(self.settings.size).pow(2) * textures;
        texels.saturating_mul(bytes_per_texel)
    }

    /// The sizes at which `node` is resident, smallest first.
    fn resident_sizes(&self, node: NodeId) -> impl Iterator<Item = u32> + '_ {
        let sizes = (0..self.slots.len()).map(|k| self.settings.min_tile << k);
        sizes.filter(move |&s| self.index.contains_key(&(node, s)))
    }

    /// Where the resident tile `(node, size)` lies (callers check residency).
    fn slot(&self, node: NodeId, size: u32) -> TileSlot {
        let (_, index) = self.index.get(&(node, size)).copied().unwrap_or((0, 0));
        let settings = &self.settings;
        let per_texture = settings.slots_per_texture(size).max(1);
        let texture = settings.first_texture(size).unwrap_or(0) + index / per_texture;
        let (local, per_row) = (index % per_texture, (settings.size / size).max(1));
        let (x, y) = (local % per_row * size, local / per_row * size);
        TileSlot { texture, x, y, size }
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
        let layer = self.settings.size_index(size)?;
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

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use super::*;
    use crate::texturing::quadtree::{select_tiles, NodeBounds, QuadtreeSettings};
    use crate::view::Footprint;

    const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

    fn needed_from(eye: DVec3) -> Vec<NeededTile> {
        let pixel_footprint = Footprint::pixel_footprint_for(1.0, 1080);
        let view = Footprint {
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
        // One texture per size, so slot counts are easy to reason about.
        let mut settings = AtlasSettings {
            size,
            border,
            textures: [1; MAX_TILE_SIZES],
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
        let mut cache = atlas(16384, 4, 16, 512).unwrap();
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
    fn forgetting_a_rectangle_regenerates_exactly_the_tiles_reaching_into_it() {
        let mut cache = atlas(16384, 4, 16, 512).unwrap();
        let a = needed_from(DVec3::new(1000.0, 1000.0, 300.0));
        cache.plan_frame(1, &a, usize::MAX);
        // A detail window's rectangle around the eye.
        let rect = (DVec2::new(900.0, 950.0), DVec2::new(1150.0, 1100.0));
        cache.forget_overlapping(EXTENT, rect);
        let again = cache.plan_frame(2, &a, usize::MAX);
        // The root, forgotten too, comes back as the fallback of last resort.
        let generated: HashSet<NodeId> = (again.generate.iter().map(|&(n, _)| n))
            .filter(|&n| n != NodeId::ROOT)
            .collect();
        let reaches = |t: &NeededTile| {
            let (lo, hi) = t.node.rect(EXTENT);
            // The border's 4 texels either side of the 8 fewer inner ones.
            let margin = (hi - lo) * 4.0 / f64::from(cache.settings.fit(t.size) - 8);
            let (lo, hi) = (lo - margin, hi + margin);
            lo.x <= rect.1.x && rect.0.x <= hi.x && lo.y <= rect.1.y && rect.0.y <= hi.y
        };
        let expected: HashSet<NodeId> = (a.iter().filter(|t| reaches(t)).map(|t| t.node))
            .filter(|&n| n != NodeId::ROOT)
            .collect();
        assert!(!expected.is_empty() && expected.len() < a.len());
        assert_eq!(generated, expected);
        let root_needed = a.iter().any(|t| t.node == NodeId::ROOT);
        assert_eq!(again.stats.hits, a.len() - expected.len() - usize::from(root_needed));
    }

    #[test]
    fn cap_defers_to_resident_ancestor() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        // Cap 0 with nothing resident still generates the root.
        let first = cache.plan_frame(1, &[tile(0, 0, 0, 64)], 0);
        let root_slot = first.generate[0].1;
        assert_eq!(first.generate.len(), 1);
        assert_eq!(
            (root_slot.texture, root_slot.x, root_slot.y, root_slot.size),
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
    fn texel_budget_defers_in_priority_order() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        cache.plan_frame(1, &[tile(0, 0, 0, 16)], 1);
        let needed = NodeId::ROOT.children().map(|n| tile(1, n.x, n.y, 64));
        let budget = GenerationBudget {
            tiles: 10,
            texels: 2 * 64 * 64 + 100,
            gpu_time: None,
        };
        let plan = cache.plan_frame(2, &needed, budget);
        assert_eq!((plan.stats.generated, plan.stats.deferred), (2, 2));
        assert_eq!(
            plan.generate.iter().map(|g| g.0).collect::<Vec<_>>(),
            [needed[0].node, needed[2].node],
            "nearest, then node id"
        );
        // A texel cap below one tile still generates one per frame.
        let tiny = GenerationBudget { texels: 100, ..budget };
        let plan = cache.plan_frame(3, &needed, tiny);
        assert_eq!((plan.stats.generated, plan.stats.deferred), (1, 1));
        assert_eq!(plan.generate[0].0, needed[1].node);
        // An unlimited budget takes the rest.
        let plan = cache.plan_frame(4, &needed, GenerationBudget::UNLIMITED);
        assert_eq!((plan.stats.generated, plan.stats.hits), (1, 3));
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
    fn slots_run_through_several_textures_of_a_size() {
        let mut settings = AtlasSettings {
            size: 64,
            border: 2,
            min_tile: 16,
            max_tile: 32,
            textures: [1, 2, 0, 0, 0, 0, 0, 0],
        };
        // 16-texel tiles: one texture of 16 slots; 32-texel tiles: two of 4.
        assert_eq!(settings.texture_tile_sizes(), [16, 32, 32]);
        let mut cache = TileCache::new(settings).unwrap();
        let needed: Vec<NeededTile> = (0..8).map(|i| tile(3, i, 0, 32)).collect();
        let plan = cache.plan_frame(1, &needed, 100);
        assert_eq!(plan.stats.deferred, 0);
        let slots: HashSet<(u32, u32, u32)> = plan.draw.iter().map(|d| (d.slot.texture, d.slot.x, d.slot.y)).collect();
        assert_eq!(slots.len(), 8, "distinct slots");
        assert!(slots.iter().all(|&(t, x, y)| (1..=2).contains(&t) && x < 64 && y < 64));
        settings.textures[1] = 0;
        assert!(TileCache::new(settings).is_err());
        settings.textures[1] = 65;
        assert!(TileCache::new(settings).is_err());
    }

    #[test]
    fn settings_layers_and_memory() {
        let s = AtlasSettings::default();
        assert_eq!((s.sizes(), s.size_index(16), s.size_index(512)), (6, Some(0), Some(5)));
        assert_eq!((s.size_index(24), s.size_index(1024)), (None, None));
        assert_eq!((s.slots_per_texture(256), s.slots_per_texture(16)), (16, 4096));
        // Aim 128: eight textures for 128², two for 64², four above.
        let textures = [16, 32, 64, 128, 256, 512].map(|t| s.textures_of(t));
        assert_eq!(textures, [1, 1, 2, 8, 4, 4]);
        let sizes = s.texture_tile_sizes();
        assert_eq!(
            (sizes.len(), sizes[3], sizes[4], sizes[11], sizes[19]),
            (20, 64, 128, 128, 512)
        );
        assert_eq!(
            (s.first_texture(16), s.first_texture(256), s.first_texture(8)),
            (Some(0), Some(12), None)
        );
        assert_eq!(TileCache::new(s).unwrap().memory_bytes(4), 20 * 1024 * 1024 * 4);
        assert!(atlas(1000, 4, 16, 512).is_err() && atlas(1024, 4, 16, 2048).is_err());
        assert!(atlas(1024, 4, 1024, 512).is_err() && atlas(1024, 8, 16, 512).is_err());
        assert_eq!(TileStats::default().hit_rate(), 1.0);
    }
}
