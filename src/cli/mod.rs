//! Subcommands of the `alpenglow` binary.

mod args;
mod bench;
mod dem;
mod errors;
mod exr;
mod fly;
mod layers;
mod lighting;
mod orbit;
mod outputs;
mod points;
mod progress;
mod renderdoc;
mod rig;
mod spt;
mod synth;
mod terrain_spec;
#[cfg(test)]
mod tests;
mod view;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Result};
use glam::DVec2;

use alpenglow::files::load_heightmap;
use alpenglow::tools::profile::{chrome_trace, profile_json};
use alpenglow::{
    validate_size, Camera, Context, ContextOptions, DeviceSelector, FrameProfile, HeightmapOptions, ImportanceFactors,
    LodMode, LodSettings, Scene, Settings, SketchAlignment, TerrainSettings, TerrainView, TexturingMode,
    ValidationReport, ViewSpec,
};
use bench::report_textures;
pub use errors::error_line;

use outputs::Outputs;

use args::{
    AlignArg, Cli, Command, DeviceArgs, FactorArg, LodArg, RenderArgs, SceneArgs, TerrainArgs, TerrainDebugArgs,
    ViewArg,
};

/// Lets every option that takes a value accept a value that starts with a
/// hyphen, in every subcommand: `--near -1`, `--near -inf`, `--fov-y
/// -1e-300`, `--spacing -1,2`, `--time -1:00` are then errors naming the
/// option, not "unexpected argument '-i'" (clap's negative numbers are
/// digits and a point only). File options keep clap's reading (a negative
/// number at most), so `--out --width 3` is still "a value is required for
/// --out", never a file named `--width`.
fn allow_negative_values(command: clap::Command) -> clap::Command {
    use std::any::TypeId;
    command
        .mut_args(|arg| {
            if !arg.get_action().takes_values() || arg.is_positional() {
                return arg;
            }
            let parsed = arg.get_value_parser().type_id();
            let files = [TypeId::of::<PathBuf>(), TypeId::of::<(usize, PathBuf)>()];
            if files.iter().any(|t| parsed == *t) {
                arg.allow_negative_numbers(true)
            } else {
                arg.allow_hyphen_values(true)
            }
        })
        .mut_subcommands(allow_negative_values)
}

/// The parsed command line (negative numbers allowed as values).
fn parse_command_line() -> std::result::Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let command = allow_negative_values(Cli::command()).mut_subcommands(|c| c.after_help(args::ENVIRONMENT_HELP));
    let matches = command.try_get_matches()?;
    Cli::from_arg_matches(&matches)
}

/// Parses the command line and runs the subcommand.
pub fn run() -> Result<ExitCode> {
    let cli = match parse_command_line() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                e.print()?;
                return Ok(ExitCode::SUCCESS);
            }
            let first = errors::clap_error_line(&e);
            bail!("{first} (see alpenglow --help)");
        }
    };
    match cli.command {
        Command::Render(args) => render(args),
        Command::Bench(args) => bench::bench(args),
        Command::Fly(args) => fly::fly(args),
        Command::View(args) => view::view(args),
        Command::Spt(args::SptCommand::Build(args)) => spt::build(args),
        Command::Info(args) => info(args),
        Command::Layers(command) => layers::run(command),
        Command::Synth(command) => synth::synth(command),
        Command::Dem(command) => dem::run(command),
    }
}

fn context(args: &DeviceArgs) -> Result<Context> {
    let device = match &args.device {
        Some(d) => d.parse::<DeviceSelector>()?,
        None => DeviceSelector::Best,
    };
    Context::new(&ContextOptions {
        validation: args.validation,
        device,
    })
    .map_err(renderdoc::explain_device_error)
}

/// Fails when validation reported anything (call after everything Vulkan was dropped).
fn check_validation(report: Option<std::sync::Arc<ValidationReport>>) -> Result<()> {
    if let Some(report) = report {
        if report.set_aside() > 0 {
            log::info!(
                "{} synchronization-validation reports on bindless descriptor-array elements set aside \
                 (false positives of validation layers before 1.3.268, KhronosGroup/Vulkan-ValidationLayers#3450)",
                report.set_aside()
            );
        }
        if report.total() > 0 {
            let first = report.messages().into_iter().next().unwrap_or_default();
            bail!(
                "validation reported {} error(s) and {} warning(s); first: {}",
                report.errors(),
                report.warnings(),
                first.lines().next().unwrap_or("")
            );
        }
    }
    Ok(())
}

