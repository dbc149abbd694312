//! The lighting parts of the frame graph (§9), composed: the lighting
//! technique that writes each view's constants, and the sun's shadow maps
//! with their caster passes (terrain and points). Declared before any
//! shading pass, so every shading pass reads what they write.

use std::path::Path;

use crate::error::Result;
use crate::graph::{RenderGraph, UploadRegion};
use crate::lighting::atmosphere::{AtmosphereParameters, LutSizes, PhysicalAtmosphere};
use crate::lighting::reference::{MonteCarloReference, ReferenceSettings};
use crate::lighting::shadows::{ShadowAtlas, ShadowMaps, ShadowSettings};
use crate::lighting::sky_light::{BakeSettings, SkyLight, SkyLightBake};
use crate::lighting::technique::{FieldInfo, PreparedLighting, SceneLighting};
use crate::points::render::shadow::PointShadows;
use crate::points::render::PointRenderer;
use crate::terrain::Terrain;
use crate::view::{Declare, LightingMap, LightingSetup, SceneTargets, View, ViewGraph};
use crate::vulkan::Context;

use super::{RenderFrame, Scene};

/// The sun's shadow maps and their point casters.
pub(super) struct SunShadows {
    pub maps: ShadowMaps,
    pub points: Option<PointShadows>,
}

/// The scene's lighting technique, writing every view's lighting constants
/// into `regions` ([`SceneLighting::declare_constants`]).
pub(super) fn scene_lighting(scene: &Scene, regions: Vec<UploadRegion>) -> SceneLighting {
    let field = &scene.heights;
    let extent = field.extent();
    let (lo, _) = scene.height_range();
    SceneLighting::new(
        regions,
        FieldInfo {
            extent: [extent.x as f32, extent.y as f32],
            texels: [
                field.columns.saturating_sub(1) as f32,
                field.rows.saturating_sub(1) as f32,
            ],
            ground: lo,
        },
    )
}

/// Creates each view's shadow atlas (when the scene has casters) and adds
/// it to what the view's shading passes read: before the views' `sky`
/// passes, which write the lighting constants that name it.
pub(super) fn shadow_atlases(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (views, targets): (&[View], &mut [SceneTargets]),
    casters: bool,
    settings: &ShadowSettings,
) -> Result<Vec<ShadowAtlas>> {
    if !casters {
        return Ok(Vec::new());
    }
    let mut atlases = Vec::with_capacity(views.len());
    for (k, (view, targets)) in views.iter().zip(targets).enumerate() {
        let atlas = ShadowAtlas::new(ctx, graph, (k, view), settings)?;
        targets.lighting.images.push((LightingMap::ShadowAtlas, atlas.id()));
        atlases.push(atlas);
    }
    Ok(atlases)
}

