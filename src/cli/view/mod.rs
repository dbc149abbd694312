//! `alpenglow view`: the scene live in a window (winit: X11 and Wayland),
//! through a fly camera. The frames are the renderer's, presented through
//! a swapchain the render graph imports ([`alpenglow::Swapchain`]); the
//! render size is `--width`×`--height` whatever the window's (letterboxed
//! into it), so a frame on screen is the frame `render` writes.
//!
//! Keys: WASD move, E/Space up, Q/C down, Shift 4× faster; mouse look
//! with a button held; the wheel scales the speed; arrows move the sun
//! (up/down: elevation, left/right: azimuth); V cycles a rig's views; F12
//! writes PNG, EXR, profile and trace of the frame on screen; F11 has
//! RenderDoc capture the next frame (under RenderDoc or with
//! `--renderdoc`); F1 hides the
//! overlay ([`hud`]: per-pass GPU times, frame-time plot, statistics,
//! switches); Esc quits.
//!
//! Scripted (tests, recordings): `--frames N` renders N frames and exits,
//! with a fixed 1/30 s step per frame so a run is reproducible; `--input
//! EVENTS` replays key and mouse events ([`input`]); `--screenshot OUT.png`
//! writes the last frame (as `render --out` would, no overlay). At exit
//! the camera is printed as `render` options.

mod captures;
mod fly_camera;
mod hud;
mod input;
#[cfg(feature = "hot-reload")]
mod shader_reload;

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{anyhow, Result};
use clap::Args;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{DeviceEvent, DeviceId, ElementState, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::PhysicalKey;
use winit::window::{Window, WindowId};

use alpenglow::tools::renderdoc::RenderDocCapture;
use alpenglow::{Context, Lighting, Renderer, Scene, SunPosition, Swapchain};

use super::args::SceneArgs;
use fly_camera::FlyCamera;
use input::{Held, Input, Key, Script};

/// The time step of a scripted run (`--frames`), seconds.
const SCRIPTED_STEP_S: f64 = 1.0 / 30.0;
/// Degrees the sun moves per arrow-key press.
const SUN_STEP_DEG: f32 = 2.0;

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Render COUNT frames, then exit (scripted runs; 1–100000). Without
    /// it the viewer runs until the window is closed or Esc.
    #[arg(long, value_name = "COUNT", value_parser = clap::value_parser!(u32).range(1..=100_000), help_heading = "Viewer")]
    pub frames: Option<u32>,
    /// Replay key and mouse events: one `FRAME key NAME [down|up]`,
    /// `FRAME mouse DX DY` or `FRAME wheel NOTCHES` per line.
    #[arg(long, value_name = "EVENTS", help_heading = "Viewer")]
    pub input: Option<PathBuf>,
    /// Write the last frame (tone-mapped sRGB, without the overlay) as PNG.
    #[arg(long, value_name = "OUT.png", help_heading = "Viewer")]
    pub screenshot: Option<PathBuf>,
    /// Where F12 writes its captures (capture_FRAME.png, .exr, .json, .trace.json).
    #[arg(
        long = "capture-dir",
        default_value = ".",
        value_name = "DIR",
        help_heading = "Viewer"
    )]
    pub capture_dir: PathBuf,
    /// Load RenderDoc's library (default: librenderdoc.so from the linker's
    /// path or the usual install places) so F11 can capture; not needed
    /// when the viewer runs under RenderDoc.
    #[arg(long, value_name = "PATH", num_args = 0..=1, help_heading = "Viewer")]
    pub renderdoc: Option<Option<PathBuf>>,
    /// Present as fast as frames come (mailbox or immediate) instead of vsync.
    #[arg(long = "no-vsync", help_heading = "Viewer")]
    pub no_vsync: bool,
    /// Watch DIR and hot-reload its shaders (default: ./glsl, else the
    /// source tree's).
    #[cfg(feature = "hot-reload")]
    #[arg(long, value_name = "DIR", help_heading = "Viewer")]
    pub glsl: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
}

