//! Command-line parsing and error wording found by the CLI property test
//! (`tests/cli_property.rs`): values clap took for unknown options,
//! library parameter names that reached the user instead of the flag, and
//! non-finite height mappings accepted without a word.

use std::path::Path;

use clap::{CommandFactory, FromArgMatches};

use super::args::{Cli, Command, SptCommand};
use super::errors::error_line;

/// `args` parsed as `parse_command_line` parses the real command line.
fn parse(args: &[&str]) -> Result<Cli, String> {
    let matches = super::allow_negative_values(Cli::command())
        .try_get_matches_from(std::iter::once("alpenglow").chain(args.iter().copied()))
        .map_err(|e| super::errors::clap_error_line(&e))?;
    Cli::from_arg_matches(&matches).map_err(|e| e.to_string())
}

/// Values with a leading hyphen reach their parsers (then a range error
/// names the option), in nested subcommands too; clap alone read `-inf`,
/// `-1e-300` and `-1:27` as unknown options `-i` and `-1`.
#[test]
fn numeric_options_take_any_hyphen_value() {
    let Command::Render(render) = parse(&["render", "--near", "-inf", "--fov-y", "-1e-300"])
        .unwrap()
        .command
    else {
        panic!("not render");
    };
    assert_eq!(render.scene.near, Some(f64::NEG_INFINITY));
    assert_eq!(render.scene.fov_y, -1e-300);
    let Command::Spt(SptCommand::Build(build)) = parse(&["spt", "build", "a.ply", "b.spt", "--epsilon", "-inf"])
        .unwrap()
        .command
    else {
        panic!("not spt build");
    };
    assert_eq!(build.epsilon, f32::NEG_INFINITY);
    let Command::Fly(fly) = parse(&["fly", "--spacing", "2", "--time", "-1:27"]).unwrap().command else {
        panic!("not fly");
    };
    assert_eq!(fly.scene.lighting.time.as_deref(), Some("-1:27"));
    let e = parse(&["render", "--spacing", "-1e-300,2"]).unwrap_err();
    assert!(e.contains("'--spacing"), "{e}");
    let e = parse(&["bench", "--frames", "-1e3"]).unwrap_err();
    assert!(e.contains("'--frames"), "{e}");
    // File options still refuse a missing value rather than take the next flag.
    let e = parse(&["render", "--out", "--width", "3"]).unwrap_err();
    assert!(e.contains("--out"), "{e}");
}

/// Height-map scale, offset and spacing are named by their flags when the
/// loader refuses them, and non-finite ones are refused by the parser
/// whether or not a height map is read.
#[test]
fn height_mapping_errors_name_the_flags() {
    use alpenglow::files::load_heightmap;
    use alpenglow::HeightmapOptions;
    for (opts, start) in [
        (
            HeightmapOptions {
                scale: f32::NAN,
                ..HeightmapOptions::default()
            },
            "invalid --height-scale: ",
        ),
        (
            HeightmapOptions {
                offset: f32::NEG_INFINITY,
                ..HeightmapOptions::default()
            },
            "invalid --height-offset: ",
        ),
        (
            HeightmapOptions {
                spacing: Some(glam::DVec2::new(0.0, 1.0)),
                ..HeightmapOptions::default()
            },
            "invalid --spacing: ",
        ),
    ] {
        let e = load_heightmap(Path::new("dem.png"), &opts).unwrap_err();
        let line = error_line(&anyhow::Error::from(e));
        assert!(line.starts_with(start), "{line}");
    }
    // Refused by the parser, with or without a height map to read.
    for (args, needle) in [
        (&["render", "--height-scale", "nan"][..], "'--height-scale"),
        (&["render", "--height-scale", "0"][..], "'--height-scale"),
        (&["render", "--height-offset", "-1e308"][..], "'--height-offset"),
        (&["render", "--height-offset", "1000001"][..], "'--height-offset"),
        (
            &[
                "synth",
                "transition",
                "procedural:fbm",
                "procedural:fbm",
                "--out",
                "o.png",
                "--band",
                "9",
                "--height-offset",
                "inf",
            ][..],
            "'--height-offset",
        ),
        (
            &[
                "layers",
                "from-image",
                "--image",
                "i.png",
                "--heightmap",
                "h.png",
                "--out",
                "o.toml",
                "--height-scale",
                "-1",
            ][..],
            "'--height-scale",
        ),
    ] {
        let e = parse(args).unwrap_err();
        assert!(e.contains(needle), "{args:?}: {e}");
    }
    let Command::Render(render) = parse(&["render", "--height-scale", "2.5", "--height-offset", "-100"])
        .unwrap()
        .command
    else {
        panic!("not render");
    };
    assert_eq!((render.scene.height_scale, render.scene.height_offset), (2.5, -100.0));
}

/// The points' angular threshold is `--epsilon` pixels of the view's own
/// pixel footprint: `1/fx` for a telephoto given by intrinsics, not the
/// footprint of `--fov-y` (which the intrinsics override).
#[test]
fn the_splat_threshold_follows_the_intrinsics() {
    let Command::Render(render) = parse(&[
        "render",
        "--intrinsics",
        "1600,1600,120,80",
        "--width",
        "240",
        "--height",
        "160",
        "--epsilon",
        "2",
    ])
    .unwrap()
    .command
    else {
        panic!("not render");
    };
    let (_, views) = super::views(&render.scene).unwrap();
    let settings = super::points::splat_settings(&render.scene.points, &views, render.scene.fov_y).unwrap();
    let epsilon = settings.epsilon.unwrap();
    assert!((epsilon - 2.0 / 1600.0).abs() < 1e-9, "epsilon {epsilon}, not 2/fx");
    let Command::Render(render) = parse(&["render", "--height", "160", "--fov-y", "60", "--epsilon", "2"])
        .unwrap()
        .command
    else {
        panic!("not render");
    };
    let (_, views) = super::views(&render.scene).unwrap();
    let settings = super::points::splat_settings(&render.scene.points, &views, render.scene.fov_y).unwrap();
    let by_fov = 2.0 * 2.0 * (30f32.to_radians()).tan() / 160.0;
    assert!((settings.epsilon.unwrap() - by_fov).abs() < 1e-7);
}
