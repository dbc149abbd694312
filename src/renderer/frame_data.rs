//! Borrowed views of a completed frame's readback slot: [`FrameData`] (the
//! frame), [`ViewData`] (one view) and [`Plane`] (one output of a view,
//! straight from the mapped readback memory), with `copy_into` helpers
//! that convert into caller-owned buffers (f16 normals into f32 × 3,
//! class and instance de-interleaved from the ids image). Nothing here
//! allocates.

use super::outputs::{Element, Output, Outputs};
use super::readback::Readback;
use crate::error::{Error, Result};

/// One output of one view in a readback slot: `width × height` pixels, row
/// 0 at the top, rows packed; each pixel is `stride` samples of `element`
/// (little-endian), of which the output's [`Output::channels`] start at
/// sample `offset` (the normal is stored as 4 × f16 of which 3 are used;
/// class and instance are samples 0 and 1 of the ids image's 2 × u32).
#[derive(Clone, Copy, Debug)]
pub struct Plane<'a> {
    pub output: Output,
    pub width: u32,
    pub height: u32,
    /// The stored element type.
    pub element: Element,
    /// Stored samples per pixel.
    pub stride: usize,
    /// The output's first sample within a pixel.
    pub offset: usize,
    /// The mapped readback memory: `width × height × stride × element size` bytes.
    pub bytes: &'a [u8],
}

impl<'a> Plane<'a> {
    /// Pixels of the plane.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The samples as `f32` without a copy, when stored as packed f32
    /// (hdr, depth, distance, motion, visibility, weight); None otherwise
    /// or if the memory is not 4-byte aligned.
    pub fn as_f32(&self) -> Option<&'a [f32]> {
        let packed = self.element == Element::F32 && self.stride == self.output.channels();
        packed.then(|| bytemuck::try_cast_slice(self.bytes).ok()).flatten()
    }

    fn check_len(&self, len: usize, unit: usize) -> Result<()> {
        let want = self.pixels() * self.output.channels() * unit;
        if len != want {
            return Err(Error::invalid(
                "buffer",
                format!(
                    "{} elements for '{}' of {}×{} pixels; it needs {want}",
                    len / unit,
                    self.output,
                    self.width,
                    self.height
                ),
            ));
        }
        Ok(())
    }

    fn wrong_type(&self, what: &str) -> Error {
        Error::invalid(
            "output",
            format!(
                "'{}' holds {:?} samples, not {what}",
                self.output,
                self.output.element()
            ),
        )
    }

    /// Pixel `p`'s stored samples.
    fn pixel_chunks(&self) -> std::slice::ChunksExact<'a, u8> {
        self.bytes.chunks_exact(self.stride * self.element.size())
    }

    /// Copies a float output (hdr, depth, distance, normal as f32 × 3,
    /// motion, visibility, weight) into `dst` (`pixels × channels` values).
    pub fn copy_into_f32(&self, dst: &mut [f32]) -> Result<()> {
        if self.output.element() != Element::F32 {
            return Err(self.wrong_type("f32"));
        }
        self.check_len(dst.len(), 1)?;
        if let Some(src) = self.as_f32() {
            dst.copy_from_slice(src);
            return Ok(());
        }
        let (channels, size, offset) = (self.output.channels(), self.element.size(), self.offset);
        let f16 = self.element == Element::F16;
        for (px, out) in self.pixel_chunks().zip(dst.chunks_exact_mut(channels)) {
            for (c, o) in out.iter_mut().enumerate() {
                let s = &px[(offset + c) * size..][..size];
                *o = match f16 {
                    true => f16_to_f32(u16::from_le_bytes([s[0], s[1]])),
                    false => f32::from_le_bytes([s[0], s[1], s[2], s[3]]),
                };
            }
        }
        Ok(())
    }

    /// Copies an id output (class, instance) into `dst` (`pixels` values),
    /// de-interleaved from the ids image.
    pub fn copy_into_u32(&self, dst: &mut [u32]) -> Result<()> {
        if self.output.element() != Element::U32 {
            return Err(self.wrong_type("u32"));
        }
        self.check_len(dst.len(), 1)?;
        let offset = self.offset * 4;
        for (px, out) in self.pixel_chunks().zip(dst.iter_mut()) {
            let s = &px[offset..offset + 4];
            *out = u32::from_le_bytes([s[0], s[1], s[2], s[3]]);
        }
        Ok(())
    }

    /// Copies the output into `dst` as the caller sees it: `pixels ×`
    /// [`Output::bytes_per_pixel`] bytes of [`Output::element`] samples in
    /// native byte order (rgba8 as is, f16 normals as f32 × 3, ids
    /// de-interleaved). `dst` needs no alignment.
    pub fn copy_into(&self, dst: &mut [u8]) -> Result<()> {
        self.check_len(dst.len(), self.output.element().size())?;
        let channels = self.output.channels();
        let size = self.element.size();
        let out_size = self.output.element().size();
        if self.element == Element::U8 {
            dst.copy_from_slice(self.bytes);
            return Ok(());
        }
        for (px, out) in self.pixel_chunks().zip(dst.chunks_exact_mut(channels * out_size)) {
            for c in 0..channels {
                let s = &px[(self.offset + c) * size..][..size];
                let value: [u8; 4] = match self.element {
                    Element::F16 => f16_to_f32(u16::from_le_bytes([s[0], s[1]])).to_ne_bytes(),
                    _ => u32::from_le_bytes([s[0], s[1], s[2], s[3]]).to_ne_bytes(),
                };
                out[c * 4..c * 4 + 4].copy_from_slice(&value);
            }
        }
        Ok(())
    }
}

