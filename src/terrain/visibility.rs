//! The terrain's compute path (issue 28): the warped grid of §7.4.2
//! rasterized by compute shaders into a visibility buffer, then shaded once
//! per pixel with the same surface shading as `terrain.draw` (§7.4.3, §8.2,
//! §9; `glsl/include/terrain_shade.glsl`). Datacenter GPUs run compute on
//! the whole chip and fragment work on a small part of it, and the grid's
//! triangles are a pixel or two on screen by construction, where a
//! hardware rasterizer shades 2×2 quads.
//!
//! | pass | does |
//! |---|---|
//! | `terrain.raster_clear` | empties the view's visibility buffer and big-triangle list |
//! | `terrain.raster` | one thread a triangle: culls, rasterizes the small ones (fixed-point edge functions with a tie rule: watertight), lists the rest |
//! | `terrain.raster_big` | one workgroup a listed triangle, its threads over the bounding box; near-plane crossings in homogeneous coordinates |
//! | `terrain.shade` | per pixel: the kept triangle, the exact surface sample on the pixel's ray, the shading; the sky where no triangle was kept (no separate `sky` pass on this path); writes every pixel of the view's targets and the view's lighting constants |
//! | `terrain.depth` | the depth buffer for passes that depth-test with the hardware (points), when there are such |
//!
//! With the points' splats on the compute path too ([`ComputeShading::WithSplats`],
//! issue 29), `terrain.shade` is declared after the points' passes, which
//! test their splats against the visibility keys ([`GroundKeys`]), and
//! shades their sums where they cover a pixel (§10.2.3 pass 3: the
//! points' normalization fused into the frame's one shading pass); no
//! `terrain.depth`.
//!
//! Shaders: `glsl/terrain/raster_clear.comp`, `raster.comp`,
//! `raster_big.comp`, `shade.comp` (`shade_splats.comp` with the splats),
//! `depth.frag`; `glsl/include/terrain_visibility.glsl`,
//! `glsl/include/terrain_shade_pixel.glsl`.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::DMat4;

use crate::error::{Error, Result};
use crate::graph::{
    stride_groups, BufferAccess, BufferId, BufferInfo, ImageAccess, ImageInfo, RenderGraph, Stage, UploadRegion,
};
use crate::lighting::sky::write_view_lighting;
use crate::lighting::technique::PreparedLighting;
use crate::shaders;
use crate::terrain::shading::SurfaceInputs;
use crate::terrain::TerrainFrame;
use crate::view::deferred::{GroundKeys, SplatSums};
use crate::view::{Frame, Provides, SceneTargets, View, ViewIndex};
use crate::vulkan::{
    CompareOp, ComputePipeline, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, MemoryLocation,
};

/// Which rasterizer draws the terrain (`--raster`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RasterPath {
    /// The compute path where the device has 64-bit buffer atomics, the
    /// hardware path otherwise (the default).
    #[default]
    Auto,
    /// The visibility buffer and deferred shading in compute shaders
    /// (needs `shaderBufferInt64Atomics`).
    Compute,
    /// The text's path: the grid drawn by the hardware rasterizer.
    Hardware,
}

/// The device feature the compute path needs.
pub const COMPUTE_RASTER_FEATURE: &str = "shaderBufferInt64Atomics";

impl RasterPath {
    /// Whether the terrain is rasterized in compute on `ctx`; an error
    /// naming the feature when `Compute` is asked of a device without it.
    pub fn uses_compute(self, ctx: &Context) -> Result<bool> {
        let offered = ctx.has_feature(COMPUTE_RASTER_FEATURE);
        match self {
            RasterPath::Hardware => Ok(false),
            RasterPath::Auto => Ok(offered),
            RasterPath::Compute if offered => Ok(true),
            RasterPath::Compute => Err(Error::invalid(
                "raster",
                format!("compute needs the device feature {COMPUTE_RASTER_FEATURE}, which this device lacks"),
            )),
        }
    }

    /// The path's name in profiles and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RasterPath::Auto => "auto",
            RasterPath::Compute => "compute",
            RasterPath::Hardware => "hardware",
        }
    }
}

