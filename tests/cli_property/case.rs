//! One case: a command, a small valid base command line (tiny images, few
//! frames, small inputs) and one to three numeric options with random or
//! extreme values, plus a few other valid options.

use std::path::{Path, PathBuf};

use super::options::{Command, Opt, Scene};
use super::values::{self, Rng};

/// Small input files shared by every case (made once per run).
pub struct Fixtures {
    pub dir: PathBuf,
}

impl Fixtures {
    /// Writes a 33×33 DEM (16-bit PNG), a mask with a 5×5 hole and a
    /// 33×33 colour image into `dir`.
    pub fn create(dir: &Path) -> Fixtures {
        use alpenglow::files::{encode_png_gray16, encode_png_rgba8};
        std::fs::create_dir_all(dir).unwrap();
        let side = 33u32;
        let at = |i: u32| (f64::from(i % side), f64::from(i / side));
        let dem: Vec<u16> = (0..side * side)
            .map(|i| {
                let (x, y) = at(i);
                (1000.0 + 300.0 * (x * 0.3).sin() * (y * 0.2).cos() + 10.0 * x) as u16
            })
            .collect();
        let mask: Vec<u16> = (0..side * side)
            .map(|i| {
                let (x, y) = at(i);
                u16::from((14.0..19.0).contains(&x) && (14.0..19.0).contains(&y)) * 255
            })
            .collect();
        let rgba: Vec<u8> = (0..side * side)
            .flat_map(|i| {
                let (x, y) = at(i);
                let green = x < 16.0;
                let v = (100.0 + 50.0 * (y * 0.5).sin()) as u8;
                if green {
                    [40, v, 30, 255]
                } else {
                    [v, v, v.saturating_add(20), 255]
                }
            })
            .collect();
        std::fs::write(dir.join("dem.png"), encode_png_gray16(&dem, side, side).unwrap()).unwrap();
        std::fs::write(dir.join("mask.png"), encode_png_gray16(&mask, side, side).unwrap()).unwrap();
        std::fs::write(dir.join("rgb.png"), encode_png_rgba8(&rgba, side, side).unwrap()).unwrap();
        Fixtures { dir: dir.to_path_buf() }
    }

    pub fn path(&self, name: &str) -> String {
        self.dir.join(name).to_string_lossy().into_owned()
    }
}

/// A file of the repository's test data.
pub fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// What a successful run must have written.
#[derive(Clone, Debug)]
pub enum Output {
    /// An RGBA PNG (`--out`).
    Png(PathBuf),
    /// An OpenEXR file.
    Exr(PathBuf),
    /// A JSON document.
    Json(PathBuf),
    /// A folder of PNG frames (`fly --out-dir`).
    Frames(PathBuf),
    /// An SPT file.
    Spt(PathBuf),
    /// A height map of the input's size (`synth`; `synth grow`: its `--size`).
    Height(PathBuf),
    /// A layer tree (TOML).
    Layers(PathBuf),
}

