//! Surface layers from a real image (dissertation §8.3,
//! `crate::texturing::from_image`) on the Rocky Mountain National Park
//! pair (`tests/data/real-world/README.md`): a 152 × 187 DEM at ~234 m and
//! a true-colour Landsat image at twice its resolution.
//!
//! * The classification finds forest below the treeline, bare tundra above
//!   it, the lakes as water, and rock and snow among the near-grey pixels.
//! * Shade: pixels in the DEM's deep shadow (an independent hillshade from
//!   central differences of the samples) are water at most 3 % of the time;
//!   without the shade rule more than 10 % of them are.
//! * The rendered region (top-down, class AOV: the dominant layer) covers
//!   each class's share of the image within 0.08, shows the image's class
//!   at the same place on more pixels than chance + 0.10, and its hue–saturation
//!   histogram is nearer the image's than that of the built-in layers;
//!   an oblique view shows every class; all under validation.

use std::sync::OnceLock;

use crate::io::heightmap::{load_heightmap, HeightField, HeightmapOptions, RowOrder};
use crate::io::limits::InputLimits;
use crate::renderer::{Camera, FrameImages, RenderSettings, Renderer, Scene};
use crate::surface::layers::{Constraint, LayerTree};
use crate::test_support::{assert_validation_clean, data, dump_pngs, validated_context};
use crate::texturing::from_image::classify::hsv;
use crate::texturing::from_image::{build_layers, load_rgb_image, ClassCount, FromImageOptions, GeneratedLayers};
use crate::view::aov::CLASS_LAYER_BASE;
use crate::view::{Lighting, SunPosition};
use glam::{DVec2, DVec3};
use image::RgbImage;

/// Metres between the DEM's samples (x east, y north).
const SPACING: DVec2 = DVec2::new(233.6, 234.3);
/// Top-down render size (the DEM's aspect).
const TOP: (u32, u32) = (160, 198);
/// Oblique render size.
const OBLIQUE: (u32, u32) = (160, 100);

fn rmnp() -> &'static (RgbImage, HeightField) {
    static DATA: OnceLock<(RgbImage, HeightField)> = OnceLock::new();
    DATA.get_or_init(|| {
        let options = HeightmapOptions {
            spacing: Some(SPACING),
            rows: RowOrder::NorthUp,
            ..Default::default()
        };
        let field = load_heightmap(&data("real-world/rmnp-dem.png"), &options).expect("DEM");
        let image = load_rgb_image(&data("real-world/rmnp-rgb.png"), &InputLimits::default()).expect("image");
        (image, field)
    })
}

fn generate(options: &FromImageOptions) -> GeneratedLayers {
    let (image, field) = rmnp();
    build_layers(image, field, &[None, None, None], options).expect("layers")
}

/// The layers of the default options (automatic k, shade handled, calibrated).
fn generated() -> &'static GeneratedLayers {
    static LAYERS: OnceLock<GeneratedLayers> = OnceLock::new();
    LAYERS.get_or_init(|| generate(&FromImageOptions::default()))
}

fn class_index(generated: &GeneratedLayers, name: &str) -> usize {
    let classes = &generated.classification.classes;
    classes.iter().position(|c| c.name == name).unwrap_or_else(|| {
        panic!(
            "no class {name}: {:?}",
            classes.iter().map(|c| &c.name).collect::<Vec<_>>()
        )
    })
}

#[test]
fn the_region_classifies_into_forest_tundra_water_rock_and_snow() {
    let g = generated();
    let c = &g.classification;
    let names: Vec<&str> = c.classes.iter().map(|c| c.name.as_str()).collect();
    eprintln!(
        "classes {names:?}, fractions {:?}, silhouettes {:?}",
        c.fractions(),
        c.silhouettes
    );
    for name in ["forest", "bare", "water", "rock", "snow"] {
        class_index(g, name);
    }
    assert_eq!(c.k, 3, "automatic k: {:?}", c.silhouettes);
    // Grand Lake (south-west) is water.
    let (image, field) = rmnp();
    let at = |i: u32, j: u32| usize::from(c.labels[(j * image.width() + i) as usize]);
    assert_eq!(at(40, 350), class_index(g, "water"));
    // The treeline: forest lies lower than bare tundra, on average by more than 200 m (bare
    // also holds valley meadows).
    let positions = c.registration.world_positions();
    let mean_altitude = |class: usize| {
        let heights: Vec<f64> = (0..positions.len())
            .filter(|&i| usize::from(c.labels[i]) == class)
            .map(|i| crate::surface::bspline::sample_bspline(field, positions[i].x, positions[i].y))
            .collect();
        heights.iter().sum::<f64>() / heights.len() as f64
    };
    let (forest, bare) = (
        mean_altitude(class_index(g, "forest")),
        mean_altitude(class_index(g, "bare")),
    );
    eprintln!("mean altitude: forest {forest:.0} m, bare {bare:.0} m");
    assert!(bare - forest > 200.0, "forest {forest:.0} m, bare {bare:.0} m");
    // The file: a header, the most common class at the root, sampled altitude and slope below it.
    let toml = g.to_toml(&["test".into()]);
    assert!(
        toml.contains("k = 3 of the largest silhouette") && toml.contains("Shade:"),
        "{toml}"
    );
    let tree = LayerTree::parse(&toml, "generated").expect("the written tree parses");
    assert_eq!(tree.layers.len(), 5);
    assert_eq!(tree.layers[0].layer.name, "forest");
    for flat in &tree.layers[1..] {
        let l = &flat.layer;
        assert_eq!(flat.level, 1);
        assert!(
            matches!(&l.altitude, Some(Constraint::Sampled(f)) if f.samples.len() == 48 && f.min == 2281.0 && f.max == 4261.0)
        );
        assert!(matches!(&l.slope, Some(Constraint::Sampled(_))), "{}", l.name);
    }
}

