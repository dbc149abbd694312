//! Level-2 layers and the mask on synthetic images whose classes are
//! known by construction: a slope rising to the north, forest low, bare
//! ground above it in two shades (brown below, tan at the top).

use glam::DVec2;
use image::RgbImage;

use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::test_support::{data, target_tmp};
use crate::texturing::from_image::calibrate::layer_fractions;
use crate::texturing::from_image::{build_layers, load_mask, ClassCount, FromImageOptions, Registration};

const TAN: [f64; 3] = [200.0, 170.0, 120.0];
const BROWN: [f64; 3] = [150.0, 95.0, 55.0];
const FOREST: [f64; 3] = [60.0, 80.0, 40.0];
/// Image rows (north up) of the tan and brown bands; forest below.
const TAN_ROWS: std::ops::Range<u32> = 0..12;
const BROWN_ROWS: std::ops::Range<u32> = 12..20;

fn slope() -> HeightField {
    HeightField::from_fn(32, 24, DVec2::splat(100.0), |_, r| 1000.0 + 50.0 * r as f32)
}

/// The 64 × 48 image of the module docs, ±6 code values of noise;
/// `paint` may override a pixel.
fn banded(paint: impl Fn(u32, u32) -> Option<[f64; 3]>) -> RgbImage {
    let mut rng = SplitMix64(5);
    RgbImage::from_fn(64, 48, |i, j| {
        let base = paint(i, j).unwrap_or(if TAN_ROWS.contains(&j) {
            TAN
        } else if BROWN_ROWS.contains(&j) {
            BROWN
        } else {
            FOREST
        });
        image::Rgb(base.map(|c| (c + 12.0 * (rng.next_f64() - 0.5)).clamp(0.0, 255.0) as u8))
    })
}

fn linear(c: [f64; 3]) -> glam::Vec3 {
    glam::Vec3::from(c.map(|v| crate::texturing::from_image::classify::srgb_to_linear(v as u8)))
}

/// Level 2 splits the bare class into its two shades: every brown pixel
/// and no other in the child, the child's colour the brown's, its altitude
/// function on the brown band only, and in the CPU twin of the renderer
/// the child dominates the brown band and the image's share of it.
#[test]
fn level_two_recovers_the_sub_classes_of_a_class() {
    let field = slope();
    let image = banded(|_, _| None);
    let options = FromImageOptions {
        classes: ClassCount::Fixed(2),
        level2: Some(2),
        ..Default::default()
    };
    let generated = build_layers(&image, &field, &[None, None, None], &options).unwrap();
    let c = &generated.classification;
    assert_eq!(c.classes.len(), 3, "{:?}", c.classes);
    let label = |i: u32, j: u32| usize::from(c.labels[(j * 64 + i) as usize]);
    let (bare, brown) = (label(10, 5), label(10, 15));
    assert_eq!(c.classes[brown].parent, Some(bare));
    assert_eq!(c.classes[bare].parent, None);
    assert_eq!(c.classes[brown].name, format!("{}.2", c.classes[bare].name));
    let wrong = (0..48u32)
        .flat_map(|j| (0..64u32).map(move |i| (i, j)))
        .filter(|&(i, j)| (label(i, j) == brown) != BROWN_ROWS.contains(&j))
        .count();
    assert_eq!(wrong, 0, "pixels in the wrong sub-class");
    assert!((c.classes[brown].linear - linear(BROWN)).abs().max_element() < 0.02);
    assert!((c.classes[bare].linear - linear(TAN)).abs().max_element() < 0.02);

    let tree = generated.tree().unwrap();
    let levels: Vec<usize> = tree.layers.iter().map(|l| l.level).collect();
    assert_eq!(levels, vec![0, 1, 2]);
    assert_eq!(tree.layers[2].parent, Some(1));
    let registration = Registration::new(64, 48, &field, options.image_rows).unwrap();
    let altitude_of_row = |j: u32| 1000.0 + 50.0 * registration.world(0, j).y as f32 / 100.0;
    let crate::surface::layers::Constraint::Sampled(f) = tree.layers[2].layer.altitude.as_ref().unwrap() else {
        panic!("no sampled altitude on the level-2 layer");
    };
    assert!(f.eval(altitude_of_row(16)) > 0.9, "{f:?}");
    assert!(
        f.eval(altitude_of_row(4)) == 0.0 && f.eval(altitude_of_row(40)) == 0.0,
        "{f:?}"
    );

    // The CPU twin: who dominates the brown band's pixels, and the shares.
    let band: Vec<DVec2> = (BROWN_ROWS.start + 1..BROWN_ROWS.end - 1)
        .flat_map(|j| (0..64).map(move |i| (i, j)))
        .map(|(i, j)| registration.world(i, j))
        .collect();
    let shares = layer_fractions(&tree, &field, &[None, None, None], &band, 100.0).unwrap();
    eprintln!(
        "brown band dominated by {shares:?}; predicted areas {:?}",
        generated.predicted
    );
    assert!(shares[2] >= 0.8, "{shares:?}");
    assert!(
        (generated.predicted[2] - 8.0 / 48.0).abs() < 0.05,
        "{:?}",
        generated.predicted
    );

    // Without level 2: two layers, the bare colour between tan and brown.
    let flat = build_layers(
        &image,
        &field,
        &[None, None, None],
        &FromImageOptions {
            level2: None,
            ..options.clone()
        },
    )
    .unwrap();
    assert_eq!(flat.tree().unwrap().layers.len(), 2);
}

