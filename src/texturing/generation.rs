//! Tile generation on the GPU (dissertation §8.2.2–8.2.4, Fig. 8.3–8.4;
//! `ALGORITHMS.md` §4 items 3–4), as render-graph passes over **all** dirty
//! tiles of a frame at once:
//!
//! 1. CPU, in [`TextureAtlas`]'s `prepare` (before recording): the quadtree
//!    picks the nodes all the frame's views need, one partition of what any
//!    of them sees ([`select_tiles_for_views`]), coarsened where it would not
//!    fit the atlas ([`fit_to_atlas`]); the tile cache plans what to
//!    generate within the [`GenerationBudget`] (its GPU time turned into
//!    texels by the [`GenerationPacer`]) and what to draw from where
//!    ([`TileCache::plan_frame`]), and one page table for all views is built
//!    ([`PageTable`]). The dirty tiles become [`TileJob`]s: one thread per
//!    texel, border included, of all of them.
//! 2. `texturing.upsample`: the base surface (the height field as a cubic
//!    B-spline) at every texel: height and slope (`glsl/texturing/upsample.comp`).
//! 3. `texturing.layer<i>.<name>`: one pass per layer in depth-first order
//!    (`glsl/texturing/layer.comp`): coverage per tree level, colour blend,
//!    displaced height passed on to the next layer; the per-texel state
//!    lives in a scratch buffer.
//! 4. `texturing.finish`: colour (sRGB-encoded) and the normal of the
//!    layers' displacement into the atlas textures
//!    (`glsl/texturing/finish.comp`).
//!
//! `terrain.draw` then samples the atlas through the page table.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DVec2;

use crate::error::{Error, Result};
use crate::graph::{BufferInfo, ImageId, RenderGraph, UploadRegion};
use crate::io::heightmap::HeightField;
use crate::profile::FrameProfile;
use crate::surface::gpu_layout::{DetailPush, LayerTable};
use crate::surface::input_maps::InputMaps;
use crate::surface::layers::LayerTree;
#[cfg(doc)]
use crate::texturing::atlas::GenerationBudget;
use crate::texturing::atlas::{TileCache, TilePlan};
use crate::texturing::fit::{select_to_fit, Coarsening};
use crate::texturing::pacing::GenerationPacer;
#[cfg(test)]
use crate::texturing::pacing::GpuTimeBudget;
use crate::texturing::page_table::PageTable;
use crate::texturing::passes::{add_atlas_readback, base_push, GenerationPasses};
use crate::texturing::quadtree::{HeightBounds, NeededTile, NodeId};
pub use crate::texturing::stats::TextureFrameStats;
pub use crate::texturing::streaming::{TextureStreaming, MAX_VIEWS};
use crate::view::{Footprint, Frame, FrameContext, Provides, Technique, View};
use crate::vulkan::{Buffer, Context, Format, Image, ImageDesc, ImageUsageFlags, MemoryLocation};

/// Bytes of one texel's state in the scratch buffer (`TexelState`).
pub const TEXEL_STATE_BYTES: u64 = 32;
/// Capacity of the per-frame page-table buffer in 16-byte words.
pub const PAGE_TABLE_WORDS: usize = 1 << 16;
/// Texels per workgroup of the generation passes.
pub(crate) const GROUP: u64 = 64;
/// Most texels one frame generates: one-dimensional dispatches of 65 535 groups.
pub const MAX_DISPATCH_TEXELS: u64 = 65_535 * GROUP;

/// One dirty tile (`TileJob` in glsl/include/texture_tiles.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct TileJob {
    /// xy of texel (0, 0)'s centre, texel spacing x, y (metres).
    pub world: [f32; 4],
    /// First scratch texel, tile size (border included), slot x, slot y.
    pub tile: [u32; 4],
    /// Colour and normal textures (storage handles), 0, 0. In the
    /// prepared [`TextureFrame`] x holds the texture's index instead:
    /// `texturing.finish`, which declares the textures, puts in the handles.
    pub images: [u32; 4],
}

