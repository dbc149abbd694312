//! The per-frame indirection from world position to atlas tile (dissertation
//! §8.2: the terrain mesh and the texture tiles stay independent). The
//! needed nodes of a frame partition the visible part of the terrain
//! rectangle; the page table is the quadtree down to them, flattened into
//! one buffer the fragment shader walks from the root
//! (`glsl/include/texture_atlas.glsl`): at most `max_depth` steps, each one
//! 16-byte read.
//!
//! # Buffer layout (`uvec4` words)
//!
//! * word 0: header `(root ref, fallback ref, first entry word, node count)`;
//! * words `1 ..= node count`: inner nodes, four child refs each, child
//!   `cy·2 + cx` for the quadrant `(cx, cy)` (x east, y north);
//! * then the entries, two words each ([`PageEntry`]).
//!
//! A ref is a node index, [`LEAF`]` | entry index`, or [`NONE`] (a culled
//! region: the fallback, the root tile, is used).

use bytemuck::{Pod, Zeroable};
use glam::DVec2;

use crate::error::{Error, Result};
use crate::texturing::atlas::{DrawTile, TilePlan, TileSlot};
use crate::texturing::quadtree::NodeId;

/// Ref bit of a leaf: the low bits index the entries.
pub const LEAF: u32 = 0x8000_0000;
/// Ref of a region without tile.
pub const NONE: u32 = 0xffff_ffff;
/// Deepest node the shader's walk reaches (`MAX_PAGE_DEPTH` in the GLSL).
pub const MAX_PAGE_DEPTH: u32 = 16;

/// Where the tile a region is drawn from lies. 32 bytes, laid out like the
/// std430 struct `{ vec2 node_min; vec2 node_size; vec2 atlas_origin; float
/// inner_texels; uint texture; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PageEntry {
    /// World corner (min x, min y) of the source node's rectangle, metres.
    pub node_min: [f32; 2],
    /// World size of the source node's rectangle, metres.
    pub node_size: [f32; 2],
    /// Texel coordinates in the texture of the inner region's corner (slot
    /// origin + border).
    pub atlas_origin: [f32; 2],
    /// Inner texels across the tile: `size − 2·border`.
    pub inner_texels: f32,
    /// Atlas texture of the tile.
    pub texture: u32,
}

impl PageEntry {
    /// The entry of the tile of `node` in `slot`.
    pub fn new(node: NodeId, slot: TileSlot, extent: DVec2, border: u32) -> PageEntry {
        let (min, max) = node.rect(extent);
        PageEntry {
            node_min: min.as_vec2().to_array(),
            node_size: (max - min).as_vec2().to_array(),
            atlas_origin: [(slot.x + border) as f32, (slot.y + border) as f32],
            inner_texels: slot.size.saturating_sub(2 * border) as f32,
            texture: slot.texture,
        }
    }

    /// Texel coordinates (in the atlas texture) of world `xy`.
    pub fn texel(&self, xy: DVec2) -> DVec2 {
        let (min, size) = (
            DVec2::from(self.node_min.map(f64::from)),
            DVec2::from(self.node_size.map(f64::from)),
        );
        DVec2::from(self.atlas_origin.map(f64::from)) + (xy - min) / size * f64::from(self.inner_texels)
    }
}

/// Where a ref is stored: the root ref, or child `.1` of inner node `.0`.
#[derive(Clone, Copy)]
enum RefSlot {
    Root,
    Child(u32, usize),
}

/// The page table of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PageTable {
    /// Ref of the root.
    pub root: u32,
    /// Ref used for culled regions: the root tile, or [`NONE`].
    pub fallback: u32,
    /// Inner nodes.
    pub nodes: Vec<[u32; 4]>,
    /// Leaf entries.
    pub entries: Vec<PageEntry>,
}

impl PageTable {
    /// Builds the table of `plan` over the rectangle `[0, extent]`. Errors
    /// when a needed node is deeper than [`MAX_PAGE_DEPTH`], lies outside the
    /// tree, or overlaps another.
    pub fn build(plan: &TilePlan, extent: DVec2) -> Result<PageTable> {
        let mut table = PageTable {
            root: NONE,
            fallback: NONE,
            ..PageTable::default()
        };
        if let Some(root) = plan.root {
            table
                .entries
                .push(PageEntry::new(NodeId::ROOT, root, extent, plan.border));
            table.fallback = LEAF;
        }
        for d in &plan.draw {
            table.insert(d, extent, plan.border)?;
        }
        Ok(table)
    }

