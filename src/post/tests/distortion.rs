//! `post.distortion`: zero coefficients are the identity, barrel and
//! pincushion lenses agree with the CPU twin, and world points projected
//! with OpenCV's formulas land where the pass samples the pinhole render.

use crate::post::distortion::{
    distortion_cpu, distortion_exact_cpu, source_intrinsics, DistortedCamera, LensDistortion,
};
use crate::post::resample::{bilinear, ImageKind, Plane, ResampleImage};
use crate::view::lens::{Distortion, Intrinsics};
use crate::vulkan::Format;

use super::{as_fetched, assert_close, synthetic, with_gpu, OneFrame, Texels};

const SIZE: (u32, u32) = (96, 64);

fn camera(lens: Distortion) -> DistortedCamera {
    DistortedCamera {
        // About 70° across: strong enough for the edges to move many pixels.
        intrinsics: Intrinsics {
            cx: 47.2,
            cy: 31.9,
            ..Intrinsics::centred(68.0, 68.0, SIZE.0, SIZE.1)
        },
        lens,
        width: SIZE.0,
        height: SIZE.1,
    }
}

const BARREL: Distortion = Distortion {
    k1: -0.31,
    k2: 0.09,
    k3: -0.01,
    p1: 0.0015,
    p2: -0.001,
};

const PINCUSHION: Distortion = Distortion {
    k1: 0.18,
    k2: 0.04,
    k3: 0.0,
    p1: -0.002,
    p2: 0.0012,
};

/// The float images of the test: (format, kind).
const FLOAT_IMAGES: [(Format, ImageKind); 3] = [
    (Format::R32G32B32A32_SFLOAT, ImageKind::Filtered),
    (Format::R32_SFLOAT, ImageKind::Exact),
    (Format::R32G32_SFLOAT, ImageKind::Motion),
];

/// Runs the pass for `lens` on the test images; returns GPU and CPU results.
fn run(lens: Distortion) -> (Vec<Texels>, Vec<Texels>) {
    let camera = camera(lens);
    let source = source_intrinsics(&camera).expect("source intrinsics");
    let size = (source.width, source.height);
    with_gpu(|ctx| {
        let distortion = LensDistortion::new(ctx, &camera, &source).expect("distortion");
        let mut frame = OneFrame::new(ctx);
        let (mut images, mut expected) = (Vec::new(), Vec::new());
        for (salt, &(format, kind)) in FLOAT_IMAGES.iter().enumerate() {
            let texels = synthetic(format, salt as u32, size);
            let input = frame.input(&format!("in {salt}"), format, &Texels::Float(texels.clone()));
            let output = frame.output(&format!("out {salt}"), format, SIZE.0, SIZE.1);
            images.push(ResampleImage::new(input, output, format, kind));
            let cpu = distortion_cpu(distortion.cpu(), &texels, kind).expect("twin");
            expected.push(Texels::Float(Plane {
                texels: cpu.texels.iter().map(|&t| as_fetched(format, t)).collect(),
                ..cpu
            }));
        }
        let ids = Plane::from_fn(size.0, size.1, |x, y| [x, y, 0, 1]);
        let input = frame.input("ids", Format::R32G32_UINT, &Texels::Uint(ids.clone()));
        let output = frame.output("ids out", Format::R32G32_UINT, SIZE.0, SIZE.1);
        images.push(ResampleImage::new(input, output, Format::R32G32_UINT, ImageKind::Exact));
        expected.push(Texels::Uint(
            distortion_exact_cpu(&distortion.cpu().map, &ids).expect("twin"),
        ));
        distortion.declare(&mut frame.graph, "", &images).expect("declare");
        (frame.run(), expected)
    })
}

#[test]
fn zero_coefficients_are_the_identity() {
    let centred = DistortedCamera {
        intrinsics: Intrinsics::centred(68.0, 68.0, SIZE.0, SIZE.1),
        ..camera(Distortion::default())
    };
    let source = source_intrinsics(&centred).unwrap();
    assert_eq!(
        (source.width, source.height, source.intrinsics),
        (SIZE.0, SIZE.1, centred.intrinsics)
    );
    let gpu = with_gpu(|ctx| {
        let distortion = LensDistortion::new(ctx, &centred, &source).expect("distortion");
        let mut frame = OneFrame::new(ctx);
        let mut images = Vec::new();
        let mut inputs = Vec::new();
        for (salt, &(format, kind)) in FLOAT_IMAGES.iter().enumerate() {
            let texels = Texels::Float(synthetic(format, salt as u32, SIZE));
            let input = frame.input(&format!("in {salt}"), format, &texels);
            let output = frame.output(&format!("out {salt}"), format, SIZE.0, SIZE.1);
            images.push(ResampleImage::new(input, output, format, kind));
            inputs.push(texels);
        }
        distortion.declare(&mut frame.graph, "", &images).expect("declare");
        (frame.run(), inputs)
    });
    let (outputs, inputs) = gpu;
    for (n, (output, input)) in outputs.iter().zip(&inputs).enumerate() {
        assert!(
            output == input,
            "image {n} ({:?}) is not passed through unchanged",
            FLOAT_IMAGES[n]
        );
    }
}