/// Warns when `--input-map NAME=FILE` has no effect: no layer of the tree
/// constrains input `k`, or classic texturing uses no layer tree.
fn warn_unused_input_map(args: &SceneArgs, scene: &Scene, k: usize) {
    let name = alpenglow::tools::layers::INPUT_NAMES[k];
    let tree = match &args.terrain.layers {
        Some(path) => format!("the layer tree {}", path.display()),
        None => "the built-in layer tree".to_string(),
    };
    if args.terrain.texturing == args::TexturingArg::Classic {
        log::warn!("--input-map {name} is ignored: --texturing classic uses no layer tree");
    } else if !scene.layers.uses_input(k) {
        log::warn!("--input-map {name} is ignored: no layer of {tree} constrains {name}");
    }
}

fn load_scene(args: &SceneArgs) -> Result<Scene> {
    validate_size(args.width, args.height)?;
    let builtin = args.terrain.terrain.is_none() && args.heightmap.is_none();
    let mut scene = load_terrain(args)?;
    points::add_points(&args.points, &mut scene, builtin)?;
    if let Some(path) = &args.terrain.layers {
        scene.layers = alpenglow::LayerTree::load(path)?;
    }
    for (k, path) in &args.terrain.input_maps {
        let name = alpenglow::tools::layers::INPUT_NAMES[*k];
        if scene.input_maps[*k].is_some() {
            bail!("--input-map {name} is given twice");
        }
        // The grid spans the terrain whatever its spacing: no spacing warning.
        let opts = HeightmapOptions {
            spacing: Some(DVec2::ONE),
            limits: input_limits(&args.terrain),
            ..HeightmapOptions::default()
        };
        scene.input_maps[*k] = Some(load_heightmap(path, &opts)?);
        warn_unused_input_map(args, &scene, *k);
    }
    points::add_vegetation(&args.points, &mut scene, builtin)?;
    Ok(scene)
}

/// The rig of the scene arguments and the views a frame renders.
pub(crate) fn views(args: &SceneArgs) -> Result<(Option<alpenglow::Rig>, Vec<ViewSpec>)> {
    let rig = args.camera.rig(args.width)?;
    let specs = args
        .camera
        .view_specs(rig.as_ref(), (args.width, args.height), args.fov_y)?;
    Ok((rig, specs))
}

/// Render settings of the scene arguments for the views `views`.
fn render_settings(args: &SceneArgs, scene: &Scene, views: &[ViewSpec], readback: bool) -> Result<Settings> {
    let lighting = lighting::lighting(&args.lighting, scene.default_lighting())?;
    lighting.validate()?;
    let mut settings = Settings::new(args.width, args.height);
    settings.views = views.to_vec();
    settings.msaa = args.camera.msaa;
    settings.motion_blur = args.camera.motion_blur()?;
    settings.readback = readback;
    settings.terrain = terrain_settings(&args.terrain, &args.debug)?;
    settings.points = points::splat_settings(&args.points, views, args.fov_y)?;
    settings.texturing = match args.terrain.texturing {
        args::TexturingArg::Classic => TexturingMode::Classic,
        args::TexturingArg::Direct => TexturingMode::Direct,
        args::TexturingArg::Atlas => TexturingMode::Atlas,
    };
    settings.texture_streaming = texture_streaming(args, views)?;
    settings.raster = match args.terrain.raster {
        args::RasterArg::Auto => alpenglow::RasterPath::Auto,
        args::RasterArg::Compute => alpenglow::RasterPath::Compute,
        args::RasterArg::Hardware => alpenglow::RasterPath::Hardware,
    };
    settings.lighting = Some(lighting);
    // Only a terrain is baked: no cache (nor a warning about it) without one.
    settings.cache_dir = scene
        .draw_terrain
        .then(|| lighting::cache_dir(&args.lighting))
        .flatten();
    Ok(settings)
}

/// Atlas streaming for `views` with the tile budget of the arguments.
fn texture_streaming(args: &SceneArgs, views: &[ViewSpec]) -> Result<alpenglow::TextureStreaming> {
    let sizes: Vec<(u32, u32)> = views.iter().map(|v| (v.width, v.height)).collect();
    let mut streaming = alpenglow::TextureStreaming::for_views(&sizes);
    if args.terrain.no_tile_pacing {
        streaming.budget.gpu_time = None;
    }
    Ok(streaming.with_tile_budget(args.terrain.tile_budget)?)
}

