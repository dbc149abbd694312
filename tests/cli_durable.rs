//! End-to-end tests of what the `alpenglow` binary writes besides its
//! outputs, and of output names at the file system's limit:
//!
//! * the sky-light cache is optional: an unwritable cache folder (under a
//!   file, in `/proc`, read-only), no `HOME` and no `XDG_CACHE_HOME`, or a
//!   relative `XDG_CACHE_HOME` (ignored, as the XDG specification says)
//!   each give one warning line, exit 0 and a valid PNG;
//! * outputs named with 255 bytes (the most a name may have) are written,
//!   whatever their hidden temporaries are called; a 256-byte name is a
//!   one-line error naming it before anything renders.
//!
//! Renders are tiny (32×24).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::cli::*;

/// `render` of a tiny default scene into `png` with `extra` arguments and
/// the environment `env` (None: the variable removed), nothing else of the
/// cache environment inherited.
fn render_with_env(png: &Path, extra: &[&str], env: &[(&str, Option<&Path>)]) -> Output {
    let mut cmd = Command::new(bin());
    cmd.args([
        "render",
        "--validation",
        "--width",
        "32",
        "--height",
        "24",
        "--vegetation",
        "off",
        "--out",
    ])
    .arg(png)
    .args(extra)
    .env_remove("XDG_CACHE_HOME")
    .env_remove("RUST_LOG");
    for (name, value) in env {
        match value {
            Some(v) => cmd.env(name, v),
            None => cmd.env_remove(name),
        };
    }
    cmd.output().unwrap_or_else(|e| panic!("cannot run {}: {e}", bin()))
}

/// Checks a run that must succeed with a valid 32×24 PNG at `png` and
/// exactly one line on stderr, a warning that mentions every `needle`.
fn assert_renders_with_one_warning(what: &str, out: &Output, png: &Path, needles: &[&str]) {
    assert_success(what, out);
    let image = image::open(png).unwrap_or_else(|e| panic!("{what}: {}: {e}", png.display()));
    assert_eq!((image.width(), image.height()), (32, 24), "{what}");
    let stderr = text(&out.stderr);
    // alpenglow's lines (its log's `[LEVEL target] …`, `error: …`); the
    // Vulkan driver may add its own (Mesa's shader cache, which reads
    // XDG_CACHE_HOME too, says when it cannot create its folder).
    let lines: Vec<&str> = (stderr.lines())
        .filter(|l| l.starts_with('[') || l.starts_with("error"))
        .collect();
    assert_eq!(lines.len(), 1, "{what}: expected one warning line, got:\n{stderr}");
    assert!(lines[0].starts_with("[WARN"), "{what}: {stderr}");
    for needle in needles {
        assert!(
            lines[0].contains(needle),
            "{what}: the warning does not mention {needle:?}: {stderr}"
        );
    }
}

/// A cache folder that cannot be created (below a regular file, or in
/// `/proc`) or written (read-only): the render goes on, with one warning
/// naming the cache file and why.
#[test]
fn an_unwritable_cache_is_a_warning() {
    let dir = fresh_dir("durable_cache_unwritable");
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, "a file, not a folder").unwrap();
    let png = dir.join("a.png");
    let under_file = blocker.join("cache");
    let out = render_with_env(&png, &["--cache-dir", &under_file.to_string_lossy()], &[]);
    assert_renders_with_one_warning("--cache-dir under a file", &out, &png, &["blocker/cache", "sky-light"]);

    let png = dir.join("b.png");
    let in_proc = Path::new("/proc/alpenglow-no-cache");
    let out = render_with_env(&png, &[], &[("XDG_CACHE_HOME", Some(in_proc))]);
    assert_renders_with_one_warning(
        "XDG_CACHE_HOME in /proc",
        &out,
        &png,
        &["/proc/alpenglow-no-cache", "sky-light"],
    );

    // Read-only: unwritable unless this runs as root (then it is written).
    let read_only = dir.join("read-only");
    std::fs::create_dir(&read_only).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&read_only, std::fs::Permissions::from_mode(0o555)).unwrap();
    let writable = std::fs::write(read_only.join("probe"), "x").is_ok();
    let png = dir.join("c.png");
    let out = render_with_env(&png, &["--cache-dir", &read_only.to_string_lossy()], &[]);
    if writable {
        assert_success("--cache-dir read-only (as root)", &out);
    } else {
        assert_renders_with_one_warning("--cache-dir read-only", &out, &png, &["read-only", "sky-light"]);
    }
    std::fs::set_permissions(&read_only, std::fs::Permissions::from_mode(0o755)).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}

