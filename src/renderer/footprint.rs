//! The renderer's part of the memory model ([`crate::budget`]): what a
//! frame's views, the height field and the point instances need, checked
//! in [`super::Renderer::new`] against the device's limits before anything
//! is allocated, with an error naming the setting at fault (`width/height`,
//! `msaa`, `views`, `height field`, `point instances`).

use crate::budget::{Footprint, MemoryLimits};
use crate::error::Result;
use crate::io::heightmap::{HEIGHT_DEVICE_BYTES, HEIGHT_HOST_BYTES};
use crate::points::render::gpu_layout::INSTANCE_BYTES;
use crate::post::resolve::supersampled_size;
use crate::view::rig::ViewSpec;
use crate::view::TargetFormats;
use crate::vulkan::{Format, FRAMES_IN_FLIGHT};

/// Bytes per texel of the scene targets' formats.
fn texel_bytes(format: Format) -> u64 {
    match format {
        Format::R32G32B32A32_SFLOAT | Format::R32G32B32A32_UINT => 16,
        Format::R16G16B16A16_SFLOAT | Format::R32G32_SFLOAT | Format::R32G32_UINT => 8,
        Format::R8_UNORM => 1,
        _ => 4,
    }
}

/// Device bytes per pixel of one view's scene targets
/// ([`crate::view::SceneTargets`], 64 B), with the splat weight and the EWA
/// accumulation targets (two RGBA32F) when the scene has points (100 B).
pub fn target_bytes_per_pixel(points: bool) -> u64 {
    let f = TargetFormats::default();
    let base = [
        f.radiance,
        f.view_depth,
        f.depth,
        f.display,
        f.visibility,
        f.normal,
        f.ids,
        f.motion,
        f.distance,
    ]
    .map(texel_bytes)
    .iter()
    .sum::<u64>();
    match points {
        true => base + texel_bytes(f.weight) + 2 * texel_bytes(f.accumulation),
        false => base,
    }
}

/// Host-visible bytes per output pixel of one frame slot's readback
/// buffers (`readback.rs`): HDR 16, depth 4, sRGB 4,
/// lighting visibility 8, normal 8, class and instance 8, motion 8,
/// distance 4, splat weight 4.
pub const READBACK_BYTES_PER_PIXEL: u64 = 64;

/// Host bytes per output pixel of a [`super::FrameImages`] (the frame read
/// back into vectors): rgba8 4, hdr 16, depth 4, weight 4, visibility 8,
/// normal 12, class 4, instance 4, motion 8, distance 4.
pub const FRAME_IMAGES_BYTES_PER_PIXEL: u64 = 68;

/// What one `width`×`height` output view rendered at `render` size needs:
/// the scene targets at the render size, again at the output size where
/// it differs (the resolve's targets), and with `readback` (the slot count) a host-visible
/// buffer set per frame in flight and the frame's copy in vectors. The
/// largest single allocation is an RGBA32F image or buffer.
pub fn view_footprint(output: (u32, u32), render: (u32, u32), points: bool, readback: Option<usize>) -> Footprint {
    let pixels = |(w, h): (u32, u32)| u64::from(w) * u64::from(h);
    let (out, rendered) = (pixels(output), pixels(render));
    let per_pixel = target_bytes_per_pixel(points);
    let mut device = rendered.saturating_mul(per_pixel);
    if render != output {
        device = device.saturating_add(out.saturating_mul(per_pixel));
    }
    let largest = rendered.max(out).saturating_mul(16);
    let mut footprint = Footprint::device(device, largest);
    if let Some(slots) = readback {
        let slots = slots as u64;
        footprint = footprint.plus(Footprint::host(
            out.saturating_mul(READBACK_BYTES_PER_PIXEL * slots + FRAME_IMAGES_BYTES_PER_PIXEL),
        ));
    }
    footprint
}

/// Device bytes of `instances` point instances drawn into `views` views:
/// a record ([`INSTANCE_BYTES`]) in the draw and in the shadow casters'
/// upload region per view and frame in flight.
pub fn instances_footprint(instances: usize, views: usize) -> Footprint {
    let per_instance = 2 * INSTANCE_BYTES * views as u64 * FRAMES_IN_FLIGHT as u64;
    Footprint::per_item(instances as u64, 0, per_instance)
}

/// Checks the views `specs` rendered with `msaa` samples per pixel (and
/// `readback`) against `limits`. The error names `msaa` when the views
/// would fit without it, `views` for a rig, else `width/height`; the
/// message says the sizes, the estimate and the limit.
pub fn check_views(
    limits: &MemoryLimits,
    specs: &[ViewSpec],
    msaa: u32,
    points: bool,
    readback: Option<usize>,
) -> Result<()> {
    let total = |samples: u32| -> Result<Footprint> {
        specs.iter().try_fold(Footprint::default(), |sum, v| {
            let render = supersampled_size(v.width, v.height, samples)?;
            Ok(sum.plus(view_footprint((v.width, v.height), render, points, readback)))
        })
    };
    let footprint = total(msaa)?;
    if limits.fits(footprint) {
        return Ok(());
    }
    let sizes = match specs {
        [v] => format!("{}×{} pixels", v.width, v.height),
        _ => format!("{} views of {} pixels in all", specs.len(), {
            specs
                .iter()
                .map(|v| u64::from(v.width) * u64::from(v.height))
                .sum::<u64>()
        }),
    };
    if msaa > 1 && limits.fits(total(1)?) {
        return limits.check("msaa", &format!("{sizes} at {msaa} samples per pixel"), footprint);
    }
    let option = if specs.len() > 1 { "views" } else { "width/height" };
    limits.check(option, &sizes, footprint)
}

