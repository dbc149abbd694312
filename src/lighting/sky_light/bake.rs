//! The sky-light bake (§9.3–9.5): horizon tracing, the direct transfer
//! (`glsl/lighting/sky_light_transfer.comp`) and 0–2 interreflection
//! bounces (`sky_light_bounce.comp`, §9.4, eq. 9.9–9.11) on the GPU, in
//! chunks of rows (one submission each, so the progress callback advances
//! and no dispatch runs long), optionally through the [`super::cache`].

use std::borrow::Cow;
use std::path::Path;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DVec2;

use super::cache::{self, BakeData, BakeKey};
use super::fit;
use super::horizon::{declare_horizon, HorizonPass, HorizonPush};
use super::tables::{transfer_tables, ENTRIES};
use super::{HORIZON_MAP_AZIMUTHS, PATCHES_PER_SIDE, SURFACE_FLOATS};
use crate::error::{Error, Result};
use crate::graph::{BufferAccess, RenderGraph, Stage};
use crate::io::heightmap::HeightField;
use crate::shaders;
use crate::surface::bspline::knot_field;
use crate::view::{Lighting, LightingSetup};
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, Format, FrameRing, Image, ImageDesc,
    ImageUsageFlags, MemoryLocation,
};

/// Texels per submission, about.
const TEXELS_PER_CHUNK: u32 = 1 << 16;

/// What the bake computes; all of it is part of the cache key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeSettings {
    /// SH bands of the transfer: 3 or 5 (a 5-band bake also serves 3 bands).
    pub sh_bands: u32,
    /// Interreflection bounces: 0, 1 or 2.
    pub bounces: u32,
    /// Traced azimuths K: a multiple of 16 in 16..=256.
    pub azimuths: u32,
    /// Albedo ρ_b of the terrain the bounces reflect off (0..=1).
    pub bounce_albedo: f32,
}

impl Default for BakeSettings {
    fn default() -> Self {
        BakeSettings {
            sh_bands: 5,
            bounces: 1,
            azimuths: 32,
            bounce_albedo: 0.3,
        }
    }
}

impl BakeSettings {
    /// The bake a frame's lighting needs: its bands and bounces, the albedo
    /// override (or 0.3) as bounce albedo, 32 azimuths.
    pub fn from_lighting(lighting: &Lighting) -> BakeSettings {
        BakeSettings::from_setup(&lighting.setup())
    }

    /// The bake of the lighting the renderer is built with.
    pub fn from_setup(setup: &LightingSetup) -> BakeSettings {
        BakeSettings {
            sh_bands: setup.sh_bands,
            bounces: setup.bounces,
            bounce_albedo: setup.bounce_albedo,
            ..BakeSettings::default()
        }
    }

    /// Checks every field; errors name `sky_light.*`.
    pub fn validate(&self) -> Result<()> {
        if !matches!(self.sh_bands, 3 | 5) {
            return Err(Error::invalid(
                "sky_light.sh_bands",
                format!("{}; must be 3 or 5", self.sh_bands),
            ));
        }
        if self.bounces > 2 {
            return Err(Error::invalid(
                "sky_light.bounces",
                format!("{}; must be 0, 1 or 2", self.bounces),
            ));
        }
        if self.azimuths % 16 != 0 || !(16..=256).contains(&self.azimuths) {
            return Err(Error::invalid(
                "sky_light.azimuths",
                format!("{}; must be a multiple of 16 in 16..=256", self.azimuths),
            ));
        }
        if !(0.0..=1.0).contains(&self.bounce_albedo) {
            return Err(Error::invalid(
                "sky_light.bounce_albedo",
                format!("{}; must be in 0..=1", self.bounce_albedo),
            ));
        }
        Ok(())
    }

    /// SH coefficients of the transfer.
    pub fn coefficients(&self) -> u32 {
        self.sh_bands * self.sh_bands
    }

    /// Floats per texel of the transfer: SH, then the 8×8 patches.
    pub fn stride(&self) -> u32 {
        self.coefficients() + PATCHES_PER_SIDE * PATCHES_PER_SIDE
    }
}

/// Rows `first_row..first_row + rows` of one submission of a bake pass.
#[derive(Clone, Copy, Debug)]
pub struct Chunk {
    pub first_row: u32,
    pub rows: u32,
}

