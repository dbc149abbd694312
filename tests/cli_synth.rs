//! End-to-end tests of `alpenglow synth fill`, `synth grow` and `synth
//! transition` (§7.3) with the CPU search: outputs that keep the known
//! samples exactly, voids of an EXR as the unknown samples, one-line
//! errors that leave no file behind.

mod common;

use std::path::{Path, PathBuf};

use alpenglow::files::{encode_exr_height, encode_png_gray16, load_heightmap};
use alpenglow::HeightmapOptions;
use common::cli::*;

const SIDE: u32 = 40;

/// A 40×40 crop of the Jacksboro DEM at column `x0`, row `y0` as raw
/// 16-bit values (metres).
fn crop(x0: u32, y0: u32) -> Vec<u16> {
    let full = load_heightmap(
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/jacksboro-fault.png")),
        &HeightmapOptions {
            spacing: Some(alpenglow::glam::DVec2::ONE),
            ..HeightmapOptions::default()
        },
    )
    .unwrap();
    (0..SIDE * SIDE)
        .map(|i| full.height(x0 + i % SIDE, y0 + i / SIDE) as u16)
        .collect()
}

fn write_png(path: &Path, values: &[u16], width: u32, height: u32) {
    std::fs::write(path, encode_png_gray16(values, width, height).unwrap()).unwrap();
}

/// Raw values of a greyscale PNG or the heights of an EXR.
fn read(path: &Path) -> Vec<f32> {
    let opts = HeightmapOptions {
        spacing: Some(alpenglow::glam::DVec2::ONE),
        ..HeightmapOptions::default()
    };
    load_heightmap(path, &opts).unwrap().heights
}

/// An 8×6 hole at column 12, row 20 (`true`: unknown).
fn hole() -> Vec<bool> {
    (0..SIDE * SIDE)
        .map(|i| (12..20).contains(&(i % SIDE)) && (20..26).contains(&(i / SIDE)))
        .collect()
}

/// Input and mask files in `dir`.
fn fixture(dir: &Path) -> (PathBuf, PathBuf, Vec<u16>) {
    let input = dir.join("dem.png");
    let mask = dir.join("mask.png");
    let values = crop(60, 150);
    write_png(&input, &values, SIDE, SIDE);
    let mask_values: Vec<u16> = hole().iter().map(|&u| if u { 255 } else { 0 }).collect();
    write_png(&mask, &mask_values, SIDE, SIDE);
    (input, mask, values)
}

const FAST: [&str; 6] = ["--search", "cpu", "--candidates", "256", "--spacing", "74.4,92.6"];

fn args<'a>(head: &[&'a str], paths: &'a [String]) -> Vec<&'a str> {
    let mut all: Vec<&str> = vec!["synth"];
    all.extend_from_slice(head);
    all.extend(paths.iter().map(String::as_str));
    all.extend_from_slice(&FAST);
    all
}

#[test]
fn fill_keeps_known_samples_and_fills_the_mask() {
    let dir = fresh_dir("synth-fill");
    let (input, mask, values) = fixture(&dir);
    let hole = hole();
    for name in ["out.png", "out.exr"] {
        let out = dir.join(name);
        let paths = [
            "--input".into(),
            input.display().to_string(),
            "--mask".into(),
            mask.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ];
        let run_out = run(&args(&["fill"], &paths));
        assert_success(name, &run_out);
        assert!(
            text(&run_out.stdout).contains("filled 48 of 40×40 samples"),
            "{}",
            text(&run_out.stdout)
        );
        let filled = read(&out);
        let (lo, hi) = (
            *values.iter().min().unwrap() as f32,
            *values.iter().max().unwrap() as f32,
        );
        for (i, (&v, &f)) in values.iter().zip(&filled).enumerate() {
            if hole[i] {
                assert!((lo..=hi).contains(&f), "{name}: filled sample {i} = {f}");
            } else {
                assert_eq!(f, f32::from(v), "{name}: known sample {i}");
            }
        }
    }
}

#[test]
fn fill_takes_the_voids_of_an_exr_without_a_mask() {
    let dir = fresh_dir("synth-voids");
    let values = crop(200, 40);
    let hole = hole();
    let heights: Vec<f32> = values
        .iter()
        .zip(&hole)
        .map(|(&v, &u)| if u { f32::NAN } else { f32::from(v) })
        .collect();
    let input = dir.join("voids.exr");
    std::fs::write(&input, encode_exr_height(&heights, SIDE, SIDE).unwrap()).unwrap();
    let out = dir.join("filled.exr");
    let paths = [
        "--input".into(),
        input.display().to_string(),
        "--out".into(),
        out.display().to_string(),
    ];
    let run_out = run(&args(&["fill"], &paths));
    assert_success("voids", &run_out);
    let filled = read(&out);
    assert!(filled.iter().all(|h| h.is_finite()));
    for i in (0..heights.len()).filter(|&i| !hole[i]) {
        assert_eq!(filled[i].to_bits(), heights[i].to_bits());
    }
}

