//! `sky_light.horizon` (§9.5; `glsl/lighting/horizon.comp`): per texel and
//! for K azimuths `φ_k = 2πk/K` (+X towards +Y), the height field is
//! marched outwards with steps growing by 3 % (at least one texel) to its
//! edge, stopping early once nothing higher can follow, and the highest
//! terrain elevation is kept: `z_h` (sine of the horizon elevation) and the
//! distance to that horizon point (for the bounces, §9.4), as
//! `packHalf2x16(z_h, distance / min(dx, dy))` per (texel, azimuth).
//!
//! Every K/16-th azimuth also goes into the sun **horizon map** (Hoffman's
//! horizon mapping): an RGBA32F image of 2×2 tiles of the field's size,
//! tile `t` holding azimuths `4t..4t+3` (elevation angles in radians), read
//! by `horizon_sun_visibility()` in `glsl/include/horizon.glsl`: the
//! shadows of `ShadowMode::Horizon`, and of `ShadowMode::Cascaded` beyond
//! the last cascade (`distant_sun_visibility()` in
//! `glsl/include/shadows.glsl`, §9.5). Traced once per terrain, it does not
//! depend on the sun: a moving sun needs no new bake. 64 bytes per bake
//! texel (the bake's grid, [`super::fit`]: at most the device's capacity,
//! about 377 000 texels or 24 MiB on lavapipe), a sixth of what the
//! transfer takes; 16 azimuths (22.5°, interpolated linearly) agree with
//! a ray cast on 98–99.8 % of a distant view's pixels (docs/LIGHTING.md).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::bake::Chunk;
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, RenderGraph, Stage};
use crate::vulkan::ComputePipeline;

/// Push constants of `glsl/lighting/horizon.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct HorizonPush {
    /// Heights, horizons (written), horizon map (storage image): written
    /// by the pass from its bindings.
    pub handles: [u32; 4],
    /// Columns, rows, azimuths K, first row of the chunk.
    pub grid: [u32; 4],
    /// dx, dy, highest height of the field.
    pub spacing: [f32; 4],
}

/// The resources of the horizon pass.
pub(crate) struct HorizonPass {
    pub heights: BufferId,
    pub horizons: BufferId,
    pub map: ImageId,
    pub push: HorizonPush,
}

/// Declares `sky_light.horizon`, dispatched per chunk of rows.
pub(crate) fn declare_horizon(graph: &mut RenderGraph<Chunk>, pipeline: Arc<ComputePipeline>, pass: HorizonPass) {
    let HorizonPass {
        heights,
        horizons,
        map,
        push,
    } = pass;
    let compute = Stage::Compute;
    let mut pass = graph.pass("sky_light.horizon");
    let handles = [
        pass.storage_buffer(heights, BufferAccess::StorageRead(compute)),
        pass.storage_buffer(horizons, BufferAccess::StorageReadWrite(compute)),
        pass.storage_image(map, ImageAccess::StorageReadWrite(compute)),
    ];
    pass.record(move |ctx, chunk| {
        let mut push = push;
        for (slot, &binding) in push.handles.iter_mut().zip(&handles) {
            *slot = ctx.handle(binding)?;
        }
        push.grid[3] = chunk.first_row;
        let groups = [push.grid[0].div_ceil(8), chunk.rows.div_ceil(8), 1];
        ctx.dispatch(&pipeline, &push, groups)
    });
}