/// A block of an outlier colour (a blue "cultivated" field) under the
/// mask changes nothing: the same block painted red gives the same file,
/// and without the mask the block changes the result.
#[test]
fn masked_pixels_do_not_influence_the_fit() {
    let field = slope();
    let block = |i: u32, j: u32| i < 20 && (30..46).contains(&j);
    let blue = banded(|i, j| block(i, j).then_some([40.0, 90.0, 220.0]));
    let red = banded(|i, j| block(i, j).then_some([220.0, 40.0, 40.0]));
    let exclude: Vec<bool> = (0..48u32).flat_map(|j| (0..64u32).map(move |i| block(i, j))).collect();
    let masked = FromImageOptions {
        exclude: Some(exclude.clone()),
        ..Default::default()
    };
    let maps = [None, None, None];
    let a = build_layers(&blue, &field, &maps, &masked).unwrap();
    let b = build_layers(&red, &field, &maps, &masked).unwrap();
    assert_eq!(a.to_toml(&[]), b.to_toml(&[]));
    assert_eq!(a.classification.classes, b.classification.classes);
    let c = &a.classification;
    // The three bands, nothing of the block.
    assert_eq!(c.classes.len(), 3, "{:?}", c.classes);
    let outside = exclude.iter().filter(|&&e| !e).count();
    assert_eq!(c.classes.iter().map(|k| k.pixels).sum::<usize>(), outside);
    assert!((c.fractions().iter().sum::<f64>() - 1.0).abs() < 1e-9);
    let unmasked = build_layers(&blue, &field, &maps, &FromImageOptions::default()).unwrap();
    assert_ne!(unmasked.to_toml(&[]), a.to_toml(&[]));
    assert!(
        unmasked.classification.classes.iter().any(|k| k.name == "water"),
        "{:?}",
        unmasked.classification.classes
    );
}

#[test]
fn bad_masks_and_level_two_counts_are_one_line_errors() {
    let field = slope();
    let image = banded(|_, _| None);
    let dir = target_tmp().join("level2-masks");
    std::fs::create_dir_all(&dir).unwrap();
    let small = dir.join("small.png");
    image::GrayImage::new(32, 24).save(&small).unwrap();
    let full = dir.join("full.png");
    image::GrayImage::from_pixel(64, 48, image::Luma([255]))
        .save(&full)
        .unwrap();
    let limits = crate::io::limits::InputLimits::default();
    for (path, what) in [
        (small, "32×24"),
        (full, "every pixel"),
        (data("not-an-image.png"), "not-an-image.png"),
    ] {
        let e = load_mask(&path, 64, 48, &limits).unwrap_err().to_string();
        assert!(
            e.contains(&*path.to_string_lossy()) && e.contains(what) && !e.contains('\n'),
            "{e}"
        );
    }
    let maps = [None, None, None];
    for options in [
        FromImageOptions {
            exclude: Some(vec![false; 10]),
            ..Default::default()
        },
        FromImageOptions {
            exclude: Some(vec![true; 64 * 48]),
            ..Default::default()
        },
    ] {
        let e = build_layers(&image, &field, &maps, &options).unwrap_err();
        assert_eq!(e.parameter(), Some("from_image.mask"), "{e}");
    }
    for k in [0, 1, 5] {
        let options = FromImageOptions {
            level2: Some(k),
            ..Default::default()
        };
        let e = build_layers(&image, &field, &maps, &options).unwrap_err();
        assert_eq!(e.parameter(), Some("from_image.level2"), "{e}");
    }
}
