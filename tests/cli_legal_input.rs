//! End-to-end tests of legal input at the edges of what the `alpenglow`
//! binary accepts: terrains a thousand times longer than wide, millimetre
//! and continent-sized terrains with the automatic camera and orbit, and
//! the errors that must name the option the user wrote (not one the
//! program filled in).
//!
//! Every command that creates a Vulkan device runs with `--validation`;
//! images are 32×24 pixels.

mod common;

use common::cli::*;

/// `render` of `terrain` at 32×24 with validation, plus `extra`.
fn render(terrain: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "render",
        "--validation",
        "--width",
        "32",
        "--height",
        "24",
        "--terrain",
        terrain,
    ];
    args.extend(extra);
    run(&args)
}

/// A strip 2048 samples long and 2 wide renders, lengthwise in x with
/// `render` and in y with `fly` (both panicked in the sketch map: its
/// smallest region was wider than the strip).
#[test]
fn strips_render() {
    let dir = fresh_dir("strips");
    let png = dir.join("strip.png");
    let out = render(
        "procedural:fbm,size=2048:2,spacing=30",
        &["--out", png.to_str().unwrap()],
    );
    assert_success("render of a 2048×2 strip", &out);
    assert!(png.is_file(), "no image written");
    let frames = dir.join("frames");
    let out = run(&[
        "fly",
        "--validation",
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "2",
        "--terrain",
        "procedural:fbm,size=2:2048,spacing=1",
        "--out-dir",
        frames.to_str().unwrap(),
    ]);
    assert_success("fly over a 2×2048 strip", &out);
    assert_eq!(entries(&frames).len(), 2, "{:?}", entries(&frames));
}

/// Terrains whose automatic camera used to be invalid (and blamed --eye,
/// --up or --near/--far, which the user never gave) render with it: one
/// larger than the camera's coordinate limit, a 2×2 millimetre field, and
/// a millimetre field a hundred kilometres high.
#[test]
fn the_automatic_camera_fits_every_terrain() {
    let dir = fresh_dir("automatic-camera");
    for (k, terrain) in [
        "procedural:fbm,size=1100:2,spacing=100000",
        "procedural:fbm,size=2,spacing=0.001",
        "procedural:fbm,size=3,spacing=0.001,wavelength=0.002,amplitude=100000",
    ]
    .into_iter()
    .enumerate()
    {
        let png = dir.join(format!("{k}.png"));
        let out = render(terrain, &["--out", png.to_str().unwrap()]);
        assert_success(&format!("render --terrain {terrain}"), &out);
        assert!(png.is_file(), "{terrain}: no image written");
    }
}
