//! The option space under test: every option of `render`, `bench`, `fly`,
//! `spt build`, `synth fill`, `synth grow`, `synth transition` and `layers from-image`
//! that takes a value, split into the numeric ones (with their documented
//! ranges, varied by the property test) and the others (files, names,
//! modes: set by the test's base command lines only). The test
//! `every_option_is_listed` checks these lists against each command's
//! `--help`, so an option added later cannot be forgotten here.

/// How a numeric option's values are generated.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// An integer in `lo..=hi` (documented); valid values above `cheap`
    /// (legal but slow, as 100,000 frames) are not generated, values
    /// beyond `hi` always are.
    Int { lo: i128, hi: i128, cheap: i128 },
    /// One of these integers.
    OneOf(&'static [i128]),
    /// A float in `lo..=hi` (documented), valid values above `cheap` not
    /// generated.
    Float { lo: f64, hi: f64, cheap: f64 },
    /// Comma-separated floats, `n` of them (any of the counts), each in
    /// `lo..=hi`.
    List { n: &'static [usize], lo: f64, hi: f64 },
    /// A value of its own shape (see `values::special`).
    Special(Special),
}

/// Values with a shape of their own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Special {
    /// `--pose`: a 4×4 camera→world matrix, row by row.
    Pose,
    /// `--rotation`: a unit quaternion.
    Rotation,
    /// `--terrain procedural:MODEL,key=value...`.
    Terrain,
    /// `--points-transform t=X,Y,Z;r=RX,RY,RZ;s=S`.
    Transform,
    /// `--date YYYY-MM-DD`.
    Date,
    /// `--time HH:MM`.
    Time,
    /// `--exposure EV100|auto`.
    Exposure,
    /// `layers from-image --classes K|auto`.
    Classes,
}

/// The scene a scene command (`render`, `bench`, `fly`) needs for an
/// option to matter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scene {
    /// Any scene (the small procedural terrain by default).
    Any,
    /// The built-in terrain (its boulders: `--rocks`).
    Builtin,
    /// A height-map file (`--height-scale`, `--max-input-mb`, ...).
    Heightmap,
    /// A point object (`--points-transform`, `--points-samples`).
    Points,
    /// Plants (`--vegetation-density`).
    Vegetation,
}

/// A numeric option.
#[derive(Clone, Copy, Debug)]
pub struct Opt {
    pub flag: &'static str,
    pub kind: Kind,
    pub scene: Scene,
    /// Options added with a valid value when the command line lacks them
    /// (an option that is only read together with others).
    pub with: &'static [(&'static str, &'static str)],
}

const fn opt(flag: &'static str, kind: Kind) -> Opt {
    Opt {
        flag,
        kind,
        scene: Scene::Any,
        with: &[],
    }
}

const fn int(lo: i128, hi: i128, cheap: i128) -> Kind {
    Kind::Int { lo, hi, cheap }
}

const fn float(lo: f64, hi: f64) -> Kind {
    Kind::Float { lo, hi, cheap: hi }
}

const U32: i128 = u32::MAX as i128;
const U64: i128 = u64::MAX as i128;
const BIG: f64 = 1e6;
const SOLAR: &[(&str, &str)] = &[
    ("--date", "2021-06-21"),
    ("--time", "12:00"),
    ("--latitude", "46.5"),
    ("--longitude", "8"),
];

