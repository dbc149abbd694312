//! Per-frame pass timings, their summary, and two file formats for them:
//! a plain JSON report and a Chrome Trace Event Format file that opens in
//! Perfetto (ui.perfetto.dev) and chrome://tracing.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::io::atomic::write_bytes_atomically;

mod trace;
pub(crate) mod tracy;

pub use trace::{chrome_trace, gpu_spans_outside_frames, write_chrome_trace};

/// Deserialises a number, reading `null` (how JSON stores NaN and
/// infinities) as NaN, so that every written profile can be read back.
fn f64_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Timing of one render-graph pass in one frame.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassTiming {
    /// Pass name as declared in the render graph.
    pub name: String,
    /// GPU time between the pass's begin and end timestamps.
    #[serde(deserialize_with = "f64_or_nan")]
    pub gpu_ms: f64,
    /// CPU time spent recording the pass.
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_ms: f64,
    /// GPU begin, relative to the frame's first timestamp.
    #[serde(deserialize_with = "f64_or_nan")]
    pub gpu_start_ms: f64,
    /// CPU begin, relative to the frame's CPU start.
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_start_ms: f64,
    /// What the device counted in the pass, when pipeline statistics were
    /// asked for (`--pipeline-stats`); None otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipeline_stats: Option<PipelineStats>,
}

/// Pipeline-statistics counters of one pass (a Vulkan pipeline-statistics
/// query around it; needs the device feature `pipelineStatisticsQuery`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PipelineStats {
    pub input_assembly_vertices: u64,
    pub input_assembly_primitives: u64,
    pub vertex_shader_invocations: u64,
    pub clipping_invocations: u64,
    pub clipping_primitives: u64,
    pub fragment_shader_invocations: u64,
    pub compute_shader_invocations: u64,
}

impl PipelineStats {
    /// The counters in the order of their query flags (the order a query
    /// writes them).
    pub const COUNT: usize = 7;

    /// The counters from a query's results, in flag order.
    pub fn from_counters(c: [u64; Self::COUNT]) -> PipelineStats {
        PipelineStats {
            input_assembly_vertices: c[0],
            input_assembly_primitives: c[1],
            vertex_shader_invocations: c[2],
            clipping_invocations: c[3],
            clipping_primitives: c[4],
            fragment_shader_invocations: c[5],
            compute_shader_invocations: c[6],
        }
    }

    /// The counters in flag order.
    pub fn counters(&self) -> [u64; Self::COUNT] {
        [
            self.input_assembly_vertices,
            self.input_assembly_primitives,
            self.vertex_shader_invocations,
            self.clipping_invocations,
            self.clipping_primitives,
            self.fragment_shader_invocations,
            self.compute_shader_invocations,
        ]
    }

    /// Each counter's median over `stats` (the lower middle for an even
    /// count); None when empty.
    pub fn median(stats: &[PipelineStats]) -> Option<PipelineStats> {
        let mid = stats.len().checked_sub(1)? / 2;
        let mut out = [0u64; Self::COUNT];
        let mut column = Vec::with_capacity(stats.len());
        for (k, o) in out.iter_mut().enumerate() {
            column.clear();
            column.extend(stats.iter().map(|s| s.counters()[k]));
            column.sort_unstable();
            *o = column[mid];
        }
        Some(PipelineStats::from_counters(out))
    }

    /// One line: `vs 1200 fs 64000 cs 0 …` (only the counters that are not 0;
    /// "nothing counted" when all are).
    pub fn line(&self) -> String {
        const NAMES: [&str; PipelineStats::COUNT] =
            ["ia.vertices", "ia.primitives", "vs", "clip.in", "clip.out", "fs", "cs"];
        let parts: Vec<String> = (NAMES.iter().zip(self.counters()))
            .filter(|(_, v)| *v > 0)
            .map(|(n, v)| format!("{n} {v}"))
            .collect();
        match parts.is_empty() {
            true => "nothing counted".into(),
            false => parts.join(", "),
        }
    }
}

