//! Command-line arguments (the stable contract of the README).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::DVec3;

use crate::cli::orbit::parse_orbit;
use crate::cli::terrain_spec::TerrainSpec;
use alpenglow::Orbit;

/// alpenglow: a Vulkan renderer for large outdoor scenes.
#[derive(Parser, Debug)]
#[command(name = "alpenglow", version, about, after_help = ENVIRONMENT_HELP)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The environment variables, shown under every command's `--help`.
pub const ENVIRONMENT_HELP: &str = "Environment:
  ALPENGLOW_DEVICE  Vulkan device by index or name substring (as --device)
  RUST_LOG          log filter: error, warn (default), info, debug or trace,
                    also per module, e.g. RUST_LOG=alpenglow::texturing=debug
  VK_LAYER_PATH     where the Khronos validation layer is found (--validation)

Boolean options are flags: --X turns a feature on, --no-X turns off one that
is on by default. Lengths are in metres, angles in degrees, times in seconds.";

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one frame of a scene (the built-in default scene without input files).
    Render(RenderArgs),
    /// Render N frames and report the median GPU time per pass and per frame.
    Bench(BenchArgs),
    /// Render a camera path (keyframe file or orbit) to a PNG sequence and report per-frame times.
    Fly(FlyArgs),
    /// Show the scene live in a window with a fly camera (WASD, mouse, wheel; arrows move the sun; F12 captures).
    View(super::view::ViewArgs),
    /// Sequential point trees: `spt build IN OUT`.
    #[command(subcommand)]
    Spt(SptCommand),
    /// Print the Vulkan device, driver and the features in use.
    Info(DeviceArgs),
    /// Surface-layer trees: `layers from-image` (§8.3).
    #[command(subcommand)]
    Layers(super::layers::LayersCommand),
    /// Height-field synthesis (§7.3): `synth fill`, `synth transition`.
    #[command(subcommand)]
    Synth(super::synth::SynthCommand),
    /// Height pyramids for fields of any size: `dem import`, `dem info`.
    #[command(subcommand)]
    Dem(super::dem::DemCommand),
}

#[derive(Args, Debug, Clone)]
pub struct DeviceArgs {
    /// Enable the Khronos validation layers (and synchronization validation);
    /// exit non-zero if any validation error or warning was reported.
    #[arg(long, help_heading = "Debug")]
    pub validation: bool,
    /// Vulkan device by index or name substring (default: discrete, integrated, then CPU).
    #[arg(long, env = "ALPENGLOW_DEVICE", value_name = "INDEX|NAME", help_heading = "Debug")]
    pub device: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1280, value_name = "PIXELS", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Camera")]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 720, value_name = "PIXELS", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Camera")]
    pub height: u32,
    /// Camera position X,Y,Z in metres (default: framing the whole terrain).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z", help_heading = "Camera")]
    pub eye: Option<DVec3>,
    /// Point looked at X,Y,Z in metres (default: the terrain's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z", help_heading = "Camera")]
    pub target: Option<DVec3>,
    /// Up direction X,Y,Z (a direction, any length; +Z is up in the world).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1", value_name = "X,Y,Z", help_heading = "Camera")]
    pub up: DVec3,
    /// Vertical field of view in degrees, (0, 180).
    #[arg(
        long = "fov-y",
        default_value_t = 50.0,
        value_name = "DEGREES",
        help_heading = "Camera"
    )]
    pub fov_y: f64,
    /// Near plane distance in metres (default: from the terrain size).
    #[arg(long, value_name = "METRES", help_heading = "Camera")]
    pub near: Option<f64>,
    /// Far plane distance in metres, or `inf` for an infinite far plane
    /// (default: from the terrain size). Depth is reversed (near 1, far 0,
    /// 32-bit float), so a near plane of centimetres still orders ridges
    /// 100 km away.
    #[arg(long, value_name = "METRES", help_heading = "Camera")]
    pub far: Option<f64>,
    /// Height field: 16-bit PNG (value·scale + offset), EXR (first channel,
    /// metres·scale + offset), GeoTIFF, SRTM .hgt, or a height pyramid
    /// (.hpyr, `alpenglow dem import`; see --resident-side).
    #[arg(long, value_name = "FILE", help_heading = "Terrain")]
    pub heightmap: Option<PathBuf>,
    /// Metres between height samples: DX, or DX,DY for columns and rows,
    /// each 0.001..=100000 (default: a GeoTIFF's or .hgt's georeferencing,
    /// else 1 with a warning).
    #[arg(long, value_parser = parse_spacing, value_name = "DX[,DY]", help_heading = "Terrain")]
    pub spacing: Option<(f64, f64)>,
    /// Multiplier of height-map values (to metres).
    #[arg(
        long = "height-scale",
        default_value_t = 1.0,
        value_parser = parse_height_scale,
        value_name = "FACTOR",
        help_heading = "Terrain"
    )]
    pub height_scale: f32,
    /// Added to height-map values after scaling, in metres.
    #[arg(
        long = "height-offset",
        default_value_t = 0.0,
        value_parser = parse_height_offset,
        value_name = "METRES",
        help_heading = "Terrain"
    )]
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
    pub debug: TerrainDebugArgs,
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
    /// EWA splatting in one pass with a fuzzy depth test (§10.4).
    SinglePass,
}

