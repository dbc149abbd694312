//! Multi-view rigs (§3.3): one renderer renders several views per frame in
//! one submission, sharing the texture atlas and the sky-light bake. Each
//! view of a rig must look like the same camera rendered alone, and
//! off-axis intrinsics must project like a crop of a centred camera.
//! All under validation and synchronization validation.

mod common;

use alpenglow::glam::DVec3;
use alpenglow::{
    Camera, Context, Exposure, FrameImages, Intrinsics, Lighting, ProceduralTerrain, Renderer, Rig, Scene, Settings,
    ViewSpec,
};
use common::{assert_validation_clean, dump_pngs, mean_flip, validated_context};

/// Most frames a still view takes to settle its textures.
const SETTLE: u32 = 64;

/// A 2.5 km procedural terrain with a handful of rocks.
fn scene() -> Scene {
    let mut scene =
        Scene::from_terrain(&ProceduralTerrain::default(), (129, 129), (20.0, 20.0)).expect("procedural terrain");
    scene.add_rocks(40).expect("rocks");
    scene
}

/// The rig's camera: 25 m above the middle of the terrain, looking north.
fn rig_camera(scene: &Scene) -> Camera {
    let field = &scene.heights;
    let ground = field.height(field.columns / 2, field.rows / 2) as f64;
    let eye = DVec3::new(1280.0, 1280.0, ground + 25.0);
    Camera {
        eye,
        target: eye + DVec3::new(0.0, 100.0, -8.0),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.5,
        far: 6000.0,
    }
}

/// Renders `cameras` through views `specs` until settled; every view's images.
fn render(ctx: &Context, scene: &Scene, specs: Vec<ViewSpec>, cameras: &[Camera]) -> (Vec<FrameImages>, Vec<String>) {
    let mut settings = Settings::for_views(specs);
    // A fixed exposure: views of one scene metered alike.
    settings.lighting = Some(Lighting {
        exposure: Exposure::Ev100(14.0),
        ..scene.default_lighting()
    });
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let frame = renderer.render_views_settled(cameras, SETTLE).expect("settled frame");
    let images = renderer.read_views(&frame).expect("readback");
    renderer.finish().expect("finish");
    (images, renderer.pass_names())
}

#[test]
fn every_view_of_a_ring6_rig_equals_its_camera_rendered_alone() {
    let (ctx, report) = validated_context();
    {
        let scene = scene();
        let rig = Rig::ring6(96);
        let specs = rig.specs((96, 72)).unwrap();
        let cameras = rig.cameras(&rig_camera(&scene)).unwrap();
        let (views, passes) = render(&ctx, &scene, specs.clone(), &cameras);
        // One graph: every view's passes, suffixed with its name, once each
        // (the compute path, the default here, shades the sky in terrain.shade).
        let terrain = match passes.iter().any(|p| p.starts_with("terrain.shade@")) {
            true => ["terrain.raster", "terrain.shade"],
            false => ["sky", "terrain.draw"],
        };
        for spec in &specs {
            for pass in ["terrain.warp", "tonemap", "readback"].iter().chain(&terrain) {
                let name = format!("{pass}@{}", spec.name);
                assert_eq!(passes.iter().filter(|p| **p == name).count(), 1, "{name} in {passes:?}");
            }
        }
        assert_eq!(passes.iter().filter(|p| p.starts_with("texturing.upsample")).count(), 1);
        for (k, (spec, camera)) in specs.iter().zip(&cameras).enumerate() {
            let alone = ViewSpec {
                name: String::new(),
                ..spec.clone()
            };
            let (single, _) = render(&ctx, &scene, vec![alone], std::slice::from_ref(camera));
            let (rig_view, single) = (&views[k], &single[0]);
            assert_eq!((rig_view.width, rig_view.height), (96, 72));
            let (flip, _) = mean_flip(&single.rgba8, &rig_view.rgba8, 96, 72);
            dump_pngs(&[("alone", &single.rgba8), (&spec.name, &rig_view.rgba8)], 96, 72);
            assert!(
                flip <= 0.02,
                "view {}: mean FLIP {flip} against the camera alone",
                spec.name
            );
            // The view sees terrain and sky.
            let sky = rig_view.depth.iter().filter(|d| d.is_infinite()).count();
            assert!(
                sky > 0 && sky < rig_view.depth.len(),
                "view {}: {sky} sky pixels",
                spec.name
            );
        }
        // The views look in different directions: no two are alike.
        for a in 0..views.len() {
            for b in a + 1..views.len() {
                let (flip, _) = mean_flip(&views[a].rgba8, &views[b].rgba8, 96, 72);
                assert!(flip > 0.05, "views {a} and {b} are alike (FLIP {flip})");
            }
        }
    }
    assert_validation_clean(&report);
}

/// A principal point on the left edge (OpenCV's pixel centres at
/// integers: the edge is −½) shows the right half of a centred
/// camera twice as wide with the same focal length; views of different
/// sizes render in one frame.
#[test]
fn off_axis_intrinsics_render_a_crop_of_the_centred_camera() {
    let (ctx, report) = validated_context();
    {
        let scene = scene();
        let camera = rig_camera(&scene);
        let f = 70.0;
        let wide = ViewSpec {
            name: "wide".into(),
            width: 128,
            height: 64,
            intrinsics: Some(Intrinsics {
                fx: f,
                fy: f,
                cx: 63.5,
                cy: 31.5,
            }),
            distortion: None,
        };
        let half = ViewSpec {
            name: "half".into(),
            width: 64,
            height: 64,
            intrinsics: Some(Intrinsics {
                fx: f,
                fy: f,
                cx: -0.5,
                cy: 31.5,
            }),
            distortion: None,
        };
        let (views, _) = render(&ctx, &scene, vec![wide, half], &[camera, camera]);
        let (wide, half) = (&views[0], &views[1]);
        assert_eq!((half.width, half.height), (64, 64));
        let crop: Vec<u8> = (0..64)
            .flat_map(|y| {
                let row = (y * 128 + 64) * 4;
                wide.rgba8[row..row + 64 * 4].to_vec()
            })
            .collect();
        let (flip, _) = mean_flip(&crop, &half.rgba8, 64, 64);
        dump_pngs(&[("wide-right-half", &crop), ("off-axis", &half.rgba8)], 64, 64);
        assert!(flip <= 0.03, "mean FLIP {flip} between the off-axis view and the crop");
        // Depth agrees pixel for pixel where both see terrain (same rays).
        let mut compared = 0;
        for y in 0..64usize {
            for x in 0..64usize {
                let (a, b) = (wide.depth[y * 128 + 64 + x], half.depth[y * 64 + x]);
                if a.is_finite() && b.is_finite() {
                    compared += 1;
                    assert!((a - b).abs() <= 0.02 * a.max(1.0), "pixel {x},{y}: depth {a} vs {b}");
                }
            }
        }
        assert!(compared > 500, "{compared} terrain pixels compared");
    }
    assert_validation_clean(&report);
}
