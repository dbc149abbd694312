//! alpenglow: a Vulkan-native, low-level renderer for large outdoor scenes
//! (terrain, point objects, vegetation, physically based sky and sun),
//! headless, for simulators and dataset generation.
//!
//! # The front door
//!
//! Everything a program needs is at the crate root, plus three modules:
//! [`files`] (height maps, point clouds, images, atomic outputs),
//! [`tools`] (the offline tools of the CLI: point trees, terrain synthesis,
//! layer trees from images, budgets, profiles) and [`glam`] (the vector
//! types of every signature). The rest of the crate is private.
//!
//! * a GPU: [`Context`] from [`ContextOptions`] ([`DeviceSelector`],
//!   [`DeviceInfo`], [`ValidationReport`]);
//! * what to draw: [`Scene`], from a height slice ([`Scene::from_heights`]),
//!   a file ([`Scene::from_file`], [`HeightmapOptions`]) or a procedural
//!   model ([`Scene::procedural`], [`ProceduralTerrain`]), with rocks,
//!   vegetation ([`VegetationOptions`]), point objects ([`PointScene`]) and
//!   a layer tree ([`LayerTree`]);
//! * how to draw it: [`Renderer`] with [`Settings`] (the one settings type;
//!   its technique settings [`TerrainSettings`], [`SplatSettings`],
//!   [`TexturingMode`], [`TextureStreaming`], [`ShadowSettings`],
//!   [`MotionBlurSettings`] are here too);
//! * from where: [`Camera`], [`Orbit`], [`CameraPath`], [`ViewSpec`],
//!   [`Rig`], [`Intrinsics`], [`Distortion`];
//! * in which light: [`Lighting`], [`SunPosition`], [`SkyModel`],
//!   [`Exposure`], [`ShadowMode`], [`SkyLightMode`];
//! * what comes back: [`FrameImages`] (colour, HDR and every AOV of a
//!   view) and [`FrameProfile`] (GPU and CPU time per pass;
//!   [`PipelineStats`], [`DeviceMemoryUse`]);
//! * when it goes wrong: [`Error`] (one line naming the parameter, file or
//!   feature at fault) and [`Result`]. The library never panics on input.
//!
//! # Quick start
//!
//! ```no_run
//! use alpenglow::glam::DVec3;
//! use alpenglow::{Camera, Context, ContextOptions, Renderer, Scene, Settings};
//!
//! let ctx = Context::new(&ContextOptions::default())?;
//! let scene = Scene::procedural("ridged", 7, 513, 20.0)?;
//! let mut renderer = Renderer::new(&ctx, &scene, Settings::new(640, 360))?;
//! let camera = Camera {
//!     eye: DVec3::new(2000.0, 1500.0, 900.0),
//!     target: DVec3::new(5000.0, 5000.0, 300.0),
//!     up: DVec3::Z,
//!     fov_y_deg: 60.0,
//!     near: 1.0,
//!     far: 1e5,
//! };
//! let frame = renderer.render_settled(&camera, 8)?;
//! let images = renderer.read(&frame)?;
//! alpenglow::files::write_png_rgba8("frame.png".as_ref(), &images.rgba8, images.width, images.height)?;
//! # Ok::<(), alpenglow::Error>(())
//! ```
//!
//! # Inside
//!
//! Layers, bottom up (each uses only the ones below it): `vulkan` (the
//! only `unsafe` code) → `graph` (render graph: passes declare reads and
//! writes; baking derives barriers) → `view` (cameras, views, the frame's
//! shared targets and uploads) → `surface` (what the techniques share: the
//! ground surface and the surface material) → the techniques (`terrain`,
//! `synthesis`, `texturing`, `lighting`, `points`, `post`) → `renderer`
//! (composition: scenes, frames, outputs) → the CLI (binary only). `io`,
//! `budget` (the memory model), `profile`, `random`, `shaders` and `error`
//! are leaves every layer may use. Every module but `vulkan` is
//! `#[forbid(unsafe_code)]`.