/// How single-pass splatting merges each pixel (§10.4).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatBackendArg {
    /// Compute passes: splats binned into 16x16-pixel tiles, each tile sorted front to back and merged (deterministic).
    Compute,
    /// Fragment shader interlock (needs VK_EXT_fragment_shader_interlock).
    Interlock,
}

/// Screen-space splat kernel (§10.2, Figs. 10.15–10.17).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatKernelArg {
    /// Perspective-accurate: the exact projection of each splat's ellipse.
    Perspective,
    /// Affine EWA (Zwicker et al. 2001): the Jacobian of the projection at the splat centre.
    Affine,
}

/// Error of the SPT interval test (§10.1.4, §10.1.7).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SptErrorArg {
    /// The geometric error e_g = sqrt(e_p² + e_t²), the same at every view angle.
    Isotropic,
    /// e_p·sin α + e_t·cos α (α: view vector to normal), tested per splat: fewer splats.
    ViewDependent,
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
    /// The text's quadruplicated object-space quads, kernel in a texture (§10.3).
    ObjectQuad,
    /// The text's instanced object-space quads, kernel in a texture (§10.3).
    ObjectInstanced,
}

#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Points")]
pub struct PointArgs {
    /// Point object: PLY (points or mesh), OBJ (mesh) or SPT file; repeatable.
    #[arg(long = "points", value_name = "FILE")]
    pub points: Vec<PathBuf>,
    /// Placement of the n-th --points object: t=X,Y,Z;r=RX,RY,RZ;s=S (metres,
    /// degrees, a factor; each part optional); repeatable.
    #[arg(
        long = "points-transform",
        allow_hyphen_values = true,
        value_name = "t=X,Y,Z;r=RX,RY,RZ;s=S"
    )]
    pub transforms: Vec<String>,
    /// Splat mode.
    #[arg(long, value_enum, default_value = "ewa", value_name = "MODE")]
    pub splat: SplatArg,
    /// Splat primitive.
    #[arg(
        long = "splat-primitive",
        value_enum,
        default_value = "quad",
        value_name = "PRIMITIVE"
    )]
    pub splat_primitive: SplatPrimitiveArg,
    /// Backend of --splat single-pass.
    #[arg(
        long = "splat-backend",
        value_enum,
        default_value = "compute",
        value_name = "BACKEND"
    )]
    pub splat_backend: SplatBackendArg,
    /// Screen-space splat kernel (screen-space primitives only).
    #[arg(
        long = "splat-kernel",
        value_enum,
        default_value = "perspective",
        value_name = "KERNEL"
    )]
    pub splat_kernel: SplatKernelArg,
    /// Error of the SPT interval test (screen-space primitives only for view-dependent).
    #[arg(long = "spt-error", value_enum, default_value = "isotropic", value_name = "ERROR")]
    pub spt_error: SptErrorArg,
    /// SPT error threshold in pixels of this image (r_min = e_g / ε).
    #[arg(long, default_value_t = 1.0, value_name = "PIXELS")]
    pub epsilon: f32,
    /// Surfels sampled from PLY/OBJ meshes given to --points.
    #[arg(long = "points-samples", default_value_t = 50_000, value_name = "COUNT", value_parser = clap::builder::RangedI64ValueParser::<usize>::new().range(0..))]
    pub samples: usize,
    /// No splat shading: write the splats' albedo (debugging, tests).
    #[arg(long = "no-splat-shading")]
    pub no_shading: bool,
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
    /// With --hybrid: draw the points red, the triangles in their colours
    /// (Fig. 10.8, left: where points replace small triangles).
    #[arg(long = "hybrid-red-points", requires = "hybrid")]
    pub hybrid_red_points: bool,
    /// Procedural boulders scattered over the built-in terrain (0: none).
    #[arg(long, default_value_t = 300, value_name = "COUNT", value_parser = clap::builder::RangedI64ValueParser::<usize>::new().range(0..))]
    pub rocks: usize,
    /// Procedural plants of the layer tree's `vegetation` tables (default:
    /// on for the built-in terrain, off for height maps and --terrain specs).
    #[arg(long, value_enum, value_name = "on|off")]
    pub vegetation: Option<VegetationArg>,
    /// Multiplier of every layer's plant density (≥ 0).
    #[arg(
        long = "vegetation-density",
        default_value_t = 1.0,
        value_name = "F",
        allow_hyphen_values = true
    )]
    pub vegetation_density: f64,
    /// Draw no terrain: point objects against the sky.
    #[arg(long = "no-terrain")]
    pub no_terrain: bool,
}

