//! Host copies of a view's images: the `readback` pass copies the
//! requested [`Output`]s of frame `k` into the host-visible buffers of
//! readback slot `k % slots` (a ring sized by
//! [`super::RenderSettings::readback_slots`]); the graph imports each
//! output's slot buffers as one resource and picks the frame's by its
//! number, so it derives every barrier. [`super::FrameData`] hands out
//! borrowed slices of a completed slot, [`FrameImages`] owned copies.

use std::sync::Arc;

use super::frame_data::Plane;
use super::outputs::{Element, Output, Outputs};
use crate::error::{Error, Result};
use crate::graph::{BufferId, ImageId, RenderGraph};
use crate::view::{pass_name, Frame, SceneTargets, View};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Context, MemoryLocation};

/// A rendered view in host memory. Row 0 is the top of the image. An
/// output the renderer does not read back ([`super::RenderSettings::outputs`])
/// is empty (`weight`: None).
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

/// The readback buffers: one per image copied (class and instance share
/// the ids image's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    Display,
    Radiance,
    ViewDepth,
    Distance,
    Normal,
    Ids,
    Motion,
    Visibility,
    Weight,
}

const SOURCES: usize = 9;

/// Where `output` lives: its buffer, the stored element, samples per
/// pixel and the output's first sample within a pixel.
fn layout(output: Output) -> (Source, Element, usize, usize) {
    match output {
        Output::Rgba8 => (Source::Display, Element::U8, 4, 0),
        Output::Hdr => (Source::Radiance, Element::F32, 4, 0),
        Output::Depth => (Source::ViewDepth, Element::F32, 1, 0),
        Output::Distance => (Source::Distance, Element::F32, 1, 0),
        Output::Normal => (Source::Normal, Element::F16, 4, 0),
        Output::Class => (Source::Ids, Element::U32, 2, 0),
        Output::Instance => (Source::Ids, Element::U32, 2, 1),
        Output::Motion => (Source::Motion, Element::F32, 2, 0),
        Output::Visibility => (Source::Visibility, Element::F32, 2, 0),
        Output::Weight => (Source::Weight, Element::F32, 1, 0),
    }
}

/// The image of `targets` that `source` copies (None: the view has none).
fn image_of(targets: &SceneTargets, source: Source) -> Option<ImageId> {
    Some(match source {
        Source::Display => targets.display,
        Source::Radiance => targets.radiance,
        Source::ViewDepth => targets.view_depth,
        Source::Distance => targets.distance,
        Source::Normal => targets.normal,
        Source::Ids => targets.ids,
        Source::Motion => targets.motion,
        Source::Visibility => targets.visibility,
        Source::Weight => targets.weight?,
    })
}

/// One view's readback ring: per copied image, one host buffer per slot.
pub(super) struct Readback {
    name: String,
    size: (u32, u32),
    /// The outputs read back (requested and present in the view).
    outputs: Outputs,
    buffers: [Vec<Arc<Buffer>>; SOURCES],
}

impl Readback {
    /// Declares the view's `readback` pass copying `outputs` of `targets`
    /// into `slots` host buffers each; returns None (and declares nothing)
    /// when there is nothing to copy.
    pub(super) fn declare<S: 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<Frame<S>>,
        view: &View,
        targets: &SceneTargets,
        (outputs, slots): (Outputs, usize),
    ) -> Result<Option<Readback>> {
        let pixels = u64::from(targets.width) * u64::from(targets.height);
        let mut rb = Readback {
            name: view.name.clone(),
            size: (targets.width, targets.height),
            outputs: Outputs::NONE,
            buffers: Default::default(),
        };
        let mut copies: Vec<(ImageId, BufferId)> = Vec::new();
        for output in outputs.iter() {
            let (source, element, stride, _) = layout(output);
            let Some(image) = image_of(targets, source) else {
                continue;
            };
            rb.outputs = rb.outputs.with(output);
            if !rb.buffers[source as usize].is_empty() {
                continue;
            }
            let name = pass_name(&format!("{} readback", output.name()), &view.name);
            let size = pixels * (stride * element.size()) as u64;
            let buffers = (0..slots)
                .map(|slot| host_buffer(ctx, format!("{name} {slot}"), size))
                .collect::<Result<Vec<_>>>()?;
            copies.push((image, graph.import_buffers_per_frame(buffers.clone())));
            rb.buffers[source as usize] = buffers;
        }
        if copies.is_empty() {
            return Ok(None);
        }
        graph.read_back_images(&pass_name("readback", &view.name), copies);
        Ok(Some(rb))
    }

    /// The view's name.
    pub(super) fn name(&self) -> &str {
        &self.name
    }

    /// The output size.
    pub(super) fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The outputs read back.
    pub(super) fn outputs(&self) -> Outputs {
        self.outputs
    }

    /// `output` in slot `slot` (its frame must have completed).
    pub(super) fn plane(&self, output: Output, slot: usize) -> Result<Plane<'_>> {
        let (source, element, stride, offset) = layout(output);
        let buffer = match self.outputs.contains(output) {
            true => self.buffers[source as usize].get(slot),
            false => None,
        };
        let buffer = buffer.ok_or_else(|| {
            let why = match output {
                Output::Weight => "(it needs point objects and `outputs` with it)",
                _ => "(see the settings' `outputs`)",
            };
            Error::invalid(
                "output",
                format!("'{output}' is not read back for view '{}' {why}", self.name),
            )
        })?;
        Ok(Plane {
            output,
            width: self.size.0,
            height: self.size.1,
            element,
            stride,
            offset,
            bytes: buffer.mapped()?,
        })
    }

    /// Owned copies of the images in slot `slot` (its frame must have completed).
    pub(super) fn read(&self, slot: usize) -> Result<FrameImages> {
        let pixels = self.size.0 as usize * self.size.1 as usize;
        let floats = |o: Output| -> Result<Vec<f32>> {
            if !self.outputs.contains(o) {
                return Ok(Vec::new());
            }
            let mut v = vec![0.0; pixels * o.channels()];
            self.plane(o, slot)?.copy_into_f32(&mut v)?;
            Ok(v)
        };
        let ids = |o: Output| -> Result<Vec<u32>> {
            if !self.outputs.contains(o) {
                return Ok(Vec::new());
            }
            let mut v = vec![0; pixels];
            self.plane(o, slot)?.copy_into_u32(&mut v)?;
            Ok(v)
        };
        Ok(FrameImages {
            name: self.name.clone(),
            width: self.size.0,
            height: self.size.1,
            rgba8: match self.outputs.contains(Output::Rgba8) {
                true => self.plane(Output::Rgba8, slot)?.bytes.to_vec(),
                false => Vec::new(),
            },
            hdr: floats(Output::Hdr)?,
            depth: floats(Output::Depth)?,
            weight: match self.outputs.contains(Output::Weight) {
                true => Some(floats(Output::Weight)?),
                false => None,
            },
            visibility: floats(Output::Visibility)?,
            normal: floats(Output::Normal)?,
            class: ids(Output::Class)?,
            instance: ids(Output::Instance)?,
            motion: floats(Output::Motion)?,
            distance: floats(Output::Distance)?,
        })
    }
}

/// A host-visible readback buffer of `size` bytes.
fn host_buffer(ctx: &Context, name: String, size: u64) -> Result<Arc<Buffer>> {
    let desc = BufferDesc {
        name,
        size,
        usage: BufferUsageFlags::TRANSFER_DST,
        location: MemoryLocation::GpuToCpu,
    };
    Buffer::new(ctx, desc).map(Arc::new)
}