/// A and B of the transition tests written to `dir`: two crops, and the
/// arguments `A B --out OUT` for `out` (named in `dir`).
struct TransitionInputs {
    b: PathBuf,
    va: Vec<u16>,
    vb: Vec<u16>,
    paths: [String; 4],
}

fn transition_inputs(dir: &Path, out: &str) -> TransitionInputs {
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    let (va, vb) = (crop(60, 150), crop(250, 20));
    write_png(&a, &va, SIDE, SIDE);
    write_png(&b, &vb, SIDE, SIDE);
    let paths = [
        a.display().to_string(),
        b.display().to_string(),
        "--out".into(),
        dir.join(out).display().to_string(),
    ];
    TransitionInputs { b, va, vb, paths }
}

/// Asserts that `joined` holds A west of the band (columns 15..25: 10
/// samples of 74.4 m) and B east of it exactly.
fn assert_a_and_b_kept(joined: &[f32], inputs: &TransitionInputs) {
    for (i, &h) in joined.iter().enumerate() {
        let c = i as u32 % SIDE;
        if c < 15 {
            assert_eq!(h, f32::from(inputs.va[i]), "A at {i}");
        } else if c >= 25 {
            assert_eq!(h, f32::from(inputs.vb[i]), "B at {i}");
        }
    }
}

#[test]
fn transition_keeps_a_and_b_on_their_sides() {
    let dir = fresh_dir("synth-transition");
    let inputs = transition_inputs(&dir, "joined.png");
    let run_out = run(&args(&["transition", "--band", "744", "--window", "7"], &inputs.paths));
    assert_success("transition", &run_out);
    assert_a_and_b_kept(&read(&dir.join("joined.png")), &inputs);
    let b = &inputs.b;
    // A procedural A against a file B of the same grid.
    let exr = dir.join("procedural.exr");
    let paths = [
        "procedural:ridged,size=40,spacing=74.4:92.6".to_string(),
        b.display().to_string(),
        "--out".into(),
        exr.display().to_string(),
    ];
    let run_out = run(&args(&["transition", "--band", "744", "--window", "7"], &paths));
    assert_success("procedural transition", &run_out);
    assert_eq!(read(&exr).len(), (SIDE * SIDE) as usize);
}

/// `--steps K` (Fig. 7.6): K intermediate fields beside --out, A and B as
/// given in each, the band grown further from step to step (a sample once
/// grown keeps its height; those grown later differ from the last step).
#[test]
fn transition_writes_intermediate_steps() {
    let dir = fresh_dir("synth-transition-steps");
    let inputs = transition_inputs(&dir, "joined.exr");
    let extra = [
        "transition",
        "--band",
        "744",
        "--window",
        "7",
        "--batch",
        "16",
        "--steps",
        "3",
    ];
    let run_out = run(&args(&extra, &inputs.paths));
    assert_success("transition --steps", &run_out);
    let steps: Vec<Vec<f32>> = (1..=3)
        .map(|i| read(&dir.join(format!("joined-step-{i}.exr"))))
        .collect();
    let in_band = |i: usize| (15..25).contains(&(i as u32 % SIDE));
    let mut later = Vec::new();
    for step in &steps {
        assert_a_and_b_kept(step, &inputs);
        let differ = (0..step.len())
            .filter(|&i| in_band(i) && step[i] != steps[2][i])
            .count();
        later.push(differ);
    }
    let band = (10 * SIDE) as usize;
    println!("band samples differing from step 3: {later:?} of {band}");
    assert!(
        later[0] > later[1] && later[1] > 0 && later[2] == 0,
        "the band does not grow from step to step: {later:?}"
    );
    // Step 1 has about a quarter of the band grown, step 3 three quarters.
    assert!(
        later[0] >= band / 4 && later[0] <= 3 * band / 4,
        "step 1 differs from step 3 at {} of {band}",
        later[0]
    );
}

