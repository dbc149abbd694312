//! Tile generation on the GPU (dissertation §8.2.2–8.2.4, Fig. 8.3–8.4;
//! `ALGORITHMS.md` §4 items 3–4), as render-graph passes over **all** dirty
//! tiles of a frame at once:
//!
//! 1. CPU, in `texturing.upsample`'s recording: the quadtree picks the nodes
//!    the view needs ([`select_tiles`]), the tile cache plans what to
//!    generate within the [`GenerationBudget`] and what to draw from where
//!    ([`TileCache::plan_frame`]), and the page table is built
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

use std::sync::{Arc, Mutex};

use bytemuck::{Pod, Zeroable};
use glam::DVec2;

use crate::error::{Error, Result};
use crate::graph::{Access, BufferInfo, RenderGraph, ResourceId, Stage};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::texturing::atlas::{GenerationBudget, TileCache, TilePlan};
use crate::texturing::input_maps::InputMaps;
use crate::texturing::layers::LayerTree;
use crate::texturing::page_table::PageTable;
use crate::texturing::quadtree::{select_tiles, HeightBounds, NodeId, QuadtreeSettings, View};
pub use crate::texturing::stats::TextureFrameStats;
pub use crate::texturing::streaming::{TextureStreaming, MAX_ATLAS_TEXTURES};
use crate::view::camera::frustum_planes;
use crate::view::FrameParams;
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, Format, Image, ImageDesc, ImageUsageFlags,
    MemoryLocation,
};

/// Bytes of one texel's state in the scratch buffer (`TexelState`).
pub const TEXEL_STATE_BYTES: u64 = 32;
/// Capacity of the per-frame page-table buffer in 16-byte words.
pub const PAGE_TABLE_WORDS: usize = 1 << 16;
/// Texels per workgroup of the generation passes.
const GROUP: u64 = 64;
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
    /// Colour and normal textures (storage handles), 0, 0.
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

/// What the generation passes and `terrain.draw` share.
pub(crate) struct GenerationState {
    cache: TileCache,
    bounds: HeightBounds,
    /// This frame's page table in words, written by `terrain.draw`.
    pub(crate) page_words: Vec<[u32; 4]>,
    /// The last recorded frame's page table.
    table: PageTable,
    jobs: u32,
    texels: u64,
    stats: Vec<TextureFrameStats>,
}

impl GenerationState {
    /// Selects the needed tiles of `view`, plans the frame within `budget`,
    /// builds the page table and the jobs of the dirty tiles
    /// (`images(texture)`: its colour and normal storage handles).
    fn plan(
        &mut self,
        frame: u64,
        view: &View,
        quadtree: &QuadtreeSettings,
        budget: GenerationBudget,
        extent: DVec2,
        images: &dyn Fn(u32) -> [u32; 2],
    ) -> Result<(TilePlan, Vec<TileJob>, u64)> {
        let needed = select_tiles(extent, view, quadtree, &|n| self.bounds.bounds(n))?;
        let plan = self.cache.plan_frame(frame, &needed, budget);
        let table = PageTable::build(&plan, extent)?;
        let words = table.words();
        if words.len() > PAGE_TABLE_WORDS {
            return Err(Error::invalid(
                "texture page table",
                format!("{} words exceed the capacity of {PAGE_TABLE_WORDS}", words.len()),
            ));
        }
        (self.page_words, self.table) = (words, table);
        let (jobs, texels) = tile_jobs(&plan, extent, images);
        Ok((plan, jobs, texels))
    }
}

/// Shared between the passes' recording closures.
pub(crate) type SharedGeneration = Arc<Mutex<GenerationState>>;

pub(crate) fn locked(state: &SharedGeneration) -> Result<std::sync::MutexGuard<'_, GenerationState>> {
    state
        .lock()
        .map_err(|_| Error::Graph("texture generation state lock poisoned".into()))
}