/// Whether plants grow (`--vegetation`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum VegetationArg {
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

/// Debugging views and switches of the terrain (listed last in `--help`).
#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Debug")]
pub struct TerrainDebugArgs {
    /// Vertex placement.
    #[arg(
        long,
        value_enum,
        default_value = "warped",
        value_name = "PLACEMENT",
        help_heading = "Debug"
    )]
    pub lod: LodArg,
    /// Debug view of the terrain.
    #[arg(
        long,
        value_enum,
        default_value = "shaded",
        value_name = "MODE",
        help_heading = "Debug"
    )]
    pub view: ViewArg,
    /// Sketch map orientation.
    #[arg(
        long = "sketch-align",
        value_enum,
        default_value = "view",
        value_name = "ALIGNMENT",
        help_heading = "Debug"
    )]
    pub sketch_align: AlignArg,
    /// Switch importance factors off (comma-separated), for debugging.
    #[arg(
        long = "importance-off",
        value_enum,
        value_delimiter = ',',
        value_name = "FACTOR,...",
        help_heading = "Debug"
    )]
    pub importance_off: Vec<FactorArg>,
}

#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Terrain")]
pub struct TerrainArgs {
    /// Procedural terrain instead of a height map: procedural:MODEL[,key=value...]
    /// with MODEL fbm|multifractal|heterogeneous|hybrid|ridged and keys seed, octaves,
    /// lacunarity, h, offset, gain, wavelength, amplitude, size, spacing (DX or DX:DY).
    #[arg(long, conflicts_with = "heightmap", value_name = "procedural:MODEL[,KEY=VALUE...]")]
    pub terrain: Option<TerrainSpec>,
    /// No procedural displacement and bump mapping: the height field's
    /// B-spline surface alone.
    #[arg(long = "no-terrain-detail")]
    pub no_terrain_detail: bool,
    /// Procedural detail in the geometry only: no per-pixel bump mapping
    /// of the octaves finer than the mesh (Fig. 7.14, centre).
    #[arg(long = "no-detail-shading", conflicts_with = "no_terrain_detail")]
    pub no_detail_shading: bool,
    /// Amplitude of the procedural detail, as a fraction of the
    /// height-sample spacing (0.15: 15 cm for 1 m samples).
    #[arg(long = "detail-amplitude", default_value_t = 0.15, value_name = "FRACTION")]
    pub detail_amplitude: f32,
    /// Height pyramids (.hpyr): the finest level with at most this many
    /// samples a side is held in memory as the sketch atlas (§7.4.4);
    /// memory then does not grow with the field.
    #[arg(long = "resident-side", default_value_t = alpenglow::files::DEFAULT_RESIDENT_SIDE, value_name = "SAMPLES", value_parser = clap::value_parser!(u32).range(2..=16384))]
    pub resident_side: u32,
    /// Height pyramids (.hpyr): side in samples of the detail window, a
    /// finer level streamed around the camera over the resident one (0:
    /// off; rounded up to whole tiles). `render` waits for its tiles;
    /// `fly` and `bench` draw the resident level until they arrive.
    #[arg(long = "detail-window", default_value_t = alpenglow::files::DEFAULT_DETAIL_WINDOW, value_name = "SAMPLES", value_parser = clap::value_parser!(u32).range(0..=8192))]
    pub detail_window: u32,
    /// Which rasterizer draws the terrain and the EWA splats: compute
    /// shaders (the terrain into a visibility buffer, then one shading pass
    /// per pixel; the splats and their shadows with 64-bit atomics; needs
    /// the device feature shaderBufferInt64Atomics), the hardware
    /// rasterizer (hardware, the text's path), or compute where the device
    /// has the feature (auto, the default).
    #[arg(long, value_enum, default_value = "auto", value_name = "PATH")]
    pub raster: RasterArg,
    /// Geometry-image side in vertices (the terrain mesh has GRID² vertices).
    #[arg(long, default_value_t = 512, value_name = "VERTICES", value_parser = clap::value_parser!(u32).range(2..))]
    pub grid: u32,
    /// Sketch map side in texels.
    #[arg(long, default_value_t = 128, value_name = "TEXELS", value_parser = clap::builder::RangedI64ValueParser::<usize>::new().range(0..))]
    pub sketch: usize,
    /// Anchors the terrain's LOD plan to the world against swimming
    /// (§7.4.3, §7.4.5): the plan's eye snaps to a grid of at most this
    /// many sketch texels of the whole terrain, halved until it is at most
    /// the eye's height above the ground, and the mesh is planned again
    /// only when the eye moves to another grid point (1, the default, cuts
    /// a flying camera's swimming 5–8×; 0: planned for the eye every
    /// frame, as in the text). 0..=1024.
    #[arg(long = "lod-snap", default_value_t = alpenglow::DEFAULT_LOD_SNAP, value_name = "TEXELS")]
    pub lod_snap: f64,
    /// Terrain colouring: the surface-layer tree cached in a texture atlas
    /// (atlas, §8.2), the same tree evaluated per pixel (direct, the atlas's
    /// reference), or classic surface types (§7.4.3).
    #[arg(
        long,
        value_enum,
        default_value = "atlas",
        value_name = "MODE",
        help_heading = "Texturing"
    )]
    pub texturing: TexturingArg,
    /// Most texture tiles generated per frame (atlas texturing), 1..=255;
    /// the texel budget is this many 128² tiles. Still renders keep
    /// rendering until every tile is ready.
    #[arg(
        long = "tile-budget",
        default_value_t = 32,
        value_name = "TILES",
        help_heading = "Texturing",
        value_parser = clap::value_parser!(u32).range(1..=i64::from(alpenglow::MAX_TILE_BUDGET))
    )]
    pub tile_budget: u32,
    /// Tile counts only, no pacing of tile generation by measured GPU time
    /// (by default a quarter of the rest of the frame, for steady frame
    /// times): a camera path's frames are then the same on every run.
    #[arg(long = "no-tile-pacing", help_heading = "Texturing")]
    pub no_tile_pacing: bool,
    /// Surface-layer tree (TOML; default: the built-in tree).
    #[arg(long, value_name = "FILE", help_heading = "Texturing")]
    pub layers: Option<PathBuf>,
    /// Extra input map of the layers, NAME=FILE with NAME rainfall,
    /// radiation or temperature (repeatable): a greyscale PNG or EXR whose
    /// grid spans the terrain rectangle; the layers' hats use its raw values.
    #[arg(long = "input-map", value_parser = parse_input_map, value_name = "NAME=FILE", help_heading = "Texturing")]
    pub input_maps: Vec<(usize, PathBuf)>,
    /// Where a PNG, EXR or plain TIFF height map's first row lies: south-up
    /// (default: rows kept, row 0 at y = 0, the south edge) or north-up
    /// (flipped: row 0 is the north edge, as in nearly every GIS raster).
    /// GeoTIFF and .hgt files carry their own orientation.
    #[arg(long, value_enum, default_value = "south-up", value_name = "ORDER")]
    pub rows: RowsArg,
    /// Largest height-map or input-map file in MiB (default 2048); the
    /// image-size and decode limits grow in proportion above it.
    #[arg(long = "max-input-mb", default_value_t = 2048, value_name = "MIB", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_input_mb: u64,
}

