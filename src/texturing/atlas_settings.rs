//! The layout of the texture atlas (dissertation §8.2; the rules are in
//! [`super::atlas`]'s documentation, "Atlases"): the texture size, the range
//! of tile sizes and how many textures each tile size gets.

use crate::error::{Error, Result};
use crate::texturing::quadtree::QuadtreeSettings;

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
    /// Textures per tile size, `textures[k]` for tiles of `min_tile·2^k`
    /// (1..=64 for every size in the range).
    pub textures: [u32; MAX_TILE_SIZES],
}

/// Most distinct tile sizes (16² to 2048²).
pub const MAX_TILE_SIZES: usize = 8;

impl Default for AtlasSettings {
    fn default() -> Self {
        AtlasSettings {
            size: 1024,
            border: 4,
            min_tile: 16,
            max_tile: 512,
            textures: AtlasSettings::textures_around(16, 128),
        }
    }
}

impl AtlasSettings {
    /// Atlases of 1024² texels (larger if `max_tile` is) for the tiles of
    /// `quadtree`.
    pub fn for_quadtree(quadtree: &QuadtreeSettings) -> AtlasSettings {
        let aim = quadtree.aim_texels.next_power_of_two();
        AtlasSettings {
            size: quadtree.max_tile.max(1024),
            border: quadtree.border,
            min_tile: quadtree.min_tile,
            max_tile: quadtree.max_tile,
            textures: AtlasSettings::textures_around(quadtree.min_tile, aim),
        }
    }

    /// Texture counts for a quadtree aiming at `aim_tile` (§8.2.4: medium
    /// tiles of about 128² are the most frequent): eight textures for the
    /// aim size, two for half of it, four for each larger size (only the
    /// finest nodes near the viewer get those), one for the rest.
    pub fn textures_around(min_tile: u32, aim_tile: u32) -> [u32; MAX_TILE_SIZES] {
        std::array::from_fn(|k| {
            let size = u64::from(min_tile) << k;
            match size.cmp(&u64::from(aim_tile)) {
                std::cmp::Ordering::Equal => 8,
                std::cmp::Ordering::Greater => 4,
                std::cmp::Ordering::Less if 2 * size == u64::from(aim_tile) => 2,
                std::cmp::Ordering::Less => 1,
            }
        })
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
        } else if self.sizes() as usize > MAX_TILE_SIZES {
            format!("{} tile sizes exceed {MAX_TILE_SIZES}", self.sizes())
        } else if let Some(k) = (0..self.sizes() as usize).find(|&k| !(1..=64).contains(&self.textures[k])) {
            format!(
                "{} textures for {}² tiles; must be in 1..=64",
                self.textures[k],
                self.tile_size(k as u32)
            )
        } else {
            return Ok(());
        };
        Err(Error::invalid("texture atlas settings", why))
    }

    /// Number of tile sizes from `min_tile` to `max_tile`.
    pub fn sizes(&self) -> u32 {
        let (min, max) = (self.min_tile.trailing_zeros(), self.max_tile.trailing_zeros());
        max.saturating_sub(min) + 1
    }

    /// The tile size of size index `k` (0: `min_tile`).
    pub fn tile_size(&self, k: u32) -> u32 {
        self.min_tile << k
    }

    /// The size index of `tile_size`, `None` for a size not in the atlas.
    pub fn size_index(&self, tile_size: u32) -> Option<u32> {
        let fits = tile_size.is_power_of_two() && (self.min_tile..=self.max_tile).contains(&tile_size);
        fits.then(|| tile_size.trailing_zeros() - self.min_tile.trailing_zeros())
    }

    /// Slots of one texture for tiles of `tile_size`, 0 for a size not in the atlas.
    pub fn slots_per_texture(&self, tile_size: u32) -> u32 {
        match self.size_index(tile_size) {
            Some(_) => (self.size / tile_size).pow(2),
            None => 0,
        }
    }

    /// Textures holding tiles of `tile_size`, 0 for a size not in the atlas.
    pub fn textures_of(&self, tile_size: u32) -> u32 {
        let k = self.size_index(tile_size);
        k.and_then(|k| self.textures.get(k as usize)).copied().unwrap_or(0)
    }

    /// Index of the first texture of `tile_size`, `None` for a size not in the atlas.
    pub fn first_texture(&self, tile_size: u32) -> Option<u32> {
        let k = self.size_index(tile_size)?;
        Some((0..k).map(|j| self.textures_of(self.tile_size(j))).sum())
    }

    /// All atlas textures: `(tile size)` of each, in texture order.
    pub fn texture_tile_sizes(&self) -> Vec<u32> {
        let sizes = (0..self.sizes()).map(|k| self.tile_size(k));
        sizes
            .flat_map(|s| std::iter::repeat(s).take(self.textures_of(s) as usize))
            .collect()
    }

    /// `tile_size` clamped to the atlas's range and rounded up to a power of two.
    pub(crate) fn fit(&self, tile_size: u32) -> u32 {
        tile_size.clamp(self.min_tile, self.max_tile).next_power_of_two()
    }
}
