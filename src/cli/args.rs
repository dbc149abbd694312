//! Command-line arguments (the stable contract of the README).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::DVec3;

use crate::cli::orbit::parse_orbit;
use crate::cli::terrain_spec::TerrainSpec;
use alpenglow::view::camera_path::Orbit;

/// alpenglow: a Vulkan renderer for large outdoor scenes.
#[derive(Parser, Debug)]
#[command(name = "alpenglow", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one frame of a scene (the built-in default scene without input files).
    Render(RenderArgs),
    /// Render N frames and report the median GPU time per pass and per frame.
    Bench(BenchArgs),
    /// Render a camera path (keyframe file or orbit) to a PNG sequence and report per-frame times.
    Fly(FlyArgs),
    /// Sequential point trees: `spt build IN OUT`.
    #[command(subcommand)]
    Spt(SptCommand),
    /// Print the Vulkan device, driver and the features in use.
    Info(DeviceArgs),
}

#[derive(Args, Debug, Clone)]
pub struct DeviceArgs {
    /// Enable the Khronos validation layers (and synchronization validation);
    /// exit non-zero if any validation error or warning was reported.
    #[arg(long)]
    pub validation: bool,
    /// Vulkan device by index or name substring (default: discrete, integrated, then CPU).
    #[arg(long, env = "ALPENGLOW_DEVICE")]
    pub device: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Camera position X,Y,Z in metres (default: framing the whole terrain).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<DVec3>,
    /// Point looked at, X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<DVec3>,
    /// Up direction X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    pub up: DVec3,
    /// Vertical field of view in degrees.
    #[arg(long = "fov-y", default_value_t = 50.0)]
    pub fov_y: f64,
    /// Near plane distance in metres (default: from the terrain size).
    #[arg(long)]
    pub near: Option<f64>,
    /// Far plane distance in metres (default: from the terrain size).
    #[arg(long)]
    pub far: Option<f64>,
    /// Height field: 16-bit PNG (value·scale + offset) or EXR (first channel, metres·scale + offset).
    #[arg(long)]
    pub heightmap: Option<PathBuf>,
    /// Metres per height sample: DX or DX,DY.
    #[arg(long, value_parser = parse_spacing, default_value = "1")]
    pub spacing: (f64, f64),
    /// Multiplier of height-map values.
    #[arg(long = "height-scale", default_value_t = 1.0, allow_hyphen_values = true)]
    pub height_scale: f32,
    /// Added to height-map values after scaling, metres.
    #[arg(long = "height-offset", default_value_t = 0.0, allow_hyphen_values = true)]
    pub height_offset: f32,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub points: PointArgs,
    #[command(flatten)]
    pub camera: super::rig::CameraArgs,
    #[command(flatten)]
    pub lighting: super::lighting::LightingArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// Splat mode (§10.2).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatArg {
    /// Opaque discs, one pass (the fast baseline).
    Opaque,
    /// Perspective-accurate EWA splatting in three passes.
    Ewa,
}

/// Primitive carrying a splat (§10.3).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatPrimitiveArg {
    /// Point primitives (quads where a splat exceeds the largest point size).
    Point,
    /// Quads by vertex pulling.
    Quad,
    /// Instanced quads.
    Instanced,
}

#[derive(Args, Debug, Clone)]
pub struct PointArgs {
    /// Point object: PLY (points or mesh), OBJ (mesh) or SPT file; repeatable.
    #[arg(long = "points")]
    pub points: Vec<PathBuf>,
    /// Placement of the n-th --points object: t=X,Y,Z;r=RX,RY,RZ;s=S (degrees; each part optional); repeatable.
    #[arg(long = "points-transform", allow_hyphen_values = true)]
    pub transforms: Vec<String>,
    /// Splat mode.
    #[arg(long, value_enum, default_value = "ewa")]
    pub splat: SplatArg,
    /// Splat primitive.
    #[arg(long = "splat-primitive", value_enum, default_value = "quad")]
    pub splat_primitive: SplatPrimitiveArg,
    /// SPT error threshold in pixels of this image (r_min = e_g / ε).
    #[arg(long, default_value_t = 1.0)]
    pub epsilon: f32,
    /// Surfels sampled from PLY/OBJ meshes given to --points.
    #[arg(long = "points-samples", default_value_t = 50_000)]
    pub samples: usize,
    /// Splat shading; off writes the splats' albedo (debugging, tests).
    #[arg(long = "splat-shading", value_enum, default_value = "on")]
    pub shading: Switch,
    /// Draw back-facing splats (open surfaces); by default they are culled.
    #[arg(long = "two-sided")]
    pub two_sided: bool,
    /// Normal clusters (§10.1.10): skip splats of clusters facing away (closed surfaces only).
    #[arg(long = "normal-clusters")]
    pub normal_clusters: bool,
    /// Hybrid point–polygon rendering (§10.1.8): --points meshes keep their
    /// triangles, drawn where they are larger than the error threshold.
    #[arg(long)]
    pub hybrid: bool,
    /// Procedural boulders scattered over the built-in terrain (0: none).
    #[arg(long, default_value_t = 300)]
    pub rocks: usize,
    /// Draw no terrain: point objects against the sky.
    #[arg(long = "no-terrain")]
    pub no_terrain: bool,
}

