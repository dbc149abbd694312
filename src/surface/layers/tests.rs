//! Tests of the layer tree: parsing, validation and evaluation.

use super::*;

mod height_blur;
mod sampled;

/// A root and one child "c" (at line 5) with `extra` from line 8 on.
fn tree_with(extra: &str) -> String {
    format!("[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\n\n[[root.children]]\nname = \"c\"\ncolor = [0.5, 0.5, 0.5]\n{extra}\n")
}

/// Parsing `text` fails with one line naming `origin` and containing `needle`.
fn assert_error(text: &str, origin: &str, needle: &str) -> String {
    let message = LayerTree::parse(text, origin).unwrap_err().to_string();
    assert!(
        message.contains(origin) && message.contains(needle),
        "{text}: {message:?} lacks {needle:?}"
    );
    assert!(!message.contains('\n'), "one line: {message:?}");
    message
}

fn hat(min: f32, max: f32, fuzz: f32) -> Hat {
    Hat { min, max, fuzz }
}

fn hat_constraint(min: f32, max: f32, fuzz: f32) -> Option<Constraint> {
    Some(Constraint::Hat(hat(min, max, fuzz)))
}

#[test]
fn hat_functions_ramp_over_twice_the_fuzz() {
    let h = hat(100.0, 200.0, 10.0);
    assert_eq!(h.eval(50.0), 0.0);
    assert_eq!(h.eval(90.0), 0.0);
    assert_eq!(h.eval(100.0), 0.5);
    assert_eq!(h.eval(110.0), 1.0);
    assert_eq!(h.eval(150.0), 1.0);
    assert_eq!(h.eval(200.0), 0.5);
    assert_eq!(h.eval(210.0), 0.0);
    assert!((h.eval(95.0) - 0.25).abs() < 1e-6);
    // No fuzz: a box.
    let b = hat(0.0, 1.0, 0.0);
    assert_eq!(
        (b.eval(-0.1), b.eval(0.0), b.eval(1.0), b.eval(1.1)),
        (0.0, 1.0, 1.0, 0.0)
    );
    // A range narrower than the ramps peaks below 1.
    let narrow = hat(0.0, 0.0, 10.0);
    assert_eq!(narrow.eval(0.0), 0.5);
}

fn leaf(name: &str, color: [f32; 3]) -> Layer {
    Layer {
        name: name.into(),
        color: Vec3::from(color),
        roughness: 0.0,
        roughness_wavelength: 1.0,
        noise_bias: 1.0,
        noise_scale: 0.0,
        noise_wavelength: 1.0,
        altitude: None,
        elevation: None,
        slope: None,
        inputs: [None, None, None],
        height_blur: None,
        vegetation: Vec::new(),
    }
}

#[test]
fn coverage_multiplies_constraints_and_clamps_noise() {
    let mut l = leaf("snow", [1.0; 3]);
    l.altitude = hat_constraint(1000.0, 5000.0, 100.0);
    l.slope = hat_constraint(0.0, 30.0, 5.0);
    l.noise_bias = 0.5;
    l.noise_scale = 1.0;
    let at = |altitude, slope| LayerInputs {
        altitude,
        elevation: 0.5,
        slope,
        maps: [f32::NAN; 3],
    };
    assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.5), 1.0);
    assert_eq!(coverage(&l, &at(2000.0, 10.0), -0.5), 0.0);
    assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.0), 0.5);
    // 0.5 (altitude ramp) × 1 × (0.5 + 0.5) = 0.5.
    assert_eq!(coverage(&l, &at(1000.0, 10.0), 0.5), 0.5);
    // Product of two half ramps.
    assert_eq!(coverage(&l, &at(1000.0, 30.0), 0.5), 0.25);
    assert_eq!(coverage(&l, &at(500.0, 10.0), 1.0), 0.0);
    // Input maps: an absent map (NaN) fails its constraint.
    l.inputs[0] = hat_constraint(0.0, 1.0, 0.5);
    assert_eq!(coverage(&l, &at(2000.0, 10.0), 0.5), 0.0);
    let mut with_map = at(2000.0, 10.0);
    with_map.maps[0] = 0.5;
    assert_eq!(coverage(&l, &with_map, 0.5), 1.0);
}

#[test]
fn evaluation_blends_depth_first_and_coverage_feeds_children_only() {
    let text = r#"
        [root]
        name = "rock"
        color = [0.2, 0.2, 0.2]
        [[root.children]]
        name = "grass"
        color = [0.0, 1.0, 0.0]
        noise_bias = 0.5
        roughness = 2.0
        [[root.children.children]]
        name = "dry"
        color = [1.0, 1.0, 0.0]
        noise_bias = 0.5
        [[root.children]]
        name = "snow"
        color = [1.0, 1.0, 1.0]
        altitude = { min = 101.0, max = 1e6 }
    "#;
    let tree = LayerTree::parse(text, "test").unwrap();
    let names: Vec<&str> = tree.layers.iter().map(|l| l.layer.name.as_str()).collect();
    assert_eq!(names, ["rock", "grass", "dry", "snow"]);
    assert_eq!(tree.layers[2].parent, Some(1));
    assert_eq!(tree.layers[3].level, 1);
    // D_S = 1 everywhere: grass (C_S = 0.5) lifts the height by 0.5·2 = 1,
    // which brings it above the snow line.
    let noise = |_: usize, _: bool, _: DVec2, _: f32| (1.0f32, DVec2::new(0.1, 0.0));
    let at = |height| BasePoint {
        xy: DVec2::ZERO,
        height,
        gradient: DVec2::ZERO,
        range: (0.0, 200.0),
        maps: [f32::NAN; 3],
        blurred: [(0.0, DVec2::ZERO); MAX_BLUR_RADII],
    };
    let s = evaluate(&tree, &at(100.5), &noise);
    assert_eq!(s.coverage, vec![1.0, 0.5, 0.25, 1.0]);
    assert_eq!(s.height, 101.5);
    assert!((s.gradient.x - 0.1).abs() < 1e-9, "{:?}", s.gradient);
    assert_eq!(s.color, Vec3::ONE);
    // Below the snow line: rock 0.2 → grass half → dry a quarter.
    let s = evaluate(&tree, &at(90.0), &noise);
    let expected = (Vec3::splat(0.2) * 0.5 + Vec3::new(0.0, 1.0, 0.0) * 0.5) * 0.75 + Vec3::new(1.0, 1.0, 0.0) * 0.25;
    assert!((s.color - expected).length() < 1e-6, "{} vs {expected}", s.color);
}