/// Runs the viewer.
pub fn view(args: ViewArgs) -> Result<ExitCode> {
    super::check_frames(args.frames.unwrap_or(1), 0)?;
    let script = match &args.input {
        Some(path) => Script::load(path)?,
        None => Script::default(),
    };
    let (rig, specs) = super::views(&args.scene)?;
    let mut outputs = super::outputs::Outputs::default();
    outputs.add_image(args.screenshot.as_deref(), "--screenshot")?;
    let scene = super::load_scene(&args.scene)?;
    let camera = super::camera(&args.scene, &scene)?;
    // Every view of a rig renders each frame (one is shown); a rig's
    // views follow the fly camera as they follow `--eye`.
    super::rig::frame_cameras(rig.as_ref(), &camera)?;
    let settings = super::render_settings(&args.scene, &scene, &specs, true)?;
    // RenderDoc hooks Vulkan only when loaded before the instance.
    let renderdoc = match &args.renderdoc {
        Some(path) => Some(RenderDocCapture::load(path.as_deref())?),
        None => RenderDocCapture::attach(),
    };
    let renderdoc = renderdoc.map(|mut r| {
        // Its own capture keys (F12, Print Screen) would clash with the viewer's.
        r.disable_capture_keys();
        r
    });
    let ctx = super::context(&args.scene.device)?;
    let report = ctx.validation_report();
    #[cfg(feature = "hot-reload")]
    let shaders = shader_reload::ShaderReload::new(&ctx, args.glsl.as_deref())?;
    let event_loop = EventLoop::new().map_err(|e| anyhow!("the viewer needs a display (X11 or Wayland): {e}"))?;
    let switches = hud::Switches {
        shadows: settings.lighting.map(|l| l.shadows).unwrap_or_default(),
        sky_light: settings.lighting.map(|l| l.sky_light).unwrap_or_default(),
        sky: settings.lighting.map(|l| l.sky).unwrap_or_default(),
        terrain_view: settings.terrain.view,
        texturing: settings.texturing,
        image: alpenglow::PresentedImage::Color,
    };
    let mut app = Viewer {
        state: None,
        setup: Some(Setup { ctx, scene, settings }),
        switches,
        renderdoc,
        renderdoc_pending: None,
        notice: None,
        shader_error: None,
        #[cfg(feature = "hot-reload")]
        shaders,
        textures_line: None,
        points_line: None,
        rig,
        fly: FlyCamera::new(camera),
        held: Held::default(),
        looking: false,
        script,
        frames: args.frames.map(u64::from),
        rendered: 0,
        shown: 0,
        vsync: !args.no_vsync,
        last_time: None,
        error: None,
        captures: captures::Captures::new(args.capture_dir.clone(), args.screenshot.clone()),
        size: (args.scene.width, args.scene.height),
    };
    let run = event_loop.run_app(&mut app);
    let sun = app.state.as_ref().map(|s| sun_options(s.renderer.lighting()));
    let Viewer {
        state,
        error,
        fly,
        captures,
        ..
    } = app;
    let screenshot = match state {
        Some(state) => state.finish(captures, outputs),
        None => Ok(()),
    };
    // Everything Vulkan is gone: the validation report is complete.
    check_frames_ran(error, run)?;
    screenshot?;
    super::check_validation(report)?;
    println!("camera: {}", fly.options());
    if let Some(sun) = sun {
        println!("sun: {sun}");
    }
    Ok(ExitCode::SUCCESS)
}

/// The first error of the run: the viewer's own, else the event loop's.
fn check_frames_ran(error: Option<anyhow::Error>, run: Result<(), winit::error::EventLoopError>) -> Result<()> {
    if let Some(e) = error {
        return Err(e);
    }
    run.map_err(|e| anyhow!("the window's event loop failed: {e}"))
}

/// What the window needs before its first frame.
struct Setup {
    ctx: Context,
    scene: Scene,
    settings: alpenglow::Settings,
}

/// The window and what draws into it (dropped in this order: renderer,
/// swapchain, window).
struct Live {
    renderer: Renderer,
    swapchain: Swapchain,
    hud: hud::Hud,
    window: Window,
    /// What the renderer was built from (rebuilt when a switch needs it).
    setup: Setup,
}

impl Live {
    /// A new renderer from the setup with `change` applied to its settings,
    /// keeping the lighting.
    fn rebuild(&mut self, change: impl FnOnce(&mut alpenglow::Settings)) -> Result<()> {
        let lighting = *self.renderer.lighting();
        change(&mut self.setup.settings);
        self.setup.settings.lighting = Some(lighting);
        let settings = self.setup.settings.clone();
        let image = self.renderer.presented_image();
        self.renderer = build_renderer(&self.setup.ctx, &self.setup.scene, settings)?;
        self.renderer.set_presented_image(image);
        Ok(())
    }
}