/// On or off.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    On,
    Off,
}

/// Terrain LOD placement.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LodArg {
    /// Geometry image warping by the importance map (§7.4).
    Warped,
    /// A regular grid over the sketch map with the same vertex count.
    Uniform,
}

/// What the terrain shows.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewArg {
    Shaded,
    Importance,
    DensityRatio,
    SplitOctave,
    Wireframe,
}

/// Orientation of the sketch map.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlignArg {
    /// Rows across the view direction (default).
    View,
    /// Rows along world x (the text's choice).
    Axes,
}

/// A factor of the importance map (eq. 7.4).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FactorArg {
    Distance,
    Frustum,
    Backface,
    Surface,
}

#[derive(Args, Debug, Clone)]
pub struct TerrainArgs {
    /// Procedural terrain instead of a height map: procedural:MODEL[,key=value...]
    /// with MODEL fbm|multifractal|heterogeneous|hybrid|ridged and keys seed, octaves,
    /// lacunarity, h, offset, gain, wavelength, amplitude, size, spacing (DX or DX:DY).
    #[arg(long, conflicts_with = "heightmap")]
    pub terrain: Option<TerrainSpec>,
    /// Procedural displacement and bump mapping; off shows the sketch atlas surface alone.
    #[arg(long = "terrain-detail", value_enum, default_value = "on")]
    pub terrain_detail: Switch,
    /// Detail amplitude relative to the height-sample spacing.
    #[arg(long = "detail-amplitude", default_value_t = 0.15)]
    pub detail_amplitude: f32,
    /// Vertex placement.
    #[arg(long, value_enum, default_value = "warped")]
    pub lod: LodArg,
    /// Debug view of the terrain.
    #[arg(long, value_enum, default_value = "shaded")]
    pub view: ViewArg,
    /// Output grid side (vertices per side of the geometry image).
    #[arg(long, default_value_t = 512)]
    pub grid: u32,
    /// Sketch map side (texels per side).
    #[arg(long, default_value_t = 128)]
    pub sketch: usize,
    /// Sketch map orientation.
    #[arg(long = "sketch-align", value_enum, default_value = "view")]
    pub sketch_align: AlignArg,
    /// Switch importance factors off (comma-separated), for debugging.
    #[arg(long = "importance-off", value_enum, value_delimiter = ',')]
    pub importance_off: Vec<FactorArg>,
    /// Terrain colouring: the surface-layer tree cached in a texture atlas
    /// (atlas, §8.2), the same tree evaluated per pixel (direct, the atlas's
    /// reference), or classic surface types (§7.4.3).
    #[arg(long, value_enum, default_value = "atlas")]
    pub texturing: TexturingArg,
    /// Most texture tiles generated per frame (atlas texturing), 1..=255;
    /// the texel budget is this many 128² tiles. Still renders keep
    /// rendering until every tile is ready.
    #[arg(long = "tile-budget", default_value_t = 32,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(alpenglow::texturing::streaming::MAX_TILE_BUDGET)))]
    pub tile_budget: u32,
    /// Spread tile generation by GPU time as well (a quarter of the rest of
    /// the frame, measured): steady frame times for moving cameras. off:
    /// tile counts only, so a camera path's frames are the same on every run.
    #[arg(long = "tile-pacing", value_enum, default_value = "on")]
    pub tile_pacing: Switch,
    /// Surface-layer tree (TOML; default: the built-in tree).
    #[arg(long)]
    pub layers: Option<PathBuf>,
    /// Extra input map of the layers, NAME=FILE with NAME rainfall,
    /// radiation or temperature (repeatable): a greyscale PNG or EXR whose
    /// grid spans the terrain rectangle; the layers' hats use its raw values.
    #[arg(long = "input-map", value_parser = parse_input_map)]
    pub input_maps: Vec<(usize, PathBuf)>,
}

