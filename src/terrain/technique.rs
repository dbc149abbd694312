//! The terrain as a technique (dissertation §7.4): the height field's GPU
//! resources, one geometry image per view, and the per-frame CPU stage —
//! sketch map, importance map and warp of every view (§7.4.2,
//! [`crate::terrain::lod`]) — run in `prepare`, before the frame is
//! recorded; `terrain.warp` and `terrain.draw` then only read what it
//! prepared.

use std::sync::Arc;

use bytemuck::Zeroable;

use crate::error::{Error, Result};
use crate::graph::{BufferId, ImageId, RenderGraph, UploadRegion};
use crate::io::heightmap::HeightField;
use crate::lighting::technique::PreparedLighting;
use crate::surface::gpu_layout::{LayerTable, TexturingFrame, TexturingMode};
use crate::surface::input_maps::InputMaps;
use crate::surface::layers::LayerTree;
use crate::terrain::detail::{declare_detail_upload, DetailSource, DetailUploads, DetailWindow};
use crate::terrain::geometry_image::{declare_warp_pass, GeometryImage, TerrainSettings, WarpPass};
use crate::terrain::lod::LodFrame;
use crate::terrain::shading::{declare_draw_pass, DrawPass, SurfaceInputs, TerrainDrawPush};
use crate::terrain::shadow::ComputeCasters;
use crate::terrain::visibility::{ComputePass, ComputeRaster, ComputeShading, ComputeView, RasterPath};
use crate::texturing::generation::{AtlasBindings, GenerationInputs};
use crate::view::deferred::{GroundKeys, SplatSums};
use crate::view::{
    pass_name, per_view, Declare, Frame, FrameContext, Provides, SceneTargets, Technique, View, ViewGraph, ViewIndex,
};
use crate::vulkan::Context;

/// How `terrain.draw` colours the surface (§7.4.3 or §8.2).
pub struct TerrainTexturing<'a> {
    pub mode: TexturingMode,
    pub layers: &'a LayerTree,
    /// Extra input maps of the layers ([`crate::surface::input_maps`]).
    pub input_maps: &'a [Option<HeightField>; 3],
}

/// One view's terrain resources.
struct TerrainViewState {
    index: ViewIndex,
    lod: LodFrame,
    /// The warped sketch map (per frame).
    warp: UploadRegion,
    /// The texturing constants `terrain.draw` writes and reads (per frame).
    constants: UploadRegion,
    vertices: BufferId,
    /// The compute path's view constants (per frame; compute path only).
    compute: Option<UploadRegion>,
    /// Whether `terrain.draw` of the view was declared.
    drawn: bool,
    /// The compute path's `terrain.shade` still to declare
    /// ([`ComputeShading::WithSplats`]) and the view's visibility keys.
    unshaded: Option<(ComputePass, GroundKeys)>,
}

/// The compute path's pipelines and when it shades.
struct ComputePath {
    raster: ComputeRaster,
    /// The shadow casters in compute (None: `terrain.shadow` draws them).
    casters: Option<ComputeCasters>,
    shading: ComputeShading,
}

