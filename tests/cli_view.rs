//! The viewer (`alpenglow view`, issue 30) end to end on a virtual X
//! display with lavapipe: a scripted run (`--frames`, `--input`,
//! `--screenshot`) under validation exits 0, moves the camera as its
//! events say, and its last frame equals the headless render of the same
//! camera and sun; F12 writes a capture of the frame on screen; bad
//! scripts are one-line errors before any window opens.

mod common;

use common::cli::{assert_one_line_error, assert_success, fresh_dir, read_rgba, run, run_on_xvfb, text};
use common::mean_flip;

const SMALL_TERRAIN: &str = "procedural:ridged,size=129,spacing=40";

/// The value of `name` in a line `prefix: --name V --name2 V2` of `stdout`.
fn option<'a>(stdout: &'a str, prefix: &str, name: &str) -> &'a str {
    let line = (stdout.lines())
        .find_map(|l| l.strip_prefix(prefix))
        .unwrap_or_else(|| panic!("no '{prefix}' line in:\n{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words
        .iter()
        .position(|w| *w == name)
        .unwrap_or_else(|| panic!("no {name} in '{line}'"));
    words[at + 1]
}

fn vec3(text: &str) -> [f64; 3] {
    let v: Vec<f64> = text.split(',').map(|x| x.parse().unwrap()).collect();
    [v[0], v[1], v[2]]
}

#[test]
fn a_scripted_view_matches_the_headless_render_of_its_camera() {
    let dir = fresh_dir("view-scripted");
    let events = dir.join("events.txt");
    // W held for frames 0–5 (6 steps of 1/30 s), a look to the right and
    // down, the sun up 2 steps and right 1, F12 at frame 9; frames 10–13
    // hold still so the texture tiles settle, and present the depth,
    // normal and class debug views (the screenshot stays the colour); the
    // window is resized twice (the swapchain is recreated, the render size
    // stays).
    std::fs::write(
        &events,
        "0 key W down\n6 key W up\n7 mouse 100 30\n8 key Up\n8 key Up\n8 key Right\n9 key F12\n9 key F11\n10 key G\n11 key G\n12 key G\n3 resize 300 240\n5 resize 200 100\n",
    )
    .unwrap();
    let (shot, reference) = (dir.join("shot.png"), dir.join("reference.png"));
    let scene = [
        "--terrain",
        SMALL_TERRAIN,
        "--width",
        "160",
        "--height",
        "100",
        "--no-tile-pacing",
    ];
    let start = [
        "--eye",
        "2560,-500,900",
        "--target",
        "2560,2560,300",
        "--sun-elevation",
        "30",
        "--sun-azimuth",
        "180",
    ];
    let mut args = vec!["view", "--frames", "14", "--validation"];
    args.extend(scene);
    args.extend(start);
    let capture_dir = dir.to_str().unwrap();
    args.extend([
        "--input",
        events.to_str().unwrap(),
        "--screenshot",
        shot.to_str().unwrap(),
    ]);
    args.extend(["--capture-dir", capture_dir]);
    let Some(out) = run_on_xvfb(&args) else { return };
    assert_success("view", &out);
    let stdout = text(&out.stdout);
    // Speed: the eye–target distance (3118.3 m) per 10 s; 6 steps of 1/30 s
    // towards +Y (the heading of the start camera).
    let eye = vec3(option(&stdout, "camera: ", "--eye"));
    let distance = (3060.0f64.powi(2) + 600.0f64.powi(2)).sqrt();
    let expected_y = -500.0 + distance / 10.0 * 6.0 / 30.0;
    assert!(
        (eye[0] - 2560.0).abs() < 1e-2 && (eye[1] - expected_y).abs() < 1e-2,
        "eye {eye:?}"
    );
    assert!((eye[2] - 900.0).abs() < 1e-2, "W moves horizontally: {eye:?}");
    let target = vec3(option(&stdout, "camera: ", "--target"));
    assert!(
        target[0] > eye[0] + 100.0,
        "the look turned right (towards +X): {target:?}"
    );
    let elevation: f64 = option(&stdout, "sun: ", "--sun-elevation").parse().unwrap();
    let azimuth: f64 = option(&stdout, "sun: ", "--sun-azimuth").parse().unwrap();
    assert!(
        (elevation - 34.0).abs() < 1e-3 && (azimuth - 182.0).abs() < 1e-3,
        "sun {elevation} {azimuth}"
    );
    // F11 without RenderDoc: a warning, the run goes on.
    let stderr = text(&out.stderr);
    assert!(stderr.contains("F11: RenderDoc is not loaded"), "{stderr}");
    // F12 wrote the frame on screen: PNG, EXR, profile and trace.
    for ext in ["png", "exr", "json", "trace.json"] {
        let path = dir.join(format!("capture_00009.{ext}"));
        assert!(path.is_file(), "F12 did not write {}: {stdout}", path.display());
    }
    let profile: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("capture_00009.json")).unwrap()).unwrap();
    assert!(
        profile.to_string().contains("present.blit"),
        "the capture's profile lists the present passes"
    );
    // The headless render of the final camera and sun.
    let eye_arg = option(&stdout, "camera: ", "--eye").to_string();
    let target_arg = option(&stdout, "camera: ", "--target").to_string();
    let (e, a) = (format!("{elevation}"), format!("{azimuth}"));
    let mut render = vec![
        "render",
        "--out",
        reference.to_str().unwrap(),
        "--eye",
        &eye_arg,
        "--target",
        &target_arg,
    ];
    render.extend(scene);
    render.extend(["--sun-elevation", &e, "--sun-azimuth", &a]);
    let out = run(&render);
    assert_success("render", &out);
    let (viewed, w, h) = read_rgba(&shot);
    let (headless, rw, rh) = read_rgba(&reference);
    assert_eq!((w, h), (rw, rh));
    let (flip, _) = mean_flip(&headless, &viewed, w, h);
    assert!(
        flip <= 0.02,
        "the viewer's last frame is {flip} (mean FLIP) from the headless render"
    );
    // Not a blank frame: the terrain and sky differ.
    let distinct: std::collections::HashSet<&[u8]> = viewed.chunks(4).collect();
    assert!(
        distinct.len() > 500,
        "only {} colours in the screenshot",
        distinct.len()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bad_events_file_is_a_one_line_error_before_any_window() {
    let dir = fresh_dir("view-bad-events");
    let events = dir.join("events.txt");
    std::fs::write(&events, "0 key W down\n3 key Hyper down\n").unwrap();
    let out = run(&["view", "--frames", "2", "--input", events.to_str().unwrap()]);
    assert_one_line_error("bad key", &out, &["--input", "line 2", "unknown key 'Hyper'"]);
    let out = run(&[
        "view",
        "--frames",
        "2",
        "--input",
        dir.join("missing.txt").to_str().unwrap(),
    ]);
    assert_one_line_error("missing file", &out, &["--input", "missing.txt"]);
    let out = run(&["view", "--frames", "0"]);
    assert_one_line_error("no frames", &out, &["--frames"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_rig_shows_the_view_v_selects() {
    let dir = fresh_dir("view-rig");
    let events = dir.join("events.txt");
    // Two V presses: the third view (rear_left); G presents each of its
    // AOVs' debug views for a frame, then its colour again.
    let cycle: String = (2..10).map(|frame| format!("{frame} key G\n")).collect();
    std::fs::write(&events, format!("0 key V\n1 key V\n{cycle}")).unwrap();
    let shot = dir.join("shot.png");
    let scene = [
        "--terrain",
        "procedural:ridged,size=65,spacing=40",
        "--rig-preset",
        "ring6",
        "--width",
        "96",
    ];
    let start = ["--eye", "1280,-300,1000", "--target", "1280,1280,500"];
    let mut args = vec![
        "view",
        "--frames",
        "11",
        "--validation",
        "--input",
        events.to_str().unwrap(),
    ];
    args.extend(["--screenshot", shot.to_str().unwrap()]);
    args.extend(scene);
    args.extend(start);
    let Some(out) = run_on_xvfb(&args) else { return };
    assert_success("view with a rig", &out);
    let stdout = text(&out.stdout);
    let (eye, target) = (
        option(&stdout, "camera: ", "--eye"),
        option(&stdout, "camera: ", "--target"),
    );
    let pattern = dir.join("{view}.png");
    let mut render = vec![
        "render",
        "--out",
        pattern.to_str().unwrap(),
        "--eye",
        eye,
        "--target",
        target,
    ];
    render.extend(scene);
    let out = run(&render);
    assert_success("render with a rig", &out);
    let (viewed, w, h) = read_rgba(&shot);
    assert_eq!((w, h), (96, 72), "the screenshot is one view of the rig");
    let mut flips = Vec::new();
    for name in ["front", "front_left", "rear_left", "rear"] {
        let (headless, _, _) = read_rgba(&dir.join(format!("{name}.png")));
        flips.push((mean_flip(&headless, &viewed, w, h).0, name));
    }
    flips.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(
        flips[0].1, "rear_left",
        "the screenshot is the view V selected: {flips:?}"
    );
    assert!(flips[0].0 <= 0.02, "{flips:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