/// One view's constants of the compute passes (std430, `ComputeView` in
/// `glsl/include/terrain_visibility.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ComputeView {
    /// Eye-relative world → clip: the view's projection × its rotation.
    view_proj_rel: [f32; 16],
    /// xyz eye, w = d0 (as `terrain.draw`).
    eye: [f32; 4],
    /// xyz forward axis, w = pixel footprint per metre of depth.
    forward: [f32; 4],
    /// The ray basis of [`View::ray_basis`].
    ray_right: [f32; 4],
    ray_up: [f32; 4],
    ray_forward: [f32; 4],
    /// Width, height, grid side, triangles.
    size: [u32; 4],
    /// Near, far, detail amplitude, detail H.
    clip: [f32; 4],
}

impl ComputeView {
    /// The constants of `view` for a `grid_side`² grid; `draw` gives d0,
    /// the footprint and the detail parameters as `terrain.draw` has them.
    pub fn new(view: &View, grid_side: u32, draw: &crate::terrain::shading::TerrainDrawPush) -> ComputeView {
        let eye = view.camera.eye;
        let rel = view.view_proj_f64() * DMat4::from_translation(eye);
        let (right, up, forward) = view.ray_basis();
        let side = grid_side.max(2);
        ComputeView {
            view_proj_rel: rel.as_mat4().to_cols_array(),
            eye: draw.eye,
            forward: draw.forward,
            ray_right: right.extend(0.0).to_array(),
            ray_up: up.extend(0.0).to_array(),
            ray_forward: forward.extend(0.0).to_array(),
            size: [view.width, view.height, side, triangles(side)],
            clip: [
                view.camera.near as f32,
                view.camera.far as f32,
                draw.detail_amplitude,
                draw.detail_h,
            ],
        }
    }
}

/// Triangles of a `side`² grid.
fn triangles(side: u32) -> u32 {
    2 * (side - 1) * (side - 1)
}

/// Push constants of the raster passes.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct RasterPush {
    /// View constants, grid vertices, visibility buffer, big-triangle list.
    handles: [u32; 4],
    /// `terrain.raster_clear`: pixels.
    size: [u32; 4],
}

/// Push constants of `terrain.shade`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ShadePush {
    /// View constants, grid vertices, visibility buffer.
    handles: [u32; 4],
    /// Radiance, view depth, lighting AOVs, normal (storage).
    images: [u32; 4],
    /// Ids, NDC depth ([`NO_DEPTH`]: none) (storage).
    more: [u32; 4],
    /// Lighting constants, noise tile, texturing constants.
    surface: [u32; 4],
}

/// Push constants of `terrain.shade` with the points' sums (the splat
/// passes' block of `glsl/include/splat.glsl` with `SPLAT_GROUND_SHADE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ShadeSplatsPush {
    /// Sums, point frame, 0, nearest words.
    handles: [u32; 4],
    /// Last records, 0, 0, 0.
    mode: [u32; 4],
    /// Radiance, view depth, W, lighting AOVs (storage).
    outputs: [u32; 4],
    /// Normal, ids (storage); width, height.
    more: [u32; 4],
    /// View constants, grid vertices, visibility buffer, 0.
    ground: [u32; 4],
    /// Lighting constants, noise tile, texturing constants, 0.
    surface: [u32; 4],
}

/// `terrain.shade` writes no NDC depth.
const NO_DEPTH: u32 = u32::MAX;

/// When and with what the compute path's `terrain.shade` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ComputeShading {
    /// Right after the raster passes; `write_depth`: `terrain.depth` then
    /// writes the depth buffer for passes that depth-test with the hardware.
    Immediate { write_depth: bool },
    /// After the points' compute passes (declared by
    /// [`crate::terrain::Terrain::declare_shade`]), shading their sums with
    /// the ground: the points read the visibility keys, not a depth buffer.
    WithSplats,
}

/// Workgroups of `terrain.raster_big` (each loops over the list).
const BIG_WORKGROUPS: u32 = 256;

