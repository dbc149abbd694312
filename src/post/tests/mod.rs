//! The simulator cameras' post passes (issue 14; src/post/resolve.rs,
//! src/post/distortion, src/post/motion_blur.rs) on a real device under
//! validation and synchronization validation: small graphs of synthetic
//! input images, the pass, a readback; every result against the pass's CPU
//! twin (Filtered to 1e-5 relative, Exact bit for bit) and an analytic case.

mod distortion;
mod motion_blur;
mod resolve;

use std::sync::Arc;

use crate::graph::{ImageId, ImageInfo, RenderGraph};
use crate::post::resample::{is_uint_format, Plane};
use crate::test_support::{assert_validation_clean, validated_context};
use crate::vulkan::{
    Buffer, BufferDesc, BufferUsageFlags, Context, Format, FrameRing, Image, ImageDesc, ImageUsageFlags, MemoryLocation,
};

/// Texels of an image: what `texelFetch` returns (float or uint, missing
/// channels 0, 0, 1).
#[derive(Clone, Debug, PartialEq)]
pub enum Texels {
    Float(Plane<[f32; 4]>),
    Uint(Plane<[u32; 4]>),
}

impl Texels {
    pub fn float(&self) -> &Plane<[f32; 4]> {
        match self {
            Texels::Float(p) => p,
            Texels::Uint(_) => panic!("a uint image"),
        }
    }

    pub fn uint(&self) -> &Plane<[u32; 4]> {
        match self {
            Texels::Uint(p) => p,
            Texels::Float(_) => panic!("a float image"),
        }
    }
}

/// Channels of a format.
fn channels(format: Format) -> usize {
    match format {
        Format::R32_SFLOAT | Format::R32_UINT => 1,
        Format::R32G32_SFLOAT | Format::R32G32_UINT => 2,
        _ => 4,
    }
}

/// `v` as `format` stores and `texelFetch` returns it: missing channels
/// 0, 0, 1; RGBA16F and RGBA8 rounded (test values are exact in them).
pub fn as_fetched(format: Format, v: [f32; 4]) -> [f32; 4] {
    let mut out = [0.0, 0.0, 0.0, 1.0];
    out[..channels(format)].copy_from_slice(&v[..channels(format)]);
    out
}

/// f32 → f16 bits for values f16 holds exactly (normal numbers and zero).
fn f16_bits(v: f32) -> u16 {
    if v == 0.0 {
        return 0;
    }
    let b = v.to_bits();
    let exponent = ((b >> 23) & 0xff) as i32 - 127 + 15;
    assert!(
        (1..31).contains(&exponent) && b & 0x1fff == 0,
        "{v} is not exact in f16"
    );
    (((b >> 16) & 0x8000) | ((exponent as u32) << 10) | ((b >> 13) & 0x3ff)) as u16
}

fn f16_value(h: u16) -> f32 {
    let (sign, exponent, mantissa) = (
        u32::from(h & 0x8000) << 16,
        u32::from((h >> 10) & 0x1f),
        u32::from(h & 0x3ff),
    );
    if exponent == 0 {
        assert_eq!(mantissa, 0, "subnormal f16");
        return f32::from_bits(sign);
    }
    f32::from_bits(sign | ((exponent + 127 - 15) << 23) | (mantissa << 13))
}

fn encode(format: Format, texels: &Texels) -> Vec<u8> {
    let n = channels(format);
    match (format, texels) {
        (Format::R16G16B16A16_SFLOAT, Texels::Float(p)) => p
            .texels
            .iter()
            .flat_map(|t| t.map(f16_bits))
            .flat_map(u16::to_le_bytes)
            .collect(),
        (Format::R8G8B8A8_UNORM, Texels::Float(p)) => p
            .texels
            .iter()
            .flat_map(|t| t.map(|c| (c * 255.0).round() as u8))
            .collect(),
        (_, Texels::Float(p)) => p
            .texels
            .iter()
            .flat_map(|t| t[..n].to_vec())
            .flat_map(f32::to_le_bytes)
            .collect(),
        (_, Texels::Uint(p)) => p
            .texels
            .iter()
            .flat_map(|t| t[..n].to_vec())
            .flat_map(u32::to_le_bytes)
            .collect(),
    }
}

fn decode(format: Format, bytes: &[u8], width: u32, height: u32) -> Texels {
    let n = channels(format);
    let texel = |x: u32, y: u32| (y * width + x) as usize * n;
    if is_uint_format(format) {
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(bytes);
        return Texels::Uint(Plane::from_fn(width, height, |x, y| {
            let mut t = [0, 0, 0, 1];
            t[..n].copy_from_slice(&words[texel(x, y)..texel(x, y) + n]);
            t
        }));
    }
    let values: Vec<f32> = match format {
        Format::R16G16B16A16_SFLOAT => bytemuck::pod_collect_to_vec::<u8, u16>(bytes)
            .into_iter()
            .map(f16_value)
            .collect(),
        Format::R8G8B8A8_UNORM => bytes.iter().map(|&b| f32::from(b) / 255.0).collect(),
        _ => bytemuck::pod_collect_to_vec(bytes),
    };
    Texels::Float(Plane::from_fn(width, height, |x, y| {
        let mut t = [0.0, 0.0, 0.0, 1.0];
        t[..n].copy_from_slice(&values[texel(x, y)..texel(x, y) + n]);
        t
    }))
}

