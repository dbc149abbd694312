//! Cascaded sun shadow maps (§9.5) on a real device under validation and
//! synchronization validation: a flat plane with a long box drawn into the
//! atlas by the `terrain.shadow` pipeline (the terrain's vertex layout),
//! then `sun_visibility` (glsl/include/shadows.glsl) evaluated at surface
//! points by the shadow probe and compared with a CPU ray cast towards the
//! sun; and no acne on a lit plane for sun elevations 10°…80°.

use std::sync::Arc;

use crate::graph::{BufferAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::lighting::constants::{LightingFrame, LIGHTING_SOFT_SUN, SHADOWS_CASCADED, SUN_ANGULAR_RADIUS};
use crate::lighting::shadows::{record_cascades, SceneBounds, ShadowFrame, ShadowMaps, ShadowSettings};
use crate::points::render::shadow::PointShadowFrame;
use crate::points::render::shadow::PointShadows;
use crate::points::render::{PointRenderer, SplatSettings, SptError};
use crate::points::scene::{PointScene, PointTransform};
use crate::shaders;
use crate::terrain::shadow::shadow_pipeline;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::view::lighting::sun_direction;
use crate::view::{
    frame_slots, Camera, Declare, Frame, FrameLighting, Lighting, LightingMap, SunPosition, View, ViewGraph,
};

frame_slots! {
    /// What the shadow test's techniques prepare.
    struct Slots {
        shadows: ShadowFrame,
        point_shadows: PointShadowFrame,
    }
}
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, ComputePipeline, Context, FrameRing, MemoryLocation};
use bytemuck::Zeroable;
use glam::DVec3;

/// The long box on the plane: x ±60, y ±10, z 0..30 (m).
const BOX_MIN: DVec3 = DVec3::new(-60.0, -10.0, 0.0);
const BOX_MAX: DVec3 = DVec3::new(60.0, 10.0, 30.0);
const PLANE: f64 = 400.0;

/// What a shadow run draws and how: the camera, the shadow settings, an
/// optional box on the plane (min, max corners) and the lighting flags
/// (`models.w`, e.g. `LIGHTING_SOFT_SUN`).
pub(super) struct Setup {
    pub camera: Camera,
    pub settings: ShadowSettings,
    pub wall: Option<(DVec3, DVec3)>,
    pub flags: u32,
}

impl Setup {
    /// The long box (or none) under [`camera`], 4 cascades over 500 m.
    fn standard(with_box: bool) -> Setup {
        Setup {
            camera: camera(),
            settings: ShadowSettings {
                cascades: 4,
                atlas_size: 1024,
                max_distance: 500.0,
                lambda: 0.75,
                pcf_radius: 2,
            },
            wall: with_box.then_some((BOX_MIN, BOX_MAX)),
            flags: 0,
        }
    }
}

/// Vertices (position, normal: 32 bytes, as the geometry image) and indices.
fn mesh(wall: Option<(DVec3, DVec3)>) -> (Vec<[f32; 8]>, Vec<u32>) {
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    let mut quad = |corners: [DVec3; 4], n: DVec3| {
        let base = vertices.len() as u32;
        for c in corners {
            vertices.push([
                c.x as f32, c.y as f32, c.z as f32, 0.0, n.x as f32, n.y as f32, n.z as f32, 0.0,
            ]);
        }
        indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    };
    let p = PLANE;
    quad(
        [
            DVec3::new(-p, -p, 0.0),
            DVec3::new(p, -p, 0.0),
            DVec3::new(p, p, 0.0),
            DVec3::new(-p, p, 0.0),
        ],
        DVec3::Z,
    );
    if let Some((a, b)) = wall {
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        quad(
            [v(a.x, a.y, b.z), v(b.x, a.y, b.z), v(b.x, b.y, b.z), v(a.x, b.y, b.z)],
            DVec3::Z,
        );
        quad(
            [v(a.x, a.y, a.z), v(b.x, a.y, a.z), v(b.x, a.y, b.z), v(a.x, a.y, b.z)],
            -DVec3::Y,
        );
        quad(
            [v(a.x, b.y, a.z), v(b.x, b.y, a.z), v(b.x, b.y, b.z), v(a.x, b.y, b.z)],
            DVec3::Y,
        );
        quad(
            [v(a.x, a.y, a.z), v(a.x, b.y, a.z), v(a.x, b.y, b.z), v(a.x, a.y, b.z)],
            -DVec3::X,
        );
        quad(
            [v(b.x, a.y, a.z), v(b.x, b.y, a.z), v(b.x, b.y, b.z), v(b.x, a.y, b.z)],
            DVec3::X,
        );
    }
    (vertices, indices)
}