/// The baked sky light of one height field, resident on the GPU.
pub struct SkyLightBake {
    pub settings: BakeSettings,
    pub columns: u32,
    pub rows: u32,
    pub spacing: DVec2,
    /// Per texel: normal xyz, sky visibility, bent normal xyz, 0.
    pub(crate) surface: Arc<Buffer>,
    /// Per texel: [`BakeSettings::stride`] floats (SH, then patches).
    pub(crate) transfer: Arc<Buffer>,
    /// The sun horizon map (RGBA32F, 2·columns × 2·rows).
    pub(crate) horizon_map: Arc<Image>,
    /// Whether the bake came from the cache.
    pub from_cache: bool,
    key: BakeKey,
}

/// Push constants of `sky_light_transfer.comp` and `sky_light_bounce.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TransferPush {
    handles: [u32; 4],
    grid: [u32; 4],
    layout: [u32; 4],
    params: [f32; 4],
}

/// A device-local storage buffer of `floats` floats, within the device's
/// storage-buffer range.
fn storage(ctx: &Context, name: &str, bytes: u64) -> Result<Arc<Buffer>> {
    let limit = u64::from(ctx.shared.limits.max_storage_buffer_range);
    if bytes > limit {
        return Err(Error::invalid(
            "sky light",
            format!("'{name}' needs {bytes} bytes; the device's storage buffers hold at most {limit} (use a smaller height field)"),
        ));
    }
    Ok(Arc::new(Buffer::new(
        ctx,
        BufferDesc {
            name: name.into(),
            size: bytes.max(4),
            usage: BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC | BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuOnly,
        },
    )?))
}

fn horizon_map_desc(columns: u32, rows: u32) -> ImageDesc {
    ImageDesc {
        name: "sky-light horizon map".into(),
        width: 2 * columns,
        height: 2 * rows,
        format: Format::R32G32B32A32_SFLOAT,
        usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC,
    }
}

/// Runs `graph` once per chunk of rows, reporting `progress(done / total)`.
fn run_chunks(
    ctx: &Context,
    frames: &mut FrameRing,
    graph: RenderGraph<Chunk>,
    rows: u32,
    chunk_rows: u32,
    progress: &mut dyn FnMut(f32),
    step: (&mut u32, u32),
) -> Result<()> {
    let mut baked = graph.bake(ctx)?;
    let (done, total) = step;
    let mut first_row = 0;
    while first_row < rows {
        let chunk = Chunk {
            first_row,
            rows: chunk_rows.min(rows - first_row),
        };
        baked.execute(frames, &chunk, &[])?;
        first_row += chunk.rows;
        *done += 1;
        progress(*done as f32 / total.max(1) as f32);
    }
    baked.finish(frames)
}

impl SkyLightBake {
    /// The bake of `field` with `settings`, traced on the surface the
    /// renderer draws: the B-spline at the samples ([`knot_field`], §7.4),
    /// not the raw samples, whose peaks stand higher and valleys lie deeper
    /// (on the Jacksboro DEM at 5× relief the raw samples' horizon map
    /// shadowed 1.5–4 % more of a distant view than a ray cast of the drawn
    /// surface; the knots: within 0.7 %, docs/LIGHTING.md). From `cache` (a directory) when it
    /// holds a valid file of the same key, else computed on the GPU and
    /// written there. The cache is only an optimisation: a corrupt,
    /// truncated or stale cache file is rebuilt, and one that cannot be read
    /// or written (permissions, a full disk, a read-only file system) is a
    /// warning naming the file and why (`log::warn`), and the bake goes on
    /// without it. `progress` gets the fraction done (0..=1).
    pub fn bake(
        ctx: &Context,
        field: &HeightField,
        settings: &BakeSettings,
        cache: Option<&Path>,
        progress: &mut dyn FnMut(f32),
    ) -> Result<SkyLightBake> {
        settings.validate()?;
        field.validate(Path::new("sky-light height field"))?;
        let drawn = knot_field(field);
        let field = &*SkyLightBake::fitted(ctx, &drawn, settings);
        let key = BakeKey::new(field, settings);
        let Some(dir) = cache else {
            return SkyLightBake::compute_fitted(ctx, field, settings, progress);
        };
        let path = cache::cache_path(dir, &key);
        match cache::load(&path, &key) {
            Ok(Some(data)) => {
                let bake = SkyLightBake::upload(ctx, field, settings, &data)?;
                progress(1.0);
                return Ok(bake);
            }
            Ok(None) => {}
            Err(e) => log::warn!("sky-light cache not read, baking anew: {e}"),
        }
        let bake = SkyLightBake::compute_fitted(ctx, field, settings, progress)?;
        if let Err(e) = cache::store(&path, &bake.read_back(ctx)?) {
            log::warn!("sky-light cache not written, rendering without it: {e}");
        }
        Ok(bake)
    }