#[forbid(unsafe_code)]
pub(crate) mod budget;
#[forbid(unsafe_code)]
pub(crate) mod error;
#[forbid(unsafe_code)]
pub(crate) mod graph;
#[forbid(unsafe_code)]
pub(crate) mod io;
#[forbid(unsafe_code)]
pub(crate) mod lighting;
#[forbid(unsafe_code)]
pub(crate) mod points;
#[forbid(unsafe_code)]
pub(crate) mod post;
#[forbid(unsafe_code)]
pub(crate) mod profile;
#[forbid(unsafe_code)]
pub(crate) mod random;
#[forbid(unsafe_code)]
pub(crate) mod renderer;
#[forbid(unsafe_code)]
pub(crate) mod shaders;
#[forbid(unsafe_code)]
pub(crate) mod surface;
#[forbid(unsafe_code)]
pub(crate) mod synthesis;
#[forbid(unsafe_code)]
pub(crate) mod terrain;
#[forbid(unsafe_code)]
pub(crate) mod texturing;
#[forbid(unsafe_code)]
pub(crate) mod view;
pub(crate) mod vulkan;

/// Helpers shared by the in-crate white-box tests (validated context, FLIP,
/// goldens, the Jacksboro DEM).
#[cfg(test)]
#[forbid(unsafe_code)]
pub(crate) mod test_support;

#[forbid(unsafe_code)]
mod front;

/// The layering of the crate checked from its `use` lines: no cycle between
/// top-level modules, no technique above the renderer.
#[cfg(test)]
#[forbid(unsafe_code)]
mod module_graph_tests;

#[doc(hidden)]
#[forbid(unsafe_code)]
pub mod bench;
#[forbid(unsafe_code)]
pub mod files;
#[cfg(feature = "hot-reload")]
#[forbid(unsafe_code)]
pub(crate) mod hot_reload;
#[forbid(unsafe_code)]
pub mod tools;

/// The vector and matrix types of every signature (`DVec3`, `DMat4`, …).
pub use glam;

/// The error of every fallible call: one line naming the parameter, file
/// or feature at fault (control characters escaped).
///
/// ```no_run
/// let e = alpenglow::Scene::procedural("perlin", 1, 65, 10.0).unwrap_err();
/// if let alpenglow::Error::InvalidArgument { parameter, .. } = &e {
///     assert_eq!(parameter, "model");
/// }
/// eprintln!("error: {e}");
/// ```
pub use error::Error;
/// `std::result::Result` with [`Error`].
pub use error::Result;

// --- The GPU ---

pub use post::overlay::{OverlayFrame, OverlayMesh, OverlayTexels, OverlayVertex, OVERLAY_ATLAS_SIDE};
/// What the viewer's overlay draws over a presented frame
/// ([`Renderer::set_overlay`]): triangle meshes and font-atlas updates in
/// egui's layout, without depending on egui.
pub use post::present::PresentedImage;
/// The Vulkan instance and device every renderer of a program shares.
///
/// ```no_run
/// use alpenglow::{Context, ContextOptions, DeviceSelector};
/// let ctx = Context::new(&ContextOptions {
///     validation: false,
///     device: "0".parse::<DeviceSelector>()?,
/// })?;
/// println!("{}", ctx.info().name);
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use vulkan::Context;
/// A window's surface and swapchain (any `raw-window-handle` window):
/// frames reach it through [`Renderer::present`] of a renderer built with
/// [`Settings::present_to`]. What `alpenglow view` shows its frames in.
pub use vulkan::Swapchain;
pub use vulkan::{ContextOptions, DeviceInfo, DeviceSelector, ValidationReport};

// --- The scene ---

