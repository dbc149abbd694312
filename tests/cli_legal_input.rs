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

/// Writes `text` to `dir/name` and returns the path as a string.
fn file(dir: &std::path::Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

/// Values that were accepted though wrong: a rig view named "" (its files
/// had no name), `{view}` without a rig (it expanded to nothing).
#[test]
fn nameless_views_are_refused() {
    let dir = fresh_dir("nameless-views");
    let out = dir.join("o.png");
    for (rig, view) in [
        ("[[view]]\nname = \"\"\n", "view 1"),
        ("[[view]]\nname = \"front\"\n[[view]]\nname = \"\"\n", "view 2"),
    ] {
        let rig = file(&dir, "rig.toml", rig);
        let pattern = dir.join("o_{view}.png");
        let result = run(&["render", "--rig", &rig, "--out", pattern.to_str().unwrap()]);
        assert_one_line_error("a view named \"\"", &result, &[&rig, view, "name ''"]);
    }
    for flag in ["--out", "--exr"] {
        let pattern = dir.join("o_{view}.png");
        let result = run(&["render", flag, pattern.to_str().unwrap()]);
        assert_one_line_error(&format!("{flag} with {{view}}"), &result, &[flag, "{view}", "--rig"]);
    }
    assert_eq!(entries(&dir), ["rig.toml"], "a refused render wrote something");
    assert!(!out.exists());
}

/// User-supplied layer names reach the terminal (the pass names of the
/// profile line) with their control characters escaped, not raw.
#[test]
fn layer_names_are_escaped_on_the_terminal() {
    let dir = fresh_dir("layer-names");
    let layers = file(
        &dir,
        "layers.toml",
        "[root]\nname = \"ro\\u001b[2Jck\"\ncolor = [0.3, 0.27, 0.24]\n\n\
         [[root.children]]\nname = \"gr\\u0007ass\"\ncolor = [0.16, 0.24, 0.08]\n\
         slope = { min = 0.0, max = 30.0, fuzz = 4.0 }\n",
    );
    let png = dir.join("o.png");
    let out = render(
        "procedural:ridged,size=33,spacing=40",
        &["--layers", &layers, "--out", png.to_str().unwrap()],
    );
    assert_success("render with control characters in layer names", &out);
    let stdout = text(&out.stdout);
    assert!(
        !stdout.contains('\u{1b}') && !stdout.contains('\u{7}'),
        "raw control characters: {stdout:?}"
    );
    assert!(
        stdout.contains("ro\\u{1b}[2Jck") && stdout.contains("gr\\u{7}ass"),
        "{stdout}"
    );
}

/// Errors name the option the user wrote: an orbit beyond the camera's
/// limits is --orbit's (was --eye's), a rig view's distortion is the rig
/// file's and the view's (was --distortion's), a fill whose input is all
/// voids is the input's (was a mask's, though none was given).
#[test]
fn errors_name_the_culprit() {
    let dir = fresh_dir("culprits");
    for orbit in ["0,0,0,1e9,5", "0,0,0,1e-9,1000", "9e7,0,0,2e7,5"] {
        let out = run(&[
            "fly", "--frames", "2", "--width", "32", "--height", "24", "--orbit", orbit,
        ]);
        assert_one_line_error(&format!("--orbit {orbit}"), &out, &["--orbit"]);
        assert!(!text(&out.stderr).contains("--eye"), "{}", text(&out.stderr));
    }
    let rig = file(
        &dir,
        "rig.toml",
        "[[view]]\nname = \"wide\"\nfov_y = 120\nk1 = -1\nk2 = -1\n",
    );
    let pattern = dir.join("o_{view}.png");
    let out = run(&["render", "--rig", &rig, "--out", pattern.to_str().unwrap()]);
    assert_one_line_error("a rig's folding distortion", &out, &[&rig, "view 'wide'"]);
    assert!(!text(&out.stderr).contains("--distortion"), "{}", text(&out.stderr));

    let voids = dir.join("voids.exr");
    let nan = vec![f32::NAN; 16 * 16];
    std::fs::write(&voids, alpenglow::files::encode_exr_height(&nan, 16, 16).unwrap()).unwrap();
    let filled = dir.join("filled.exr");
    let out = run(&[
        "synth",
        "fill",
        "--input",
        voids.to_str().unwrap(),
        "--spacing",
        "10",
        "--out",
        filled.to_str().unwrap(),
    ]);
    assert_one_line_error(
        "fill of an input of voids only",
        &out,
        &[voids.to_str().unwrap(), "voids"],
    );
    assert!(!text(&out.stderr).contains("invalid mask"), "{}", text(&out.stderr));
    assert!(!filled.exists());
}

/// A malformed layer manifest in VK_LAYER_PATH: the validation layer could
/// not be loaded, naming VK_LAYER_PATH (was "a host memory allocation has
/// failed"); without --validation no layer is needed.
#[test]
fn a_malformed_layer_manifest_names_vk_layer_path() {
    let dir = fresh_dir("layer-manifest");
    let layers = dir.join("layers");
    std::fs::create_dir(&layers).unwrap();
    std::fs::write(
        layers.join("broken.json"),
        "{\"file_format_version\": \"1.2.0\", \"layer\": {",
    )
    .unwrap();
    let png = dir.join("o.png");
    let out = std::process::Command::new(bin())
        .args([
            "render",
            "--validation",
            "--width",
            "32",
            "--height",
            "24",
            "--vegetation",
            "off",
        ])
        .arg("--out")
        .arg(&png)
        .env("VK_LAYER_PATH", &layers)
        .env(
            "XDG_CACHE_HOME",
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .output()
        .unwrap();
    assert_one_line_error(
        "a malformed manifest",
        &out,
        &["validation layer", "VK_LAYER_PATH", layers.to_str().unwrap()],
    );
    assert!(!png.exists());
    // Without --validation the loader still reads the manifest: the error
    // says so and names VK_LAYER_PATH too.
    let out = std::process::Command::new(bin())
        .arg("info")
        .env("VK_LAYER_PATH", &layers)
        .output()
        .unwrap();
    if !out.status.success() {
        assert_one_line_error("info with a malformed manifest", &out, &["VK_LAYER_PATH", "manifest"]);
    }
}

/// Found by the hour-long CLI property run: a `--pose` whose translation is
/// beyond the camera limits was reported as `--eye`, and `--fov-y 1e-300`
/// (legal in degrees, infinite in the GPU's 32-bit projection) as
/// `--epsilon 1`. Both fail before anything renders.
#[test]
fn pose_and_narrow_fields_of_view_name_their_option() {
    let pose = "1,0,0,10,0,1,0,20,0,0,1,1.8446744073709552e19,0,0,0,1";
    let o = run(&["render", "--width", "32", "--height", "24", "--pose", pose]);
    assert_one_line_error("--pose beyond the limits", &o, &["invalid --pose", "1e8"]);
    let o = run(&["render", "--width", "32", "--height", "24", "--fov-y", "1e-300"]);
    assert_one_line_error("--fov-y 1e-300", &o, &["--fov-y", "32-bit projection"]);
}
