//! The wiring list of the renderer: every technique's passes of every
//! view declared into the frame graph in execution order, each view's post
//! chain and outputs, and the orderings kept for old validation layers.

use std::sync::Arc;

use super::lighting;
use super::outputs::Outputs;
use super::readback::Readback;
use super::view_chain::ViewChain;
use super::{RenderFrame, RenderSettings, Scene, Techniques};
use crate::error::Result;
use crate::graph::RenderGraph;
use crate::lighting::sky::Sky;
use crate::lighting::technique::SceneLighting;
use crate::points::render::PointRenderer;
use crate::post::aovs::Aovs;
use crate::post::exposure::ExposureMeter;
use crate::post::motion_blur::MotionBlur;
use crate::post::resolve::Resolve;
use crate::post::tonemap::Tonemap;
use crate::surface::gpu_layout::TexturingMode;
use crate::terrain::visibility::ComputeShading;
use crate::terrain::{Terrain, TerrainTexturing};
use crate::texturing::generation::{TextureAtlas, TextureStreaming};
use crate::view::{declare_views, Declare, LightingSetup, SceneTargets, View, ViewGraph};
use crate::vulkan::Context;

/// What the techniques are declared for.
pub(super) struct Wiring<'a> {
    pub(super) ctx: &'a Context,
    pub(super) scene: &'a Scene,
    pub(super) settings: &'a RenderSettings,
    pub(super) views: &'a [View],
}

impl Wiring<'_> {
    /// The wiring list: every technique's passes of every view, in
    /// execution order (the graph runs passes in the order declared); a
    /// technique's inputs are what earlier ones returned. Beyond what the
    /// data orders, two edges are kept for validation layers before
    /// 1.3.268, which count a dispatch as writing every buffer of the heap
    /// (the geometry images included), marked "Edge" below. Adding a
    /// technique: its folder, a slot in [`Slots`], one line here (and its
    /// prepare in [`Renderer::prepare_and_execute`]).
    pub(super) fn declare(
        &self,
        graph: &mut RenderGraph<RenderFrame>,
        chains: &[ViewChain],
        setup: LightingSetup,
        progress: &mut dyn FnMut(f32),
    ) -> Result<(Techniques, Vec<SceneTargets>)> {
        let (ctx, scene, settings, views) = (self.ctx, self.scene, self.settings, self.views);
        let points_present = !scene.points.is_empty();
        // The lighting declares each view's constants; the targets carry them.
        let regions: Vec<_> = (views.iter())
            .map(|v| SceneLighting::declare_constants(graph, v))
            .collect();
        let mut targets: Vec<SceneTargets> = (views.iter().zip(&regions))
            .map(|(v, &region)| SceneTargets::declare(graph, v, points_present, region))
            .collect();
        let mut scene_lighting = lighting::scene_lighting(scene, regions);
        // The lighting's lookup tables and maps first: every shading pass reads them.
        lighting::declare_atmosphere(ctx, graph, (views, &setup), (&mut targets, &mut scene_lighting))?;
        if scene.draw_terrain {
            let parts = (&mut targets[..], &mut scene_lighting);
            lighting::declare_sky_light(
                ctx,
                graph,
                (scene, &setup),
                parts,
                settings.cache_dir.as_deref(),
                progress,
            )?;
        }
        // Each view's shadow atlas before its sky (or terrain.shade): that
        // pass writes the view's lighting constants, which name the atlas.
        let casters = scene.draw_terrain || points_present;
        let atlases = lighting::shadow_atlases(ctx, graph, (views, &mut targets), casters, &settings.shadows)?;
        let mut points = match points_present {
            true => Some(PointRenderer::new(
                ctx,
                &scene.points,
                settings.points,
                settings.raster.uses_compute(ctx)?,
            )?),
            false => None,
        };
        let mut terrain = match scene.draw_terrain {
            true => Some(warped_terrain(ctx, graph, (scene, points.as_ref()), settings, views)?),
            false => None,
        };
        // The compute path's `terrain.shade` shades the sky where no terrain is.
        if !terrain.as_ref().is_some_and(Terrain::shades_sky) {
            declare_views(&mut Sky::new(ctx)?, ctx, graph, views, &targets)?;
        }
        // Edge (validation_layer_edges): the atlas's generation passes before the shadow casters.
        let atlas = match (&terrain, settings.texturing) {
            (Some(terrain), TexturingMode::Atlas) => Some(TextureAtlas::declare(
                ctx,
                graph,
                terrain.generation_inputs(&scene.layers),
                streaming_for(settings, chains),
            )?),
            _ => None,
        };
        let casters = (terrain.as_ref(), points.as_ref());
        let shadows = lighting::declare_shadows(ctx, graph, (views, atlases), casters, settings.shadows)?;
        // Edge (validation_layer_edges): every view's draws before any post-processing.
        let mut ground_keys = vec![None; views.len()];
        if let Some(terrain) = &mut terrain {
            let atlas = atlas.as_ref().map(|a| a.bindings());
            ground_keys = declare_views(terrain, ctx, graph, views, targets.iter().map(|t| (t, atlas)))?;
        }
        if let Some(points) = &mut points {
            let clear_depth = !scene.draw_terrain;
            // On the compute path the splats test against the terrain's
            // visibility keys and `terrain.shade` resolves their sums.
            let shaded_by_terrain = terrain_shades_splats(terrain.as_ref(), points, ctx);
            let ground = |keys: Option<_>| keys.filter(|_| shaded_by_terrain);
            let inputs = (targets.iter().zip(&ground_keys)).map(|(t, &keys)| (t, clear_depth, ground(keys)));
            let sums = declare_views(points, ctx, graph, views, inputs)?;
            if let Some(terrain) = &mut terrain {
                for (k, (view, sums)) in views.iter().zip(sums).enumerate() {
                    if let Some(sums) = sums {
                        terrain.declare_shade(ViewGraph::new(ctx, graph, (k, view)), (&targets[k], sums))?;
                    }
                }
            }
        }
        let mut aovs = Aovs::new(ctx)?;
        declare_views(&mut aovs, ctx, graph, views, &targets)?;
        validation_layer_edges(graph);
        let techniques = Techniques {
            lighting: scene_lighting,
            shadows,
            terrain,
            atlas,
            points,
            aovs,
            overlay: None,
        };
        Ok((techniques, targets))
    }
}

