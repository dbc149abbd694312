//! Cascaded sun shadow maps (dissertation §9.5, which compares shadow maps
//! with the horizon maps of the height field; `ALGORITHMS.md` §6).
//!
//! [`ShadowMaps`] owns one shadow atlas per view: a single `D32_SFLOAT` 2-D
//! image, 2×2 quadrants, one per cascade ([`ShadowAtlas`]), imported into
//! the graph before the view's `sky` pass, which declares it and writes its
//! heap handle into the view's lighting constants. Per frame its `prepare`
//! ([`Technique`]) plans each view's cascades ([`cascades::plan_cascades`])
//! into a [`ShadowFrame`]; the lighting copies a view's [`CascadePlan`] into
//! its `LightingFrame` with [`CascadePlan::fill`].
//!
//! Passes, in this order, each writing the atlas as a depth attachment
//! (`.depth(atlas, ..)`: the graph begins and ends rendering):
//!
//! | pass | declared by | what |
//! |---|---|---|
//! | `shadow.clear` | [`ShadowMaps::declare_clear`] | clears the atlas to 1 (not on the compute path: [`ShadowMaps::adopt`]) |
//! | `terrain.shadow` | `Terrain::declare_shadow` (`src/terrain/shadow.rs`) | the view's warped geometry image, per cascade (on the compute path compute passes, copied into the atlas) |
//! | `points.shadow` | `PointShadows::declare` (`src/points/render/shadow.rs`) | splats as depth discs, per cascade |
//!
//! The caster passes read the cascade matrices from the frame's prepared
//! [`ShadowFrame`] and push them (no upload region): each cascade is one
//! draw with the scissor on its quadrant ([`record_cascades`]). Consumers
//! sample the atlas through `glsl/include/shadows.glsl` after declaring
//! `pass.sample(atlas, Stage::Fragment)` (or `Compute`) of
//! [`ShadowTarget::atlas`].

pub mod cascades;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

pub use cascades::{plan_cascades, plan_cascades_into, CascadePlan, SceneBounds, ShadowSettings};

use crate::error::{Error, Result};
use crate::graph::{BufferAccess, BufferId, BufferInfo, ImageAccess, ImageId, RenderGraph};
use crate::shaders;
use crate::view::{
    pass_name, per_view, Declare, Frame, FrameContext, ShadowMode, Technique, View, ViewGraph, ViewIndex,
};
use crate::vulkan::{
    Blend, CommandRecorder, CompareOp, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc,
    ImageUsageFlags, MemoryLocation, PrimitiveTopology,
};

/// The depth format of shadow atlases.
pub const SHADOW_FORMAT: Format = Format::D32_SFLOAT;

/// Push constants of the shadow caster passes
/// (`glsl/lighting/shadow_terrain.vert`, `glsl/lighting/shadow_points.vert`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowCasterPush {
    /// World → atlas clip space of the cascade drawn.
    pub view_proj: [f32; 16],
    /// xyz: unit vector towards the sun; w: world size (m) of one texel of the cascade.
    pub sun_texel: [f32; 4],
    /// Pass-specific heap handles and indices.
    pub handles: [u32; 4],
}

/// One view's shadow atlas in the graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowTarget {
    pub view: ViewIndex,
    /// The atlas (declare `ImageAccess::Sampled(..)` to read it).
    pub atlas: ImageId,
    /// Side in texels.
    pub size: u32,
    /// On the compute path: the atlas-sized buffer of depth bits (depth in
    /// [0, 1] orders as unsigned integers) the compute casters `atomicMin`
    /// into, copied into the atlas by `shadow.copy`; None where the casters
    /// draw into the atlas.
    pub depths: Option<BufferId>,
}

/// One view's shadow atlas, created and imported into a graph before its
/// passes are declared ([`ShadowMaps::declare_clear`]): the passes that
/// write the view's lighting constants must declare it first.
pub struct ShadowAtlas {
    target: ShadowTarget,
    /// Kept alive with the graph that imported it.
    image: Arc<Image>,
    /// The view's name (for the pass names).
    view_name: String,
}

