//! Command-line parsing and error wording found by the CLI property test
//! (`tests/cli_property.rs`): values clap took for unknown options, and
//! library parameter names that reached the user instead of the flag.

use std::path::Path;

use clap::{CommandFactory, FromArgMatches};

use super::args::{check_height_mapping, Cli, Command, SptCommand};
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

/// `spt build --epsilon/--fov-y/--rows` errors name the flag, before the
/// input is read (the library says "pixel threshold", "field of view").
#[test]
fn spt_threshold_errors_name_the_flags() {
    for (args, start) in [
        (&["--epsilon", "0"][..], "invalid --epsilon 0: "),
        (&["--epsilon", "inf"][..], "invalid --epsilon inf: "),
        (&["--fov-y", "180"][..], "invalid --fov-y 180: "),
        (&["--fov-y", "-1e-300"][..], "invalid --fov-y -0: "),
    ] {
        let mut all = vec!["spt", "build", "/nonexistent/in.ply", "out.spt"];
        all.extend(args);
        let Command::Spt(SptCommand::Build(build)) = parse(&all).unwrap().command else {
            panic!("not spt build");
        };
        let line = error_line(&super::spt::build(build).unwrap_err());
        assert!(line.starts_with(start), "{args:?}: {line}");
    }
    let e = parse(&["spt", "build", "a", "b", "--rows", "0"]).unwrap_err();
    assert!(e.contains("--rows") && e.contains("1 or more"), "{e}");
}

/// Height-map scale, offset and spacing are named by their flags, whether
/// the loader refuses them or the command reads no height map.
#[test]
fn height_mapping_errors_name_the_flags() {
    use alpenglow::io::heightmap::{load_heightmap, HeightmapOptions};
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
    let line = |r: anyhow::Result<()>| error_line(&r.unwrap_err());
    assert!(line(check_height_mapping(f32::NAN, 0.0)).starts_with("invalid --height-scale NaN"));
    assert!(line(check_height_mapping(0.0, 0.0)).starts_with("invalid --height-scale 0"));
    assert!(line(check_height_mapping(1.0, f32::NEG_INFINITY)).starts_with("invalid --height-offset -inf"));
    assert!(check_height_mapping(2.5, -100.0).is_ok());
}