/// The atlas and page table the generation passes leave for `terrain.draw`.
#[derive(Clone)]
pub struct AtlasResources {
    /// Colour (sRGB-encoded RGBA8) textures, in texture order.
    pub colors: Vec<ResourceId>,
    /// Displacement normal (RGBA8, n·½ + ½) textures.
    pub normals: Vec<ResourceId>,
    /// This frame's page table (host-written, per frame).
    pub page_table: ResourceId,
    /// Texels per atlas side.
    pub atlas_size: u32,
    pub(crate) state: SharedGeneration,
    /// Host copies of the colour textures, per texture and frame slot
    /// ([`TextureStreaming::readback`]).
    pub(crate) readback: Option<Vec<Vec<Arc<Buffer>>>>,
}

impl AtlasResources {
    /// The page table of the last recorded frame.
    pub fn page_table(&self) -> Result<PageTable> {
        Ok(locked(&self.state)?.table.clone())
    }

    /// Needed tiles the last recorded frame drew from a coarser tile.
    pub fn last_deferred(&self) -> Result<usize> {
        Ok(locked(&self.state)?.stats.last().map_or(0, |s| s.tiles.deferred))
    }

    /// Texture statistics of the frames recorded so far and not yet taken.
    pub fn take_stats(&self) -> Result<Vec<TextureFrameStats>> {
        Ok(std::mem::take(&mut locked(&self.state)?.stats))
    }
}

/// Push constants of every `texturing.*` pass (texture_tiles.glsl).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TileGenerationPush {
    handles: [u32; 4],
    counts: [u32; 4],
    grid: [u32; 4],
    spacing_range: [f32; 4],
    maps: [u32; 4],
    extent: [f32; 4],
}

/// What the passes read besides their own resources.
pub struct GenerationInputs<'a> {
    pub field: Arc<HeightField>,
    /// The height field as an R32F texture, the wavelet noise tile, the
    /// layers buffer.
    pub heights: ResourceId,
    pub noise: ResourceId,
    pub layers: ResourceId,
    /// The layers' extra input maps.
    pub maps: InputMaps,
    pub tree: &'a LayerTree,
    /// Image rows (the pixel footprint).
    pub image_height: u32,
}

