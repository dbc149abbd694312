//! Up-front cost of pixel growing (`synth fill`, `synth transition`): the
//! work and the memory of a growth from its sizes alone, before anything
//! is planned or allocated, so that an absurd combination (`--window 63
//! --candidates 1000000`, two 8193² fields on the CPU, `--blur 1000000`) is
//! refused with its estimate instead of running silently for hours.
//!
//! # Work
//!
//! With a `W`×`H` field, `U` unknown samples, window side `n` and at most
//! `K = min(--candidates, (W−n+1)·(H−n+1))` candidate windows (the fully
//! known windows are at most all windows inside the field):
//!
//! * the search compares every unknown sample's window with every
//!   candidate: `U·K·n²` candidate·taps, at the search's rate
//!   ([`SearchDevice`]);
//! * the rest of growing builds each sample's query, updates the fill order
//!   and pastes with an offset: about `4·U·n²` taps on one thread;
//! * planning (slopes, channels, distances, the window table, the sort of
//!   the windows) passes over every sample a few times: `W·H` samples;
//! * a transition also blurs the field twice, the base with radius `n` and
//!   the grown band with radius `R` (`--blur`): `2·(2n+1)·W·H` and
//!   `2·(2R+1)·W·H` taps, on one thread.
//!
//! # Rates
//!
//! Measured with release builds on the 2-core AMD EPYC build VM (shared,
//! load average 3–9; docs/PERFORMANCE.md, "Height-field synthesis"):
//!
//! * the CPU twin: [`CPU_TAPS_PER_THREAD_SECOND`] candidate·taps per second
//!   and thread (7.3·10⁸ on both threads filling 64²–256² holes of the
//!   Jacksboro DEM at 1025²; 2.9–3.7·10⁸ in the search benchmark under
//!   heavier load);
//! * the GPU passes on a device that is a CPU (lavapipe):
//!   [`CPU_DEVICE_TAPS_PER_THREAD_SECOND`] (2.0–2.4·10⁸ on both threads);
//! * a real GPU: [`GPU_TAPS_PER_SECOND`], an assumption, not a measurement
//!   (no GPU was lent to this work): optimistic on purpose, so that only
//!   work no GPU finishes in the limit is refused;
//! * the serial parts: [`SERIAL_TAPS_PER_SECOND`] blur or window taps and
//!   [`PLAN_SAMPLES_PER_SECOND`] planned samples per second.
//!
//! # Memory (host)
//!
//! Counted from the allocations alive at the peak, per sample of the field:
//! [`FILL_BYTES_PER_SAMPLE`] for `fill`, [`TRANSITION_BYTES_PER_SAMPLE`]
//! for `transition`; per unknown sample the fill order's buckets
//! ([`BYTES_PER_UNKNOWN`]); one wave's queries, `min(--batch, U)·n²` taps
//! of 16 bytes; the CPU search's distances, 4 bytes per candidate and
//! thread; the GPU search's copy of the exemplar, 16 bytes per sample. The
//! GPU search's device memory: the exemplar (16 bytes per sample), the
//! candidates (4 bytes each), the distances of one batch (at most 64 MiB)
//! and two frames of taps.

use crate::budget::{check_duration, format_bytes, Footprint, MemoryLimits};
use crate::error::{Error, Result};
use crate::synthesis::fill::FillParams;
use crate::synthesis::gpu::GpuSearchLimits;
use crate::synthesis::transition::{Band, TransitionParams};

