//! Readback of a view's simulator AOVs (`crate::view::aov`): world normal,
//! class and instance ids, motion and distance, into per-frame host buffers
//! and out of them into [`super::FrameImages`].

use std::sync::Arc;

use crate::error::Result;
use crate::graph::{BufferId, ImageId, RenderGraph};
use crate::view::{pass_name, Frame, SceneTargets, View};
use crate::vulkan::{Buffer, Context};

/// The AOVs of one frame in host memory.
pub(super) struct AovImages {
    pub normal: Vec<f32>,
    pub class: Vec<u32>,
    pub instance: Vec<u32>,
    pub motion: Vec<f32>,
    pub distance: Vec<f32>,
}

/// One readback buffer per frame slot for each AOV image.
pub(super) struct AovReadback {
    normal: Vec<Arc<Buffer>>,
    ids: Vec<Arc<Buffer>>,
    motion: Vec<Arc<Buffer>>,
    distance: Vec<Arc<Buffer>>,
}

impl AovReadback {
    /// The buffers of `targets`' AOVs, imported into `graph`, and their
    /// copies added to `copies`.
    pub(super) fn declare(
        ctx: &Context,
        graph: &mut RenderGraph<Frame>,
        view: &View,
        targets: &SceneTargets,
        copies: &mut Vec<(ImageId, BufferId)>,
    ) -> Result<AovReadback> {
        let pixels = u64::from(targets.width) * u64::from(targets.height);
        let buffers = |what: &str, size| super::readback::host_buffers(ctx, &pass_name(what, &view.name), size);
        let rb = AovReadback {
            normal: buffers("world normal", pixels * 8)?,
            ids: buffers("class and instance", pixels * 8)?,
            motion: buffers("motion", pixels * 8)?,
            distance: buffers("distance", pixels * 4)?,
        };
        for (image, buffers) in [
            (targets.normal, &rb.normal),
            (targets.ids, &rb.ids),
            (targets.motion, &rb.motion),
            (targets.distance, &rb.distance),
        ] {
            copies.push((image, graph.import_buffers_per_frame(buffers.clone())));
        }
        Ok(rb)
    }

    /// The AOVs of frame slot `slot` (its frame has completed).
    pub(super) fn read(&self, slot: usize) -> Result<AovImages> {
        let halves: Vec<u16> = bytemuck::pod_collect_to_vec(self.normal[slot].mapped()?);
        let normal = halves
            .chunks_exact(4)
            .flat_map(|n| [n[0], n[1], n[2]].map(f16_to_f32))
            .collect();
        let ids: Vec<u32> = bytemuck::pod_collect_to_vec(self.ids[slot].mapped()?);
        Ok(AovImages {
            normal,
            class: ids.iter().step_by(2).copied().collect(),
            instance: ids.iter().skip(1).step_by(2).copied().collect(),
            motion: bytemuck::pod_collect_to_vec(self.motion[slot].mapped()?),
            distance: bytemuck::pod_collect_to_vec(self.distance[slot].mapped()?),
        })
    }
}

/// An IEEE 754 half (binary16) as f32 (exact).
fn f16_to_f32(h: u16) -> f32 {
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
    use super::f16_to_f32;

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
}