#[cfg(test)]
thread_local! {
    /// Tests: the compute path keeps the hardware's shadow casters (to
    /// compare the compute casters against them on otherwise equal frames).
    pub(crate) static HARDWARE_CASTERS: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The terrain: persistent GPU state, `terrain.warp` and `terrain.draw` per
/// view, and the CPU LOD of every view in `prepare`.
pub struct Terrain {
    geometry: GeometryImage,
    mode: TexturingMode,
    layer_count: u32,
    atlas: ImageId,
    noise: ImageId,
    indices: BufferId,
    layers: LayerTable,
    maps: InputMaps,
    views: Vec<TerrainViewState>,
    /// The previous frame's prepared views, reused ([`Technique::recycle`]).
    spare: Vec<TerrainViewFrame>,
    /// None: the hardware path (`terrain.draw`).
    compute: Option<ComputePath>,
    /// The streamed detail window ([`Terrain::stream_detail`]).
    detail: Option<(DetailWindow, crate::terrain::detail::DetailDevice)>,
}

/// What the terrain passes read this frame.
pub struct TerrainFrame {
    pub views: Vec<TerrainViewFrame>,
    /// What `terrain.detail` uploads and the window `terrain.warp` reads.
    pub detail: DetailUploads,
}

/// One view's prepared push constants of `terrain.draw` (its handles come
/// from the pass's bindings).
#[derive(Clone, Copy, Debug)]
pub struct TerrainViewFrame {
    pub view: ViewIndex,
    pub draw: TerrainDrawPush,
}

impl TerrainFrame {
    /// The prepared data of view `index`.
    pub fn view(&self, index: ViewIndex) -> Result<&TerrainViewFrame> {
        per_view(&self.views, index, |v| v.view)
            .ok_or_else(|| Error::Graph(format!("terrain: view {index} was not prepared")))
    }
}

impl Terrain {
    /// Uploads the height field, the noise tile, the surface layers and
    /// their input maps, and imports them into `graph`.
    pub fn new<S: Provides<TerrainFrame> + 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        field: Arc<HeightField>,
        settings: TerrainSettings,
        texturing: &TerrainTexturing,
    ) -> Result<Terrain> {
        let geometry = GeometryImage::new(ctx, field, settings)?;
        let maps = InputMaps::import(ctx, graph, texturing.layers, texturing.input_maps, &geometry.field)?;
        let layer_count = texturing.layers.layers.len() as u32;
        if layer_count == 0 {
            return Err(Error::invalid("surface layers", "the tree has no layer"));
        }
        Ok(Terrain {
            atlas: graph.import_image(geometry.atlas.clone()),
            noise: graph.import_image(geometry.noise.clone()),
            indices: graph.import_buffer(geometry.indices.clone()),
            layers: LayerTable::declare(graph, texturing.layers),
            geometry,
            mode: texturing.mode,
            layer_count,
            maps,
            views: Vec::new(),
            spare: Vec::new(),
            compute: None,
            detail: None,
        })
    }

    /// Streams detail finer than the resident field from `source` near
    /// the camera ([`crate::terrain::detail`]): declares `terrain.detail`.
    /// Before any [`Terrain::declare_warp`]; nothing when `source` asks
    /// for no window or the resident level is the finest.
    pub fn stream_detail<S: Provides<TerrainFrame> + 'static>(
        &mut self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        source: &DetailSource,
    ) -> Result<()> {
        if !self.views.is_empty() {
            return Err(Error::Graph(
                "terrain: the detail window is declared before the views".into(),
            ));
        }
        if let Some(window) = DetailWindow::open(source)? {
            let device = declare_detail_upload(ctx, graph, &window)?;
            self.detail = Some((window, device));
        }
        Ok(())
    }

    /// Rasterizes and shades the terrain in compute shaders (the visibility
    /// buffer, [`crate::terrain::visibility`]) instead of `terrain.draw`,
    /// shaded as `shading` says. Before any [`Terrain::declare_warp`].
    pub fn use_compute_raster(&mut self, ctx: &Context, shading: ComputeShading) -> Result<()> {
        if !self.views.is_empty() {
            return Err(Error::Graph(
                "terrain: the raster path is chosen before the views are declared".into(),
            ));
        }
        #[cfg(test)]
        let hardware_casters = HARDWARE_CASTERS.get();
        #[cfg(not(test))]
        let hardware_casters = false;
        self.compute = Some(ComputePath {
            raster: ComputeRaster::new(ctx, shading)?,
            casters: (!hardware_casters).then(|| ComputeCasters::new(ctx)).transpose()?,
            shading,
        });
        Ok(())
    }

    /// The compute path's `terrain.shade` of the view with the points'
    /// `sums` ([`ComputeShading::WithSplats`]): declared after the view's
    /// points passes, which wrote them.
    pub fn declare_shade<S: Provides<TerrainFrame> + Provides<PreparedLighting> + 'static>(
        &mut self,
        at: ViewGraph<'_, S>,
        (targets, sums): (&SceneTargets, SplatSums),
    ) -> Result<()> {
        let (graph, index, view) = (at.graph, at.index, at.view);
        let unshaded = (self.views.iter_mut().find(|v| v.index == index)).and_then(|v| v.unshaded.take());
        let (Some(path), Some((pass, keys))) = (&self.compute, unshaded) else {
            return Err(Error::Graph(format!(
                "terrain.shade of view {index}: the view's compute passes left no shading for the splats"
            )));
        };
        path.raster
            .declare_shade_with_splats(graph, view, &pass, (keys, sums), targets)
    }

    /// Whether `terrain.shade` shades the sky too (the compute path): then
    /// no `sky` pass is declared for the views.
    pub fn shades_sky(&self) -> bool {
        self.compute.is_some()
    }

    /// The compute path's shadow casters, if it has them.
    pub(super) fn compute_casters(&self) -> Option<&ComputeCasters> {
        self.compute.as_ref().and_then(|c| c.casters.as_ref())
    }

    /// Side of the geometry image's grid.
    pub(super) fn grid_side(&self) -> u32 {
        self.geometry.settings.grid_side
    }

    /// The rasterizer the terrain is drawn with (for profiles).
    pub fn raster_path(&self) -> RasterPath {
        match self.compute {
            Some(_) => RasterPath::Compute,
            None => RasterPath::Hardware,
        }
    }

    /// What the texture atlas's generation passes read.
    pub fn generation_inputs<'a>(&self, tree: &'a LayerTree) -> GenerationInputs<'a> {
        GenerationInputs {
            field: self.geometry.field.clone(),
            heights: self.atlas,
            noise: self.noise,
            layers: self.layers.clone(),
            maps: self.maps,
            tree,
            window: self.detail.as_ref().map(|(_, d)| d.image),
        }
    }

    /// Declares `terrain.warp` of view `index`, with its geometry image.
    pub fn declare_warp<S: Provides<TerrainFrame> + 'static>(
        &mut self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
    ) -> Result<()> {
        let vertex_buffer = self.geometry.vertex_buffer(ctx, &view.name)?;
        let vertices = graph.import_buffer(vertex_buffer);
        let warp = graph.upload_region(
            &pass_name("terrain warp", &view.name),
            self.geometry.warp_upload_bytes(),
        );
        let constants = graph.upload_region(
            &pass_name("terrain texturing", &view.name),
            std::mem::size_of::<TexturingFrame>() as u64,
        );
        let pass = WarpPass {
            view: index,
            atlas: self.atlas,
            noise: self.noise,
            upload: warp,
            vertices,
            push: self.geometry.warp_push(),
            window: self.detail.as_ref().map(|(_, d)| d.image),
        };
        declare_warp_pass(ctx, graph, &pass_name("terrain.warp", &view.name), pass)?;
        let compute = self.compute.as_ref().map(|_| {
            let name = pass_name("terrain compute view", &view.name);
            graph.upload_region(&name, std::mem::size_of::<ComputeView>() as u64)
        });
        self.views.push(TerrainViewState {
            index,
            lod: LodFrame::default(),
            warp,
            constants,
            vertices,
            compute,
            drawn: false,
            unshaded: None,
        });
        Ok(())
    }

    /// View `index`'s geometry image (vertex buffer), the grid's index
    /// buffer and its index count, and the height field's box (x, y over
    /// the extent, z over the height range): what `terrain.shadow` draws.
    pub fn shadow_geometry(&self, index: ViewIndex) -> Result<(BufferId, BufferId, u32, [f64; 6])> {
        let state = (self.views.iter().find(|v| v.index == index))
            .ok_or_else(|| Error::Graph(format!("terrain.shadow of view {index} before its terrain.warp")))?;
        let side = self.geometry.settings.grid_side;
        let field = &self.geometry.field;
        let (lo, hi) = field.min_max();
        let extent = field.extent();
        let bounds = [0.0, 0.0, f64::from(lo), extent.x, extent.y, f64::from(hi)];
        Ok((state.vertices, self.indices, (side - 1) * (side - 1) * 6, bounds))
    }

    /// The texturing constants of `terrain.draw` (`TerrainTexturing` in
    /// glsl/include/texture_atlas.glsl) but for their heap handles, which
    /// the pass puts in from its bindings.
    fn texturing_constants(&self, atlas: Option<&AtlasBindings>) -> TexturingFrame {
        let field = &self.geometry.field;
        let (lo, hi) = field.min_max();
        let extent = field.extent();
        let mut frame = TexturingFrame {
            handles: [0, 0, 0, self.mode.code()],
            grid: [field.columns, field.rows, self.layer_count, 0],
            spacing_range: [field.spacing.x as f32, field.spacing.y as f32, lo, hi],
            extent: [extent.x as f32, extent.y as f32, 0.0, 0.0],
            draw: self.geometry.settings.draw_constants(),
            ..TexturingFrame::zeroed()
        };
        if let Some(a) = atlas {
            frame.atlas = [0, a.colors.len() as u32, a.atlas_size, 0];
        }
        frame
    }
}