/// Device memory in use (the profile JSON's and `bench`'s `device_memory`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeviceMemoryUse {
    /// Bytes the context's allocations hold (what the allocator handed out).
    pub allocated_bytes: u64,
    /// Bytes of the device-memory blocks the allocator reserved for them.
    pub reserved_bytes: u64,
    /// With `VK_EXT_memory_budget`: what this process uses of the device's
    /// device-local heaps, and their budget; None without it.
    pub heap_usage_bytes: Option<u64>,
    pub heap_budget_bytes: Option<u64>,
}

/// A CPU stage of a frame before its passes are recorded: a technique's
/// `prepare` (LOD, tile and point planning), named `prepare.<technique>`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageTiming {
    pub name: String,
    /// CPU time of the stage.
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_ms: f64,
    /// CPU begin, relative to the frame's CPU start.
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_start_ms: f64,
}

/// Timings of one frame.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FrameProfile {
    /// Frame index.
    pub frame: u64,
    /// CPU stages before recording, in order (techniques' `prepare`).
    #[serde(default)]
    pub prepare: Vec<StageTiming>,
    /// Passes in submission order.
    pub passes: Vec<PassTiming>,
    /// GPU time from the first begin to the last end timestamp.
    #[serde(deserialize_with = "f64_or_nan")]
    pub gpu_ms: f64,
    /// CPU time of the frame (prepare, recording and submission).
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_ms: f64,
    /// CPU start of this frame, relative to the first frame's start.
    #[serde(deserialize_with = "f64_or_nan")]
    pub cpu_start_ms: f64,
    /// CPU time right before the frame was submitted (same origin as
    /// `cpu_start_ms`).
    #[serde(default, deserialize_with = "f64_or_nan")]
    pub submit_ms: f64,
    /// CPU time the first wait for the frame's completion returned (same
    /// origin): the frame's GPU work ended before it.
    #[serde(default, deserialize_with = "f64_or_nan")]
    pub fence_ms: f64,
    /// The frame's first GPU timestamp on the CPU clock (same origin) when
    /// GPU timestamps are calibrated
    /// ([`DeviceInfo::calibrated_timestamps`](crate::DeviceInfo)); None
    /// without calibration.
    #[serde(default)]
    pub gpu_start_on_cpu_ms: Option<f64>,
}

/// Median timings of one pass over all profiled frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassSummary {
    /// Pass name.
    pub name: String,
    /// How many timings went into the medians.
    pub samples: usize,
    /// Median GPU time.
    pub median_gpu_ms: f64,
    /// 95th and 99th percentile GPU times ([`quantile`]).
    #[serde(default)]
    pub p95_gpu_ms: f64,
    #[serde(default)]
    pub p99_gpu_ms: f64,
    /// Median CPU recording time.
    pub median_cpu_ms: f64,
    /// 95th and 99th percentile CPU recording times.
    #[serde(default)]
    pub p95_cpu_ms: f64,
    #[serde(default)]
    pub p99_cpu_ms: f64,
    /// Smallest GPU time.
    pub min_gpu_ms: f64,
    /// Largest GPU time.
    pub max_gpu_ms: f64,
    /// Each pipeline statistic's median over the samples that have them
    /// (`--pipeline-stats`); None without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipeline_stats: Option<PipelineStats>,
}

/// Median timings of whole frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameSummary {
    /// Number of frames.
    pub frames: usize,
    /// Median GPU frame time.
    pub median_gpu_ms: f64,
    /// 95th and 99th percentile GPU frame times ([`quantile`]).
    #[serde(default)]
    pub p95_gpu_ms: f64,
    #[serde(default)]
    pub p99_gpu_ms: f64,
    /// Median CPU frame time.
    pub median_cpu_ms: f64,
    /// 95th and 99th percentile CPU frame times.
    #[serde(default)]
    pub p95_cpu_ms: f64,
    #[serde(default)]
    pub p99_cpu_ms: f64,
}

/// Median of `values`, ignoring NaN: the middle value for an odd count,
/// the mean of the two middle values for an even count, NaN if empty.
pub fn median(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.into_iter().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let mid = v.len() / 2;
    if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    }
}

/// `q`-quantile (0..=1) of `values` (nearest rank), ignoring non-finite
/// values; NaN when empty.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
}

