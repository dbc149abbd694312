//! End-to-end tests of the outputs of the `alpenglow` binary as one
//! transaction: non-regular files are never replaced, two outputs at one
//! path are refused, a failing output keeps what was there, files left by
//! killed runs are cleaned up (or rolled back) by the next run, output
//! formats follow the extension, and `--frames` is bounded.
//!
//! Renders are tiny (32×24) and run with `--validation`.

mod common;

use std::ffi::OsString;
use std::path::Path;

use common::cli::*;

/// A process id that no process has (above Linux's largest `pid_max`).
const DEAD: u32 = 4_000_000_000;

/// `render` of a tiny default scene with `extra` arguments.
fn render(extra: &[&OsString]) -> std::process::Output {
    let mut args: Vec<OsString> = ["render", "--validation", "--width", "32", "--height", "24"]
        .iter()
        .map(OsString::from)
        .collect();
    args.extend(extra.iter().map(|s| (*s).clone()));
    run(&args)
}

fn os(s: &str) -> OsString {
    OsString::from(s)
}

fn p(path: &Path) -> OsString {
    path.as_os_str().to_os_string()
}

#[test]
fn symlink_at_out_is_refused_and_stays_a_link() {
    let dir = fresh_dir("outputs_symlink");
    let real = dir.join("real.png");
    std::fs::write(&real, "precious").unwrap();
    let link = dir.join("link.png");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let out = render(&[&os("--out"), &p(&link)]);
    assert_one_line_error("render --out <symlink>", &out, &["link.png", "symbolic link", "--out"]);
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "precious");
    assert_eq!(entries(&dir), ["link.png", "real.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fifo_and_device_at_out_are_refused() {
    let dir = fresh_dir("outputs_fifo");
    let fifo = dir.join("pipe.png");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let out = render(&[&os("--out"), &p(&fifo)]);
    assert_one_line_error("render --out <fifo>", &out, &["pipe.png", "FIFO"]);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    let out = render(&[&os("--profile"), &os("/dev/full")]);
    assert_one_line_error("render --profile /dev/full", &out, &["/dev/full", "device node"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_outputs_at_one_path_are_refused() {
    let dir = fresh_dir("outputs_twice");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let png = dir.join("x.png");
    let out = render(&[&os("--out"), &p(&png), &os("--exr"), &p(&png)]);
    assert_one_line_error("render --out X --exr X", &out, &["--exr", "x.png", ".exr"]);
    let out = render(&[&os("--out"), &p(&png), &os("--trace"), &p(&dir.join("sub/../x.png"))]);
    assert_one_line_error("render --out X --trace X", &out, &["--trace", "same file", "--out"]);
    let json = dir.join("p.json");
    let out = render(&[&os("--profile"), &p(&json), &os("--trace"), &p(&json)]);
    assert_one_line_error(
        "render --profile X --trace X",
        &out,
        &["--trace", "same file", "--profile"],
    );
    assert_eq!(entries(&dir), ["sub"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--out old.png --exr /proc/x.exr`: the EXR cannot be written, so the
/// render fails — and old.png keeps its previous contents.
#[test]
fn failing_later_output_keeps_the_previous_file() {
    let dir = fresh_dir("outputs_keep_old");
    let old = dir.join("old.png");
    std::fs::write(&old, "previous contents").unwrap();
    let out = render(&[&os("--out"), &p(&old), &os("--exr"), &os("/proc/x.exr")]);
    assert_one_line_error("render --out old.png --exr /proc/x.exr", &out, &["x.exr"]);
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "previous contents");
    assert_eq!(entries(&dir), ["old.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

fn hex(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    path.as_os_str().as_bytes().iter().map(|b| format!("{b:02x}")).collect()
}

/// What a `render --out o.png --exr o.exr` killed in the middle of its
/// commit leaves: a journal, the new PNG renamed into place with the old
/// one aside, the new EXR still in its temporary — plus a temporary and a
/// staging folder of other killed runs. The next render into that folder
/// restores both old files and removes the rest.
#[test]
fn next_run_rolls_back_a_killed_commit_and_removes_stale_files() {
    let dir = fresh_dir("outputs_stale");
    let canonical = dir.canonicalize().unwrap();
    let (png, exr) = (canonical.join("o.png"), canonical.join("o.exr"));
    let journal = canonical.join(format!(".alpenglow-commit-{DEAD}-1.journal"));
    std::fs::write(
        &journal,
        format!(
            "alpenglow commit journal 1\nprimary {}\npid {DEAD}\nfile existed 7 {}\nfile existed 8 {}\n",
            hex(&journal),
            hex(&png),
            hex(&exr)
        ),
    )
    .unwrap();
    std::fs::write(&png, "new png").unwrap();
    std::fs::write(dir.join(format!(".o.png.bak-{DEAD}-7")), "old png").unwrap();
    std::fs::write(&exr, "old exr").unwrap();
    std::fs::write(dir.join(format!(".o.exr.tmp-{DEAD}-8")), "new exr").unwrap();
    std::fs::write(dir.join(format!(".x.exr.tmp-{DEAD}-3")), "40 MB once").unwrap();
    let partial = dir.join(format!(".frames.partial-{DEAD}"));
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(partial.join("frame_00000.png"), "x").unwrap();
    let live = format!(".y.png.tmp-{}-1", std::process::id());
    std::fs::write(dir.join(&live), "a running process's").unwrap();

    let other = dir.join("other.png");
    let out = render(&[&os("--out"), &p(&other)]);
    assert_success("render after a killed one", &out);
    assert_eq!(std::fs::read_to_string(&png).unwrap(), "old png");
    assert_eq!(std::fs::read_to_string(&exr).unwrap(), "old exr");
    assert_eq!(entries(&dir), [live.as_str(), "o.exr", "o.png", "other.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `fly` killed while writing frames leaves `.frames.partial-PID/`; the
/// next `fly` into that folder's directory removes it.
#[test]
fn fly_removes_the_staging_folder_of_a_killed_run() {
    let dir = fresh_dir("outputs_fly_stale");
    let partial = dir.join(format!(".frames.partial-{DEAD}"));
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(partial.join("frame_00000.png"), "x").unwrap();
    let frames = dir.join("frames");
    let args: Vec<OsString> = [
        "fly",
        "--validation",
        "--width",
        "32",
        "--height",
        "24",
        "--terrain",
        "procedural:ridged,size=65,spacing=40",
        "--orbit",
        "1280,1280,0,1800,1500",
        "--frames",
        "2",
        "--out-dir",
    ]
    .iter()
    .map(OsString::from)
    .chain([p(&frames)])
    .collect();
    let out = run(&args);
    assert_success("fly after a killed one", &out);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("first") && stdout.contains("start-up excluded"),
        "{stdout}"
    );
    assert_eq!(entries(&dir), ["frames"]);
    assert_eq!(entries(&frames), ["frame_00000.png", "frame_00001.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn frames_beyond_the_maximum_are_a_one_line_error() {
    for command in ["fly", "bench"] {
        let out =
            run(&[command, "--frames", "4294967295", "--orbit", "0,0,0,10,5"][..if command == "fly" { 5 } else { 3 }]);
        assert_one_line_error(&format!("{command} --frames 4294967295"), &out, &["--frames", "100000"]);
    }
}

#[test]
fn out_format_follows_the_extension() {
    let dir = fresh_dir("outputs_formats");
    let jpg = dir.join("o.jpg");
    let out = render(&[&os("--out"), &p(&jpg)]);
    assert_success("render --out o.jpg", &out);
    let bytes = std::fs::read(&jpg).unwrap();
    assert_eq!(&bytes[..3], &[0xFF, 0xD8, 0xFF], "not a JPEG");
    let out = render(&[&os("--out"), &p(&dir.join("o.bmp"))]);
    assert_one_line_error(
        "render --out o.bmp",
        &out,
        &["--out", "unsupported extension .bmp; use .png or .jpg"],
    );
    let out = render(&[&os("--exr"), &p(&dir.join("o.png"))]);
    assert_one_line_error("render --exr o.png", &out, &["--exr", ".exr"]);
    assert_eq!(entries(&dir), ["o.jpg"]);
    let _ = std::fs::remove_dir_all(&dir);
}
