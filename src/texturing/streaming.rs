//! How the texture atlas streams (dissertation §8.2.4): quadtree
//! refinement, the atlas textures per tile size, sized from the views a
//! frame renders, and the per-frame generation budget.
//!
//! # Atlas size
//!
//! [`TextureStreaming::for_views`] gives every tile size
//! `views·base + pixels/pixels_per_tile` slots ([`SLOTS_PER_SIZE`]), the
//! pixels summed over the views. The constants come from the most
//! demanding view measured, a driver's view 2 m above the Jacksboro DEM
//! (near nodes at the deepest level, grazing ones squashed on screen: about
//! 390 pixels per tile at 640×360 against 2800 for oblique views), with half
//! again as much as a margin. Textures are 1024² (2048² or 4096² where more
//! than [`MAX_ATLAS_TEXTURES`] would be needed), and the whole atlas stays
//! within a memory limit ([`DEFAULT_ATLAS_BYTES`] or the caller's): above
//! it, sizes lose textures, each time the size that keeps the largest share
//! of its wanted slots without one. A view that needs more
//! than the atlas holds still settles: the selection is coarsened to fit
//! ([`crate::texturing::fit`]).

use crate::error::{Error, Result};
use crate::texturing::atlas::{AtlasSettings, GenerationBudget, GpuTimeBudget};
use crate::texturing::generation::MAX_DISPATCH_TEXELS;
use crate::texturing::quadtree::QuadtreeSettings;

/// Most atlas textures (`MAX_ATLAS_TEXTURES` in texture_atlas.glsl).
pub const MAX_ATLAS_TEXTURES: usize = 32;
/// Most views one atlas serves per frame.
pub const MAX_VIEWS: usize = 16;
/// Default limit of the atlas textures' memory (colour and normal).
pub const DEFAULT_ATLAS_BYTES: u64 = 1 << 30;
/// Slots per tile size, `(tile size, base per view, pixels per tile)`
/// (module documentation).
pub const SLOTS_PER_SIZE: [(u32, u64, u64); 5] = [
    (16, 64, 4000),
    (32, 120, 1540),
    (64, 96, 1150),
    (128, 96, 1150),
    (256, 10, 17700),
];
/// The largest tile budget of [`TextureStreaming::for_views`]'s quadtree
/// (aim 128²): [`TextureStreaming::max_tile_budget`], for argument parsers
/// that check the range before anything starts.
pub const MAX_TILE_BUDGET: u32 = (MAX_DISPATCH_TEXELS / (128 * 128)) as u32;
/// Default share of the frame's other GPU time tile generation may add.
pub const DEFAULT_FRAME_SHARE: f32 = 0.25;

/// How textures stream: quadtree refinement, atlas layout and the
/// per-frame generation budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureStreaming {
    pub quadtree: QuadtreeSettings,
    pub atlas: AtlasSettings,
    /// Most tiles, texels and GPU time generated per frame.
    pub budget: GenerationBudget,
    /// Copy the colour atlas textures to the host every frame (for tests
    /// and debugging: [`crate::renderer::Renderer::read_texture_atlas`]).
    pub readback: bool,
}

impl Default for TextureStreaming {
    /// [`TextureStreaming::for_image`] of 1280×720.
    fn default() -> Self {
        TextureStreaming::for_image(1280, 720)
    }
}

impl TextureStreaming {
    /// Streaming for one `width`×`height` view: [`TextureStreaming::for_views`].
    pub fn for_image(width: u32, height: u32) -> TextureStreaming {
        TextureStreaming::for_views(&[(width, height)])
    }

    /// Streaming for frames of `views` (width, height) served by one atlas
    /// within `DEFAULT_ATLAS_BYTES`: [`TextureStreaming::for_views_within`]
    /// (which cannot fail at that limit).
    pub fn for_views(views: &[(u32, u32)]) -> TextureStreaming {
        let atlas = atlas_for(views, DEFAULT_ATLAS_BYTES).unwrap_or_else(|_| minimal_atlas());
        TextureStreaming::with_atlas(atlas)
    }

    /// Streaming for frames of `views`: the quadtree aims at 128² tiles,
    /// 16² to 128², and only the finest nodes (level 12) get up to 256²
    /// (§8.2.4); the atlas sized from the views (module documentation) in
    /// at most `max_bytes`; at most 32 tiles of 128² generated per frame,
    /// and at most `DEFAULT_FRAME_SHARE` of the frame's GPU time. Errors
    /// when `max_bytes` is below [`TextureStreaming::min_atlas_bytes`].
    pub fn for_views_within(views: &[(u32, u32)], max_bytes: u64) -> Result<TextureStreaming> {
        Ok(TextureStreaming::with_atlas(atlas_for(views, max_bytes)?))
    }

