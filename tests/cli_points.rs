//! End-to-end tests of `alpenglow spt build` (§10.1): a mesh and a point
//! cloud become readable SPT files; bad inputs give one-line errors naming
//! the file and leave no output behind.

mod common;

use common::cli::*;
use common::data;

use alpenglow::points::spt_file::read_spt;

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
    assert_one_line_error("--epsilon 0", &r, &["pixel threshold"]);
    assert_no_files_left("--epsilon 0", &dir);
    std::fs::remove_dir_all(dir).unwrap();
}