/// The orderings beyond the declared accesses, kept for validation layers
/// before 1.3.268, which count a dispatch as writing every buffer of the
/// bindless heap (the geometry images included): a pass's barrier on a
/// geometry image must come after those dispatches, so the atlas's
/// generation passes precede the shadow casters, and every view's draws
/// precede any view's post-processing (the other views' geometry images).
/// The graph checks them at bake.
fn validation_layer_edges(graph: &mut RenderGraph<RenderFrame>) {
    const ATLAS: &str = "validation layers before 1.3.268: the shadow casters' geometry-image barrier \
                         must follow the atlas's dispatches";
    const DRAWS: &str = "validation layers before 1.3.268: every view's draws (geometry images) \
                         before any post-processing dispatch";
    for caster in ["terrain.shadow", "points.shadow"] {
        graph.edge("texturing.", caster, ATLAS);
    }
    for draw in ["terrain.draw", "points."] {
        for post in ["aovs", "post.", "exposure", "tonemap"] {
            graph.edge(draw, post, DRAWS);
        }
    }
}

/// A view's name and its post-processed targets (what the present passes show).
pub(super) type NamedTargets = (String, SceneTargets);

/// Each view's post chain (resolve, distortion, motion blur), exposure,
/// tone mapping and readback of `outputs` into `slots` slots (none read
/// back: the display image is kept).
pub(super) fn declare_outputs(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (views, targets, chains): (&[View], &[SceneTargets], &[ViewChain]),
    settings: &RenderSettings,
    (outputs, slots): (Outputs, usize),
) -> Result<(Vec<Readback>, Vec<NamedTargets>)> {
    let mut exposure = ExposureMeter::new(ctx)?;
    let mut tonemap = Tonemap::new(ctx)?;
    let resolve = Resolve::new(ctx)?;
    let blur = match settings.motion_blur {
        Some(s) if s.shutter_s > 0.0 => Some((MotionBlur::new(ctx)?, s)),
        _ => None,
    };
    // Every view's images are final before any is read (validation layers
    // before 1.3.268 count view k's tonemap dispatch as writing view j's
    // display image: after the barrier of j's readback it would look like
    // an unsynchronised write before the present pass reads it).
    let mut displays = Vec::new();
    for (index, ((view, rendered), chain)) in views.iter().zip(targets).zip(chains).enumerate() {
        let blur = blur.as_ref().map(|(b, s)| (b, *s));
        let targets = chain.declare(graph, rendered, (&resolve, blur))?;
        let exposure = exposure.declare(ViewGraph::new(ctx, graph, (index, view)), &targets)?;
        tonemap.declare(ViewGraph::new(ctx, graph, (index, view)), (&targets, exposure))?;
        displays.push((view.name.clone(), targets));
    }
    let mut readback = Vec::new();
    for (view, (_, targets)) in views.iter().zip(&displays) {
        match Readback::declare(ctx, graph, view, targets, (outputs, slots))? {
            Some(rb) => readback.push(rb),
            None => graph.keep(targets.display),
        }
    }
    Ok((readback, displays))
}

