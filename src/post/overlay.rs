//! The viewer's overlay, drawn by passes of the frame graph over the
//! swapchain image after `present.blit`: `overlay.font` writes what changed
//! of the font atlas, `overlay.draw` draws the overlay's triangle meshes
//! (egui's, converted by the caller into [`OverlayFrame`]: the library
//! knows no GUI toolkit). Both read this frame's upload regions; the meshes
//! are pulled in the vertex shader (`glsl/post/overlay.vert`), the atlas is
//! sampled through the heap, each mesh is clipped by a scissor.

use std::collections::VecDeque;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::graph::{ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::shaders;
use crate::view::{Frame, FrameContext, Provides, Technique};
use crate::vulkan::{
    Blend, ComputePipeline, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc, ImageUsageFlags,
    LoadOp,
};

/// The font atlas image's side (egui's default largest texture side).
pub const OVERLAY_ATLAS_SIDE: u32 = 2048;
/// Bytes of the meshes one frame may draw (vertices and indices).
const GEOMETRY_BYTES: u64 = 4 << 20;
/// Bytes of atlas texels one frame uploads (larger updates take more frames).
const TEXEL_BYTES: u64 = 2 << 20;

/// A vertex of the overlay: position in points (from the top-left corner),
/// atlas coordinates (0..1 of its used part) and a premultiplied sRGB
/// colour; the layout of egui's `epaint::Vertex`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct OverlayVertex {
    pub position: [f32; 2],
    pub uv: [f32; 2],
    pub color: [u8; 4],
}

/// Triangles sharing a clip rectangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OverlayMesh {
    /// The clip rectangle in points: min x, min y, max x, max y.
    pub clip: [f32; 4],
    pub vertices: Vec<OverlayVertex>,
    /// Three per triangle, into `vertices`.
    pub indices: Vec<u32>,
}

/// A rectangle of the font atlas to (re)write: RGBA8 premultiplied texels,
/// rows packed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OverlayTexels {
    /// Where in the atlas (None: the whole atlas, from the corner, which
    /// then is `size`).
    pub at: Option<[u32; 2]>,
    pub size: [u32; 2],
    pub rgba: Vec<u8>,
}

/// What the overlay draws over the next presented frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OverlayFrame {
    /// Physical pixels per point.
    pub pixels_per_point: f32,
    pub meshes: Vec<OverlayMesh>,
    /// Changes of the font atlas, in order.
    pub atlas: Vec<OverlayTexels>,
}

/// A draw of `overlay.draw`: the scissor (pixels) and the index range.
#[derive(Clone, Copy, Debug, PartialEq)]
struct OverlayDraw {
    scissor: [u32; 4],
    first: u32,
    count: u32,
}

/// What the overlay's passes read this frame.
#[derive(Clone, Debug, Default)]
pub struct OverlayPrepared {
    draws: Vec<OverlayDraw>,
    /// Word offset of the indices in the geometry region.
    index_base: u32,
    pixels_per_point: f32,
    uv_scale: [f32; 2],
    /// The atlas rectangle `overlay.font` writes (x, y, width, height;
    /// width 0: none).
    font_rect: [u32; 4],
}

/// Push constants of `overlay.draw` (`glsl/post/overlay.vert`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct DrawPush {
    handles: [u32; 4],
    screen: [f32; 4],
    uv_scale: [f32; 4],
}

/// Push constants of `overlay.font` (`glsl/post/overlay_font.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FontPush {
    handles: [u32; 4],
    rect: [u32; 4],
}

/// The overlay technique: its pipelines, atlas and upload regions, the
/// frame it draws next and the atlas rows still to upload.
pub struct Overlay {
    draw: Arc<GraphicsPipeline>,
    font: Arc<ComputePipeline>,
    atlas: Arc<Image>,
    geometry: Option<UploadRegion>,
    texels: Option<UploadRegion>,
    next: Option<OverlayFrame>,
    /// Atlas rectangles not uploaded yet (split into bands that fit a frame).
    pending: VecDeque<OverlayTexels>,
    /// The used part of the atlas (the last whole-atlas size).
    atlas_size: [u32; 2],
    /// The previous frame's prepared data, reused.
    spare: Option<OverlayPrepared>,
}