impl ShadowAtlas {
    /// Creates view `index`'s atlas of `settings.atlas_size` and imports it
    /// into `graph`.
    pub fn new<P: 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<P>,
        (index, view): (ViewIndex, &View),
        settings: &ShadowSettings,
    ) -> Result<ShadowAtlas> {
        settings.validate()?;
        let size = settings.atlas_size;
        let image = Arc::new(Image::new(
            ctx,
            ImageDesc {
                name: pass_name("shadow atlas", &view.name),
                width: size,
                height: size,
                format: SHADOW_FORMAT,
                // Transfer: the compute casters copy their depths in.
                usage: ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | ImageUsageFlags::SAMPLED
                    | ImageUsageFlags::TRANSFER_DST,
            },
        )?);
        let atlas = graph.import_image(image.clone());
        Ok(ShadowAtlas {
            target: ShadowTarget {
                view: index,
                atlas,
                size,
                depths: None,
            },
            image,
            view_name: view.name.clone(),
        })
    }

    /// The atlas in the graph.
    pub fn id(&self) -> ImageId {
        self.target.atlas
    }
}

struct ShadowView {
    target: ShadowTarget,
    /// Kept alive with the graph that imported it.
    _image: Arc<Image>,
}

/// What the shadow passes read this frame: each view's cascades.
#[derive(Clone, Debug, Default)]
pub struct ShadowFrame {
    pub views: Vec<(ViewIndex, CascadePlan)>,
}

impl ShadowFrame {
    /// The cascades of view `index` (at `views[index]` when the views were
    /// declared in order, as the renderer does).
    pub fn view(&self, index: ViewIndex) -> Result<&CascadePlan> {
        per_view(&self.views, index, |(v, _)| *v)
            .map(|(_, p)| p)
            .ok_or_else(|| Error::Graph(format!("shadows: view {index} was not prepared")))
    }
}

/// The shadow atlases of every view and the per-frame cascade planning.
pub struct ShadowMaps {
    settings: ShadowSettings,
    bounds: SceneBounds,
    views: Vec<ShadowView>,
    /// The previous frame's plans, reused ([`Technique::recycle`]).
    spare: Vec<(ViewIndex, CascadePlan)>,
    /// The depth-only pipeline `shadow.clear` declares (never bound).
    clear_pipeline: Option<GraphicsPipeline>,
}

/// The pipeline of splat-shaped casters into a shadow atlas, depth only
/// (`glsl/lighting/shadow_points.*`, no vertex input): `points.shadow`'s,
/// and what `shadow.clear` declares (it draws nothing).
pub fn splat_caster_desc(name: &'static str) -> GraphicsPipelineDesc {
    GraphicsPipelineDesc {
        name,
        vertex: shaders::SHADOW_POINTS_VERT,
        fragment: shaders::SHADOW_POINTS_FRAG,
        vertex_stride: 0,
        vertex_attributes: Vec::new(),
        topology: PrimitiveTopology::TRIANGLE_LIST,
        cull_back_faces: false,
        wireframe: false,
        color_formats: Vec::new(),
        blend: Blend::None,
        depth_format: Some(SHADOW_FORMAT),
        depth_test: true,
        depth_write: true,
        depth_compare: CompareOp::LESS_OR_EQUAL,
    }
}