/// Declares `texturing.upsample`, one `texturing.layer*` pass per layer and
/// `texturing.finish` (module documentation).
pub fn add_generation_passes(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    inputs: GenerationInputs,
    streaming: TextureStreaming,
) -> Result<AtlasResources> {
    streaming.validate()?;
    let field = inputs.field.clone();
    let extent = field.extent();
    let state = Arc::new(Mutex::new(GenerationState {
        cache: TileCache::new(streaming.atlas)?,
        bounds: HeightBounds::new(&field, streaming.quadtree.max_depth)?,
        page_words: Vec::new(),
        table: PageTable::default(),
        jobs: 0,
        texels: 0,
        stats: Vec::new(),
    }));
    let atlas_size = streaming.atlas.size;
    let mut colors = Vec::new();
    let mut normals = Vec::new();
    let readback_usage = match streaming.readback {
        true => ImageUsageFlags::TRANSFER_SRC,
        false => ImageUsageFlags::empty(),
    };
    for (k, tile) in streaming.atlas.texture_tile_sizes().into_iter().enumerate() {
        for (what, list) in [("colour", &mut colors), ("normal", &mut normals)] {
            let image = Image::new(
                ctx,
                ImageDesc {
                    name: format!("texture atlas {k} ({tile}² tiles, {what})"),
                    width: atlas_size,
                    height: atlas_size,
                    format: Format::R8G8B8A8_UNORM,
                    usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | readback_usage,
                },
            )?;
            list.push(graph.import_image(Arc::new(image)));
        }
    }
    let max_jobs = streaming.budget.tiles.saturating_add(1).min(1 << 16);
    let jobs = graph.import_buffers_per_frame(Buffer::per_frame(
        ctx,
        BufferDesc {
            name: "texture tile jobs".into(),
            size: (max_jobs * std::mem::size_of::<TileJob>()) as u64,
            usage: BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )?);
    let page_table = graph.import_buffers_per_frame(Buffer::per_frame(
        ctx,
        BufferDesc {
            name: "texture page table".into(),
            size: (PAGE_TABLE_WORDS * 16) as u64,
            usage: BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )?);
    let scratch_texels = streaming.scratch_texels();
    let scratch = graph.create_buffer(
        "texel states",
        BufferInfo {
            size: scratch_texels * TEXEL_STATE_BYTES,
            location: MemoryLocation::GpuOnly,
        },
    );
    let (lo, hi) = field.min_max();
    let base_push = TileGenerationPush {
        handles: [0; 4],
        counts: [0; 4],
        grid: [field.columns, field.rows, 0, 0],
        spacing_range: [field.spacing.x as f32, field.spacing.y as f32, lo, hi],
        maps: [0; 4],
        extent: [extent.x as f32, extent.y as f32, 0.0, 0.0],
    };
    let (heights, noise, layers, maps) = (inputs.heights, inputs.noise, inputs.layers, inputs.maps);

    // texturing.upsample: plans the frame on the CPU, then the base surface.
    let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_UPSAMPLE)?;
    let shared = state.clone();
    let (image_height, quadtree, budget) = (inputs.image_height, streaming.quadtree, streaming.budget);
    let texture_handles: Vec<(ResourceId, ResourceId)> = colors.iter().copied().zip(normals.iter().copied()).collect();
    let pass = graph
        .pass("texturing.upsample")
        .read(heights, Access::SampledImage(Stage::Compute))
        .read(jobs, Access::StorageBufferRead(Stage::Compute))
        .write(scratch, Access::StorageBufferWrite(Stage::Compute));
    pass.record(move |pass, params| {
        let start = std::time::Instant::now();
        let camera = &params.camera;
        let view = View {
            eye: camera.eye,
            pixel_footprint: View::pixel_footprint_for(camera.fov_y_deg.to_radians(), image_height),
            frustum: Some(frustum_planes(camera.view_proj_f64(params.aspect))),
        };
        let handles = texture_handles
            .iter()
            .map(|&(c, n)| Ok([pass.storage_image(c)?, pass.storage_image(n)?]))
            .collect::<Result<Vec<_>>>()?;
        let mut s = locked(&shared)?;
        let frame = pass.frame();
        let planned = s.plan(frame, &view, &quadtree, budget, extent, &|t| handles[t as usize]);
        let (plan, tile_jobs, texels) = match planned {
            Ok(p) if p.2 <= scratch_texels && p.1.len() <= max_jobs => p,
            // Tiles the plan marked resident will not be generated: forget
            // them all, so the next frame starts afresh.
            failed => {
                s.cache.clear();
                return Err(match failed {
                    Err(e) => e,
                    Ok((_, jobs, texels)) => Error::Graph(format!(
                        "texturing: {} tiles of {texels} texels exceed the scratch buffer",
                        jobs.len()
                    )),
                });
            }
        };
        pass.buffer(jobs)?.write(0, bytemuck::cast_slice(&tile_jobs))?;
        (s.jobs, s.texels) = (tile_jobs.len() as u32, texels);
        s.stats.push(TextureFrameStats {
            frame,
            tiles: plan.stats,
            hit_rate: plan.stats.hit_rate(),
            texels_generated: texels,
            cpu_ms: start.elapsed().as_secs_f64() * 1e3,
        });
        let push = TileGenerationPush {
            handles: [pass.storage_buffer(jobs)?, pass.storage_buffer(scratch)?, 0, 0],
            counts: [s.jobs, texels as u32, 0, pass.sampled(heights)?],
            ..base_push
        };
        drop(s);
        dispatch(pass.cmd(), &pipeline, &push)
    });

    // texturing.layer<i>.<name>: one layer over every dirty texel.
    let layer_pipeline = Arc::new(ComputePipeline::new(ctx, shaders::TEXTURING_LAYER)?);
    for (i, flat) in inputs.tree.layers.iter().enumerate() {
        let name = format!(
            "texturing.layer{i}.{}",
            flat.layer.name.replace(char::is_whitespace, "_")
        );
        let (shared, pipeline) = (state.clone(), layer_pipeline.clone());
        let mut pass = graph
            .pass(&name)
            .read(jobs, Access::StorageBufferRead(Stage::Compute))
            .read(layers, Access::StorageBufferRead(Stage::Compute))
            .read(noise, Access::SampledImage(Stage::Compute));
        for map in maps.present() {
            pass = pass.read(map, Access::SampledImage(Stage::Compute));
        }
        pass.write(scratch, Access::StorageBufferReadWrite(Stage::Compute))
            .record(move |pass, _| {
                let (job_count, texels) = {
                    let s = locked(&shared)?;
                    (s.jobs, s.texels)
                };
                let push = TileGenerationPush {
                    handles: [
                        pass.storage_buffer(jobs)?,
                        pass.storage_buffer(scratch)?,
                        pass.storage_buffer(layers)?,
                        pass.sampled(noise)?,
                    ],
                    counts: [job_count, texels as u32, i as u32, 0],
                    maps: maps.handles(|id| pass.sampled(id))?,
                    ..base_push
                };
                dispatch(pass.cmd(), &pipeline, &push)
            });
    }

    // texturing.finish: colour and normal into the atlas.
    let pipeline = ComputePipeline::new(ctx, shaders::TEXTURING_FINISH)?;
    let shared = state.clone();
    let mut pass = graph
        .pass("texturing.finish")
        .read(jobs, Access::StorageBufferRead(Stage::Compute))
        .read(scratch, Access::StorageBufferRead(Stage::Compute));
    for &image in colors.iter().chain(&normals) {
        pass = pass.write(image, Access::StorageImageReadWrite(Stage::Compute));
    }
    pass.record(move |pass, _| {
        let (job_count, texels) = {
            let s = locked(&shared)?;
            (s.jobs, s.texels)
        };
        let push = TileGenerationPush {
            handles: [pass.storage_buffer(jobs)?, pass.storage_buffer(scratch)?, 0, 0],
            counts: [job_count, texels as u32, 0, 0],
            ..base_push
        };
        dispatch(pass.cmd(), &pipeline, &push)
    });
    let readback = match streaming.readback {
        true => Some(add_atlas_readback(ctx, graph, &colors, atlas_size)?),
        false => None,
    };
    Ok(AtlasResources {
        colors,
        normals,
        page_table,
        atlas_size,
        state,
        readback,
    })
}

/// `texturing.readback`: every colour texture into host buffers.
fn add_atlas_readback(
    ctx: &Context,
    graph: &mut RenderGraph<FrameParams>,
    colors: &[ResourceId],
    atlas_size: u32,
) -> Result<Vec<Vec<Arc<Buffer>>>> {
    let mut copies = Vec::new();
    let mut buffers = Vec::new();
    for (k, &image) in colors.iter().enumerate() {
        let per_frame = Buffer::per_frame(
            ctx,
            BufferDesc {
                name: format!("texture atlas {k} readback"),
                size: u64::from(atlas_size).pow(2) * 4,
                usage: BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        copies.push((image, graph.import_buffers_per_frame(per_frame.clone())));
        buffers.push(per_frame);
    }
    let mut pass = graph.pass("texturing.readback").transfer();
    for &(image, buffer) in &copies {
        pass = pass.read(image, Access::TransferSrc).write(buffer, Access::TransferDst);
    }
    let recorded = copies.clone();
    pass.record(move |pass, _| {
        for &(image, buffer) in &recorded {
            let (image, buffer) = (pass.image(image)?, pass.buffer(buffer)?);
            pass.cmd().copy_image_to_buffer(image, buffer);
        }
        Ok(())
    });
    for &(_, buffer) in &copies {
        graph.read_back(buffer);
    }
    Ok(buffers)
}

/// One thread per dirty texel; nothing when no tile is dirty.
fn dispatch(
    cmd: &mut crate::vulkan::CommandRecorder,
    pipeline: &ComputePipeline,
    push: &TileGenerationPush,
) -> Result<()> {
    let groups = u64::from(push.counts[1]).div_ceil(GROUP);
    if groups == 0 {
        return Ok(());
    }
    cmd.bind_compute(pipeline);
    cmd.push_constants(push)?;
    cmd.dispatch(groups as u32, 1, 1);
    Ok(())
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
