//! The EXR of a rendered frame: linear `R,G,B,A`, view-space depth `Z`,
//! the lighting AOVs, `W` with points, and the simulator AOVs
//! (see [`alpenglow::FrameImages`]): `distance`, `N.X, N.Y, N.Z`, `class` and
//! `instance` (32-bit unsigned integer channels, exact), `motion.X`,
//! `motion.Y`.

use alpenglow::files::{encode_exr_samples, ExrSamples};
use alpenglow::FrameImages;

/// Every other value of `values` from the `k`-th of each group of `n`.
fn channel(values: &[f32], n: usize, k: usize) -> Vec<f32> {
    values.iter().skip(k).step_by(n).copied().collect()
}

/// The OpenEXR file of `images` with every channel.
pub(super) fn encode_frame_exr(images: &FrameImages) -> alpenglow::Result<Vec<u8>> {
    let (sun, sky) = (images.visibility_channel(0), images.visibility_channel(1));
    let normal: Vec<Vec<f32>> = (0..3).map(|k| channel(&images.normal, 3, k)).collect();
    let motion: Vec<Vec<f32>> = (0..2).map(|k| channel(&images.motion, 2, k)).collect();
    let mut extra = vec![
        ("sun_visibility", ExrSamples::F32(&sun)),
        ("sky_visibility", ExrSamples::F32(&sky)),
        ("distance", ExrSamples::F32(&images.distance)),
        ("N.X", ExrSamples::F32(&normal[0])),
        ("N.Y", ExrSamples::F32(&normal[1])),
        ("N.Z", ExrSamples::F32(&normal[2])),
        ("class", ExrSamples::U32(&images.class)),
        ("instance", ExrSamples::U32(&images.instance)),
        ("motion.X", ExrSamples::F32(&motion[0])),
        ("motion.Y", ExrSamples::F32(&motion[1])),
    ];
    extra.extend(images.weight.iter().map(|w| ("W", ExrSamples::F32(w))));
    encode_exr_samples((images.width, images.height), (&images.hdr, &images.depth), &extra)
}
