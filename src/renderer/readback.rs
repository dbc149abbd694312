//! Host copies of a view's images: per frame slot, the `readback` pass
//! copies them into host-visible buffers that [`super::Renderer::read_view`]
//! reads once the frame completed.

use std::sync::Arc;

use super::aov_readback::AovReadback;
use crate::error::Result;
use crate::graph::RenderGraph;
use crate::view::{pass_name, Frame, SceneTargets, View};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, MemoryLocation};

/// A rendered view in host memory. Row 0 is the top of the image.
#[derive(Clone, Debug)]
pub struct FrameImages {
    /// The view's name (empty for a single unnamed view).
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Tone-mapped sRGB, 4 bytes per pixel.
    pub rgba8: Vec<u8>,
    /// Linear HDR radiance, 4 floats per pixel (alpha 1 everywhere).
    pub hdr: Vec<f32>,
    /// View-space depth along the camera's forward axis, metres; +inf for sky.
    pub depth: Vec<f32>,
    /// W: the accumulated EWA splat weight before normalisation (opaque
    /// splats: 1), 0 where no splat reached; None for scenes without points.
    pub weight: Option<Vec<f32>>,
    /// The lighting AOVs, 2 floats per pixel: sun visibility (0 = in
    /// shadow, 1 = lit; the filtered shadow term) and sky visibility (the
    /// ambient-occlusion term, 1 = open sky); (1, 1) for sky pixels.
    pub visibility: Vec<f32>,
    /// The simulator AOVs (`crate::view::aov`): world-space shading normal,
    /// 3 floats per pixel (0 for sky).
    pub normal: Vec<f32>,
    /// Semantic class per pixel (sky 0, terrain 1 or 10 + its dominant
    /// surface layer, rock 2, other point objects 3, vegetation 4).
    pub class: Vec<u32>,
    /// Point instance id per pixel (1-based; 0 for terrain and sky).
    pub instance: Vec<u32>,
    /// Motion from the previous frame in pixels, 2 floats per pixel (this
    /// frame's position minus the previous one's; +x right, +y down; 0 on
    /// the first frame).
    pub motion: Vec<f32>,
    /// Euclidean distance from the eye along the pixel's ray, metres; +inf for sky.
    pub distance: Vec<f32>,
}

impl FrameImages {
    /// One AOV channel of [`FrameImages::visibility`]: 0 sun, 1 sky.
    pub fn visibility_channel(&self, k: usize) -> Vec<f32> {
        self.visibility.iter().skip(k).step_by(2).copied().collect()
    }
}

/// One view's readback buffers, one per frame slot each.
pub(super) struct Readback {
    name: String,
    size: (u32, u32),
    hdr: Vec<Arc<Buffer>>,
    depth: Vec<Arc<Buffer>>,
    ldr: Vec<Arc<Buffer>>,
    weight: Option<Vec<Arc<Buffer>>>,
    visibility: Vec<Arc<Buffer>>,
    aovs: AovReadback,
}

/// One readback buffer per frame slot.
pub(super) fn host_buffers(ctx: &Context, name: &str, size: u64) -> Result<Vec<Arc<Buffer>>> {
    Buffer::per_frame(
        ctx,
        BufferDesc {
            name: format!("{name} readback"),
            size,
            usage: BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuToCpu,
        },
    )
}

impl Readback {
    /// Declares the view's `readback`: its images into per-frame host buffers.
    pub(super) fn declare(
        ctx: &Context,
        graph: &mut RenderGraph<Frame>,
        view: &View,
        targets: &SceneTargets,
    ) -> Result<Readback> {
        let pixels = u64::from(targets.width) * u64::from(targets.height);
        let buffers = |what: &str, size| host_buffers(ctx, &pass_name(what, &view.name), size);
        let mut copies = Vec::new();
        let rb = Readback {
            aovs: AovReadback::declare(ctx, graph, view, targets, &mut copies)?,
            name: view.name.clone(),
            size: (targets.width, targets.height),
            hdr: buffers("hdr", pixels * 16)?,
            depth: buffers("depth", pixels * 4)?,
            ldr: buffers("srgb", pixels * 4)?,
            visibility: buffers("lighting visibility", pixels * 8)?,
            weight: match targets.weight {
                Some(_) => Some(buffers("splat weight", pixels * 4)?),
                None => None,
            },
        };
        copies.extend([
            (targets.radiance, graph.import_buffers_per_frame(rb.hdr.clone())),
            (targets.view_depth, graph.import_buffers_per_frame(rb.depth.clone())),
            (targets.display, graph.import_buffers_per_frame(rb.ldr.clone())),
            (
                targets.visibility,
                graph.import_buffers_per_frame(rb.visibility.clone()),
            ),
        ]);
        if let (Some(image), Some(buffers)) = (targets.weight, &rb.weight) {
            copies.push((image, graph.import_buffers_per_frame(buffers.clone())));
        }
        graph.read_back_images(&pass_name("readback", &view.name), copies);
        Ok(rb)
    }

    /// The images of frame slot `slot` (its frame must have completed).
    pub(super) fn read(&self, slot: usize) -> Result<FrameImages> {
        let floats = |b: &Buffer| -> Result<Vec<f32>> { Ok(bytemuck::pod_collect_to_vec(b.mapped()?)) };
        let aovs = self.aovs.read(slot)?;
        Ok(FrameImages {
            name: self.name.clone(),
            width: self.size.0,
            height: self.size.1,
            rgba8: self.ldr[slot].mapped()?.to_vec(),
            hdr: floats(&self.hdr[slot])?,
            depth: floats(&self.depth[slot])?,
            weight: match &self.weight {
                Some(w) => Some(floats(&w[slot])?),
                None => None,
            },
            visibility: floats(&self.visibility[slot])?,
            normal: aovs.normal,
            class: aovs.class,
            instance: aovs.instance,
            motion: aovs.motion,
            distance: aovs.distance,
        })
    }
}
