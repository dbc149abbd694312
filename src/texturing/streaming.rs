//! How the texture atlas streams (dissertation §8.2.4): quadtree
//! refinement, the atlas textures per tile size, sized from the output
//! image, and the per-frame generation budget.

use crate::error::{Error, Result};
use crate::texturing::atlas::{AtlasSettings, GenerationBudget};
use crate::texturing::generation::MAX_DISPATCH_TEXELS;
use crate::texturing::quadtree::QuadtreeSettings;

/// Most atlas textures (`MAX_ATLAS_TEXTURES` in texture_atlas.glsl).
pub const MAX_ATLAS_TEXTURES: usize = 32;
/// How textures stream: quadtree refinement, atlas layout and the
/// per-frame generation budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureStreaming {
    pub quadtree: QuadtreeSettings,
    pub atlas: AtlasSettings,
    /// Most tiles and texels generated per frame.
    pub budget: GenerationBudget,
    /// Copy the colour atlas textures to the host every frame (for tests
    /// and debugging: [`crate::renderer::Renderer::read_texture_atlas`]).
    pub readback: bool,
}

/// Screen pixels per visible tile: views of the default scene and of the
/// Jacksboro DEM at 1280×720 need about 330 tiles, nearly all of the aim
/// size (a node stops splitting once it needs ≤ 120 texels, so its tile
/// needs 60–120: 128²); grazing views squash tiles on screen.
pub const PIXELS_PER_TILE: u64 = 2800;

impl Default for TextureStreaming {
    /// [`TextureStreaming::for_image`] of 1280×720.
    fn default() -> Self {
        TextureStreaming::for_image(1280, 720)
    }
}

impl TextureStreaming {
    /// Streaming for `width`×`height` images: the quadtree aims at 128²
    /// tiles, 16² to 128², and only the finest nodes (level 12) get up to
    /// 256² (§8.2.4); the atlas holds twice the tiles a view needs
    /// ([`PIXELS_PER_TILE`]) of the aim size, in 1024² textures (2048²
    /// above what [`MAX_ATLAS_TEXTURES`] allows), one texture for each
    /// smaller size and four for 256²; at most 32 tiles generated per frame.
    pub fn for_image(width: u32, height: u32) -> TextureStreaming {
        let defaults = QuadtreeSettings::default();
        let quadtree = QuadtreeSettings {
            // The geometric error (z_max − z_min)/2 of HeightBounds, in
            // pixels, against half the aim: a node also splits while its
            // height range needs more texels than the aim, so steep nodes,
            // whose surface is larger than their plan, get finer tiles.
            pixel_error: defaults.aim_texels as f32 / 2.0,
            // Nodes down to 1/4096 of the terrain (2.5 m on the default
            // 10 km scene: 2 cm texels in 128² tiles); f32 world
            // coordinates keep well under a texel at that depth.
            max_tile: 256,
            max_depth: 12,
            ..defaults
        };
        let mut atlas = AtlasSettings::for_quadtree(&quadtree);
        let aim = quadtree.aim_texels.next_power_of_two();
        let wanted = 2 * (u64::from(width) * u64::from(height)).div_ceil(PIXELS_PER_TILE);
        for size in [1024, 2048] {
            atlas.size = size;
            atlas.textures = std::array::from_fn(|k| if atlas.tile_size(k as u32) > aim { 4 } else { 1 });
            let per_texture = u64::from(atlas.slots_per_texture(aim).max(1));
            if let Some(k) = atlas.size_index(aim) {
                atlas.textures[k as usize] = wanted.div_ceil(per_texture).clamp(2, 64) as u32;
            }
            if atlas.texture_tile_sizes().len() <= MAX_ATLAS_TEXTURES {
                break;
            }
        }
        TextureStreaming {
            quadtree,
            atlas,
            budget: GenerationBudget {
                tiles: 32,
                texels: 32 * 128 * 128,
            },
            readback: false,
        }
    }

    /// Streaming for views of the sizes `sizes` rendered together: the
    /// atlas holds the tiles of all of them (one image of their total pixels).
    pub fn for_views(sizes: &[(u32, u32)]) -> TextureStreaming {
        let pixels: u64 = sizes.iter().map(|&(w, h)| u64::from(w) * u64::from(h)).sum();
        TextureStreaming::for_image(pixels.min(u64::from(u32::MAX)) as u32, 1)
    }

    /// Bytes of the atlas textures (colour and normal, RGBA8).
    pub fn atlas_bytes(&self) -> u64 {
        let textures = self.atlas.texture_tile_sizes().len() as u64;
        textures * u64::from(self.atlas.size).pow(2) * 8
    }

    /// Checks the settings and that the budget fits a scratch buffer.
    pub fn validate(&self) -> Result<()> {
        self.quadtree.validate()?;
        self.atlas.validate()?;
        let textures = self.atlas.texture_tile_sizes().len();
        let why = if self.atlas.border != self.quadtree.border
            || self.atlas.min_tile != self.quadtree.min_tile
            || self.atlas.max_tile != self.quadtree.max_tile
        {
            "atlas and quadtree disagree on border or tile sizes".to_string()
        } else if textures > MAX_ATLAS_TEXTURES {
            format!("{textures} atlas textures exceed {MAX_ATLAS_TEXTURES}")
        } else if self.budget.tiles == 0 || self.budget.texels < u64::from(self.atlas.min_tile).pow(2) {
            format!("budget {:?} cannot generate one tile", self.budget)
        } else if self.scratch_texels() > MAX_DISPATCH_TEXELS {
            format!(
                "budget of {} texels per frame exceeds {MAX_DISPATCH_TEXELS} with the largest tile",
                self.budget.texels
            )
        } else {
            return Ok(());
        };
        Err(Error::invalid("texture streaming", why))
    }

    /// Texels the scratch buffer holds: the budget, plus the largest tile
    /// for the root exception (`crate::texturing::atlas`).
    pub fn scratch_texels(&self) -> u64 {
        let tiles = (self.budget.tiles as u64).saturating_add(1);
        let biggest = u64::from(self.atlas.max_tile).pow(2);
        self.budget
            .texels
            .min(tiles.saturating_mul(biggest))
            .saturating_add(biggest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atlas_grows_with_the_image() {
        let textures_of_128 = |w, h| {
            let s = TextureStreaming::for_image(w, h);
            s.validate().unwrap();
            (
                s.atlas.size,
                s.atlas.textures_of(128),
                s.atlas.textures_of(256),
                s.atlas_bytes() >> 20,
            )
        };
        // 2·⌈pixels/2800⌉ tiles of 128², 64 per 1024² texture.
        assert_eq!(textures_of_128(640, 360), (1024, 3, 4, 80));
        assert_eq!(textures_of_128(1280, 720), (1024, 11, 4, 144));
        assert_eq!(textures_of_128(1920, 1080), (1024, 24, 4, 248));
        // 4K needs more than 32 textures of 1024²: 2048² instead.
        assert_eq!(textures_of_128(3840, 2160), (2048, 24, 4, 992));
        assert_eq!(TextureStreaming::default(), TextureStreaming::for_image(1280, 720));
    }
}
