//! End-to-end tests of the memory model (`alpenglow::tools::budget`): every count
//! that scales memory is checked before anything is allocated, and a count
//! that does not fit is a one-line error naming the option the user wrote,
//! the estimate and the limit, with no output written. The limits are
//! forced small with `ALPENGLOW_HOST_MEMORY_MB` and
//! `ALPENGLOW_DEVICE_MEMORY_MB`, so no test allocates anything large.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::cli::*;

const SMALL_TERRAIN: &str = "procedural:fbm,size=65,spacing=20";

/// Runs the binary with `args` and the environment variables `env`.
fn run_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    let renders = args.first().is_some_and(|a| ["render", "bench", "fly"].contains(a));
    let validation = (renders && !args.contains(&"--validation")).then_some("--validation");
    Command::new(bin())
        .args(args.iter().copied().chain(validation))
        .envs(env.iter().copied())
        .env(
            "XDG_CACHE_HOME",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", bin()))
}

/// A small render of the built-in scene into `out` plus `extra`.
fn render_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "render",
        "--width",
        "64",
        "--height",
        "48",
        "--vegetation",
        "off",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    args
}

#[test]
fn counts_that_do_not_fit_the_host_name_their_option() {
    let dir = fresh_dir("bounds-host");
    let out = dir.join("o.png");
    let out = out.to_str().unwrap();
    let host = [("ALPENGLOW_HOST_MEMORY_MB", "4096")];
    let o = run_with(&host, &render_args(out, &["--rocks", "100000000"]));
    assert_one_line_error(
        "--rocks 1e8",
        &o,
        &[
            "--rocks",
            "100000000 boulders need about",
            "of host memory; 4.0 GiB is available",
        ],
    );
    let bunny = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/models/teapot.obj");
    let o = run_with(
        &host,
        &render_args(
            out,
            &["--no-terrain", "--points", bunny, "--points-samples", "100000000"],
        ),
    );
    assert_one_line_error(
        "--points-samples 1e8",
        &o,
        &[
            "--points-samples",
            "100000000 samples need about",
            "4.0 GiB is available",
        ],
    );
    let spt = dir.join("o.spt");
    let o = run_with(
        &host,
        &["spt", "build", bunny, spt.to_str().unwrap(), "--samples", "100000000"],
    );
    assert_one_line_error(
        "spt build --samples 1e8",
        &o,
        // spt build's plan counts the build's peak (the surfels and their tree).
        &[
            "--samples 100000000",
            "100000000 surfels need about",
            "4.0 GiB is available",
        ],
    );
    // Height fields: a procedural grid and a DEM file, before they are made.
    let tiny = [("ALPENGLOW_HOST_MEMORY_MB", "4")];
    let o = run_with(
        &tiny,
        &render_args(out, &["--terrain", "procedural:fbm,size=1025,spacing=20"]),
    );
    assert_one_line_error(
        "1025² grid in 4 MiB",
        &o,
        &[
            "--terrain",
            "1025×1025 height samples need about 8.0 MiB of host memory",
        ],
    );
    let dem = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/jacksboro-fault.png");
    let o = run_with(
        &[("ALPENGLOW_HOST_MEMORY_MB", "1")],
        &render_args(out, &["--heightmap", dem, "--spacing", "30"]),
    );
    assert_one_line_error(
        "403×344 DEM in 1 MiB",
        &o,
        &["jacksboro-fault.png", "403×344 pixels needs about", "of host memory"],
    );
    assert_no_files_left("host bounds", &dir);
}

#[test]
fn absurd_vegetation_densities_are_refused() {
    let dir = fresh_dir("bounds-vegetation");
    let out = dir.join("o.png");
    for density in ["1e300", "1e308"] {
        let o = run_as_is(&[
            "render",
            "--width",
            "64",
            "--height",
            "48",
            "--vegetation",
            "on",
            "--vegetation-density",
            density,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_one_line_error(
            density,
            &o,
            &["--vegetation-density", "plants over the", "at most 1e12"],
        );
    }
    assert_no_files_left("vegetation density", &dir);
}

#[test]
fn images_that_do_not_fit_the_device_name_their_size() {
    let dir = fresh_dir("bounds-device");
    let out = dir.join("o.png");
    let out = out.to_str().unwrap();
    let small = |mib: &'static str| [("ALPENGLOW_DEVICE_MEMORY_MB", mib)];
    // 1024² RGBA32F radiance is 16 MiB in one allocation.
    let o = run_with(
        &small("8"),
        &[
            "render",
            "--width",
            "1024",
            "--height",
            "1024",
            "--vegetation",
            "off",
            "--out",
            out,
        ],
    );
    assert_one_line_error(
        "1024² in 8 MiB",
        &o,
        &[
            "--width/--height",
            "1024×1024 pixels need a single GPU allocation of about 16.0 MiB",
            "at most 8.0 MiB",
        ],
    );
    // 512² fits 64 MiB; supersampled 16 times it does not.
    let o = run_with(
        &small("64"),
        &[
            "render",
            "--width",
            "512",
            "--height",
            "512",
            "--msaa",
            "16",
            "--vegetation",
            "off",
            "--out",
            out,
        ],
    );
    assert_one_line_error(
        "--msaa 16",
        &o,
        &[
            "--msaa",
            "512×512 pixels at 16 samples per pixel need about",
            "the device has 64.0 MiB",
        ],
    );
    // A height field larger than the device takes.
    let o = run_with(
        &small("12"),
        &render_args(
            out,
            &["--terrain", "procedural:fbm,size=2049,spacing=20", "--rocks", "0"],
        ),
    );
    assert_one_line_error(
        "2049² DEM in 12 MiB",
        &o,
        &["height field", "2049×2049 height samples need", "12.0 MiB"],
    );
    assert_no_files_left("device bounds", &dir);
    // What fits renders under the same cap.
    let o = run_with(
        &small("64"),
        &render_args(out, &["--terrain", SMALL_TERRAIN, "--rocks", "0"]),
    );
    assert_success("64×48 in 64 MiB", &o);
}