/// The numeric options of `render`, `bench` and `fly` (the scene).
pub const SCENE: &[Opt] = &[
    // Legal images above 1024 pixels a side are slow under validation in a
    // debug build (a 32×4284 bench ran past 60 s); 16385 and more are
    // generated (they must be refused at once).
    opt("--width", int(1, 16384, 1024)),
    opt("--height", int(1, 16384, 1024)),
    opt(
        "--eye",
        Kind::List {
            n: &[3],
            lo: -1e8,
            hi: 1e8,
        },
    ),
    opt(
        "--target",
        Kind::List {
            n: &[3],
            lo: -1e8,
            hi: 1e8,
        },
    ),
    opt(
        "--up",
        Kind::List {
            n: &[3],
            lo: -1.0,
            hi: 1.0,
        },
    ),
    opt("--fov-y", float(0.0, 180.0)),
    opt("--near", float(1e-6, 1e9)),
    opt("--far", float(1e-6, 1e9)),
    opt("--pose", Kind::Special(Special::Pose)),
    Opt {
        with: &[("--eye", "300,-200,400")],
        ..opt("--rotation", Kind::Special(Special::Rotation))
    },
    opt(
        "--intrinsics",
        Kind::List {
            n: &[4],
            lo: -100.0,
            hi: 100.0,
        },
    ),
    opt(
        "--distortion",
        Kind::List {
            n: &[5],
            lo: -10.0,
            hi: 10.0,
        },
    ),
    opt("--msaa", Kind::OneOf(&[1, 2, 4, 8, 16])),
    opt("--shutter", float(0.0, 1.0 / 30.0)),
    opt("--fps", float(0.0, 1000.0)),
    Opt {
        scene: Scene::Heightmap,
        ..opt(
            "--spacing",
            Kind::List {
                n: &[1, 2],
                lo: 0.001,
                hi: 100000.0,
            },
        )
    },
    Opt {
        scene: Scene::Heightmap,
        ..opt("--height-scale", float(-BIG, BIG))
    },
    Opt {
        scene: Scene::Heightmap,
        ..opt("--height-offset", float(-1e6, 1e6))
    },
    opt("--terrain", Kind::Special(Special::Terrain)),
    opt("--detail-amplitude", float(0.0, 10.0)),
    // Only read for height pyramids (.hpyr); any value is valid for others.
    Opt {
        scene: Scene::Heightmap,
        ..opt("--resident-side", int(2, 16384, 16384))
    },
    // Also only read for height pyramids; above 1024 a window's image and
    // upload region grow past what a property run needs.
    Opt {
        scene: Scene::Heightmap,
        ..opt("--detail-window", int(0, 8192, 1024))
    },
    // A 2048² grid (4 M vertices warped per frame) is legal but ran past
    // 60 s on lavapipe in a debug build under load; 2049 and more are
    // generated.
    opt("--grid", int(2, 2048, 1024)),
    opt("--sketch", int(4, 1024, 1024)),
    opt("--lod-snap", float(0.0, 1024.0)),
    Opt {
        scene: Scene::Heightmap,
        ..opt("--max-input-mb", int(1, U64, 1 << 40))
    },
    opt("--tile-budget", int(1, 255, 255)),
    Opt {
        scene: Scene::Points,
        ..opt("--points-transform", Kind::Special(Special::Transform))
    },
    opt(
        "--epsilon",
        Kind::Float {
            lo: 0.0,
            hi: BIG,
            cheap: BIG,
        },
    ),
    Opt {
        scene: Scene::Points,
        ..opt("--points-samples", int(1, U64, 20_000))
    },
    Opt {
        scene: Scene::Builtin,
        ..opt("--rocks", int(0, U64, 100))
    },
    Opt {
        scene: Scene::Vegetation,
        ..opt(
            "--vegetation-density",
            Kind::Float {
                lo: 0.0,
                hi: 1e300,
                // Denser meadows are legal but slow on lavapipe (a fly of
                // two frames at 4 ran past 60 s under load).
                cheap: 1.0,
            },
        )
    },
    opt("--sun-elevation", float(-90.0, 90.0)),
    opt("--sun-azimuth", float(-BIG, BIG)),
    Opt {
        with: SOLAR,
        ..opt("--date", Kind::Special(Special::Date))
    },
    Opt {
        with: SOLAR,
        ..opt("--time", Kind::Special(Special::Time))
    },
    Opt {
        with: SOLAR,
        ..opt("--latitude", float(-90.0, 90.0))
    },
    Opt {
        with: SOLAR,
        ..opt("--longitude", float(-180.0, 180.0))
    },
    opt("--turbidity", float(1.7, 10.0)),
    opt("--exposure", Kind::Special(Special::Exposure)),
    opt("--sh-bands", Kind::OneOf(&[3, 5])),
    opt("--bounces", Kind::OneOf(&[0, 1, 2])),
    Opt {
        with: &[("--lighting", "patches")],
        ..opt("--sky-patches", Kind::OneOf(&[4, 8]))
    },
    opt("--albedo-override", float(0.0, 1.0)),
];

