//! The compiled SPIR-V modules in `spirv/`, embedded into the library so the
//! renderer runs from any working directory. `spirv/` is produced from
//! `glsl/` by `cargo run -p alpenglow-tools --bin compile-shaders`; a test in
//! the tools crate fails when it is stale.

use crate::vulkan::SpirV;

macro_rules! spirv {
    ($path:literal) => {
        SpirV {
            name: $path,
            bytes: include_bytes!(concat!("../spirv/", $path, ".spv")),
        }
    };
}

/// terrain.warp: warp and zoom of the geometry image into the vertex buffer (compute).
pub const TERRAIN_WARP: SpirV = spirv!("terrain/warp.comp");
/// terrain.detail: the streamed tiles into the detail window (compute).
pub const TERRAIN_DETAIL_UPLOAD: SpirV = spirv!("terrain/detail_upload.comp");
/// terrain.draw: vertex stage.
pub const TERRAIN_DRAW_VERT: SpirV = spirv!("terrain/draw.vert");
/// terrain.draw: fragment stage.
pub const TERRAIN_DRAW_FRAG: SpirV = spirv!("terrain/draw.frag");
/// terrain.raster_clear: empties the compute path's visibility buffer.
pub const TERRAIN_RASTER_CLEAR: SpirV = spirv!("terrain/raster_clear.comp");
/// terrain.raster: the compute path's rasterizer, one thread a triangle.
pub const TERRAIN_RASTER: SpirV = spirv!("terrain/raster.comp");
/// terrain.raster_big: the triangles terrain.raster lists, one workgroup each.
pub const TERRAIN_RASTER_BIG: SpirV = spirv!("terrain/raster_big.comp");
/// terrain.shadow_clear: the compute casters' depth buffer at 1, their lists empty (§9.5).
pub const TERRAIN_SHADOW_CLEAR: SpirV = spirv!("terrain/shadow_clear.comp");
/// terrain.shadow (compute path): the warped grid into a cascade, one thread a triangle (§9.5).
pub const TERRAIN_SHADOW_RASTER: SpirV = spirv!("terrain/shadow_raster.comp");
/// terrain.shadow_big: the casters terrain.shadow lists, one workgroup each (§9.5).
pub const TERRAIN_SHADOW_RASTER_BIG: SpirV = spirv!("terrain/shadow_raster_big.comp");
/// terrain.shade: the visibility buffer shaded per pixel.
pub const TERRAIN_SHADE: SpirV = spirv!("terrain/shade.comp");
/// terrain.shade with the points' sums: splats normalized where they cover a pixel (issue 29).
pub const TERRAIN_SHADE_SPLATS: SpirV = spirv!("terrain/shade_splats.comp");
/// terrain.depth: the depth buffer from the compute path's NDC depth.
pub const TERRAIN_DEPTH_FRAG: SpirV = spirv!("terrain/depth.frag");
/// Every full-screen pass (sky, points.normalize): one triangle covering the screen.
pub const FULL_SCREEN_VERT: SpirV = spirv!("post/full_screen.vert");
/// sky: the sky model and sun disc per pixel (compute).
pub const SKY: SpirV = spirv!("lighting/sky.comp");
/// aovs: distance and motion from view depth and the cameras (compute).
pub const AOVS: SpirV = spirv!("post/aovs.comp");
/// overlay.draw: the viewer's overlay (egui meshes pulled from an upload region), vertex stage.
pub const OVERLAY_VERT: SpirV = spirv!("post/overlay.vert");
/// overlay.draw: fragment stage (vertex colour × font atlas, premultiplied).
pub const OVERLAY_FRAG: SpirV = spirv!("post/overlay.frag");
/// overlay.font: a rectangle of the overlay's font atlas from an upload region.
pub const OVERLAY_FONT: SpirV = spirv!("post/overlay_font.comp");
/// present.aov: one of a view's AOVs in display colours (the viewer's debug views).
pub const PRESENT_AOV: SpirV = spirv!("post/present_aov.comp");
/// tonemap: HDR → sRGB8.
pub const TONEMAP: SpirV = spirv!("post/tonemap.comp");
/// exposure.meter: sums of log luminance per 128×64-pixel tile.
pub const EXPOSURE_METER: SpirV = spirv!("post/exposure.comp");
/// exposure.average: the tiles' sums → the exposure multiplier.
pub const EXPOSURE_AVERAGE: SpirV = spirv!("post/exposure_average.comp");
/// points.*: vertex stage of every splat pass (interval test, EWA set-up).
pub const SPLAT_VERT: SpirV = spirv!("points/splat.vert");
/// points.visibility: ray–plane depth pushed back by ε.
pub const SPLAT_VISIBILITY_FRAG: SpirV = spirv!("points/visibility.frag");
/// points.accumulate: weighted colour, normal and depth, additively blended.
pub const SPLAT_ACCUMULATE_FRAG: SpirV = spirv!("points/accumulate.frag");
/// points.opaque: opaque shaded discs.
pub const SPLAT_OPAQUE_FRAG: SpirV = spirv!("points/opaque.frag");
/// points.single_pass.clear (§10.4), compute backend: every tile's entry count 0.
pub const SPLAT_SINGLE_PASS_BINS_CLEAR: SpirV = spirv!("points/single_pass_bins_clear.comp");
/// points.single_pass.count (§10.4), compute backend: the splats set up and counted into tiles.
pub const SPLAT_SINGLE_PASS_BIN: SpirV = spirv!("points/single_pass_bin.comp");
/// points.single_pass.scatter (§10.4), compute backend: the splats' tile entries written, no barrier.
pub const SPLAT_SINGLE_PASS_SCATTER: SpirV = spirv!("points/single_pass_scatter.comp");
/// points.single_pass.prefix (§10.4), compute backend: the binning workgroups' entry offsets, the sort's state.
pub const SPLAT_SINGLE_PASS_PREFIX: SpirV = spirv!("points/single_pass_prefix.comp");
/// points.single_pass.ranges (§10.4), compute backend: each tile's slice of the sorted entries.
pub const SPLAT_SINGLE_PASS_RANGES: SpirV = spirv!("points/single_pass_ranges.comp");
/// points.single_pass.radix_serial<k>.count (§10.4), compute backend, serial-blocks sort: each radix block's digit counts.
pub const SPLAT_SINGLE_PASS_RADIX_COUNT: SpirV = spirv!("points/single_pass_radix_count.comp");
/// points.single_pass.radix_serial<k>.scan (§10.4), compute backend: each (block, digit)'s entries of the earlier blocks.
pub const SPLAT_SINGLE_PASS_RADIX_SCAN: SpirV = spirv!("points/single_pass_radix_scan.comp");
/// points.single_pass.radix_serial<k>.starts (§10.4), compute backend: each digit's first output position.
pub const SPLAT_SINGLE_PASS_RADIX_STARTS: SpirV = spirv!("points/single_pass_radix_starts.comp");
/// points.single_pass.radix_serial<k>.scatter (§10.4), compute backend: each block's entries, stably, to their positions.
pub const SPLAT_SINGLE_PASS_RADIX_SCATTER: SpirV = spirv!("points/single_pass_radix_scatter.comp");
/// points.single_pass.radix_runs<k>.count (§10.4), compute backend, shared-runs sort: each radix block's digit counts.
pub const SPLAT_SINGLE_PASS_RADIX_RUNS_COUNT: SpirV = spirv!("points/single_pass_radix_runs_count.comp");
/// points.single_pass.radix_runs<k>.scan (§10.4), compute backend, shared-runs sort: each (digit, block)'s output position.
pub const SPLAT_SINGLE_PASS_RADIX_RUNS_SCAN: SpirV = spirv!("points/single_pass_radix_runs_scan.comp");
/// points.single_pass.radix_runs<k>.scatter (§10.4), compute backend, shared-runs sort: each block's entries, stably, to their positions.
pub const SPLAT_SINGLE_PASS_RADIX_RUNS_SCATTER: SpirV = spirv!("points/single_pass_radix_runs_scatter.comp");
/// points.single_pass.merge (§10.4), compute backend: per tile, its sorted slice merged front to back, shaded.
pub const SPLAT_SINGLE_PASS_TILE: SpirV = spirv!("points/single_pass_tile.comp");
/// points.single_pass (§10.4): the interlock backend's fragment stage.
pub const SPLAT_SINGLE_PASS_INTERLOCK_FRAG: SpirV = spirv!("points/single_pass_interlock.frag");
/// points.single_pass.clear (§10.4), interlock backend: every pixel's state reset.
pub const SPLAT_SINGLE_PASS_CLEAR: SpirV = spirv!("points/single_pass_clear.comp");
/// points.single_pass.resolve (§10.4), interlock backend: normalisation and shading of the pixel sums.
pub const SPLAT_SINGLE_PASS_RESOLVE: SpirV = spirv!("points/single_pass_resolve.comp");
/// points.normalize: divide by the weight and shade (compute, per pixel).
pub const SPLAT_NORMALIZE: SpirV = spirv!("points/normalize.comp");
/// points.clear (compute path): each pixel's splat state from the depth buffer (§10.2.3).
pub const SPLAT_COMPUTE_CLEAR: SpirV = spirv!("points/compute_clear.comp");
/// points.visibility (compute path): pushed-back depth and winner into 64-bit words (§10.2.3).
pub const SPLAT_COMPUTE_VISIBILITY: SpirV = spirv!("points/compute_visibility.comp");
/// points.accumulate (compute path): fixed-point weighted sums, order-independent (§10.2.3).
pub const SPLAT_COMPUTE_ACCUMULATE: SpirV = spirv!("points/compute_accumulate.comp");
/// points.normalize (compute path): the sums divided and shaded (§10.2.3).
pub const SPLAT_COMPUTE_NORMALIZE: SpirV = spirv!("points/compute_normalize.comp");
/// points.opaque (compute path): the nearest splat's index raised per pixel.
pub const SPLAT_COMPUTE_OPAQUE: SpirV = spirv!("points/compute_opaque.comp");
/// points.opaque.resolve (compute path): the winning splat shaded per pixel.
pub const SPLAT_COMPUTE_OPAQUE_RESOLVE: SpirV = spirv!("points/compute_opaque_resolve.comp");
/// points.*, object-space primitives (§10.3): quads in the tangent plane, the interval test.
pub const OBJECT_SPLAT_VERT: SpirV = spirv!("points/object_splat.vert");
/// points.visibility, object-space primitives: the pushed-back quad's depth inside the kernel's disk.
pub const OBJECT_VISIBILITY_FRAG: SpirV = spirv!("points/object_visibility.frag");
/// points.accumulate, object-space primitives: the kernel texel as weight, additively blended.
pub const OBJECT_ACCUMULATE_FRAG: SpirV = spirv!("points/object_accumulate.frag");
/// points.opaque, object-space primitives: the kernel's disk opaque, shaded directly.
pub const OBJECT_OPAQUE_FRAG: SpirV = spirv!("points/object_opaque.frag");
/// points.*, hybrid triangles (§10.1.8): vertex pulling and the test r < s/ε.
pub const HYBRID_VERT: SpirV = spirv!("points/hybrid.vert");
/// points.visibility, hybrid triangles: depth pushed back by the surfels' offset.
pub const HYBRID_VISIBILITY_FRAG: SpirV = spirv!("points/hybrid_visibility.frag");
/// points.accumulate, hybrid triangles: weight-1 colour, normal and depth.
pub const HYBRID_ACCUMULATE_FRAG: SpirV = spirv!("points/hybrid_accumulate.frag");
/// points.opaque, hybrid triangles: shaded directly.
pub const HYBRID_OPAQUE_FRAG: SpirV = spirv!("points/hybrid_opaque.frag");
/// points.visibility.triangles (compute path): pushed-back depth into the splats' nearest words (§10.1.8).
pub const HYBRID_COMPUTE_VISIBILITY_FRAG: SpirV = spirv!("points/hybrid_compute_visibility.frag");
/// points.accumulate.triangles (compute path): weight-1 sums into the splats' state (§10.1.8).
pub const HYBRID_COMPUTE_ACCUMULATE_FRAG: SpirV = spirv!("points/hybrid_compute_accumulate.frag");
/// texturing.upsample: the base surface at every texel of the dirty tiles (§8.2).
pub const TEXTURING_UPSAMPLE: SpirV = spirv!("texturing/upsample.comp");
/// texturing.layer*: one surface layer over every texel of the dirty tiles (§8.2).
pub const TEXTURING_LAYER: SpirV = spirv!("texturing/layer.comp");
/// texturing.finish: colour and displacement normal into the atlas (§8.2).
pub const TEXTURING_FINISH: SpirV = spirv!("texturing/finish.comp");
/// terrain.shadow: the warped geometry image into a cascade of the shadow atlas (§9.5).
pub const SHADOW_TERRAIN_VERT: SpirV = spirv!("lighting/shadow_terrain.vert");
/// terrain.shadow: depth only (no colour output).
pub const SHADOW_DEPTH_FRAG: SpirV = spirv!("lighting/shadow_depth.frag");
/// points.shadow: splats as depth discs in a cascade of the shadow atlas (§9.5).
pub const SHADOW_POINTS_VERT: SpirV = spirv!("lighting/shadow_points.vert");
/// points.shadow: discards outside the splat's disc.
pub const SHADOW_POINTS_FRAG: SpirV = spirv!("lighting/shadow_points.frag");
/// points.shadow (compute path): splat discs into the atlas's depth bits, a dispatch a cascade (§9.5).
pub const SHADOW_POINTS_COMPUTE: SpirV = spirv!("lighting/shadow_points.comp");
/// shadow probe: `sun_visibility` at a list of points (tests and AOV checks of §9.5).
#[cfg(test)]
pub const SHADOW_PROBE: SpirV = spirv!("lighting/shadow_probe.comp");
/// sky_light.horizon: horizon tracing of the height field and the sun horizon map (§9.5).
pub const SKY_LIGHT_HORIZON: SpirV = spirv!("lighting/horizon.comp");
/// sky_light.transfer: direct SH and patch transfer, sky visibility, bent normals (§9.3, §9.5).
pub const SKY_LIGHT_TRANSFER: SpirV = spirv!("lighting/sky_light_transfer.comp");
/// sky_light.bounce: one interreflection bounce of the transfer (§9.4).
pub const SKY_LIGHT_BOUNCE: SpirV = spirv!("lighting/sky_light_bounce.comp");
/// lighting.environment: the sky projected into SH and sky patches (§9.3, §9.5).
pub const LIGHTING_ENVIRONMENT: SpirV = spirv!("lighting/environment.comp");
/// lighting.sky_light: the per-texel sky-light map by mode (§9.3–9.5).
pub const SKY_LIGHT_EVALUATE: SpirV = spirv!("lighting/sky_light_evaluate.comp");
/// lighting.reference: Monte Carlo ray tracing of sky light on the height field (§9.2).
pub const LIGHTING_REFERENCE: SpirV = spirv!("lighting/reference.comp");
/// lighting.transmittance: the physical atmosphere's transmittance table (compute).
pub const ATMOSPHERE_TRANSMITTANCE: SpirV = spirv!("lighting/atmosphere_transmittance.comp");
/// lighting.multiscattering: the physical atmosphere's multiple-scattering table (compute).
pub const ATMOSPHERE_MULTISCATTERING: SpirV = spirv!("lighting/atmosphere_multiscattering.comp");
/// lighting.sky_view: the physical atmosphere's sky-view table of a view (compute).
pub const ATMOSPHERE_SKY_VIEW: SpirV = spirv!("lighting/atmosphere_sky_view.comp");
/// post.resolve: a supersampled image down to the output size (§3.3).
pub const POST_RESOLVE: SpirV = spirv!("post/resolve.comp");
/// post.distortion: Brown–Conrady lens distortion by a per-pixel source map (§3.3).
pub const POST_DISTORTION: SpirV = spirv!("post/distortion.comp");
/// post.motion_blur: velocity-based motion blur (§3.3).
pub const POST_MOTION_BLUR: SpirV = spirv!("post/motion_blur.comp");
/// synthesis.clear: the per-query results of a search batch reset (§7.3).
pub const SYNTHESIS_CLEAR: SpirV = spirv!("synthesis/clear.comp");
/// synthesis.distance: s(c) of every (query, candidate) and the best per query (§7.3).
pub const SYNTHESIS_DISTANCE: SpirV = spirv!("synthesis/distance.comp");
/// synthesis.accept: the smallest choice hash among the accepted candidates (§7.3).
pub const SYNTHESIS_ACCEPT: SpirV = spirv!("synthesis/accept.comp");
/// synthesis.pick: the smallest accepted candidate with that hash (§7.3).
pub const SYNTHESIS_PICK: SpirV = spirv!("synthesis/pick.comp");
/// synthesis.resolve: the pick, its s and the best s into the readback buffer (§7.3).
pub const SYNTHESIS_RESOLVE: SpirV = spirv!("synthesis/resolve.comp");