/// Candidate·taps per second and thread of the CPU twin (module docs).
pub const CPU_TAPS_PER_THREAD_SECOND: f64 = 3.5e8;
/// Candidate·taps per second and thread of the GPU passes on a Vulkan
/// device that is a CPU (lavapipe; module docs).
pub const CPU_DEVICE_TAPS_PER_THREAD_SECOND: f64 = 1.0e8;
/// Candidate·taps per second assumed of a real GPU (module docs: an
/// optimistic assumption, not a measurement).
pub const GPU_TAPS_PER_SECOND: f64 = 1.0e12;
/// Blur and window taps per second of the serial parts (module docs).
pub const SERIAL_TAPS_PER_SECOND: f64 = 1.0e8;
/// Samples per second of planning (module docs).
pub const PLAN_SAMPLES_PER_SECOND: f64 = 1.0e7;
/// Peak host bytes per field sample of `fill` (module docs): the field and
/// mask (5), the state, heights and mask of the growth (9), the channels
/// and the exemplar's copy (24), slopes and distances while planning (12),
/// the window table and candidates (8), the fill order's counts (4), the
/// output's encoding (2–4).
pub const FILL_BYTES_PER_SAMPLE: u64 = 64;
/// Peak host bytes per field sample of `transition` (module docs): A and B
/// (8), the composed field, its mask and residual (9), the base (8, f64),
/// the blur's two f64 passes (16), and planning as for `fill` (49).
pub const TRANSITION_BYTES_PER_SAMPLE: u64 = 90;
/// Host bytes per unknown sample of the fill order's buckets.
pub const BYTES_PER_UNKNOWN: u64 = 24;
/// Bytes of one query tap (h, hx, hy, w as f32).
const TAP_BYTES: u64 = 16;

/// Where the neighbourhood search runs, which decides its rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchDevice {
    /// The CPU twin on `threads` threads.
    Cpu { threads: usize },
    /// The GPU passes on a Vulkan device that is a CPU (lavapipe) with
    /// `threads` threads.
    CpuDevice { threads: usize },
    /// The GPU passes on a real GPU.
    Gpu,
}

impl SearchDevice {
    /// Candidate·taps per second (module docs).
    pub fn taps_per_second(self) -> f64 {
        match self {
            SearchDevice::Cpu { threads } => CPU_TAPS_PER_THREAD_SECOND * threads.max(1) as f64,
            SearchDevice::CpuDevice { threads } => CPU_DEVICE_TAPS_PER_THREAD_SECOND * threads.max(1) as f64,
            SearchDevice::Gpu => GPU_TAPS_PER_SECOND,
        }
    }

    /// The search and its rate in words.
    pub fn describe(self) -> String {
        match self {
            SearchDevice::Cpu { threads } => format!(
                "the CPU search on {threads} thread{} at {:.1e} per second",
                if threads == 1 { "" } else { "s" },
                self.taps_per_second()
            ),
            SearchDevice::CpuDevice { threads } => format!(
                "the GPU search on a CPU device ({threads} thread{}) at {:.1e} per second",
                if threads == 1 { "" } else { "s" },
                self.taps_per_second()
            ),
            SearchDevice::Gpu => format!("the GPU search at an assumed {:.0e} per second", self.taps_per_second()),
        }
    }
}

/// The sizes that decide a growth's cost (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct GrowthCost {
    pub columns: u32,
    pub rows: u32,
    /// Unknown samples to grow.
    pub unknown: u64,
    /// Window side n.
    pub window: u32,
    /// `--candidates` as given.
    pub candidates_asked: u64,
    /// `--batch`.
    pub batch: u64,
    /// Radius of a transition's band blur (`--blur`); None for `fill`.
    pub blur: Option<u32>,
}

/// One part of a cost: the options that drive it, in words, and its seconds.
struct Term {
    options: String,
    what: String,
    seconds: f64,
}

impl GrowthCost {
    /// The cost of filling `unknown` samples of a `columns`×`rows` field.
    pub fn fill(columns: u32, rows: u32, unknown: u64, params: &FillParams) -> GrowthCost {
        GrowthCost {
            columns,
            rows,
            unknown,
            window: params.window,
            candidates_asked: params.candidates as u64,
            batch: params.batch as u64,
            blur: None,
        }
    }

    /// The cost of growing the transition `band` between two
    /// `columns`×`rows` fields.
    pub fn transition(columns: u32, rows: u32, band: &Band, params: &TransitionParams) -> GrowthCost {
        let across = match band.axis {
            crate::synthesis::transition::Axis::X => rows,
            crate::synthesis::transition::Axis::Y => columns,
        };
        GrowthCost {
            blur: Some(params.blur_radius),
            ..GrowthCost::fill(columns, rows, u64::from(band.width) * u64::from(across), &params.grow)
        }
    }

