//! Tests of camera paths: keyframe files, interpolation, orbits.

use super::*;

/// An orbit starting at [`DEFAULT_START_ANGLE_DEG`].
fn orbit_around(centre: DVec3, radius: f64, height: f64, turns: f64) -> Orbit {
    Orbit {
        centre,
        radius,
        height,
        turns,
        start_angle_deg: DEFAULT_START_ANGLE_DEG,
    }
}

fn base() -> Camera {
    Camera {
        eye: DVec3::ZERO,
        target: DVec3::X,
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 1.0,
        far: 100_000.0,
    }
}

const FILE: &str = "\
# a flythrough
[[keyframe]]
time = 0.0
eye = [5120.0, -1200.0, 1400.0]
target = [5120.0, 5120.0, 200.0]

[[keyframe]]
time = 4
eye = [9000, 2000, 1100]
target = [5120.0, 5120.0, 200.0]

[[keyframe]]
time = 5.5
eye = [9500.0, 6000.0, 900.0]
target = [4000.0, 6000.0, 300.0]

[[keyframe]]
time = 10.0
eye = [6000.0, 9500.0, 1500.0]
target = [5120.0, 5120.0, 0.0]
";

fn parse(text: &str) -> Result<CameraPath> {
    parse_keyframes(text, Path::new("path.toml"))
}

fn keys(path: &CameraPath) -> &[Keyframe] {
    match path {
        CameraPath::Keyframes(k) => k,
        CameraPath::Orbit(_) => panic!("not keyframes"),
    }
}

#[test]
fn keyframes_load_and_interpolate_through_every_keyframe() {
    let path = parse(FILE).unwrap();
    path.validate().unwrap();
    let k = keys(&path);
    assert_eq!(k.len(), 4);
    assert_eq!(k[1].eye, DVec3::new(9000.0, 2000.0, 1100.0));
    assert_eq!((path.start_time(), path.duration()), (0.0, 10.0));
    for key in k {
        let c = path.camera_at(key.time, &base());
        assert_eq!((c.eye, c.target), (key.eye, key.target), "t = {}", key.time);
        assert_eq!((c.up, c.fov_y_deg, c.near, c.far), (DVec3::Z, 50.0, 1.0, 100_000.0));
    }
    // Clamped outside the keyframe times.
    assert_eq!(path.camera_at(-3.0, &base()).eye, k[0].eye);
    assert_eq!(path.camera_at(f64::NAN, &base()).eye, k[0].eye);
    assert_eq!(path.camera_at(99.0, &base()).eye, k[3].eye);
    // Continuous across a keyframe, and between its neighbours' range.
    let (a, b) = (path.camera_at(4.0 - 1e-7, &base()), path.camera_at(4.0 + 1e-7, &base()));
    assert!(a.eye.distance(b.eye) < 1e-2, "{a:?} {b:?}");
    // A fixed target stays fixed.
    let mid = path.camera_at(2.0, &base());
    assert!(mid.target.distance(k[0].target) < 1e-9, "{:?}", mid.target);
    assert!(mid.eye.x > 5120.0 && mid.eye.x < 9000.0, "{:?}", mid.eye);
    // Eases in: zero velocity at the start.
    let early = path.camera_at(1e-4, &base());
    assert!(early.eye.distance(k[0].eye) < 1e-3);
}

#[test]
fn uniform_spacing_gives_the_uniform_spline() {
    // Collinear, evenly spaced points: the spline is the straight line,
    // and in the interior segment a point moves linearly with time.
    let keys: Vec<Keyframe> = (0..4)
        .map(|i| Keyframe {
            time: f64::from(i),
            eye: DVec3::new(100.0 * f64::from(i), 0.0, 50.0),
            target: DVec3::new(100.0 * f64::from(i), 500.0, 0.0),
        })
        .collect();
    let path = CameraPath::Keyframes(keys);
    let c = path.camera_at(1.25, &base());
    assert!(c.eye.distance(DVec3::new(125.0, 0.0, 50.0)) < 1e-9, "{:?}", c.eye);
}