/// Row order of `--rows`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowsArg {
    /// Image row 0 is the south edge (rows kept).
    SouthUp,
    /// Image row 0 is the north edge (rows flipped).
    NorthUp,
}

/// The terrain's and the splats' rasterizer (`--raster`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterArg {
    /// Compute where the device has 64-bit buffer atomics, else hardware.
    Auto,
    /// The visibility buffer and deferred shading in compute shaders.
    Compute,
    /// The hardware rasterizer.
    Hardware,
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
    /// Tone-mapped sRGB PNG.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub out: Option<PathBuf>,
    /// OpenEXR: linear R,G,B,A, Z (view-space depth, +inf where nothing was hit), the lighting and simulator AOVs
    /// (distance, N.X/Y/Z, class, instance, motion.X/Y) and, with points, W (EWA weight).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub exr: Option<PathBuf>,
    /// Per-pass timings as JSON (name, GPU ms, CPU ms; frame totals).
    #[arg(long, alias = "json", value_name = "FILE", help_heading = "Output")]
    pub profile: Option<PathBuf>,
    /// Chrome trace (opens in Perfetto).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub trace: Option<PathBuf>,
    /// Count each pass's pipeline statistics (vertex, fragment, compute
    /// invocations…) into the profile; needs the device feature pipelineStatisticsQuery.
    #[arg(long, help_heading = "Output")]
    pub pipeline_stats: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
    // After the scene: its Debug heading stays last in --help.
    #[command(flatten)]
    pub renderdoc: super::renderdoc::RenderDocArgs,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Frames to time (after warm-up), 1–100000.
    #[arg(long, default_value_t = 60, value_name = "COUNT", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Output")]
    pub frames: u32,
    /// Frames rendered first and not timed, at most 100000.
    #[arg(long, default_value_t = 5, value_name = "COUNT", help_heading = "Output", value_parser = clap::value_parser!(u32).range(0..))]
    pub warmup: u32,
    /// The summary (per-pass medians, frame times) as JSON.
    #[arg(long = "profile", alias = "json", value_name = "FILE", help_heading = "Output")]
    pub profile: Option<PathBuf>,
    /// Chrome trace of the timed frames (opens in Perfetto).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub trace: Option<PathBuf>,
    /// Count each pass's pipeline statistics (vertex, fragment, compute
    /// invocations…) and report their medians; needs the device feature pipelineStatisticsQuery.
    #[arg(long, help_heading = "Output")]
    pub pipeline_stats: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
    // After the scene: its Debug heading stays last in --help.
    #[command(flatten)]
    pub renderdoc: super::renderdoc::RenderDocArgs,
}

