//! One memory model: what an option's count or size costs in host and device
//! memory, checked *before* anything is allocated.
//!
//! Every option or file count that scales memory turns into a [`Footprint`]
//! through the estimate of the module that allocates it; the footprint is
//! checked against [`MemoryLimits`] with [`MemoryLimits::check`], which gives
//! a one-line error naming the option, the estimate and the limit:
//!
//! ```text
//! invalid --rocks: 100000000 boulders need about 177.0 GiB of host memory; 22.5 GiB is available
//! ```
//!
//! The estimates, each derived from the data structures it counts (see the
//! constants' docs) and checked where the count is first known:
//!
//! | count | estimate | checked in |
//! |---|---|---|
//! | boulders (`--rocks`) | 1.9 kB each, measured at a render's peak | `Scene::add_rocks` |
//! | plants (`--vegetation-density`) | at most 10¹² asked for; the kept ones as boulders | `Scene::add_vegetation` |
//! | mesh samples (`--samples`, `--points-samples`) | ≈ 550 B blue noise, ≈ 200 B stratified | `sampling::sample_mesh`, the CLI before sampling |
//! | height samples (`--terrain`, `--heightmap`) | 8 B host, 8 B device (4 B in one allocation) | `ProceduralTerrain::try_generate`, `InputLimits::check_image_fits`, `Renderer::new` |
//! | pixels × `--msaa` × views | 64–100 B device per rendered pixel, 16 B in one allocation, 64 B host readback per output pixel and readback slot + 68 B for the owned copy | `renderer::footprint::check_views` in `Renderer::new` |
//! | point instances × views | two 96 B records per view and frame in flight | `renderer::footprint::check_scene` |
//!
//! Time has a ceiling of its own: long CPU work (synthesis, SPT builds)
//! estimates its seconds from operation counts at measured rates and
//! [`check_duration`] refuses an estimate above the command's
//! `--max-hours` (default [`DEFAULT_MAX_HOURS`]) the same way.
//!
//! Host memory is what `/proc/meminfo` calls `MemAvailable` (or
//! [`HOST_MEMORY_ENV`], `ALPENGLOW_HOST_MEMORY_MB`, when set, for tests and
//! for sharing a machine). Device memory comes from the device through
//! `Context::memory_limits`: the largest device-local heap
//! (`VkPhysicalDeviceMemoryProperties`, its budget with `VK_EXT_memory_budget`
//! where offered) and the largest single allocation (`maxMemoryAllocationSize`,
//! `maxBufferSize`, the heap), both capped by [`DEVICE_MEMORY_ENV`]
//! (`ALPENGLOW_DEVICE_MEMORY_MB`) when set. lavapipe allows 2 GiB in one
//! allocation, so its largest image is 11585² (the RGBA32F radiance target,
//! 16 B a pixel).

use crate::error::{Error, Result};

/// Host and device bytes an operation is estimated to need at its peak.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Footprint {
    /// Bytes of host (CPU) memory.
    pub host: u64,
    /// Bytes of device-local (GPU) memory.
    pub device: u64,
    /// Bytes of the largest single device allocation (an image or a
    /// buffer), checked against the device's `maxMemoryAllocationSize` and
    /// `maxBufferSize`.
    pub device_allocation: u64,
}

impl Footprint {
    /// `bytes` of host memory only.
    pub fn host(bytes: u64) -> Footprint {
        Footprint {
            host: bytes,
            ..Footprint::default()
        }
    }

    /// `bytes` of device memory only, in allocations of at most
    /// `largest` bytes each.
    pub fn device(bytes: u64, largest: u64) -> Footprint {
        Footprint {
            device: bytes,
            device_allocation: largest,
            ..Footprint::default()
        }
    }

    /// `count` items of `host_each` and `device_each` bytes, saturating.
    pub fn per_item(count: u64, host_each: u64, device_each: u64) -> Footprint {
        Footprint {
            host: count.saturating_mul(host_each),
            device: count.saturating_mul(device_each),
            device_allocation: 0,
        }
    }

