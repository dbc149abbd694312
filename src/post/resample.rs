//! What the resampling post passes share ([`super::resolve`],
//! [`super::distortion`]; §3.3, the cameras of a driving simulator): a list
//! of images, each with its [`ImageKind`], read through the heap's sampled
//! arrays by `texelFetch` (any format, uint included) and written through the
//! storage array of its [`Format`]; and the CPU side of their twins, images
//! as [`Plane`]s of texels. GLSL side: `glsl/include/resample.glsl`.

use std::sync::Arc;

use bytemuck::Pod;

use crate::error::{Error, Result};
use crate::graph::{BufferAccess, BufferId, ImageAccess, ImageId, RenderGraph, Stage};
use crate::vulkan::{ComputePipeline, Format};

/// How a resampling pass treats an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ImageKind {
    /// Float values, averaged or interpolated (radiance).
    Filtered,
    /// One source texel, copied bit for bit (ids, depth, distance, normals,
    /// visibility): never a mix of two surfaces, and every Exact image of a
    /// view takes the same texel, so the AOVs stay consistent.
    Exact,
    /// Exact, and its first two channels a displacement in pixels (the
    /// motion AOV), carried into the target's pixels.
    Motion,
}

impl ImageKind {
    /// The code the shaders use (`KIND_*`).
    pub(crate) fn code(self) -> u32 {
        match self {
            ImageKind::Filtered => 0,
            ImageKind::Exact => 1,
            ImageKind::Motion => 2,
        }
    }
}

/// The formats the resampling passes read and write, in the order of the
/// shaders' format codes (`FORMAT_*`): float formats, then uint formats.
pub const RESAMPLE_FORMATS: [Format; 7] = [
    Format::R32G32B32A32_SFLOAT,
    Format::R16G16B16A16_SFLOAT,
    Format::R32G32_SFLOAT,
    Format::R32_SFLOAT,
    Format::R8G8B8A8_UNORM,
    Format::R32G32_UINT,
    Format::R32_UINT,
];

/// Whether `format` holds unsigned integers.
pub fn is_uint_format(format: Format) -> bool {
    matches!(format, Format::R32G32_UINT | Format::R32_UINT)
}

/// One image of a resampling pass: `source` (read sampled) into `target`
/// (written as a storage image), both of `format`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResampleImage {
    pub source: ImageId,
    pub target: ImageId,
    pub format: Format,
    pub kind: ImageKind,
}

impl ResampleImage {
    /// `source` into `target`, both of `format`, treated as `kind`.
    pub fn new(source: ImageId, target: ImageId, format: Format, kind: ImageKind) -> ResampleImage {
        ResampleImage {
            source,
            target,
            format,
            kind,
        }
    }
}

/// An image of a pass, checked: its heap resources and shader codes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CheckedImage {
    pub source: ImageId,
    pub target: ImageId,
    pub format: u32,
    pub kind: u32,
}

/// Checks `images` of the pass `pass`: at least one, supported formats,
/// Filtered and Motion kinds only of float formats, a Motion image with two
/// channels or more, no source that is also a target.
pub(crate) fn check_images(pass: &str, images: &[ResampleImage]) -> Result<Vec<CheckedImage>> {
    if images.is_empty() {
        return Err(Error::invalid(format!("{pass} images"), "the list is empty"));
    }
    images
        .iter()
        .enumerate()
        .map(|(i, image)| {
            let parameter = format!("{pass} image {i}");
            let format = RESAMPLE_FORMATS
                .iter()
                .position(|&f| f == image.format)
                .ok_or_else(|| {
                    Error::invalid(
                        &parameter,
                        format!("format {:?} is not one of {RESAMPLE_FORMATS:?}", image.format),
                    )
                })?;
            if image.kind != ImageKind::Exact && is_uint_format(image.format) {
                return Err(Error::invalid(
                    &parameter,
                    format!(
                        "a {:?} image must be of a float format, not {:?}",
                        image.kind, image.format
                    ),
                ));
            }
            if image.kind == ImageKind::Motion && matches!(image.format, Format::R32_SFLOAT | Format::R8G8B8A8_UNORM) {
                return Err(Error::invalid(
                    &parameter,
                    "a motion image needs two signed float channels (x, y)",
                ));
            }
            if images.iter().any(|other| other.target == image.source) {
                return Err(Error::invalid(&parameter, "its source is also a target of the pass"));
            }
            Ok(CheckedImage {
                source: image.source,
                target: image.target,
                format: format as u32,
                kind: image.kind.code(),
            })
        })
        .collect()
}

/// Checks an image size of a pass.
pub(crate) fn check_size(parameter: &str, (width, height): (u32, u32)) -> Result<()> {
    let max = crate::view::MAX_IMAGE_SIDE;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::invalid(
            parameter,
            format!("{width}×{height}; each side must be in 1..={max}"),
        ));
    }
    Ok(())
}