fn load_terrain(args: &SceneArgs) -> Result<Scene> {
    if let Some(spec) = &args.terrain.terrain {
        return Ok(Scene::new(spec.generate()?));
    }
    match &args.heightmap {
        Some(path) if is_pyramid(path) => Ok(Scene::from_pyramid_file(
            path,
            args.terrain.resident_side,
            args.terrain.detail_window,
        )?),
        Some(path) => {
            let field = load_heightmap(
                path,
                &HeightmapOptions {
                    scale: args.height_scale,
                    offset: args.height_offset,
                    spacing: args.spacing.map(|(dx, dy)| DVec2::new(dx, dy)),
                    rows: match args.terrain.rows {
                        args::RowsArg::NorthUp => alpenglow::RowOrder::NorthUp,
                        args::RowsArg::SouthUp => alpenglow::RowOrder::SouthUp,
                    },
                    limits: input_limits(&args.terrain),
                },
            )?;
            Ok(Scene::new(field))
        }
        None => Ok(Scene::default_terrain()?),
    }
}

/// Whether `path` names a height pyramid (`.hpyr`).
fn is_pyramid(path: &std::path::Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("hpyr"))
}

/// The input limits of `--max-input-mb`.
fn input_limits(args: &TerrainArgs) -> alpenglow::files::InputLimits {
    alpenglow::files::InputLimits::with_max_file_mib(args.max_input_mb)
}

fn terrain_settings(args: &TerrainArgs, debug: &TerrainDebugArgs) -> Result<TerrainSettings> {
    let off = |f: FactorArg| debug.importance_off.contains(&f);
    let settings = TerrainSettings {
        grid_side: args.grid,
        lod: LodSettings {
            sketch_side: args.sketch,
            snap: args.lod_snap,
            mode: match debug.lod {
                LodArg::Warped => LodMode::Warped,
                LodArg::Uniform => LodMode::Uniform,
            },
            factors: ImportanceFactors {
                distance: !off(FactorArg::Distance),
                frustum: !off(FactorArg::Frustum),
                backface: !off(FactorArg::Backface),
                surface: !off(FactorArg::Surface),
            },
            alignment: match debug.sketch_align {
                AlignArg::View => SketchAlignment::View,
                AlignArg::Axes => SketchAlignment::Axes,
            },
        },
        detail: !args.no_terrain_detail,
        detail_shading: !args.no_detail_shading,
        detail_amplitude: args.detail_amplitude,
        view: match debug.view {
            ViewArg::Shaded => TerrainView::Shaded,
            ViewArg::Importance => TerrainView::Importance,
            ViewArg::DensityRatio => TerrainView::DensityRatio,
            ViewArg::SplitOctave => TerrainView::SplitOctave,
            ViewArg::Wireframe => TerrainView::Wireframe,
        },
        ..TerrainSettings::default()
    };
    settings.validate()?;
    Ok(settings)
}

fn camera(args: &SceneArgs, scene: &Scene) -> Result<Camera> {
    let mut camera = scene.default_camera();
    if let Some(eye) = args.eye {
        camera.eye = eye;
    }
    if let Some(target) = args.target {
        camera.target = target;
    }
    camera.up = args.up;
    camera.fov_y_deg = args.fov_y;
    if let Some(near) = args.near {
        camera.near = near;
    }
    if let Some(far) = args.far {
        camera.far = far;
    }
    camera.validate()?;
    args.camera.place(camera)
}

fn print_profile(device: &str, frame: &FrameProfile) {
    let passes: Vec<String> = frame
        .passes
        .iter()
        .map(|p| format!("{} {:.2}", p.name, p.gpu_ms))
        .collect();
    println!(
        "{device}: frame {:.2} ms GPU, {:.2} ms CPU ({})",
        frame.gpu_ms,
        frame.cpu_ms,
        passes.join(", ")
    );
}

/// Most frames `bench` and `fly` render in one run (55 minutes at 30 fps):
/// their per-frame timings stay in memory until the end, 2–3 KiB a frame
/// (a name and four times per pass), so at most about 300 MiB.
pub(crate) const MAX_FRAMES: u32 = 100_000;

/// Checks `--frames` (1 to [`MAX_FRAMES`]) and `--warmup` (at most [`MAX_FRAMES`]).
fn check_frames(frames: u32, warmup: u32) -> Result<()> {
    if !(1..=MAX_FRAMES).contains(&frames) {
        bail!("--frames {frames} is out of range: must be 1 to {MAX_FRAMES}");
    }
    if warmup > MAX_FRAMES {
        bail!("--warmup {warmup} is out of range: must be at most {MAX_FRAMES}");
    }
    Ok(())
}

/// Frames in a row without a texture tile more before a still render gives
/// up (every frame generates at least one, so this means a fault).
const MAX_SETTLE_FRAMES: u32 = 64;

