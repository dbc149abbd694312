//! `alpenglow layers from-image` end to end (the library side is tested in
//! `src/texturing/tests/layers_from_image.rs`): it writes a layer tree for
//! the Rocky Mountain National Park pair (`tests/data/real-world/README.md`)
//! and refuses bad input in one line naming the option.

mod common;

use alpenglow::LayerTree;
use common::data;

#[test]
fn the_command_writes_a_tree_and_refuses_bad_input_in_one_line() {
    let dir = std::env::temp_dir().join(format!("alpenglow-from-image-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let out = dir.join("rmnp.toml");
    let run = |image: &str, extra: &[&str]| {
        let image = data(image);
        let dem = data("real-world/rmnp-dem.png");
        let mut args = vec![
            "layers",
            "from-image",
            "--image",
            image.to_str().unwrap(),
            "--heightmap",
            dem.to_str().unwrap(),
        ];
        args.extend([
            "--spacing",
            "233.6,234.3",
            "--rows",
            "north-up",
            "--out",
            out.to_str().unwrap(),
        ]);
        args.extend(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_alpenglow"))
            .args(&args)
            .output()
            .expect("run")
    };
    let ok = run("real-world/rmnp-rgb.png", &["--classes", "3", "--no-calibration"]);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let text = std::fs::read_to_string(&out).expect("written");
    assert!(text.starts_with("# Image: ") && text.contains("k = 3 given"), "{text}");
    assert_eq!(LayerTree::parse(&text, "written").expect("parses").layers.len(), 5);
    for (image, extra, expected) in [
        ("real-world/rmnp-rgb.png", &["--classes", "9"][..], "--classes"),
        ("real-world/rmnp-rgb.png", &["--bins", "65"][..], "invalid --bins"),
        ("tiny-ramp.png", &[][..], "integer multiple"),
    ] {
        let bad = run(image, extra);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(!bad.status.success(), "{extra:?} succeeded");
        assert!(
            stderr.contains(expected) && stderr.trim().lines().count() == 1,
            "{extra:?}: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