#[test]
fn times_must_strictly_increase() {
    let text = FILE.replace("time = 5.5", "time = 4.0");
    let e = parse(&text).unwrap_err().to_string();
    assert!(
        e.starts_with("path.toml: keyframe 3 (line 13): time 4 is not after"),
        "{e}"
    );
    let text = FILE.replace("time = 5.5", "time = 3.0");
    assert!(parse(&text).unwrap_err().to_string().contains("strictly increase"));
    let text = FILE.replace("time = 5.5", "time = nan");
    assert!(parse(&text).unwrap_err().to_string().contains("time NaN is not in"));
    let mut path = parse(FILE).unwrap();
    if let CameraPath::Keyframes(k) = &mut path {
        k[2].time = 1.0;
    }
    assert!(path.validate().unwrap_err().to_string().contains("keyframe 3"));
    // Must not panic on an invalid path.
    let _ = path.sample(7, &base());
}

#[test]
fn too_few_keyframes() {
    let one = "[[keyframe]]\ntime = 0\neye = [0, 0, 10]\ntarget = [1, 0, 0]\n";
    let e = parse(one).unwrap_err().to_string();
    assert!(
        e.contains("path.toml") && e.contains("at least 2") && e.contains("found 1"),
        "{e}"
    );
    assert!(parse("").unwrap_err().to_string().contains("found 0"));
    assert!(CameraPath::Keyframes(vec![]).validate().is_err());
    assert_eq!(CameraPath::Keyframes(vec![]).camera_at(1.0, &base()), base());
    assert_eq!(CameraPath::Keyframes(vec![]).sample(3, &base()).len(), 3);
}

#[test]
fn bad_toml_reports_the_line() {
    let text = FILE.replace("eye = [9000, 2000, 1100]", "eye = [9000, 2000 1100]");
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.starts_with("path.toml: line 9: "), "{e}");
    assert!(!e.contains('\n'), "{e}");
    // An unclosed array may continue on the next line: toml reports where `]` was expected.
    let text = FILE.replace("eye = [9000, 2000, 1100]", "eye = [9000, 2000, 1100");
    let e = parse(&text).unwrap_err().to_string();
    assert!(
        e.starts_with("path.toml: line 10: ") && e.contains("expected `]`"),
        "{e}"
    );
    let text = FILE.replace("time = 4\n", "time = 4\nfov = 30\n");
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.starts_with("path.toml: line 9: ") && e.contains("fov"), "{e}");
    let text = FILE.replace("target = [4000.0, 6000.0, 300.0]", "target = [4000.0, 6000.0]");
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.contains("keyframe 3 (line 15): target has 2 components"), "{e}");
    let text = FILE.replace("time = 4\n", "time = \"4\"\n");
    assert!(parse(&text).unwrap_err().to_string().starts_with("path.toml: line 8: "));
    let text = FILE.replace("[9500.0, 6000.0, 900.0]", "[4000.0, 6000.0, 300.0]");
    assert!(parse(&text).unwrap_err().to_string().contains("eye equals target"));
}

