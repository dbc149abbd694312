//! End-to-end tests of `alpenglow spt build` (§10.1): a mesh and a point
//! cloud become readable SPT files; bad inputs give one-line errors naming
//! the file and leave no output behind.

mod common;

use common::cli::*;
use common::data;

use alpenglow::files::read_spt;

#[test]
fn builds_the_bunny_into_a_readable_tree() {
    let dir = fresh_dir("spt-bunny");
    let out = dir.join("bunny.spt");
    let input = data("models/stanford-bunny.obj");
    let run_out = run(&[
        "spt".as_ref(),
        "build".as_ref(),
        input.as_os_str(),
        out.as_os_str(),
        "--samples".as_ref(),
        "5000".as_ref(),
    ]);
    assert_success("spt build bunny", &run_out);
    let tree = read_spt(&out).expect("the written SPT file reads back");
    let leaves = tree.nodes.iter().filter(|n| n.is_leaf).count();
    assert_eq!(leaves, 5000);
    assert!(tree.nodes.len() > leaves, "inner nodes exist");
    assert!(
        tree.nodes.windows(2).all(|w| w[0].r_max >= w[1].r_max),
        "sorted by decreasing r_max"
    );
    assert!(text(&run_out.stdout).contains("5000 surfels"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn builds_a_point_cloud() {
    let dir = fresh_dir("spt-cloud");
    let out = dir.join("c.spt");
    let input = data("points/colored-points.ply");
    let r = run(&["spt".as_ref(), "build".as_ref(), input.as_os_str(), out.as_os_str()]);
    assert_success("spt build point cloud", &r);
    assert!(read_spt(&out).is_ok());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_inputs_are_one_line_errors_without_output() {
    let dir = fresh_dir("spt-bad");
    let out = dir.join("x.spt");
    for (file, needle) in [
        ("points/bad-index.ply", "bad-index.ply"),
        ("points/short-count.ply", "short-count.ply"),
        ("missing.obj", "missing.obj"),
        ("README.md", "README.md"),
    ] {
        let input = data(file);
        let r = run(&["spt".as_ref(), "build".as_ref(), input.as_os_str(), out.as_os_str()]);
        assert_one_line_error(file, &r, &[needle]);
        assert_no_files_left(file, &dir);
    }
    let input = data("models/teapot.obj");
    let r = run(&[
        "spt".as_ref(),
        "build".as_ref(),
        input.as_os_str(),
        out.as_os_str(),
        "--epsilon".as_ref(),
        "0".as_ref(),
    ]);
    // The flag the user wrote, before the teapot is even read.
    assert_one_line_error("--epsilon 0", &r, &["invalid --epsilon: 0 px"]);
    assert_no_files_left("--epsilon 0", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

fn bunny_render_args(dir: &std::path::Path, extra: &[&str]) -> Vec<String> {
    let bunny = data("models/stanford-bunny.obj");
    let mut args: Vec<String> = [
        "render",
        "--validation",
        "--no-terrain",
        "--width",
        "96",
        "--height",
        "64",
        "--points-samples",
        "4000",
        "--points-transform",
        "r=90,0,0",
        "--eye",
        "0.1,-0.3,0.17",
        "--target",
        "-0.02,0,0.09",
        "--near",
        "0.01",
        "--far",
        "10",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.push("--points".into());
    args.push(bunny.display().to_string());
    args.push("--out".into());
    args.push(dir.join("o.png").display().to_string());
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// The W channel of the EXR at `path`.
fn exr_weight(path: &std::path::Path) -> Vec<f32> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).expect("EXR reads");
    let w = (image.layer_data[0].channel_data.list.iter())
        .find(|c| c.name.to_string() == "W")
        .expect("channel W");
    w.sample_data.values_as_f32().collect()
}

/// W > 0 on the bunny in the EXR at `path`: more than 200 pixels, less
/// than half the image.
fn assert_bunny_covered(path: &std::path::Path, what: &str) -> Vec<f32> {
    let values = exr_weight(path);
    let covered = values.iter().filter(|v| **v > 0.0).count();
    assert!(
        covered > 200 && covered < values.len() / 2,
        "{what}: W > 0 on {covered} pixels"
    );
    values
}

/// Both splat modes and all five primitives render the bunny under
/// validation; the EXR carries W (positive on the bunny, 0 on the sky), and
/// the statistics line reports the GPU's interval test (and, with
/// `--hybrid`, the triangles drawn up close).
#[test]
fn renders_points_in_every_mode_and_primitive_with_w_in_the_exr() {
    let dir = fresh_dir("points-render");
    let exr_path = dir.join("o.exr");
    for (splat, primitive, hybrid) in [
        ("ewa", "quad", false),
        ("ewa", "instanced", false),
        ("ewa", "point", false),
        ("opaque", "quad", false),
        ("opaque", "point", false),
        ("ewa", "object-quad", false),
        ("ewa", "quad", true),
        ("opaque", "quad", true),
    ] {
        let exr = exr_path.display().to_string();
        let mut extra = vec!["--splat", splat, "--splat-primitive", primitive, "--exr", &exr];
        if hybrid {
            extra.push("--hybrid");
        }
        let args = bunny_render_args(&dir, &extra);
        let out = run(&args);
        assert_success(&format!("render {}", extra.join(" ")), &out);
        let stdout = text(&out.stdout);
        assert!(stdout.contains("pass the interval test"), "{stdout}");
        assert_eq!(stdout.contains("triangles in prefixes drawn"), hybrid, "{stdout}");
        let values = assert_bunny_covered(&exr_path, &format!("{splat}/{primitive}"));
        assert_eq!(values[0], 0.0, "the corner shows sky");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--splat-kernel affine` (§10.2, Figs. 10.15–10.17) renders the bunny
/// under validation in both three-pass modes and the single pass, W in the
/// EXR; with an object-space primitive it is a one-line error naming the
/// option, with nothing written.
#[test]
fn renders_the_affine_kernel_and_names_it_for_object_space_primitives() {
    let dir = fresh_dir("points-affine");
    let exr_path = dir.join("o.exr");
    let exr = exr_path.display().to_string();
    for splat in ["ewa", "opaque", "single-pass"] {
        let extra = ["--splat", splat, "--splat-kernel", "affine", "--exr", &exr];
        let out = run(&bunny_render_args(&dir, &extra));
        assert_success(&format!("render {}", extra.join(" ")), &out);
        assert_bunny_covered(&exr_path, &format!("{splat} affine"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert_object_space_refuses(["--splat-kernel", "affine"], "object-quad");
}

/// `option value` with the object-space `primitive` is a one-line error
/// naming the option, and nothing is written.
fn assert_object_space_refuses([option, value]: [&str; 2], primitive: &str) {
    let dir = fresh_dir("points-object-space-refusal");
    let args = bunny_render_args(&dir, &[option, value, "--splat-primitive", primitive]);
    let what = format!("{option} {value} --splat-primitive {primitive}");
    assert_one_line_error(&what, &run(&args), &[&format!("invalid {option}: {value}")]);
    assert_no_files_left(&what, &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--spt-error view-dependent` (§10.1.4, §10.1.7) renders the bunny under
/// validation with fewer splats passing the interval test than the default
/// isotropic error; with an object-space primitive it is a one-line error
/// naming the option, with nothing written.
#[test]
fn renders_the_view_dependent_error_and_names_it_for_object_space_primitives() {
    let dir = fresh_dir("points-spt-error");
    let exr_path = dir.join("o.exr");
    let exr = exr_path.display().to_string();
    let mut passed = Vec::new();
    for error in ["isotropic", "view-dependent"] {
        let extra = ["--spt-error", error, "--exr", &exr];
        let out = run(&bunny_render_args(&dir, &extra));
        assert_success(&format!("render {}", extra.join(" ")), &out);
        assert_bunny_covered(&exr_path, error);
        let stdout = text(&out.stdout);
        let count = stdout
            .split(" pass the interval test")
            .next()
            .and_then(|head| head.rsplit(' ').next())
            .and_then(|n| n.parse::<u64>().ok())
            .unwrap_or_else(|| panic!("no interval count in {stdout}"));
        passed.push(count);
    }
    assert!(
        passed[1] < passed[0],
        "view-dependent {} not < isotropic {}",
        passed[1],
        passed[0]
    );
    std::fs::remove_dir_all(&dir).unwrap();
    assert_object_space_refuses(["--spt-error", "view-dependent"], "object-instanced");
}

/// An SPT file from `spt build` renders; bad point inputs and transforms
/// are one-line errors naming the file or the option, and nothing is written.
#[test]
fn spt_files_render_and_bad_point_inputs_fail_cleanly() {
    let dir = fresh_dir("points-bad");
    let spt = dir.join("bunny.spt");
    let bunny = data("models/stanford-bunny.obj");
    let built = run(&[
        "spt".as_ref(),
        "build".as_ref(),
        bunny.as_os_str(),
        spt.as_os_str(),
        "--samples".as_ref(),
        "3000".as_ref(),
    ]);
    assert_success("spt build", &built);
    let mut args = bunny_render_args(&dir, &[]);
    let i = args.iter().position(|a| a.ends_with("stanford-bunny.obj")).unwrap();
    args[i] = spt.display().to_string();
    assert_success("render an SPT file", &run(&args));
    std::fs::remove_file(dir.join("o.png")).unwrap();

    for (file, needle) in [
        ("points/short-count.ply", "short-count.ply"),
        ("missing.obj", "missing.obj"),
    ] {
        let mut args = bunny_render_args(&dir, &[]);
        args[i] = data(file).display().to_string();
        assert_one_line_error(&format!("render --points {file}"), &run(&args), &[needle]);
    }
    for transform in ["s=0", "t=1,2", "q=1"] {
        let mut args = bunny_render_args(&dir, &[]);
        let t = args.iter().position(|a| a == "r=90,0,0").unwrap();
        args[t] = transform.into();
        assert_one_line_error(
            &format!("--points-transform {transform}"),
            &run(&args),
            &["--points-transform"],
        );
    }
    let args = bunny_render_args(&dir, &["--epsilon", "0"]);
    assert_one_line_error("--epsilon 0", &run(&args), &["--epsilon"]);
    std::fs::remove_file(&spt).unwrap();
    assert_no_files_left("bad point inputs", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--splat single-pass` (§10.4) renders the bunny under validation with W
/// in the EXR, alone and with `--hybrid`; `--splat-backend interlock`
/// renders where the device offers fragment shader interlock and is else a
/// one-line error naming the feature, with nothing written.
#[test]
fn renders_single_pass_splats_and_names_a_missing_interlock() {
    let dir = fresh_dir("points-single-pass");
    let exr_path = dir.join("o.exr");
    let exr = exr_path.display().to_string();
    for hybrid in [false, true] {
        let mut extra = vec!["--splat", "single-pass", "--exr", &exr];
        if hybrid {
            extra.push("--hybrid");
        }
        let out = run(&bunny_render_args(&dir, &extra));
        assert_success(&format!("render {}", extra.join(" ")), &out);
        let stdout = text(&out.stdout);
        assert!(stdout.contains("pass the interval test"), "{stdout}");
        assert_bunny_covered(&exr_path, &format!("single-pass (hybrid {hybrid})"));
        std::fs::remove_file(&exr_path).unwrap();
        std::fs::remove_file(dir.join("o.png")).unwrap();
    }
    let args = bunny_render_args(&dir, &["--splat", "single-pass", "--splat-backend", "interlock"]);
    let out = run(&args);
    if !out.status.success() {
        assert_one_line_error(
            "--splat-backend interlock",
            &out,
            &["fragmentShaderPixelInterlock (VK_EXT_fragment_shader_interlock)"],
        );
        assert!(!dir.join("o.png").exists(), "nothing written");
    }
    // The primitive belongs to the ewa and opaque modes.
    let args = bunny_render_args(&dir, &["--splat", "single-pass", "--splat-primitive", "point"]);
    assert_one_line_error("single-pass with a primitive", &run(&args), &["--splat-primitive"]);
    assert!(!dir.join("o.png").exists(), "nothing written");
    std::fs::remove_dir_all(dir).unwrap();
}
