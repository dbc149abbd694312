//! RenderDoc captures (`--renderdoc-capture N`, `--renderdoc [PATH]`,
//! `alpenglow::tools::renderdoc`): the error paths without RenderDoc, and,
//! where Debian's `renderdoc` package is installed (tools/test installs
//! it), runs under `renderdoccmd capture`.
//!
//! RenderDoc reports Vulkan 1.2 for a device without
//! `bufferDeviceAddressCaptureReplay`, lavapipe among them, and alpenglow
//! needs 1.3: on such a device the capture test checks that alpenglow says
//! so in one line and passes; on a GPU driver with the feature it checks
//! the capture file of the asked frame.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use alpenglow::tools::renderdoc::RenderDocCapture;
use common::cli::*;

/// `renderdoccmd`, when on PATH.
fn renderdoccmd() -> Option<&'static str> {
    let found = Command::new("renderdoccmd").arg("version").output();
    found.is_ok_and(|o| o.status.success()).then_some("renderdoccmd")
}

/// Runs `renderdoccmd capture -w -c TEMPLATE PROGRAM ARGS…` (the program's
/// output passes through).
fn under_renderdoccmd(template: &Path, program: &Path, args: &[&str]) -> Output {
    Command::new("renderdoccmd")
        .args(["capture", "-w", "-c"])
        .arg(template)
        .arg(program)
        .args(args)
        .env(
            "XDG_CACHE_HOME",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .output()
        .expect("cannot run renderdoccmd")
}

/// Runs a scene command with `args` in a fresh directory and expects a
/// one-line error naming `needles` and no file left.
fn expect_error(test: &str, args: &[&str], needles: &[&str]) {
    if RenderDocCapture::attach().is_some() {
        eprintln!("{test}: skipped under RenderDoc");
        return;
    }
    let dir = fresh_dir(test);
    let mut all: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    all.extend(["--width", "32", "--height", "32"].map(String::from));
    if args[0] == "fly" {
        all.extend(["--out-dir".into(), dir.join("frames").to_string_lossy().into_owned()]);
    } else if args[0] == "render" {
        all.extend(render_outputs(&dir, None));
    }
    let out = run(&all);
    assert_one_line_error(&args.join(" "), &out, needles);
    assert_no_files_left(&args.join(" "), &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn capture_without_renderdoc_is_one_line_naming_the_option() {
    for command in ["render", "bench", "fly"] {
        let args = [command, "--renderdoc-capture", "0"];
        expect_error(
            "rdoc_missing",
            &args,
            &["--renderdoc-capture", "renderdoccmd", "--renderdoc"],
        );
    }
}

#[test]
fn frame_beyond_the_run_is_an_error_before_rendering() {
    let fly = ["fly", "--frames", "3", "--renderdoc-capture", "3"];
    expect_error("rdoc_range_fly", &fly, &["--renderdoc-capture 3", "0 to 2"]);
    let bench = ["bench", "--frames", "2", "--warmup", "1", "--renderdoc-capture", "3"];
    expect_error("rdoc_range_bench", &bench, &["--renderdoc-capture 3", "0 to 2"]);
    let render = ["render", "--renderdoc-capture", "100000"];
    expect_error(
        "rdoc_range_render",
        &render,
        &["--renderdoc-capture 100000", "0 to 99999"],
    );
}

#[test]
fn missing_library_names_the_file() {
    let args = [
        "render",
        "--renderdoc-capture",
        "0",
        "--renderdoc",
        "/nonexistent/librenderdoc.so",
    ];
    expect_error("rdoc_library", &args, &["--renderdoc", "/nonexistent/librenderdoc.so"]);
}

#[test]
fn renderdoc_without_a_capture_is_a_usage_error() {
    let out = run(&["render", "--renderdoc", "--width", "32", "--height", "32"]);
    assert_one_line_error("render --renderdoc", &out, &["--renderdoc-capture"]);
}

/// A small flythrough of three frames capturing frame 1.
const FLY_CAPTURE: [&str; 9] = [
    "fly",
    "--width",
    "64",
    "--height",
    "48",
    "--frames",
    "3",
    "--renderdoc-capture",
    "1",
];

/// `renderdoccmd capture … fly --frames 3 --renderdoc-capture 1`: one
/// capture, of frame 1, where the device runs under RenderDoc.
#[test]
fn renderdoccmd_captures_the_asked_frame() {
    let Some(_) = renderdoccmd() else {
        eprintln!("renderdoccmd is not installed (Debian: apt-get install renderdoc): capture test skipped");
        return;
    };
    let dir = fresh_dir("rdoc_capture");
    let template = dir.join("cap");
    let args = [&FLY_CAPTURE[..], &["--vegetation", "off", "--validation"]].concat();
    let out = under_renderdoccmd(&template, Path::new(bin()), &args);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    if stderr.contains("is Vulkan 1.2 under RenderDoc") {
        let line = stderr
            .lines()
            .find(|l| l.contains("under RenderDoc"))
            .unwrap_or_default();
        eprintln!("no capture on this device: {line}");
        assert_eq!(entries(&dir), Vec::<String>::new(), "files written by a failed run");
        return;
    }
    let expected = dir.join("cap_frame1_capture.rdc");
    assert!(
        stdout.contains(&format!("RenderDoc capture of frame 1: {}", expected.display())),
        "stdout:\n{stdout}\nstderr:\n{stderr}"
    );
    assert!(expected.is_file(), "{} missing; stderr:\n{stderr}", expected.display());
    let captures: Vec<String> = entries(&dir).into_iter().filter(|n| n.ends_with(".rdc")).collect();
    assert_eq!(captures, ["cap_frame1_capture.rdc"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `fly --renderdoc-capture 1 --renderdoc`: the library loaded in-process
/// (before the Vulkan instance), the capture in RenderDoc's default place.
#[test]
fn renderdoc_option_loads_the_library() {
    if renderdoccmd().is_none() || RenderDocCapture::attach().is_some() {
        eprintln!("RenderDoc is not installed (or this runs under it): load test skipped");
        return;
    }
    let out = run(&[&FLY_CAPTURE[..], &["--renderdoc"]].concat());
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    if stderr.contains("is Vulkan 1.2 under RenderDoc") {
        assert_one_line_error("fly --renderdoc", &out, &["bufferDeviceAddressCaptureReplay"]);
        eprintln!("no capture on this device: {}", stderr.trim());
        return;
    }
    assert_success("fly --renderdoc", &out);
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("RenderDoc capture of frame 1: "));
    let path = Path::new(line.unwrap_or_else(|| panic!("no capture printed:\n{stdout}")));
    assert!(
        path.to_string_lossy().ends_with("_frame1_capture.rdc"),
        "{}",
        path.display()
    );
    assert!(path.is_file(), "{} missing", path.display());
    let _ = std::fs::remove_file(path);
}

/// The in-application API against the real library: this test binary runs
/// [`api_inside_renderdoc`] under `renderdoccmd capture` (no Vulkan device:
/// it checks attaching, the template and the error of a capture of nothing).
#[test]
fn api_attaches_under_renderdoccmd() {
    let Some(_) = renderdoccmd() else {
        eprintln!("renderdoccmd is not installed: API test skipped");
        return;
    };
    if RenderDocCapture::attach().is_some() {
        return; // this is the inner run
    }
    let dir = fresh_dir("rdoc_api");
    let template = dir.join("api");
    let me = std::env::current_exe().unwrap();
    let out = under_renderdoccmd(
        &template,
        &me,
        &["--exact", "api_inside_renderdoc", "--nocapture", "--test-threads", "1"],
    );
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(&format!("renderdoc api ok: {}", template.display())),
        "stdout:\n{stdout}\nstderr:\n{}",
        text(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The inner half of [`api_attaches_under_renderdoccmd`]; does nothing
/// outside RenderDoc.
#[test]
fn api_inside_renderdoc() {
    let Some(mut rdoc) = RenderDocCapture::attach() else {
        return;
    };
    assert!(rdoc.loaded_library().is_none());
    assert!(rdoc.api_version() >= (1, 4, 1), "{:?}", rdoc.api_version());
    let template = rdoc.capture_path_template().expect("a template");
    let other = template.with_file_name("other");
    rdoc.set_capture_path_template(&other).unwrap();
    assert_eq!(rdoc.capture_path_template().as_deref(), Some(other.as_path()));
    rdoc.set_capture_path_template(&template).unwrap();
    assert!(rdoc.set_capture_path_template(Path::new("")).is_err());
    rdoc.disable_capture_keys();
    // No Vulkan device: nothing to capture, a one-line error.
    rdoc.start_frame();
    let line = rdoc.end_frame().unwrap_err().to_string();
    assert!(
        line.contains("no capture was written") && !line.contains('\n'),
        "{line}"
    );
    assert_eq!(rdoc.captures(), 0);
    assert!(rdoc.latest_capture().is_none());
    println!("renderdoc api ok: {}", template.display());
}