#[test]
fn load_keyframes_names_the_file() {
    let dir = std::env::temp_dir().join(format!("alpenglow-camera-path-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("fly.toml");
    std::fs::write(&file, FILE).unwrap();
    assert_eq!(load_keyframes(&file).unwrap(), parse(FILE).unwrap());
    std::fs::write(&file, "[[keyframe]\n").unwrap();
    let e = load_keyframes(&file).unwrap_err().to_string();
    assert!(e.contains("fly.toml: line 1"), "{e}");
    let missing = dir.join("missing.toml");
    let e = load_keyframes(&missing).unwrap_err().to_string();
    assert!(e.contains("missing.toml: file not found"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn orbit_circles_the_centre_and_returns() {
    let orbit = orbit_around(DVec3::new(5120.0, 5120.0, 200.0), 3000.0, 900.0, 1.0);
    let path = CameraPath::Orbit(orbit);
    assert_eq!((path.start_time(), path.duration()), (0.0, 1.0));
    let start = path.camera_at(0.0, &base());
    // Starts south of the centre.
    assert!(
        start.eye.distance(DVec3::new(5120.0, 2120.0, 1100.0)) < 1e-9,
        "{:?}",
        start.eye
    );
    for c in path.sample(37, &base()) {
        let d = (c.eye - orbit.centre).truncate().length();
        assert!((d - 3000.0).abs() < 1e-9, "{d}");
        assert_eq!(c.eye.z, 1100.0);
        assert_eq!(c.target, orbit.centre);
    }
    let end = path.camera_at(1.0, &base());
    assert!(end.eye.distance(start.eye) < 1e-9);
    let quarter = path.camera_at(0.25, &base());
    assert!(
        quarter.eye.distance(DVec3::new(8120.0, 5120.0, 1100.0)) < 1e-9,
        "counter-clockwise"
    );
    let half = CameraPath::Orbit(orbit_around(DVec3::ZERO, 10.0, 5.0, 0.5));
    assert!(half.camera_at(1.0, &base()).eye.distance(DVec3::new(0.0, 10.0, 5.0)) < 1e-12);
}

#[test]
fn orbit_validation_names_the_orbit() {
    for bad in [
        orbit_around(DVec3::ZERO, 0.0, 1.0, 1.0),
        orbit_around(DVec3::ZERO, -1.0, 1.0, 1.0),
        orbit_around(DVec3::ZERO, 1.0, f64::INFINITY, 1.0),
        orbit_around(DVec3::new(0.0, f64::NAN, 0.0), 1.0, 1.0, 1.0),
    ] {
        let e = bad.validate().unwrap_err();
        assert_eq!(e.parameter(), Some("orbit"), "{e}");
        assert!(!e.to_string().contains("--"), "{e}");
    }
    orbit_around(DVec3::ZERO, 1.0, 0.0, 0.0).validate().unwrap();
}

/// An orbit either fails its own validation, naming the orbit, or every
/// camera on it is valid: huge radii and heights, eyes straight above the
/// centre, tiny orbits far from the origin (these used to pass and fail
/// later as the camera's eye or up, which the user never gave).
#[test]
fn a_valid_orbit_gives_valid_cameras() {
    let base = base();
    let centres = [
        DVec3::ZERO,
        DVec3::new(5e7, -9e7, 3e4),
        DVec3::new(1e8, 0.0, 0.0),
        DVec3::splat(-2e8),
    ];
    let lengths = [1e-9, 1e-3, 1.0, 3e3, 5e7, 1e9, 1e300];
    for centre in centres {
        for radius in lengths {
            for height in lengths.iter().flat_map(|&h| [h, -h, 0.0]) {
                let orbit = orbit_around(centre, radius, height, 1.25);
                let path = CameraPath::Orbit(orbit);
                match orbit.validate() {
                    Ok(()) => {
                        for i in 0..9 {
                            let c = path.sample_at(i, 9, &base);
                            c.validate().unwrap_or_else(|e| panic!("{orbit:?} frame {i}: {e}"));
                        }
                    }
                    Err(e) => {
                        assert_eq!(e.parameter(), Some("orbit"), "{orbit:?}: {e}");
                        let line = e.to_string();
                        assert!(line.len() < 300, "{line}");
                    }
                }
            }
        }
    }
}

#[test]
fn sample_counts_and_valid_cameras() {
    let paths = [
        parse(FILE).unwrap(),
        CameraPath::Orbit(orbit_around(DVec3::ZERO, 1000.0, 300.0, 2.5)),
    ];
    for path in &paths {
        assert!(path.sample(0, &base()).is_empty());
        let one = path.sample(1, &base());
        assert_eq!(one, vec![path.camera_at(path.start_time(), &base())]);
        let two = path.sample(2, &base());
        assert_eq!(two[1], path.camera_at(path.start_time() + path.duration(), &base()));
        let many = path.sample(241, &base());
        assert_eq!(many.len(), 241);
        assert_eq!(
            many[120],
            path.camera_at(path.start_time() + path.duration() / 2.0, &base())
        );
        for c in &many {
            c.validate().unwrap();
        }
        // Any frame of the longest path, without allocating the path.
        let end = path.camera_at(path.start_time() + path.duration(), &base());
        assert_eq!(path.sample_at(u32::MAX - 1, u32::MAX, &base()), end);
    }
}

#[test]
fn keyframe_times_positions_and_counts_are_bounded() {
    let key = |time: &str, eye: &str| format!("[[keyframe]]\ntime = {time}\neye = {eye}\ntarget = [0, 0, 0]\n");
    let two = |t0: &str, t1: &str, eye: &str| format!("{}{}", key(t0, "[1, 0, 0]"), key(t1, eye));
    let bad = [
        (
            two("-1e308", "1e308", "[2, 0, 0]"),
            "keyframe 1 (line 2): time -1e308 is not in 0..=1000000 s",
        ),
        (
            two("0", "1e308", "[2, 0, 0]"),
            "keyframe 2 (line 6): time 1e308 is not in",
        ),
        (two("0", "-1", "[2, 0, 0]"), "time -1 is not in"),
        (two("0", "nan", "[2, 0, 0]"), "time NaN is not in"),
        (two("0", "1", "[3e38, 0, 0]"), "eye (3e38, 0, 0) exceeds ±10000000 m"),
        (two("0", "1", "[0, -1e300, 0]"), "exceeds ±10000000 m"),
        (two("0", "1", "[1, 0, inf]"), "must be finite"),
        (two("5", "5", "[2, 0, 0]"), "times must strictly increase"),
    ];
    for (text, expected) in bad {
        let message = parse(&text).unwrap_err().to_string();
        assert!(
            message.contains("path.toml") && message.contains(expected),
            "{text}: {message}"
        );
        assert!(!message.contains('\n'), "{message:?}");
    }
    // The duration of a valid path is finite, at most the time limit.
    let path = parse(&two("0", "1e6", "[2, 0, 0]")).unwrap();
    assert_eq!(path.duration(), MAX_KEYFRAME_TIME);
    // Too many keyframes.
    let many: String = (0..=MAX_KEYFRAMES).map(|i| key(&i.to_string(), "[1, 0, 0]")).collect();
    let message = parse(&many).unwrap_err().to_string();
    assert!(message.contains("more than the limit of 10000"), "{message}");
    // The library check agrees.
    let mut keys = keys(&parse(FILE).unwrap()).to_vec();
    keys[2].target.x = 5e7;
    let message = CameraPath::Keyframes(keys).validate().unwrap_err().to_string();
    assert!(message.contains("keyframe 3: target"), "{message}");
}

#[test]
fn keyframe_files_are_read_through_read_input_as_utf8() {
    let path = std::env::temp_dir().join(format!("alpenglow-keys-{}.toml", std::process::id()));
    std::fs::write(&path, b"[[keyframe]]\ntime = 0 # \xfe\n").unwrap();
    let message = load_keyframes(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(message.ends_with("not UTF-8 text"), "{message}");
    let message = load_keyframes(&std::env::temp_dir()).unwrap_err().to_string();
    assert!(message.contains("is a directory"), "{message}");
}

/// The automatic orbit is valid for the box of every legal height field,
/// and unchanged for an ordinary one.
#[test]
fn the_automatic_orbit_is_valid_for_every_legal_terrain() {
    let sides = [1e-3, 30.0, 61_410.0, 2.048e8, 32_767.0 * 1e5];
    for x in sides {
        for y in sides {
            for (lo, hi) in [(0.0, 0.0), (0.0, 100.0), (-1e6, 1e6), (1e6, 1e6), (-1e6, -1e6)] {
                let orbit = Orbit::around(DVec2::new(x, y), lo, hi);
                orbit
                    .validate()
                    .unwrap_or_else(|e| panic!("{x}×{y}, {lo}..{hi}: {orbit:?}: {e}"));
            }
        }
    }
    assert_eq!(
        Orbit::around(DVec2::new(10_240.0, 8_000.0), 100.0, 1_300.0),
        orbit_around(
            DVec3::new(5_120.0, 4_000.0, 100.0),
            10_240.0 * 0.3,
            1_200.0 + 10_240.0 * 0.08,
            1.0
        )
    );
}
