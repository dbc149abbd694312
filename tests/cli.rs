//! End-to-end tests of the `alpenglow` binary: error paths (one line on
//! stderr, non-zero exit, no output files), a full render with every output,
//! determinism, the contents of the EXR, `info` and `bench`.
//!
//! Every command that creates a Vulkan device runs with `--validation`, so a
//! validation message fails the run (and the test).

mod common;

use common::cli::*;
use common::data;

use serde_json::Value;

/// A test fixture in `tests/data`.
/// Runs `render` with `scene_args` plus every output (PNG, EXR, profile,
/// trace) in a fresh directory, expects a one-line error mentioning
/// `needles`, and checks that the directory is still empty (no output and
/// no temporary file). Adds a small size unless `scene_args` sets one.
fn expect_render_error(test: &str, scene_args: &[&str], needles: &[&str]) {
    let dir = fresh_dir(test);
    let mut args: Vec<String> = vec!["render".into(), "--validation".into()];
    if !scene_args.contains(&"--width") {
        args.extend(["--width".into(), "32".into()]);
    }
    if !scene_args.contains(&"--height") {
        args.extend(["--height".into(), "32".into()]);
    }
    args.extend(scene_args.iter().map(|s| s.to_string()));
    args.extend(render_outputs(&dir, None));
    let out = run(&args);
    let what = format!("render {}", scene_args.join(" "));
    assert_one_line_error(&what, &out, needles);
    assert_no_files_left(&what, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

fn heightmap_error(test: &str, file: &str) {
    let path = data(file);
    expect_render_error(test, &["--heightmap", path.to_str().unwrap()], &[file]);
}

// ---------------------------------------------------------------- errors

#[test]
fn missing_heightmap() {
    heightmap_error("missing_heightmap", "no-such-heightmap.png");
}

#[test]
fn truncated_png() {
    heightmap_error("truncated_png", "truncated.png");
}

#[test]
fn empty_file() {
    heightmap_error("empty_file", "empty.png");
}

#[test]
fn not_an_image() {
    heightmap_error("not_an_image", "not-an-image.png");
}

#[test]
fn colour_png() {
    heightmap_error("colour_png", "colour.png");
}

#[test]
fn nan_heights_exr() {
    heightmap_error("nan_heights_exr", "nan.exr");
}

#[test]
fn zero_width() {
    expect_render_error("zero_width", &["--width", "0"], &["--width"]);
}

#[test]
fn zero_height() {
    expect_render_error("zero_height", &["--height", "0"], &["--height"]);
}

#[test]
fn huge_width() {
    expect_render_error("huge_width", &["--width", "100000"], &["--width"]);
}

#[test]
fn eye_equals_target() {
    expect_render_error("eye_equals_target", &["--eye", "1,2,3", "--target", "1,2,3"], &["eye"]);
}

#[test]
fn unparsable_eye() {
    expect_render_error("unparsable_eye", &["--eye", "1,2"], &["--eye"]);
}

#[test]
fn zero_fov() {
    expect_render_error("zero_fov", &["--fov-y", "0"], &["--fov-y"]);
}

#[test]
fn near_beyond_far() {
    expect_render_error("near_beyond_far", &["--near", "10", "--far", "5"], &["--near", "--far"]);
}

/// Each output flag in turn points into a directory that does not exist
/// while the others are valid: one error naming the directory, nothing
/// written anywhere.
#[test]
fn output_into_missing_directory() {
    let dir = fresh_dir("output_into_missing_directory");
    let missing = dir.join("does-not-exist");
    for (flag, file) in RENDER_OUTPUTS {
        let mut args: Vec<String> = ["render", "--validation", "--width", "32", "--height", "32"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        args.extend(render_outputs(&dir, Some((flag, &missing))));
        let out = run(&args);
        let what = format!("render {flag} into a missing directory");
        assert_one_line_error(&what, &out, &["does-not-exist", file]);
        assert!(!missing.exists(), "{what}: the directory was created");
        assert_no_files_left(&what, &dir);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An output that can only fail when it is written (its path is an existing
/// directory) must not leave the outputs written before it behind: a failed
/// render writes nothing.
#[test]
fn failing_later_output_leaves_no_earlier_file() {
    let dir = fresh_dir("failing_later_output");
    let blocker = dir.join("blocker");
    std::fs::create_dir(&blocker).unwrap();
    let png = dir.join("o.png");
    let profile = dir.join("p.json");
    let out = run(&[
        "render".as_ref(),
        "--validation".as_ref(),
        "--width".as_ref(),
        "32".as_ref(),
        "--height".as_ref(),
        "32".as_ref(),
        "--out".as_ref(),
        png.as_os_str(),
        "--exr".as_ref(),
        blocker.as_os_str(),
        "--profile".as_ref(),
        profile.as_os_str(),
    ]);
    assert_one_line_error("render --exr <existing directory>", &out, &["blocker"]);
    assert_eq!(
        entries(&dir),
        vec!["blocker".to_string()],
        "a failed render left files behind"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same for `bench`: the JSON summary is written before the trace, so a
/// trace path that cannot be written must not leave the JSON behind.
#[test]
fn bench_failing_trace_leaves_no_json() {
    let dir = fresh_dir("bench_failing_trace");
    let blocker = dir.join("blocker");
    std::fs::create_dir(&blocker).unwrap();
    let json = dir.join("b.json");
    let out = run(&[
        "bench".as_ref(),
        "--validation".as_ref(),
        "--frames".as_ref(),
        "1".as_ref(),
        "--warmup".as_ref(),
        "0".as_ref(),
        "--width".as_ref(),
        "32".as_ref(),
        "--height".as_ref(),
        "32".as_ref(),
        "--profile".as_ref(),
        json.as_os_str(),
        "--trace".as_ref(),
        blocker.as_os_str(),
    ]);
    assert_one_line_error("bench --trace <existing directory>", &out, &["blocker"]);
    assert_eq!(
        entries(&dir),
        vec!["blocker".to_string()],
        "a failed bench left files behind"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- success

/// Passes every render has, and those of the terrain's path (the
/// profile's `"raster"`): the compute path shades the sky in terrain.shade.
const RENDER_PASSES: [&str; 3] = ["terrain.warp", "tonemap", "readback"];

fn path_passes(raster: &Value) -> &'static [&'static str] {
    match raster.as_str() {
        Some("hardware") => &["sky", "terrain.draw"],
        Some("compute") => &["terrain.raster", "terrain.shade"],
        other => panic!("the profile names no raster path: {other:?}"),
    }
}

#[test]
fn render_writes_every_output() {
    let dir = fresh_dir("render_writes_every_output");
    let (png, exr, profile, trace) = (
        dir.join("a.png"),
        dir.join("a.exr"),
        dir.join("p.json"),
        dir.join("t.json"),
    );
    let out = run(&[
        "render".as_ref(),
        "--validation".as_ref(),
        "--width".as_ref(),
        "160".as_ref(),
        "--height".as_ref(),
        "90".as_ref(),
        "--out".as_ref(),
        png.as_os_str(),
        "--exr".as_ref(),
        exr.as_os_str(),
        "--profile".as_ref(),
        profile.as_os_str(),
        "--trace".as_ref(),
        trace.as_os_str(),
    ]);
    assert_success("render", &out);
    assert!(
        text(&out.stderr).trim().is_empty(),
        "render printed on stderr:\n{}",
        text(&out.stderr)
    );
    assert_eq!(
        entries(&dir),
        vec!["a.exr", "a.png", "p.json", "t.json"],
        "unexpected files"
    );

    let image = image::open(&png).expect("the PNG decodes");
    assert_eq!((image.width(), image.height()), (160, 90));

    // Profile: every pass in every frame and in the summary, finite times.
    let p: Value = serde_json::from_slice(&std::fs::read(&profile).unwrap()).unwrap();
    let expected: Vec<&str> = RENDER_PASSES.iter().chain(path_passes(&p["raster"])).copied().collect();
    let frames = p["frames"].as_array().expect("profile has frames");
    assert!(!frames.is_empty(), "profile has no frames");
    for frame in frames {
        finite_ms(frame, "gpu_ms", "frame");
        let passes = frame["passes"].as_array().expect("frame has passes");
        for &name in &expected {
            let pass = passes
                .iter()
                .find(|q| q["name"] == name)
                .unwrap_or_else(|| panic!("profile frame lacks pass {name}: {frame}"));
            finite_ms(pass, "gpu_ms", name);
            finite_ms(pass, "cpu_ms", name);
        }
    }
    let summary = p["summary"]["passes"].as_array().expect("profile has summary.passes");
    for &name in &expected {
        let pass = summary
            .iter()
            .find(|q| q["name"] == name)
            .unwrap_or_else(|| panic!("profile summary lacks pass {name}"));
        finite_ms(pass, "median_gpu_ms", name);
    }

    // Trace: complete events for every pass.
    let t: Value = serde_json::from_slice(&std::fs::read(&trace).unwrap()).unwrap();
    let events = t["traceEvents"].as_array().expect("traceEvents array");
    let complete: Vec<&Value> = events.iter().filter(|e| e["ph"] == "X").collect();
    assert!(!complete.is_empty(), "no complete events in the trace");
    for e in &complete {
        finite_ms(e, "ts", "trace event");
        finite_ms(e, "dur", "trace event");
    }
    for &name in &expected {
        assert!(
            complete.iter().any(|e| e["name"] == name),
            "trace lacks a complete event for {name}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- determinism

/// Renders twice into separate directories and returns both PNG and EXR files.
fn render_twice(test: &str, extra: &[&str]) -> [(Vec<u8>, Vec<u8>); 2] {
    let dir = fresh_dir(test);
    let result = [0, 1].map(|i| {
        let (png, exr) = (dir.join(format!("{i}.png")), dir.join(format!("{i}.exr")));
        let mut args: Vec<&std::ffi::OsStr> = ["render", "--validation", "--width", "160", "--height", "90"]
            .iter()
            .map(|s| s.as_ref())
            .collect();
        args.extend(extra.iter().map(|s| std::ffi::OsStr::new(*s)));
        args.extend(["--out".as_ref(), png.as_os_str(), "--exr".as_ref(), exr.as_os_str()]);
        let out = run(&args);
        assert_success(&format!("render {}", extra.join(" ")), &out);
        (std::fs::read(&png).unwrap(), std::fs::read(&exr).unwrap())
    });
    let _ = std::fs::remove_dir_all(&dir);
    result
}

#[test]
fn default_scene_is_deterministic() {
    let [a, b] = render_twice("default_scene_is_deterministic", &[]);
    assert!(a.0 == b.0, "two renders of the default scene wrote different PNGs");
    assert!(a.1 == b.1, "two renders of the default scene wrote different EXRs");
}

#[test]
fn heightmap_scene_is_deterministic() {
    let dem = data("jacksboro-fault.png");
    let [a, b] = render_twice(
        "heightmap_scene_is_deterministic",
        &["--heightmap", dem.to_str().unwrap(), "--spacing", "74.4,92.6"],
    );
    assert!(a.0 == b.0, "two renders of the DEM wrote different PNGs");
    assert!(a.1 == b.1, "two renders of the DEM wrote different EXRs");
}

// ---------------------------------------------------------------- EXR contents

#[test]
fn exr_has_colour_and_depth() {
    let dir = fresh_dir("exr_has_colour_and_depth");
    let exr = dir.join("a.exr");
    let out = run(&[
        "render".as_ref(),
        "--validation".as_ref(),
        "--width".as_ref(),
        "160".as_ref(),
        "--height".as_ref(),
        "90".as_ref(),
        "--exr".as_ref(),
        exr.as_os_str(),
    ]);
    assert_success("render --exr", &out);
    let (w, h, channels) = alpenglow::files::read_exr_channels(&exr).unwrap();
    assert_eq!((w, h), (160, 90));
    let (w, h) = (w as usize, h as usize);
    let channel = |name: &str| -> &Vec<f32> {
        &channels
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| {
                panic!(
                    "EXR lacks channel {name}; has {:?}",
                    channels.iter().map(|c| &c.0).collect::<Vec<_>>()
                )
            })
            .1
    };
    for name in ["R", "G", "B", "A"] {
        let c = channel(name);
        assert_eq!(c.len(), w * h);
        assert!(
            c.iter().all(|v| v.is_finite() && *v >= 0.0),
            "channel {name} has negative or non-finite values"
        );
    }

    // The default scene's camera depends on its terrain only (no plants to build).
    let camera = alpenglow::Scene::default_terrain().unwrap().default_camera();
    let (near, far) = (camera.near as f32, camera.far as f32);
    let z = channel("Z");
    assert_eq!(z.len(), w * h);
    assert!(
        z.iter().all(|v| !v.is_nan() && *v != f32::NEG_INFINITY),
        "Z has NaN or -inf"
    );
    let top = &z[..w];
    assert!(
        top.contains(&f32::INFINITY),
        "no sky (+inf depth) in the top row: {top:?}"
    );
    let bottom = &z[(h - 1) * w..];
    assert!(
        bottom.iter().all(|v| v.is_finite() && *v > 0.0),
        "bottom row is not all terrain (finite positive depth): {bottom:?}"
    );
    for v in z.iter().filter(|v| v.is_finite()) {
        assert!(
            *v < far && *v >= near * 0.999,
            "depth {v} outside [near {near}, far {far})"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------- info, bench

#[test]
fn info_names_device_and_driver() {
    let out = run(&["info", "--validation"]);
    assert_success("info", &out);
    let stdout = text(&out.stdout);
    for prefix in ["device:", "driver:"] {
        assert!(
            stdout.lines().any(|l| l.starts_with(prefix) && l.len() > prefix.len()),
            "info prints no {prefix:?} line:\n{stdout}"
        );
    }
}

#[test]
fn bench_writes_json_summary() {
    let dir = fresh_dir("bench_writes_json_summary");
    let (json, trace) = (dir.join("b.json"), dir.join("t.json"));
    let out = run(&[
        "bench".as_ref(),
        "--validation".as_ref(),
        "--frames".as_ref(),
        "3".as_ref(),
        "--warmup".as_ref(),
        "1".as_ref(),
        "--width".as_ref(),
        "64".as_ref(),
        "--height".as_ref(),
        "64".as_ref(),
        "--profile".as_ref(),
        json.as_os_str(),
        "--trace".as_ref(),
        trace.as_os_str(),
        "--pipeline-stats".as_ref(),
    ]);
    assert_success("bench", &out);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("p95") && stdout.contains("p99"), "{stdout}");
    assert!(stdout.contains("device memory"), "{stdout}");
    let b: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(b["frames"], 3, "bench JSON: {b}");
    assert_eq!((b["width"].as_u64(), b["height"].as_u64()), (Some(64), Some(64)));
    finite_ms(&b, "median_frame_gpu_ms", "bench");
    let passes = b["passes"].as_array().expect("bench JSON has passes");
    // Bench renders without readback.
    let bench_passes = ["terrain.warp", "tonemap"]
        .iter()
        .chain(path_passes(&b["raster"]))
        .copied();
    for name in bench_passes {
        let pass = passes
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("bench JSON lacks pass {name}: {b}"));
        for key in ["median_gpu_ms", "p95_gpu_ms", "p99_gpu_ms"] {
            finite_ms(pass, key, name);
        }
        assert_eq!(pass["samples"], 3, "pass {name}");
    }
    finite_ms(&b, "p99_frame_gpu_ms", "bench");
    // --pipeline-stats: every pass has its counters; the compute passes count invocations.
    assert!(passes.iter().all(|p| p["pipeline_stats"].is_object()), "{b}");
    let warp = passes.iter().find(|p| p["name"] == "terrain.warp").unwrap();
    assert!(
        warp["pipeline_stats"]["compute_shader_invocations"].as_u64() > Some(0),
        "{warp}"
    );
    assert!(stdout.contains("pipeline statistics (median)"), "{stdout}");
    assert!(b["device_memory"]["allocated_bytes"].as_u64() > Some(0), "{b}");
    // One timeline: with calibrated timestamps every GPU span of the trace
    // lies between its frame's submit and fence wait on the CPU clock.
    let trace = std::fs::read_to_string(&trace).unwrap();
    let calibrated = b["device"]["calibrated_timestamps"] == true;
    match alpenglow::tools::profile::gpu_spans_outside_frames(&trace) {
        Ok(outside) => assert!(calibrated && outside.is_empty(), "{outside:#?}"),
        Err(e) => assert!(!calibrated && e.to_string().contains("not calibrated"), "{e}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_lighting_flags_are_one_line_errors() {
    let cases: &[(&str, &[&str], &[&str])] = &[
        ("sun-elevation", &["--sun-elevation", "95"], &["--sun-elevation", "95"]),
        ("turbidity-low", &["--turbidity", "1.5"], &["--turbidity", "1.7"]),
        ("turbidity-high", &["--turbidity", "11"], &["--turbidity", "10"]),
        ("sky-preset", &["--sky-preset", "dusk"], &["--sky-preset", "dusk"]),
        (
            "date",
            &[
                "--date",
                "2026-02-30",
                "--time",
                "10:00",
                "--latitude",
                "45",
                "--longitude",
                "7",
            ],
            &["--date", "2026-02-30"],
        ),
        (
            "time",
            &[
                "--date",
                "2026-06-01",
                "--time",
                "25:00",
                "--latitude",
                "45",
                "--longitude",
                "7",
            ],
            &["--time", "25:00"],
        ),
        ("date-alone", &["--date", "2026-06-01"], &["--date", "all four"]),
        ("exposure", &["--exposure", "bright"], &["--exposure", "bright"]),
        ("sh-bands", &["--sh-bands", "4"], &["--sh-bands", "3 or 5"]),
        ("bounces", &["--bounces", "3"], &["--bounces"]),
        ("sky-patches", &["--sky-patches", "5"], &["--sky-patches"]),
        ("albedo", &["--albedo-override", "1.5"], &["--albedo-override"]),
        (
            "sun-twice",
            &["--sun-elevation", "10", "--sky-preset", "noon"],
            &["--sun-elevation", "not several"],
        ),
    ];
    for (name, args, needles) in cases {
        expect_render_error(&format!("lighting-{name}"), args, needles);
    }
}