pub use front::scene::MAX_PROCEDURAL_SIZE;
pub use io::heightmap::{HeightField, HeightmapOptions, RowOrder};
pub use points::scene::{PointLoadOptions, PointObject, PointScene, PointTransform};
pub use points::vegetation::{VegetationOptions, VegetationReport};
pub use renderer::scene::DEFAULT_ROCKS;
/// What is drawn: a height field, its layer tree and input maps, point
/// objects (rocks, vegetation, meshes, point clouds) and the sun.
///
/// ```no_run
/// use alpenglow::{Scene, VegetationOptions};
/// let mut scene = Scene::procedural("hybrid", 3, 257, 30.0)?;
/// scene.add_rocks(200)?;
/// scene.add_vegetation(&VegetationOptions::default())?;
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use renderer::Scene;
pub use surface::layers::LayerTree;
pub use terrain::detail::StreamedGround;
pub use terrain::ground::Ground;
pub use terrain::procedural::{ProceduralTerrain, TerrainModel};

// --- The renderer and its settings ---

/// A submitted frame: pass it to [`Renderer::read`] (and friends) for its images.
pub use graph::FrameOutcome;
pub use lighting::shadows::ShadowSettings;
pub use points::render::{SplatBackend, SplatKernel, SplatMode, SplatPrimitive, SplatSettings, SptError};
pub use post::motion_blur::MotionBlurSettings;
/// The one settings type of a [`Renderer`]: image size or views, anti-aliasing,
/// motion blur, readback, and every technique's settings. `#[non_exhaustive]`:
/// start from [`Settings::new`] and set the public fields.
///
/// ```no_run
/// use alpenglow::{Settings, ShadowSettings, TexturingMode};
/// let mut settings = Settings::new(640, 360);
/// settings.msaa = 4;
/// settings.texturing = TexturingMode::Atlas;
/// settings.terrain.detail = false;
/// settings.shadows = ShadowSettings { atlas_size: 1024, ..ShadowSettings::default() };
/// ```
pub use renderer::RenderSettings as Settings;
/// Renders one scene, frame after frame, into colour, HDR radiance, depth
/// and the simulator AOVs of each view.
///
/// ```no_run
/// use alpenglow::{Camera, Context, ContextOptions, Renderer, Scene, Settings};
/// let ctx = Context::new(&ContextOptions::default())?;
/// let scene = Scene::default_procedural()?;
/// let mut renderer = Renderer::new(&ctx, &scene, Settings::new(320, 240))?;
/// let camera = scene.default_camera();
/// let frame = renderer.render(&camera)?;
/// let images = renderer.read(&frame)?;
/// assert_eq!(images.rgba8.len(), 320 * 240 * 4);
/// let profiles = renderer.finish()?;
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use renderer::Renderer;
pub use surface::gpu_layout::TexturingMode;
pub use terrain::geometry_image::{TerrainSettings, TerrainView};
pub use terrain::lod::{
    ImportanceFactors, LodMode, LodSettings, ANCHORED_SNAP as ANCHORED_LOD_SNAP, DEFAULT_SNAP as DEFAULT_LOD_SNAP,
};
pub use terrain::sketch_map::SketchAlignment;
pub use terrain::visibility::RasterPath;
pub use texturing::generation::TextureStreaming;
pub use texturing::streaming::MAX_TILE_BUDGET;

// --- Cameras, views and rigs ---

/// Several views rendered in one frame, each with its pose relative to the
/// rig's camera, its size, intrinsics and distortion.
///
/// ```no_run
/// use alpenglow::{Rig, Scene, Settings};
/// let scene = Scene::default_procedural()?;
/// let rig = Rig::ring6(320);
/// let settings = Settings::for_views(rig.specs((320, 240))?);
/// let cameras = rig.cameras(&scene.default_camera())?;
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use renderer::Rig;
pub use renderer::{check_view, validate_size, MAX_IMAGE_SIDE};
pub use renderer::{ViewSpec, MAX_VIEWS};
pub use view::camera_path::{CameraPath, Orbit, DEFAULT_START_ANGLE_DEG};
pub use view::lens::{Distortion, Intrinsics};
/// The views of a [`Rig`]: pose relative to the rig's camera (or fixed in
/// the world), lens and distortion, size and clip planes.
pub use view::rig::{RigLens, RigPose, RigView};
/// A pinhole camera: eye, target, up, vertical field of view, near and far
/// planes (metres, +z up).
///
/// ```no_run
/// use alpenglow::glam::{DMat4, DVec3};
/// use alpenglow::Camera;
/// let camera = Camera {
///     eye: DVec3::new(0.0, 0.0, 500.0),
///     target: DVec3::new(1000.0, 1000.0, 200.0),
///     up: DVec3::Z,
///     fov_y_deg: 60.0,
///     near: 1.0,
///     far: 1e5,
/// };
/// camera.validate()?;
/// let from_pose = Camera::from_pose(DMat4::IDENTITY, 60.0, 1.0, 1e5)?;
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use view::Camera;