fn check_twin(name: &str, lens: Distortion) {
    let (gpu, cpu) = run(lens);
    let mut worst = 0.0f32;
    for (n, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        let what = format!("{name} image {n}");
        match (n, g, c) {
            (0, Texels::Float(g), Texels::Float(c)) => worst = worst.max(assert_close(&what, g, c, 1e-5, 1e-30)),
            // Motion carried through the lens's derivative, in f32 on both.
            (2, Texels::Float(g), Texels::Float(c)) => worst = worst.max(assert_close(&what, g, c, 1e-5, 1e-3)),
            _ => assert!(g == c, "{what}: an Exact image differs from its twin"),
        }
    }
    println!("distortion ({name}): largest relative error against the twin {worst:e}");
}

#[test]
fn barrel_distortion_matches_its_cpu_twin() {
    check_twin("barrel", BARREL);
}

#[test]
fn pincushion_distortion_matches_its_cpu_twin() {
    check_twin("pincushion", PINCUSHION);
}

/// OpenCV's projectPoints for a camera at the origin looking along +Z.
fn project_opencv(camera: &DistortedCamera, p: [f64; 3]) -> [f64; 2] {
    let d = camera.lens.distort([p[0] / p[2], p[1] / p[2]]);
    let k = camera.intrinsics;
    [k.fx * d[0] + k.cx, k.fy * d[1] + k.cy]
}

#[test]
fn world_points_land_where_the_pass_samples_the_pinhole_render() {
    // The source holds its own texel coordinates; bilinear interpolation of
    // that ramp is exact, so the output holds where each output pixel sampled.
    for lens in [BARREL, PINCUSHION] {
        let camera = camera(lens);
        let source = source_intrinsics(&camera).unwrap();
        let ramp = Plane::from_fn(source.width, source.height, |x, y| [x as f32, y as f32, 0.0, 1.0]);
        let sampled = with_gpu(|ctx| {
            let distortion = LensDistortion::new(ctx, &camera, &source).expect("distortion");
            let mut frame = OneFrame::new(ctx);
            let input = frame.input("ramp", Format::R32G32_SFLOAT, &Texels::Float(ramp.clone()));
            let output = frame.output("ramp out", Format::R32G32_SFLOAT, SIZE.0, SIZE.1);
            let image = ResampleImage::new(input, output, Format::R32G32_SFLOAT, ImageKind::Filtered);
            distortion.declare(&mut frame.graph, "", &[image]).expect("declare");
            frame.run().remove(0)
        });
        let sampled = sampled.float();
        let k = source.intrinsics;
        let mut worst = 0.0f64;
        let mut count = 0;
        for a in 0..9 {
            for b in 0..7 {
                // A point 40 m out, spread over the field of view.
                let (x, y) = (-0.62 + 0.155 * f64::from(a), -0.41 + 0.136 * f64::from(b));
                let world = [40.0 * x, 40.0 * y, 40.0];
                let [u, v] = project_opencv(&camera, world);
                if !(0.0..=f64::from(SIZE.0 - 1)).contains(&u) || !(0.0..=f64::from(SIZE.1 - 1)).contains(&v) {
                    continue;
                }
                // Where the pinhole render images the point.
                let pinhole = [k.fx * world[0] / world[2] + k.cx, k.fy * world[1] / world[2] + k.cy];
                let got = bilinear(sampled, [u as f32, v as f32]);
                let error = (f64::from(got[0]) - pinhole[0]).hypot(f64::from(got[1]) - pinhole[1]);
                assert!(
                    error < 0.05,
                    "{lens:?}: point {world:?} at ({u:.2}, {v:.2}): {got:?} vs {pinhole:?}"
                );
                worst = worst.max(error);
                count += 1;
            }
        }
        assert!(count >= 40, "only {count} points in the image");
        println!("distortion: {count} world points within {worst:.4} px of the pinhole projection");
    }
}
