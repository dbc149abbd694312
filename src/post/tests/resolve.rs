//! `post.resolve`: the CPU twin at every supersampling factor and both
//! filters; the exact coverage fraction of supersampled hard edges.

use crate::post::resample::{ImageKind, Plane, ResampleImage};
use crate::post::resolve::{
    resolve_cpu, resolve_exact_cpu, supersampled_size, Resolve, ResolveDesc, ResolveFilter, SAMPLES_PER_PIXEL,
};
use crate::vulkan::Format;

use super::{as_fetched, assert_close, hash, synthetic, with_gpu, OneFrame, Texels};

/// Target size of the twin test.
const TARGET: (u32, u32) = (40, 25);

/// The float images of a view (format, kind); the salt of their texels is the index.
const FLOAT_IMAGES: [(Format, ImageKind); 4] = [
    (Format::R32G32B32A32_SFLOAT, ImageKind::Filtered),
    (Format::R32_SFLOAT, ImageKind::Exact),
    (Format::R16G16B16A16_SFLOAT, ImageKind::Exact),
    (Format::R32G32_SFLOAT, ImageKind::Motion),
];

fn ids((w, h): (u32, u32)) -> Plane<[u32; 4]> {
    Plane::from_fn(w, h, |x, y| [(hash(x, y, 99) * 7.0) as u32, x * 1000 + y, 0, 1])
}

#[test]
fn resolve_matches_its_cpu_twin_at_every_factor() {
    let cases: Vec<(u32, ResolveFilter)> = SAMPLES_PER_PIXEL[1..]
        .iter()
        .flat_map(|&spp| [(spp, ResolveFilter::Box), (spp, ResolveFilter::Tent)])
        .collect();
    let results = with_gpu(|ctx| {
        let resolve = Resolve::new(ctx).expect("resolve");
        let mut frame = OneFrame::new(ctx);
        let mut expected = Vec::new();
        for (case, &(spp, filter)) in cases.iter().enumerate() {
            let source = supersampled_size(TARGET.0, TARGET.1, spp).unwrap();
            let mut images = Vec::new();
            for (salt, &(format, kind)) in FLOAT_IMAGES.iter().enumerate() {
                let texels = synthetic(format, salt as u32, source);
                let name = format!("{case}.{salt}");
                let input = frame.input(&name, format, &Texels::Float(texels.clone()));
                let output = frame.output(&format!("{name} resolved"), format, TARGET.0, TARGET.1);
                images.push(ResampleImage::new(input, output, format, kind));
                let cpu = resolve_cpu(&texels, TARGET, kind, filter).expect("twin");
                expected.push(Texels::Float(Plane {
                    texels: cpu.texels.iter().map(|&t| as_fetched(format, t)).collect(),
                    ..cpu
                }));
            }
            let id_texels = ids(source);
            let input = frame.input(
                &format!("{case} ids"),
                Format::R32G32_UINT,
                &Texels::Uint(id_texels.clone()),
            );
            let output = frame.output(&format!("{case} ids resolved"), Format::R32G32_UINT, TARGET.0, TARGET.1);
            images.push(ResampleImage::new(input, output, Format::R32G32_UINT, ImageKind::Exact));
            expected.push(Texels::Uint(resolve_exact_cpu(&id_texels, TARGET).expect("twin")));
            let desc = ResolveDesc {
                source_size: source,
                target_size: TARGET,
                filter,
            };
            resolve
                .declare(&mut frame.graph, &case.to_string(), &desc, &images)
                .expect("declare");
        }
        (frame.run(), expected)
    });
    let (gpu, cpu) = results;
    let mut worst = 0.0f32;
    for (n, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        let (spp, filter) = cases[n / 5];
        let what = format!("{spp} spp {filter:?} image {}", n % 5);
        match (g, c) {
            (Texels::Float(g), Texels::Float(c)) if n % 5 == 0 => {
                worst = worst.max(assert_close(&what, g, c, 1e-5, 1e-30));
            }
            _ => assert!(g == c, "{what}: an Exact image differs from its twin"),
        }
    }
    println!("resolve: largest relative error of radiance against the twin {worst:e}");
    // Motion is scaled to output pixels: 4 × 4 samples → a quarter.
    let motion_source = synthetic(Format::R32G32_SFLOAT, 3, (160, 100));
    let motion = gpu[5 * 6 + 3].float();
    assert_eq!(cases[6], (16, ResolveFilter::Box));
    let m = motion_source.at(4 * 7 + 2, 4 * 3 + 2);
    assert_eq!(motion.at(7, 3)[..2], [m[0] / 4.0, m[1] / 4.0]);
}

/// 1 left of the source column `column(y)` and above the source row `row`.
fn edge_texels(source: (u32, u32), column: impl Fn(u32) -> f64, row: f64) -> Plane<[f32; 4]> {
    Plane::from_fn(source.0, source.1, |x, y| {
        let inside = f64::from(x) < column(y) && f64::from(y) < row;
        as_fetched(Format::R32_SFLOAT, [if inside { 1.0 } else { 0.0 }; 4])
    })
}

