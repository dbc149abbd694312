//! Sampled functions (§8.3): parsing, validation, evaluation and packing.

use super::*;
use crate::surface::gpu_layout::{pack_layers, GpuLayer};

fn sampled(min: f32, max: f32, samples: &[f32]) -> SampledFunction {
    SampledFunction {
        min,
        max,
        samples: samples.to_vec(),
    }
}

#[test]
fn sampled_functions_parse_with_default_and_given_domains() {
    let text = tree_with(
        "slope = { samples = [0.2, 0.9, 1.0, 0.4] }\n\
         altitude = { samples = [0.1, 0.5, 1.0], min = 2281.0, max = 4261.0 }\n\
         elevation = { samples = [1.0] }\n\
         rainfall = { samples = [0, 1], min = -5, max = 5 }\n\
         temperature = { min = 0.0, max = 30.0, fuzz = 2.0 }",
    );
    let tree = LayerTree::parse(&text, "s.toml").unwrap();
    let c = &tree.layers[1].layer;
    let slope = Constraint::Sampled(sampled(0.0, 90.0, &[0.2, 0.9, 1.0, 0.4]));
    assert_eq!(c.slope, Some(slope));
    let altitude = Constraint::Sampled(sampled(2281.0, 4261.0, &[0.1, 0.5, 1.0]));
    assert_eq!(c.altitude, Some(altitude));
    assert_eq!(c.elevation, Some(Constraint::Sampled(sampled(0.0, 1.0, &[1.0]))));
    assert_eq!(c.inputs[0], Some(Constraint::Sampled(sampled(-5.0, 5.0, &[0.0, 1.0]))));
    assert_eq!(c.inputs[1], None);
    assert_eq!(c.inputs[2], hat_constraint(0.0, 30.0, 2.0));
    assert!(tree.uses_input(0) && !tree.uses_input(1) && tree.uses_input(2));
    // One bound given: the other is the default domain's.
    let tree = LayerTree::parse(&tree_with("slope = { samples = [1.0], max = 45 }"), "s.toml").unwrap();
    assert_eq!(
        tree.layers[1].layer.slope,
        Some(Constraint::Sampled(sampled(0.0, 45.0, &[1.0])))
    );
    let most = format!("slope = {{ samples = [{}] }}", vec!["0.5"; MAX_SAMPLES].join(", "));
    assert!(LayerTree::parse(&tree_with(&most), "s.toml").is_ok());
}

#[test]
fn bad_sampled_functions_are_one_line_errors_naming_file_line_layer_and_key() {
    let too_many = format!("slope = {{ samples = [{}] }}", vec!["0.5"; MAX_SAMPLES + 1].join(", "));
    let cases = [
        (
            "slope = { samples = [] }",
            "slope: 0 samples; a sampled function has 1 to 64",
        ),
        (too_many.as_str(), "slope: 65 samples; a sampled function has 1 to 64"),
        (
            "slope = { samples = [0.5, 1.5] }",
            "slope: sample 1 is 1.5, not in [0, 1]",
        ),
        ("slope = { samples = [nan] }", "slope: sample 0 is NaN, not in [0, 1]"),
        ("slope = { samples = [-0.1] }", "sample 0 is -0.1"),
        (
            "altitude = { samples = [0.5] }",
            "altitude: a sampled function needs min and max here",
        ),
        (
            "altitude = { samples = [0.5], min = 3 }",
            "altitude: a sampled function needs min and max",
        ),
        (
            "radiation = { samples = [0.5] }",
            "radiation: a sampled function needs min and max",
        ),
        (
            "elevation = { samples = [0.5], min = 1, max = 1 }",
            "elevation: min 1 is not below max 1",
        ),
        (
            "slope = { samples = [0.5], min = 95 }",
            "slope: min 95 is not below max 90",
        ),
        (
            "slope = { samples = [0.5], max = inf }",
            "slope: min and max must be finite",
        ),
        ("slope = { samples = [0.5], max = 1e30 }", "within ±10000000"),
        ("slope = { samples = [0.5], fuzz = 2 }", "slope: fuzz belongs to hats"),
        ("slope = { sample = [0.5] }", "unknown field `sample`"),
        ("slope = { samples = 0.5 }", "line 8"),
        ("slope = { max = 5 }", "slope: a hat needs min and max"),
    ];
    for (constraint, needle) in cases {
        let message = assert_error(&tree_with(constraint), "s.toml", needle);
        if !needle.starts_with("line") && !needle.starts_with("unknown") {
            assert!(message.contains("line 5: layer 'c': "), "{constraint}: {message}");
        }
    }
    let root = "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nslope = { samples = [1.0] }\n";
    let message = LayerTree::parse(root, "s.toml").unwrap_err().to_string();
    assert!(message.contains("takes no constraints"), "{message}");
}