/// Declares each view's `shadow.clear` of its atlas ([`shadow_atlases`])
/// and its casters (`terrain.shadow` after the view's `terrain.warp`,
/// `points.shadow`). None without casters.
pub(super) fn declare_shadows(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (views, atlases): (&[View], Vec<ShadowAtlas>),
    (terrain, points): (Option<&Terrain>, Option<&PointRenderer>),
    settings: ShadowSettings,
) -> Result<Option<SunShadows>> {
    let terrain_bounds = terrain.map(|t| t.shadow_bounds(0)).transpose()?;
    let point_bounds = points.and_then(PointShadows::bounds);
    let bounds = match (terrain_bounds, point_bounds) {
        (Some(a), Some(b)) => a.union(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => return Ok(None),
    };
    let mut maps = ShadowMaps::new(settings, bounds)?;
    let mut casters = points.map(|p| PointShadows::new(p, &maps));
    if atlases.len() != views.len() {
        return Err(crate::error::Error::Graph("shadows: a view has no atlas".into()));
    }
    for (k, (view, atlas)) in views.iter().zip(atlases).enumerate() {
        // The compute casters write every texel (the terrain's clear their
        // depth bits first): no clear; the bits are copied in after them.
        let compute = terrain.is_some_and(Terrain::casts_in_compute);
        let target = match compute {
            true => maps.adopt_compute(graph, atlas)?,
            false => maps.declare_clear(ctx, graph, atlas)?,
        };
        if let Some(terrain) = terrain {
            terrain.declare_shadow(ctx, graph, (k, view), target)?;
        }
        if let Some(casters) = &mut casters {
            casters.declare(ViewGraph::new(ctx, graph, (k, view)), target)?;
        }
        if compute {
            maps.declare_copy(graph, target, view)?;
        }
    }
    Ok(Some(SunShadows { maps, points: casters }))
}

/// Bakes the height field's sky-light transfer (or loads it from `cache`),
/// declares `lighting.environment` and `lighting.sky_light`, and, when the
/// first frames use it, the Monte Carlo reference's `lighting.reference`;
/// adds their maps to what the view's shading passes read.
pub(super) fn declare_sky_light(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (scene, lighting): (&Scene, &LightingSetup),
    (targets, scene_lighting): (&mut [SceneTargets], &mut SceneLighting),
    cache: Option<&Path>,
    progress: &mut dyn FnMut(f32),
) -> Result<()> {
    let region = targets[0].lighting.constants;
    let sky_inputs = targets[0].lighting.image_ids();
    let bake = SkyLightBake::bake(
        ctx,
        &scene.heights,
        &BakeSettings::from_setup(lighting),
        cache,
        progress,
    )?;
    let sky_light = SkyLight::new(ctx, bake)?;
    let refresh = |frame: &RenderFrame| (frame.prepared::<PreparedLighting>()).map_or(true, |p| p.refresh.environment);
    let ids = sky_light.declare(graph, region, &sky_inputs, refresh);
    for t in targets.iter_mut() {
        (t.lighting.images).extend([(LightingMap::SkyLight, ids.map), (LightingMap::Horizon, ids.horizon)]);
        (t.lighting.buffers).push((LightingMap::Environment, ids.environment));
    }
    scene_lighting.sky_light = Some(sky_light);
    if lighting.reference {
        let [targets] = targets else {
            return Err(crate::error::Error::invalid(
                "lighting.sky_light",
                "the Monte Carlo reference renders one view, not a rig",
            ));
        };
        let settings = ReferenceSettings {
            bounces: lighting.bounces,
            bounce_albedo: lighting.bounce_albedo,
            ..ReferenceSettings::default()
        };
        // The surface the bake traces (the B-spline at the samples), so
        // that the cheap methods and the reference see the same terrain.
        let drawn = crate::surface::bspline::knot_field(&scene.heights);
        let reference = MonteCarloReference::new(ctx, &drawn, settings)?;
        let images = reference.declare(graph, region, &sky_inputs);
        targets.lighting.images.extend([
            (LightingMap::ReferenceSkyLight, images.sky_light),
            (LightingMap::ReferenceSunVisibility, images.sun_visibility),
        ]);
        scene_lighting.reference = Some(reference);
    }
    Ok(())
}

/// The physical atmosphere's lookup tables: `lighting.transmittance`,
/// `lighting.multiscattering` and the view's `lighting.sky_view`, declared
/// first, read by every pass that evaluates the sky.
pub(super) fn declare_atmosphere(
    ctx: &Context,
    graph: &mut RenderGraph<RenderFrame>,
    (views, lighting): (&[View], &LightingSetup),
    (targets, scene_lighting): (&mut [SceneTargets], &mut SceneLighting),
) -> Result<()> {
    let params = AtmosphereParameters::for_turbidity(lighting.turbidity)?;
    let atmosphere = PhysicalAtmosphere::new(ctx, &params, LutSizes::default(), views.len())?;
    let regions: Vec<(&str, _)> = (views.iter().zip(targets.iter()))
        .map(|(v, t)| (v.name.as_str(), t.lighting.constants))
        .collect();
    let refresh = |frame: &RenderFrame, table: Option<usize>| {
        (frame.prepared::<PreparedLighting>()).map_or(true, |p| match table {
            None => p.refresh.tables,
            Some(k) => p.refresh.sky_view(k),
        })
    };
    let luts = atmosphere.declare(graph, &regions, refresh)?;
    for (k, t) in targets.iter_mut().enumerate() {
        let [transmittance, multiscattering, sky_view] = luts.reads(k)?;
        t.lighting.images.extend([
            (LightingMap::Transmittance, transmittance),
            (LightingMap::Multiscattering, multiscattering),
            (LightingMap::SkyView, sky_view),
        ]);
    }
    scene_lighting.atmosphere = Some(atmosphere);
    Ok(())
}
