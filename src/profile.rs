//! Per-frame pass timings, their summary, and two file formats for them:
//! a plain JSON report and a Chrome Trace Event Format file that opens in
//! Perfetto (ui.perfetto.dev) and chrome://tracing.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::io::atomic::write_bytes_atomically;

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
fn json_text(value: &Value) -> Result<String> {
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

/// Milliseconds to whole nanoseconds; NaN, negative or infinite become 0.
fn ns(ms: f64) -> i64 {
    let v = (ms * 1.0e6).round();
    if v.is_finite() && v > 0.0 {
        v.min(i64::MAX as f64 / 4.0) as i64
    } else {
        0
    }
}

/// Nanoseconds to the trace's microseconds.
fn us(ns: i64) -> f64 {
    ns as f64 / 1000.0
}

const PID: u32 = 1;
const CPU_TID: u32 = 1;
const GPU_TID: u32 = 2;

/// One complete ("X") event.
fn complete(name: &str, cat: &str, tid: u32, start_ns: i64, dur_ns: i64, args: Value) -> Value {
    json!({
        "name": name, "cat": cat, "ph": "X", "pid": PID, "tid": tid,
        "ts": us(start_ns), "dur": us(dur_ns), "args": args,
    })
}

/// One event of a track: name, args, start and duration (ns, relative to
/// the frame's start).
type Span<'a> = (&'a str, Value, i64, i64);

/// A pass's span on the CPU or GPU track.
fn pass_span<'a>(frame: &FrameProfile, pass: &'a PassTiming, start: i64, dur: i64) -> Span<'a> {
    let args = json!({ "frame": frame.frame, "gpu_ms": pass.gpu_ms, "cpu_ms": pass.cpu_ms });
    (&pass.name, args, start, dur)
}

/// Appends one frame's events on one track. `spans` are (name, args,
/// start, dur) in ns relative to `frame_start`. Passes are laid out in start order and
/// clipped so they never overlap (the trace format nests events on a
/// thread; partial overlaps would be misdrawn); the frame event is widened
/// to enclose them. The raw values stay in each event's `args`.
fn push_track(
    events: &mut Vec<Value>,
    tid: u32,
    frame: &FrameProfile,
    frame_start: i64,
    frame_dur: i64,
    spans: Vec<Span<'_>>,
) -> i64 {
    let mut spans = spans;
    spans.sort_by_key(|s| s.2);
    let mut cursor = frame_start;
    let mut pass_events = Vec::with_capacity(spans.len());
    for (name, args, start, dur) in spans {
        let begin = (frame_start + start).max(cursor);
        let end = (frame_start + start + dur).max(begin);
        let cat = if name.starts_with("prepare.") {
            "prepare"
        } else {
            "pass"
        };
        pass_events.push(complete(name, cat, tid, begin, end - begin, args));
        cursor = end;
    }
    let end = (frame_start + frame_dur).max(cursor);
    let args = json!({ "gpu_ms": frame.gpu_ms, "cpu_ms": frame.cpu_ms });
    let name = format!("frame {}", frame.frame);
    events.push(complete(&name, "frame", tid, frame_start, end - frame_start, args));
    events.extend(pass_events);
    end
}

/// Writes a Chrome Trace Event Format file:
/// `{"traceEvents": [...], "displayTimeUnit": "ms"}` with complete events
/// (`ph: "X"`, `ts`/`dur` in microseconds) in process 1 "alpenglow", thread
/// 1 "CPU (prepare, record)" and thread 2 "GPU (`device_name`)", named by `M` metadata
/// events. Each track has one "frame N" event per frame enclosing one event
/// per pass.
///
/// GPU and CPU clocks are not calibrated against each other: each GPU frame
/// is placed at its frame's CPU start, or right after the previous GPU frame
/// if that is later, so the GPU track never overlaps itself.
pub fn write_chrome_trace(path: &Path, device_name: &str, frames: &[FrameProfile]) -> Result<()> {
    write_bytes_atomically(path, chrome_trace(device_name, frames)?.as_bytes())
}