impl Terrain {
    /// The detail window of the frame's first view's camera: the tiles
    /// that arrived into the upload region, the window's constants.
    fn prepare_detail(&mut self, frame: &mut FrameContext<'_, '_>) -> Result<DetailUploads> {
        let (Some((window, device)), Some(view)) = (&mut self.detail, frame.views.first()) else {
            return Ok(DetailUploads::default());
        };
        let uploads = window.update(view.camera.eye, &self.geometry.field)?;
        device.write(&uploads, window.tile_side(), frame.uploads)?;
        Ok(DetailUploads {
            tiles: uploads.len() as u32,
            tile_side: window.tile_side(),
            push: window.push(),
        })
    }

    /// The CPU LOD of every view (§7.4.2: sketch map, importance, warp),
    /// the views in parallel threads: they share only the height field.
    fn plan_views(&mut self, views: &[View]) -> Result<()> {
        let field = &self.geometry.field;
        let settings = self.geometry.settings;
        let debug = settings.view.debug_scalar();
        let plan = |state: &mut TerrainViewState| -> Result<()> {
            let view = (views.get(state.index))
                .ok_or_else(|| Error::Graph(format!("terrain: the frame has no view {}", state.index)))?;
            let culling = view.culling_camera();
            state
                .lod
                .plan(field, &culling, view.culling_aspect(), &settings.lod, debug)
        };
        if self.views.len() == 1 {
            return self.views.iter_mut().try_for_each(plan);
        }
        std::thread::scope(|scope| {
            let plan = &plan;
            let threads: Vec<_> = (self.views.iter_mut())
                .map(|state| scope.spawn(move || plan(state)))
                .collect();
            threads.into_iter().try_for_each(|t| {
                t.join()
                    .unwrap_or_else(|_| Err(Error::Graph("terrain: a view's LOD thread panicked".into())))
            })
        })
    }
}