/// A renderer presenting to the swapchain `settings` name.
fn build_renderer(ctx: &Context, scene: &Scene, settings: alpenglow::Settings) -> Result<Renderer> {
    let mut renderer = super::lighting::renderer(ctx, scene, settings)?;
    renderer.set_profile_history(captures::PROFILE_HISTORY);
    Ok(renderer)
}

impl Live {
    /// Waits for the GPU and writes the screenshot of the last frame.
    fn finish(mut self, captures: captures::Captures, outputs: super::outputs::Outputs) -> Result<()> {
        captures.screenshot(&mut self.renderer, outputs)?;
        drop(self.renderer);
        drop(self.swapchain);
        drop(self.hud);
        drop(self.window);
        drop(self.setup);
        Ok(())
    }
}

struct Viewer {
    state: Option<Live>,
    setup: Option<Setup>,
    switches: hud::Switches,
    /// RenderDoc's in-application API, when loaded or attached (F11).
    renderdoc: Option<RenderDocCapture>,
    /// The capture count when F11 was pressed, until the capture is written.
    renderdoc_pending: Option<u32>,
    /// A message the overlay shows (a switch the renderer refused).
    notice: Option<String>,
    /// The compile errors of the last shader reload (feature `hot-reload`),
    /// one line each, while the last good shaders keep running.
    shader_error: Option<String>,
    #[cfg(feature = "hot-reload")]
    shaders: shader_reload::ShaderReload,
    /// The last tile-streaming and point statistics.
    textures_line: Option<String>,
    points_line: Option<String>,
    rig: Option<alpenglow::Rig>,
    fly: FlyCamera,
    held: Held,
    /// A mouse button is down: motion turns the camera.
    looking: bool,
    script: Script,
    /// Frames to render (scripted), or None: until closed.
    frames: Option<u64>,
    rendered: u64,
    shown: usize,
    vsync: bool,
    last_time: Option<Instant>,
    error: Option<anyhow::Error>,
    captures: captures::Captures,
    /// The render size (the window's initial inner size).
    size: (u32, u32),
}