    /// Samples of the field.
    pub fn samples(&self) -> u64 {
        u64::from(self.columns) * u64::from(self.rows)
    }

    /// At most this many candidate windows: `--candidates`, or all windows
    /// inside the field when fewer.
    pub fn candidates(&self) -> u64 {
        let n = u64::from(self.window);
        let inside = |side: u32| (u64::from(side) + 1).saturating_sub(n);
        self.candidates_asked.min(inside(self.columns) * inside(self.rows))
    }

    /// Taps of one window, n².
    fn taps(&self) -> f64 {
        f64::from(self.window) * f64::from(self.window)
    }

    /// Candidate·taps the search compares: U·K·n².
    pub fn search_taps(&self) -> f64 {
        self.unknown as f64 * self.candidates() as f64 * self.taps()
    }

    /// The CPU twin's threads: the machine's, at most one per query of a wave.
    pub fn cpu_threads(&self, machine_threads: usize) -> usize {
        let wave = self.batch.min(self.unknown).max(1);
        machine_threads.clamp(1, usize::try_from(wave).unwrap_or(usize::MAX))
    }

    /// The parts of the cost on `device` (module docs).
    fn terms(&self, device: SearchDevice) -> Vec<Term> {
        let n = self.window;
        let field = self.samples() as f64;
        let mut terms = vec![
            Term {
                options: format!("--window {n}, --candidates {}", self.candidates_asked),
                what: format!(
                    "growing {} samples against at most {} candidate windows of {n}×{n} taps \
                     ({:.1e} comparisons, {})",
                    self.unknown,
                    self.candidates(),
                    self.search_taps(),
                    device.describe()
                ),
                seconds: self.search_taps() / device.taps_per_second(),
            },
            Term {
                options: format!("--window {n}"),
                what: format!("ordering and pasting {} samples with {n}×{n} windows", self.unknown),
                seconds: 4.0 * self.unknown as f64 * self.taps() / SERIAL_TAPS_PER_SECOND,
            },
            Term {
                options: String::new(),
                what: format!("planning the {}×{} field", self.columns, self.rows),
                seconds: field / PLAN_SAMPLES_PER_SECOND,
            },
        ];
        if let Some(radius) = self.blur {
            let kernel = |r: u32| 2.0 * (2.0 * f64::from(r) + 1.0) * field;
            terms.push(Term {
                options: format!("--window {n}"),
                what: format!("blurring the base with radius {n}"),
                seconds: kernel(n) / SERIAL_TAPS_PER_SECOND,
            });
            terms.push(Term {
                options: format!("--blur {radius}"),
                what: format!(
                    "blurring the {}×{} field with radius {radius} ({:.1e} taps)",
                    self.columns,
                    self.rows,
                    kernel(radius)
                ),
                seconds: kernel(radius) / SERIAL_TAPS_PER_SECOND,
            });
        }
        terms
    }

    /// Estimated seconds on `device` (module docs).
    pub fn seconds(&self, device: SearchDevice) -> f64 {
        self.terms(device).iter().map(|t| t.seconds).sum()
    }

    /// Peak host and device memory with the search on `device` (module docs).
    pub fn footprint(&self, device: SearchDevice) -> Footprint {
        let per_sample = if self.blur.is_some() {
            TRANSITION_BYTES_PER_SAMPLE
        } else {
            FILL_BYTES_PER_SAMPLE
        };
        let fields = Footprint::host(self.samples().saturating_mul(per_sample))
            .plus(Footprint::host(self.unknown.saturating_mul(BYTES_PER_UNKNOWN)));
        fields.plus(self.wave_footprint()).plus(self.search_footprint(device))
    }