#[test]
fn the_default_tree_parses_with_the_issue_layers() {
    let tree = LayerTree::parse(DEFAULT_LAYERS, "built-in").unwrap();
    let names: Vec<&str> = tree.layers.iter().map(|l| l.layer.name.as_str()).collect();
    for name in [
        "rock",
        "grass",
        "dark grass",
        "dry grass",
        "light grass",
        "sand",
        "snow",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    assert_eq!(tree.layers[0].layer.name, "rock");
    assert_eq!(LayerTree::default_tree(), tree);
}

#[test]
fn bad_files_name_the_line() {
    let cases = [
        ("[root]\nname = \"r\"\ncolor = [0.1, 0.1]\n", "line 3"),
        ("[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nbogus = 1\n", "line 4"),
        (
            "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\n\n[[root.children]]\nname = \"c\"\ncolor = [0.5, 0.5, 0.5]\nslope = { min = 40.0, max = 10.0 }\n",
            "line 5",
        ),
        ("[root]\nname = \"r\"\ncolor = [2.0, 0.1, 0.1]\n", "line 1"),
        (
            "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\naltitude = { min = 0.0, max = 1.0 }\n",
            "takes no constraints",
        ),
        ("[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nroughness = -1.0\n", "roughness -1 is not in"),
    ];
    for (text, needle) in cases {
        let err = LayerTree::parse(text, "layers.toml").unwrap_err().to_string();
        assert!(
            err.contains("layers.toml") && err.contains(needle),
            "{err:?} lacks {needle:?}"
        );
        assert!(!err.contains('\n'), "one line: {err:?}");
    }
}

#[test]
fn colour_components_and_numeric_ranges_are_checked() {
    let layer = |extra: &str| format!("[root]\nname = \"rock\"\n{extra}\n");
    let bad = [
        ("color = [0.5, 0.5, 0.5, 1.0]", "color must have 3 components, has 4"),
        ("color = [0.5, 0.5]", "color must have 3 components, has 2"),
        ("color = [0.5, 1.5, 0.5]", "not linear albedo in [0, 1]"),
        ("color = [0.5, nan, 0.5]", "not linear albedo"),
        (
            "color = [0.5, 0.5, 0.5]\nroughness = 1e30",
            "roughness 1000000000000000000000000000000 is not in",
        ),
        ("color = [0.5, 0.5, 0.5]\nroughness = -1", "roughness -1 is not in"),
        ("color = [0.5, 0.5, 0.5]\nnoise_wavelength = 1e-30", "noise_wavelength"),
        (
            "color = [0.5, 0.5, 0.5]\nroughness_wavelength = inf",
            "roughness_wavelength inf",
        ),
        ("color = [0.5, 0.5, 0.5]\nnoise_bias = 1e9", "noise_bias"),
        ("color = [0.5, 0.5, 0.5]\nnoise_scale = nan", "noise_scale NaN"),
        ("color = [0.5, 0.5, 0.5]\nglow = 1", "unknown field"),
    ];
    for (extra, expected) in bad {
        assert_error(&layer(extra), "l.toml", expected);
    }
    let child = "[root]\nname = \"rock\"\ncolor = [0.5, 0.5, 0.5]\n[[root.children]]\nname = \"snow\"\n\
                 color = [1, 1, 1]\naltitude = { min = 0, max = 1e30 }\n";
    let message = LayerTree::parse(child, "l.toml").unwrap_err().to_string();
    assert!(
        message.contains("altitude: range and fuzz must lie within ±10000000"),
        "{message}"
    );
    assert!(LayerTree::parse(&layer("color = [0, 1, 0.25]"), "l.toml").is_ok());
}

#[test]
fn layer_files_are_read_through_read_input_as_utf8() {
    let path = std::env::temp_dir().join(format!("alpenglow-layers-{}.toml", std::process::id()));
    std::fs::write(&path, b"[root]\nname = \"r\xff\"\ncolor = [0, 0, 0]\n").unwrap();
    let message = LayerTree::load(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(
        message.ends_with("not UTF-8 text") && message.contains("alpenglow-layers"),
        "{message}"
    );
    let message = LayerTree::load(&std::env::temp_dir()).unwrap_err().to_string();
    assert!(message.contains("is a directory"), "{message}");
}

#[test]
fn toml_syntax_errors_are_one_line() {
    // toml's message for a bad float has two lines ("…\nexpected digit").
    let text = "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nroughness = 1.e\n";
    let message = LayerTree::parse(text, "l.toml").unwrap_err().to_string();
    assert!(message.contains("line 4: ") && !message.contains('\n'), "{message:?}");
}