/// What one view's compute passes read and write.
#[derive(Clone, Debug)]
pub struct ComputePass {
    /// The view's geometry image.
    pub vertices: BufferId,
    pub grid_side: u32,
    /// The view's [`ComputeView`] (written in prepare).
    pub constants: UploadRegion,
    pub surface: SurfaceInputs,
    /// When `terrain.shade` runs, and whether `terrain.depth` follows it.
    pub shading: ComputeShading,
    /// The view (`terrain.shade` writes its lighting constants).
    pub view: ViewIndex,
}

/// The compute pipelines, shared by every view.
pub struct ComputeRaster {
    clear: Arc<ComputePipeline>,
    raster: Arc<ComputePipeline>,
    big: Arc<ComputePipeline>,
    shade: Arc<ComputePipeline>,
    /// `terrain.shade` with the points' sums ([`ComputeShading::WithSplats`] only).
    shade_splats: Option<Arc<ComputePipeline>>,
}

impl ComputeRaster {
    /// Builds the pipelines (`terrain.shade`'s with the points' sums when
    /// `shading` asks for it).
    pub fn new(ctx: &Context, shading: ComputeShading) -> Result<ComputeRaster> {
        let pipeline = |spirv| ComputePipeline::new(ctx, spirv).map(Arc::new);
        Ok(ComputeRaster {
            clear: pipeline(shaders::TERRAIN_RASTER_CLEAR)?,
            raster: pipeline(shaders::TERRAIN_RASTER)?,
            big: pipeline(shaders::TERRAIN_RASTER_BIG)?,
            shade: pipeline(shaders::TERRAIN_SHADE)?,
            shade_splats: match shading {
                ComputeShading::WithSplats => Some(pipeline(shaders::TERRAIN_SHADE_SPLATS)?),
                ComputeShading::Immediate { .. } => None,
            },
        })
    }