/// One view of a completed frame, borrowed from the renderer's readback slot.
#[derive(Clone, Copy)]
pub struct ViewData<'a> {
    pub(super) readback: &'a Readback,
    pub(super) slot: usize,
}

impl<'a> ViewData<'a> {
    /// The view's name (empty for a single unnamed view).
    pub fn name(&self) -> &'a str {
        self.readback.name()
    }

    /// Output width in pixels.
    pub fn width(&self) -> u32 {
        self.readback.size().0
    }

    /// Output height in pixels.
    pub fn height(&self) -> u32 {
        self.readback.size().1
    }

    /// The outputs this view has (the requested ones; weight only with
    /// point objects).
    pub fn outputs(&self) -> Outputs {
        self.readback.outputs()
    }

    /// `output`, straight from the mapped memory; an error names an output
    /// that is not read back.
    pub fn plane(&self, output: Output) -> Result<Plane<'a>> {
        self.readback.plane(output, self.slot)
    }

    /// Every output this view has, in [`Output::ALL`] order.
    pub fn planes(&self) -> impl Iterator<Item = Plane<'a>> + 'a {
        let (readback, slot) = (self.readback, self.slot);
        (readback.outputs().iter()).filter_map(move |o| readback.plane(o, slot).ok())
    }

    /// [`Plane::copy_into`] of `output`.
    pub fn copy_into(&self, output: Output, dst: &mut [u8]) -> Result<()> {
        self.plane(output)?.copy_into(dst)
    }
}

impl std::fmt::Debug for ViewData<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ViewData")
            .field("name", &self.name())
            .field("width", &self.width())
            .field("height", &self.height())
            .field("outputs", &self.outputs())
            .finish()
    }
}

/// A completed frame's read-back outputs, borrowed from the renderer
/// ([`super::Renderer::try_read`], [`super::Renderer::wait`]): valid until
/// the renderer is used again.
#[derive(Clone, Copy)]
pub struct FrameData<'a> {
    pub(super) frame: u64,
    pub(super) views: &'a [Readback],
    pub(super) slot: usize,
}

impl<'a> FrameData<'a> {
    /// The frame's number (0, 1, 2, …).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The number of views.
    pub fn len(&self) -> usize {
        self.views.len()
    }