/// The other value options of `render`, `bench` and `fly`.
pub const SCENE_OTHER: &[&str] = &[
    "--rig",
    "--rig-preset",
    "--heightmap",
    "--rows",
    "--texturing",
    "--raster",
    "--layers",
    "--input-map",
    "--points",
    "--splat",
    "--splat-primitive",
    "--splat-backend",
    "--splat-kernel",
    "--spt-error",
    "--vegetation",
    "--sky-preset",
    "--sky",
    "--shadows",
    "--sun-disc",
    "--lighting",
    "--cache-dir",
    "--lod",
    "--view",
    "--sketch-align",
    "--importance-off",
    "--device",
];

// `--renderdoc-capture`: needs RenderDoc (tests/cli_renderdoc.rs), not varied here.
pub const RENDER_OTHER: &[&str] = &["--out", "--exr", "--profile", "--trace", "--renderdoc-capture"];

pub const BENCH: &[Opt] = &[opt("--frames", int(1, 100_000, 2)), opt("--warmup", int(0, 100_000, 1))];
pub const BENCH_OTHER: &[&str] = &["--profile", "--trace", "--renderdoc-capture"];

pub const FLY: &[Opt] = &[
    opt("--frames", int(1, 100_000, 3)),
    opt(
        "--orbit",
        Kind::List {
            n: &[5, 6],
            lo: -1e4,
            hi: 1e4,
        },
    ),
];
pub const FLY_OTHER: &[&str] = &["--path", "--out-dir", "--profile", "--trace", "--renderdoc-capture"];

pub const SPT: &[Opt] = &[
    opt("--samples", int(1, U64, 5_000)),
    opt("--seed", int(0, U64, U64)),
    opt(
        "--epsilon",
        Kind::Float {
            lo: 0.0,
            hi: BIG,
            cheap: BIG,
        },
    ),
    opt("--fov-y", float(0.0, 180.0)),
    opt("--rows", int(1, U32, U32)),
    // Any positive number of hours; above the default (1 h) it only lets
    // slow work run, so larger ceilings are not generated.
    opt(
        "--max-hours",
        Kind::Float {
            lo: 0.0,
            hi: BIG,
            cheap: 1.0,
        },
    ),
];
pub const SPT_OTHER: &[&str] = &["--sampling"];

/// The options `synth fill`, `synth grow` and `synth transition` share.
pub const GROW: &[Opt] = &[
    opt("--window", int(3, 63, 15)),
    opt("--lambda", float(0.0, BIG)),
    opt("--epsilon", float(0.0, BIG)),
    opt("--seed", int(0, U32, U32)),
    opt("--batch", int(1, U64, U64)),
    opt("--candidates", int(1, U64, 100_000)),
    opt(
        "--spacing",
        Kind::List {
            n: &[1, 2],
            lo: 0.001,
            hi: 100000.0,
        },
    ),
    opt("--height-scale", float(-BIG, BIG)),
    opt("--height-offset", float(-1e6, 1e6)),
    opt("--max-input-mb", int(1, U64, 1 << 40)),
    // Any positive number of hours; above the default (1 h) it only lets
    // slow work run, so larger ceilings are not generated.
    opt(
        "--max-hours",
        Kind::Float {
            lo: 0.0,
            hi: BIG,
            cheap: 1.0,
        },
    ),
];
pub const FILL_OTHER: &[&str] = &["--input", "--mask", "--out", "--search", "--device", "--rows"];

// Sides of the grown field: legal up to 8192, but above 48 (on the 33²
// fixture) a debug build under load takes long; below the window an error.
pub const FREE: &[Opt] = &[opt("--size", int(7, 8192, 48))];
pub const FREE_OTHER: &[&str] = &["--exemplar", "--out", "--search", "--device", "--rows"];