/// A generated command line.
#[derive(Clone, Debug)]
pub struct Case {
    pub command: Command,
    pub args: Vec<String>,
    /// The numeric options varied, with their values.
    pub varied: Vec<(&'static str, String)>,
    /// Files and positional values on the command line (an error may name
    /// one of them instead of an option).
    pub files: Vec<String>,
    pub outputs: Vec<Output>,
    /// Where outputs go (must stay empty when the command fails).
    pub out_dir: PathBuf,
}

impl Case {
    /// The options on the command line.
    pub fn flags(&self) -> Vec<&str> {
        self.args
            .iter()
            .filter(|a| a.starts_with("--"))
            .map(String::as_str)
            .collect()
    }
}

/// Valid extras of the scene commands (mixed in, none changing the cost
/// much).
const SCENE_EXTRAS: &[&[&str]] = &[
    &["--sky", "preetham"],
    &["--shadows", "off"],
    &["--shadows", "horizon"],
    &["--lighting", "ao"],
    &["--lighting", "off"],
    &["--texturing", "classic"],
    &["--texturing", "direct"],
    &["--lod", "uniform"],
    &["--view", "wireframe"],
    &["--sketch-align", "axes"],
    &["--no-terrain-detail"],
    &["--no-tile-pacing"],
    &["--rows", "north-up"],
    &["--importance-off", "distance"],
];

/// The case with id `id`, its files under `root`.
pub fn generate(id: u64, fixtures: &Fixtures, root: &Path) -> Case {
    let mut rng = Rng(id);
    let command = *rng.pick(&[
        Command::Render,
        Command::Render,
        Command::Render,
        Command::Bench,
        Command::Fly,
        Command::SptBuild,
        Command::SynthFill,
        Command::SynthGrow,
        Command::SynthTransition,
        Command::LayersFromImage,
    ]);
    let out_dir = root.join(format!("case-{id:016x}"));
    let options = command.numeric();
    let mut chosen: Vec<Opt> = Vec::new();
    for _ in 0..1 + rng.below(3) {
        let o = *rng.pick(&options);
        if !chosen.iter().any(|c| c.flag == o.flag) {
            chosen.push(o);
        }
    }
    let varied: Vec<(&'static str, String)> = chosen
        .iter()
        .map(|o| (o.flag, values::value(&mut rng, o.kind)))
        .collect();
    let mut case = Case {
        command,
        args: command.words().iter().map(|w| w.to_string()).collect(),
        varied: varied.clone(),
        files: Vec::new(),
        outputs: Vec::new(),
        out_dir: out_dir.clone(),
    };
    let mut base: Vec<String> = Vec::new();
    let args = (&mut case, &mut base, &varied[..]);
    match command {
        Command::Render | Command::Bench | Command::Fly => scene_command(&mut rng, (command, &chosen), fixtures, args),
        Command::SptBuild => spt_build(&mut rng, args),
        Command::SynthFill | Command::SynthGrow | Command::SynthTransition => synth(&mut rng, command, fixtures, args),
        Command::LayersFromImage => layers_from_image(&mut rng, fixtures, args),
    }
    if command.uses_device() {
        base.push("--validation".into());
    }
    // The varied options, then the options they need.
    for (flag, value) in &varied {
        base.push(flag.to_string());
        base.push(value.clone());
    }
    for o in &chosen {
        for (flag, value) in o.with {
            if !base.iter().any(|a| a == flag) {
                base.extend([flag.to_string(), value.to_string()]);
            }
        }
    }
    case.args.extend(base);
    case
}

/// What a case's command line says beyond the varied options: its base
/// arguments into `base`, its files and outputs into `case`.
type CaseParts<'a> = (&'a mut Case, &'a mut Vec<String>, &'a [(&'static str, String)]);

/// `render`, `bench` and `fly`: a scene, the outputs, maybe extras.
fn scene_command(
    rng: &mut Rng,
    (command, chosen): (Command, &[Opt]),
    fixtures: &Fixtures,
    (case, base, varied): CaseParts,
) {
    let out_dir = case.out_dir.clone();
    let out = |name: &str| out_dir.join(name);
    let is_varied = |flag: &str| varied.iter().any(|(f, _)| *f == flag);
    let push = |args: &[&str], base: &mut Vec<String>| base.extend(args.iter().map(|s| s.to_string()));
    scene_base(rng, chosen, fixtures, case, base);
    match command {
        Command::Render => {
            let (png, exr, json) = (out("o.png"), out("o.exr"), out("p.json"));
            for (flag, path) in [("--out", &png), ("--exr", &exr), ("--profile", &json)] {
                base.extend([flag.to_string(), path.to_string_lossy().into_owned()]);
            }
            case.outputs
                .extend([Output::Png(png), Output::Exr(exr), Output::Json(json)]);
        }
        Command::Bench => {
            if !is_varied("--frames") {
                push(&["--frames", "1"], base);
            }
            if !is_varied("--warmup") {
                push(&["--warmup", "0"], base);
            }
            let json = out("p.json");
            base.extend(["--profile".into(), json.to_string_lossy().into_owned()]);
            case.outputs.push(Output::Json(json));
        }
        _ => {
            if !is_varied("--frames") {
                push(&["--frames", "2"], base);
            }
            let frames = out("frames");
            base.extend(["--out-dir".into(), frames.to_string_lossy().into_owned()]);
            case.outputs.push(Output::Frames(frames));
        }
    }
    if rng.chance(0.5) {
        for arg in *rng.pick(SCENE_EXTRAS) {
            if !base.iter().any(|a| a == arg) {
                base.push(arg.to_string());
            }
        }
    }
}

/// `spt build` of one of the PLY fixtures.
fn spt_build(rng: &mut Rng, (case, base, varied): CaseParts) {
    let out_dir = case.out_dir.clone();
    let out = |name: &str| out_dir.join(name);
    let is_varied = |flag: &str| varied.iter().any(|(f, _)| *f == flag);
    let push = |args: &[&str], base: &mut Vec<String>| base.extend(args.iter().map(|s| s.to_string()));
    let input = if rng.chance(0.5) {
        data("points/quad.ply")
    } else {
        data("points/colored-points.ply")
    };
    let spt = out("o.spt");
    base.extend([input.clone(), spt.to_string_lossy().into_owned()]);
    if !is_varied("--samples") {
        push(&["--samples", "500"], base);
    }
    if rng.chance(0.3) {
        push(&["--sampling", "stratified"], base);
    }
    case.files.extend([input, spt.to_string_lossy().into_owned()]);
    case.outputs.push(Output::Spt(spt));
}

/// `synth fill` of the DEM fixture, `synth grow` from it, or `synth
/// transition` of two procedural terrains.
fn synth(rng: &mut Rng, command: Command, fixtures: &Fixtures, (case, base, varied): CaseParts) {
    let out_dir = case.out_dir.clone();
    let out = |name: &str| out_dir.join(name);
    let is_varied = |flag: &str| varied.iter().any(|(f, _)| *f == flag);
    let push = |args: &[&str], base: &mut Vec<String>| base.extend(args.iter().map(|s| s.to_string()));
    let o = out(if rng.chance(0.5) { "o.exr" } else { "o.png" });
    if command == Command::SynthFill {
        let (dem, mask) = (fixtures.path("dem.png"), fixtures.path("mask.png"));
        base.extend(["--input".into(), dem.clone(), "--mask".into(), mask.clone()]);
        case.files.extend([dem, mask]);
    } else if command == Command::SynthGrow {
        let dem = fixtures.path("dem.png");
        base.extend(["--exemplar".into(), dem.clone()]);
        if !is_varied("--size") {
            push(&["--size", "24x20"], base);
        }
        case.files.push(dem);
    } else {
        let a = "procedural:fbm,size=33,seed=1".to_string();
        let b = "procedural:fbm,size=33,seed=2".to_string();
        base.extend([a.clone(), b.clone()]);
        if !is_varied("--band") {
            push(&["--band", "200"], base);
        }
        case.files.extend([a, b]);
    }
    base.extend(["--out".into(), o.to_string_lossy().into_owned()]);
    case.files.push(o.to_string_lossy().into_owned());
    case.outputs.push(Output::Height(o));
    let search = if rng.chance(0.5) { "cpu" } else { "gpu" };
    push(&["--search", search], base);
}

/// `layers from-image` of the RGB and DEM fixtures.
fn layers_from_image(rng: &mut Rng, fixtures: &Fixtures, (case, base, varied): CaseParts) {
    let out_dir = case.out_dir.clone();
    let out = |name: &str| out_dir.join(name);
    let is_varied = |flag: &str| varied.iter().any(|(f, _)| *f == flag);
    let push = |args: &[&str], base: &mut Vec<String>| base.extend(args.iter().map(|s| s.to_string()));
    let (img, dem) = (fixtures.path("rgb.png"), fixtures.path("dem.png"));
    let toml = out("layers.toml");
    let map = out("classes.png");
    base.extend(["--image".into(), img.clone(), "--heightmap".into(), dem.clone()]);
    if !is_varied("--spacing") {
        push(&["--spacing", "30"], base);
    }
    if !is_varied("--classes") && rng.chance(0.7) {
        push(&["--classes", "2"], base);
    }
    base.extend(["--out".into(), toml.to_string_lossy().into_owned()]);
    base.extend(["--class-map".into(), map.to_string_lossy().into_owned()]);
    case.files.extend([img, dem]);
    case.files
        .extend([toml.to_string_lossy().into_owned(), map.to_string_lossy().into_owned()]);
    case.outputs.extend([Output::Layers(toml), Output::Png(map)]);
}

/// The scene of `render`, `bench` and `fly` that the chosen options need:
/// a 33² procedural terrain by default, the built-in terrain with a few
/// boulders, a 33² height map, a point object, or plants.
fn scene_base(rng: &mut Rng, chosen: &[Opt], fixtures: &Fixtures, case: &mut Case, base: &mut Vec<String>) {
    let needs = |s: Scene| chosen.iter().any(|o| o.scene == s);
    let varied = |flag: &str| chosen.iter().any(|o| o.flag == flag);
    if !varied("--width") {
        base.extend(["--width".into(), "32".into()]);
    }
    if !varied("--height") {
        base.extend(["--height".into(), "24".into()]);
    }
    let mut args: Vec<String> = Vec::new();
    if needs(Scene::Builtin) {
        // The built-in terrain: no --terrain or --heightmap.
    } else if needs(Scene::Heightmap) || (!varied("--terrain") && rng.chance(0.25)) {
        let dem = fixtures.path("dem.png");
        args.extend(["--heightmap".into(), dem.clone()]);
        if !varied("--spacing") {
            args.extend(["--spacing".into(), "30".into()]);
        }
        case.files.push(dem);
    } else if !varied("--terrain") {
        args.extend(["--terrain".into(), "procedural:fbm,size=33".into()]);
    }
    if !varied("--rocks") && needs(Scene::Builtin) {
        args.extend(["--rocks".into(), "3".into()]);
    }
    if needs(Scene::Points) || (rng.chance(0.1) && !needs(Scene::Builtin)) {
        let ply = data("points/quad.ply");
        args.extend(["--points".into(), ply.clone()]);
        if !varied("--points-samples") {
            args.extend(["--points-samples".into(), "200".into()]);
        }
        case.files.push(ply);
    }
    if needs(Scene::Vegetation) {
        let layers = data("layers-vegetation-meadow.toml");
        args.extend(["--layers".into(), layers.clone(), "--vegetation".into(), "on".into()]);
        case.files.push(layers);
    } else {
        args.extend(["--vegetation".into(), "off".into()]);
    }
    base.extend(args);
}

/// The command line as a shell would take it (for replay).
pub fn shell_line(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            if !a.is_empty() && a.chars().all(|c| c.is_ascii_alphanumeric() || "-_.,/:=+".contains(c)) {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}
