//! Benchmark of the simulator cameras' post passes (§3.3; src/post):
//! `cargo run --release -p alpenglow-bench --bin post_bench [-- WIDTH HEIGHT]` (default
//! 640×360 output).
//!
//! One graph with the three passes on synthetic images of a view's five
//! targets (radiance RGBA32F Filtered, view depth R32F, ids RG32UI, normal
//! RGBA16F Exact, motion RG32F Motion): `post.resolve` from 4 samples per
//! pixel (2× per axis) and from 16 (4×, the reference), box filter;
//! `post.distortion` of a barrel lens from its undistorted render;
//! `post.motion_blur` with 16 samples. Prints each pass's median GPU time
//! over 20 frames after 3 warm-up frames, and the CPU time of building the
//! distortion's source map.

use std::sync::Arc;
use std::time::Instant;

use alpenglow::bench::{
    source_intrinsics, supersampled_size, DistortedCamera, Distortion, Format, FrameRing, Image, ImageDesc, ImageId,
    ImageInfo, ImageKind, ImageUsageFlags, Intrinsics, LensDistortion, MotionBlur, MotionBlurImages, RenderGraph,
    ResampleImage, Resolve, ResolveDesc, ResolveFilter,
};
use alpenglow::tools::profile::median;
use alpenglow::{Context, ContextOptions, DeviceSelector, MotionBlurSettings};

const WARMUP: usize = 3;
const FRAMES: usize = 20;

/// A view's five targets: (format, kind, bytes per texel).
const TARGETS: [(Format, ImageKind, usize); 5] = [
    (Format::R32G32B32A32_SFLOAT, ImageKind::Filtered, 16),
    (Format::R32_SFLOAT, ImageKind::Exact, 4),
    (Format::R32G32_UINT, ImageKind::Exact, 8),
    (Format::R16G16B16A16_SFLOAT, ImageKind::Exact, 8),
    (Format::R32G32_SFLOAT, ImageKind::Motion, 8),
];

/// An input image of `size` holding bytes of a simple pattern (the passes'
/// cost does not depend on the values; motion and depth are set apart).
fn input(
    ctx: &Context,
    graph: &mut RenderGraph<()>,
    name: &str,
    format: Format,
    bpt: usize,
    size: (u32, u32),
) -> ImageId {
    let texels = (size.0 * size.1) as usize;
    let bytes: Vec<u8> = match format {
        // 12 px of motion to the right; depth 50 m.
        Format::R32G32_SFLOAT => [12.0f32, 0.0]
            .repeat(texels)
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect(),
        Format::R32_SFLOAT => vec![50.0f32; texels].iter().flat_map(|v| v.to_le_bytes()).collect(),
        _ => (0..texels * bpt).map(|i| (i * 7 % 251) as u8 & 0x3f).collect(),
    };
    let desc = ImageDesc {
        name: name.into(),
        width: size.0,
        height: size.1,
        format,
        usage: ImageUsageFlags::SAMPLED,
    };
    graph.import_image(Arc::new(Image::with_data(ctx, desc, &bytes).expect("input image")))
}

/// The view's images at `source` into new targets of `target` size.
fn images(
    ctx: &Context,
    graph: &mut RenderGraph<()>,
    what: &str,
    source: (u32, u32),
    target: (u32, u32),
) -> Vec<ResampleImage> {
    TARGETS
        .iter()
        .enumerate()
        .map(|(n, &(format, kind, bpt))| {
            let input = input(ctx, graph, &format!("{what} {n}"), format, bpt, source);
            let output = graph.create_image(&format!("{what} {n} out"), ImageInfo::new(target.0, target.1, format));
            graph.keep(output);
            ResampleImage::new(input, output, format, kind)
        })
        .collect()
}

fn main() -> alpenglow::Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (w, h) = (
        args.first().copied().unwrap_or(640),
        args.get(1).copied().unwrap_or(360),
    );
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    println!("device: {}; output {w}×{h}", ctx.info().name);
    let mut graph: RenderGraph<()> = RenderGraph::new();

    let resolve = Resolve::new(&ctx)?;
    for spp in [4, 16] {
        let source = supersampled_size(w, h, spp)?;
        let list = images(&ctx, &mut graph, &format!("resolve {spp}"), source, (w, h));
        let desc = ResolveDesc {
            source_size: source,
            target_size: (w, h),
            filter: ResolveFilter::Box,
        };
        resolve.declare(&mut graph, &format!("{spp}spp"), &desc, &list)?;
    }

    let camera = DistortedCamera {
        intrinsics: Intrinsics::centred(0.6 * f64::from(w), 0.6 * f64::from(w), w, h),
        lens: Distortion {
            k1: -0.28,
            k2: 0.07,
            k3: 0.0,
            p1: 0.001,
            p2: -0.0005,
        },
        width: w,
        height: h,
    };
    let start = Instant::now();
    let source = source_intrinsics(&camera)?;
    let distortion = LensDistortion::new(&ctx, &camera, &source)?;
    let map_ms = start.elapsed().as_secs_f64() * 1e3;
    let list = images(&ctx, &mut graph, "distortion", (source.width, source.height), (w, h));
    distortion.declare(&mut graph, "", &list)?;

    let blur = MotionBlur::new(&ctx)?;
    let output = graph.create_image("blurred", ImageInfo::new(w, h, Format::R32G32B32A32_SFLOAT));
    graph.keep(output);
    let blur_images = MotionBlurImages {
        width: w,
        height: h,
        radiance: input(
            &ctx,
            &mut graph,
            "blur radiance",
            Format::R32G32B32A32_SFLOAT,
            16,
            (w, h),
        ),
        depth: input(&ctx, &mut graph, "blur depth", Format::R32_SFLOAT, 4, (w, h)),
        motion: input(&ctx, &mut graph, "blur motion", Format::R32G32_SFLOAT, 8, (w, h)),
        output,
    };
    blur.declare(&mut graph, "", &blur_images, &MotionBlurSettings::default())?;

    let mut baked = graph.bake(&ctx)?;
    let mut frames = FrameRing::new(&ctx)?;
    for _ in 0..WARMUP + FRAMES {
        frames.wait_for_next()?;
        baked.execute(&mut frames, &(), &[])?;
    }
    baked.finish(&mut frames)?;
    let profiles = baked.take_profiles();
    println!(
        "source map (source_intrinsics + inversion + upload), {}×{} render: {map_ms:.1} ms CPU",
        source.width, source.height
    );
    for name in baked.pass_names() {
        let ms = median(
            profiles
                .iter()
                .skip(WARMUP)
                .filter_map(|p| p.passes.iter().find(|t| t.name == name).map(|t| t.gpu_ms)),
        );
        println!("{name:<24} {ms:8.3} ms GPU (median of {FRAMES})");
    }
    Ok(())
}
