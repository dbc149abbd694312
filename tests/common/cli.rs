//! Helpers of the end-to-end tests of the `alpenglow` binary
//! (`tests/cli.rs`, `tests/cli_terrain.rs`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

/// The binary under test.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_alpenglow")
}

/// A fresh, empty directory unique to this test and process.
pub fn fresh_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-cli-{test}-{}", std::process::id()));
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary with `args` (the device choice comes from the
/// environment, `ALPENGLOW_DEVICE`, as for every user). The sky-light bake
/// is cached under the target folder, not the user's cache. Scene commands
/// (`render`, `bench`, `fly`) that do not say `--vegetation` get
/// `--vegetation off`: the built-in scene's plants cost about 2 s of scatter
/// in a debug build, and only `tests/cli_vegetation.rs` looks at them (it
/// runs the defaults with [`run_as_is`]).
pub fn run<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(AsRef::as_ref).collect();
    let scene_command = args
        .first()
        .is_some_and(|a| ["render", "bench", "fly", "view"].iter().any(|c| a == c));
    let says_vegetation = args.iter().any(|a| *a == "--vegetation");
    let mut args = args;
    if scene_command && !says_vegetation {
        args.extend([std::ffi::OsStr::new("--vegetation"), std::ffi::OsStr::new("off")]);
    }
    run_as_is(&args)
}

/// [`run`] without any added option but `--validation`: every command
/// that renders (`render`, `bench`, `fly`) runs under the Khronos
/// validation layers and synchronization validation, and exits non-zero on
/// any message (issue 27: no test renders unvalidated).
pub fn run_as_is<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    run_with(Command::new(bin()), args)
}

/// Runs `alpenglow ARGS` as [`run`] does, on a virtual X display
/// (`xvfb-run`): the viewer's tests. None when `xvfb-run` is missing
/// (tools/test installs it; `ALPENGLOW_REQUIRE_XVFB=1` makes that a failure).
pub fn run_on_xvfb<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Option<Output> {
    let found = Command::new("xvfb-run").arg("--help").output().is_ok();
    if !found {
        let required = std::env::var("ALPENGLOW_REQUIRE_XVFB").is_ok_and(|v| v == "1");
        assert!(!required, "xvfb-run is missing (apt install xvfb xauth)");
        eprintln!("xvfb-run is missing: the viewer test is skipped (apt install xvfb xauth)");
        return None;
    }
    let mut command = Command::new("xvfb-run");
    command.args(["-a", "-s", "-screen 0 800x600x24", bin()]);
    let mut args: Vec<&std::ffi::OsStr> = args.iter().map(AsRef::as_ref).collect();
    if !args.iter().any(|a| *a == "--vegetation") {
        args.extend([std::ffi::OsStr::new("--vegetation"), std::ffi::OsStr::new("off")]);
    }
    Some(run_with(command, &args))
}

fn run_with<S: AsRef<std::ffi::OsStr>>(mut command: Command, args: &[S]) -> Output {
    let mut args: Vec<&std::ffi::OsStr> = args.iter().map(AsRef::as_ref).collect();
    let renders = (args.first()).is_some_and(|a| ["render", "bench", "fly", "view"].iter().any(|c| a == c));
    if renders && !args.iter().any(|a| *a == "--validation") {
        args.push(std::ffi::OsStr::new("--validation"));
    }
    command
        .args(&args)
        .env(
            "XDG_CACHE_HOME",
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", bin()))
}

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Panics with the command's output unless it exited 0.
pub fn assert_success(what: &str, out: &Output) {
    assert!(
        out.status.success(),
        "{what} failed ({}):\nstdout:\n{}\nstderr:\n{}",
        out.status,
        text(&out.stdout),
        text(&out.stderr)
    );
}

/// Checks a failed run: non-zero exit, exactly one non-empty stderr line
/// that mentions every string of `needles`, and no panic.
pub fn assert_one_line_error(what: &str, out: &Output, needles: &[&str]) {
    let stderr = text(&out.stderr);
    assert!(
        !out.status.success(),
        "{what}: expected failure, got {}\nstdout:\n{}\nstderr:\n{stderr}",
        out.status,
        text(&out.stdout)
    );
    let trimmed = stderr.trim();
    assert!(!trimmed.is_empty(), "{what}: nothing on stderr");
    assert_eq!(
        trimmed.lines().count(),
        1,
        "{what}: expected one line on stderr, got:\n{stderr}"
    );
    let lower = trimmed.to_lowercase();
    assert!(
        !lower.contains("panicked") && !lower.contains("backtrace"),
        "{what}: panic on stderr: {trimmed}"
    );
    for needle in needles {
        assert!(
            trimmed.contains(needle),
            "{what}: stderr does not mention {needle:?}: {trimmed}"
        );
    }
}

/// The RGBA8 pixels of an image file and its size.
pub fn read_rgba(path: &Path) -> (Vec<u8>, u32, u32) {
    let image = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8();
    let (w, h) = image.dimensions();
    (image.into_raw(), w, h)
}

/// The entries of `dir` (file names), sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A finite, non-negative number at `value[key]`.
pub fn finite_ms(value: &Value, key: &str, what: &str) -> f64 {
    let v = value[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: {key} is not a number: {value}"));
    assert!(v.is_finite() && v >= 0.0, "{what}: {key} = {v}");
    v
}

/// Every output option of `render` with its file name.
pub const RENDER_OUTPUTS: [(&str, &str); 4] = [
    ("--out", "o.png"),
    ("--exr", "o.exr"),
    ("--profile", "p.json"),
    ("--trace", "t.json"),
];

/// Every output option of `render`, each into `dir` (or into `other` for
/// the option named `redirect`).
pub fn render_outputs(dir: &Path, redirect: Option<(&str, &Path)>) -> Vec<String> {
    RENDER_OUTPUTS
        .iter()
        .flat_map(|&(flag, file)| {
            let base = match redirect {
                Some((f, other)) if f == flag => other,
                _ => dir,
            };
            [flag.to_string(), base.join(file).to_string_lossy().into_owned()]
        })
        .collect()
}

/// Fails unless `dir` is empty (a failed command must leave no file).
pub fn assert_no_files_left(what: &str, dir: &Path) {
    let left = entries(dir);
    assert!(left.is_empty(), "{what}: files left behind: {left:?}");
}

/// A `side`² DEM with a `hole`² hole in its centre: the DEM and the mask.
pub fn dem_with_hole(dir: &Path, side: u32, hole: u32) -> (PathBuf, PathBuf) {
    let dem = dir.join(format!("dem{side}.png"));
    let mask = dir.join(format!("mask{side}-{hole}.png"));
    let values: Vec<u16> = (0..side * side)
        .map(|i| {
            let (c, r) = ((i % side) as f32, (i / side) as f32);
            (1000.0 + 200.0 * (c * 0.05).sin() + 150.0 * (r * 0.031).cos() + (c * r % 13.0)) as u16
        })
        .collect();
    let lo = (side - hole) / 2;
    let inside = |v: u32| (lo..lo + hole).contains(&v);
    let holes: Vec<u16> = (0..side * side)
        .map(|i| if inside(i % side) && inside(i / side) { 255 } else { 0 })
        .collect();
    std::fs::write(&dem, alpenglow::files::encode_png_gray16(&values, side, side).unwrap()).unwrap();
    std::fs::write(&mask, alpenglow::files::encode_png_gray16(&holes, side, side).unwrap()).unwrap();
    (dem, mask)
}