impl ShadowMaps {
    /// Shadow maps for casters inside `bounds` (see
    /// `Terrain::shadow_bounds`, `PointShadows::bounds`).
    pub fn new(settings: ShadowSettings, bounds: SceneBounds) -> Result<ShadowMaps> {
        settings.validate()?;
        if !(bounds.min.is_finite() && bounds.max.is_finite()) || bounds.min.cmpgt(bounds.max).any() {
            return Err(Error::invalid(
                "shadows.bounds",
                format!("{:?}..{:?}; must be finite, min ≤ max", bounds.min, bounds.max),
            ));
        }
        Ok(ShadowMaps {
            settings,
            bounds,
            views: Vec::new(),
            spare: Vec::new(),
            clear_pipeline: None,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &ShadowSettings {
        &self.settings
    }

    /// The box holding every caster.
    pub fn bounds(&self) -> SceneBounds {
        self.bounds
    }

    /// Creates view `index`'s atlas, imports it and declares `shadow.clear`
    /// (clears it to depth 1 each frame). Declare before the caster passes.
    pub fn declare_view<S: 'static>(
        &mut self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        (index, view): (ViewIndex, &View),
    ) -> Result<ShadowTarget> {
        let atlas = ShadowAtlas::new(ctx, graph, (index, view), &self.settings)?;
        self.declare_clear(ctx, graph, atlas)
    }

    /// Declares `shadow.clear` of an atlas created with this graph (clears
    /// it to depth 1 each frame). Declare before the caster passes.
    pub fn declare_clear<S: 'static>(
        &mut self,
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        atlas: ShadowAtlas,
    ) -> Result<ShadowTarget> {
        let view_name = atlas.view_name.clone();
        let target = self.adopt(atlas)?;
        if self.clear_pipeline.is_none() {
            self.clear_pipeline = Some(GraphicsPipeline::new(ctx, &splat_caster_desc("shadow.clear"))?);
        }
        let pipeline = self
            .clear_pipeline
            .as_ref()
            .ok_or_else(|| Error::Graph("shadows: no pipeline".into()))?;
        // Clears only: the graph begins rendering with the clear; the
        // pipeline states the attachment's format.
        graph
            .pass(&pass_name("shadow.clear", &view_name))
            .graphics()
            .pipeline(pipeline)
            .depth(target.atlas, Some(1.0))
            .record(|_, _| Ok(()));
        Ok(target)
    }

    /// Takes an atlas created with this graph whose first caster writes
    /// every texel (the terrain's compute casters,
    /// `Terrain::casts_in_compute`): no `shadow.clear`.
    pub fn adopt(&mut self, atlas: ShadowAtlas) -> Result<ShadowTarget> {
        let ShadowAtlas { target, image, .. } = atlas;
        if self.views.iter().any(|v| v.target.view == target.view) {
            return Err(Error::Graph(format!("shadows: view {} declared twice", target.view)));
        }
        if target.size != self.settings.atlas_size {
            return Err(Error::Graph(format!(
                "shadows: the atlas is {} texels, the settings {}",
                target.size, self.settings.atlas_size
            )));
        }
        self.views.push(ShadowView { target, _image: image });
        Ok(target)
    }

    /// Adopts `atlas` for compute casters: creates the buffer of depth bits
    /// they write ([`ShadowTarget::depths`]; the first caster clears it),
    /// which [`ShadowMaps::declare_copy`] copies into the atlas after them.
    pub fn adopt_compute<P: 'static>(
        &mut self,
        graph: &mut RenderGraph<P>,
        atlas: ShadowAtlas,
    ) -> Result<ShadowTarget> {
        let name = pass_name("shadow depths", &atlas.view_name);
        let mut target = self.adopt(atlas)?;
        let texels = u64::from(target.size) * u64::from(target.size);
        let info = BufferInfo {
            size: 4 * texels,
            location: MemoryLocation::GpuOnly,
        };
        target.depths = Some(graph.create_buffer(&name, info));
        if let Some(v) = self.views.iter_mut().find(|v| v.target.view == target.view) {
            v.target = target;
        }
        Ok(target)
    }

