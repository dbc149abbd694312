//! Long CPU work of the command line (`synth fill`, `synth transition`,
//! `spt build`): absurd combinations are refused within a second with the
//! estimate, the limit and the options at fault; `spt build` reports bad
//! inputs naming the file before it samples; progress goes to stderr only
//! on a terminal (a pipe sees none). (`tests/cli_synth.rs` interrupts a
//! growth: it keeps both cores busy, so it runs apart from the timings here.)

mod common;

use std::path::Path;
use std::process::{Command, Output};
use std::time::Instant;

use common::cli::*;

/// The tests of this file run one at a time: they time refusals, and a
/// neighbouring test's work would slow them down on a small machine.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Runs the binary with `args` and extra environment, timed.
fn run_timed(args: &[&str], env: &[(&str, &str)]) -> (Output, f64) {
    let started = Instant::now();
    let out = Command::new(bin())
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", bin()));
    (out, started.elapsed().as_secs_f64())
}

fn fill_args<'a>(dem: &'a str, mask: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "synth",
        "fill",
        "--input",
        dem,
        "--mask",
        mask,
        "--out",
        out,
        "--spacing",
        "30",
    ];
    args.extend_from_slice(extra);
    args
}

/// The issue's `--window 63 --candidates 1000000`, on a 513² DEM with a
/// 100² hole: about 8·10¹² comparisons, hours on any CPU; refused at once
/// with the estimate, the limit and both options, nothing written.
/// `--max-hours 0.1` keeps the test independent of the machine's threads.
#[test]
fn absurd_synthesis_is_refused_at_once() {
    let _serial = serial();
    let dir = fresh_dir("progress-absurd");
    let (dem, mask) = dem_with_hole(&dir, 513, 100);
    let (dem, mask) = (dem.display().to_string(), mask.display().to_string());
    let out = dir.join("out.png").display().to_string();
    let args = fill_args(
        &dem,
        &mask,
        &out,
        &[
            "--window",
            "63",
            "--candidates",
            "1000000",
            "--search",
            "cpu",
            "--max-hours",
            "0.1",
        ],
    );
    let (result, seconds) = run_timed(&args, &[]);
    assert_one_line_error(
        "synth fill --window 63 --candidates 1000000",
        &result,
        &[
            "--window 63, --candidates 1000000",
            "growing 10000 samples",
            "takes about",
            "the limit is 6.0 min",
            "--max-hours",
        ],
    );
    assert!(seconds < 1.0, "refused after {seconds:.2} s");
    // The GPU search (default) is refused too, at the latest once the
    // device is known (lavapipe: a CPU).
    let args = fill_args(&dem, &mask, &out, &["--window", "63", "--candidates", "1000000"]);
    let (result, seconds) = run_timed(&args, &[]);
    assert_one_line_error(
        "synth fill (GPU search)",
        &result,
        &["--window 63, --candidates 1000000", "--max-hours"],
    );
    assert!(seconds < 10.0, "refused after {seconds:.2} s");
    // Memory: the field itself, named as the user gave it.
    let args = fill_args(&dem, &mask, &out, &["--search", "cpu"]);
    let (result, seconds) = run_timed(&args, &[("ALPENGLOW_HOST_MEMORY_MB", "8")]);
    assert_one_line_error(
        "synth fill with 8 MiB",
        &result,
        &[
            &format!("invalid --input {dem}: 513×513 samples"),
            "of host memory; 8.0 MiB is available",
        ],
    );
    assert!(seconds < 1.0, "refused after {seconds:.2} s");
    // A blur of a hundred million samples, named by its option.
    let args = [
        "synth",
        "transition",
        "procedural:fbm,size=129",
        "procedural:ridged,size=129",
        "--band",
        "2000",
        "--blur",
        "100000000",
        "--search",
        "cpu",
        "--out",
        &out,
    ];
    let (result, seconds) = run_timed(&args, &[]);
    assert_one_line_error(
        "synth transition --blur 100000000",
        &result,
        &["invalid --blur 100000000", "--max-hours"],
    );
    assert!(seconds < 1.0, "refused after {seconds:.2} s");
    std::fs::remove_file(&dem).unwrap();
    std::fs::remove_file(&mask).unwrap();
    assert_no_files_left("refused synthesis", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

/// An OBJ of `faces` over `vertices`.
fn write_obj(path: &Path, vertices: &[[f64; 3]], faces: &[[usize; 3]]) {
    let mut text = String::new();
    for v in vertices {
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(path, text).unwrap();
}

/// Bad inputs and options of `spt build` fail before any sampling (with a
/// million samples asked, sampling would take seconds) and name the file
/// or the option.
#[test]
fn spt_build_names_the_file_before_sampling() {
    let _serial = serial();
    let dir = fresh_dir("progress-spt");
    let out = dir.join("out.spt").display().to_string();
    let flat = dir.join("flat.obj");
    write_obj(
        &flat,
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        &[[0, 1, 2]],
    );
    let huge = dir.join("huge.obj");
    write_obj(
        &huge,
        &[[0.0, 0.0, 0.0], [3e38, 0.0, 0.0], [0.0, 3e38, 0.0]],
        &[[0, 1, 2]],
    );
    let same = dir.join("same.ply");
    let mut ply =
        "ply\nformat ascii 1.0\nelement vertex 40\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
            .to_string();
    ply += &"1 2 3\n".repeat(40);
    std::fs::write(&same, ply).unwrap();
    let bunny = common::data("models/stanford-bunny.obj");
    let (flat, huge, same, bunny) = (
        flat.display().to_string(),
        huge.display().to_string(),
        same.display().to_string(),
        bunny.display().to_string(),
    );
    let million = ["--samples", "1000000"];
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec![&flat], vec!["flat.obj: no triangle with a positive, finite area"]),
        (vec![&huge], vec!["huge.obj: coordinates too large"]),
        (vec![&same], vec!["same.ply: all 40 points lie at"]),
        (vec![&bunny, "--epsilon", "0"], vec!["invalid --epsilon: 0 px"]),
        (vec![&bunny, "--fov-y", "180"], vec!["invalid --fov-y: 180°"]),
        (vec![&bunny, "--rows", "0"], vec!["invalid --rows"]),
        (vec![&bunny, "--samples", "0"], vec!["invalid --samples: 0"]),
        (
            vec![&bunny, "--samples", "100000000"],
            vec![
                "invalid --samples 100000000: 100000000 surfels need about",
                "1.0 GiB is available",
            ],
        ),
        (
            vec![&bunny, "--samples", "500000", "--max-hours", "0.001"],
            vec!["invalid --samples 500000: sampling 500000 surfels", "--max-hours"],
        ),
    ];
    for (input, needles) in cases {
        let mut args = vec!["spt", "build"];
        args.push(input[0]);
        args.push(&out);
        args.extend_from_slice(&input[1..]);
        if !input.contains(&"--samples") {
            args.extend_from_slice(&million);
        }
        let (result, seconds) = run_timed(&args, &[("ALPENGLOW_HOST_MEMORY_MB", "1024")]);
        assert_one_line_error(&args.join(" "), &result, &needles);
        // Sampling a million surfels takes minutes in a debug build.
        assert!(seconds < 3.0, "{}: refused after {seconds:.2} s", args.join(" "));
    }
    for file in ["flat.obj", "huge.obj", "same.ply"] {
        std::fs::remove_file(dir.join(file)).unwrap();
    }
    assert_no_files_left("refused builds", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Progress goes to stderr only on a terminal: through a pipe a run's
/// stderr is empty; on a pseudo-terminal (`script`) the bar shows.
#[test]
fn progress_shows_on_a_terminal_only() {
    let _serial = serial();
    let dir = fresh_dir("progress-terminal");
    let (dem, mask) = dem_with_hole(&dir, 96, 16);
    let (dem, mask) = (dem.display().to_string(), mask.display().to_string());
    let out = dir.join("out.png").display().to_string();
    let args = fill_args(
        &dem,
        &mask,
        &out,
        &["--search", "cpu", "--candidates", "2048", "--batch", "8"],
    );
    let piped = run(&args);
    assert_success("synth fill through a pipe", &piped);
    assert_eq!(text(&piped.stderr), "", "no progress on a pipe");
    std::fs::remove_file(&out).unwrap();

    let command = std::iter::once(bin().to_string())
        .chain(args.iter().map(|a| a.to_string()))
        .collect::<Vec<_>>()
        .join(" ");
    let terminal = Command::new("script")
        .args(["-q", "-e", "-c", &command, "/dev/null"])
        .output()
        .expect("util-linux script runs a command on a pseudo-terminal");
    assert_success("synth fill on a terminal", &terminal);
    let shown = text(&terminal.stdout);
    assert!(shown.contains("samples grown"), "no progress on a terminal: {shown:?}");
    std::fs::remove_dir_all(dir).unwrap();
}
