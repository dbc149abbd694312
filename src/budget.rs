//! One memory model: what an option's count or size costs in host and device
//! memory, checked *before* anything is allocated.
//!
//! Every option or file count that scales memory (rocks, plants, SPT
//! samples, image size × MSAA × views, rig views, synthesis windows and
//! candidates, DEM samples) turns into a [`Footprint`] through the estimate
//! functions of the module that allocates it; the footprint is checked
//! against [`MemoryLimits`] with [`MemoryLimits::check`], which gives a
//! one-line error naming the option, the estimate and the limit:
//!
//! ```text
//! invalid --rocks: 100000000 boulders need about 12.0 GiB of host memory; 9.7 GiB is available
//! ```
//!
//! Host memory is what `/proc/meminfo` calls `MemAvailable` (or
//! `ALPENGLOW_HOST_MEMORY_MB` when set, for tests and for sharing a machine);
//! device memory comes from the device's heaps
//! (`VkPhysicalDeviceMemoryProperties`, and `VK_EXT_memory_budget` where
//! offered) through the Vulkan context.

use crate::error::{Error, Result};

/// Host and device bytes an operation is estimated to need at its peak.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Footprint {
    /// Bytes of host (CPU) memory.
    pub host: u64,
    /// Bytes of device-local (GPU) memory.
    pub device: u64,
}

impl Footprint {
    /// `bytes` of host memory only.
    pub fn host(bytes: u64) -> Footprint {
        Footprint { host: bytes, device: 0 }
    }

    /// `bytes` of device memory only.
    pub fn device(bytes: u64) -> Footprint {
        Footprint { host: 0, device: bytes }
    }

    /// `count` items of `host_each` and `device_each` bytes, saturating.
    pub fn per_item(count: u64, host_each: u64, device_each: u64) -> Footprint {
        Footprint {
            host: count.saturating_mul(host_each),
            device: count.saturating_mul(device_each),
        }
    }

    /// The sum of two footprints, saturating.
    pub fn plus(self, other: Footprint) -> Footprint {
        Footprint {
            host: self.host.saturating_add(other.host),
            device: self.device.saturating_add(other.device),
        }
    }
}

/// What this machine and device can take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryLimits {
    /// Bytes of host memory available.
    pub host: u64,
    /// Bytes of device memory available (the largest device-local heap's
    /// budget); `u64::MAX` where no device is known yet.
    pub device: u64,
    /// Largest single device allocation (`maxMemoryAllocationSize`, and the
    /// heap's size); `u64::MAX` where no device is known yet.
    pub device_allocation: u64,
}

/// Environment variable that overrides the host memory available, in MiB.
pub const HOST_MEMORY_ENV: &str = "ALPENGLOW_HOST_MEMORY_MB";

impl MemoryLimits {
    /// The host's available memory, with no device known yet.
    pub fn host_only() -> MemoryLimits {
        MemoryLimits {
            host: host_available_bytes(),
            device: u64::MAX,
            device_allocation: u64::MAX,
        }
    }

    /// Checks `footprint` against these limits: a one-line
    /// [`Error::InvalidArgument`] naming `option` (the flag or setting the
    /// user wrote, e.g. `--rocks`), `what` (e.g. "100000000 boulders"), the
    /// estimate and the limit when either side does not fit.
    pub fn check(&self, option: &str, what: &str, footprint: Footprint) -> Result<()> {
        if footprint.host > self.host {
            return Err(Error::invalid(
                option,
                format!(
                    "{what} need about {} of host memory; {} is available",
                    format_bytes(footprint.host),
                    format_bytes(self.host)
                ),
            ));
        }
        if footprint.device > self.device {
            return Err(Error::invalid(
                option,
                format!(
                    "{what} need about {} of GPU memory; the device has {}",
                    format_bytes(footprint.device),
                    format_bytes(self.device)
                ),
            ));
        }
        Ok(())
    }
}

/// Bytes of host memory available: `ALPENGLOW_HOST_MEMORY_MB` when set,
/// else `MemAvailable` of `/proc/meminfo`, else 8 GiB.
pub fn host_available_bytes() -> u64 {
    if let Some(mib) = std::env::var(HOST_MEMORY_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        return mib.saturating_mul(1 << 20);
    }
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| meminfo_field(&text, "MemAvailable:").or_else(|| meminfo_field(&text, "MemTotal:")))
        .unwrap_or(8 << 30)
}

/// The value of `field` (in kB) of a `/proc/meminfo` text, in bytes.
fn meminfo_field(text: &str, field: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line[field.len()..].split_whitespace().next()?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

/// `bytes` for people: "512 B", "3.0 KiB", "12.4 GiB".
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.1} {}", UNITS[unit])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_read_as_people_write_them() {
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(format_bytes(3 << 10), "3.0 KiB");
        assert_eq!(format_bytes(12 << 30), "12.0 GiB");
        assert_eq!(format_bytes(u64::MAX), "16.0 EiB");
    }

    #[test]
    fn meminfo_is_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:   10000000 kB\n";
        assert_eq!(meminfo_field(text, "MemAvailable:"), Some(10_000_000 * 1024));
        assert_eq!(meminfo_field(text, "Missing:"), None);
    }

    #[test]
    fn check_names_option_estimate_and_limit() {
        let limits = MemoryLimits {
            host: 1 << 30,
            device: 2 << 30,
            device_allocation: 1 << 30,
        };
        assert!(limits.check("--rocks", "10 boulders", Footprint::host(1000)).is_ok());
        let e = limits
            .check("--rocks", "100000000 boulders", Footprint::per_item(100_000_000, 128, 0))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "invalid --rocks: 100000000 boulders need about 11.9 GiB of host memory; 1.0 GiB is available"
        );
        let e = limits
            .check("--width", "a 16384×16384 image", Footprint::device(3 << 30))
            .unwrap_err()
            .to_string();
        assert!(e.contains("3.0 GiB of GPU memory; the device has 2.0 GiB"), "{e}");
    }
}