pub const TRANSITION: &[Opt] = &[
    opt("--band", float(0.0, BIG)),
    opt("--blur", int(0, U32, 16)),
    opt("--steps", int(0, 16, 4)),
];
pub const TRANSITION_OTHER: &[&str] = &["--out", "--axis", "--search", "--device", "--rows"];

pub const LAYERS: &[Opt] = &[
    opt(
        "--spacing",
        Kind::List {
            n: &[1, 2],
            lo: 0.001,
            hi: 100000.0,
        },
    ),
    opt("--height-scale", float(-BIG, BIG)),
    opt("--height-offset", float(-1e6, 1e6)),
    opt("--classes", Kind::Special(Special::Classes)),
    opt("--sun-azimuth", float(-BIG, BIG)),
    opt("--sun-elevation", float(-90.0, 90.0)),
    opt("--snow-min-altitude", float(-1e6, 1e6)),
    opt("--bins", int(1, 64, 64)),
    opt("--value-weight", float(0.0, 4.0)),
    opt("--level2", int(2, 4, 4)),
    opt("--seed", int(0, U64, U64)),
    opt("--max-input-mb", int(1, U64, 1 << 40)),
];
pub const LAYERS_OTHER: &[&str] = &[
    "--image",
    "--heightmap",
    "--rows",
    "--input-map",
    "--mask",
    "--out",
    "--class-map",
    "--histograms",
    "--hs-histogram",
];

/// A command under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    Render,
    Bench,
    Fly,
    SptBuild,
    SynthFill,
    SynthGrow,
    SynthTransition,
    LayersFromImage,
}

impl Command {
    pub const ALL: [Command; 8] = [
        Command::Render,
        Command::Bench,
        Command::Fly,
        Command::SptBuild,
        Command::SynthFill,
        Command::SynthGrow,
        Command::SynthTransition,
        Command::LayersFromImage,
    ];

    /// The words that start its command line.
    pub fn words(self) -> &'static [&'static str] {
        match self {
            Command::Render => &["render"],
            Command::Bench => &["bench"],
            Command::Fly => &["fly"],
            Command::SptBuild => &["spt", "build"],
            Command::SynthFill => &["synth", "fill"],
            Command::SynthGrow => &["synth", "grow"],
            Command::SynthTransition => &["synth", "transition"],
            Command::LayersFromImage => &["layers", "from-image"],
        }
    }

    /// Its numeric options.
    pub fn numeric(self) -> Vec<Opt> {
        let mut v: Vec<Opt> = match self {
            Command::Render | Command::Bench | Command::Fly => SCENE.to_vec(),
            Command::SptBuild => SPT.to_vec(),
            Command::SynthFill => GROW.to_vec(),
            Command::SynthGrow => [GROW, FREE].concat(),
            Command::SynthTransition => [GROW, TRANSITION].concat(),
            Command::LayersFromImage => LAYERS.to_vec(),
        };
        match self {
            Command::Bench => v.extend_from_slice(BENCH),
            Command::Fly => v.extend_from_slice(FLY),
            _ => {}
        }
        v
    }

    /// Its other options that take a value (not varied).
    pub fn other(self) -> Vec<&'static str> {
        match self {
            Command::Render => [SCENE_OTHER, RENDER_OTHER].concat(),
            Command::Bench => [SCENE_OTHER, BENCH_OTHER].concat(),
            Command::Fly => [SCENE_OTHER, FLY_OTHER].concat(),
            Command::SptBuild => SPT_OTHER.to_vec(),
            Command::SynthFill => FILL_OTHER.to_vec(),
            Command::SynthGrow => FREE_OTHER.to_vec(),
            Command::SynthTransition => TRANSITION_OTHER.to_vec(),
            Command::LayersFromImage => LAYERS_OTHER.to_vec(),
        }
    }

    /// Whether it runs on the Vulkan device (and takes `--validation`).
    pub fn uses_device(self) -> bool {
        !matches!(self, Command::SptBuild | Command::LayersFromImage)
    }
}