/// The text of [`write_chrome_trace`].
pub fn chrome_trace(device_name: &str, frames: &[FrameProfile]) -> Result<String> {
    let meta =
        |name: &str, tid: u32, args: Value| json!({ "name": name, "ph": "M", "pid": PID, "tid": tid, "args": args });
    let mut events = vec![
        meta("process_name", 0, json!({ "name": "alpenglow" })),
        meta("thread_name", CPU_TID, json!({ "name": "CPU (prepare, record)" })),
        meta("thread_sort_index", CPU_TID, json!({ "sort_index": 1 })),
        meta(
            "thread_name",
            GPU_TID,
            json!({ "name": format!("GPU ({device_name})") }),
        ),
        meta("thread_sort_index", GPU_TID, json!({ "sort_index": 2 })),
    ];
    let mut cpu_end = 0i64;
    let mut gpu_end = 0i64;
    for frame in frames {
        let cpu_start = ns(frame.cpu_start_ms).max(cpu_end);
        let prepare = frame.prepare.iter().map(|s| {
            let args = json!({ "frame": frame.frame, "cpu_ms": s.cpu_ms });
            (s.name.as_str(), args, ns(s.cpu_start_ms), ns(s.cpu_ms))
        });
        let cpu_spans = prepare
            .chain(
                frame
                    .passes
                    .iter()
                    .map(|p| pass_span(frame, p, ns(p.cpu_start_ms), ns(p.cpu_ms))),
            )
            .collect();
        cpu_end = push_track(&mut events, CPU_TID, frame, cpu_start, ns(frame.cpu_ms), cpu_spans);
        let gpu_start = cpu_start.max(gpu_end);
        let gpu_spans = frame
            .passes
            .iter()
            .map(|p| pass_span(frame, p, ns(p.gpu_start_ms), ns(p.gpu_ms)))
            .collect();
        gpu_end = push_track(&mut events, GPU_TID, frame, gpu_start, ns(frame.gpu_ms), gpu_spans);
    }
    json_text(&json!({ "traceEvents": events, "displayTimeUnit": "ms" }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pass(name: &str, gpu_start: f64, gpu: f64, cpu_start: f64, cpu: f64) -> PassTiming {
        PassTiming {
            name: name.into(),
            gpu_ms: gpu,
            cpu_ms: cpu,
            gpu_start_ms: gpu_start,
            cpu_start_ms: cpu_start,
        }
    }

    fn frames() -> Vec<FrameProfile> {
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
            })
            .collect()
    }

    fn temp(name: &str) -> std::path::PathBuf {
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

    #[test]
    fn chrome_trace_is_well_formed() {
        let path = temp("trace.json");
        write_chrome_trace(&path, "Test GPU", &frames()).unwrap();
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(v["displayTimeUnit"], "ms");
        let events = v["traceEvents"].as_array().unwrap();
        let thread_names: Vec<&str> = events
            .iter()
            .filter(|e| e["ph"] == "M" && e["name"] == "thread_name")
            .map(|e| e["args"]["name"].as_str().unwrap())
            .collect();
        assert_eq!(thread_names, ["CPU (prepare, record)", "GPU (Test GPU)"]);
        let complete: Vec<&Value> = events.iter().filter(|e| e["ph"] == "X").collect();
        // Per frame and track: one frame event plus three passes.
        assert_eq!(complete.len(), 3 * 2 * 4);
        for e in &complete {
            for key in ["name", "ph", "pid", "tid", "ts", "dur"] {
                assert!(!e[key].is_null(), "{key} missing in {e}");
            }
            assert!(e["dur"].as_f64().unwrap() >= 0.0, "{e}");
            assert!(e["ts"].as_f64().unwrap() >= 0.0, "{e}");
        }
        // Passes lie inside their frame and do not overlap on a track.
        for tid in [1, 2] {
            let mut frame_span = (0.0, 0.0);
            let mut last_end = 0.0;
            for e in complete.iter().filter(|e| e["tid"] == tid) {
                let (ts, dur) = (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap());
                if e["cat"] == "frame" {
                    assert!(ts >= frame_span.1, "frames overlap on track {tid}");
                    frame_span = (ts, ts + dur);
                    last_end = ts;
                } else {
                    assert!(ts >= frame_span.0 && ts + dur <= frame_span.1 + 1e-9, "{e}");
                    assert!(ts >= last_end - 1e-9, "passes overlap: {e}");
                    last_end = ts + dur;
                }
            }
        }
    }
}