/// Declares the compute pass `name`: reads every source (sampled) and
/// `buffers` (storage), writes every target, and per image pushes what
/// `push` makes of it (with its source's sampled and its target's storage
/// handle, and the handles of `buffers`, in order) and dispatches 8×8
/// groups over `target_size`.
pub(crate) fn declare_pass<P: 'static, T: Pod>(
    graph: &mut RenderGraph<P>,
    name: &str,
    pipeline: Arc<ComputePipeline>,
    images: Vec<CheckedImage>,
    buffers: &[BufferId],
    target_size: (u32, u32),
    push: impl Fn(&CheckedImage, [u32; 2], &[u32]) -> Result<T> + Send + Sync + 'static,
) {
    let mut pass = graph.pass(name);
    let sources: Vec<_> = (images.iter())
        .map(|image| pass.sample(image.source, Stage::Compute))
        .collect();
    let buffers: Vec<_> = (buffers.iter())
        .map(|&buffer| pass.storage_buffer(buffer, BufferAccess::StorageRead(Stage::Compute)))
        .collect();
    let targets: Vec<_> = (images.iter())
        .map(|image| pass.storage_image(image.target, ImageAccess::StorageWrite(Stage::Compute)))
        .collect();
    pass.record(move |ctx, _| {
        let buffers = (buffers.iter()).map(|&b| ctx.handle(b)).collect::<Result<Vec<_>>>()?;
        for ((image, &source), &target) in images.iter().zip(&sources).zip(&targets) {
            let handles = [ctx.handle(source)?, ctx.handle(target)?];
            let constants = push(image, handles, &buffers)?;
            let groups = [target_size.0.div_ceil(8), target_size.1.div_ceil(8), 1];
            ctx.dispatch(&pipeline, &constants, groups)?;
        }
        Ok(())
    });
}

/// An image on the CPU (the twins' input and output): `width`×`height`
/// texels, rows top to bottom. Float images are `Plane<[f32; 4]>` whatever
/// their format (what `texelFetch` returns: missing channels 0, 0, 1).
#[derive(Clone, Debug, PartialEq)]
#[cfg(test)]
pub struct Plane<T> {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<T>,
}

#[cfg(test)]
impl<T: Copy> Plane<T> {
    /// A plane of `f(x, y)`.
    #[cfg(test)]
    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> T) -> Plane<T> {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y));
        Plane {
            width,
            height,
            texels: texels.collect(),
        }
    }

    /// Checks that the plane has a size and a texel per pixel; errors name `parameter`.
    #[cfg(test)]
    pub fn check(&self, parameter: &str) -> Result<()> {
        check_size(parameter, (self.width, self.height))?;
        if self.texels.len() != self.width as usize * self.height as usize {
            return Err(Error::invalid(
                parameter,
                format!("{} texels for {}×{}", self.texels.len(), self.width, self.height),
            ));
        }
        Ok(())
    }

    /// The texel at (`x`, `y`), clamped to the edge (of a checked plane).
    #[cfg(test)]
    pub fn at(&self, x: i64, y: i64) -> T {
        let x = x.clamp(0, i64::from(self.width) - 1) as usize;
        let y = y.clamp(0, i64::from(self.height) - 1) as usize;
        self.texels[y * self.width as usize + x]
    }
}

/// `sum + w·c`, channel by channel.
#[cfg(test)]
pub(crate) fn add_weighted(sum: &mut [f32; 4], w: f32, c: [f32; 4]) {
    for (s, c) in sum.iter_mut().zip(c) {
        *s += w * c;
    }
}

/// Bilinear interpolation at `q` in texel coordinates (texel k's centre at
/// k), clamped to the edge, skipping taps of weight 0: the twin of
/// `bilinear` in `glsl/include/resample.glsl`.
#[cfg(test)]
pub fn bilinear(plane: &Plane<[f32; 4]>, q: [f32; 2]) -> [f32; 4] {
    let q = [
        q[0].clamp(-1.0, plane.width as f32),
        q[1].clamp(-1.0, plane.height as f32),
    ];
    let f = [q[0].floor(), q[1].floor()];
    let t = [q[0] - f[0], q[1] - f[1]];
    let mut sum = [0.0; 4];
    for dy in 0..2 {
        let wy = if dy == 0 { 1.0 - t[1] } else { t[1] };
        for dx in 0..2 {
            let w = if dx == 0 { 1.0 - t[0] } else { t[0] } * wy;
            if w > 0.0 {
                add_weighted(&mut sum, w, plane.at(f[0] as i64 + dx, f[1] as i64 + dy));
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_interpolates_a_ramp_and_keeps_infinity_out_of_exact_taps() {
        let plane = Plane::from_fn(4, 3, |x, y| [x as f32, y as f32, 0.0, 1.0]);
        assert_eq!(bilinear(&plane, [1.25, 0.5]), [1.25, 0.5, 0.0, 1.0]);
        assert_eq!(bilinear(&plane, [-3.0, 7.0]), [0.0, 2.0, 0.0, 1.0]);
        let sky = Plane::from_fn(2, 1, |x, _| [if x == 1 { f32::INFINITY } else { 3.0 }; 4]);
        assert_eq!(bilinear(&sky, [0.0, 0.0]), [3.0; 4]);
    }
}