    /// One wave's queries: min(--batch, U)·n² taps.
    fn wave_footprint(&self) -> Footprint {
        let wave = self.batch.min(self.unknown);
        let taps = u64::from(self.window) * u64::from(self.window);
        Footprint::host(wave.saturating_mul(taps).saturating_mul(TAP_BYTES))
    }

    /// The search's own memory on `device`.
    fn search_footprint(&self, device: SearchDevice) -> Footprint {
        let candidates = self.candidates();
        match device {
            SearchDevice::Cpu { threads } => Footprint::host(
                candidates
                    .saturating_mul(4)
                    .saturating_mul(self.cpu_threads(threads) as u64),
            ),
            SearchDevice::CpuDevice { .. } | SearchDevice::Gpu => {
                let limits = GpuSearchLimits::default();
                let taps = u64::from(self.window) * u64::from(self.window) * TAP_BYTES;
                let row = candidates.max(1).saturating_mul(4);
                let batch = (limits.distance_bytes / row)
                    .clamp(1, u64::from(limits.batch_queries))
                    .min(self.unknown.max(1));
                let exemplar = self.samples().saturating_mul(16);
                let device = exemplar
                    .saturating_add(candidates.saturating_mul(4))
                    .saturating_add(batch.saturating_mul(row))
                    .saturating_add(2 * batch.saturating_mul(taps));
                let largest = exemplar
                    .max(candidates.saturating_mul(4))
                    .max(batch.saturating_mul(row))
                    .max(batch.saturating_mul(taps));
                Footprint {
                    host: exemplar,
                    device,
                    device_allocation: largest,
                }
            }
        }
    }

    /// One line for the log: the estimated seconds and memory on `device`.
    pub fn summary(&self, device: SearchDevice) -> String {
        let f = self.footprint(device);
        let device_memory = if f.device > 0 {
            format!(", {} of GPU memory", format_bytes(f.device))
        } else {
            String::new()
        };
        format!(
            "{} unknown of {}×{} samples, window {}, at most {} candidates: {:.1e} comparisons with {}; \
             about {}, {} of host memory{device_memory}",
            self.unknown,
            self.columns,
            self.rows,
            self.window,
            self.candidates(),
            self.search_taps(),
            device.describe(),
            crate::budget::format_duration(self.seconds(device)),
            format_bytes(f.host)
        )
    }

    /// Refuses the growth when its memory on `device` exceeds `limits`
    /// (naming `field`, how the user gave the field, e.g. `--input
    /// dem.png`, or the options of the largest part) or its estimated time
    /// exceeds `max_seconds` (naming the options of the largest part and
    /// `--max-hours`).
    pub fn check(&self, device: SearchDevice, limits: &MemoryLimits, max_seconds: f64, field: &str) -> Result<()> {
        self.check_memory(device, limits, field)?;
        let terms = self.terms(device);
        let total: f64 = terms.iter().map(|t| t.seconds).sum();
        let largest = terms
            .iter()
            .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
            .ok_or_else(|| Error::invalid("synthesis", "no cost terms"))?;
        let options = if largest.options.is_empty() {
            field
        } else {
            &largest.options
        };
        check_duration(options, &largest.what, total, max_seconds, "--max-hours")
    }

    fn check_memory(&self, device: SearchDevice, limits: &MemoryLimits, field: &str) -> Result<()> {
        let total = self.footprint(device);
        let wave = self.wave_footprint().host;
        let search = self.search_footprint(device).host;
        let (option, what) = if wave > total.host / 2 {
            (
                format!("--batch {}, --window {}", self.batch, self.window),
                format!(
                    "waves of {} queries of {}×{} taps",
                    self.batch.min(self.unknown),
                    self.window,
                    self.window
                ),
            )
        } else if search > total.host / 2 {
            (
                format!("--candidates {}", self.candidates_asked),
                format!("{} candidate windows", self.candidates()),
            )
        } else {
            (
                field.to_string(),
                format!("{}×{} samples with {} to grow", self.columns, self.rows, self.unknown),
            )
        };
        limits.check(&option, &what, total)
    }
}

#[cfg(test)]
#[path = "cost_tests.rs"]
mod tests;
