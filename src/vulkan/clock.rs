//! Calibrated timestamps: the device's timestamp clock read together with
//! the CPU's (`VK_EXT_calibrated_timestamps`, or its promotion
//! `VK_KHR_calibrated_timestamps`), so that GPU timestamps can be placed
//! on the CPU clock of the profile and the trace ([`std::time::Instant`]).
//!
//! `Instant` is `CLOCK_MONOTONIC` on Linux and Android; elsewhere (or when
//! the device cannot calibrate against it) there is no calibration and the
//! trace says so.

use std::ffi::CStr;
use std::time::{Duration, Instant};

use ash::vk;

/// A GPU timestamp and the CPU instant it was taken at.
#[derive(Clone, Copy, Debug)]
pub struct Calibration {
    /// The device's timestamp, in ticks.
    pub gpu_ticks: u64,
    /// The CPU instant of `gpu_ticks`.
    pub cpu: Instant,
    /// Nanoseconds per tick.
    pub period_ns: f64,
}

impl Calibration {
    /// The CPU instant of GPU timestamp `ticks` (of the same device).
    pub fn instant_of(&self, ticks: u64) -> Instant {
        let delta_ns = (ticks as i128 - self.gpu_ticks as i128) as f64 * self.period_ns;
        offset(self.cpu, delta_ns)
    }
}

/// `at` moved by `ns` nanoseconds (either way; saturating at what
/// `Instant` can hold).
fn offset(at: Instant, ns: f64) -> Instant {
    let d = Duration::from_nanos(ns.abs().min(u64::MAX as f64) as u64);
    match ns >= 0.0 {
        true => at.checked_add(d).unwrap_or(at),
        false => at.checked_sub(d).unwrap_or(at),
    }
}

/// The host time domain `Instant` runs on, where known.
#[cfg(any(target_os = "linux", target_os = "android"))]
const HOST_DOMAIN: Option<vk::TimeDomainKHR> = Some(vk::TimeDomainKHR::CLOCK_MONOTONIC);
#[cfg(not(any(target_os = "linux", target_os = "android")))]
const HOST_DOMAIN: Option<vk::TimeDomainKHR> = None;

/// `CLOCK_MONOTONIC` now, in nanoseconds.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn monotonic_ns() -> Option<u64> {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid, writable timespec for the duration of the call.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
    (rc == 0).then(|| t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64)
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn monotonic_ns() -> Option<u64> {
    None
}

/// The `Instant` of host clock reading `host_ns` (`CLOCK_MONOTONIC`): a
/// reading between two `Instant`s taken back to back (tens of nanoseconds
/// apart) stands for their midpoint.
fn instant_of_host(host_ns: u64) -> Option<Instant> {
    let before = Instant::now();
    let mono = monotonic_ns()?;
    let now = before + (Instant::now() - before) / 2;
    Some(offset(now, host_ns as f64 - mono as f64))
}

/// Which calibrated-timestamps extension `physical` offers (the EXT
/// first: validation layers before 1.3.275 do not know the KHR) with a
/// time domain `Instant` runs on; None without one.
pub(crate) fn offered(
    entry: &ash::Entry,
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
) -> Option<&'static CStr> {
    let host = HOST_DOMAIN?;
    // SAFETY: plain query on a physical device of this instance.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.ok()?;
    let has = |name: &CStr| extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
    let domains = if has(ash::ext::calibrated_timestamps::NAME) {
        let ext = ash::ext::calibrated_timestamps::Instance::new(entry, instance);
        // SAFETY: the device offers the extension; plain query.
        let domains = unsafe { ext.get_physical_device_calibrateable_time_domains(physical) };
        domains.ok().map(|d| (ash::ext::calibrated_timestamps::NAME, d))
    } else if has(ash::khr::calibrated_timestamps::NAME) {
        let ext = ash::khr::calibrated_timestamps::Instance::new(entry, instance);
        // SAFETY: as above.
        let domains = unsafe { ext.get_physical_device_calibrateable_time_domains(physical) };
        domains.ok().map(|d| (ash::khr::calibrated_timestamps::NAME, d))
    } else {
        None
    };
    let (name, domains) = domains?;
    (domains.contains(&vk::TimeDomainKHR::DEVICE) && domains.contains(&host)).then_some(name)
}

/// Reads the device and host clocks together.
pub(crate) struct GpuClock {
    get: vk::PFN_vkGetCalibratedTimestampsKHR,
    device: vk::Device,
    host: vk::TimeDomainKHR,
    period_ns: f64,
}

impl GpuClock {
    /// The clock of `device`, created with extension `name` (from [`offered`]).
    pub(crate) fn new(instance: &ash::Instance, device: &ash::Device, name: &CStr, period_ns: f32) -> Option<GpuClock> {
        let get = if name == ash::ext::calibrated_timestamps::NAME {
            ash::ext::calibrated_timestamps::Device::new(instance, device)
                .fp()
                .get_calibrated_timestamps_ext
        } else {
            ash::khr::calibrated_timestamps::Device::new(instance, device)
                .fp()
                .get_calibrated_timestamps_khr
        };
        Some(GpuClock {
            get,
            device: device.handle(),
            host: HOST_DOMAIN?,
            period_ns: f64::from(period_ns),
        })
    }

    /// The device's timestamp now and its CPU instant (no allocation);
    /// None if the driver fails to read them.
    pub(crate) fn calibrate(&self) -> Option<Calibration> {
        let infos = [
            vk::CalibratedTimestampInfoKHR::default().time_domain(vk::TimeDomainKHR::DEVICE),
            vk::CalibratedTimestampInfoKHR::default().time_domain(self.host),
        ];
        let mut values = [0u64; 2];
        let mut deviation = 0u64;
        // SAFETY: the extension was enabled on this live device and both
        // domains were reported calibrateable; the arrays hold `infos.len()`
        // values and outlive the call.
        let result = unsafe {
            (self.get)(
                self.device,
                infos.len() as u32,
                infos.as_ptr(),
                values.as_mut_ptr(),
                &mut deviation,
            )
        };
        if result != vk::Result::SUCCESS {
            return None;
        }
        Some(Calibration {
            gpu_ticks: values[0],
            cpu: instant_of_host(values[1])?,
            period_ns: self.period_ns,
        })
    }
}

impl super::Context {
    /// The device's timestamp clock now, in nanoseconds (ticks times the
    /// period), where timestamps are calibrated; None otherwise.
    pub(crate) fn gpu_time_ns(&self) -> Option<i64> {
        let c = self.shared.clock.as_ref()?.calibrate()?;
        Some((c.gpu_ticks as f64 * c.period_ns) as i64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_map_either_side_of_the_calibration() {
        let cpu = Instant::now();
        let c = Calibration {
            gpu_ticks: 1_000,
            cpu,
            period_ns: 2.0,
        };
        assert_eq!(c.instant_of(1_500) - cpu, Duration::from_nanos(1_000));
        assert_eq!(cpu - c.instant_of(500), Duration::from_nanos(1_000));
    }

    #[cfg(any(target_os = "linux", target_os = "android"))]
    #[test]
    fn the_host_domain_is_the_clock_of_instant() {
        let before = Instant::now();
        let at = instant_of_host(monotonic_ns().unwrap()).unwrap();
        let after = Instant::now();
        assert!(at >= before - Duration::from_micros(50) && at <= after + Duration::from_micros(50));
    }
}