/// World position of texel `(i, j)` (border included) of the tile of
/// `node` with `size` texels and `border`: texel centres, the inner
/// `size − 2·border` texels covering the node exactly.
pub fn texel_world(node: NodeId, size: u32, border: u32, extent: DVec2, (i, j): (u32, u32)) -> DVec2 {
    let (min, max) = node.rect(extent);
    let spacing = (max - min) / f64::from(size - 2 * border);
    min + (DVec2::new(f64::from(i), f64::from(j)) - f64::from(border) + 0.5) * spacing
}

/// The jobs of `plan.generate`, texels numbered tile after tile, and the
/// texel count; `images(texture)` gives the colour and normal storage
/// handles of an atlas texture.
pub fn tile_jobs(plan: &TilePlan, extent: DVec2, images: &dyn Fn(u32) -> [u32; 2]) -> (Vec<TileJob>, u64) {
    let mut texels = 0u64;
    let jobs = plan
        .generate
        .iter()
        .map(|&(node, slot)| {
            let origin = texel_world(node, slot.size, plan.border, extent, (0, 0));
            let (min, max) = node.rect(extent);
            let spacing = (max - min) / f64::from(slot.size - 2 * plan.border);
            let [color, normal] = images(slot.texture);
            let job = TileJob {
                world: [origin.x as f32, origin.y as f32, spacing.x as f32, spacing.y as f32],
                tile: [texels as u32, slot.size, slot.x, slot.y],
                images: [color, normal, 0, 0],
            };
            texels += u64::from(slot.size).pow(2);
            job
        })
        .collect();
    (jobs, texels)
}

/// The texture atlas (§8.2): the tile cache and the atlas textures that
/// persist from frame to frame, the generation passes declared once, and a
/// `prepare` step that plans each frame (quadtree, cache, page table, jobs)
/// before it is recorded.
pub struct TextureAtlas {
    streaming: TextureStreaming,
    extent: DVec2,
    cache: TileCache,
    bounds: HeightBounds,
    bindings: AtlasBindings,
    max_jobs: usize,
    scratch_texels: u64,
    /// The last prepared frame's page table.
    table: PageTable,
    stats: Vec<TextureFrameStats>,
    /// GPU cost of generation, measured (the budget's GPU time).
    pacer: GenerationPacer,
    /// Whether the GPU time budget applies ([`TextureAtlas::set_paced`]).
    paced: bool,
    /// Host copies of the colour textures, per texture and frame slot
    /// ([`TextureStreaming::readback`]).
    readback: Option<Vec<Vec<Arc<Buffer>>>>,
    /// The detail window the resident tiles were generated with.
    window: DetailPush,
}

/// What the generation passes read this frame (prepared by [`TextureAtlas`]).
#[derive(Clone, Debug, Default)]
pub struct TextureFrame {
    /// Dirty tiles and their texels.
    pub jobs: u32,
    pub texels: u64,
    /// The dirty tiles' jobs, `images` holding the texture's index
    /// ([`TileJob::images`]).
    pub tile_jobs: Vec<TileJob>,
    /// The terrain's detail window this frame (`texturing.upsample`).
    pub window: DetailPush,
}

/// The atlas and page table the generation passes leave for `terrain.draw`.
#[derive(Clone, Debug)]
pub struct AtlasBindings {
    /// Colour (sRGB-encoded RGBA8) textures, in texture order.
    pub colors: Vec<ImageId>,
    /// Displacement normal (RGBA8, n·½ + ½) textures.
    pub normals: Vec<ImageId>,
    /// This frame's page table (an upload region, written by `prepare`).
    pub page_table: UploadRegion,
    /// Texels per atlas side.
    pub atlas_size: u32,
}

/// What the passes read besides their own resources.
pub struct GenerationInputs<'a> {
    pub field: Arc<HeightField>,
    /// The height field as an R32F texture, the wavelet noise tile, the
    /// layers buffer.
    pub heights: ImageId,
    pub noise: ImageId,
    pub layers: LayerTable,
    /// The layers' extra input maps.
    pub maps: InputMaps,
    pub tree: &'a LayerTree,
    /// The terrain's streamed detail window, if it has one.
    pub window: Option<ImageId>,
}