    /// Whether the frame has no views (never: a renderer has at least one).
    pub fn is_empty(&self) -> bool {
        self.views.is_empty()
    }

    /// View `k` (in the order of the settings' views).
    pub fn view(&self, k: usize) -> Result<ViewData<'a>> {
        let readback = self
            .views
            .get(k)
            .ok_or_else(|| Error::invalid("view", format!("{k}; the frame has {} views", self.views.len())))?;
        Ok(ViewData {
            readback,
            slot: self.slot,
        })
    }

    /// The view named `name`.
    pub fn view_named(&self, name: &str) -> Result<ViewData<'a>> {
        let readback = (self.views.iter().find(|r| r.name() == name))
            .ok_or_else(|| Error::invalid("view", format!("no view is named '{name}'")))?;
        Ok(ViewData {
            readback,
            slot: self.slot,
        })
    }

    /// Every view, in order.
    pub fn views(&self) -> impl Iterator<Item = ViewData<'a>> + 'a {
        let slot = self.slot;
        self.views.iter().map(move |readback| ViewData { readback, slot })
    }
}

impl std::fmt::Debug for FrameData<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameData")
            .field("frame", &self.frame)
            .field("views", &self.views().collect::<Vec<_>>())
            .finish()
    }
}

/// An IEEE 754 half (binary16) as f32 (exact).
pub(super) fn f16_to_f32(h: u16) -> f32 {
    let sign = u32::from(h >> 15) << 31;
    let exponent = u32::from((h >> 10) & 0x1f);
    let mantissa = u32::from(h & 0x3ff);
    match exponent {
        // Zero and subnormals: mantissa · 2^-24.
        0 => (mantissa as f32 * (-24f32).exp2()).copysign(f32::from_bits(sign | 0x3f80_0000)),
        // Infinities and NaNs.
        31 => f32::from_bits(sign | 0x7f80_0000 | mantissa << 13),
        _ => f32::from_bits(sign | (exponent + 112) << 23 | mantissa << 13),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_convert_exactly() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3555), 0.333_251_95);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), (-24f32).exp2());
        assert_eq!(f16_to_f32(0x8001), -(-24f32).exp2());
        assert_eq!(f16_to_f32(0x0000), 0.0);
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    fn plane(output: Output, element: Element, stride: usize, offset: usize, bytes: &[u8]) -> Plane<'_> {
        Plane {
            output,
            width: 2,
            height: 1,
            element,
            stride,
            offset,
            bytes,
        }
    }

    #[test]
    fn ids_deinterleave_and_normals_widen() {
        let ids: Vec<u8> = [1u32, 7, 2, 9].iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut out = [0u32; 2];
        plane(Output::Instance, Element::U32, 2, 1, &ids)
            .copy_into_u32(&mut out)
            .expect("instance");
        assert_eq!(out, [7, 9]);
        plane(Output::Class, Element::U32, 2, 0, &ids)
            .copy_into_u32(&mut out)
            .expect("class");
        assert_eq!(out, [1, 2]);
        let halves: Vec<u8> = [0x3c00u16, 0xc000, 0, 0x7bff, 0x3c00, 0x3c00, 0x3c00, 0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let normal = plane(Output::Normal, Element::F16, 4, 0, &halves);
        let mut n = [0f32; 6];
        normal.copy_into_f32(&mut n).expect("normal");
        assert_eq!(n, [1.0, -2.0, 0.0, 1.0, 1.0, 1.0]);
        let mut bytes = [0u8; 24];
        normal.copy_into(&mut bytes).expect("normal bytes");
        assert_eq!(bytes[4..8], (-2f32).to_ne_bytes());
        let e = normal.copy_into_f32(&mut [0.0; 5]).expect_err("short");
        assert!(e.to_string().contains("needs 6"), "{e}");
        assert!(normal.copy_into_u32(&mut [0; 2]).is_err());
    }
}
