//! End-to-end tests of the terrain options of the `alpenglow` binary
//! (`--view`, `--lod`, `--no-terrain-detail`, `--terrain`, `--grid`,
//! `--sketch`, `--importance-off`, `--texturing`, `--layers`,
//! `--input-map`, `--tile-budget`) and of the `fly` subcommand (orbit and
//! keyframe paths, the frame directory, the JSON summary, error paths).
//!
//! Every command that creates a Vulkan device runs with `--validation`, so a
//! validation message fails the run (and the test). Scenes are tiny (a
//! 65×65 procedural terrain, 64×40 pixels) to keep each run around a second
//! on a software rasteriser.

mod common;

use common::cli::*;
use std::ffi::OsString;
use std::path::Path;

use serde_json::Value;

/// Image size of every render.
const WIDTH: u32 = 64;
const HEIGHT: u32 = 40;

/// The small scene most tests render: 65×65 samples, 40 m apart (2560 m).
const SMALL_TERRAIN: &str = "procedural:ridged,size=65,spacing=40";

/// An orbit around the centre of [`SMALL_TERRAIN`], well above it.
const SMALL_ORBIT: &str = "1280,1280,0,1800,1500";

/// `args` as owned OS strings, for mixing with paths.
fn os_args(args: &[&str]) -> Vec<OsString> {
    args.iter().map(OsString::from).collect()
}

/// The `render` arguments for a small image of `terrain` plus `extra`.
fn render_args(terrain: &str, extra: &[&str]) -> Vec<OsString> {
    let (w, h) = (WIDTH.to_string(), HEIGHT.to_string());
    let mut args = os_args(&[
        "render",
        "--validation",
        "--width",
        &w,
        "--height",
        &h,
        "--terrain",
        terrain,
    ]);
    args.extend(extra.iter().map(OsString::from));
    args
}

/// Renders `terrain` with `extra` options to `dir/name`, checks the PNG's
/// size and returns its decoded RGBA pixels.
fn render_png(dir: &Path, name: &str, terrain: &str, extra: &[&str]) -> Vec<u8> {
    let png = dir.join(name);
    let mut args = render_args(terrain, extra);
    args.extend([OsString::from("--out"), png.clone().into_os_string()]);
    let what = format!("render --terrain {terrain} {}", extra.join(" "));
    let out = run(&args);
    assert_success(&what, &out);
    assert!(
        text(&out.stderr).trim().is_empty(),
        "{what} printed on stderr:\n{}",
        text(&out.stderr)
    );
    let image = image::open(&png).unwrap_or_else(|e| panic!("{what}: the PNG does not decode: {e}"));
    assert_eq!((image.width(), image.height()), (WIDTH, HEIGHT), "{what}: PNG size");
    image.to_rgba8().into_raw()
}

