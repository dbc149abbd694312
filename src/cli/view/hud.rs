//! The viewer's overlay (egui): the last completed frame's GPU time per
//! pass as bars, a rolling plot of the frame time, the CPU `prepare.*`
//! stages, tile-streaming and point statistics, device memory, and
//! switches for the debug views, texturing, lighting and shadow modes.
//! egui builds and tessellates it here; the renderer draws the meshes with
//! its own overlay passes ([`alpenglow::OverlayFrame`]). F1 hides it.

use std::collections::VecDeque;

use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};
use winit::event::WindowEvent;
use winit::window::Window;

use alpenglow::{
    DeviceMemoryUse, FrameProfile, OverlayFrame, OverlayMesh, OverlayTexels, OverlayVertex, PresentedImage, ShadowMode,
    SkyLightMode, SkyModel, TerrainView, TexturingMode,
};

/// Frame times the plot shows.
const PLOT_FRAMES: usize = 240;

/// What the overlay shows besides the profiles.
pub struct HudStats<'a> {
    pub device: &'a str,
    pub raster: &'a str,
    pub profiles: &'a VecDeque<FrameProfile>,
    pub memory: DeviceMemoryUse,
    pub textures: Option<String>,
    pub points: Option<String>,
    pub view: (usize, usize, &'a str),
    pub notice: Option<&'a str>,
}

/// The switches; the viewer applies what changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Switches {
    pub shadows: ShadowMode,
    pub sky_light: SkyLightMode,
    pub sky: SkyModel,
    /// Rebuild the renderer when these change.
    pub terrain_view: TerrainView,
    pub texturing: TexturingMode,
    /// The colour or an AOV's debug view (at once).
    pub image: PresentedImage,
}

pub struct Hud {
    ctx: egui::Context,
    input: egui_winit::State,
    pub visible: bool,
}

impl Hud {
    pub fn new(window: &Window) -> Hud {
        let ctx = egui::Context::default();
        let scale = Some(window.scale_factor() as f32);
        let side = Some(alpenglow::OVERLAY_ATLAS_SIDE as usize);
        let input = egui_winit::State::new(ctx.clone(), egui::ViewportId::ROOT, window, scale, None, side);
        Hud {
            ctx,
            input,
            visible: true,
        }
    }

    /// Gives `event` to egui; true when egui used it (a click on a switch).
    pub fn on_event(&mut self, window: &Window, event: &WindowEvent) -> bool {
        self.visible && self.input.on_window_event(window, event).consumed
    }

    /// Builds the overlay of this frame; changes `switches` as clicked.
    pub fn build(&mut self, window: &Window, stats: &HudStats<'_>, switches: &mut Switches) -> OverlayFrame {
        let raw = self.input.take_egui_input(window);
        let visible = self.visible;
        let output = self.ctx.run(raw, |ctx| {
            if visible {
                panel(ctx, stats, switches);
            }
        });
        self.input.handle_platform_output(window, output.platform_output);
        let ppp = output.pixels_per_point;
        let primitives = self.ctx.tessellate(output.shapes, ppp);
        OverlayFrame {
            pixels_per_point: ppp,
            meshes: primitives.into_iter().filter_map(mesh).collect(),
            atlas: output.textures_delta.set.into_iter().filter_map(texels).collect(),
        }
    }
}

fn mesh(primitive: egui::ClippedPrimitive) -> Option<OverlayMesh> {
    let egui::epaint::Primitive::Mesh(mesh) = primitive.primitive else {
        return None;
    };
    // Only the font atlas is a texture of the overlay.
    if mesh.texture_id != egui::TextureId::default() {
        return None;
    }
    let clip = primitive.clip_rect;
    Some(OverlayMesh {
        clip: [clip.min.x, clip.min.y, clip.max.x, clip.max.y],
        vertices: (mesh.vertices.iter())
            .map(|v| OverlayVertex {
                position: [v.pos.x, v.pos.y],
                uv: [v.uv.x, v.uv.y],
                color: v.color.to_array(),
            })
            .collect(),
        indices: mesh.indices,
    })
}