/// Checks the height field of `samples` samples and `instances` point
/// instances drawn into `views` views against `limits`.
pub fn check_scene(limits: &MemoryLimits, (columns, rows): (u32, u32), instances: usize, views: usize) -> Result<()> {
    let samples = u64::from(columns) * u64::from(rows);
    let heights =
        Footprint::per_item(samples, HEIGHT_HOST_BYTES, HEIGHT_DEVICE_BYTES).plus(Footprint::device(0, samples * 4));
    limits.check("height field", &format!("{columns}×{rows} height samples"), heights)?;
    limits.check(
        "point instances",
        &format!("{instances} point instances in {views} views"),
        instances_footprint(instances, views),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(device_mib: u64) -> MemoryLimits {
        MemoryLimits {
            host: 64 << 30,
            device: device_mib << 20,
            device_allocation: device_mib << 20,
        }
    }

    #[test]
    fn per_pixel_bytes_follow_the_target_formats() {
        assert_eq!(target_bytes_per_pixel(false), 64);
        assert_eq!(target_bytes_per_pixel(true), 100);
        let f = view_footprint((100, 50), (100, 50), false, Some(2));
        assert_eq!(f.device, 5000 * 64);
        assert_eq!(f.device_allocation, 5000 * 16);
        assert_eq!(f.host, 5000 * (64 * 2 + 68));
        // Supersampled: the render targets and the output's again.
        let f = view_footprint((100, 50), (400, 200), true, None);
        assert_eq!((f.device, f.host), ((80_000 + 5000) * 100, 0));
        assert_eq!(f.device_allocation, 80_000 * 16);
    }

    #[test]
    fn the_error_names_the_size_the_samples_or_the_rig() {
        let one = |w, h| vec![ViewSpec::new(w, h)];
        assert!(check_views(&limits(64), &one(640, 480), 1, true, Some(2)).is_ok());
        // 1024² RGBA32F is 16 MiB in one allocation.
        let e = check_views(&limits(8), &one(1024, 1024), 1, false, None).unwrap_err();
        assert_eq!(e.parameter(), Some("width/height"));
        let text = e.to_string();
        assert!(
            text.contains("1024×1024 pixels need a single GPU allocation of about 16.0 MiB"),
            "{text}"
        );
        assert!(text.contains("at most 8.0 MiB"), "{text}");
        // Fits alone, not supersampled 16 times.
        let e = check_views(&limits(64), &one(512, 512), 16, true, None).unwrap_err();
        assert_eq!(e.parameter(), Some("msaa"));
        assert!(e.to_string().contains("512×512 pixels at 16 samples per pixel"), "{e}");
        // Six views that fit one by one, not together.
        let rig: Vec<ViewSpec> = (0..6).map(|_| ViewSpec::new(512, 512)).collect();
        let e = check_views(&limits(64), &rig, 1, true, None).unwrap_err();
        assert_eq!(e.parameter(), Some("views"));
        assert!(
            e.to_string().contains("6 views of 1572864 pixels in all need about"),
            "{e}"
        );
    }

    #[test]
    fn the_largest_legal_image_fits_a_device_that_can_take_it() {
        // 16384² with readback on a device with 64 GiB and 4 GiB allocations.
        let big = MemoryLimits {
            host: 64 << 30,
            device: 64 << 30,
            device_allocation: 4 << 30,
        };
        assert!(check_views(&big, &[ViewSpec::new(16384, 16384)], 1, true, Some(2)).is_ok());
        // lavapipe allows 2 GiB in one allocation: 11585² fits, 11586² does not.
        let lavapipe = MemoryLimits {
            device_allocation: 2 << 30,
            ..big
        };
        assert!(check_views(&lavapipe, &[ViewSpec::new(11585, 11585)], 1, true, Some(2)).is_ok());
        let e = check_views(&lavapipe, &[ViewSpec::new(11586, 11586)], 1, true, Some(2)).unwrap_err();
        assert!(
            e.to_string()
                .contains("11586×11586 pixels need a single GPU allocation"),
            "{e}"
        );
    }

    #[test]
    fn height_fields_and_instances_are_bounded() {
        assert!(check_scene(&limits(64), (513, 513), 300, 1).is_ok());
        let e = check_scene(&limits(64), (8193, 8193), 0, 1).unwrap_err();
        assert_eq!(e.parameter(), Some("height field"));
        assert!(e.to_string().contains("8193×8193 height samples need"), "{e}");
        let e = check_scene(&limits(64), (513, 513), 10_000_000, 6).unwrap_err();
        assert_eq!(e.parameter(), Some("point instances"));
    }
}