impl Overlay {
    /// The pipelines (drawing into `format`) and the atlas.
    pub fn new(ctx: &Context, format: Format) -> Result<Overlay> {
        let mut desc = GraphicsPipelineDesc::full_screen(
            "overlay.draw",
            (shaders::OVERLAY_VERT, shaders::OVERLAY_FRAG),
            vec![format],
        );
        desc.blend = Blend::PremultipliedOver;
        let atlas = Image::new(
            ctx,
            ImageDesc {
                name: "overlay atlas".into(),
                width: OVERLAY_ATLAS_SIDE,
                height: OVERLAY_ATLAS_SIDE,
                format: Format::R8G8B8A8_UNORM,
                usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED,
            },
        )?;
        Ok(Overlay {
            draw: Arc::new(GraphicsPipeline::new(ctx, &desc)?),
            font: Arc::new(ComputePipeline::new(ctx, shaders::OVERLAY_FONT)?),
            atlas: Arc::new(atlas),
            geometry: None,
            texels: None,
            next: None,
            pending: VecDeque::new(),
            atlas_size: [1, 1],
            spare: None,
        })
    }

    /// What the next frame draws (replacing a frame not drawn yet; its
    /// atlas changes are kept).
    pub fn set(&mut self, frame: OverlayFrame) -> Result<()> {
        for texels in &frame.atlas {
            check_texels(texels)?;
        }
        if let Some(old) = self.next.take() {
            self.queue(old.atlas);
        }
        self.next = Some(frame);
        Ok(())
    }

    fn queue(&mut self, atlas: Vec<OverlayTexels>) {
        for texels in atlas {
            if texels.at.is_none() {
                self.atlas_size = texels.size;
            }
            let rows_per_band = (TEXEL_BYTES / (4 * u64::from(texels.size[0].max(1)))).max(1) as u32;
            let at = texels.at.unwrap_or([0, 0]);
            let row_bytes = 4 * texels.size[0] as usize;
            for y in (0..texels.size[1]).step_by(rows_per_band as usize) {
                let rows = rows_per_band.min(texels.size[1] - y);
                let bytes = &texels.rgba[y as usize * row_bytes..(y + rows) as usize * row_bytes];
                self.pending.push_back(OverlayTexels {
                    at: Some([at[0], at[1] + y]),
                    size: [texels.size[0], rows],
                    rgba: bytes.to_vec(),
                });
            }
        }
    }

    /// Declares `overlay.font` and `overlay.draw` over `window`.
    pub fn declare<S>(&mut self, graph: &mut RenderGraph<Frame<S>>, window: ImageId)
    where
        S: Provides<OverlayPrepared> + 'static,
    {
        let geometry = graph.upload_region("overlay geometry", GEOMETRY_BYTES);
        let texels = graph.upload_region("overlay texels", TEXEL_BYTES);
        (self.geometry, self.texels) = (Some(geometry), Some(texels));
        let atlas = graph.import_image(self.atlas.clone());
        let font = self.font.clone();
        let mut pass = graph.pass("overlay.font");
        let texels = pass.upload(texels, Stage::Compute);
        let atlas_storage = pass.storage_image(atlas, ImageAccess::StorageReadWrite(Stage::Compute));
        pass.record(move |ctx, frame: &Frame<S>| {
            let rect = frame.prepared::<OverlayPrepared>()?.font_rect;
            let push = FontPush {
                handles: [ctx.handle(texels)?, ctx.handle(atlas_storage)?, 0, 0],
                rect,
            };
            ctx.dispatch(&font, &push, [rect[2].div_ceil(8), rect[3].div_ceil(8), 1])
        });
        let draw = self.draw.clone();
        let mut pass = graph.pass("overlay.draw").graphics();
        let geometry = pass.upload(geometry, Stage::Vertex);
        let atlas_sampled = pass.sample(atlas, Stage::Fragment);
        pass.pipeline(&draw)
            .color(window, LoadOp::Load)
            .record(move |ctx, frame: &Frame<S>| {
                let prepared = frame.prepared::<OverlayPrepared>()?;
                if prepared.draws.is_empty() {
                    return Ok(());
                }
                let target = ctx.image(window)?.desc();
                let push = DrawPush {
                    handles: [
                        ctx.handle(geometry)?,
                        ctx.handle(atlas_sampled)?,
                        prepared.index_base,
                        0,
                    ],
                    screen: [
                        target.width as f32,
                        target.height as f32,
                        prepared.pixels_per_point,
                        0.0,
                    ],
                    uv_scale: [prepared.uv_scale[0], prepared.uv_scale[1], 0.0, 0.0],
                };
                let (width, height) = (target.width, target.height);
                let cmd = ctx.cmd();
                cmd.bind_graphics(&draw);
                cmd.push_constants(&push)?;
                for d in &prepared.draws {
                    let [x, y, w, h] = d.scissor;
                    cmd.set_scissor(x, y, w.min(width.saturating_sub(x)), h.min(height.saturating_sub(y)));
                    cmd.draw_range(d.count, d.first);
                }
                cmd.set_scissor(0, 0, width, height);
                Ok(())
            });
    }