    /// The sum of two footprints, saturating (the larger of the two
    /// largest allocations).
    pub fn plus(self, other: Footprint) -> Footprint {
        Footprint {
            host: self.host.saturating_add(other.host),
            device: self.device.saturating_add(other.device),
            device_allocation: self.device_allocation.max(other.device_allocation),
        }
    }

    /// `count` times this footprint, saturating (the largest allocation
    /// stays as it is).
    pub fn times(self, count: u64) -> Footprint {
        Footprint {
            host: self.host.saturating_mul(count),
            device: self.device.saturating_mul(count),
            device_allocation: self.device_allocation,
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

/// Environment variable that caps the device memory (the heap and the
/// largest single allocation) below what the device reports, in MiB: for
/// tests of the bounds without huge images, and for sharing a GPU.
pub const DEVICE_MEMORY_ENV: &str = "ALPENGLOW_DEVICE_MEMORY_MB";

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
            return Err(Error::invalid(option, {
                let (need, have) = estimate_and_limit(footprint.host, self.host);
                format!("{what} need about {need} of host memory; {have} is available")
            }));
        }
        if footprint.device_allocation > self.device_allocation {
            return Err(Error::invalid(option, {
                let (need, have) = estimate_and_limit(footprint.device_allocation, self.device_allocation);
                format!("{what} need a single GPU allocation of about {need}; the device allows at most {have} in one")
            }));
        }
        if footprint.device > self.device {
            return Err(Error::invalid(option, {
                let (need, have) = estimate_and_limit(footprint.device, self.device);
                format!("{what} need about {need} of GPU memory; the device has {have}")
            }));
        }
        Ok(())
    }

    /// Whether `footprint` fits these limits.
    pub fn fits(&self, footprint: Footprint) -> bool {
        self.check("", "", footprint).is_ok()
    }

    /// These limits with the device side capped by
    /// `DEVICE_MEMORY_ENV` when it is set.
    pub fn with_device_override(self) -> MemoryLimits {
        match env_mib(DEVICE_MEMORY_ENV) {
            Some(cap) => MemoryLimits {
                device: self.device.min(cap),
                device_allocation: self.device_allocation.min(cap),
                ..self
            },
            None => self,
        }
    }
}

/// An environment variable's value in MiB, in bytes.
fn env_mib(name: &str) -> Option<u64> {
    let mib = std::env::var(name).ok()?.trim().parse::<u64>().ok()?;
    Some(mib.saturating_mul(1 << 20))
}