    /// Words of the table of a plan drawing `needed` nodes (with a root
    /// tile): the header, one per inner node (every proper ancestor of a
    /// needed node), two per entry.
    pub fn words_for(needed: impl Iterator<Item = NodeId>) -> usize {
        let mut inner = std::collections::HashSet::new();
        let mut entries = 1;
        for node in needed {
            entries += 1;
            let mut up = node.parent();
            while let Some(n) = up.filter(|n| inner.insert(*n)) {
                up = n.parent();
            }
        }
        1 + inner.len() + 2 * entries
    }

    fn insert(&mut self, d: &DrawTile, extent: DVec2, border: u32) -> Result<()> {
        let node = d.needed;
        let side = 1u64.checked_shl(node.level).unwrap_or(0);
        let why = if node.level > MAX_PAGE_DEPTH {
            format!("node {node:?} is deeper than {MAX_PAGE_DEPTH}")
        } else if u64::from(node.x) >= side || u64::from(node.y) >= side {
            format!("node {node:?} lies outside the tree")
        } else {
            String::new()
        };
        if !why.is_empty() {
            return Err(Error::invalid("page table", why));
        }
        let overlap = || Error::invalid("page table", format!("node {node:?} overlaps another needed node"));
        // One descent from the root, creating inner nodes down to the
        // needed node's parent; `slot` is where the current ref is stored.
        let mut slot = RefSlot::Root;
        for level in 0..node.level {
            let index = match self.get(slot) {
                NONE => {
                    let index = self.nodes.len() as u32;
                    self.nodes.push([NONE; 4]);
                    self.set(slot, index);
                    index
                }
                r if r & LEAF != 0 => return Err(overlap()),
                r => r,
            };
            let shift = node.level - level - 1;
            let child = ((node.y >> shift) & 1) * 2 + ((node.x >> shift) & 1);
            slot = RefSlot::Child(index, child as usize);
        }
        if self.get(slot) != NONE {
            return Err(overlap());
        }
        self.set(slot, LEAF | self.entries.len() as u32);
        self.entries.push(PageEntry::new(d.source, d.slot, extent, border));
        Ok(())
    }

    fn get(&self, slot: RefSlot) -> u32 {
        match slot {
            RefSlot::Root => self.root,
            RefSlot::Child(node, child) => self.nodes[node as usize][child],
        }
    }

    fn set(&mut self, slot: RefSlot, value: u32) {
        match slot {
            RefSlot::Root => self.root = value,
            RefSlot::Child(node, child) => self.nodes[node as usize][child] = value,
        }
    }

    /// The entry covering world `xy` (the CPU twin of the shader's walk):
    /// the leaf's, else the fallback's; `None` without either.
    pub fn lookup(&self, xy: DVec2, extent: DVec2) -> Option<&PageEntry> {
        let mut uv = (xy / extent).clamp(DVec2::ZERO, DVec2::ONE);
        let mut r = self.root;
        for _ in 0..=MAX_PAGE_DEPTH {
            if r == NONE || r & LEAF != 0 {
                break;
            }
            uv *= 2.0;
            let c = uv.floor().clamp(DVec2::ZERO, DVec2::ONE);
            uv -= c;
            r = self.nodes[r as usize][(c.y * 2.0 + c.x) as usize];
        }
        let r = if r == NONE || r & LEAF == 0 { self.fallback } else { r };
        (r != NONE).then(|| &self.entries[(r & !LEAF) as usize])
    }