    /// Writes the frame's meshes into the geometry region and the next
    /// atlas band into the texel region.
    fn prepare_frame(&mut self, frame: &mut FrameContext<'_, '_>, mut out: OverlayPrepared) -> Result<OverlayPrepared> {
        out.draws.clear();
        out.font_rect = [0; 4];
        let (Some(geometry), Some(texel_region)) = (self.geometry, self.texels) else {
            return Ok(out);
        };
        let next = self.next.take().unwrap_or_default();
        self.queue(next.atlas);
        if let Some(band) = self.pending.pop_front() {
            let at = band.at.unwrap_or([0, 0]);
            frame.uploads.write(texel_region, &band.rgba)?;
            out.font_rect = [at[0], at[1], band.size[0], band.size[1]];
        }
        out.pixels_per_point = next.pixels_per_point.max(0.01);
        out.uv_scale = self.atlas_size.map(|s| s as f32 / OVERLAY_ATLAS_SIDE as f32);
        let vertex_words: usize = next.meshes.iter().map(|m| 5 * m.vertices.len()).sum();
        let index_words: usize = next.meshes.iter().map(|m| m.indices.len()).sum();
        if 4 * (vertex_words + index_words) as u64 > geometry.size() {
            log::warn!(
                "overlay: {} meshes exceed the overlay's {GEOMETRY_BYTES} bytes; not drawn",
                next.meshes.len()
            );
            return Ok(out);
        }
        let mut indices: Vec<u32> = Vec::with_capacity(index_words);
        let (mut vertex_base, mut offset) = (0u32, 0u64);
        for mesh in &next.meshes {
            let bytes: &[u8] = bytemuck::cast_slice(&mesh.vertices);
            frame.uploads.write_at(geometry, offset, bytes)?;
            offset += bytes.len() as u64;
            let first = indices.len() as u32;
            let count = mesh.vertices.len() as u32;
            indices.extend(mesh.indices.iter().filter(|&&i| i < count).map(|i| i + vertex_base));
            vertex_base += count;
            let clip = mesh.clip.map(|c| (c * out.pixels_per_point).round().max(0.0) as u32);
            let scissor = [
                clip[0],
                clip[1],
                clip[2].saturating_sub(clip[0]),
                clip[3].saturating_sub(clip[1]),
            ];
            let count = indices.len() as u32 - first;
            if count > 0 && scissor[2] > 0 && scissor[3] > 0 {
                out.draws.push(OverlayDraw { scissor, first, count });
            }
        }
        out.index_base = (offset / 4) as u32;
        frame
            .uploads
            .write_at(geometry, offset, bytemuck::cast_slice(&indices))?;
        Ok(out)
    }
}

/// A texel rectangle's checks: its bytes are its size's, it lies in the atlas.
fn check_texels(t: &OverlayTexels) -> Result<()> {
    let at = t.at.unwrap_or([0, 0]);
    let fits = (at[0] as u64 + t.size[0] as u64) <= OVERLAY_ATLAS_SIDE as u64
        && (at[1] as u64 + t.size[1] as u64) <= OVERLAY_ATLAS_SIDE as u64;
    if !fits {
        return Err(Error::invalid(
            "overlay atlas",
            format!("{:?} at {at:?} exceeds the {OVERLAY_ATLAS_SIDE}² atlas", t.size),
        ));
    }
    if t.rgba.len() as u64 != 4 * t.size[0] as u64 * t.size[1] as u64 {
        return Err(Error::invalid(
            "overlay atlas",
            format!("{} bytes for {}×{} texels", t.rgba.len(), t.size[0], t.size[1]),
        ));
    }
    Ok(())
}

impl Technique for Overlay {
    type Prepared = OverlayPrepared;
    type Needs<'a> = ();

    fn name(&self) -> &'static str {
        "overlay"
    }

    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, (): ()) -> Result<OverlayPrepared> {
        let spare = self.spare.take().unwrap_or_default();
        self.prepare_frame(frame, spare)
    }

    fn recycle(&mut self, previous: OverlayPrepared) {
        self.spare = Some(previous);
    }
}