/// An atlas texture and its graph resource.
type AtlasTexture = (ImageId, Arc<Image>);

/// The atlas textures, imported into `graph`: (colour, normal) per texture.
fn atlas_textures<S: Provides<TextureFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    streaming: &TextureStreaming,
) -> Result<Vec<[AtlasTexture; 2]>> {
    let readback_usage = match streaming.readback {
        true => ImageUsageFlags::TRANSFER_SRC,
        false => ImageUsageFlags::empty(),
    };
    let size = streaming.atlas.size;
    let mut textures = Vec::new();
    for (k, tile) in streaming.atlas.texture_tile_sizes().into_iter().enumerate() {
        let mut image = |what: &str| -> Result<AtlasTexture> {
            let image = Arc::new(Image::new(
                ctx,
                ImageDesc {
                    name: format!("texture atlas {k} ({tile}² tiles, {what})"),
                    width: size,
                    height: size,
                    format: Format::R8G8B8A8_UNORM,
                    usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | readback_usage,
                },
            )?);
            Ok((graph.import_image(image.clone()), image))
        };
        textures.push([image("colour")?, image("normal")?]);
    }
    Ok(textures)
}

impl TextureAtlas {
    /// Creates the atlas and declares `texturing.upsample`, one
    /// `texturing.layer*` pass per layer and `texturing.finish` (module
    /// documentation), and `texturing.readback` when asked for.
    pub fn declare<S: Provides<TextureFrame> + 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        inputs: GenerationInputs,
        streaming: TextureStreaming,
    ) -> Result<TextureAtlas> {
        streaming.validate()?;
        let field = inputs.field.clone();
        let textures: Vec<[ImageId; 2]> = (atlas_textures(ctx, graph, &streaming)?.into_iter())
            .map(|[(color, _), (normal, _)]| [color, normal])
            .collect();
        let colors: Vec<ImageId> = textures.iter().map(|t| t[0]).collect();
        let normals: Vec<ImageId> = textures.iter().map(|t| t[1]).collect();
        let max_jobs = streaming.budget.tiles.saturating_add(1).min(1 << 16);
        let jobs = graph.upload_region("texture tile jobs", (max_jobs * std::mem::size_of::<TileJob>()) as u64);
        let page_table = graph.upload_region("texture page table", (PAGE_TABLE_WORDS * 16) as u64);
        let scratch_texels = streaming.scratch_texels();
        let scratch = graph.create_buffer(
            "texel states",
            BufferInfo {
                size: scratch_texels * TEXEL_STATE_BYTES,
                location: MemoryLocation::GpuOnly,
            },
        );
        let passes = GenerationPasses {
            jobs,
            scratch,
            base_push: base_push(&field),
        };
        passes.declare_upsample(ctx, graph, (inputs.heights, inputs.window))?;
        passes.declare_layers(ctx, graph, &inputs)?;
        passes.declare_finish(ctx, graph, &textures)?;
        let readback = match streaming.readback {
            true => Some(add_atlas_readback(ctx, graph, &colors, streaming.atlas.size)?),
            false => None,
        };
        Ok(TextureAtlas {
            extent: field.extent(),
            cache: TileCache::new(streaming.atlas)?,
            bounds: HeightBounds::new(&field, streaming.quadtree.max_depth)?,
            bindings: AtlasBindings {
                colors,
                normals,
                page_table,
                atlas_size: streaming.atlas.size,
            },
            max_jobs,
            scratch_texels,
            table: PageTable::default(),
            stats: Vec::new(),
            pacer: GenerationPacer::default(),
            paced: true,
            readback,
            streaming,
            window: DetailPush::default(),
        })
    }

    /// What `terrain.draw` samples.
    pub fn bindings(&self) -> &AtlasBindings {
        &self.bindings
    }

    /// The page table of the last prepared frame.
    pub fn page_table(&self) -> &PageTable {
        &self.table
    }

    /// Needed tiles the last prepared frame drew from a coarser tile.
    pub fn last_deferred(&self) -> usize {
        self.stats.last().map_or(0, |s| s.tiles.deferred)
    }

    /// Texture statistics of the frames prepared so far and not yet taken.
    pub fn take_stats(&mut self) -> Vec<TextureFrameStats> {
        std::mem::take(&mut self.stats)
    }

    /// Host copies of the colour textures, per texture and frame slot.
    pub fn readback(&self) -> Option<&[Vec<Arc<Buffer>>]> {
        self.readback.as_deref()
    }

    /// Whether the budget's GPU time applies (default true). A still
    /// render that only waits for every tile clears it: its frames are not
    /// shown, so only the tile and texel counts bound them.
    pub fn set_paced(&mut self, paced: bool) {
        self.paced = paced;
    }

    /// Sets the budget's GPU time per frame (a simulator's frame time may
    /// change at run time); errors on a value that is not finite and positive.
    #[cfg(test)]
    pub fn set_gpu_time(&mut self, gpu_time: Option<GpuTimeBudget>) -> Result<()> {
        if let Some(t) = gpu_time.filter(|t| !t.is_valid()) {
            return Err(Error::invalid(
                "texturing.gpu_time",
                format!("{t:?}; must be finite and positive"),
            ));
        }
        self.streaming.budget.gpu_time = gpu_time;
        Ok(())
    }

    /// Takes the GPU timings of completed frames (the renderer passes its
    /// graph's profiles; frames already seen are skipped), from which the
    /// budget's GPU time becomes a texel cap ([`GenerationPacer`]).
    pub fn observe_profiles(&mut self, profiles: &[FrameProfile]) {
        self.pacer.observe(profiles);
    }

    /// The measured generation cost: GPU milliseconds per texel, once known.
    #[cfg(test)]
    pub fn gpu_ms_per_texel(&self) -> Option<f64> {
        self.pacer.ms_per_texel()
    }

    /// The tiles `views` need, coarsened to fit the atlas and the page table.
    fn select(&self, views: &[Footprint]) -> Result<(Vec<NeededTile>, Coarsening)> {
        select_to_fit(self.extent, views, &self.streaming, &self.bounds)
    }

    /// Selects the tiles `views` need, plans the frame within the budget,
    /// builds the page table and the jobs of the dirty tiles.
    fn plan(&mut self, frame: u64, views: &[Footprint]) -> Result<PlannedFrame> {
        let extent = self.extent;
        let (needed, coarsening) = self.select(views)?;
        let mut budget = self.streaming.budget;
        if self.paced {
            if let Some(cap) = self.pacer.texel_cap(budget.gpu_time) {
                budget.texels = budget.texels.min(cap);
            }
        }
        let plan = self.cache.plan_frame(frame, &needed, budget);
        let table = PageTable::build(&plan, extent)?;
        let (jobs, texels) = tile_jobs(&plan, extent, &|texture| [texture, texture]);
        if texels > self.scratch_texels || jobs.len() > self.max_jobs {
            return Err(Error::Graph(format!(
                "texturing: {} tiles of {texels} texels exceed the scratch buffer",
                jobs.len()
            )));
        }
        Ok(PlannedFrame {
            plan,
            table,
            jobs,
            texels,
            coarsening,
            texel_cap: budget.texels,
        })
    }
}