    /// The smallest atlas: one 1024² texture per tile size.
    pub fn min_atlas_bytes() -> u64 {
        bytes_of(&minimal_atlas())
    }

    fn with_atlas(atlas: AtlasSettings) -> TextureStreaming {
        TextureStreaming {
            quadtree: quadtree(),
            atlas,
            budget: GenerationBudget {
                tiles: 32,
                texels: 32 * 128 * 128,
                gpu_time: Some(GpuTimeBudget::FrameShare(DEFAULT_FRAME_SHARE)),
            },
            readback: false,
        }
    }

    /// The most tiles of the aim size one frame may generate:
    /// `MAX_DISPATCH_TEXELS` over the aim size's texels.
    pub fn max_tile_budget(&self) -> u32 {
        let aim = u64::from(self.quadtree.aim_texels.next_power_of_two()).pow(2);
        (MAX_DISPATCH_TEXELS / aim).min(u64::from(u32::MAX)) as u32
    }

    /// At most `tiles` tiles and `tiles` aim-size tiles' texels per frame;
    /// errors (parameter `texturing.tile_budget`) unless `tiles` is in
    /// `1..=`[`TextureStreaming::max_tile_budget`].
    pub fn with_tile_budget(mut self, tiles: u32) -> Result<TextureStreaming> {
        let max = self.max_tile_budget();
        if !(1..=max).contains(&tiles) {
            return Err(Error::invalid(
                "texturing.tile_budget",
                format!("{tiles}; must be in 1..={max}"),
            ));
        }
        let aim = u64::from(self.quadtree.aim_texels.next_power_of_two()).pow(2);
        self.budget.tiles = tiles as usize;
        self.budget.texels = u64::from(tiles) * aim;
        Ok(self)
    }

    /// Bytes of the atlas textures (colour and normal, RGBA8).
    pub fn atlas_bytes(&self) -> u64 {
        bytes_of(&self.atlas)
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
        } else if self.budget.tiles == 0 || self.budget.texels == 0 {
            format!("budget {:?} cannot generate one tile", self.budget)
        } else if self.budget.gpu_time.is_some_and(|t| !t.is_valid()) {
            format!("GPU time budget {:?} must be finite and positive", self.budget.gpu_time)
        } else if self.scratch_texels() > MAX_DISPATCH_TEXELS {
            format!(
                "budget of {} texels per frame exceeds {MAX_DISPATCH_TEXELS}",
                self.budget.texels
            )
        } else {
            return Ok(());
        };
        Err(Error::invalid("texture streaming", why))
    }

    /// Texels the scratch buffer holds: the most one frame generates,
    /// `max(budget, largest tile²)` (the budget at most `tiles` of the
    /// largest; `crate::texturing::atlas`).
    pub fn scratch_texels(&self) -> u64 {
        let biggest = u64::from(self.atlas.max_tile).pow(2);
        let tiles = self.budget.tiles as u64;
        self.budget.texels.min(tiles.saturating_mul(biggest)).max(biggest)
    }
}

/// The quadtree of [`TextureStreaming::for_views_within`].
fn quadtree() -> QuadtreeSettings {
    let defaults = QuadtreeSettings::default();
    QuadtreeSettings {
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
    }
}

fn bytes_of(atlas: &AtlasSettings) -> u64 {
    atlas.texture_tile_sizes().len() as u64 * u64::from(atlas.size).pow(2) * 8
}

/// One 1024² texture per tile size of [`quadtree`].
fn minimal_atlas() -> AtlasSettings {
    AtlasSettings {
        size: 1024,
        textures: [1; 8],
        ..AtlasSettings::for_quadtree(&quadtree())
    }
}

/// Slots each tile size of `atlas` should have for `views`, one more than
/// the views need (the cache keeps a root tile, `fit.rs`).
fn wanted_slots(atlas: &AtlasSettings, views: &[(u32, u32)]) -> Vec<u64> {
    let pixels: u64 = views.iter().map(|&(w, h)| u64::from(w) * u64::from(h)).sum();
    let count = views.len().max(1) as u64;
    (0..atlas.sizes())
        .map(|k| {
            let tile = atlas.tile_size(k);
            let row = SLOTS_PER_SIZE.iter().find(|s| s.0 == tile);
            row.map_or(1, |&(_, base, per_tile)| count * base + pixels.div_ceil(per_tile)) + 1
        })
        .collect()
}

/// Texels of the wanted slots `atlas` lacks.
fn deficit(atlas: &AtlasSettings, wanted: &[u64]) -> u64 {
    (wanted.iter().enumerate())
        .map(|(k, &w)| {
            let tile = atlas.tile_size(k as u32);
            let slots = u64::from(atlas.slots_per_texture(tile)) * u64::from(atlas.textures_of(tile));
            w.saturating_sub(slots) * u64::from(tile).pow(2)
        })
        .sum()
}