/// Direct light relative to flat ground from central differences of the
/// DEM's samples (no cast shadows), at the DEM cell of each image pixel.
fn independent_hillshade(image: &RgbImage, field: &HeightField) -> Vec<f64> {
    let sun = DVec3::new(150f64.to_radians().sin(), 150f64.to_radians().cos(), 0.0) * 30f64.to_radians().cos()
        + DVec3::new(0.0, 0.0, 30f64.to_radians().sin());
    let s = image.width() / field.columns;
    let mut out = Vec::with_capacity((image.width() * image.height()) as usize);
    for j in 0..image.height() {
        for i in 0..image.width() {
            let (c, r) = (i / s, field.rows - 1 - j / s);
            let h = |c: i64, r: i64| {
                f64::from(field.height(
                    c.clamp(0, i64::from(field.columns) - 1) as u32,
                    r.clamp(0, i64::from(field.rows) - 1) as u32,
                ))
            };
            let (c, r) = (i64::from(c), i64::from(r));
            let gx = (h(c + 1, r) - h(c - 1, r)) / (2.0 * SPACING.x);
            let gy = (h(c, r + 1) - h(c, r - 1)) / (2.0 * SPACING.y);
            let n = DVec3::new(-gx, -gy, 1.0).normalize();
            out.push(n.dot(sun).max(0.0) / sun.z);
        }
    }
    out
}

#[test]
fn pixels_in_deep_shadow_are_not_water() {
    let (image, field) = rmnp();
    let light = independent_hillshade(image, field);
    let deep: Vec<usize> = (0..light.len()).filter(|&i| light[i] < 0.1).collect();
    assert!(deep.len() > 300, "{} pixels in deep shadow", deep.len());
    let water_share = |g: &GeneratedLayers| {
        let water = class_index(g, "water");
        let n = deep
            .iter()
            .filter(|&&i| usize::from(g.classification.labels[i]) == water)
            .count();
        n as f64 / deep.len() as f64
    };
    let handled = water_share(generated());
    let unhandled = water_share(&generate(&FromImageOptions {
        shade_handling: false,
        calibrate: false,
        ..Default::default()
    }));
    eprintln!(
        "{} pixels in deep shadow: water {handled:.4} with the shade rule, {unhandled:.4} without",
        deep.len()
    );
    assert!(handled <= 0.03, "{handled} of the deep shadow is water");
    assert!(unhandled > 0.10, "without the shade rule only {unhandled} is water");
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let (image, field) = rmnp();
    let maps = [None, None, None];
    let odd = image::imageops::crop_imm(image, 0, 0, 303, 374).to_image();
    let e = build_layers(&odd, field, &maps, &FromImageOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("integer multiple") && !e.contains('\n'), "{e}");
    for (options, what) in [
        (
            FromImageOptions {
                classes: ClassCount::Fixed(9),
                ..Default::default()
            },
            "from_image.classes",
        ),
        (
            FromImageOptions {
                classes: ClassCount::Fixed(0),
                ..Default::default()
            },
            "from_image.classes",
        ),
        (
            FromImageOptions {
                bins: 0,
                ..Default::default()
            },
            "from_image.bins",
        ),
        (
            FromImageOptions {
                sun_elevation_deg: 0.0,
                ..Default::default()
            },
            "from_image.sun_elevation_deg",
        ),
    ] {
        let e = build_layers(image, field, &maps, &options).unwrap_err();
        assert_eq!(e.parameter(), Some(what), "{e}");
    }
    let e = load_rgb_image(&data("not-an-image.png"), &InputLimits::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("not-an-image.png") && !e.contains('\n'), "{e}");
}