    /// The field the bake of `field` runs on: `field`, or its area average
    /// at the most texels the device's storage buffers and images hold
    /// ([`super::fit`]).
    pub fn fitted<'f>(ctx: &Context, field: &'f HeightField, settings: &BakeSettings) -> Cow<'f, HeightField> {
        let capacity = fit::bake_capacity(settings, ctx.max_storage_buffer_range(), ctx.max_image_dimension());
        let fitted = fit::bake_field(field, capacity);
        if let Cow::Owned(f) = &fitted {
            log::info!(
                "sky light: the {}×{} height field is baked at {}×{} (the device's storage buffers hold {} texels)",
                field.columns,
                field.rows,
                f.columns,
                f.rows,
                capacity.1
            );
        }
        fitted
    }

    /// The bake computed on the GPU (no cache) on the drawn surface
    /// ([`knot_field`]), at the size [`SkyLightBake::fitted`] gives.
    pub fn compute(
        ctx: &Context,
        field: &HeightField,
        settings: &BakeSettings,
        progress: &mut dyn FnMut(f32),
    ) -> Result<SkyLightBake> {
        settings.validate()?;
        field.validate(Path::new("sky-light height field"))?;
        let drawn = knot_field(field);
        SkyLightBake::compute_fitted(ctx, &SkyLightBake::fitted(ctx, &drawn, settings), settings, progress)
    }

    /// [`SkyLightBake::compute`] of a field already [`SkyLightBake::fitted`]
    /// (and validated before fitting: an area average of a legal field may
    /// have a spacing beyond [`crate::io::heightmap::MAX_SPACING`]).
    fn compute_fitted(
        ctx: &Context,
        field: &HeightField,
        settings: &BakeSettings,
        progress: &mut dyn FnMut(f32),
    ) -> Result<SkyLightBake> {
        let (columns, rows) = (field.columns, field.rows);
        let texels = u64::from(columns) * u64::from(rows);
        let (k, stride) = (settings.azimuths, settings.stride());
        let heights = Arc::new(Buffer::with_data(
            ctx,
            "sky-light heights",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&field.heights),
        )?);
        let tables = Arc::new(Buffer::with_data(
            ctx,
            "sky-light tables",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&transfer_tables()),
        )?);
        let horizons = storage(ctx, "sky-light horizons", texels * u64::from(k) * 4)?;
        let surface = storage(ctx, "sky-light surface", texels * u64::from(SURFACE_FLOATS) * 4)?;
        let transfer_bytes = texels * u64::from(stride) * 4;
        let mut transfers = vec![storage(ctx, "sky-light transfer (direct)", transfer_bytes)?];
        for b in 1..=settings.bounces {
            transfers.push(storage(
                ctx,
                &format!("sky-light transfer (bounce {b})"),
                transfer_bytes,
            )?);
        }
        let horizon_map = Arc::new(Image::new(ctx, horizon_map_desc(columns, rows))?);

        let chunk_rows = (TEXELS_PER_CHUNK / columns.max(1)).max(1).next_multiple_of(8);
        let total = rows.div_ceil(chunk_rows) * (2 + settings.bounces);
        let mut done = 0;
        let mut frames = FrameRing::new(ctx)?;
        let spacing = [field.spacing.x as f32, field.spacing.y as f32];
        let grid = [columns, rows, k, 0];

        // Horizons.
        let mut graph = RenderGraph::new();
        let pass = HorizonPass {
            heights: graph.import_buffer(heights.clone()),
            horizons: graph.import_buffer(horizons.clone()),
            map: graph.import_image(horizon_map.clone()),
            push: HorizonPush {
                handles: [0; 4],
                grid,
                spacing: [spacing[0], spacing[1], field.min_max().1, 0.0],
            },
        };
        let pipeline = Arc::new(ComputePipeline::new(ctx, shaders::SKY_LIGHT_HORIZON)?);
        declare_horizon(&mut graph, pipeline, pass);
        run_chunks(ctx, &mut frames, graph, rows, chunk_rows, progress, (&mut done, total))?;

        // Direct transfer, visibility, bent normals.
        let push = TransferPush {
            handles: [0; 4],
            grid,
            layout: [settings.coefficients(), stride, 0, ENTRIES as u32],
            params: [spacing[0], spacing[1], 0.0, 0.0],
        };
        let mut graph = RenderGraph::new();
        let mut import = |buffer: &Arc<Buffer>| graph.import_buffer(buffer.clone());
        let buffers = [
            ChunkBuffer::read(import(&heights), &[Slot::Handle(0)]),
            ChunkBuffer::read(import(&horizons), &[Slot::Handle(1)]),
            ChunkBuffer::read(import(&tables), &[Slot::Handle(2)]),
            ChunkBuffer::write(import(&transfers[0]), &[Slot::Handle(3)]),
            ChunkBuffer::write(import(&surface), &[Slot::Layout(2)]),
        ];
        let pipeline = Arc::new(ComputePipeline::new(ctx, shaders::SKY_LIGHT_TRANSFER)?);
        declare_chunked(&mut graph, "sky_light.transfer", pipeline, &buffers, push);
        run_chunks(ctx, &mut frames, graph, rows, chunk_rows, progress, (&mut done, total))?;

        // Bounces: T^b = T^0 + ρ_b Σ w T^{b−1}(horizon point).
        let pipeline = Arc::new(ComputePipeline::new(ctx, shaders::SKY_LIGHT_BOUNCE)?);
        for b in 1..transfers.len() {
            let push = TransferPush {
                handles: [0; 4],
                grid,
                layout: [stride, 0, 0, 0],
                params: [spacing[0], spacing[1], settings.bounce_albedo, 0.0],
            };
            let mut graph = RenderGraph::new();
            let buffers = bounce_buffers(&mut graph, (&surface, &horizons), &transfers, b);
            declare_chunked(&mut graph, "sky_light.bounce", pipeline.clone(), &buffers, push);
            run_chunks(ctx, &mut frames, graph, rows, chunk_rows, progress, (&mut done, total))?;
        }
        frames.finish()?;
        let transfer = transfers
            .pop()
            .ok_or_else(|| Error::Graph("sky light: no transfer".into()))?;
        Ok(SkyLightBake {
            settings: *settings,
            columns,
            rows,
            spacing: field.spacing,
            surface,
            transfer,
            horizon_map,
            from_cache: false,
            key: BakeKey::new(field, settings),
        })
    }

    /// A bake from cached data (checked against `field` and `settings`).
    pub fn upload(
        ctx: &Context,
        field: &HeightField,
        settings: &BakeSettings,
        data: &BakeData,
    ) -> Result<SkyLightBake> {
        let key = BakeKey::new(field, settings);
        if data.key != key {
            return Err(Error::invalid(
                "sky light",
                "the cached bake is of another field or settings",
            ));
        }
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC;
        Ok(SkyLightBake {
            settings: *settings,
            columns: field.columns,
            rows: field.rows,
            spacing: field.spacing,
            surface: Arc::new(Buffer::with_data(ctx, "sky-light surface", usage, &data.surface)?),
            transfer: Arc::new(Buffer::with_data(ctx, "sky-light transfer", usage, &data.transfer)?),
            horizon_map: Arc::new(Image::with_data(
                ctx,
                horizon_map_desc(field.columns, field.rows),
                &data.horizon,
            )?),
            from_cache: true,
            key,
        })
    }

    /// Copies the bake back to the host (for the cache and tests).
    pub fn read_back(&self, ctx: &Context) -> Result<BakeData> {
        let readback = |name: &str, size: u64| -> Result<Arc<Buffer>> {
            Ok(Arc::new(Buffer::new(
                ctx,
                BufferDesc {
                    name: format!("sky-light readback ({name})"),
                    size,
                    usage: BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuToCpu,
                },
            )?))
        };
        let map_bytes = 4 * u64::from(self.columns) * u64::from(self.rows) * 16;
        let targets = [
            readback("surface", self.surface.size())?,
            readback("transfer", self.transfer.size())?,
            readback("horizon map", map_bytes)?,
        ];
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let sources = [self.surface.clone(), self.transfer.clone()].map(|b| graph.import_buffer(b));
        let map = graph.import_image(self.horizon_map.clone());
        let ids = targets.clone().map(|b| graph.import_buffer(b));
        graph
            .pass("sky_light.readback")
            .transfer()
            .read(sources[0], BufferAccess::TransferSrc)
            .read(sources[1], BufferAccess::TransferSrc)
            .read(map, crate::graph::ImageAccess::TransferSrc)
            .write(ids[0], BufferAccess::TransferDst)
            .write(ids[1], BufferAccess::TransferDst)
            .write(ids[2], BufferAccess::TransferDst)
            .record(move |pass, _| {
                for k in 0..2 {
                    let (src, dst) = (pass.buffer(sources[k])?, pass.buffer(ids[k])?);
                    pass.cmd().copy_buffer(src, dst, src.size());
                }
                let (image, dst) = (pass.image(map)?, pass.buffer(ids[2])?);
                pass.cmd().copy_image_to_buffer(image, dst);
                Ok(())
            });
        for id in ids {
            graph.read_back(id);
        }
        let mut baked = graph.bake(ctx)?;
        let mut frames = FrameRing::new(ctx)?;
        baked.execute(&mut frames, &(), &[])?;
        baked.finish(&mut frames)?;
        frames.finish()?;
        let bytes = |b: &Buffer| -> Result<Vec<u8>> { Ok(b.mapped()?.to_vec()) };
        Ok(BakeData {
            key: self.key,
            surface: bytes(&targets[0])?,
            transfer: bytes(&targets[1])?,
            horizon: bytes(&targets[2])?,
        })
    }

    /// Texels of the field.
    pub fn texels(&self) -> u64 {
        u64::from(self.columns) * u64::from(self.rows)
    }

    /// The sun horizon map's azimuths.
    pub fn horizon_map_azimuths(&self) -> u32 {
        HORIZON_MAP_AZIMUTHS
    }
}

