//! `alpenglow view --glsl DIR` (feature `hot-reload`) end to end on a
//! virtual X display with lavapipe, under validation: the tone mapper
//! changed while the viewer runs (to write magenta) is recompiled and the
//! renderer rebuilt; a syntax error after it is logged as one line naming
//! file and line while the magenta tone mapper keeps running, to the last
//! frame.

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use common::cli::{bin, fresh_dir, text};

const TONEMAP: &str = "post/tonemap.comp";
/// The tone mapper's store, which the test replaces.
const STORE: &str = "vec4(ldr, clamp(hdr.a, 0.0, 1.0))";
/// How long one step (the window opening, a reload) may take.
const STEP: Duration = Duration::from_secs(240);

/// Copies the tree `from` into `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// Waits for a stderr line containing `needle`; the lines read go to `seen`.
fn wait_for(lines: &Receiver<String>, needle: &str, seen: &mut Vec<String>) {
    let deadline = Instant::now() + STEP;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) => {
                let found = line.contains(needle);
                seen.push(line);
                if found {
                    return;
                }
            }
            Err(RecvTimeoutError::Timeout) => panic!("no '{needle}' within {STEP:?}; stderr:\n{}", seen.join("\n")),
            Err(RecvTimeoutError::Disconnected) => {
                panic!("the viewer ended before '{needle}'; stderr:\n{}", seen.join("\n"))
            }
        }
    }
}

#[test]
fn hot_reload_in_the_viewer_rebuilds_and_survives_a_syntax_error() {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        let required = std::env::var("ALPENGLOW_REQUIRE_XVFB").is_ok_and(|v| v == "1");
        assert!(!required, "xvfb-run is missing (apt install xvfb xauth)");
        eprintln!("xvfb-run is missing: the viewer test is skipped (apt install xvfb xauth)");
        return;
    }
    let dir = fresh_dir("view-hot-reload");
    let glsl = dir.join("glsl");
    copy_tree(&Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"), &glsl);
    let shot = dir.join("shot.png");
    let mut child = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 800x600x24", bin(), "view", "--validation"])
        .args(["--frames", "200", "--vegetation", "off", "--no-tile-pacing"])
        .args([
            "--terrain",
            "procedural:ridged,size=65,spacing=40",
            "--width",
            "64",
            "--height",
            "40",
        ])
        .arg("--glsl")
        .arg(&glsl)
        .arg("--screenshot")
        .arg(&shot)
        .env("RUST_LOG", "alpenglow::cli::view::shader_reload=info")
        .env(
            "XDG_CACHE_HOME",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("xvfb-run alpenglow view");
    let stderr = BufReader::new(child.stderr.take().unwrap());
    let (send, lines) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in stderr.lines().map_while(Result::ok) {
            let _ = send.send(line);
        }
    });
    let mut seen = Vec::new();
    wait_for(&lines, "hot reload: watching", &mut seen);
    let source = std::fs::read_to_string(glsl.join(TONEMAP)).unwrap();
    assert!(source.contains(STORE), "tonemap.comp stores {STORE}");
    std::fs::write(glsl.join(TONEMAP), source.replace(STORE, "vec4(1.0, 0.0, 1.0, 1.0)")).unwrap();
    wait_for(&lines, "shaders reloaded: 1", &mut seen);
    // A syntax error on line 3 of the magenta tone mapper.
    let broken = source
        .replace(STORE, "vec4(1.0, 0.0, 1.0, 1.0)")
        .replacen('\n', "\n\nint broken = ;\n", 1);
    std::fs::write(glsl.join(TONEMAP), broken).unwrap();
    wait_for(&lines, "glsl/post/tonemap.comp:3: error:", &mut seen);
    seen.extend(lines.iter());
    let out = child.wait_with_output().expect("the viewer's exit");
    let stderr = seen.join("\n");
    assert!(
        out.status.success(),
        "view failed ({}):\nstdout:\n{}\nstderr:\n{stderr}",
        out.status,
        text(&out.stdout)
    );
    let errors = seen.iter().filter(|l| l.contains(": error:")).count();
    assert_eq!(errors, 1, "one line for the one error:\n{stderr}");
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    assert!(
        image.pixels().all(|p| p.0 == [255, 0, 255]),
        "the last frame is not the magenta of the last good tone mapper:\n{stderr}"
    );
}
