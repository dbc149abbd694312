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
    /// Median CPU recording time.
    pub median_cpu_ms: f64,
    /// Smallest GPU time.
    pub min_gpu_ms: f64,
    /// Largest GPU time.
    pub max_gpu_ms: f64,
}

/// Median timings of whole frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameSummary {
    /// Number of frames.
    pub frames: usize,
    /// Median GPU frame time.
    pub median_gpu_ms: f64,
    /// Median CPU frame time.
    pub median_cpu_ms: f64,
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

/// Per-pass medians (passes in order of first appearance; a name that
/// occurs several times in a frame contributes several samples) and
/// whole-frame medians.
pub fn summarize(frames: &[FrameProfile]) -> (Vec<PassSummary>, FrameSummary) {
    let mut order: Vec<&str> = Vec::new();
    let mut by_name: BTreeMap<&str, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for pass in frames.iter().flat_map(|f| &f.passes) {
        let entry = by_name.entry(&pass.name).or_insert_with(|| {
            order.push(&pass.name);
            (Vec::new(), Vec::new())
        });
        entry.0.push(pass.gpu_ms);
        entry.1.push(pass.cpu_ms);
    }
    let passes = order
        .iter()
        .filter_map(|name| by_name.get(name).map(|e| (name, e)))
        .map(|(name, (gpu, cpu))| PassSummary {
            name: name.to_string(),
            samples: gpu.len(),
            median_gpu_ms: median(gpu.iter().copied()),
            median_cpu_ms: median(cpu.iter().copied()),
            min_gpu_ms: gpu.iter().copied().fold(f64::INFINITY, f64::min),
            max_gpu_ms: gpu.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
        .collect();
    let frame = FrameSummary {
        frames: frames.len(),
        median_gpu_ms: median(frames.iter().map(|f| f.gpu_ms)),
        median_cpu_ms: median(frames.iter().map(|f| f.cpu_ms)),
    };
    (passes, frame)
}

/// Serialises `value` as pretty JSON with a final newline.
pub(crate) fn json_text(value: &Value) -> Result<String> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| Error::invalid("JSON encoding", e))?;
    text.push('\n');
    Ok(text)
}

/// The text of [`write_profile_json`].
pub fn profile_json(device_name: &str, raster: &str, frames: &[FrameProfile]) -> Result<String> {
    let (passes, frame) = summarize(frames);
    json_text(&json!({
        "device": device_name,
        "raster": raster,
        "frames": frames,
        "summary": { "passes": passes, "frame": frame },
    }))
}

/// Writes `{"device", "raster", "frames": [...], "summary": {"passes": [...],
/// "frame": {...}}}` (see [`summarize`]; `raster`: the terrain's path,
/// [`crate::RasterPath::name`]). Non-finite numbers become `null`.
pub fn write_profile_json(path: &Path, device_name: &str, raster: &str, frames: &[FrameProfile]) -> Result<()> {
    write_bytes_atomically(path, profile_json(device_name, raster, frames)?.as_bytes())
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
        write_profile_json(&path, "Test GPU", "compute", &frames()).unwrap();
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
    }
}