/// Bytes per texel of a format.
fn texel_bytes(format: Format) -> u64 {
    match format {
        Format::R16G16B16A16_SFLOAT => 8,
        Format::R8G8B8A8_UNORM => 4,
        f => 4 * channels(f) as u64,
    }
}

/// Runs `f` with a validated context; fails on any validation message.
pub fn with_gpu<R>(f: impl FnOnce(&Context) -> R) -> R {
    let (ctx, report) = validated_context();
    let result = f(&ctx);
    drop(ctx);
    assert_validation_clean(&report);
    result
}

/// A one-frame graph: uploaded inputs, passes, read-back outputs.
pub struct OneFrame<'c> {
    ctx: &'c Context,
    pub graph: RenderGraph<()>,
    inputs: Vec<Arc<Image>>,
    outputs: Vec<(ImageId, Arc<Buffer>, Format, u32, u32)>,
}

impl<'c> OneFrame<'c> {
    pub fn new(ctx: &'c Context) -> Self {
        OneFrame {
            ctx,
            graph: RenderGraph::new(),
            inputs: Vec::new(),
            outputs: Vec::new(),
        }
    }

    /// An input image of `format` holding `texels`.
    pub fn input(&mut self, name: &str, format: Format, texels: &Texels) -> ImageId {
        let (width, height) = match texels {
            Texels::Float(p) => (p.width, p.height),
            Texels::Uint(p) => (p.width, p.height),
        };
        let desc = ImageDesc {
            name: name.into(),
            width,
            height,
            format,
            usage: ImageUsageFlags::SAMPLED,
        };
        let image = Arc::new(Image::with_data(self.ctx, desc, &encode(format, texels)).expect("input image"));
        self.inputs.push(image.clone());
        self.graph.import_image(image)
    }

    /// A transient output image, read back after the frame.
    pub fn output(&mut self, name: &str, format: Format, width: u32, height: u32) -> ImageId {
        let image = self.graph.create_image(name, ImageInfo::new(width, height, format));
        let desc = BufferDesc {
            name: format!("{name} readback"),
            size: u64::from(width * height) * texel_bytes(format),
            usage: BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuToCpu,
        };
        let buffer = Arc::new(Buffer::new(self.ctx, desc).expect("readback buffer"));
        self.outputs.push((image, buffer, format, width, height));
        image
    }

    /// Runs the frame; the outputs in the order they were declared.
    pub fn run(mut self) -> Vec<Texels> {
        let copies = self
            .outputs
            .iter()
            .map(|(image, buffer, ..)| (*image, self.graph.import_buffer(buffer.clone())))
            .collect();
        self.graph.read_back_images("readback", copies);
        let mut baked = self.graph.bake(self.ctx).expect("bake");
        let mut frames = FrameRing::new(self.ctx).expect("frames");
        frames.wait_for_next().expect("frame");
        baked.execute(&mut frames, &(), &[]).expect("execute");
        baked.finish(&mut frames).expect("finish");
        self.outputs
            .iter()
            .map(|(_, buffer, format, w, h)| decode(*format, buffer.mapped().expect("mapped"), *w, *h))
            .collect()
    }
}

/// Synthetic texels of a view's image of `format` (as fetched): HDR
/// radiance over eight decades (RGBA32F), view depth with a tenth sky
/// (R32F), normals exact in f16 (RGBA16F), motion in pixels (RG32F).
pub fn synthetic(format: Format, salt: u32, (w, h): (u32, u32)) -> Plane<[f32; 4]> {
    Plane::from_fn(w, h, |x, y| {
        let r = |k: u32| hash(x, y, 4 * salt + k);
        let v = match format {
            Format::R32G32B32A32_SFLOAT => [r(0), r(1), r(2), 1.0].map(|u| 10f32.powf(8.0 * u - 3.0)),
            Format::R32_SFLOAT if r(0) < 0.1 => [f32::INFINITY; 4],
            Format::R32_SFLOAT => [1.0 + 5000.0 * r(1); 4],
            Format::R16G16B16A16_SFLOAT => [r(0), r(1), r(2), 0.0].map(|u| (u * 64.0).floor() / 32.0 - 1.0),
            _ => [r(0) * 80.0 - 40.0, r(1) * 60.0 - 30.0, 0.0, 0.0],
        };
        as_fetched(format, v)
    })
}

/// A deterministic hash of (x, y, salt) in [0, 1).
pub fn hash(x: u32, y: u32, salt: u32) -> f32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ salt.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Float planes agree to `tolerance` relative (to the larger of the
/// expected magnitude and `floor`); returns the largest relative error.
pub fn assert_close(what: &str, gpu: &Plane<[f32; 4]>, cpu: &Plane<[f32; 4]>, tolerance: f32, floor: f32) -> f32 {
    assert_eq!((gpu.width, gpu.height), (cpu.width, cpu.height), "{what}: size");
    let mut worst = 0.0f32;
    for (n, (g, c)) in gpu.texels.iter().zip(&cpu.texels).enumerate() {
        for k in 0..4 {
            if g[k] == c[k] {
                continue;
            }
            let error = (g[k] - c[k]).abs() / c[k].abs().max(floor);
            assert!(
                error <= tolerance,
                "{what}: texel ({}, {}) channel {k}: GPU {} vs CPU {} (relative {error})",
                n as u32 % gpu.width,
                n as u32 / gpu.width,
                g[k],
                c[k]
            );
            worst = worst.max(error);
        }
    }
    worst
}