/// Number of bytes in which two images differ.
fn differing_bytes(a: &[u8], b: &[u8]) -> usize {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// Runs `render` of the small scene (or of `terrain` when given) with
/// `extra` and every output in a fresh directory; expects a one-line error
/// mentioning `needles` and an empty directory afterwards.
fn expect_render_error(test: &str, terrain: Option<&str>, extra: &[&str], needles: &[&str]) {
    let dir = fresh_dir(test);
    let (w, h) = (WIDTH.to_string(), HEIGHT.to_string());
    let mut args = os_args(&["render", "--validation", "--width", &w, "--height", &h]);
    if let Some(terrain) = terrain {
        args.extend(os_args(&["--terrain", terrain]));
    }
    args.extend(extra.iter().map(OsString::from));
    args.extend(render_outputs(&dir, None).into_iter().map(OsString::from));
    let out = run(&args);
    let what = format!("render --terrain {terrain:?} {}", extra.join(" "));
    assert_one_line_error(&what, &out, needles);
    assert_no_files_left(&what, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- views

const VIEWS: [&str; 5] = ["shaded", "importance", "density-ratio", "split-octave", "wireframe"];

/// Every `--view` renders a PNG of the requested size; each debug view
/// differs from the shaded image and from every other debug view.
#[test]
fn every_view_renders_and_debug_views_differ() {
    let dir = fresh_dir("every_view");
    let images: Vec<(&str, Vec<u8>)> = VIEWS
        .iter()
        .map(|&view| {
            (
                view,
                render_png(&dir, &format!("{view}.png"), SMALL_TERRAIN, &["--view", view]),
            )
        })
        .collect();
    for (i, (a, image_a)) in images.iter().enumerate() {
        for (b, image_b) in &images[i + 1..] {
            assert!(
                differing_bytes(image_a, image_b) > 0,
                "--view {a} and --view {b} rendered identical images"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- LOD, detail

/// `--lod uniform` and `--no-terrain-detail` render, and each differs from
/// the default (warped, with detail) render.
#[test]
fn uniform_lod_and_detail_off_differ_from_default() {
    let dir = fresh_dir("lod_detail");
    let default = render_png(&dir, "default.png", SMALL_TERRAIN, &[]);
    let uniform = render_png(&dir, "uniform.png", SMALL_TERRAIN, &["--lod", "uniform"]);
    let no_detail = render_png(&dir, "no-detail.png", SMALL_TERRAIN, &["--no-terrain-detail"]);
    assert!(
        differing_bytes(&default, &uniform) > 0,
        "--lod uniform rendered the same image as --lod warped"
    );
    assert!(
        differing_bytes(&default, &no_detail) > 0,
        "--no-terrain-detail rendered the same image as the default"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- --terrain

#[test]
fn procedural_terrain_spec_renders() {
    let dir = fresh_dir("procedural_spec");
    let fbm = render_png(&dir, "fbm.png", "procedural:fbm,seed=3,size=65,spacing=50", &[]);
    assert!(
        fbm.chunks_exact(4).any(|p| p != &fbm[..4]),
        "the fbm terrain rendered a uniform image"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_terrain_spec_unknown_model() {
    expect_render_error(
        "bad_spec_model",
        Some("procedural:perlin"),
        &[],
        &["--terrain", "perlin"],
    );
}

#[test]
fn bad_terrain_spec_unknown_key() {
    expect_render_error(
        "bad_spec_key",
        Some("procedural:ridged,colour=1"),
        &[],
        &["--terrain", "colour"],
    );
}

#[test]
fn bad_terrain_spec_missing_prefix() {
    expect_render_error(
        "bad_spec_prefix",
        Some("ridged,size=65"),
        &[],
        &["--terrain", "procedural:"],
    );
}

#[test]
fn terrain_with_heightmap_is_refused() {
    // The height map exists and is valid: only the combination is wrong.
    let dem = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/jacksboro-fault.png");
    assert!(dem.is_file(), "missing fixture {}", dem.display());
    expect_render_error(
        "terrain_with_heightmap",
        Some(SMALL_TERRAIN),
        &["--heightmap", dem.to_str().unwrap()],
        &["--terrain", "--heightmap"],
    );
}

// ---------------------------------------------------------------- grid, sketch, importance

#[test]
fn grid_of_one_is_refused() {
    expect_render_error("grid_one", Some(SMALL_TERRAIN), &["--grid", "1"], &["--grid"]);
}

#[test]
fn sketch_of_two_is_refused() {
    expect_render_error("sketch_two", Some(SMALL_TERRAIN), &["--sketch", "2"], &["--sketch"]);
}

#[test]
fn all_importance_factors_off_renders() {
    let dir = fresh_dir("importance_off");
    render_png(
        &dir,
        "flat.png",
        SMALL_TERRAIN,
        &["--importance-off", "distance,frustum,backface,surface"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- texturing

/// A file in `tests/data` as an argument.
fn data_arg(name: &str) -> String {
    common::data(name).to_string_lossy().into_owned()
}

/// Every `--texturing` mode renders; classic differs from the layer tree;
/// the rainfall input map changes the image.
#[test]
fn texturing_modes_and_input_maps_render() {
    let dir = fresh_dir("texturing_modes");
    let atlas = render_png(&dir, "atlas.png", SMALL_TERRAIN, &["--tile-budget", "4"]);
    let direct = render_png(&dir, "direct.png", SMALL_TERRAIN, &["--texturing", "direct"]);
    let classic = render_png(&dir, "classic.png", SMALL_TERRAIN, &["--texturing", "classic"]);
    let (layers, map) = (
        data_arg("layers-rainfall.toml"),
        format!("rainfall={}", data_arg("rainfall.png")),
    );
    let rain = render_png(
        &dir,
        "rain.png",
        SMALL_TERRAIN,
        &["--layers", &layers, "--input-map", &map],
    );
    let pixels = (WIDTH * HEIGHT * 4) as usize;
    assert!(
        differing_bytes(&atlas, &classic) > pixels / 4,
        "classic looks like the layer tree"
    );
    assert!(
        differing_bytes(&atlas, &rain) > pixels / 4,
        "the rainfall tree looks like the default tree"
    );
    let close = atlas.iter().zip(&direct).filter(|(a, b)| a.abs_diff(**b) <= 12).count();
    assert!(
        close > pixels * 9 / 10,
        "atlas and direct differ in {} of {pixels} bytes",
        pixels - close
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--tile-budget` has one range, 1..=255 (one frame's texels fit one
/// dispatch): its ends render the same image, values outside it are one-line
/// errors naming the flag and the range.
#[test]
fn tile_budget_range_ends_render_and_outside_is_refused() {
    let dir = fresh_dir("tile_budget");
    let one = render_png(&dir, "one.png", SMALL_TERRAIN, &["--tile-budget", "1"]);
    let most = render_png(&dir, "most.png", SMALL_TERRAIN, &["--tile-budget", "255"]);
    assert_eq!(
        differing_bytes(&one, &most),
        0,
        "a settled frame does not depend on the budget"
    );
    let _ = std::fs::remove_dir_all(&dir);
    for value in ["0", "256", "4294967295"] {
        expect_render_error(
            &format!("tile_budget_{value}"),
            Some(SMALL_TERRAIN),
            &["--tile-budget", value],
            &["--tile-budget", value, "1..=255"],
        );
    }
}

#[test]
fn layer_using_a_missing_input_map_is_refused() {
    let layers = data_arg("layers-rainfall.toml");
    let needles = ["input map 'rainfall'", "--input-map rainfall=FILE"];
    expect_render_error(
        "missing_input_map",
        Some(SMALL_TERRAIN),
        &["--layers", &layers],
        &needles,
    );
}

#[test]
fn unknown_or_corrupt_input_map_is_refused() {
    expect_render_error(
        "unknown_input_map",
        Some(SMALL_TERRAIN),
        &["--input-map", "snow=x.png"],
        &["snow", "rainfall"],
    );
    let map = format!("rainfall={}", data_arg("truncated.png"));
    expect_render_error(
        "corrupt_input_map",
        Some(SMALL_TERRAIN),
        &["--input-map", &map],
        &["truncated.png"],
    );
}

// ---------------------------------------------------------------- fly

/// The `fly` arguments for the small scene with `frames` frames plus `extra`.
fn fly_args(frames: u32, extra: &[&str]) -> Vec<OsString> {
    let (w, h, n) = (WIDTH.to_string(), HEIGHT.to_string(), frames.to_string());
    let mut args = os_args(&[
        "fly",
        "--validation",
        "--width",
        &w,
        "--height",
        &h,
        "--terrain",
        SMALL_TERRAIN,
        "--frames",
        &n,
    ]);
    args.extend(extra.iter().map(OsString::from));
    args
}

/// `frame_00000.png` … for `n` frames.
fn frame_names(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("frame_{i:05}.png")).collect()
}

/// Checks that `dir` holds exactly `n` frames of the small image size.
fn assert_frames(what: &str, dir: &Path, n: usize) {
    assert_eq!(entries(dir), frame_names(n), "{what}: frame directory");
    for name in frame_names(n) {
        let image = image::open(dir.join(&name)).unwrap_or_else(|e| panic!("{what}: {name} does not decode: {e}"));
        assert_eq!((image.width(), image.height()), (WIDTH, HEIGHT), "{what}: {name} size");
    }
}

/// No staging directory (`.NAME.partial-PID`) is left in `parent`.
fn assert_no_partial(what: &str, parent: &Path) {
    let partial: Vec<String> = entries(parent).into_iter().filter(|n| n.contains(".partial")).collect();
    assert!(partial.is_empty(), "{what}: staging directories left: {partial:?}");
}

/// Where `fly --out-dir` points before the run.
#[derive(Clone, Copy, Debug, PartialEq)]
enum OutDir {
    /// A path that does not exist yet (the usual case).
    Missing,
    /// An existing, empty directory.
    Empty,
}

/// Runs `fly` with 3 frames, `path_args` (`--orbit …` or `--path …`),
/// `--out-dir ROOT/frames` (created first for [`OutDir::Empty`]) and
/// `--profile ROOT/fly.json`; checks the frames, the JSON and stdout and
/// returns the frame directory's images.
fn fly_frames(root: &Path, path_args: &[OsString], out_dir: OutDir) -> Vec<Vec<u8>> {
    let frames = root.join("frames");
    if out_dir == OutDir::Empty {
        std::fs::create_dir(&frames).unwrap();
    }
    let json = root.join("fly.json");
    let mut args = fly_args(3, &[]);
    args.extend(path_args.iter().cloned());
    args.extend([
        OsString::from("--out-dir"),
        frames.clone().into_os_string(),
        OsString::from("--profile"),
        json.clone().into_os_string(),
    ]);
    let out = run(&args);
    let what = format!("fly {} into a {out_dir:?} --out-dir", path_args[0].to_string_lossy());
    assert_success(&what, &out);
    assert_frames(&what, &frames, 3);
    assert_no_partial(&what, root);

    let j: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(j["frames"], 3, "{what}: JSON {j}");
    let gpu = &j["gpu_ms"];
    let (min, median, max) = (
        finite_ms(gpu, "min", "gpu_ms"),
        finite_ms(gpu, "median", "gpu_ms"),
        finite_ms(gpu, "max", "gpu_ms"),
    );
    assert!(min <= median && median <= max, "{what}: gpu_ms {gpu}");
    let per_frame = gpu["per_frame"].as_array().expect("gpu_ms.per_frame is an array");
    assert_eq!(per_frame.len(), 3, "{what}: gpu_ms.per_frame {gpu}");

    // stdout reports the GPU frame time as min / median / max.
    let stdout = text(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.contains("GPU frame time"))
        .unwrap_or_else(|| panic!("{what}: no GPU frame time on stdout:\n{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let numbers: Vec<f64> = ["min", "median", "max"]
        .iter()
        .map(|key| {
            let at = words
                .iter()
                .position(|w| w == key)
                .unwrap_or_else(|| panic!("{what}: no {key} in {line:?}"));
            words
                .get(at + 1)
                .and_then(|w| w.parse().ok())
                .unwrap_or_else(|| panic!("{what}: no number after {key} in {line:?}"))
        })
        .collect();
    assert!(
        numbers[0] <= numbers[1] && numbers[1] <= numbers[2],
        "{what}: stdout min/median/max out of order: {line:?}"
    );
    frame_names(3)
        .iter()
        .map(|name| image::open(frames.join(name)).unwrap().to_rgba8().into_raw())
        .collect()
}

fn orbit_args() -> Vec<OsString> {
    os_args(&["--orbit", SMALL_ORBIT])
}

#[test]
fn fly_orbit_writes_frames_and_json() {
    let root = fresh_dir("fly_orbit");
    fly_frames(&root, &orbit_args(), OutDir::Missing);
    assert_eq!(entries(&root), vec!["fly.json", "frames"], "files beside the frames");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn fly_orbit_into_empty_directory() {
    let root = fresh_dir("fly_orbit_empty");
    fly_frames(&root, &orbit_args(), OutDir::Empty);
    assert_eq!(entries(&root), vec!["fly.json", "frames"], "files beside the frames");
    let _ = std::fs::remove_dir_all(&root);
}

const TWO_KEYFRAMES: &str = "\
[[keyframe]]
time = 0.0
eye = [1280.0, -1500.0, 1500.0]
target = [1280.0, 1280.0, 0.0]

[[keyframe]]
time = 2.0
eye = [3500.0, 1280.0, 1200.0]
target = [1280.0, 1280.0, 0.0]
";

/// A keyframe path: frames written, and the camera moves (the first and
/// last frames differ).
fn fly_keyframes(test: &str, out_dir: OutDir) {
    let root = fresh_dir(test);
    let path = root.join("path.toml");
    std::fs::write(&path, TWO_KEYFRAMES).unwrap();
    let images = fly_frames(&root, &[OsString::from("--path"), path.into_os_string()], out_dir);
    assert_eq!(
        entries(&root),
        vec!["fly.json", "frames", "path.toml"],
        "files beside the frames"
    );
    assert!(
        differing_bytes(&images[0], &images[2]) > 0,
        "fly --path: first and last frames are identical"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn fly_keyframe_file_writes_frames() {
    fly_keyframes("fly_keyframes", OutDir::Missing);
}

#[test]
fn fly_keyframe_file_into_empty_directory() {
    fly_keyframes("fly_keyframes_empty", OutDir::Empty);
}

/// Runs `fly` with keyframe file `name` holding `contents`, first into an
/// existing empty `--out-dir` (left empty), then into one that does not
/// exist (not created): each time a one-line error naming the file and no
/// staging directory beside the frame directory.
fn expect_bad_keyframes(test: &str, name: &str, contents: &str) {
    let root = fresh_dir(test);
    let path = root.join(name);
    std::fs::write(&path, contents).unwrap();
    let frames = root.join("frames");
    for out_dir in [OutDir::Empty, OutDir::Missing] {
        if out_dir == OutDir::Empty {
            std::fs::create_dir(&frames).unwrap();
        }
        let mut args = fly_args(3, &[]);
        args.extend([
            OsString::from("--path"),
            path.clone().into_os_string(),
            OsString::from("--out-dir"),
            frames.clone().into_os_string(),
        ]);
        let out = run(&args);
        let what = format!("fly --path {name} into a {out_dir:?} --out-dir");
        assert_one_line_error(&what, &out, &[name]);
        assert_no_partial(&what, &root);
        if out_dir == OutDir::Empty {
            assert!(entries(&frames).is_empty(), "{what}: files left in the frame directory");
            std::fs::remove_dir(&frames).unwrap();
        } else {
            assert!(!frames.exists(), "{what}: the frame directory was created");
        }
        assert_eq!(entries(&root), vec![name.to_string()], "{what}: files left behind");
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn fly_refuses_a_single_keyframe() {
    let one = TWO_KEYFRAMES.split("\n\n").next().unwrap();
    expect_bad_keyframes("fly_one_keyframe", "one-keyframe.toml", one);
}

#[test]
fn fly_refuses_non_increasing_times() {
    let same = TWO_KEYFRAMES.replace("time = 2.0", "time = 0.0");
    expect_bad_keyframes("fly_same_times", "same-times.toml", &same);
    let backwards = TWO_KEYFRAMES.replace("time = 2.0", "time = -1.0");
    expect_bad_keyframes("fly_backwards_times", "backwards-times.toml", &backwards);
}

#[test]
fn fly_refuses_toml_syntax_error() {
    let broken = TWO_KEYFRAMES.replacen("[[keyframe]]", "[[keyframe]", 1);
    expect_bad_keyframes("fly_toml_syntax", "broken.toml", &broken);
}

#[test]
fn fly_refuses_non_empty_out_dir() {
    let root = fresh_dir("fly_non_empty");
    let frames = root.join("frames");
    std::fs::create_dir(&frames).unwrap();
    let keep = frames.join("keep.txt");
    std::fs::write(&keep, "precious").unwrap();
    let mut args = fly_args(3, &["--orbit", SMALL_ORBIT]);
    args.extend([OsString::from("--out-dir"), frames.clone().into_os_string()]);
    let out = run(&args);
    let what = "fly --out-dir <non-empty directory>";
    assert_one_line_error(what, &out, &["--out-dir", "frames"]);
    assert_eq!(entries(&frames), vec!["keep.txt"], "{what}: directory changed");
    assert_eq!(
        std::fs::read_to_string(&keep).unwrap(),
        "precious",
        "{what}: file changed"
    );
    assert_eq!(entries(&root), vec!["frames"], "{what}: files left beside it");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn fly_refuses_zero_frames() {
    let root = fresh_dir("fly_zero_frames");
    let frames = root.join("frames");
    let json = root.join("fly.json");
    let mut args = fly_args(0, &["--orbit", SMALL_ORBIT]);
    args.extend([
        OsString::from("--out-dir"),
        frames.into_os_string(),
        OsString::from("--profile"),
        json.into_os_string(),
    ]);
    let out = run(&args);
    assert_one_line_error("fly --frames 0", &out, &["--frames"]);
    assert!(entries(&root).is_empty(), "fly --frames 0 left {:?}", entries(&root));
    let _ = std::fs::remove_dir_all(&root);
}

// ------------------------------------------------- hostile inputs (issue 15)

/// Absurd PNG headers as `--heightmap` and as `--input-map` are one-line
/// errors (they aborted the process), so are a FIFO and /dev/zero, and
/// out-of-range spacings name their option and the range.
#[test]
fn hostile_heightmaps_input_maps_and_spacings_are_one_line_errors() {
    let dir = fresh_dir("hostile-inputs");
    let absurd = dir.join("absurd.png");
    std::fs::write(&absurd, common::absurd_png(150_000, 100_000)).unwrap();
    let absurd = absurd.to_str().unwrap().to_string();
    let map = format!("rainfall={absurd}");
    expect_render_error(
        "hostile-heightmap",
        None,
        &["--heightmap", &absurd],
        &["absurd.png", "largest supported side"],
    );
    expect_render_error(
        "hostile-input-map",
        Some(SMALL_TERRAIN),
        &["--input-map", &map],
        &["absurd.png", "largest supported side"],
    );
    let fifo = dir.join("fifo.png");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let fifo = fifo.to_str().unwrap().to_string();
    expect_render_error(
        "hostile-fifo",
        None,
        &["--heightmap", &fifo],
        &["is a FIFO, not a regular file"],
    );
    expect_render_error(
        "hostile-dev-zero",
        None,
        &["--heightmap", "/dev/zero"],
        &["/dev/zero: is a character device"],
    );
    for bad in ["1e30", "1e-30"] {
        expect_render_error(
            "hostile-spacing",
            Some(SMALL_TERRAIN),
            &["--spacing", bad],
            &["--spacing", "0.001..=100000 m"],
        );
        let spec = format!("procedural:fbm,size=65,spacing={bad}");
        expect_render_error(
            "hostile-spec-spacing",
            Some(&spec),
            &[],
            &["spacing=", "0.001..=100000 m"],
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