/// The top-down camera: straight down from high above with a narrow field
/// of view, the terrain filling the frame (north up).
fn top_down(field: &HeightField) -> Camera {
    let extent = field.extent();
    let centre = DVec3::new(extent.x / 2.0, extent.y / 2.0, 3300.0);
    let fov: f64 = 20.0;
    let distance = 0.49 * extent.y / (fov.to_radians() / 2.0).tan();
    Camera {
        eye: centre + DVec3::Z * distance,
        target: centre,
        up: DVec3::Y,
        fov_y_deg: fov,
        near: distance - 4000.0,
        far: distance + 4000.0,
    }
}

/// Looking north-west over the Continental Divide from the south-east.
fn oblique(field: &HeightField) -> Camera {
    let extent = field.extent();
    Camera {
        eye: DVec3::new(0.75 * extent.x, 0.08 * extent.y, 9000.0),
        target: DVec3::new(0.35 * extent.x, 0.55 * extent.y, 3000.0),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 50.0,
        far: 200_000.0,
    }
}

/// Settled frames of `cameras` (each with its size) with `tree`, the
/// image's sun, no aerial perspective, under validation.
fn render(tree: LayerTree, cameras: &[(Camera, (u32, u32))]) -> Vec<FrameImages> {
    let mut scene = Scene::new(rmnp().1.clone());
    scene.layers = tree;
    let (ctx, report) = validated_context();
    let frames = cameras
        .iter()
        .map(|(camera, (w, h))| {
            let settings = RenderSettings {
                lighting: Some(Lighting {
                    sun: SunPosition::Angles {
                        elevation_deg: 30.0,
                        azimuth_deg: 150.0,
                    },
                    aerial_perspective: false,
                    ..Default::default()
                }),
                ..RenderSettings::new(*w, *h)
            };
            let mut renderer = Renderer::new(&ctx, &scene, settings).expect("renderer");
            let frame = renderer.render_settled(camera, 16).expect("frame");
            let images = renderer.read(&frame).expect("read");
            renderer.finish().expect("finish");
            images
        })
        .collect();
    drop(ctx);
    assert_validation_clean(&report);
    frames
}

/// Share of the terrain pixels per class (the dominant layer's class).
fn rendered_fractions(frame: &FrameImages, generated: &GeneratedLayers) -> Vec<f64> {
    let mut counts = vec![0usize; generated.classification.classes.len()];
    let mut terrain = 0;
    for &class in &frame.class {
        let layer = class
            .checked_sub(CLASS_LAYER_BASE)
            .and_then(|l| generated.layers.get(l as usize));
        if let Some(layer) = layer {
            counts[layer.class] += 1;
            terrain += 1;
        }
    }
    assert!(terrain > 0, "no terrain pixel");
    counts.iter().map(|&c| c as f64 / terrain as f64).collect()
}

/// Share of the terrain pixels of the top-down `frame` whose dominant
/// layer's class is the image's class at the same place (the surface point
/// from the pixel's ray and `distance`, mapped back through the
/// registration), and the share expected by chance (Σ image share ×
/// render share over the classes).
fn place_agreement(frame: &FrameImages, camera: &Camera, generated: &GeneratedLayers) -> (f64, f64) {
    let (image, field) = rmnp();
    let (w, h) = TOP;
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = f64::from(w) / f64::from(h);
    let s = f64::from(image.width() / field.columns);
    let labels = &generated.classification.labels;
    let (mut agree, mut terrain) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let Some(layer) = frame.class[i].checked_sub(CLASS_LAYER_BASE) else {
                continue;
            };
            let ndc = DVec2::new(
                (f64::from(x) + 0.5) / f64::from(w) * 2.0 - 1.0,
                1.0 - (f64::from(y) + 0.5) / f64::from(h) * 2.0,
            );
            let ray = camera.forward() + camera.right() * (ndc.x * tan * aspect) + camera.image_up() * (ndc.y * tan);
            let p = camera.eye + ray.normalize() * f64::from(frame.distance[i]);
            let column = ((p.x / SPACING.x + 0.5) * s)
                .floor()
                .clamp(0.0, f64::from(image.width() - 1));
            let row = ((f64::from(field.rows - 1) - p.y / SPACING.y + 0.5) * s)
                .floor()
                .clamp(0.0, f64::from(image.height() - 1));
            let label = labels[row as usize * image.width() as usize + column as usize];
            terrain += 1;
            agree += usize::from(generated.layers[layer as usize].class == usize::from(label));
        }
    }
    let chance = (generated.classification.fractions().iter())
        .zip(rendered_fractions(frame, generated))
        .map(|(a, b)| a * b)
        .sum();
    (agree as f64 / terrain.max(1) as f64, chance)
}

