//! `post.motion_blur`: zero motion is the identity, a vertical stripe under
//! constant horizontal motion blurs to the analytic box profile, a static
//! foreground stays sharp over a moving background, and a scene of objects
//! at several depths (sky included) agrees with the CPU twin.

use crate::graph::ImageId;
use crate::post::motion_blur::{motion_blur_cpu, MotionBlur, MotionBlurImages, MotionBlurSettings};
use crate::post::resample::Plane;
use crate::vulkan::Format;

use super::{as_fetched, assert_close, hash, with_gpu, OneFrame, Texels};

/// Radiance, depth and motion of one test scene.
struct Scene {
    radiance: Plane<[f32; 4]>,
    depth: Plane<[f32; 4]>,
    motion: Plane<[f32; 4]>,
}

impl Scene {
    fn new(
        (w, h): (u32, u32),
        radiance: impl Fn(u32, u32) -> [f32; 4],
        depth: impl Fn(u32, u32) -> f32,
        motion: impl Fn(u32, u32) -> [f32; 2],
    ) -> Scene {
        Scene {
            radiance: Plane::from_fn(w, h, radiance),
            depth: Plane::from_fn(w, h, |x, y| as_fetched(Format::R32_SFLOAT, [depth(x, y); 4])),
            motion: Plane::from_fn(w, h, |x, y| {
                let m = motion(x, y);
                as_fetched(Format::R32G32_SFLOAT, [m[0], m[1], 0.0, 0.0])
            }),
        }
    }

    /// Declares the scene's inputs, an output and the pass; returns the output.
    fn declare(
        &self,
        frame: &mut OneFrame<'_>,
        blur: &MotionBlur,
        name: &str,
        settings: &MotionBlurSettings,
    ) -> ImageId {
        let (w, h) = (self.radiance.width, self.radiance.height);
        let images = MotionBlurImages {
            width: w,
            height: h,
            radiance: frame.input(
                &format!("{name} radiance"),
                Format::R32G32B32A32_SFLOAT,
                &Texels::Float(self.radiance.clone()),
            ),
            depth: frame.input(
                &format!("{name} depth"),
                Format::R32_SFLOAT,
                &Texels::Float(self.depth.clone()),
            ),
            motion: frame.input(
                &format!("{name} motion"),
                Format::R32G32_SFLOAT,
                &Texels::Float(self.motion.clone()),
            ),
            output: frame.output(&format!("{name} blurred"), Format::R32G32B32A32_SFLOAT, w, h),
        };
        blur.declare(&mut frame.graph, name, &images, settings)
            .expect("declare");
        images.output
    }

    fn cpu(&self, settings: &MotionBlurSettings) -> Plane<[f32; 4]> {
        motion_blur_cpu(&self.radiance, &self.depth, &self.motion, settings).expect("twin")
    }
}

/// A half-open shutter at 60 Hz: the blur is half the motion.
const HALF_OPEN: MotionBlurSettings = MotionBlurSettings {
    shutter_s: 1.0 / 120.0,
    frame_interval_s: 1.0 / 60.0,
    samples: 16,
    max_length_px: 48.0,
};

fn random_radiance(x: u32, y: u32) -> [f32; 4] {
    [hash(x, y, 1) * 300.0, hash(x, y, 2) * 30.0, hash(x, y, 3) * 3000.0, 1.0]
}

/// Stripe columns of the analytic test.
const STRIPE: std::ops::Range<u32> = 40..46;

