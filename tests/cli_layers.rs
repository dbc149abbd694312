//! `alpenglow layers from-image` end to end (the library side is tested in
//! `src/texturing/tests/layers_from_image.rs`): it writes a layer tree for
//! the Rocky Mountain National Park pair (`tests/data/real-world/README.md`)
//! and refuses bad input in one line naming the option; `--level2` and
//! `--mask` end to end.

mod common;

use alpenglow::LayerTree;
use common::data;

#[test]
fn the_command_writes_a_tree_and_refuses_bad_input_in_one_line() {
    let dir = std::env::temp_dir().join(format!("alpenglow-from-image-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let out = dir.join("rmnp.toml");
    let run = |image: &str, extra: &[&str]| {
        let image = data(image);
        let dem = data("real-world/rmnp-dem.png");
        let mut args = vec![
            "layers",
            "from-image",
            "--image",
            image.to_str().unwrap(),
            "--heightmap",
            dem.to_str().unwrap(),
        ];
        args.extend([
            "--spacing",
            "233.6,234.3",
            "--rows",
            "north-up",
            "--out",
            out.to_str().unwrap(),
        ]);
        args.extend(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_alpenglow"))
            .args(&args)
            .output()
            .expect("run")
    };
    let (histograms, hs) = (dir.join("histograms.png"), dir.join("hs.png"));
    let ok = run(
        "real-world/rmnp-rgb.png",
        &[
            "--classes",
            "3",
            "--no-calibration",
            "--histograms",
            histograms.to_str().unwrap(),
            "--hs-histogram",
            hs.to_str().unwrap(),
        ],
    );
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let text = std::fs::read_to_string(&out).expect("written");
    assert!(text.starts_with("# Image: ") && text.contains("k = 3 given"), "{text}");
    assert_eq!(LayerTree::parse(&text, "written").expect("parses").layers.len(), 5);
    // Fig. 8.13: a row of 64 + 2 + 8 pixels per class (3 + snow and rock),
    // two panels (altitude, slope) of 4 pixels per bin (the default 48
    // bins) after a 32-pixel swatch, 8-pixel margins.
    let plot = image::open(&histograms).expect("histograms PNG").to_rgba8();
    assert_eq!((plot.width(), plot.height()), (8 + 32 + 8 + 2 * (192 + 8), 8 + 5 * 74));
    // Fig. 8.12: 180 hue × 100 saturation bins and the colour table.
    let hs = image::open(&hs).expect("hue-saturation PNG").to_rgba8();
    assert_eq!((hs.width(), hs.height()), (3 * 8 + 2 * 180, 2 * 8 + 100));
    for (image, extra, expected) in [
        ("real-world/rmnp-rgb.png", &["--classes", "9"][..], "--classes"),
        ("real-world/rmnp-rgb.png", &["--bins", "65"][..], "invalid --bins"),
        ("tiny-ramp.png", &[][..], "integer multiple"),
    ] {
        let bad = run(image, extra);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(!bad.status.success(), "{extra:?} succeeded");
        assert!(
            stderr.contains(expected) && stderr.trim().lines().count() == 1,
            "{extra:?}: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--level2 2` on the RMNP pair writes level-2 layers the renderer's
/// parser accepts; `--mask` (the image's 304×374, a block in the north-west
/// excluded) is recorded in the header, and a mask of another size or a
/// mask that excludes every pixel is a one-line error naming the file.
#[test]
fn level2_and_mask_options() {
    let dir = std::env::temp_dir().join(format!("alpenglow-from-image-l2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let out = dir.join("rmnp.toml");
    let mask_png = |name: &str, w: u32, h: u32, excluded: &dyn Fn(u32, u32) -> bool| {
        let rgba: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let v = if excluded(i % w, i / w) { 255 } else { 0 };
                [v, v, v, 255]
            })
            .collect();
        let path = dir.join(name);
        std::fs::write(&path, alpenglow::files::encode_png_rgba8(&rgba, w, h).unwrap()).unwrap();
        path.to_str().unwrap().to_string()
    };
    let block = mask_png("block.png", 304, 374, &|x, y| x < 100 && y < 100);
    let small = mask_png("small.png", 152, 187, &|_, _| false);
    let full = mask_png("full.png", 304, 374, &|_, _| true);
    let run = |extra: &[&str]| {
        let (image, dem) = (data("real-world/rmnp-rgb.png"), data("real-world/rmnp-dem.png"));
        let mut args = vec!["layers", "from-image", "--image", image.to_str().unwrap()];
        args.extend(["--heightmap", dem.to_str().unwrap(), "--spacing", "233.6,234.3"]);
        args.extend(["--rows", "north-up", "--classes", "3", "--no-calibration"]);
        args.extend(["--out", out.to_str().unwrap()]);
        args.extend(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_alpenglow"))
            .args(&args)
            .output()
            .expect("run")
    };
    let ok = run(&["--level2", "2", "--mask", &block]);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let text = std::fs::read_to_string(&out).expect("written");
    assert!(
        text.contains("# Level 2: ") && text.contains("# Mask: ") && text.contains("block.png"),
        "{text}"
    );
    let tree = LayerTree::parse(&text, "written").expect("parses");
    assert!(tree.layers.iter().any(|l| l.level == 2), "no level-2 layer: {text}");
    for (extra, expected) in [
        (&["--mask", &small][..], "small.png"),
        (&["--mask", &full][..], "every pixel"),
        (&["--level2", "5"][..], "--level2"),
    ] {
        let bad = run(extra);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(!bad.status.success(), "{extra:?} succeeded");
        assert!(
            stderr.contains(expected) && stderr.trim().lines().count() == 1,
            "{extra:?}: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