fn texels((id, delta): (egui::TextureId, egui::epaint::ImageDelta)) -> Option<OverlayTexels> {
    if id != egui::TextureId::default() {
        return None;
    }
    let (size, pixels): ([usize; 2], Vec<Color32>) = match &delta.image {
        egui::ImageData::Color(image) => (image.size, image.pixels.clone()),
        egui::ImageData::Font(font) => (font.size, font.srgba_pixels(None).collect()),
    };
    Some(OverlayTexels {
        at: delta.pos.map(|p| [p[0] as u32, p[1] as u32]),
        size: [size[0] as u32, size[1] as u32],
        rgba: pixels.iter().flat_map(|c| c.to_array()).collect(),
    })
}

fn panel(ctx: &egui::Context, stats: &HudStats<'_>, switches: &mut Switches) {
    egui::Window::new("alpenglow")
        .default_pos(Pos2::new(8.0, 8.0))
        .default_width(330.0)
        .resizable(false)
        .show(ctx, |ui| {
            ui.label(format!("{} — {} raster", stats.device, stats.raster));
            let (shown, views, name) = stats.view;
            if views > 1 {
                ui.label(format!("view {}/{views}: {name} (V cycles)", shown + 1));
            }
            if let Some(notice) = stats.notice {
                ui.colored_label(Color32::from_rgb(255, 120, 90), notice);
            }
            frame_times(ui, stats.profiles);
            if let Some(last) = stats.profiles.back() {
                egui::CollapsingHeader::new("GPU passes")
                    .default_open(true)
                    .show(ui, |ui| {
                        egui::ScrollArea::vertical()
                            .max_height(220.0)
                            .show(ui, |ui| pass_bars(ui, last));
                    });
                egui::CollapsingHeader::new("CPU prepare").show(ui, |ui| {
                    for s in &last.prepare {
                        ui.label(format!("{:<22} {:>7.2} ms", s.name, s.cpu_ms));
                    }
                });
            }
            egui::CollapsingHeader::new("Streaming and memory").show(ui, |ui| {
                ui.label(stats.textures.as_deref().unwrap_or("textures: no atlas"));
                ui.label(stats.points.as_deref().unwrap_or("points: none"));
                let mib = |b: u64| b as f64 / (1 << 20) as f64;
                ui.label(format!(
                    "device memory: {:.0} MiB allocated, {:.0} MiB reserved",
                    mib(stats.memory.allocated_bytes),
                    mib(stats.memory.reserved_bytes)
                ));
                if let (Some(used), Some(budget)) = (stats.memory.heap_usage_bytes, stats.memory.heap_budget_bytes) {
                    ui.label(format!("device heap: {:.0} of {:.0} MiB", mib(used), mib(budget)));
                }
            });
            egui::CollapsingHeader::new("Switches")
                .default_open(true)
                .show(ui, |ui| switch_rows(ui, switches));
        });
}