    /// Declares the compute passes of one view (`name`: the view's name)
    /// into `targets`, after the view's `terrain.warp`: the raster passes,
    /// then `terrain.shade` (and `terrain.depth`) unless the pass shades
    /// with the splats ([`ComputeRaster::declare_shade_with_splats`] later).
    /// Returns the view's visibility keys.
    pub fn declare<S: Provides<TerrainFrame> + Provides<PreparedLighting> + 'static>(
        &self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        pass: &ComputePass,
        targets: &SceneTargets,
    ) -> Result<GroundKeys> {
        let pixels = u64::from(targets.width) * u64::from(targets.height);
        let visibility = graph.create_buffer(
            &crate::view::pass_name("terrain visibility", &view.name),
            BufferInfo {
                size: pixels * 8,
                location: MemoryLocation::GpuOnly,
            },
        );
        let list = graph.create_buffer(
            &crate::view::pass_name("terrain big triangles", &view.name),
            BufferInfo {
                size: 16 + 4 * u64::from(triangles(pass.grid_side)),
                location: MemoryLocation::GpuOnly,
            },
        );
        self.declare_raster(graph, view, pass, (visibility, list), pixels)?;
        let write_depth = match pass.shading {
            ComputeShading::Immediate { write_depth } => write_depth,
            ComputeShading::WithSplats => return Ok(GroundKeys(visibility)),
        };
        let ndc_depth = write_depth.then(|| {
            let name = crate::view::pass_name("terrain ndc depth", &view.name);
            graph.create_image(&name, ImageInfo::new(targets.width, targets.height, Format::R32_SFLOAT))
        });
        self.declare_shade(graph, view, pass, visibility, (targets, ndc_depth));
        if let Some(ndc_depth) = ndc_depth {
            declare_depth(ctx, graph, view, ndc_depth, targets)?;
        }
        Ok(GroundKeys(visibility))
    }

    /// `terrain.raster_clear`, `terrain.raster`, `terrain.raster_big`.
    fn declare_raster<S: 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        pass: &ComputePass,
        (visibility, list): (BufferId, BufferId),
        pixels: u64,
    ) -> Result<()> {
        let compute = Stage::Compute;
        let pixels = u32::try_from(pixels).map_err(|_| Error::invalid("image size", "too many pixels"))?;
        let name = |base| crate::view::pass_name(base, &view.name);

        let pipeline = self.clear.clone();
        let mut clear = graph.pass(&name("terrain.raster_clear"));
        let (keys, big) = (
            clear.storage_buffer(visibility, BufferAccess::StorageWrite(compute)),
            clear.storage_buffer(list, BufferAccess::StorageWrite(compute)),
        );
        clear.record(move |ctx, _| {
            let push = RasterPush {
                handles: [0, 0, ctx.handle(keys)?, ctx.handle(big)?],
                size: [pixels, 0, 0, 0],
            };
            ctx.dispatch(&pipeline, &push, [stride_groups(pixels, 256), 1, 1])
        });

        let count = triangles(pass.grid_side);
        for (base, pipeline, groups) in [
            ("terrain.raster", self.raster.clone(), stride_groups(count, 64)),
            ("terrain.raster_big", self.big.clone(), BIG_WORKGROUPS),
        ] {
            let mut raster = graph.pass(&name(base));
            let constants = raster.upload(pass.constants, compute);
            let vertices = raster.storage_buffer(pass.vertices, BufferAccess::StorageRead(compute));
            let keys = raster.storage_buffer(visibility, BufferAccess::StorageReadWrite(compute));
            let big = raster.storage_buffer(list, BufferAccess::StorageReadWrite(compute));
            raster.record(move |ctx, _| {
                let handles = [
                    ctx.handle(constants)?,
                    ctx.handle(vertices)?,
                    ctx.handle(keys)?,
                    ctx.handle(big)?,
                ];
                let push = RasterPush { handles, size: [0; 4] };
                ctx.dispatch(&pipeline, &push, [groups, 1, 1])
            });
        }
        Ok(())
    }

    /// `terrain.shade`: the visibility buffer shaded into `targets` (and
    /// the NDC depth into `ndc_depth`).
    fn declare_shade<S: Provides<TerrainFrame> + Provides<PreparedLighting> + 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        pass: &ComputePass,
        visibility: BufferId,
        (targets, ndc_depth): (&SceneTargets, Option<crate::graph::ImageId>),
    ) {
        let compute = Stage::Compute;
        let pipeline = self.shade.clone();
        let mut shade = graph.pass(&crate::view::pass_name("terrain.shade", &view.name));
        let constants = shade.upload(pass.constants, compute);
        let vertices = shade.storage_buffer(pass.vertices, BufferAccess::StorageRead(compute));
        let keys = shade.storage_buffer(visibility, BufferAccess::StorageRead(compute));
        let surface = pass.surface.read_in(&mut shade, targets, compute);
        // Every pixel written: the terrain's, or the sky where none covers it.
        let write = ImageAccess::StorageWrite(compute);
        let images = targets.shaded().map(|image| shade.storage_image(image, write));
        let ndc = ndc_depth.map(|image| shade.storage_image(image, ImageAccess::StorageWrite(compute)));
        let (inputs, (width, height), index) = (pass.surface.clone(), (targets.width, targets.height), pass.view);
        shade.record(move |ctx, frame| {
            let window = frame.prepared::<crate::terrain::TerrainFrame>()?.detail.push;
            let handles = inputs.write(ctx, &surface, window)?;
            write_view_lighting(ctx, frame, index, surface.lighting())?;
            let image = |k: usize| ctx.handle(images[k]);
            let push = ShadePush {
                handles: [ctx.handle(constants)?, ctx.handle(vertices)?, ctx.handle(keys)?, 0],
                images: [image(0)?, image(1)?, image(2)?, image(3)?],
                more: [
                    image(4)?,
                    ndc.map(|b| ctx.handle(b)).transpose()?.unwrap_or(NO_DEPTH),
                    0,
                    0,
                ],
                surface: [handles.lighting, handles.noise_tile, handles.texturing_frame, 0],
            };
            ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
        });
    }
}

