//! End-to-end tests of `--vegetation on|off` and `--vegetation-density`
//! (dissertation chapter 10, Fig. 10.12): plants of a layer file's
//! `vegetation` table appear in the image, density 0 is the same image as
//! off, the built-in scene grows plants unless told not to, and bad values
//! and tables are one-line errors. (These tests run the binary as is:
//! [`common::cli::run`] turns plants off for the other CLI tests.)

mod common;

use common::cli::*;

fn render_args(layers: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> Vec<std::ffi::OsString> {
    let mut args: Vec<std::ffi::OsString> = [
        "render",
        "--validation",
        "--width",
        "48",
        "--height",
        "32",
        "--terrain",
        "procedural:ridged,size=33,spacing=8,amplitude=1",
        "--eye",
        "128,40,8",
        "--target",
        "128,140,0",
    ]
    .iter()
    .map(Into::into)
    .collect();
    args.extend(["--layers".into(), layers.as_os_str().to_owned()]);
    args.extend(extra.iter().map(Into::into));
    args.extend(["--out".into(), out.as_os_str().to_owned()]);
    args
}

fn pixels(path: &std::path::Path) -> Vec<u8> {
    image::open(path).expect("png").to_rgba8().into_raw()
}

#[test]
fn plants_appear_with_vegetation_on_and_density_zero_is_off() {
    let dir = fresh_dir("vegetation-on-off");
    let layers = common::data("layers-vegetation-meadow.toml");
    let image = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let r = run_as_is(&render_args(&layers, &out, extra));
        assert_success(name, &r);
        pixels(&out)
    };
    // A --terrain spec is not the built-in scene: off unless asked for.
    let default = image("default.png", &[]);
    let off = image("off.png", &["--vegetation", "off"]);
    let on = image("on.png", &["--vegetation", "on"]);
    let zero = image("zero.png", &["--vegetation", "on", "--vegetation-density", "0"]);
    assert_eq!(default, off);
    assert_eq!(zero, off);
    let changed = on.chunks(4).zip(off.chunks(4)).filter(|(a, b)| a != b).count();
    assert!(changed > 48 * 32 / 10, "plants changed only {changed} pixels");
    std::fs::remove_dir_all(dir).unwrap();
}

/// The instances of the points statistics line (`points: D/N instances, …`).
fn instances(stdout: &str) -> usize {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("points: "))
        .expect("points statistics");
    let counts = line["points: ".len()..].split(' ').next().expect("D/N");
    counts.split('/').nth(1).and_then(|n| n.parse().ok()).expect("N")
}

#[test]
fn the_built_in_scene_grows_plants_by_default() {
    let dir = fresh_dir("vegetation-built-in");
    let out = dir.join("o.png");
    let count = |extra: &[&str]| {
        let mut args = vec!["render", "--width", "32", "--height", "20", "--rocks", "0"];
        args.extend_from_slice(extra);
        let out_arg = out.to_str().expect("UTF-8 path");
        args.extend(["--out", out_arg]);
        let r = run_as_is(&args);
        assert_success(&args.join(" "), &r);
        instances(&text(&r.stdout))
    };
    let default = count(&[]);
    assert!(default > 10_000, "{default} plants in the default scene");
    let half = count(&["--vegetation-density", "0.5"]) as f64 / default as f64;
    assert!((half - 0.5).abs() < 0.03, "half the density gave {half} of the plants");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_vegetation_values_and_tables_are_one_line_errors() {
    let dir = fresh_dir("vegetation-bad");
    let layers = common::data("layers-vegetation-meadow.toml");
    let out = dir.join("o.png");
    for (extra, needles) in [
        (
            &["--vegetation-density", "-1"][..],
            &["--vegetation-density", "≥ 0"][..],
        ),
        (&["--vegetation-density", "nan"][..], &["--vegetation-density"][..]),
        (&["--vegetation", "maybe"][..], &["--vegetation"][..]),
    ] {
        let r = run_as_is(&render_args(&layers, &out, extra));
        assert_one_line_error(&extra.join(" "), &r, needles);
    }
    for (table, needle) in [
        ("density = -1", "vegetation[0].density -1"),
        ("density = 0.1\nscale = [3, 1]", "vegetation[0].scale"),
        ("density = 0.1\nmodel2 = 1", "unknown field `model2`"),
    ] {
        let bad = dir.join("bad.toml");
        let text =
            format!("[root]\nname = \"m\"\ncolor = [0.1, 0.2, 0.1]\n[[root.vegetation]]\nmodel = \"shrub\"\n{table}\n");
        std::fs::write(&bad, text).unwrap();
        let r = run_as_is(&render_args(&bad, &out, &["--vegetation", "on"]));
        assert_one_line_error(table, &r, &[needle, "bad.toml"]);
    }
    assert!(!out.exists(), "no output after an error");
    std::fs::remove_dir_all(dir).unwrap();
}