#[derive(Args, Debug)]
pub struct FlyArgs {
    /// Keyframes (TOML: [[keyframe]] time in seconds, eye = [x,y,z] and
    /// target = [x,y,z] in metres); fov, near, far from the camera options.
    #[arg(long, conflicts_with = "orbit", value_name = "FILE", help_heading = "Camera")]
    pub path: Option<PathBuf>,
    /// Orbit around the centre CX,CY,CZ (metres) at RADIUS metres, HEIGHT
    /// metres above the centre, TURNS turns over the frames (default 1;
    /// default orbit: one turn around the terrain's centre).
    #[arg(long, value_parser = parse_orbit, allow_hyphen_values = true, value_name = "CX,CY,CZ,RADIUS,HEIGHT[,TURNS]", help_heading = "Camera")]
    pub orbit: Option<Orbit>,
    /// Frames over the whole path, 1–100000.
    #[arg(long, default_value_t = 60, value_name = "COUNT", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Output")]
    pub frames: u32,
    /// Directory for frame_00000.png…; must not exist or be empty (without it, frames are only timed).
    #[arg(long = "out-dir", value_name = "DIR", help_heading = "Output")]
    pub out_dir: Option<PathBuf>,
    /// Also write DIR/frame_00000.exr… with every channel (as render --exr; motion from the path's previous frame).
    #[arg(long, help_heading = "Output")]
    pub exr: bool,
    /// Per-frame times and pass medians as JSON.
    #[arg(long = "profile", alias = "json", value_name = "FILE", help_heading = "Output")]
    pub profile: Option<PathBuf>,
    /// Chrome trace of all frames (opens in Perfetto).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub trace: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
    // After the scene: its Debug heading stays last in --help.
    #[command(flatten)]
    pub renderdoc: super::renderdoc::RenderDocArgs,
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
    #[arg(long, default_value_t = 100_000, value_name = "COUNT", value_parser = clap::builder::RangedI64ValueParser::<usize>::new().range(0..))]
    pub samples: usize,
    /// Mesh sampling method.
    #[arg(long, value_enum, default_value = "blue-noise", value_name = "METHOD")]
    pub sampling: SamplingArg,
    /// Sampling seed.
    #[arg(long, default_value_t = 1, value_name = "SEED", value_parser = clap::value_parser!(u64).range(0..))]
    pub seed: u64,
    /// SPT error threshold in pixels (r_min = e_g / ε).
    #[arg(long, default_value_t = 1.0, value_name = "PIXELS")]
    pub epsilon: f32,
    /// Vertical field of view the pixel threshold refers to, in degrees.
    #[arg(long = "fov-y", default_value_t = 60.0, value_name = "DEGREES")]
    pub fov_y: f32,
    /// Image rows the pixel threshold refers to.
    #[arg(long, default_value_t = 1080, value_name = "PIXELS", value_parser = clap::value_parser!(u32).range(0..))]
    pub rows: u32,
    /// Longest estimated build accepted, in hours: a build estimated to
    /// take longer is refused before it samples (README, "Command line").
    #[arg(long = "max-hours", default_value_t = alpenglow::tools::budget::DEFAULT_MAX_HOURS, value_name = "HOURS", value_parser = parse_hours)]
    pub max_hours: f64,
}