#[test]
fn supersampled_hard_edges_resolve_to_their_exact_coverage() {
    // Per factor: 1 left of a vertical edge that steps 3.1 output pixels
    // per band of rows and above a horizontal edge, both on source pixel
    // boundaries inside output pixels; the box resolve gives the area of
    // each output pixel inside, exactly at integer factors and to f32
    // rounding at √2 and √8.
    let target = (24u32, 16u32);
    let spps = [2u32, 4, 8, 16];
    let sources: Vec<(u32, u32)> = spps
        .iter()
        .map(|&s| supersampled_size(target.0, target.1, s).unwrap())
        .collect();
    let edges = |source: (u32, u32)| {
        let s = f64::from(source.0) / f64::from(target.0);
        // Source column of the edge in source row y: 6.3 output pixels
        // plus a step per band, rounded to a source pixel boundary.
        move |y: u32| ((6.3 + f64::from(y * 4 / source.1) * 3.1) * s).round()
    };
    let gpu = with_gpu(|ctx| {
        let resolve = Resolve::new(ctx).expect("resolve");
        let mut frame = OneFrame::new(ctx);
        for (n, &source) in sources.iter().enumerate() {
            let row = (f64::from(source.1) * 0.6).round();
            let texels = edge_texels(source, edges(source), row);
            let input = frame.input(&format!("edge {n}"), Format::R32_SFLOAT, &Texels::Float(texels));
            let output = frame.output(&format!("edge {n} resolved"), Format::R32_SFLOAT, target.0, target.1);
            let desc = ResolveDesc {
                source_size: source,
                target_size: target,
                filter: ResolveFilter::Box,
            };
            let image = ResampleImage::new(input, output, Format::R32_SFLOAT, ImageKind::Filtered);
            resolve
                .declare(&mut frame.graph, &n.to_string(), &desc, &[image])
                .expect("declare");
        }
        frame.run()
    });
    for (n, &source) in sources.iter().enumerate() {
        let (sx, sy) = (
            f64::from(source.0) / f64::from(target.0),
            f64::from(source.1) / f64::from(target.1),
        );
        let row = (f64::from(source.1) * 0.6).round();
        let column = edges(source);
        let plane = gpu[n].float();
        let mut partial = 0;
        for j in 0..target.1 {
            for i in 0..target.0 {
                // The area inside, summed over the source rows of the pixel.
                let (y0, y1) = (f64::from(j) * sy, f64::from(j + 1) * sy);
                let mut area = 0.0;
                for y in (y0.floor() as u32)..(y1.ceil() as u32).min(source.1) {
                    let h = (f64::from(y + 1).min(y1) - f64::from(y).max(y0)).max(0.0);
                    let inside_row = if f64::from(y) < row { 1.0 } else { 0.0 };
                    let w = ((column(y) - f64::from(i) * sx) / sx).clamp(0.0, 1.0);
                    area += h * inside_row * w;
                }
                let coverage = area / sy;
                let got = f64::from(plane.at(i.into(), j.into())[0]);
                let exact = spps[n] == 4 || spps[n] == 16;
                let tolerance = if exact { 0.0 } else { 2e-6 };
                assert!(
                    (got - coverage).abs() <= tolerance,
                    "{} spp, pixel ({i}, {j}): {got} vs coverage {coverage}",
                    spps[n]
                );
                partial += usize::from(coverage > 0.0 && coverage < 1.0);
            }
        }
        assert!(
            partial >= target.1 as usize,
            "{} spp: only {partial} edge pixels",
            spps[n]
        );
    }
}

#[test]
fn bad_image_lists_are_errors_naming_the_image() {
    with_gpu(|ctx| {
        let resolve = Resolve::new(ctx).expect("resolve");
        let mut frame = OneFrame::new(ctx);
        let ids = Texels::Uint(ids((8, 8)));
        let input = frame.input("ids", Format::R32G32_UINT, &ids);
        let output = frame.output("out", Format::R32G32_UINT, 4, 4);
        let desc = ResolveDesc {
            source_size: (8, 8),
            target_size: (4, 4),
            filter: ResolveFilter::Box,
        };
        let mut check = |images: Vec<ResampleImage>, needle: &str| {
            let e = resolve
                .declare(&mut frame.graph, "", &desc, &images)
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle) && !e.contains('\n'), "{e}");
        };
        check(vec![], "post.resolve images");
        check(
            vec![ResampleImage::new(
                input,
                output,
                Format::R32G32_UINT,
                ImageKind::Filtered,
            )],
            "post.resolve image 0",
        );
        check(
            vec![
                ResampleImage::new(input, output, Format::R32G32_UINT, ImageKind::Exact),
                ResampleImage::new(input, output, Format::R8G8_UNORM, ImageKind::Exact),
            ],
            "post.resolve image 1",
        );
        check(
            vec![ResampleImage::new(input, input, Format::R32G32_UINT, ImageKind::Exact)],
            "post.resolve image 0",
        );
        // A valid declaration still runs cleanly after the refused ones.
        let ok = [ResampleImage::new(input, output, Format::R32G32_UINT, ImageKind::Exact)];
        resolve.declare(&mut frame.graph, "", &desc, &ok).expect("declare");
        assert_eq!(
            frame.run()[0],
            Texels::Uint(resolve_exact_cpu(ids.uint(), (4, 4)).expect("twin"))
        );
    });
}