#[test]
fn sampled_functions_interpolate_between_bin_centres() {
    // Four bins over [0, 80]: centres 10, 30, 50, 70.
    let f = sampled(0.0, 80.0, &[0.2, 0.9, 1.0, 0.4]);
    for (a, expected) in [(10.0, 0.2), (30.0, 0.9), (50.0, 1.0), (70.0, 0.4)] {
        assert_eq!(f.eval(a), expected, "centre {a}");
    }
    // Halfway between centres: the mean; a quarter: a quarter of the way.
    assert!((f.eval(20.0) - 0.55).abs() < 1e-6, "{}", f.eval(20.0));
    assert!((f.eval(55.0) - 0.85).abs() < 1e-6, "{}", f.eval(55.0));
    // Outer half-bins hold the end values, the ends included.
    for (a, expected) in [(0.0, 0.2), (4.0, 0.2), (76.0, 0.4), (80.0, 0.4)] {
        assert_eq!(f.eval(a), expected, "end {a}");
    }
    // Outside the domain and NaN: 0.
    for a in [-1e-3, 80.001, -1e30, 1e30, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(f.eval(a), 0.0, "{a}");
    }
    // One sample: constant over the domain.
    let one = sampled(-1.0, 1.0, &[0.7]);
    assert_eq!(
        (one.eval(-1.0), one.eval(0.3), one.eval(1.0), one.eval(1.5)),
        (0.7, 0.7, 0.7, 0.0)
    );
    // Through the enum and the coverage product.
    let c = Constraint::Sampled(f);
    assert_eq!(c.eval(30.0), 0.9);
    let mut l = leaf("c", [1.0; 3]);
    l.slope = Some(c);
    l.altitude = hat_constraint(0.0, 100.0, 0.0);
    let inputs = |slope| LayerInputs {
        altitude: 50.0,
        elevation: 0.5,
        slope,
        maps: [f32::NAN; 3],
    };
    assert_eq!(coverage(&l, &inputs(50.0), 0.0), 1.0);
    assert!((coverage(&l, &inputs(20.0), 0.0) - 0.55).abs() < 1e-6);
    assert_eq!(coverage(&l, &inputs(85.0), 0.0), 0.0);
}

#[test]
fn packed_constraints_point_at_their_samples_after_the_layers() {
    let text = tree_with(
        "slope = { samples = [0.2, 0.9, 1.0, 0.4] }\n\
         altitude = { min = 10.0, max = 20.0, fuzz = 1.0 }\n\
         temperature = { samples = [0.25, 0.75], min = -10, max = 30 }",
    );
    let tree = LayerTree::parse(&text, "s.toml").unwrap();
    let packed = pack_layers(&tree, &[]);
    assert_eq!(packed.layers.len(), 2);
    assert_eq!(packed.samples, [0.2, 0.9, 1.0, 0.4, 0.25, 0.75]);
    let floats = (2 * std::mem::size_of::<GpuLayer>() / 4) as f32;
    let hats = packed.layers[1].hats;
    assert_eq!(hats[0], [10.0, 20.0, 1.0, 1.0]);
    assert_eq!(hats[1], [0.0; 4]);
    assert_eq!(hats[2], [0.0, 90.0, floats, 5.0]);
    assert_eq!(hats[5], [-10.0, 30.0, floats + 4.0, 3.0]);
    let bytes = packed.bytes();
    assert_eq!(bytes.len(), 2 * std::mem::size_of::<GpuLayer>() + 6 * 4);
    // The shader reads sample k of a constraint at float z + k.
    let as_floats: &[f32] = bytemuck::cast_slice(&bytes);
    assert_eq!(as_floats[hats[5][2] as usize + 1], 0.75);
    // Hat-only trees pack exactly as before: no samples.
    let packed = pack_layers(&LayerTree::default_tree(), &[]);
    assert!(packed.samples.is_empty() && packed.bytes().len() == packed.layers.len() * 144);
}