/// `--max-hours`: a positive, finite number of hours.
pub(super) fn parse_hours(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(h) if h.is_finite() && h > 0.0 => Ok(h),
        _ => Err(format!("'{s}' is not a positive number of hours")),
    }
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

pub(super) fn parse_spacing(s: &str) -> Result<(f64, f64), String> {
    let v = parse_numbers(s, "DX[,DY]")?;
    let (dx, dy) = match v.as_slice() {
        [d] => (*d, *d),
        [dx, dy] => (*dx, *dy),
        _ => return Err(format!("'{s}' is not DX or DX,DY")),
    };
    alpenglow::files::check_spacing(glam::DVec2::new(dx, dy)).map_err(|m| format!("'{s}': {m}"))?;
    Ok((dx, dy))
}

/// `NAME=FILE` of `--input-map`.
pub(super) fn parse_input_map(s: &str) -> Result<(usize, PathBuf), String> {
    let names = alpenglow::tools::layers::INPUT_NAMES;
    let (name, file) = s.split_once('=').ok_or_else(|| format!("'{s}': expected NAME=FILE"))?;
    let k = (names.iter().position(|n| *n == name))
        .ok_or_else(|| format!("'{name}': the input maps are {}", names.join(", ")))?;
    if file.is_empty() {
        return Err(format!("'{s}': no file"));
    }
    Ok((k, PathBuf::from(file)))
}

/// `--height-scale`: a finite, positive factor, refused by the parser
/// whether or not a height map is read (a procedural terrain or `synth
/// transition` of procedural fields used to take a NaN, or -1e308, which
/// is -inf as an f32, without a word).
pub(super) fn parse_height_scale(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("{v} must be a finite number > 0")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}

/// `--height-offset`: metres within the heights' range (±1000 km,
/// [`alpenglow::files::MAX_ABS_HEIGHT`]); beyond, every height of a
/// file or an output would be out of range.
pub(super) fn parse_height_offset(s: &str) -> Result<f32, String> {
    let limit = alpenglow::files::MAX_ABS_HEIGHT;
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v.abs() <= limit => Ok(v),
        Ok(v) => Err(format!("{v} m is not within ±{limit} m")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}