#[test]
fn bad_inputs_are_one_line_errors_and_write_nothing() {
    let dir = fresh_dir("synth-errors");
    let (input, mask, _) = fixture(&dir);
    let small_mask = dir.join("small-mask.png");
    write_png(&small_mask, &[0; 12], 4, 3);
    let outputs = fresh_dir("synth-errors-out");
    let out = outputs.join("o.png").display().to_string();
    let (input, mask, small_mask) = (
        input.display().to_string(),
        mask.display().to_string(),
        small_mask.display().to_string(),
    );
    let fill = |extra: &[&str], mask: &str, out: &str| {
        let mut a = vec!["synth", "fill", "--input", &input, "--mask", mask, "--out", out];
        a.extend_from_slice(extra);
        run(&a)
    };
    let cases: Vec<(&str, std::process::Output, Vec<&str>)> = vec![
        (
            "mask size",
            fill(&FAST, &small_mask, &out),
            vec!["--mask", "small-mask.png", "4×3"],
        ),
        (
            "even window",
            fill(&[&FAST[..], &["--window", "4"]].concat(), &mask, &out),
            vec!["--window", "odd"],
        ),
        (
            "huge window",
            fill(&[&FAST[..], &["--window", "41"]].concat(), &mask, &out),
            vec!["--window", "larger"],
        ),
        (
            "extension",
            fill(&FAST, &mask, &outputs.join("o.txt").display().to_string()),
            vec!["--out", ".png"],
        ),
        (
            "missing mask",
            fill(&FAST, "no-such-mask.png", &out),
            vec!["no-such-mask.png", "not found"],
        ),
    ];
    for (what, output, needles) in &cases {
        assert_one_line_error(what, output, needles);
    }
    let b = dir.join("b.png");
    write_png(&b, &[500; 100], 10, 10);
    let t = run(&[
        "synth",
        "transition",
        &input,
        &b.display().to_string(),
        "--out",
        &out,
        "--band",
        "100",
        "--search",
        "cpu",
        "--spacing",
        "1",
    ]);
    assert_one_line_error("transition sizes", &t, &["same size"]);
    assert_no_files_left("errors", &outputs);
}

#[test]
fn the_gpu_search_gives_the_cpu_twins_output_under_validation() {
    let dir = fresh_dir("synth-gpu");
    let outputs: Vec<Vec<u8>> = [&["--validation"][..], &["--search", "cpu"][..]]
        .iter()
        .enumerate()
        .map(|(k, search)| {
            let out = dir.join(format!("joined-{k}.exr")).display().to_string();
            let mut a = vec![
                "synth",
                "transition",
                "procedural:ridged,size=24,spacing=20",
                "procedural:fbm,size=24,spacing=20",
                "--band",
                "80",
                "--window",
                "5",
                "--out",
                &out,
            ];
            a.extend_from_slice(search);
            assert_success("transition", &run(&a));
            std::fs::read(&out).unwrap()
        })
        .collect();
    assert_eq!(outputs[0], outputs[1], "GPU and CPU searches differ");
}

/// `synth grow`: a new 48×36 field from the 40² crop, the same for a seed
/// with either search (the GPU's under validation), another for another
/// seed, and with `--lambda inf` (slopes only) the same on both searches;
/// one-line errors for a size below the window, a NaN λ, an exemplar with
/// a void and a window larger than the exemplar.
#[test]
fn grow_makes_a_new_field_of_the_size_asked() {
    let dir = fresh_dir("synth-grow");
    let (exemplar, _, values) = fixture(&dir);
    let exemplar = exemplar.display().to_string();
    let grow = |name: &str, extra: &[&str]| {
        let out = dir.join(name).display().to_string();
        let mut a = vec![
            "synth",
            "grow",
            "--exemplar",
            &exemplar,
            "--size",
            "48x36",
            "--out",
            &out,
        ];
        a.extend_from_slice(&FAST[2..]);
        a.extend_from_slice(extra);
        (run(&a), out)
    };
    // Waves of 8 (not the default 1) keep the GPU run short.
    let (cpu, cpu_out) = grow("cpu.exr", &["--search", "cpu", "--seed", "3", "--batch", "8"]);
    assert_success("grow cpu", &cpu);
    let (gpu, gpu_out) = grow("gpu.exr", &["--validation", "--seed", "3", "--batch", "8"]);
    assert_success("grow gpu", &gpu);
    assert_eq!(
        std::fs::read(&cpu_out).unwrap(),
        std::fs::read(&gpu_out).unwrap(),
        "GPU and CPU differ"
    );
    let heights = read(Path::new(&cpu_out));
    assert_eq!(heights.len(), 48 * 36);
    let (lo, hi) = values.iter().fold((u16::MAX, 0), |(l, h), &v| (l.min(v), h.max(v)));
    let margin = f32::from(hi - lo) * 0.25;
    assert!(
        heights
            .iter()
            .all(|&h| h >= f32::from(lo) - margin && h <= f32::from(hi) + margin),
        "heights outside the exemplar's range"
    );
    let (other, other_out) = grow("other.exr", &["--search", "cpu", "--seed", "4"]);
    assert_success("grow seed 4", &other);
    assert_ne!(std::fs::read(&cpu_out).unwrap(), std::fs::read(&other_out).unwrap());
    // `--lambda inf`: slopes only (Fig. 7.4's last panel), the same on both searches.
    let (flat_cpu, flat_cpu_out) = grow(
        "inf-cpu.exr",
        &["--search", "cpu", "--seed", "3", "--batch", "8", "--lambda", "inf"],
    );
    assert_success("grow λ inf cpu", &flat_cpu);
    let (flat_gpu, flat_gpu_out) = grow(
        "inf-gpu.exr",
        &["--validation", "--seed", "3", "--batch", "8", "--lambda", "inf"],
    );
    assert_success("grow λ inf gpu", &flat_gpu);
    assert_eq!(
        std::fs::read(&flat_cpu_out).unwrap(),
        std::fs::read(&flat_gpu_out).unwrap(),
        "λ inf: GPU and CPU differ"
    );
    assert_ne!(std::fs::read(&cpu_out).unwrap(), std::fs::read(&flat_cpu_out).unwrap());

    let outputs = fresh_dir("synth-grow-out");
    let out = outputs.join("o.png").display().to_string();
    let void = dir.join("void.exr");
    let mut with_void: Vec<f32> = values.iter().map(|&v| f32::from(v)).collect();
    with_void[5] = f32::NAN;
    std::fs::write(&void, encode_exr_height(&with_void, SIDE, SIDE).unwrap()).unwrap();
    let void = void.display().to_string();
    for (what, exemplar, size, extra, needles) in [
        ("small size", &exemplar, "5", &[][..], &["--size", "5×5"][..]),
        ("bad size", &exemplar, "12y3", &[], &["--size", "12y3"]),
        ("nan lambda", &exemplar, "24", &["--lambda", "nan"], &["--lambda"]),
        ("void", &void, "24", &[], &["void.exr"]),
        (
            "huge window",
            &exemplar,
            "48",
            &["--window", "41"],
            &["--window", "exemplar"],
        ),
    ] {
        let mut a = vec!["synth", "grow", "--exemplar", exemplar, "--size", size, "--out", &out];
        a.extend_from_slice(&FAST);
        a.extend_from_slice(extra);
        assert_one_line_error(what, &run(&a), needles);
    }
    assert_no_files_left("grow errors", &outputs);
}

