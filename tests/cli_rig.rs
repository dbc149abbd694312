//! End-to-end tests of rigs and camera models on the command line:
//! `--rig-preset ring6`, `--rig FILE.toml`, `{view}` output patterns,
//! `--pose`, `--rotation`, `--intrinsics`, and their one-line errors.

mod common;

use common::cli::{assert_no_files_left, assert_one_line_error, assert_success, fresh_dir, run};

const SMALL_TERRAIN: &str = "procedural:ridged,size=65,spacing=40";

fn png_size(path: &std::path::Path) -> (u32, u32) {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (image.width(), image.height())
}

#[test]
fn ring6_writes_one_png_and_exr_per_view() {
    let dir = fresh_dir("ring6");
    let out = run(&[
        "render",
        "--validation",
        "--terrain",
        SMALL_TERRAIN,
        "--rocks",
        "0",
        "--rig-preset",
        "ring6",
        "--width",
        "48",
        "--eye",
        "1200,1200,900",
        "--target",
        "1300,1500,850",
        "--out",
        dir.join("{view}.png").to_str().unwrap(),
        "--exr",
        dir.join("{view}.exr").to_str().unwrap(),
    ]);
    assert_success("render --rig-preset ring6", &out);
    let names = ["front", "front_left", "rear_left", "rear", "rear_right", "front_right"];
    let mut pngs = Vec::new();
    for name in names {
        let png = dir.join(format!("{name}.png"));
        assert_eq!(png_size(&png), (48, 36), "{name}: 4:3 at --width");
        assert!(dir.join(format!("{name}.exr")).is_file(), "{name}.exr");
        pngs.push(std::fs::read(png).unwrap());
    }
    assert!(pngs.windows(2).all(|w| w[0] != w[1]), "the six views differ");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_rig_file_gives_each_view_its_size_pose_and_intrinsics() {
    let dir = fresh_dir("rig-file");
    let rig = dir.join("rig.toml");
    std::fs::write(
        &rig,
        r#"
[[view]]
name = "left"
position = [0, 0.5, 0]
yaw_pitch_roll = [30, -10, 0]
fov_y = 40
width = 40
height = 30

[[view]]
name = "map"
eye = [1280, 1280, 4000]
target = [1280, 1290, 0]
fx = 60
fy = 50
cx = 20
cy = 16
width = 56
height = 24
"#,
    )
    .unwrap();
    let out_dir = dir.join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = run(&[
        "render",
        "--validation",
        "--terrain",
        SMALL_TERRAIN,
        "--rocks",
        "0",
        "--rig",
        rig.to_str().unwrap(),
        "--out",
        out_dir.join("{view}.png").to_str().unwrap(),
    ]);
    assert_success("render --rig", &out);
    assert_eq!(png_size(&out_dir.join("left.png")), (40, 30));
    assert_eq!(png_size(&out_dir.join("map.png")), (56, 24));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn posed_cameras_render() {
    let dir = fresh_dir("pose");
    let common = [
        "render",
        "--terrain",
        SMALL_TERRAIN,
        "--rocks",
        "0",
        "--width",
        "32",
        "--height",
        "24",
    ];
    // Looking along +y from (1280, 200, 900): camera −z is world +y, camera y is world z.
    let pose = "1,0,0,1280, 0,0,-1,200, 0,1,0,900, 0,0,0,1";
    let by_pose = dir.join("pose.png");
    let mut args: Vec<&str> = common.to_vec();
    args.extend(["--pose", pose, "--out", by_pose.to_str().unwrap()]);
    assert_success("render --pose", &run(&args));
    // The same camera by --eye/--target and by --eye/--rotation (90° about +x).
    let by_target = dir.join("target.png");
    let mut args: Vec<&str> = common.to_vec();
    args.extend([
        "--eye",
        "1280,200,900",
        "--target",
        "1280,1200,900",
        "--out",
        by_target.to_str().unwrap(),
    ]);
    assert_success("render --eye --target", &run(&args));
    let by_rotation = dir.join("rotation.png");
    let s = std::f64::consts::FRAC_1_SQRT_2.to_string();
    let rotation = format!("{s},0,0,{s}");
    let mut args: Vec<&str> = common.to_vec();
    args.extend([
        "--eye",
        "1280,200,900",
        "--rotation",
        &rotation,
        "--out",
        by_rotation.to_str().unwrap(),
    ]);
    assert_success("render --rotation", &run(&args));
    let decode = |p: &std::path::Path| image::open(p).unwrap().to_rgba8().into_raw();
    let reference = decode(&by_target);
    for other in [&by_pose, &by_rotation] {
        let diff = reference
            .iter()
            .zip(decode(other))
            .filter(|(a, b)| a.abs_diff(*b) > 2)
            .count();
        assert!(
            diff < reference.len() / 100,
            "{}: {diff} channels differ",
            other.display()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_cameras_and_rigs_are_one_line_errors() {
    let dir = fresh_dir("rig-errors");
    let bad_rig = dir.join("bad.toml");
    std::fs::write(&bad_rig, "[[view]]\nfov_y = 40\n").unwrap();
    let out_pattern = dir.join("x.png");
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec![
                "--rig-preset".into(),
                "ring6".into(),
                "--out".into(),
                out_pattern.display().to_string(),
            ],
            vec!["{view}", "--out"],
        ),
        (
            vec!["--rig".into(), bad_rig.display().to_string()],
            vec!["bad.toml", "has no name"],
        ),
        (
            vec!["--rig".into(), dir.join("missing.toml").display().to_string()],
            vec!["missing.toml"],
        ),
        (vec!["--intrinsics".into(), "0,10,5,5".into()], vec!["--intrinsics"]),
        (
            vec!["--intrinsics".into(), "10,10".into()],
            vec!["--intrinsics", "FX,FY,CX,CY"],
        ),
        (
            vec!["--distortion".into(), "0,0,0,0,9".into()],
            vec!["--distortion", "p2"],
        ),
        (vec!["--pose".into(), "1,2,3".into()], vec!["--pose"]),
        (
            vec!["--pose".into(), "0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,1".into()],
            vec!["--pose"],
        ),
        (vec!["--rotation".into(), "0,0,0,1".into()], vec!["--eye"]),
        (vec!["--msaa".into(), "3".into()], vec!["--msaa", "3"]),
        (vec!["--shutter".into(), "0.5".into()], vec!["--shutter"]),
        (vec!["--fps".into(), "0".into()], vec!["--fps"]),
        (vec!["--distortion=-5,0,0,0,0".into()], vec!["--distortion", "k1"]),
    ];
    for (extra, needles) in cases {
        let mut args: Vec<String> = ["render", "--terrain", SMALL_TERRAIN, "--width", "32", "--height", "24"]
            .map(String::from)
            .to_vec();
        args.extend(extra.iter().cloned());
        let out = run(&args);
        assert_one_line_error(&extra.join(" "), &out, &needles);
    }
    std::fs::remove_file(&bad_rig).unwrap();
    assert_no_files_left("bad rigs", &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `fly` of a rig writes each view's frames in its own folder, and with
/// `--no-tile-pacing` a camera path renders the same bytes every run.
#[test]
fn fly_with_a_rig_is_deterministic_without_tile_pacing() {
    let dir = fresh_dir("fly-rig");
    let fly = |out: &std::path::Path| {
        let out = run(&[
            "fly",
            "--terrain",
            SMALL_TERRAIN,
            "--rocks",
            "0",
            "--rig-preset",
            "ring6",
            "--width",
            "32",
            "--frames",
            "3",
            "--no-tile-pacing",
            "--shutter",
            "0.01",
            "--out-dir",
            out.to_str().unwrap(),
        ]);
        assert_success("fly --rig-preset ring6", &out);
    };
    let (a, b) = (dir.join("a"), dir.join("b"));
    fly(&a);
    fly(&b);
    for view in ["front", "rear_right"] {
        for frame in 0..3 {
            let name = format!("{view}/frame_{frame:05}.png");
            let (x, y) = (
                std::fs::read(a.join(&name)).unwrap(),
                std::fs::read(b.join(&name)).unwrap(),
            );
            assert!(x == y, "{name} differs between two runs");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