/// The last frame's times and the rolling plot of GPU (orange) and CPU
/// (blue) frame times.
fn frame_times(ui: &mut egui::Ui, profiles: &VecDeque<FrameProfile>) {
    let Some(last) = profiles.back() else {
        ui.label("waiting for the first frame…");
        return;
    };
    ui.label(format!(
        "frame {}: GPU {:.2} ms, CPU {:.2} ms",
        last.frame, last.gpu_ms, last.cpu_ms
    ));
    let recent: Vec<&FrameProfile> = profiles.iter().rev().take(PLOT_FRAMES).rev().collect();
    let top = recent.iter().map(|p| p.gpu_ms.max(p.cpu_ms)).fold(1.0f64, f64::max) * 1.1;
    let (response, painter) = ui.allocate_painter(Vec2::new(310.0, 70.0), Sense::hover());
    let r = response.rect;
    painter.rect_filled(r, 2.0, Color32::from_black_alpha(140));
    // Newest at the right; at least a minute at 1 fps across the plot.
    let span = recent.len().clamp(60, PLOT_FRAMES) - 1;
    let n = recent.len();
    let point = |k: usize, ms: f64| {
        let x = r.right() - r.width() * (n - 1 - k) as f32 / span as f32;
        Pos2::new(x, r.bottom() - r.height() * (ms / top) as f32)
    };
    for (pick, color) in [
        (
            &(|p: &FrameProfile| p.cpu_ms) as &dyn Fn(&FrameProfile) -> f64,
            Color32::from_rgb(90, 160, 255),
        ),
        (&|p: &FrameProfile| p.gpu_ms, Color32::from_rgb(255, 150, 60)),
    ] {
        let line: Vec<Pos2> = recent.iter().enumerate().map(|(k, p)| point(k, pick(p))).collect();
        painter.add(egui::Shape::line(line, Stroke::new(1.5, color)));
    }
    painter.text(
        r.left_top() + Vec2::new(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{top:.1} ms"),
        egui::FontId::monospace(10.0),
        Color32::GRAY,
    );
}

/// One bar per pass, in execution order, scaled to the longest.
fn pass_bars(ui: &mut egui::Ui, frame: &FrameProfile) {
    let longest = frame.passes.iter().map(|p| p.gpu_ms).fold(1e-6, f64::max);
    for pass in &frame.passes {
        let (response, painter) = ui.allocate_painter(Vec2::new(310.0, 13.0), Sense::hover());
        let r = response.rect;
        // The label takes 32 monospace characters (~200 points).
        let left = r.left() + 205.0;
        let width = (r.right() - left).max(0.0) * (pass.gpu_ms / longest) as f32;
        let bar = Rect::from_min_size(Pos2::new(left, r.top() + 1.0), Vec2::new(width, 11.0));
        painter.rect_filled(bar, 1.0, Color32::from_rgb(230, 140, 60));
        let label = format!("{:<24.24} {:>7.2}", pass.name, pass.gpu_ms);
        let font = egui::FontId::monospace(10.0);
        painter.text(r.left_center(), egui::Align2::LEFT_CENTER, label, font, Color32::WHITE);
    }
}

fn switch_rows(ui: &mut egui::Ui, s: &mut Switches) {
    use ShadowMode as Sm;
    use SkyLightMode as Sl;
    use TerrainView as Tv;
    use TexturingMode as Tm;
    for row in PresentedImage::ALL.chunks(4) {
        ui.horizontal(|ui| {
            ui.label(if row[0] == PresentedImage::Color { "image" } else { "" });
            for &image in row {
                ui.selectable_value(&mut s.image, image, image.name());
            }
        });
    }
    ui.horizontal(|ui| {
        ui.label("shadows");
        for (v, n) in [(Sm::Cascaded, "cascaded"), (Sm::Horizon, "horizon"), (Sm::Off, "off")] {
            ui.selectable_value(&mut s.shadows, v, n);
        }
    });
    ui.horizontal(|ui| {
        ui.label("sky light");
        for (v, n) in [
            (Sl::Sh, "SH"),
            (Sl::Ao, "AO"),
            (Sl::Patches, "patches"),
            (Sl::Off, "off"),
        ] {
            ui.selectable_value(&mut s.sky_light, v, n);
        }
    });
    ui.horizontal(|ui| {
        ui.label("sky");
        ui.selectable_value(&mut s.sky, SkyModel::Physical, "physical");
        ui.selectable_value(&mut s.sky, SkyModel::Preetham, "Preetham");
        ui.selectable_value(&mut s.sky, SkyModel::CieClear, "CIE clear");
        ui.selectable_value(&mut s.sky, SkyModel::CieOvercast, "CIE overcast");
    });
    ui.horizontal(|ui| {
        ui.label("view");
        for (v, n) in [
            (Tv::Shaded, "shaded"),
            (Tv::Importance, "importance"),
            (Tv::Wireframe, "wire"),
        ] {
            ui.selectable_value(&mut s.terrain_view, v, n);
        }
    });
    ui.horizontal(|ui| {
        ui.label("");
        for (v, n) in [(Tv::DensityRatio, "density ratio"), (Tv::SplitOctave, "split octave")] {
            ui.selectable_value(&mut s.terrain_view, v, n);
        }
    });
    ui.horizontal(|ui| {
        ui.label("texturing");
        for (v, n) in [(Tm::Atlas, "atlas"), (Tm::Direct, "direct"), (Tm::Classic, "classic")] {
            ui.selectable_value(&mut s.texturing, v, n);
        }
    });
}