/// Bytes of host memory available: `ALPENGLOW_HOST_MEMORY_MB` when set,
/// else `MemAvailable` of `/proc/meminfo`, else 8 GiB.
pub fn host_available_bytes() -> u64 {
    if let Some(bytes) = env_mib(HOST_MEMORY_ENV) {
        return bytes;
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

/// An estimate and its limit for people ([`format_bytes`]), in bytes where
/// the two would read the same ("2.0 GiB" against "2.0 GiB").
fn estimate_and_limit(estimate: u64, limit: u64) -> (String, String) {
    let (a, b) = (format_bytes(estimate), format_bytes(limit));
    match a == b {
        true => (format!("{estimate} B"), format!("{limit} B")),
        false => (a, b),
    }
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

/// The longest a run may be estimated to take unless its command's
/// `--max-hours` says otherwise (synthesis, SPT builds): 1 hour. An
/// estimate beyond it is almost always a typing error (a window or a count
/// ten times too large) or work that wants a GPU, not a run anyone waits
/// for at a terminal; a run that really is meant to take longer says so
/// with the option.
pub const DEFAULT_MAX_HOURS: f64 = 1.0;

/// Checks an estimated duration against a ceiling: a one-line
/// [`Error::InvalidArgument`] naming `option` (the options that drive the
/// cost, e.g. `--window 63, --candidates 1000000`), `what` (the work and the
/// rate it was estimated at), the estimate and the limit, and
/// `limit_option` (the option that raises the limit) when `seconds`
/// exceeds `limit_seconds`. A NaN estimate counts as too long.
pub fn check_duration(option: &str, what: &str, seconds: f64, limit_seconds: f64, limit_option: &str) -> Result<()> {
    if seconds <= limit_seconds {
        return Ok(());
    }
    Err(Error::invalid(
        option,
        format!(
            "{what} takes about {}; the limit is {} ({limit_option} raises it)",
            format_duration(seconds),
            format_duration(limit_seconds)
        ),
    ))
}

/// `seconds` for people: "0.4 s", "12 s", "3.5 min", "2.1 h", "4.0 days",
/// "3.2e6 years".
pub fn format_duration(seconds: f64) -> String {
    const YEAR: f64 = 365.25 * 86400.0;
    if !seconds.is_finite() {
        return "forever".to_string();
    }
    if seconds < 10.0 {
        format!("{seconds:.1} s")
    } else if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.1} min", seconds / 60.0)
    } else if seconds < 2.0 * 86400.0 {
        format!("{:.1} h", seconds / 3600.0)
    } else if seconds < YEAR {
        format!("{:.1} days", seconds / 86400.0)
    } else if seconds < 1e4 * YEAR {
        format!("{:.0} years", seconds / YEAR)
    } else {
        format!("{:.1e} years", seconds / YEAR)
    }
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
            .check(
                "--rocks",
                "100000000 boulders",
                Footprint::per_item(100_000_000, 128, 0),
            )
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "invalid --rocks: 100000000 boulders need about 11.9 GiB of host memory; 1.0 GiB is available"
        );
        let e = limits
            .check("--width", "16384×16384 pixels", Footprint::device(3 << 30, 1 << 30))
            .unwrap_err()
            .to_string();
        assert!(e.contains("3.0 GiB of GPU memory; the device has 2.0 GiB"), "{e}");
        let e = limits
            .check("--width", "16384×16384 pixels", Footprint::device(1 << 30, 4 << 30))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a single GPU allocation of about 4.0 GiB; the device allows at most 1.0 GiB in one"),
            "{e}"
        );
        assert!(limits.fits(Footprint::device(2 << 30, 1 << 30)));
        // Estimates that would read as their limit are said in bytes.
        let e = limits
            .check(
                "--width",
                "11586×11586 pixels",
                Footprint::device(1 << 30, (1 << 30) + 4096),
            )
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("about 1073745920 B; the device allows at most 1073741824 B in one"),
            "{e}"
        );
        assert_eq!(
            Footprint::device(5, 3).plus(Footprint::device(1, 4)).times(2),
            Footprint::device(12, 4)
        );
    }

    #[test]
    fn durations_read_as_people_write_them() {
        assert_eq!(format_duration(0.42), "0.4 s");
        assert_eq!(format_duration(75.0), "75 s");
        assert_eq!(format_duration(210.0), "3.5 min");
        assert_eq!(format_duration(7560.0), "2.1 h");
        assert_eq!(format_duration(4.0 * 86400.0), "4.0 days");
        assert_eq!(format_duration(1e15), "3.2e7 years");
        assert_eq!(format_duration(f64::INFINITY), "forever");
    }

    #[test]
    fn check_duration_names_options_estimate_and_limit() {
        assert!(check_duration("--window", "x", 3600.0, 7200.0, "--max-hours").is_ok());
        let e = check_duration(
            "--window 63, --candidates 1000000",
            "growing 400 samples",
            9000.0,
            7200.0,
            "--max-hours",
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "invalid --window 63, --candidates 1000000: growing 400 samples takes about 2.5 h; \
             the limit is 2.0 h (--max-hours raises it)"
        );
        assert!(check_duration("--x", "y", f64::NAN, 1.0, "--max-hours").is_err());
    }
}