/// Normalised hue–saturation histogram (12 hues of 30°, 5 saturations of 0.2).
fn hs_histogram(pixels: impl Iterator<Item = [u8; 3]>) -> Vec<f64> {
    let mut h = vec![0.0; 60];
    for p in pixels {
        let (hue, s, _) = hsv(p);
        h[((s * 5.0) as usize).min(4) * 12 + ((hue / 30.0) as usize).min(11)] += 1.0;
    }
    let total: f64 = h.iter().sum();
    h.iter().map(|v| v / total.max(1.0)).collect()
}

/// Symmetric chi-square distance ½ Σ (p − q)² / (p + q), in [0, 1].
fn chi_square(p: &[f64], q: &[f64]) -> f64 {
    0.5 * p
        .iter()
        .zip(q)
        .filter(|(a, b)| *a + *b > 0.0)
        .map(|(a, b)| (a - b).powi(2) / (a + b))
        .sum::<f64>()
}

fn rgb_pixels(frame: &FrameImages) -> impl Iterator<Item = [u8; 3]> + '_ {
    frame.rgba8.chunks_exact(4).map(|p| [p[0], p[1], p[2]])
}

#[test]
fn the_rendered_region_covers_each_class_like_the_image() {
    let g = generated();
    let (image, field) = rmnp();
    let frames = render(
        g.tree().expect("tree"),
        &[(top_down(field), TOP), (oblique(field), OBLIQUE)],
    );
    let baseline = render(LayerTree::default_tree(), &[(top_down(field), TOP)]);
    let (top, side) = (&frames[0], &frames[1]);
    assert!(top.depth.iter().all(|z| z.is_finite()), "the top-down view shows sky");
    dump_pngs(
        &[("rmnp-top", &top.rgba8), ("rmnp-top-default", &baseline[0].rgba8)],
        TOP.0,
        TOP.1,
    );
    dump_pngs(&[("rmnp-oblique", &side.rgba8)], OBLIQUE.0, OBLIQUE.1);
    let rgba = |img: &RgbImage| -> Vec<u8> { img.pixels().flat_map(|p| [p[0], p[1], p[2], 255]).collect() };
    dump_pngs(&[("rmnp-image", &rgba(image))], image.width(), image.height());
    let class_colours: Vec<[u8; 3]> = (g.classification.classes.iter())
        .map(|c| crate::texturing::reference::srgb8(c.linear))
        .collect();
    let paint = |classes: &mut dyn Iterator<Item = Option<usize>>| -> Vec<u8> {
        classes
            .flat_map(|c| {
                let [r, g, b] = c.map_or([255, 0, 255], |c| class_colours[c]);
                [r, g, b, 255]
            })
            .collect()
    };
    let image_classes = paint(&mut g.classification.labels.iter().map(|&l| Some(usize::from(l))));
    dump_pngs(&[("rmnp-image-classes", &image_classes)], image.width(), image.height());
    let render_classes = paint(&mut top.class.iter().map(|&c| {
        let layer = c.checked_sub(CLASS_LAYER_BASE)?;
        g.layers.get(layer as usize).map(|l| l.class)
    }));
    dump_pngs(&[("rmnp-top-classes", &render_classes)], TOP.0, TOP.1);

    let expected = g.classification.fractions();
    let rendered = rendered_fractions(top, g);
    for ((class, e), r) in g.classification.classes.iter().zip(&expected).zip(&rendered) {
        eprintln!("{:<8} image {e:.4}  render {r:.4}", class.name);
        assert!((e - r).abs() <= 0.08, "{}: image {e:.4}, render {r:.4}", class.name);
    }
    eprintln!("predicted by the CPU twin per layer: {:?}", g.predicted);
    let oblique_classes = rendered_fractions(side, g);
    assert!(
        oblique_classes.iter().filter(|&&f| f > 0.0).count() >= 4,
        "{oblique_classes:?}"
    );

    let (agreement, chance) = place_agreement(top, &top_down(field), g);
    eprintln!("same class at the same place: {agreement:.4} of the terrain pixels (chance {chance:.4})");
    assert!(agreement > chance + 0.1, "agreement {agreement}, chance {chance}");

    let reference = hs_histogram(image.pixels().map(|p| p.0));
    let ours = chi_square(&reference, &hs_histogram(rgb_pixels(top)));
    let default = chi_square(&reference, &hs_histogram(rgb_pixels(&baseline[0])));
    eprintln!("hue-saturation chi-square to the image: generated layers {ours:.4}, built-in layers {default:.4}");
    assert!(ours < default, "generated {ours}, built-in {default}");
}