/// No `HOME` and no `XDG_CACHE_HOME`: no cache, one warning, a render.
#[test]
fn no_home_means_no_cache_and_a_warning() {
    let dir = fresh_dir("durable_cache_no_home");
    let png = dir.join("a.png");
    let out = render_with_env(&png, &[], &[("HOME", None)]);
    assert_renders_with_one_warning("HOME unset", &out, &png, &["HOME is not set", "no sky-light cache"]);
    assert_eq!(entries(&dir), ["a.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A relative `XDG_CACHE_HOME` is ignored (the XDG specification: such
/// paths are invalid) with one warning; the cache goes to
/// `$HOME/.cache/alpenglow`, not under the working directory.
#[test]
fn a_relative_xdg_cache_home_is_ignored() {
    let dir = fresh_dir("durable_cache_relative");
    let home = dir.join("home");
    std::fs::create_dir(&home).unwrap();
    let png = dir.join("a.png");
    let mut cmd_env: Vec<(&str, Option<&Path>)> = vec![("HOME", Some(&home))];
    cmd_env.push(("XDG_CACHE_HOME", Some(Path::new("relative-cache"))));
    let out = {
        let mut cmd = Command::new(bin());
        cmd.current_dir(&dir);
        cmd.args([
            "render",
            "--validation",
            "--width",
            "32",
            "--height",
            "24",
            "--vegetation",
            "off",
            "--out",
            "a.png",
        ]);
        for (name, value) in &cmd_env {
            cmd.env(name, value.unwrap());
        }
        cmd.env_remove("RUST_LOG").output().unwrap()
    };
    assert_renders_with_one_warning(
        "XDG_CACHE_HOME relative",
        &out,
        &png,
        &["XDG_CACHE_HOME=relative-cache", "not an absolute path"],
    );
    // (The Vulkan driver's own shader cache may use it: not alpenglow's.)
    assert!(
        !dir.join("relative-cache/alpenglow").exists(),
        "a relative cache folder was used"
    );
    let cached: Vec<PathBuf> = std::fs::read_dir(home.join(".cache/alpenglow"))
        .expect("the cache falls back to $HOME/.cache")
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file name of `bytes` bytes ending in `ext`, with multi-byte characters
/// (so that a cut in the wrong place would split one).
fn long_name(bytes: usize, ext: &str) -> String {
    let mut name = String::from("x");
    while name.len() + "é".len() + ext.len() <= bytes {
        name.push('é');
    }
    while name.len() + ext.len() < bytes {
        name.push('a');
    }
    name + ext
}

/// `--out`, `--exr` and `--profile` named with 255 bytes each: written
/// (their temporaries, backups and the journal fit in 255 bytes too), and
/// again over the first ones.
#[test]
fn outputs_with_255_byte_names_are_written() {
    let dir = fresh_dir("durable_long_names");
    let names = [long_name(255, ".png"), long_name(255, ".exr"), long_name(255, ".json")];
    assert!(names.iter().all(|n| n.len() == 255));
    let paths: Vec<PathBuf> = names.iter().map(|n| dir.join(n)).collect();
    for round in ["new", "over the old ones"] {
        let out = run(&[
            "render".as_ref(),
            "--width".as_ref(),
            "32".as_ref(),
            "--height".as_ref(),
            "24".as_ref(),
            "--out".as_ref(),
            paths[0].as_os_str(),
            "--exr".as_ref(),
            paths[1].as_os_str(),
            "--profile".as_ref(),
            paths[2].as_os_str(),
        ] as &[&std::ffi::OsStr]);
        assert_success(&format!("255-byte names, {round}"), &out);
        let mut expected = names.to_vec();
        expected.sort();
        assert_eq!(entries(&dir), expected, "{round}");
        assert_eq!(image::open(&paths[0]).unwrap().width(), 32);
        assert!(std::fs::metadata(&paths[1]).unwrap().len() > 0);
        let profile: serde_json::Value = serde_json::from_slice(&std::fs::read(&paths[2]).unwrap()).unwrap();
        assert!(profile.is_object(), "{round}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 256-byte name cannot exist: a one-line error naming the option and the
/// limit before any rendering, and nothing written (not even the outputs
/// whose names are fine).
#[test]
fn a_256_byte_name_fails_first() {
    let dir = fresh_dir("durable_too_long");
    let ok = dir.join("ok.png");
    for (flag, ext) in [("--exr", ".exr"), ("--profile", ".json"), ("--out", ".png")] {
        let long = dir.join(long_name(256, ext));
        let first = if flag == "--out" { &long } else { &ok };
        let mut args: Vec<&std::ffi::OsStr> = ["render", "--width", "32", "--height", "24", "--out"]
            .iter()
            .map(|s| s.as_ref())
            .collect();
        args.push(first.as_os_str());
        if flag != "--out" {
            args.extend([flag.as_ref(), long.as_os_str()]);
        }
        let out = run(&args);
        assert_one_line_error(&format!("{flag} of 256 bytes"), &out, &[flag, "256 bytes", "255"]);
        let start: String = long_name(256, ext).chars().take(30).collect();
        assert!(text(&out.stderr).contains(&start), "{flag}: {}", text(&out.stderr));
        assert_no_files_left(flag, &dir);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