/// Whether the ray from `p` towards `sun` hits the long box (slab test).
fn ray_hits_box(p: DVec3, sun: DVec3) -> bool {
    ray_hits(p, sun, (BOX_MIN, BOX_MAX))
}

/// Whether the ray from `p` towards `dir` hits the box `(min, max)` (slab test).
pub(super) fn ray_hits(p: DVec3, sun: DVec3, (box_min, box_max): (DVec3, DVec3)) -> bool {
    let (mut t0, mut t1) = (1e-6f64, f64::INFINITY);
    for k in 0..3 {
        let (o, d) = (p[k], sun[k]);
        if d.abs() < 1e-12 {
            if o < box_min[k] || o > box_max[k] {
                return false;
            }
            continue;
        }
        let (a, b) = ((box_min[k] - o) / d, (box_max[k] - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

fn camera() -> Camera {
    Camera {
        eye: DVec3::new(-150.0, -170.0, 80.0),
        target: DVec3::new(0.0, 30.0, 0.0),
        up: DVec3::Z,
        fov_y_deg: 60.0,
        near: 0.5,
        far: 2000.0,
    }
}

/// A probe: world point, view depth, normal.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Probe {
    world_depth: [f32; 4],
    normal: [f32; 4],
}

/// Surface points in view and within the shadow distance: the plane outside
/// the box, and the box's top.
fn probes(cam: &Camera, aspect: f64, distance: f64, with_box: bool) -> Vec<(DVec3, DVec3)> {
    let vp = cam.view_proj_f64(aspect);
    let mut out = Vec::new();
    let in_view = |p: DVec3| {
        let c = vp * p.extend(1.0);
        let depth = (p - cam.eye).dot(cam.forward());
        c.w > 0.0 && c.x.abs() < c.w && c.y.abs() < c.w && depth < distance
    };
    for j in 0..80 {
        for i in 0..80 {
            let p = DVec3::new(-300.0 + 7.5 * i as f64, -300.0 + 7.5 * j as f64, 0.0);
            let inside = p.x >= BOX_MIN.x && p.x <= BOX_MAX.x && p.y >= BOX_MIN.y && p.y <= BOX_MAX.y;
            if in_view(p) && !(with_box && inside) {
                out.push((p, DVec3::Z));
            }
        }
    }
    if with_box {
        for j in 0..5 {
            for i in 0..30 {
                let p = DVec3::new(-58.0 + 4.0 * i as f64, -8.0 + 4.0 * j as f64, BOX_MAX.z);
                if in_view(p) {
                    out.push((p, DVec3::Z));
                }
            }
        }
    }
    out
}

/// Declares `terrain.shadow`: the test mesh (`mesh(with_box)`) cast into
/// every cascade of `atlas`.
fn declare_mesh_caster(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<Slots>>,
    wall: Option<(DVec3, DVec3)>,
    atlas: ImageId,
) {
    let (vertices, indices) = mesh(wall);
    let index_count = indices.len() as u32;
    let vertex_buffer = Buffer::with_data(
        ctx,
        "test vertices",
        BufferUsageFlags::VERTEX_BUFFER,
        bytemuck::cast_slice(&vertices),
    )
    .expect("vertices");
    let index_buffer = Buffer::with_data(
        ctx,
        "test indices",
        BufferUsageFlags::INDEX_BUFFER,
        bytemuck::cast_slice(&indices),
    )
    .expect("indices");
    let (vertices, indices) = (
        graph.import_buffer(Arc::new(vertex_buffer)),
        graph.import_buffer(Arc::new(index_buffer)),
    );
    let pipeline = shadow_pipeline(ctx).expect("caster pipeline");
    graph
        .pass("terrain.shadow")
        .graphics()
        .read(vertices, BufferAccess::Vertex)
        .read(indices, BufferAccess::Index)
        .pipeline(&pipeline)
        .depth(atlas, None)
        .record(move |pass, frame| {
            let plan = frame.prepared::<ShadowFrame>()?.view(0)?;
            let (v, i) = (pass.buffer(vertices)?, pass.buffer(indices)?);
            record_cascades(pass.cmd(), plan, |cmd, push| {
                cmd.bind_graphics(&pipeline);
                cmd.push_constants(&push)?;
                cmd.bind_vertex_buffer(v);
                cmd.bind_index_buffer(i);
                cmd.draw_indexed(index_count, 1);
                Ok(())
            })
        });
}

/// Declares `shadow probe`: `sun_visibility` at `count` probes (an upload
/// region of [`Probe`]s) into a read-back buffer; returns both.
fn declare_probe(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<Slots>>,
    (count, flags): (usize, u32),
    atlas: ImageId,
) -> (UploadRegion, Arc<Buffer>) {
    let lighting = graph.upload_region("lighting", std::mem::size_of::<LightingFrame>() as u64);
    let probe_region = graph.upload_region("probes", (count * 32) as u64);
    let out = Arc::new(
        Buffer::new(
            ctx,
            BufferDesc {
                name: "visibility".into(),
                size: (count * 4) as u64,
                usage: BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
            },
        )
        .expect("output"),
    );
    let out_id = graph.import_buffer(out.clone());
    let probe = ComputePipeline::new(ctx, shaders::SHADOW_PROBE).expect("probe pipeline");
    let count = count as u32;
    let mut pass = graph.pass("shadow probe");
    let atlas = pass.sample(atlas, Stage::Compute);
    let lighting = pass.upload(lighting, Stage::Compute);
    let probe_binding = pass.upload(probe_region, Stage::Compute);
    let out_binding = pass.storage_buffer(out_id, BufferAccess::StorageWrite(Stage::Compute));
    pass.record(move |pass, frame: &Frame<Slots>| {
        // The lighting constants name the atlas: written by the pass that declares it.
        let plan = frame.prepared::<ShadowFrame>()?.view(0)?;
        let mut constants = LightingFrame::zeroed();
        constants.sun = frame.lighting.sun_direction().extend(SUN_ANGULAR_RADIUS).to_array();
        constants.models = [0, SHADOWS_CASCADED, 0, flags];
        plan.fill(&mut constants);
        constants.set_map_handle(LightingMap::ShadowAtlas, pass.handle(atlas)?);
        pass.write_upload_pod(lighting, &constants)?;
        let handles = [
            pass.handle(lighting)?,
            pass.handle(probe_binding)?,
            pass.handle(out_binding)?,
            count,
        ];
        pass.dispatch(&probe, &handles, [count.div_ceil(64), 1, 1])
    });
    graph.read_back(out_id);
    (probe_region, out)
}

/// Renders the atlas of the scene and evaluates `sun_visibility` at every
/// probe for each sun; returns per sun the probes' visibility and the plan.
pub(super) fn run(
    ctx: &Context,
    (setup, points): (&Setup, Option<(&PointScene, SptError)>),
    suns: &[(f32, f32)],
    probes: &[(DVec3, DVec3)],
) -> Vec<(Vec<f32>, crate::lighting::shadows::CascadePlan)> {
    let settings = setup.settings;
    let mut bounds = SceneBounds {
        min: DVec3::new(-PLANE, -PLANE, 0.0),
        max: DVec3::new(PLANE, PLANE, setup.wall.map_or(BOX_MAX.z, |w| w.1.z)),
    };
    let renderer = points.map(|(scene, error)| {
        let settings = SplatSettings {
            error,
            ..SplatSettings::default()
        };
        PointRenderer::new(ctx, scene, settings, false).expect("points")
    });
    if let Some(b) = renderer.as_ref().and_then(PointShadows::bounds) {
        bounds = bounds.union(b);
    }
    let view = View::new(setup.camera, 320, 200);
    let mut shadows = ShadowMaps::new(settings, bounds).expect("shadow maps");
    let mut graph = RenderGraph::<Frame<Slots>>::new();
    let target = shadows.declare_view(ctx, &mut graph, (0, &view)).expect("atlas");
    let mut point_shadows = renderer.as_ref().map(|r| PointShadows::new(r, &shadows));
    if let Some(p) = point_shadows.as_mut() {
        p.declare(ViewGraph::new(ctx, &mut graph, (0, &view)), target)
            .expect("points.shadow");
    }
    declare_mesh_caster(ctx, &mut graph, setup.wall, target.atlas);
    let (probe_region, out) = declare_probe(ctx, &mut graph, (probes.len(), setup.flags), target.atlas);
    let mut baked = graph.bake(ctx).expect("bake");
    let mut frames = FrameRing::new(ctx).expect("frames");
    let mut results = Vec::new();
    let cam = setup.camera;
    for (index, &(elevation_deg, azimuth_deg)) in suns.iter().enumerate() {
        let lighting_request = Lighting {
            sun: SunPosition::Angles {
                elevation_deg,
                azimuth_deg,
            },
            ..Lighting::default()
        };
        let lighting_request = FrameLighting::new(lighting_request).expect("lighting");
        let mut frame = Frame::<Slots>::new(index as u64, vec![view.clone()], lighting_request);
        let mut uploads = baked.uploads(index as u64);
        frame
            .prepare_into(&mut shadows, (), &mut uploads, &mut Vec::new())
            .expect("prepare");
        if let Some(p) = point_shadows.as_mut() {
            frame
                .prepare_into(p, (), &mut uploads, &mut Vec::new())
                .expect("prepare points");
        }
        let plan = frame.prepared::<ShadowFrame>().unwrap().view(0).unwrap().clone();
        let packed: Vec<Probe> = probes
            .iter()
            .map(|&(p, n)| Probe {
                world_depth: p.as_vec3().extend((p - cam.eye).dot(cam.forward()) as f32).to_array(),
                normal: n.as_vec3().extend(0.0).to_array(),
            })
            .collect();
        uploads.write(probe_region, bytemuck::cast_slice(&packed)).unwrap();
        baked.execute(&mut frames, &frame, &[]).expect("frame");
        baked.finish(&mut frames).expect("finish");
        let bytes = out.mapped().expect("mapped");
        results.push((
            bytemuck::cast_slice::<u8, f32>(&bytes[..probes.len() * 4]).to_vec(),
            plan,
        ));
    }
    results
}

#[test]
fn sun_visibility_agrees_with_a_ray_cast() {
    let (ctx, report) = validated_context();
    {
        let cam = camera();
        let probes = probes(&cam, 1.6, 500.0, true);
        assert!(probes.len() > 500, "{} probes", probes.len());
        let suns = [(30.0f32, 180.0f32), (15.0, 230.0), (20.0, 160.0)];
        for ((vis, plan), &(elevation, azimuth)) in run(&ctx, (&Setup::standard(true), None), &suns, &probes)
            .iter()
            .zip(&suns)
        {
            let sun = sun_direction(elevation, azimuth).as_dvec3();
            let (mut checked, mut shadowed, mut wrong) = (0, 0, Vec::new());
            for (&(p, _), &v) in probes.iter().zip(vis) {
                let depth = (p - cam.eye).dot(cam.forward());
                let i = plan.cascades.iter().position(|c| depth <= c.far).unwrap();
                let texel = plan.cascades[(i + 1).min(plan.cascades.len() - 1)].texel;
                // Only points clearly away from a shadow edge: the PCF
                // footprint and the normal offset (up to 4.5 texels) stay on
                // one side of it.
                let m = 8.0 * texel;
                let expected = ray_hits_box(p + DVec3::Z * 1e-3, sun);
                let clear = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z]
                    .iter()
                    .all(|d| ray_hits_box(p + *d * m + DVec3::Z * 1e-3, sun) == expected);
                if !clear {
                    continue;
                }
                checked += 1;
                shadowed += usize::from(expected);
                let ok = if expected { v < 0.02 } else { v > 0.98 };
                if !ok {
                    wrong.push((p, expected, v));
                }
            }
            assert!(
                checked > 300 && shadowed > 10,
                "sun {elevation}°/{azimuth}°: {checked} checked, {shadowed} shadowed"
            );
            assert!(
                wrong.is_empty(),
                "sun {elevation}°/{azimuth}°: {} of {checked} disagree, e.g. {:?}",
                wrong.len(),
                &wrong[..wrong.len().min(8)]
            );
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// Both sun discs: the hard PCF from 10°, the soft disc filter (its
/// receiver-plane bias) from 5°.
#[test]
fn a_lit_plane_has_no_acne() {
    let (ctx, report) = validated_context();
    {
        let probes = probes(&camera(), 1.6, 500.0, false);
        let modes: [(u32, &[f32]); 2] = [
            (0, &[10.0, 20.0, 35.0, 50.0, 65.0, 80.0]),
            (LIGHTING_SOFT_SUN, &[5.0, 10.0, 20.0, 35.0, 50.0, 80.0]),
        ];
        for (flags, elevations) in modes {
            let setup = Setup {
                flags,
                ..Setup::standard(false)
            };
            let suns: Vec<(f32, f32)> = elevations
                .iter()
                .enumerate()
                .map(|(k, &e)| (e, 37.0 + 61.0 * k as f32))
                .collect();
            for ((vis, _), (elevation, azimuth)) in run(&ctx, (&setup, None), &suns, &probes).iter().zip(&suns) {
                let min = vis.iter().copied().fold(f32::INFINITY, f32::min);
                assert!(
                    min >= 0.999,
                    "flags {flags}, sun {elevation}°/{azimuth}°: visibility {min} on a lit plane"
                );
            }
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn point_objects_cast_shadows() {
    let (ctx, report) = validated_context();
    {
        let mut scene = PointScene::default();
        // The bunny, stood up and scaled to about 90 m, on the plane at the origin.
        let transform = PointTransform::parse("r=90,0,0;s=600").expect("transform");
        scene.add(crate::test_support::points::bunny_object(false), transform);
        let instance = &scene.instances[0];
        let tree = &scene.objects[0].tree;
        let centre = instance
            .transform
            .matrix()
            .transform_point3(tree.bounds_centre.as_dvec3());
        let (elevation, azimuth) = (50.0f32, 200.0f32);
        let sun = sun_direction(elevation, azimuth).as_dvec3();
        let under = centre - sun * (centre.z / sun.z);
        let cam = camera();
        let probes = vec![(under, DVec3::Z), (DVec3::new(-150.0, 0.0, 0.0), DVec3::Z)];
        let depth = (under - cam.eye).dot(cam.forward());
        assert!(depth > 0.0 && depth < 500.0);
        // The casters take the view's level of detail, with either SPT error
        // (the view-dependent one reads each splat's parent, §10.1.7).
        for error in SptError::ALL {
            let results = run(
                &ctx,
                (&Setup::standard(false), Some((&scene, error))),
                &[(elevation, azimuth)],
                &probes,
            );
            let vis = &results[0].0;
            assert!(
                vis[0] < 0.05,
                "{}: the ground under the bunny towards the sun is lit: {}",
                error.name(),
                vis[0]
            );
            assert!(vis[1] > 0.99, "{}: open ground is shadowed: {}", error.name(), vis[1]);
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}