impl TextureAtlas {
    /// Forgets the tiles where the detail window's drawn rectangle was or
    /// is when it changed: their base surface (`texturing.upsample`) did.
    fn follow_window(&mut self, window: DetailPush) {
        if window == self.window {
            return;
        }
        for rect in [self.window.drawn_rect(), window.drawn_rect()].into_iter().flatten() {
            self.cache.forget_overlapping(self.extent, rect);
        }
        self.window = window;
    }
}

/// A frame's plan, before its uploads.
struct PlannedFrame {
    plan: TilePlan,
    table: PageTable,
    jobs: Vec<TileJob>,
    texels: u64,
    coarsening: Coarsening,
    texel_cap: u64,
}

impl Technique for TextureAtlas {
    type Prepared = TextureFrame;
    /// The terrain's detail window this frame ([`crate::terrain::detail`];
    /// default: none).
    type Needs<'a> = DetailPush;

    fn name(&self) -> &'static str {
        "texturing"
    }

    /// Plans the frame for all its views (1 to [`MAX_VIEWS`]; module
    /// documentation, step 1) and uploads its jobs and the page table every
    /// view samples. A frame whose plan cannot be generated forgets the
    /// cache, so that no tile stays marked resident without being generated.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, window: DetailPush) -> Result<TextureFrame> {
        let start = std::time::Instant::now();
        self.follow_window(window);
        if !(1..=MAX_VIEWS).contains(&frame.views.len()) {
            return Err(Error::invalid(
                "views",
                format!(
                    "{}; the texture atlas serves 1..={MAX_VIEWS} views per frame",
                    frame.views.len()
                ),
            ));
        }
        let views: Vec<Footprint> = frame.views.iter().map(View::footprint).collect();
        let planned = self.plan(frame.index, &views).and_then(|p| {
            let words = p.table.words();
            if words.len() > PAGE_TABLE_WORDS {
                return Err(Error::invalid(
                    "texture page table",
                    format!("{} words exceed the capacity of {PAGE_TABLE_WORDS}", words.len()),
                ));
            }
            frame
                .uploads
                .write(self.bindings.page_table, bytemuck::cast_slice(&words))?;
            Ok(p)
        });
        let p = match planned {
            Ok(p) => p,
            Err(e) => {
                self.cache.clear();
                return Err(e);
            }
        };
        self.pacer.record(frame.index, p.texels);
        self.table = p.table;
        self.stats.push(TextureFrameStats {
            frame: frame.index,
            tiles: p.plan.stats,
            hit_rate: p.plan.stats.hit_rate(),
            texels_generated: p.texels,
            cpu_ms: start.elapsed().as_secs_f64() * 1e3,
            coarsened: p.coarsening.halved + p.coarsening.merged,
            texel_cap: p.texel_cap,
        });
        Ok(TextureFrame {
            jobs: p.jobs.len() as u32,
            texels: p.texels,
            tile_jobs: p.jobs,
            window,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texturing::atlas::{AtlasSettings, TileSlot};
    use crate::texturing::page_table::PageEntry;

    const EXTENT: DVec2 = DVec2::new(1000.0, 1000.0);
    const BORDER: u32 = 4;

    /// A smooth stand-in for the layer tree.
    fn f(p: DVec2) -> f64 {
        (p.x / 37.0).sin() + (p.y / 53.0).cos()
    }

    /// A tile of `node` generated as the shaders do: `f` at every texel.
    struct Tile {
        size: u32,
        values: Vec<f64>,
        entry: PageEntry,
    }

    impl Tile {
        fn new(node: NodeId, size: u32) -> Tile {
            let at = |(i, j)| f(texel_world(node, size, BORDER, EXTENT, (i, j)));
            let values = (0..size).flat_map(|j| (0..size).map(move |i| (i, j))).map(at).collect();
            let slot = TileSlot {
                texture: 0,
                x: 0,
                y: 0,
                size,
            };
            let entry = PageEntry::new(node, slot, EXTENT, BORDER);
            Tile { size, values, entry }
        }

        /// Bilinear sample at world `p` as terrain.draw does (texel centres at
        /// i + 0.5); panics if the footprint leaves the tile.
        fn sample(&self, p: DVec2) -> f64 {
            let t = self.entry.texel(p) - 0.5;
            let last = f64::from(self.size - 1);
            assert!(
                t.min_element() >= 0.0 && t.max_element() <= last,
                "{p} reads outside the tile: {t}"
            );
            let base = t.floor().min(DVec2::splat(last - 1.0));
            let (fx, fy) = (t.x - base.x, t.y - base.y);
            let at = |dx: f64, dy: f64| self.values[((base.y + dy) as u32 * self.size + (base.x + dx) as u32) as usize];
            let top = at(0.0, 0.0) * (1.0 - fx) + at(1.0, 0.0) * fx;
            let bottom = at(0.0, 1.0) * (1.0 - fx) + at(1.0, 1.0) * fx;
            top * (1.0 - fy) + bottom * fy
        }
    }

    /// Points along the shared vertical edge x = `x` over `[y0, y1]`.
    fn edge(x: f64, y0: f64, y1: f64) -> impl Iterator<Item = DVec2> {
        (0..=64).map(move |k| DVec2::new(x, y0 + (y1 - y0) * f64::from(k) / 64.0))
    }

    #[test]
    fn equal_size_neighbours_share_border_texels_exactly() {
        let (a, b) = (NodeId { level: 3, x: 2, y: 3 }, NodeId { level: 3, x: 3, y: 3 });
        let inner = 32 - 2 * BORDER;
        for j in 0..32 {
            for k in 0..2 * BORDER {
                // A's texel inner + k (its right border from k = BORDER on)
                // is B's texel k.
                let pa = texel_world(a, 32, BORDER, EXTENT, (inner + k, j));
                let pb = texel_world(b, 32, BORDER, EXTENT, (k, j));
                assert!(pa.distance(pb) < 1e-9, "{pa} vs {pb}");
            }
        }
        let (ta, tb) = (Tile::new(a, 32), Tile::new(b, 32));
        let (min, max) = b.rect(EXTENT);
        for p in edge(min.x, min.y, max.y) {
            assert!((ta.sample(p) - tb.sample(p)).abs() < 1e-9, "seam at {p}");
        }
    }

    #[test]
    fn different_size_neighbours_agree_within_interpolation_error() {
        // A coarse tile and the finer tiles of its eastern neighbour's children.
        let coarse = NodeId { level: 3, x: 2, y: 3 };
        let fine = [NodeId { level: 4, x: 6, y: 6 }, NodeId { level: 4, x: 6, y: 7 }];
        let ta = Tile::new(coarse, 32);
        // Bilinear error ≤ h²/8 · max|f''| per direction, h the coarse spacing.
        let h = (1000.0 / 8.0) / f64::from(32 - 2 * BORDER);
        let bound = 2.0 * h * h / 8.0 * (1.0 / (37.0f64 * 37.0)).max(1.0 / (53.0 * 53.0));
        let mut worst = 0.0f64;
        for node in fine {
            let tb = Tile::new(node, 64);
            let (min, max) = node.rect(EXTENT);
            for p in edge(min.x, min.y, max.y) {
                let d = (ta.sample(p) - tb.sample(p)).abs();
                worst = worst.max(d);
                assert!(d <= 2.0 * bound, "seam of {d} at {p} (bound {bound})");
                assert!((tb.sample(p) - f(p)).abs() <= bound, "fine tile off at {p}");
            }
        }
        assert!(worst > 0.0, "different lattices should not agree exactly");
    }

    #[test]
    fn jobs_number_texels_tile_after_tile() {
        let mut cache = TileCache::new(AtlasSettings::default()).unwrap();
        let needed = [
            crate::texturing::quadtree::NeededTile {
                node: NodeId { level: 1, x: 0, y: 0 },
                size: 64,
                distance: 1.0,
            },
            crate::texturing::quadtree::NeededTile {
                node: NodeId { level: 1, x: 1, y: 0 },
                size: 32,
                distance: 2.0,
            },
        ];
        let plan = cache.plan_frame(1, &needed, 10);
        let (jobs, texels) = tile_jobs(&plan, EXTENT, &|t| [10 + t, 20 + t]);
        // The root (16²) first, then the two needed tiles.
        assert_eq!(texels, 16 * 16 + 64 * 64 + 32 * 32);
        let firsts: Vec<u32> = jobs.iter().map(|j| j.tile[0]).collect();
        assert_eq!(firsts, [0, 256, 256 + 4096]);
        let slot = plan.generate[1].1;
        assert_eq!(jobs[1].images, [10 + slot.texture, 20 + slot.texture, 0, 0]);
        let origin = texel_world(NodeId { level: 1, x: 0, y: 0 }, 64, BORDER, EXTENT, (0, 0));
        assert_eq!(jobs[1].world[..2], [origin.x as f32, origin.y as f32]);
        assert!((f64::from(jobs[1].world[2]) - 500.0 / 56.0).abs() < 1e-4);
    }
}