    /// `shadow.copy`: the compute casters' depth bits into the atlas of
    /// `target` (adopted with [`ShadowMaps::adopt_compute`]); declare after
    /// every caster of the view.
    pub fn declare_copy<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        target: ShadowTarget,
        view: &View,
    ) -> Result<()> {
        let depths = target
            .depths
            .ok_or_else(|| Error::Graph("shadow.copy: the atlas has no compute casters".into()))?;
        graph
            .pass(&pass_name("shadow.copy", &view.name))
            .transfer()
            .read(depths, BufferAccess::TransferSrc)
            .write(target.atlas, ImageAccess::TransferDst)
            .record(move |ctx, _| {
                let (depths, atlas) = (ctx.buffer(depths)?, ctx.image(target.atlas)?);
                ctx.cmd().copy_buffer_to_image(depths, atlas);
                Ok(())
            });
        Ok(())
    }

    /// The atlas of view `index`.
    pub fn target(&self, index: ViewIndex) -> Result<ShadowTarget> {
        self.views
            .iter()
            .find(|v| v.target.view == index)
            .map(|v| v.target)
            .ok_or_else(|| Error::Graph(format!("shadows: view {index} has no atlas")))
    }

    /// The cascades of view `index` (`view`) for `sun` (unit vector towards
    /// it). With `mode` other than [`ShadowMode::Cascaded`] the plan has no
    /// cascade and the passes only clear.
    pub fn plan(&self, index: ViewIndex, view: &View, sun: glam::Vec3, mode: ShadowMode) -> Result<CascadePlan> {
        self.target(index)?;
        let mut plan = plan_cascades(
            &view.culling_camera(),
            view.culling_aspect(),
            sun,
            self.bounds,
            &self.settings,
        )?;
        if mode != ShadowMode::Cascaded {
            plan.cascades.clear();
        }
        Ok(plan)
    }

    /// [`ShadowMaps::plan`] into `plan`, reusing its memory.
    fn plan_into(
        &self,
        plan: &mut CascadePlan,
        (index, view): (ViewIndex, &View),
        sun: glam::Vec3,
        mode: ShadowMode,
    ) -> Result<()> {
        self.target(index)?;
        let camera = view.culling_camera();
        plan_cascades_into(plan, (&camera, view.culling_aspect()), sun, self.bounds, &self.settings)?;
        if mode != ShadowMode::Cascaded {
            plan.cascades.clear();
        }
        Ok(())
    }
}

/// `shadow.clear` of a view: nothing in, the view's atlas out (the casters
/// draw into it, the shading passes sample it).
impl<S: 'static> Declare<S> for ShadowMaps {
    type Inputs<'a> = ();
    type Outputs = ShadowTarget;

    fn declare(&mut self, at: ViewGraph<'_, S>, (): ()) -> Result<ShadowTarget> {
        self.declare_view(at.ctx, at.graph, (at.index, at.view))
    }
}

impl Technique for ShadowMaps {
    type Prepared = ShadowFrame;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "shadows"
    }

    /// Plans every declared view's cascades for the frame's sun.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<ShadowFrame> {
        let sun = frame.lighting.sun;
        let mut views = std::mem::take(&mut self.spare);
        views.truncate(self.views.len());
        for (k, v) in self.views.iter().enumerate() {
            let index = v.target.view;
            let view = frame
                .views
                .get(index)
                .ok_or_else(|| Error::Graph(format!("shadows: the frame has no view {index}")))?;
            if views.len() <= k {
                views.push((index, self.plan(index, view, sun, frame.lighting.shadows)?));
                continue;
            }
            views[k].0 = index;
            self.plan_into(&mut views[k].1, (index, view), sun, frame.lighting.shadows)?;
        }
        Ok(ShadowFrame { views })
    }

    fn recycle(&mut self, previous: ShadowFrame) {
        self.spare = previous.views;
    }
}

/// Each cascade of `plan` (as many as it casts: none with the sun below
/// the horizon) with its index, its receivers' texel box
/// ([`cascades::Cascade::receivers`]) and caster push constants (`handles`
/// left to the pass).
pub fn cascade_pushes(plan: &CascadePlan) -> impl Iterator<Item = (u32, [u32; 4], ShadowCasterPush)> + '_ {
    let count = plan.count() as usize;
    (plan.cascades.iter().take(count).enumerate()).map(|(i, c)| {
        let push = ShadowCasterPush {
            view_proj: c.view_proj.as_mat4().to_cols_array(),
            sun_texel: plan.sun.as_vec3().extend(c.texel as f32).to_array(),
            handles: [0; 4],
        };
        (i as u32, c.receivers, push)
    })
}

/// Records a caster pass, which declared the atlas its depth attachment
/// (loaded: `.depth(atlas, None)`): per cascade of `plan` sets the scissor
/// on its receivers' texels in its quadrant and calls `draw` with the
/// cascade's push constants (`handles` left to `draw`).
pub fn record_cascades(
    cmd: &mut CommandRecorder,
    plan: &CascadePlan,
    mut draw: impl FnMut(&mut CommandRecorder, ShadowCasterPush) -> Result<()>,
) -> Result<()> {
    for (_, [x0, y0, x1, y1], push) in cascade_pushes(plan) {
        cmd.set_scissor(x0, y0, x1 + 1 - x0, y1 + 1 - y0);
        draw(cmd, push)?;
    }
    Ok(())
}