fn render(args: RenderArgs) -> Result<ExitCode> {
    let (rig, specs) = views(&args.scene)?;
    rig::check_pattern(&args.out, "--out", &specs)?;
    rig::check_pattern(&args.exr, "--exr", &specs)?;
    let mut outputs = Outputs::default();
    for (out, exr) in rig::view_paths(&args.out, &specs)
        .iter()
        .zip(rig::view_paths(&args.exr, &specs))
    {
        outputs.add_image(out.as_deref(), "--out")?;
        outputs.add_exr(exr.as_deref(), "--exr")?;
    }
    outputs.add(args.profile.as_deref(), "--profile")?;
    outputs.add(args.trace.as_deref(), "--trace")?;
    let scene = load_scene(&args.scene)?;
    let cameras = rig::frame_cameras(rig.as_ref(), &camera(&args.scene, &scene)?)?;
    // Frames from the first, one by one up to the captured one (at most MAX_FRAMES).
    let mut capture = renderdoc::FrameCapture::new(&args.renderdoc, MAX_FRAMES.into())?;
    let ctx = context(&args.scene.device)?;
    let report = ctx.validation_report();
    let device = ctx.info().name.clone();
    let (views, profiles, raster, memory) = {
        let settings = render_settings(&args.scene, &scene, &specs, true)?;
        let mut renderer = lighting::renderer(&ctx, &scene, settings)?;
        renderer.set_pipeline_stats(args.pipeline_stats)?;
        let raster = renderer.raster_path();
        if let Some(capture) = &mut capture {
            capture.render_until(&mut renderer, &cameras)?;
        }
        let frame = renderer.render_views_settled(&cameras, MAX_SETTLE_FRAMES)?;
        let views = renderer.read_views(&frame)?;
        let profiles = renderer.finish()?;
        if let Some(stats) = renderer.take_point_stats()?.last() {
            println!("{}", stats.summary());
        }
        let textures = renderer.take_texture_stats()?;
        if let Some(last) = textures.last() {
            let generated: usize = textures.iter().map(|t| t.tiles.generated).sum();
            println!(
                "textures: {} tiles visible, {generated} generated over {} frame(s), {} resident",
                last.tiles.visible,
                textures.len(),
                last.tiles.resident
            );
        }
        (views, profiles, raster, ctx.memory_use())
    };
    drop(ctx);
    check_validation(report)?;
    for images in &views {
        let path = |p: &Option<PathBuf>| p.as_ref().map(|p| rig::view_path(p, &images.name));
        let (w, h) = (images.width, images.height);
        outputs.stage_image(path(&args.out).as_deref(), &images.rgba8, w, h)?;
        outputs.stage(path(&args.exr).as_deref(), || exr::encode_frame_exr(images))?;
    }
    outputs.stage(args.profile.as_deref(), || {
        Ok(profile_json(&device, raster.name(), &profiles, Some(memory))?.into_bytes())
    })?;
    outputs.stage(args.trace.as_deref(), || {
        Ok(chrome_trace(&device, &profiles)?.into_bytes())
    })?;
    renderdoc::report(capture)?;
    outputs.commit()?;
    if let Some(frame) = profiles.last() {
        print_profile(&device, frame);
    }
    Ok(ExitCode::SUCCESS)
}

fn info(args: DeviceArgs) -> Result<ExitCode> {
    let ctx = context(&args)?;
    let report = ctx.validation_report();
    let i = ctx.info().clone();
    drop(ctx);
    check_validation(report)?;
    println!("device:      {} (#{}, {})", i.name, i.index, i.device_type);
    println!("driver:      {} ({})", i.driver_name, i.driver_info);
    println!("vulkan:      {}", i.api_version);
    println!("vendor/id:   {:#06x}/{:#06x}", i.vendor_id, i.device_id);
    println!(
        "timestamps:  {} ns per tick, {}",
        i.timestamp_period_ns,
        if i.calibrated_timestamps {
            "calibrated against the CPU clock"
        } else {
            "not calibrated"
        }
    );
    println!("max image:   {} px per side", i.max_image_dimension_2d);
    println!(
        "memory:      {} device heap{}, at most {} in one allocation",
        alpenglow::tools::budget::format_bytes(i.memory_heap_bytes),
        if i.memory_budget { " (VK_EXT_memory_budget)" } else { "" },
        alpenglow::tools::budget::format_bytes(i.max_allocation_bytes)
    );
    println!(
        "validation:  {}",
        if i.validation {
            "on (with synchronization validation)"
        } else {
            "off"
        }
    );
    println!("features:    {}", i.features.join(", "));
    println!("optional:    {}", i.optional_features.join(", "));
    println!("point size:  up to {} px", i.max_point_size);
    Ok(ExitCode::SUCCESS)
}
