//! `height_blur` (§8.2.3, snow in furrows): parsing, validation, and the
//! CPU reference on a V-shaped furrow.

use super::*;
use crate::io::heightmap::HeightField;
use crate::texturing::reference::ReferenceSurface;

#[test]
fn height_blur_parses_and_is_checked() {
    let tree = LayerTree::parse(&tree_with("height_blur = 30.0"), "b.toml").unwrap();
    assert_eq!(tree.layers[1].layer.height_blur, Some(30.0));
    assert_eq!(tree.blur_radii(), [30.0]);
    assert_eq!(LayerTree::default_tree().blur_radii(), Vec::<f32>::new());
    let cases = [
        (
            "height_blur = 0.0",
            "line 5: layer 'c': height_blur 0 is not in (0, 100000] m",
        ),
        ("height_blur = -3", "height_blur -3 is not in"),
        ("height_blur = nan", "height_blur NaN is not in"),
        ("height_blur = 1e6", "height_blur 1000000 is not in"),
        ("height_blur = \"far\"", "line 8"),
    ];
    for (extra, needle) in cases {
        assert_error(&tree_with(extra), "b.toml", needle);
    }
    let root = "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\nheight_blur = 5.0\n";
    let message = LayerTree::parse(root, "b.toml").unwrap_err().to_string();
    assert!(message.contains("takes no constraints"), "{message}");
    // Two radii are fine (repeats count once), three are not.
    let layer =
        |name: &str, r: f32| format!("[[root.children]]\nname = \"{name}\"\ncolor = [1, 1, 1]\nheight_blur = {r}\n");
    let root = "[root]\nname = \"r\"\ncolor = [0.1, 0.1, 0.1]\n";
    let two = format!("{root}{}{}{}", layer("a", 10.0), layer("b", 20.0), layer("c", 10.0));
    assert_eq!(LayerTree::parse(&two, "b.toml").unwrap().blur_radii(), [10.0, 20.0]);
    let three = format!("{two}{}", layer("d", 5.0));
    let message = LayerTree::parse(&three, "b.toml").unwrap_err().to_string();
    assert!(
        message.contains("b.toml")
            && message.contains("3 distinct height_blur radii [10.0, 20.0, 5.0]; a tree has at most 2"),
        "{message}"
    );
}

/// Snow above 110 m on slopes up to 30°, no noise; `blur` its height_blur.
fn snow_tree(blur: &str) -> LayerTree {
    let text = format!(
        "[root]\nname = \"rock\"\ncolor = [0.3, 0.3, 0.3]\n[[root.children]]\nname = \"snow\"\n\
         color = [0.9, 0.9, 0.9]\naltitude = {{ min = 110.0, max = 1e4, fuzz = 2.0 }}\n\
         slope = {{ min = -10.0, max = 30.0, fuzz = 2.0 }}\n{blur}\n"
    );
    LayerTree::parse(&text, "snow").unwrap()
}

/// A V-shaped furrow along y at x = 320 m, 40° flanks, its bottom 100 m,
/// 65 × 65 samples 10 m apart: `height_blur` fills the furrow
/// (the blurred bottom lies higher and is flat, so snow holds there) and
/// leaves the flanks alone further than 3σ from the bottom.
#[test]
fn a_blurred_height_lays_snow_in_a_furrow() {
    let tan = 40f64.to_radians().tan();
    let field = HeightField::from_fn(65, 65, DVec2::splat(10.0), |c, _| {
        (100.0 + tan * (f64::from(c) * 10.0 - 320.0).abs()) as f32
    });
    let maps = [None, None, None];
    let coverage = |tree: &LayerTree, x: f64| {
        let reference = ReferenceSurface::new(&field, tree, &maps, 1).unwrap();
        reference.evaluate(DVec2::new(x, 320.0), 10.0).coverage[1]
    };
    let sharp = snow_tree("");
    let blurred = snow_tree("height_blur = 30.0");
    // The bottom: below the snow line and steep on either side without blur.
    assert_eq!(coverage(&sharp, 320.0), 0.0);
    let filled = coverage(&blurred, 320.0);
    assert_eq!(filled, 1.0, "furrow bottom with height_blur");
    // Within about σ of the bottom the blurred surface is still gentle.
    assert!(coverage(&blurred, 340.0) > 0.5, "{}", coverage(&blurred, 340.0));
    // On the flanks beyond 3σ both see the same 40° slope: no snow.
    assert_eq!(coverage(&sharp, 450.0), 0.0);
    assert_eq!(coverage(&blurred, 450.0), 0.0);
}