/// Ctrl-C (SIGINT) ends a long growth at once and leaves no output: the
/// output is written only when complete.
#[test]
fn an_interrupted_growth_leaves_nothing() {
    use std::os::unix::process::ExitStatusExt;
    let dir = fresh_dir("progress-interrupt");
    let (dem, mask) = dem_with_hole(&dir, 513, 160);
    let (dem, mask) = (dem.display().to_string(), mask.display().to_string());
    let out = dir.join("out.png").display().to_string();
    let args = [
        "synth",
        "fill",
        "--input",
        &dem,
        "--mask",
        &mask,
        "--out",
        &out,
        "--spacing",
        "30",
        "--search",
        "cpu",
    ];
    let mut child = std::process::Command::new(bin())
        .args(args)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let sent = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let started = std::time::Instant::now();
    let status = child.wait().unwrap();
    assert!(started.elapsed().as_secs_f64() < 2.0, "the run ended at once");
    assert_eq!(status.signal(), Some(2), "ended by SIGINT: {status:?}");
    std::fs::remove_file(&dem).unwrap();
    std::fs::remove_file(&mask).unwrap();
    assert_no_files_left("interrupted fill", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Found by the hour-long CLI property run: heights divided by a tiny
/// `--height-scale` overflowed the EXR's floats and the output held `inf`
/// (now an error naming `--height-scale`, nothing written); `spt build
/// --fov-y 1e-45` underflows the threshold angle and the error named only
/// `--epsilon`, which was not given.
#[test]
fn findings_of_the_property_test_name_their_option() {
    let dir = fresh_dir("synth-property-findings");
    let exr = dir.join("o.exr");
    let o = run(&[
        "synth",
        "transition",
        "procedural:fbm,size=33,seed=1",
        "procedural:fbm,size=33,seed=2",
        "--band",
        "200",
        "--search",
        "cpu",
        "--height-scale",
        "1e-45",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert_one_line_error(
        "transition --height-scale 1e-45",
        &o,
        &["--height-scale", "32-bit floats"],
    );
    assert_no_files_left("transition --height-scale 1e-45", &dir);
    let quad = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/points/quad.ply");
    let spt = dir.join("o.spt");
    let o = run(&[
        "spt",
        "build",
        quad,
        spt.to_str().unwrap(),
        "--samples",
        "50",
        "--fov-y",
        "1e-45",
    ]);
    assert_one_line_error("spt build --fov-y 1e-45", &o, &["--fov-y", "not a representable angle"]);
    assert_no_files_left("spt build --fov-y 1e-45", &dir);
}