/// `terrain.draw` of a view (after its `terrain.warp`): its targets and the
/// texture atlas's bindings (None: texturing in the draw) in; out, on the
/// compute path, the view's visibility keys.
impl<S: Provides<TerrainFrame> + Provides<PreparedLighting> + 'static> Declare<S> for Terrain {
    type Inputs<'a> = (&'a SceneTargets, Option<&'a AtlasBindings>);
    type Outputs = Option<GroundKeys>;

    /// Declares `terrain.draw` of view `index` into `targets`, textured from
    /// `atlas` when given (after [`Terrain::declare_warp`] of that view), or
    /// the compute path's passes (`terrain.shade` left for
    /// [`Terrain::declare_shade`] with [`ComputeShading::WithSplats`]).
    fn declare(&mut self, at: ViewGraph<'_, S>, (targets, atlas): Self::Inputs<'_>) -> Result<Option<GroundKeys>> {
        let (ctx, graph, index, view) = (at.ctx, at.graph, at.index, at.view);
        let texturing = self.texturing_constants(atlas);
        let state = (self.views.iter_mut().find(|v| v.index == index))
            .ok_or_else(|| Error::Graph(format!("terrain.draw of view {index} before its terrain.warp")))?;
        state.drawn = true;
        let side = self.geometry.settings.grid_side;
        let surface = SurfaceInputs {
            noise: self.noise,
            heights: self.atlas,
            layers: self.layers.clone(),
            maps: self.maps,
            constants: state.constants,
            texturing,
            atlas: atlas.cloned(),
            window: self.detail.as_ref().map(|(_, d)| d.image),
        };
        if let (Some(path), Some(constants)) = (&self.compute, state.compute) {
            let pass = ComputePass {
                vertices: state.vertices,
                grid_side: side,
                constants,
                surface,
                shading: path.shading,
                view: index,
            };
            let keys = path.raster.declare(ctx, graph, view, &pass, targets)?;
            if path.shading == ComputeShading::WithSplats {
                state.unshaded = Some((pass, keys));
            }
            return Ok(Some(keys));
        }
        let pass = DrawPass {
            view: index,
            vertices: state.vertices,
            indices: self.indices,
            index_count: (side - 1) * (side - 1) * 6,
            surface,
        };
        declare_draw_pass(ctx, graph, &pass_name("terrain.draw", &view.name), pass, targets)?;
        Ok(None)
    }
}

impl Technique for Terrain {
    type Prepared = TerrainFrame;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "terrain"
    }

    /// Per view: sketch map, importance map and warp (§7.4.2) into the
    /// warp upload, and the push constants of `terrain.draw`.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<TerrainFrame> {
        let mut views = std::mem::take(&mut self.spare);
        views.clear();
        let settings = self.geometry.settings;
        self.plan_views(frame.views)?;
        let detail = self.prepare_detail(frame)?;
        for (k, state) in self.views.iter().enumerate() {
            let view = frame
                .views
                .get(state.index)
                .ok_or_else(|| Error::Graph(format!("terrain: the frame has no view {}", state.index)))?;
            if !state.drawn {
                return Err(Error::Graph(format!("terrain.draw of view {k} was not declared")));
            }
            frame
                .uploads
                .write(state.warp, bytemuck::cast_slice(&state.lod.upload))?;
            let camera = &view.camera;
            let pixel_footprint = view.pixel_footprint();
            let draw = TerrainDrawPush {
                view_proj: view.view_proj().to_cols_array(),
                eye: camera.eye.as_vec3().extend(self.geometry.atlas_spacing()).to_array(),
                forward: camera.forward().as_vec3().extend(pixel_footprint as f32).to_array(),
                lighting: [0; 4],
                detail_amplitude: settings.detail_amplitude,
                detail_h: settings.detail_h,
                noise_tile: 0,
                texturing_frame: 0,
            };
            if let Some(region) = state.compute {
                let constants = ComputeView::new(view, settings.grid_side, &draw);
                frame.uploads.write(region, bytemuck::bytes_of(&constants))?;
            }
            views.push(TerrainViewFrame {
                view: state.index,
                draw,
            });
        }
        Ok(TerrainFrame { views, detail })
    }

    fn recycle(&mut self, previous: TerrainFrame) {
        self.spare = previous.views;
    }
}