impl Viewer {
    /// Opens the window and its swapchain and builds the renderer.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(setup) = self.setup.take() else {
            return Ok(());
        };
        let attributes = Window::default_attributes()
            .with_title("alpenglow")
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = event_loop.create_window(attributes)?;
        let size = window.inner_size();
        let swapchain = Swapchain::new(&setup.ctx, &window, (size.width, size.height), self.vsync)?;
        let mut setup = setup;
        setup.settings.present_to(&swapchain);
        let renderer = build_renderer(&setup.ctx, &setup.scene, setup.settings.clone())?;
        window.request_redraw();
        self.state = Some(Live {
            renderer,
            swapchain,
            hud: hud::Hud::new(&window),
            window,
            setup,
        });
        Ok(())
    }

    fn handle(&mut self, input: Input, event_loop: &ActiveEventLoop) {
        match input {
            Input::Key { key, pressed } => {
                self.held.set(key, pressed);
                if pressed {
                    self.pressed(key, event_loop);
                }
            }
            Input::Look { dx, dy } => self.fly.turn(dx, dy),
            Input::Wheel(notches) => self.fly.scroll(notches),
            Input::Resize { width, height } => {
                if let Some(state) = &self.state {
                    // The window manager (if any) answers with a Resized event.
                    let _ = state.window.request_inner_size(PhysicalSize::new(width, height));
                }
            }
        }
    }

    /// What a key press does at once (held keys move the camera each frame).
    fn pressed(&mut self, key: Key, event_loop: &ActiveEventLoop) {
        let Some(state) = &mut self.state else { return };
        let sun = |d_elevation: f32, d_azimuth: f32| move |l: Lighting| move_sun(l, d_elevation, d_azimuth);
        let result = match key {
            Key::Escape => {
                event_loop.exit();
                Ok(())
            }
            Key::V => {
                self.shown = (self.shown + 1) % state.renderer.views().len();
                Ok(())
            }
            Key::G => {
                let all = alpenglow::PresentedImage::ALL;
                let at = all.iter().position(|i| *i == self.switches.image).unwrap_or(0);
                self.switches.image = all[(at + 1) % all.len()];
                state.renderer.set_presented_image(self.switches.image);
                Ok(())
            }
            Key::Up => set_lighting(&mut state.renderer, sun(SUN_STEP_DEG, 0.0)),
            Key::Down => set_lighting(&mut state.renderer, sun(-SUN_STEP_DEG, 0.0)),
            Key::Left => set_lighting(&mut state.renderer, sun(0.0, -SUN_STEP_DEG)),
            Key::Right => set_lighting(&mut state.renderer, sun(0.0, SUN_STEP_DEG)),
            Key::F12 => {
                self.captures.request();
                Ok(())
            }
            Key::F11 => match &mut self.renderdoc {
                Some(rdoc) => {
                    rdoc.trigger_capture();
                    self.renderdoc_pending = Some(rdoc.captures());
                    Ok(())
                }
                None => Err(anyhow!(
                    "F11: RenderDoc is not loaded (run under renderdoccmd or qrenderdoc, or pass --renderdoc)"
                )),
            },
            Key::F1 => {
                state.hud.visible = !state.hud.visible;
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            log::warn!("{e}");
        }
    }

    /// Renders and presents one frame.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        for input in self.script.due(self.rendered) {
            self.handle(input, event_loop);
        }
        let now = Instant::now();
        let dt = match (self.frames, self.last_time) {
            (Some(_), _) => SCRIPTED_STEP_S,
            (None, Some(last)) => now.duration_since(last).as_secs_f64().min(0.25),
            (None, None) => 0.0,
        };
        self.last_time = Some(now);
        self.fly.advance(self.held.motion(), dt);
        #[cfg(feature = "hot-reload")]
        self.shaders.frame(self.state.as_mut(), &mut self.shader_error);
        let cameras = super::rig::frame_cameras(self.rig.as_ref(), &self.fly.camera())?;
        self.overlay()?;
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        let Some(outcome) = state.renderer.present(&cameras, &mut state.swapchain, self.shown)? else {
            return Ok(()); // minimised
        };
        self.rendered += 1;
        self.captures.frame_done(&mut state.renderer, outcome, self.shown)?;
        if self.frames.is_some_and(|n| self.rendered >= n) {
            event_loop.exit();
        } else {
            state.window.request_redraw();
        }
        self.report_renderdoc();
        Ok(())
    }

    /// Prints the RenderDoc capture F11 asked for once RenderDoc wrote it.
    fn report_renderdoc(&mut self) {
        let (Some(rdoc), Some(before)) = (&self.renderdoc, self.renderdoc_pending) else {
            return;
        };
        if rdoc.captures() > before {
            self.renderdoc_pending = None;
            let file = rdoc.latest_capture().map(|p| p.display().to_string());
            let line = format!("F11: RenderDoc capture {}", file.unwrap_or_default());
            println!("{line}");
            self.notice = Some(line);
        }
    }

    /// Builds this frame's overlay and applies the switches it changed.
    fn overlay(&mut self) -> Result<()> {
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        let renderer = &mut state.renderer;
        let textures = renderer.take_texture_stats()?.last().map(|t| {
            format!(
                "textures: {} tiles visible, {} generated, {} resident ({:.0} % hits)",
                t.tiles.visible,
                t.tiles.generated,
                t.tiles.resident,
                t.hit_rate * 100.0
            )
        });
        let points = renderer.take_completed_point_stats()?.last().map(|p| p.summary());
        self.points_line = points.or(self.points_line.take());
        self.textures_line = textures.or(self.textures_line.take());
        let views = renderer.views();
        let device = renderer.context().info().name.clone();
        let stats = hud::HudStats {
            device: &device,
            raster: renderer.raster_path().name(),
            profiles: &self.captures.profiles,
            memory: renderer.context().memory_use(),
            textures: self.textures_line.clone(),
            points: self.points_line.clone(),
            view: (self.shown, views.len(), views[self.shown].name.as_str()),
            notice: self.notice.as_deref().or(self.shader_error.as_deref()),
        };
        let mut switches = self.switches;
        let overlay = state.hud.build(&state.window, &stats, &mut switches);
        state.renderer.set_overlay(overlay)?;
        if switches != self.switches {
            self.notice = apply_switches(state, self.switches, switches)
                .err()
                .map(|e| format!("{e:#}"));
            self.switches = switches;
        }
        Ok(())
    }

    fn fail(&mut self, error: anyhow::Error, event_loop: &ActiveEventLoop) {
        self.error.get_or_insert(error);
        event_loop.exit();
    }
}