/// Terrain colouring.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexturingArg {
    /// Surface types from altitude, slope and orientation (§7.4.3).
    Classic,
    /// The surface-layer tree evaluated per pixel (§8.2 reference).
    Direct,
    /// The surface-layer tree cached in atlas tiles (§8.2).
    Atlas,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Tone-mapped sRGB PNG.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// OpenEXR: linear R,G,B,A, Z (view-space depth, +inf where nothing was hit), the lighting and simulator AOVs
    /// (distance, N.X/Y/Z, class, instance, motion.X/Y) and, with points, W (EWA weight).
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Per-pass timings as JSON (name, GPU ms, CPU ms; frame totals).
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Chrome trace (opens in Perfetto).
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Frames to time (after warm-up).
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// Frames rendered first and not timed.
    #[arg(long, default_value_t = 5)]
    pub warmup: u32,
    /// Write the summary as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Chrome trace of the timed frames.
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct FlyArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Keyframes (TOML: [[keyframe]] time, eye = [x,y,z], target = [x,y,z]); fov, near, far from the camera options.
    #[arg(long, conflicts_with = "orbit")]
    pub path: Option<PathBuf>,
    /// Orbit CX,CY,CZ,RADIUS,HEIGHT[,TURNS] (default: one turn around the terrain's centre).
    #[arg(long, value_parser = parse_orbit, allow_hyphen_values = true)]
    pub orbit: Option<Orbit>,
    /// Frames over the whole path.
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// Directory for frame_00000.png…; must not exist or be empty (without it, frames are only timed).
    #[arg(long = "out-dir")]
    pub out_dir: Option<PathBuf>,
    /// Also write DIR/frame_00000.exr… with every channel (as render --exr; motion from the path's previous frame).
    #[arg(long)]
    pub exr: bool,
    /// Per-frame times and pass medians as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Chrome trace of all frames.
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub enum SptCommand {
    /// Build a sequential point tree from a PLY or OBJ file and write it as an SPT file.
    Build(SptBuildArgs),
}

/// How meshes are sampled into surfels.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplingArg {
    Stratified,
    BlueNoise,
}

#[derive(Args, Debug)]
pub struct SptBuildArgs {
    /// Input: PLY (points or mesh) or OBJ (mesh).
    pub input: PathBuf,
    /// Output SPT file.
    pub output: PathBuf,
    /// Surfels sampled from a mesh (point clouds keep their points).
    #[arg(long, default_value_t = 100_000)]
    pub samples: usize,
    /// Mesh sampling method.
    #[arg(long, value_enum, default_value = "blue-noise")]
    pub sampling: SamplingArg,
    /// Sampling seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// SPT error threshold in pixels (r_min = e_g / ε).
    #[arg(long, default_value_t = 1.0)]
    pub epsilon: f32,
    /// Vertical field of view the pixel threshold refers to, degrees.
    #[arg(long = "fov-y", default_value_t = 60.0)]
    pub fov_y: f32,
    /// Image rows the pixel threshold refers to.
    #[arg(long, default_value_t = 1080)]
    pub rows: u32,
}

fn parse_numbers(s: &str, what: &str) -> Result<Vec<f64>, String> {
    s.split(',')
        .map(|p| {
            let v: f64 = p.trim().parse().map_err(|_| format!("'{s}' is not {what}"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("'{s}' has a non-finite number"))
            }
        })
        .collect()
}

fn parse_vec3(s: &str) -> Result<DVec3, String> {
    match parse_numbers(s, "X,Y,Z")?.as_slice() {
        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not X,Y,Z (three comma-separated numbers)")),
    }
}

fn parse_spacing(s: &str) -> Result<(f64, f64), String> {
    let v = parse_numbers(s, "DX[,DY]")?;
    let (dx, dy) = match v.as_slice() {
        [d] => (*d, *d),
        [dx, dy] => (*dx, *dy),
        _ => return Err(format!("'{s}' is not DX or DX,DY")),
    };
    if dx > 0.0 && dy > 0.0 {
        Ok((dx, dy))
    } else {
        Err(format!("'{s}': spacing must be positive"))
    }
}

/// `NAME=FILE` of `--input-map`.
fn parse_input_map(s: &str) -> Result<(usize, PathBuf), String> {
    let names = alpenglow::texturing::layers::INPUT_NAMES;
    let (name, file) = s.split_once('=').ok_or_else(|| format!("'{s}': expected NAME=FILE"))?;
    let k = (names.iter().position(|n| *n == name))
        .ok_or_else(|| format!("'{name}': the input maps are {}", names.join(", ")))?;
    if file.is_empty() {
        return Err(format!("'{s}': no file"));
    }
    Ok((k, PathBuf::from(file)))
}
