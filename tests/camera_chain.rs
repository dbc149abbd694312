//! The simulator camera chain in the renderer (§3.3): supersampled
//! anti-aliasing measured against a 4×4 supersampled reference, AOVs kept
//! exact through the resolve, lens distortion and motion blur. All under
//! validation and synchronization validation.

mod common;

use alpenglow::glam::DVec3;
use alpenglow::{
    Camera, Context, Distortion, Exposure, FrameImages, Intrinsics, Lighting, MotionBlurSettings, ProceduralTerrain,
    Renderer, Scene, Settings, ViewSpec,
};
use common::{assert_validation_clean, dump_pngs, mean_flip, validated_context};

const W: u32 = 96;
const H: u32 = 64;

fn scene() -> Scene {
    let mut scene =
        Scene::from_terrain(&ProceduralTerrain::default(), (97, 97), (25.0, 25.0)).expect("procedural terrain");
    scene.add_rocks(30).expect("rocks");
    scene
}

fn camera(scene: &Scene, x: f64) -> Camera {
    let ground = scene.ground_height(x, 300.0).expect("ground");
    let eye = DVec3::new(x, 300.0, ground + 40.0);
    Camera {
        eye,
        target: eye + DVec3::new(0.0, 100.0, -18.0),
        up: DVec3::Z,
        fov_y_deg: 55.0,
        near: 0.5,
        far: 5000.0,
    }
}

/// Renders `cameras` in turn (settled first) with `configure` applied to
/// the settings; the images of the last frame.
fn render(
    ctx: &Context,
    scene: &Scene,
    spec: ViewSpec,
    cameras: &[Camera],
    configure: impl Fn(&mut Settings),
) -> FrameImages {
    let mut settings = Settings::for_views(vec![spec]);
    settings.lighting = Some(Lighting {
        exposure: Exposure::Ev100(14.0),
        ..scene.default_lighting()
    });
    configure(&mut settings);
    let mut renderer = Renderer::new(ctx, scene, settings).expect("renderer");
    let mut frame = renderer.render_settled(&cameras[0], 64).expect("settled");
    for c in &cameras[1..] {
        frame = renderer.render(c).expect("frame");
    }
    let images = renderer.read(&frame).expect("readback");
    renderer.finish().expect("finish");
    images
}

#[test]
fn supersampling_approaches_the_4x4_reference_and_keeps_aovs_exact() {
    let (ctx, report) = validated_context();
    {
        let scene = scene();
        let cam = [camera(&scene, 1200.0)];
        let at = |samples: u32| render(&ctx, &scene, ViewSpec::new(W, H), &cam, |s| s.msaa = samples);
        let (one, four, reference) = (at(1), at(4), at(16));
        let (flip1, _) = mean_flip(&reference.rgba8, &one.rgba8, W, H);
        let (flip4, _) = mean_flip(&reference.rgba8, &four.rgba8, W, H);
        dump_pngs(
            &[("1spp", &one.rgba8), ("4spp", &four.rgba8), ("16spp", &reference.rgba8)],
            W,
            H,
        );
        println!("mean FLIP against 4×4 supersampling: 1 spp {flip1:.4}, 4 spp {flip4:.4}");
        assert!(
            flip4 < 0.75 * flip1,
            "4 spp {flip4} is not clearly closer than 1 spp {flip1}"
        );
        assert!(flip4 < 0.05, "4 spp {flip4}");
        // Exact AOVs: classes are ids (never blends of two), sky exactly
        // where depth is +inf, and the depth of an edge pixel is one of its
        // neighbours' surfaces, not an average floating in between.
        let layers = scene.layers.layers.len() as u32;
        for images in [&four, &reference] {
            for (k, &c) in images.class.iter().enumerate() {
                let spp = if std::ptr::eq(images, &four) { 4 } else { 16 };
                assert!(
                    c <= 3 || (10..10 + layers).contains(&c),
                    "{spp} spp, pixel {k}: class {c}"
                );
                assert_eq!(
                    c == 0,
                    images.depth[k].is_infinite(),
                    "pixel {k}: class {c}, depth {}",
                    images.depth[k]
                );
                let rock = c == 2;
                assert_eq!(
                    rock,
                    images.instance[k] > 0,
                    "pixel {k}: class {c}, instance {}",
                    images.instance[k]
                );
            }
        }
        assert!(four.class.contains(&0) && four.class.iter().any(|&c| c >= 10));
    }
    assert_validation_clean(&report);
}