/// Per-pass medians (passes in order of first appearance; a name that
/// occurs several times in a frame contributes several samples) and
/// whole-frame medians.
pub fn summarize(frames: &[FrameProfile]) -> (Vec<PassSummary>, FrameSummary) {
    let mut order: Vec<&str> = Vec::new();
    let mut by_name: BTreeMap<&str, PassSamples> = BTreeMap::new();
    for pass in frames.iter().flat_map(|f| &f.passes) {
        let entry = by_name.entry(&pass.name).or_insert_with(|| {
            order.push(&pass.name);
            PassSamples::default()
        });
        entry.gpu.push(pass.gpu_ms);
        entry.cpu.push(pass.cpu_ms);
        entry.stats.extend(pass.pipeline_stats);
    }
    let passes = order
        .iter()
        .filter_map(|name| by_name.get(name).map(|e| (name, e)))
        .map(|(name, s)| PassSummary {
            name: name.to_string(),
            samples: s.gpu.len(),
            median_gpu_ms: median(s.gpu.iter().copied()),
            p95_gpu_ms: quantile(&s.gpu, 0.95),
            p99_gpu_ms: quantile(&s.gpu, 0.99),
            median_cpu_ms: median(s.cpu.iter().copied()),
            p95_cpu_ms: quantile(&s.cpu, 0.95),
            p99_cpu_ms: quantile(&s.cpu, 0.99),
            min_gpu_ms: s.gpu.iter().copied().fold(f64::INFINITY, f64::min),
            max_gpu_ms: s.gpu.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            pipeline_stats: PipelineStats::median(&s.stats),
        })
        .collect();
    let gpu: Vec<f64> = frames.iter().map(|f| f.gpu_ms).collect();
    let cpu: Vec<f64> = frames.iter().map(|f| f.cpu_ms).collect();
    let frame = FrameSummary {
        frames: frames.len(),
        median_gpu_ms: median(gpu.iter().copied()),
        p95_gpu_ms: quantile(&gpu, 0.95),
        p99_gpu_ms: quantile(&gpu, 0.99),
        median_cpu_ms: median(cpu.iter().copied()),
        p95_cpu_ms: quantile(&cpu, 0.95),
        p99_cpu_ms: quantile(&cpu, 0.99),
    };
    (passes, frame)
}

/// One pass's timings over the frames of [`summarize`].
#[derive(Default)]
struct PassSamples {
    gpu: Vec<f64>,
    cpu: Vec<f64>,
    stats: Vec<PipelineStats>,
}

/// Serialises `value` as pretty JSON with a final newline.
pub(crate) fn json_text(value: &Value) -> Result<String> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| Error::invalid("JSON encoding", e))?;
    text.push('\n');
    Ok(text)
}

/// The text of [`write_profile_json`].
pub fn profile_json(
    device_name: &str,
    raster: &str,
    frames: &[FrameProfile],
    memory: Option<DeviceMemoryUse>,
) -> Result<String> {
    let (passes, frame) = summarize(frames);
    json_text(&json!({
        "device": device_name,
        "raster": raster,
        "device_memory": memory,
        "frames": frames,
        "summary": { "passes": passes, "frame": frame },
    }))
}