/// The atlas streaming of `settings`, resized for supersampled renders
/// (their tiles are finer than the outputs'); the budget stays the caller's.
fn streaming_for(settings: &RenderSettings, chains: &[ViewChain]) -> TextureStreaming {
    if chains
        .iter()
        .all(|c| (c.render.width, c.render.height) == (c.output.width, c.output.height))
    {
        return settings.texture_streaming;
    }
    let sizes: Vec<(u32, u32)> = chains.iter().map(|c| (c.render.width, c.render.height)).collect();
    TextureStreaming {
        budget: settings.texture_streaming.budget,
        readback: settings.texture_streaming.readback,
        ..TextureStreaming::for_views(&sizes)
    }
}

/// Whether the terrain's compute path shades the points' splats in its
/// `terrain.shade` (issue 29: their normalization fused into it).
fn terrain_shades_splats(terrain: Option<&Terrain>, points: &PointRenderer, ctx: &Context) -> bool {
    terrain.is_some_and(Terrain::shades_sky) && points.sums_shaded_by_ground(ctx)
}

/// The terrain of `scene` with every view's `terrain.warp` declared (and
/// `points`, when the scene has them, shaded by its compute path when
/// they can be).
fn warped_terrain(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (scene, points): (&Scene, Option<&PointRenderer>),
    settings: &RenderSettings,
    views: &[View],
) -> Result<Terrain> {
    let texturing = TerrainTexturing {
        mode: settings.texturing,
        layers: &scene.layers,
        input_maps: &scene.input_maps,
    };
    let field = Arc::new(scene.heights.clone());
    let mut terrain = Terrain::new(ctx, graph, field, settings.terrain, &texturing)?;
    if let Some(source) = &scene.detail {
        terrain.stream_detail(ctx, graph, source)?;
    }
    if settings.raster.uses_compute(ctx)? {
        let shading = match points {
            Some(p) if p.sums_shaded_by_ground(ctx) => ComputeShading::WithSplats,
            // The points depth-test against the terrain's depth buffer.
            Some(_) => ComputeShading::Immediate { write_depth: true },
            None => ComputeShading::Immediate { write_depth: false },
        };
        terrain.use_compute_raster(ctx, shading)?;
    }
    for (k, view) in views.iter().enumerate() {
        terrain.declare_warp(ctx, graph, (k, view))?;
    }
    Ok(terrain)
}