/// Where a buffer's heap handle goes in a [`TransferPush`].
#[derive(Clone, Copy, Debug)]
enum Slot {
    Handle(usize),
    Layout(usize),
}

/// A buffer a chunked pass reads or writes (part of), and the words of
/// the push constants its handle fills.
struct ChunkBuffer {
    id: crate::graph::BufferId,
    access: BufferAccess,
    slots: Vec<Slot>,
}

impl ChunkBuffer {
    fn read(id: crate::graph::BufferId, slots: &[Slot]) -> ChunkBuffer {
        ChunkBuffer {
            id,
            access: BufferAccess::StorageRead(Stage::Compute),
            slots: slots.to_vec(),
        }
    }

    fn write(id: crate::graph::BufferId, slots: &[Slot]) -> ChunkBuffer {
        ChunkBuffer {
            id,
            access: BufferAccess::StorageReadWrite(Stage::Compute),
            slots: slots.to_vec(),
        }
    }
}

/// What bounce `b` (≥ 1) reads and writes: the surface and horizons, the
/// previous bounce and the direct transfer (the same buffer for the first
/// bounce), and bounce `b`'s transfer.
fn bounce_buffers(
    graph: &mut RenderGraph<Chunk>,
    (surface, horizons): (&Arc<Buffer>, &Arc<Buffer>),
    transfers: &[Arc<Buffer>],
    b: usize,
) -> Vec<ChunkBuffer> {
    let mut import = |buffer: &Arc<Buffer>| graph.import_buffer(buffer.clone());
    let mut buffers = vec![
        ChunkBuffer::read(import(surface), &[Slot::Handle(0)]),
        ChunkBuffer::read(import(horizons), &[Slot::Handle(1)]),
    ];
    match b {
        1 => buffers.push(ChunkBuffer::read(
            import(&transfers[0]),
            &[Slot::Handle(2), Slot::Handle(3)],
        )),
        _ => buffers.extend([
            ChunkBuffer::read(import(&transfers[b - 1]), &[Slot::Handle(2)]),
            ChunkBuffer::read(import(&transfers[0]), &[Slot::Handle(3)]),
        ]),
    }
    buffers.push(ChunkBuffer::write(import(&transfers[b]), &[Slot::Layout(1)]));
    buffers
}

/// Declares a chunked compute pass of `buffers`, whose handles it writes
/// into `push` while recording.
fn declare_chunked(
    graph: &mut RenderGraph<Chunk>,
    name: &str,
    pipeline: Arc<ComputePipeline>,
    buffers: &[ChunkBuffer],
    push: TransferPush,
) {
    let mut pass = graph.pass(name);
    let bindings: Vec<_> = (buffers.iter())
        .map(|b| (pass.storage_buffer(b.id, b.access), b.slots.clone()))
        .collect();
    pass.record(move |ctx, chunk| {
        let mut push = push;
        for (binding, slots) in &bindings {
            let handle = ctx.handle(*binding)?;
            for slot in slots {
                match *slot {
                    Slot::Handle(i) => push.handles[i] = handle,
                    Slot::Layout(i) => push.layout[i] = handle,
                }
            }
        }
        push.grid[3] = chunk.first_row;
        let groups = [push.grid[0].div_ceil(8), chunk.rows.div_ceil(8), 1];
        ctx.dispatch(&pipeline, &push, groups)
    });
}