#[test]
fn zero_distortion_is_the_pinhole_and_a_barrel_lens_bends_the_view() {
    let (ctx, report) = validated_context();
    {
        let scene = scene();
        let cam = [camera(&scene, 1200.0)];
        let k = Intrinsics {
            fx: 70.0,
            fy: 70.0,
            cx: 47.5,
            cy: 31.5,
        };
        let pinhole = ViewSpec {
            intrinsics: Some(k),
            ..ViewSpec::new(W, H)
        };
        let lens = |d: Distortion| ViewSpec {
            distortion: Some(d),
            ..pinhole.clone()
        };
        let plain = render(&ctx, &scene, pinhole.clone(), &cam, |_| {});
        let identity = render(&ctx, &scene, lens(Distortion::default()), &cam, |_| {});
        assert_eq!(plain.hdr, identity.hdr, "zero coefficients resample bit for bit");
        assert_eq!(plain.class, identity.class);
        let barrel = Distortion {
            k1: -0.15,
            ..Distortion::default()
        };
        let bent = render(&ctx, &scene, lens(barrel), &cam, |_| {});
        dump_pngs(&[("pinhole", &plain.rgba8), ("barrel", &bent.rgba8)], W, H);
        // The principal point sees the same ray.
        let centre = (31 * W + 47) as usize;
        let (a, b) = (plain.depth[centre], bent.depth[centre]);
        assert!((a - b).abs() <= 0.02 * a, "centre depth {a} vs {b}");
        // Away from it a barrel lens sees rays farther out: the same ray
        // as the pinhole's pixel at the distorted position.
        let (x, y) = (0.6, 0.0); // normalised, on the horizontal axis
        let r2: f64 = x * x;
        let xd = x * (1.0 + barrel.k1 * r2);
        let pixel = |xn: f64| (k.fx * xn + k.cx).round() as u32;
        let (pin, lensed) = (pixel(x), pixel(xd));
        assert!(lensed < pin, "barrel pulls the ray inwards: {lensed} vs {pin}");
        let row = (31 + (y * k.fy) as u32) * W;
        let (a, b) = (plain.depth[(row + pin) as usize], bent.depth[(row + lensed) as usize]);
        assert!(
            (a - b).abs() <= 0.05 * a.max(1.0),
            "depth of the same ray: pinhole {a}, distorted {b}"
        );
    }
    assert_validation_clean(&report);
}

#[test]
fn motion_blur_smears_a_moving_camera_and_leaves_a_still_one_sharp() {
    let (ctx, report) = validated_context();
    {
        let scene = scene();
        let blur = MotionBlurSettings {
            shutter_s: 1.0 / 60.0,
            frame_interval_s: 1.0 / 30.0,
            ..MotionBlurSettings::default()
        };
        let with = |s: &mut Settings| s.motion_blur = Some(blur);
        let still = [camera(&scene, 1200.0), camera(&scene, 1200.0)];
        let sharp = render(&ctx, &scene, ViewSpec::new(W, H), &still, |_| {});
        let still_blurred = render(&ctx, &scene, ViewSpec::new(W, H), &still, with);
        assert_eq!(sharp.hdr, still_blurred.hdr, "no motion, no blur");
        // Sideways at 25 m/s seen from 40 m up: several pixels a frame.
        let moving = [camera(&scene, 1200.0), camera(&scene, 1200.0 + 25.0 / 30.0 * 8.0)];
        let unblurred = render(&ctx, &scene, ViewSpec::new(W, H), &moving, |_| {});
        let blurred = render(&ctx, &scene, ViewSpec::new(W, H), &moving, with);
        dump_pngs(&[("unblurred", &unblurred.rgba8), ("blurred", &blurred.rgba8)], W, H);
        let speed = unblurred.motion.chunks(2).map(|m| m[0].abs()).fold(0.0f32, f32::max);
        assert!(speed > 2.0, "largest motion {speed} px");
        // Blur lowers the image's horizontal contrast.
        let contrast = |img: &FrameImages| -> f64 {
            let luma = |k: usize| f64::from(img.hdr[4 * k] + img.hdr[4 * k + 1] + img.hdr[4 * k + 2]);
            (0..H as usize)
                .flat_map(|y| (1..W as usize).map(move |x| y * W as usize + x))
                .map(|k| (luma(k) - luma(k - 1)).abs())
                .sum()
        };
        let (c0, c1) = (contrast(&unblurred), contrast(&blurred));
        assert!(c1 < 0.9 * c0, "horizontal contrast {c1} blurred vs {c0} sharp");
    }
    assert_validation_clean(&report);
}