// --- Lighting ---

/// The lighting of a frame: sun, sky model, exposure, shadows, sky light
/// and aerial perspective.
///
/// ```no_run
/// use alpenglow::{Exposure, Lighting, SunPosition};
/// let lighting = Lighting {
///     sun: SunPosition::Angles { elevation_deg: 12.0, azimuth_deg: 250.0 },
///     exposure: Exposure::Auto,
///     ..Lighting::default()
/// };
/// lighting.validate()?;
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub use view::Lighting;
pub use view::{Exposure, ShadowMode, SkyLightMode, SkyModel, SunDisc, SunPosition};

// --- What comes back ---

pub use points::render::PointFrameStats;
pub use profile::{DeviceMemoryUse, FrameProfile, PipelineStats};
/// One rendered view in host memory: tone-mapped sRGB, HDR radiance,
/// view-space depth and the simulator AOVs (normal, class, instance,
/// motion, visibility, splat weight). Row 0 is the top of the image.
///
/// ```no_run
/// # fn show(renderer: &mut alpenglow::Renderer, camera: &alpenglow::Camera) -> alpenglow::Result<()> {
/// let frame = renderer.render(camera)?;
/// let images: alpenglow::FrameImages = renderer.read(&frame)?;
/// let centre = (images.height / 2 * images.width + images.width / 2) as usize;
/// println!("depth at the centre: {} m, class {}", images.depth[centre], images.class[centre]);
/// # Ok(()) }
/// ```
pub use renderer::FrameImages;
/// Frames read without blocking: [`Renderer::submit`] returns a [`Ticket`];
/// [`Renderer::try_read`] (never blocks) and [`Renderer::wait`] hand out a
/// [`FrameData`] borrowing the mapped readback slot: per view a
/// [`ViewData`], per requested [`Output`] a [`Plane`] (bytes, [`Element`]
/// format) with copy-into helpers for caller-owned buffers. The ring has
/// [`Settings::readback_slots`] slots; a ticket whose slot was reused is an
/// error, never stale data.
///
/// ```no_run
/// # fn drive(renderer: &mut alpenglow::Renderer, path: &[alpenglow::Camera]) -> alpenglow::Result<()> {
/// use alpenglow::Output;
/// let mut depth = vec![0f32; 320 * 240];
/// let mut previous = None;
/// for camera in path {
///     let ticket = renderer.submit(std::slice::from_ref(camera))?;
///     // The GPU renders this frame while the previous one is consumed.
///     if let Some(earlier) = previous.replace(ticket) {
///         let frame = renderer.wait(earlier)?;
///         frame.view(0)?.plane(Output::Depth)?.copy_into_f32(&mut depth)?;
///     }
/// }
/// # Ok(()) }
/// ```
pub use renderer::Ticket;
pub use renderer::{Element, FrameData, Output, Outputs, Plane, ViewData, MAX_READBACK_SLOTS};
pub use texturing::stats::{TextureFrameStats, TextureSummary};
/// The semantic classes of [`FrameImages::class`]: terrain with a known
/// surface layer k is `CLASS_LAYER_BASE + k`.
pub use view::aov::{CLASS_LAYER_BASE, CLASS_ROCK, CLASS_SCAN, CLASS_SKY, CLASS_TERRAIN, CLASS_VEGETATION};
