//! The lighting parts of the frame graph (§9), composed: the lighting
//! technique that writes each view's constants, and the sun's shadow maps
//! with their caster passes (terrain and points). Declared before any
//! shading pass, so every shading pass reads what they write.

use crate::error::Result;
use crate::graph::RenderGraph;
use crate::lighting::shadows::{ShadowMaps, ShadowSettings};
use crate::lighting::technique::{FieldInfo, SceneLighting};
use crate::points::render::shadow::PointShadows;
use crate::points::render::PointRenderer;
use crate::terrain::Terrain;
use crate::view::{Frame, SceneTargets, View};
use crate::vulkan::Context;

use super::Scene;

/// The sun's shadow maps and their point casters.
pub(super) struct SunShadows {
    pub maps: ShadowMaps,
    pub points: Option<PointShadows>,
}

/// The scene's lighting technique, writing the view's lighting constants.
pub(super) fn scene_lighting(scene: &Scene, targets: &SceneTargets) -> SceneLighting {
    let field = &scene.heights;
    let extent = field.extent();
    let (lo, _) = scene.height_range();
    SceneLighting::new(
        vec![targets.lighting.constants],
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

/// Declares the view's shadow atlas (`shadow.clear`) and its casters
/// (`terrain.shadow` after the view's `terrain.warp`, `points.shadow`), and
/// adds the atlas to what the view's shading passes read. None without
/// casters.
pub(super) fn declare_shadows(
    ctx: &Context,
    graph: &mut RenderGraph<Frame>,
    (view, targets): (&View, &mut SceneTargets),
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
    let target = maps.declare_view(ctx, graph, (0, view))?;
    if let Some(terrain) = terrain {
        terrain.declare_shadow(ctx, graph, (0, view), target)?;
    }
    let points = match points {
        Some(p) => {
            let mut casters = PointShadows::new(p, &maps);
            casters.declare(ctx, graph, (0, view), target)?;
            Some(casters)
        }
        None => None,
    };
    targets.lighting.images.push(target.atlas);
    Ok(Some(SunShadows { maps, points }))
}