fn scenes() -> [Scene; 4] {
    let size = (96, 24);
    [
        // Still: the identity.
        Scene::new(
            size,
            random_radiance,
            |x, y| 5.0 + hash(x, y, 4) * 100.0,
            |_, _| [0.0, 0.0],
        ),
        // A stripe moving 32 px a frame: a 16-pixel blur.
        Scene::new(
            size,
            |x, _| {
                if STRIPE.contains(&x) {
                    [1.0, 2.0, 4.0, 1.0]
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                }
            },
            |_, _| 30.0,
            |_, _| [32.0, 0.0],
        ),
        // A static green post (10 m) before a red background (300 m) panning 24 px.
        Scene::new(
            size,
            |x, y| {
                if STRIPE.contains(&x) {
                    [0.0, 1.0, 0.0, 1.0]
                } else {
                    [1.0 + hash(x, y, 5), 0.0, 0.0, 1.0]
                }
            },
            |x, _| if STRIPE.contains(&x) { 10.0 } else { 300.0 },
            |x, _| if STRIPE.contains(&x) { [0.0, 0.0] } else { [-24.0, 0.0] },
        ),
        // Objects at several depths and velocities, sky at +inf, some motion past the clamp.
        Scene::new(
            size,
            random_radiance,
            |x, y| match (x / 16 + y / 8) % 4 {
                0 => f32::INFINITY,
                1 => 8.0 + hash(x, y, 6),
                2 => 60.0,
                _ => 700.0 + 50.0 * hash(x, y, 7),
            },
            |x, y| {
                let a = (x / 16 + y / 8) as f32;
                [30.0 * (a * 1.7).cos() + 3.0 * hash(x, y, 8), 20.0 * (a * 0.9).sin()]
            },
        ),
    ]
}

#[test]
fn motion_blur_against_identity_box_profile_foreground_and_twin() {
    let scenes = scenes();
    let gpu = with_gpu(|ctx| {
        let blur = MotionBlur::new(ctx).expect("motion blur");
        let mut frame = OneFrame::new(ctx);
        for (n, scene) in scenes.iter().enumerate() {
            scene.declare(&mut frame, &blur, &n.to_string(), &HALF_OPEN);
        }
        frame.run()
    });
    // Zero motion: bit for bit.
    assert!(gpu[0].float() == &scenes[0].radiance, "zero motion changed the image");
    // The stripe: the box of 16 pixels centred on each pixel, over the
    // stripe's texels (a pixel's share of the stripe, times its colour).
    let stripe = gpu[1].float();
    for y in 0..24 {
        for x in 0..96u32 {
            let (a, b) = (x as f32 + 0.5 - 8.0, x as f32 + 0.5 + 8.0);
            let share = (b.min(STRIPE.end as f32) - a.max(STRIPE.start as f32)).max(0.0) / 16.0;
            let expected = [share, 2.0 * share, 4.0 * share, 1.0];
            assert_eq!(stripe.at(x.into(), y), expected, "pixel ({x}, {y})");
        }
    }
    // The post stays sharp; its green does not smear over the background
    // beyond the one-pixel ramp of the reach.
    let post = gpu[2].float();
    for x in 0..96u32 {
        let texel = post.at(x.into(), 5);
        if STRIPE.contains(&x) {
            assert_eq!(texel, [0.0, 1.0, 0.0, 1.0], "post pixel {x}");
        } else if x + 2 <= STRIPE.start || x > STRIPE.end {
            assert_eq!(texel[1], 0.0, "green at background pixel {x}");
        }
    }
    // Against the CPU twin, every scene.
    let mut worst = 0.0f32;
    for (n, scene) in scenes.iter().enumerate() {
        let cpu = scene.cpu(&HALF_OPEN);
        worst = worst.max(assert_close(&format!("scene {n}"), gpu[n].float(), &cpu, 1e-5, 1e-3));
    }
    println!("motion blur: largest relative error against the twin {worst:e}");
    // The background next to the post is blurred (it is not the input).
    assert_ne!(post.at(30, 5), scenes[2].radiance.at(30, 5));
}

#[test]
fn bad_settings_are_errors_naming_the_setting() {
    with_gpu(|ctx| {
        let blur = MotionBlur::new(ctx).expect("motion blur");
        let mut frame = OneFrame::new(ctx);
        let scene = &scenes()[0];
        let too_long = MotionBlurSettings {
            shutter_s: 0.05,
            ..HALF_OPEN
        };
        let radiance = frame.input("r", Format::R32G32B32A32_SFLOAT, &Texels::Float(scene.radiance.clone()));
        let images = MotionBlurImages {
            width: 96,
            height: 24,
            radiance,
            depth: radiance,
            motion: radiance,
            output: radiance,
        };
        let e = blur
            .declare(&mut frame.graph, "", &images, &too_long)
            .unwrap_err()
            .to_string();
        assert!(e.contains("shutter") && !e.contains('\n'), "{e}");
        let e = blur
            .declare(&mut frame.graph, "", &images, &HALF_OPEN)
            .unwrap_err()
            .to_string();
        assert!(e.contains("motion_blur output") && !e.contains('\n'), "{e}");
    });
}
