//! End-to-end tests of the simulator AOVs in the `alpenglow` binary's EXR
//! files (`render --exr`, `fly --out-dir DIR --exr`), read back with the
//! `exr` crate: the named channels `distance`, `N.X`, `N.Y`, `N.Z`,
//! `class`, `instance` (32-bit unsigned integers), `motion.X`, `motion.Y`
//! beside `R,G,B,A,Z`, and their values against `Z` (sky: class 0 and
//! infinite distance exactly where `Z` is +inf) and the camera path
//! (motion 0 on the first frame and for a still camera, not on the next).
//! Every run is validated; scenes are tiny (65² samples, 64×40 pixels).

mod common;

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::Path;

use common::cli::*;
use exr::prelude::{read, FlatSamples, ReadChannels, ReadLayers};

const SMALL: [&str; 7] = [
    "--validation",
    "--width",
    "64",
    "--height",
    "40",
    "--terrain",
    "procedural:ridged,size=65,spacing=40",
];

/// Every channel of an EXR file by name, with its samples.
fn channels(path: &Path) -> BTreeMap<String, FlatSamples> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()));
    assert_eq!(image.layer_data.size.width(), 64);
    (image.layer_data.channel_data.list.into_iter())
        .map(|c| (c.name.to_string(), c.sample_data))
        .collect()
}

fn floats<'a>(channels: &'a BTreeMap<String, FlatSamples>, name: &str) -> &'a [f32] {
    match channels.get(name) {
        Some(FlatSamples::F32(v)) => v,
        other => panic!("channel {name} is not 32-bit float: {:?}", other.map(|_| "other type")),
    }
}

fn uints<'a>(channels: &'a BTreeMap<String, FlatSamples>, name: &str) -> &'a [u32] {
    match channels.get(name) {
        Some(FlatSamples::U32(v)) => v,
        other => panic!(
            "channel {name} is not 32-bit unsigned: {:?}",
            other.map(|_| "other type")
        ),
    }
}

/// Checks the AOV channels of a terrain frame against `Z`; returns the
/// largest motion in pixels.
fn check_aovs(what: &str, path: &Path) -> f32 {
    let c = channels(path);
    let names: Vec<&str> = c.keys().map(String::as_str).collect();
    let expected = [
        "A",
        "B",
        "G",
        "N.X",
        "N.Y",
        "N.Z",
        "R",
        "Z",
        "class",
        "distance",
        "instance",
        "motion.X",
        "motion.Y",
        "sky_visibility",
        "sun_visibility",
    ];
    assert_eq!(names, expected, "{what}: channels");
    let (z, distance) = (floats(&c, "Z"), floats(&c, "distance"));
    let (class, instance) = (uints(&c, "class"), uints(&c, "instance"));
    let normal = [floats(&c, "N.X"), floats(&c, "N.Y"), floats(&c, "N.Z")];
    let (mx, my) = (floats(&c, "motion.X"), floats(&c, "motion.Y"));
    let mut largest = 0.0f32;
    for i in 0..z.len() {
        let n = normal.map(|ch| ch[i]);
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if z[i] == f32::INFINITY {
            assert_eq!(
                (class[i], distance[i], length),
                (0, f32::INFINITY, 0.0),
                "{what}: sky pixel {i}"
            );
        } else {
            // Distance along the ray is at least the depth along the forward axis.
            assert!(
                distance[i] >= z[i] && distance[i] < 1.5 * z[i],
                "{what}: pixel {i}: {} vs Z {}",
                distance[i],
                z[i]
            );
            assert!(class[i] >= 10, "{what}: terrain pixel {i} of class {}", class[i]);
            assert!((length - 1.0).abs() < 2e-3, "{what}: pixel {i}: |N| = {length}");
        }
        assert_eq!(instance[i], 0, "{what}: an instance without points");
        largest = largest.max(mx[i].hypot(my[i]));
    }
    largest
}

#[test]
fn render_exr_has_every_aov_channel() {
    let dir = fresh_dir("render_exr_aovs");
    let exr = dir.join("a.exr");
    let mut args: Vec<OsString> = ["render"].iter().chain(&SMALL).map(OsString::from).collect();
    args.extend([OsString::from("--exr"), exr.clone().into_os_string()]);
    assert_success("render --exr", &run(&args));
    // A still frame (the renderer settles the texture tiles on one camera).
    assert_eq!(check_aovs("render", &exr), 0.0, "motion in a still frame");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fly_exr_writes_every_frame_with_the_motion_of_the_path() {
    let root = fresh_dir("fly_exr_aovs");
    let frames = root.join("frames");
    let mut args: Vec<OsString> = ["fly"].iter().chain(&SMALL).map(OsString::from).collect();
    args.extend(
        [
            "--frames",
            "2",
            "--orbit",
            "1280,1280,0,1800,1500,0.05",
            "--exr",
            "--out-dir",
        ]
        .iter()
        .map(OsString::from),
    );
    args.push(frames.clone().into_os_string());
    assert_success("fly --exr", &run(&args));
    let names = [
        "frame_00000.exr",
        "frame_00000.png",
        "frame_00001.exr",
        "frame_00001.png",
    ];
    assert_eq!(entries(&frames), names, "frame directory");
    assert_eq!(
        check_aovs("fly frame 0", &frames.join(names[0])),
        0.0,
        "motion on the first frame"
    );
    let moved = check_aovs("fly frame 1", &frames.join(names[2]));
    assert!(moved > 1.0, "the second frame of the orbit moved only {moved} px");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn fly_exr_needs_an_output_directory() {
    let mut args: Vec<OsString> = ["fly"].iter().chain(&SMALL).map(OsString::from).collect();
    args.push(OsString::from("--exr"));
    assert_one_line_error("fly --exr without --out-dir", &run(&args), &["--out-dir"]);
}