/// The atlas for `views` within `max_bytes` (module documentation): of
/// 1024², 2048² and 4096² textures, the layout that lacks the fewest of the
/// wanted texels, then the smallest.
fn atlas_for(views: &[(u32, u32)], max_bytes: u64) -> Result<AtlasSettings> {
    let min = bytes_of(&minimal_atlas());
    if max_bytes < min {
        return Err(Error::invalid(
            "texturing.atlas_bytes",
            format!("{max_bytes} bytes; the atlas needs at least {min}"),
        ));
    }
    let wanted = wanted_slots(&minimal_atlas(), views);
    let mut best = minimal_atlas();
    for size in [1024, 2048, 4096] {
        let mut atlas = AtlasSettings {
            size,
            ..minimal_atlas()
        };
        for (k, &w) in wanted.iter().enumerate() {
            let per_texture = u64::from(atlas.slots_per_texture(atlas.tile_size(k as u32)).max(1));
            atlas.textures[k] = w.div_ceil(per_texture).clamp(1, 64) as u32;
        }
        // Within the limits: drop a texture from the size that keeps the
        // largest share of its wanted slots without it.
        while bytes_of(&atlas) > max_bytes || atlas.texture_tile_sizes().len() > MAX_ATLAS_TEXTURES {
            let share = |k: usize| {
                let per_texture = atlas.slots_per_texture(atlas.tile_size(k as u32));
                f64::from((atlas.textures[k] - 1) * per_texture) / wanted[k] as f64
            };
            let sizes = 0..atlas.sizes() as usize;
            match sizes
                .filter(|&k| atlas.textures[k] > 1)
                .max_by(|&a, &b| share(a).total_cmp(&share(b)))
            {
                Some(k) => atlas.textures[k] -= 1,
                None => break,
            }
        }
        let fits = bytes_of(&atlas) <= max_bytes;
        let better = (deficit(&atlas, &wanted), bytes_of(&atlas)) < (deficit(&best, &wanted), bytes_of(&best));
        if fits && better {
            best = atlas;
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atlas_grows_with_the_views() {
        let layout = |views: &[(u32, u32)]| {
            let s = TextureStreaming::for_views(views);
            s.validate().unwrap();
            let textures = [32, 64, 128, 256].map(|t| s.atlas.textures_of(t));
            (s.atlas.size, textures, s.atlas_bytes() >> 20)
        };
        // 640×360: 96 + 201 = 297 slots of 128² (64 per texture), 23 of 256².
        assert_eq!(layout(&[(640, 360)]), (1024, [1, 2, 5, 2], 88));
        assert_eq!(layout(&[(1280, 720)]), (1024, [1, 4, 15, 4], 200));
        // 1920×1080 needs more than 32 textures of 1024²: 2048² instead.
        assert_eq!(layout(&[(1920, 1080)]), (2048, [1, 2, 8, 3], 480));
        // Six views: the sum of their pixels plus six bases.
        let six = layout(&[(640, 360); 6]);
        assert_eq!((six.0, six.2), (2048, 448));
        // Within the default limit whatever the views.
        let many = layout(&[(3840, 2160); MAX_VIEWS]);
        assert!(many.2 << 20 <= DEFAULT_ATLAS_BYTES, "{many:?}");
        assert_eq!(
            many.1.iter().max(),
            Some(&many.1[2]),
            "the aim size keeps the most: {many:?}"
        );
        assert_eq!(TextureStreaming::default(), TextureStreaming::for_image(1280, 720));
    }

    #[test]
    fn memory_limit_and_tile_budget_are_checked() {
        let min = TextureStreaming::min_atlas_bytes();
        assert_eq!(min, 5 << 23, "five 1024² textures");
        assert!(TextureStreaming::for_views_within(&[(640, 360)], min - 1).is_err());
        let tight = TextureStreaming::for_views_within(&[(1920, 1080)], min).unwrap();
        assert_eq!(tight.atlas_bytes(), min);
        let s = TextureStreaming::for_image(640, 360);
        assert_eq!(s.max_tile_budget(), 255);
        assert_eq!(MAX_TILE_BUDGET, s.max_tile_budget());
        for tiles in [1, 2, 32, 128, 254, 255] {
            let b = s.with_tile_budget(tiles).unwrap();
            b.validate().unwrap();
            assert_eq!(
                (b.budget.tiles, b.budget.texels),
                (tiles as usize, u64::from(tiles) << 14)
            );
        }
        for tiles in [0, 256, u32::MAX] {
            let e = s.with_tile_budget(tiles).unwrap_err().to_string();
            assert!(e.contains("tile_budget") && e.contains("1..=255"), "{e}");
        }
        let mut bad = s;
        bad.budget.gpu_time = Some(GpuTimeBudget::FrameShare(-1.0));
        assert!(bad.validate().is_err());
    }
}