    /// The buffer the shader reads (module documentation), in `uvec4` words.
    pub fn words(&self) -> Vec<[u32; 4]> {
        let first_entry = 1 + self.nodes.len() as u32;
        let mut words = Vec::with_capacity(first_entry as usize + 2 * self.entries.len());
        words.push([self.root, self.fallback, first_entry, self.nodes.len() as u32]);
        words.extend_from_slice(&self.nodes);
        words.extend(
            self.entries
                .iter()
                .flat_map(|e| bytemuck::cast::<PageEntry, [[u32; 4]; 2]>(*e)),
        );
        words
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texturing::atlas::{AtlasSettings, TileCache};
    use crate::texturing::quadtree::NeededTile;

    const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

    fn tile(level: u32, x: u32, y: u32, size: u32) -> NeededTile {
        let (node, distance) = (NodeId { level, x, y }, f64::from(x + y));
        NeededTile { node, size, distance }
    }

    #[test]
    fn lookup_finds_the_needed_node_or_the_root() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        // Level-1 quadrant (1, 0) whole, quadrant (0, 0) whole, two level-2
        // nodes of quadrant (0, 1); the rest culled.
        let mut needed = vec![tile(1, 0, 0, 32), tile(1, 1, 0, 64)];
        needed.extend([tile(2, 0, 2, 16), tile(2, 1, 2, 16)]);
        let plan = cache.plan_frame(1, &needed, 10);
        let table = PageTable::build(&plan, EXTENT).unwrap();
        assert_eq!((table.nodes.len(), table.entries.len()), (2, 5));
        let slot = plan.draw[1].slot;
        let e = table.lookup(DVec2::new(6000.0, 1000.0), EXTENT).unwrap();
        assert_eq!((e.node_min, e.node_size), ([4000.0, 0.0], [4000.0, 2000.0]));
        assert_eq!(e.atlas_origin, [(slot.x + 4) as f32, (slot.y + 4) as f32]);
        assert_eq!((e.inner_texels, e.texture), (56.0, 2));
        let e = table.lookup(DVec2::new(2500.0, 2500.0), EXTENT).unwrap();
        assert_eq!((e.node_min, e.inner_texels), ([2000.0, 2000.0], 8.0));
        // Culled: node (1, 1, 1) and the level-2 nodes (·, 3).
        let root = PageEntry::new(NodeId::ROOT, plan.root.unwrap(), EXTENT, 4);
        for xy in [(7000.0, 3000.0), (500.0, 3500.0)] {
            assert_eq!(table.lookup(DVec2::from(xy), EXTENT), Some(&root));
        }
        // Edges clamp into the rectangle.
        assert_eq!(
            table.lookup(DVec2::new(8000.0, 0.0), EXTENT).unwrap().node_min,
            [4000.0, 0.0]
        );
        // The texel of the node's corner is the inner origin.
        assert_eq!(
            e.texel(DVec2::new(2000.0, 2000.0)),
            DVec2::from(e.atlas_origin.map(f64::from))
        );
    }

    #[test]
    fn words_hold_header_nodes_and_entries() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        let plan = cache.plan_frame(1, &[tile(1, 0, 0, 32), tile(1, 1, 1, 32)], 10);
        let table = PageTable::build(&plan, EXTENT).unwrap();
        let words = table.words();
        assert_eq!(PageTable::words_for(plan.draw.iter().map(|d| d.needed)), words.len());
        assert_eq!(words[0], [0, LEAF, 2, 1]);
        assert_eq!(words[1], [LEAF | 1, NONE, NONE, LEAF | 2]);
        assert_eq!(words.len(), 2 + 2 * 3);
        let e: PageEntry = bytemuck::cast([words[4], words[5]]);
        assert_eq!(e, table.entries[1]);
    }

    #[test]
    fn overlapping_or_out_of_tree_nodes_are_errors() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        let plan = cache.plan_frame(1, &[tile(1, 0, 0, 32), tile(2, 0, 0, 32)], 10);
        assert!(PageTable::build(&plan, EXTENT).is_err());
        let plan = cache.plan_frame(2, &[tile(1, 2, 0, 32)], 10);
        assert!(PageTable::build(&plan, EXTENT).is_err());
        // The root alone is a leaf at the root ref.
        let plan = cache.plan_frame(3, &[tile(0, 0, 0, 16)], 10);
        let table = PageTable::build(&plan, EXTENT).unwrap();
        assert_eq!((table.root, table.nodes.len()), (LEAF | 1, 0));
    }
}