/// Writes `{"device", "raster", "device_memory", "frames": [...],
/// "summary": {"passes": [...], "frame": {...}}}` (see [`summarize`];
/// `raster`: the terrain's path, [`crate::RasterPath::name`];
/// `device_memory`: `memory` or null). Non-finite numbers become `null`.
pub fn write_profile_json(
    path: &Path,
    device_name: &str,
    raster: &str,
    frames: &[FrameProfile],
    memory: Option<DeviceMemoryUse>,
) -> Result<()> {
    write_bytes_atomically(path, profile_json(device_name, raster, frames, memory)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn pass(name: &str, gpu_start: f64, gpu: f64, cpu_start: f64, cpu: f64) -> PassTiming {
        PassTiming {
            name: name.into(),
            gpu_ms: gpu,
            cpu_ms: cpu,
            gpu_start_ms: gpu_start,
            cpu_start_ms: cpu_start,
            pipeline_stats: None,
        }
    }

    pub(super) fn frames() -> Vec<FrameProfile> {
        (0..3)
            .map(|i| FrameProfile {
                frame: i,
                prepare: Vec::new(),
                passes: vec![
                    pass("shadow", 0.0, 1.0 + i as f64, 0.0, 0.1),
                    // Overlaps the previous pass and has a bogus negative time.
                    pass("terrain", 0.5 + i as f64, 2.0, 0.05, -0.2),
                    pass("tonemap", 3.5 + i as f64, 0.25, 0.2, f64::NAN),
                ],
                gpu_ms: 3.7 + i as f64,
                cpu_ms: 0.3,
                cpu_start_ms: 2.0 * i as f64,
                ..FrameProfile::default()
            })
            .collect()
    }

    pub(super) fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("alpenglow-profile-{}-{name}", std::process::id()))
    }

    #[test]
    fn median_even_odd_empty() {
        assert_eq!(median([3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median([4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median([f64::NAN, 5.0]), 5.0);
        assert!(median(std::iter::empty()).is_nan());
    }

    #[test]
    fn summary_medians() {
        let (passes, frame) = summarize(&frames());
        let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["shadow", "terrain", "tonemap"]);
        assert_eq!(passes[0].median_gpu_ms, 2.0);
        assert_eq!(passes[0].samples, 3);
        assert_eq!((passes[0].min_gpu_ms, passes[0].max_gpu_ms), (1.0, 3.0));
        assert_eq!(frame.frames, 3);
        assert!((frame.median_gpu_ms - 4.7).abs() < 1e-12);
    }

    #[test]
    fn profile_json_parses_back() {
        let path = temp("profile.json");
        let memory = DeviceMemoryUse {
            allocated_bytes: 1 << 20,
            reserved_bytes: 2 << 20,
            heap_usage_bytes: None,
            heap_budget_bytes: None,
        };
        write_profile_json(&path, "Test GPU", "compute", &frames(), Some(memory)).unwrap();
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(
            (v["device"].as_str(), v["raster"].as_str()),
            (Some("Test GPU"), Some("compute"))
        );
        let back: Vec<FrameProfile> = serde_json::from_value(v["frames"].clone()).unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!(back[2].passes[0].gpu_ms, 3.0);
        assert!(back[0].passes[2].cpu_ms.is_nan());
        assert_eq!(v["summary"]["passes"][1]["name"], "terrain");
        assert_eq!(v["summary"]["frame"]["frames"], 3);
        assert_eq!(v["device_memory"]["allocated_bytes"], 1 << 20);
        assert!(v["device_memory"]["heap_budget_bytes"].is_null());
        assert!(v["summary"]["passes"][0]["p99_gpu_ms"].is_number());
    }

    #[test]
    fn quantiles_beside_the_median() {
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!((quantile(&values, 0.95), quantile(&values, 0.99)), (95.0, 99.0));
        assert!(quantile(&[f64::NAN], 0.5).is_nan());
        let mut frames = frames();
        frames.extend((3..100).map(|i| FrameProfile {
            frame: i,
            passes: vec![pass("shadow", 0.0, 1.0, 0.0, 0.1)],
            gpu_ms: 1.0,
            ..FrameProfile::default()
        }));
        frames[50].gpu_ms = 50.0;
        let (passes, frame) = summarize(&frames);
        assert_eq!(
            (passes[0].median_gpu_ms, passes[0].p95_gpu_ms, passes[0].p99_gpu_ms),
            (1.0, 1.0, 2.0)
        );
        assert_eq!((frame.median_gpu_ms, frame.p99_gpu_ms), (1.0, 5.7));
    }

    #[test]
    fn pipeline_stats_medians_and_line() {
        let s = |vs: u64, fs: u64| PipelineStats {
            vertex_shader_invocations: vs,
            fragment_shader_invocations: fs,
            ..PipelineStats::default()
        };
        let median = PipelineStats::median(&[s(3, 10), s(1, 30), s(2, 20)]).unwrap();
        assert_eq!(median, s(2, 20));
        assert_eq!(median.line(), "vs 2, fs 20");
        assert_eq!(PipelineStats::default().line(), "nothing counted");
        assert_eq!(PipelineStats::median(&[]), None);
        let mut frames = frames();
        frames[0].passes[0].pipeline_stats = Some(s(6, 0));
        let (passes, _) = summarize(&frames);
        assert_eq!(passes[0].pipeline_stats, Some(s(6, 0)));
        assert_eq!(passes[1].pipeline_stats, None);
    }
}