impl ComputeRaster {
    /// `terrain.shade` with the points' sums ([`ComputeShading::WithSplats`]):
    /// every pixel of the view shaded once, the splats normalized and
    /// shaded where their sums hold weight (§10.2.3 pass 3, W written
    /// there and 0 elsewhere), the ground or the sky elsewhere. After the
    /// view's raster passes and the points' `points.accumulate`.
    pub fn declare_shade_with_splats<S: Provides<TerrainFrame> + Provides<PreparedLighting> + 'static>(
        &self,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        pass: &ComputePass,
        (keys, sums): (GroundKeys, SplatSums),
        targets: &SceneTargets,
    ) -> Result<()> {
        let pipeline = (self.shade_splats.clone())
            .ok_or_else(|| Error::Graph("terrain.shade: the splats' pipeline was not built".into()))?;
        let weight = (targets.weight)
            .ok_or_else(|| Error::Graph("terrain.shade: the view's targets have no splat weight".into()))?;
        let compute = Stage::Compute;
        let mut shade = graph.pass(&crate::view::pass_name("terrain.shade", &view.name));
        let constants = shade.upload(pass.constants, compute);
        let read = BufferAccess::StorageRead(compute);
        let vertices = shade.storage_buffer(pass.vertices, read);
        let keys = shade.storage_buffer(keys.0, read);
        let [nearest, sum, last] = [sums.nearest, sums.sums, sums.last].map(|b| shade.storage_buffer(b, read));
        let frame = shade.upload(sums.frame, compute);
        let surface = pass.surface.read_in(&mut shade, targets, compute);
        let write = ImageAccess::StorageWrite(compute);
        let [radiance, view_depth, visibility, normal, ids] = targets.shaded().map(|i| shade.storage_image(i, write));
        let weight = shade.storage_image(weight, write);
        let (inputs, (width, height), index) = (pass.surface.clone(), (targets.width, targets.height), pass.view);
        shade.record(move |ctx, frame_data| {
            let window = frame_data.prepared::<crate::terrain::TerrainFrame>()?.detail.push;
            let handles = inputs.write(ctx, &surface, window)?;
            write_view_lighting(ctx, frame_data, index, surface.lighting())?;
            let push = ShadeSplatsPush {
                handles: [ctx.handle(sum)?, ctx.handle(frame)?, 0, ctx.handle(nearest)?],
                mode: [ctx.handle(last)?, 0, 0, 0],
                outputs: [
                    ctx.handle(radiance)?,
                    ctx.handle(view_depth)?,
                    ctx.handle(weight)?,
                    ctx.handle(visibility)?,
                ],
                more: [ctx.handle(normal)?, ctx.handle(ids)?, width, height],
                ground: [ctx.handle(constants)?, ctx.handle(vertices)?, ctx.handle(keys)?, 0],
                surface: [handles.lighting, handles.noise_tile, handles.texturing_frame, 0],
            };
            ctx.dispatch(&pipeline, &push, [width.div_ceil(8), height.div_ceil(8), 1])
        });
        Ok(())
    }
}

/// `terrain.depth`: the view's depth buffer (cleared to far) written from
/// `ndc_depth` where the terrain covers the pixel.
fn declare_depth<S: 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    view: &View,
    ndc_depth: crate::graph::ImageId,
    targets: &SceneTargets,
) -> Result<()> {
    let desc = GraphicsPipelineDesc {
        depth_format: Some(targets.formats.depth),
        depth_test: true,
        depth_write: true,
        depth_compare: CompareOp::ALWAYS,
        ..GraphicsPipelineDesc::full_screen(
            "terrain.depth",
            (shaders::FULL_SCREEN_VERT, shaders::TERRAIN_DEPTH_FRAG),
            Vec::new(),
        )
    };
    let pipeline = Arc::new(GraphicsPipeline::new(ctx, &desc)?);
    let fragment = ImageAccess::StorageRead(Stage::Fragment);
    let mut pass = graph
        .pass(&crate::view::pass_name("terrain.depth", &view.name))
        .graphics();
    let ndc = pass.storage_image(ndc_depth, fragment);
    let view_depth = pass.storage_image(targets.view_depth, fragment);
    pass.pipeline(&pipeline)
        .depth(targets.depth, Some(crate::view::depth::FAR_DEPTH))
        .record(move |ctx, _| {
            let push = [ctx.handle(ndc)?, ctx.handle(view_depth)?, 0, 0];
            ctx.draw_full_screen(&pipeline, &push)
        });
    Ok(())
}