/// Applies the switches that changed from `old` to `new`: lighting at
/// once, the terrain view and texturing by rebuilding the renderer. An
/// error (a mode the renderer was not built for) leaves the frame as it was.
fn apply_switches(state: &mut Live, old: hud::Switches, new: hud::Switches) -> Result<()> {
    state.renderer.set_presented_image(new.image);
    if (old.shadows, old.sky_light, old.sky) != (new.shadows, new.sky_light, new.sky) {
        set_lighting(&mut state.renderer, |mut l| {
            (l.shadows, l.sky_light, l.sky) = (new.shadows, new.sky_light, new.sky);
            l
        })?;
    }
    if (old.terrain_view, old.texturing) != (new.terrain_view, new.texturing) {
        state.rebuild(|s| {
            s.terrain.view = new.terrain_view;
            s.texturing = new.texturing;
        })?;
    }
    Ok(())
}

/// Applies `change` to the renderer's lighting.
fn set_lighting(renderer: &mut Renderer, change: impl FnOnce(Lighting) -> Lighting) -> Result<()> {
    let lighting = change(*renderer.lighting());
    renderer.set_lighting(lighting)?;
    Ok(())
}

/// The sun of `lighting` as `render` options.
fn sun_options(lighting: &Lighting) -> String {
    match move_sun(*lighting, 0.0, 0.0).sun {
        SunPosition::Angles {
            elevation_deg,
            azimuth_deg,
        } => format!("--sun-elevation {elevation_deg:.4} --sun-azimuth {azimuth_deg:.4}"),
        SunPosition::Direction(_) => String::new(),
    }
}

/// The sun moved by `d_elevation` and `d_azimuth` degrees (elevation kept
/// within −10°..90°).
fn move_sun(mut lighting: Lighting, d_elevation: f32, d_azimuth: f32) -> Lighting {
    let (elevation, azimuth) = match lighting.sun {
        SunPosition::Angles {
            elevation_deg,
            azimuth_deg,
        } => (elevation_deg, azimuth_deg),
        SunPosition::Direction(d) => {
            let d = d.normalize_or_zero();
            (d.z.clamp(-1.0, 1.0).asin().to_degrees(), d.x.atan2(d.y).to_degrees())
        }
    };
    lighting.sun = SunPosition::Angles {
        elevation_deg: (elevation + d_elevation).clamp(-10.0, 90.0),
        azimuth_deg: (azimuth + d_azimuth).rem_euclid(360.0),
    };
    lighting
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if let Err(e) = self.open(event_loop) {
            self.fail(e, event_loop);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if let Some(state) = &mut self.state {
            let input = matches!(
                event,
                WindowEvent::KeyboardInput { .. } | WindowEvent::MouseInput { .. } | WindowEvent::MouseWheel { .. }
            );
            if state.hud.on_event(&state.window, &event) && input {
                return;
            }
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(state) = &mut self.state {
                    state.swapchain.resize(size.width, size.height);
                    state.window.request_redraw();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if !event.repeat => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if let Some(key) = Key::from_winit(code) {
                        let pressed = event.state == ElementState::Pressed;
                        self.handle(Input::Key { key, pressed }, event_loop);
                    }
                }
            }
            WindowEvent::MouseInput { state, .. } => self.looking = state == ElementState::Pressed,
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.handle(Input::Wheel(notches), event_loop);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame(event_loop) {
                    self.fail(e, event_loop);
                }
            }
            _ => {}
        }
    }

    fn device_event(&mut self, event_loop: &ActiveEventLoop, _: DeviceId, event: DeviceEvent) {
        if let DeviceEvent::MouseMotion { delta: (dx, dy) } = event {
            if self.looking {
                self.handle(Input::Look { dx, dy }, event_loop);
            }
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        // A live viewer draws continuously (tiles stream in, the profile
        // moves); a minimised window asks again when it is restored.
        if let Some(state) = &self.state {
            if !state.swapchain.is_minimised() {
                state.window.request_redraw();
            }
        }
    }
}
