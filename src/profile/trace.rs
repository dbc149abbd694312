//! The Chrome Trace Event Format file of frame profiles (opens in Perfetto
//! and chrome://tracing), and the check that a calibrated trace places
//! every GPU pass between its frame's submit and fence wait.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::{json, Value};

use super::{json_text, FrameProfile, PassTiming};
use crate::error::{Error, Result};
use crate::io::atomic::write_bytes_atomically;

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
    let args = json!({ "frame": frame.frame, "gpu_ms": frame.gpu_ms, "cpu_ms": frame.cpu_ms });
    let name = format!("frame {}", frame.frame);
    events.push(complete(&name, "frame", tid, frame_start, end - frame_start, args));
    events.extend(pass_events);
    end
}

/// Writes a Chrome Trace Event Format file:
/// `{"traceEvents": [...], "displayTimeUnit": "ms", "otherData": {"gpu clock": ...}}`
/// with complete events (`ph: "X"`, `ts`/`dur` in microseconds) in process
/// 1 "alpenglow", thread 1 "CPU (prepare, record)" and thread 2 "GPU
/// (`device_name`)", named by `M` metadata events. Each track has one
/// "frame N" event per frame enclosing one event per pass; the CPU track
/// also has an instant event "submit" (right before the frame's submit)
/// and "fence wait returned" (when the wait for its completion returned)
/// per frame.
///
/// With calibrated timestamps (every frame's
/// [`FrameProfile::gpu_start_on_cpu_ms`]) the GPU track is on the CPU
/// clock, and the process label and `otherData` say "gpu clock:
/// calibrated". Without, they say "not calibrated": each GPU frame is
/// placed at its frame's CPU start, or right after the previous GPU frame
/// if that is later, so the GPU track never overlaps itself.
pub fn write_chrome_trace(path: &Path, device_name: &str, frames: &[FrameProfile]) -> Result<()> {
    write_bytes_atomically(path, chrome_trace(device_name, frames)?.as_bytes())
}

/// Whether every frame's GPU timestamps were placed on the CPU clock.
fn calibrated(frames: &[FrameProfile]) -> bool {
    !frames.is_empty() && frames.iter().all(|f| f.gpu_start_on_cpu_ms.is_some())
}

const CALIBRATED: &str = "calibrated";
const NOT_CALIBRATED: &str = "not calibrated";
const SUBMIT: &str = "submit";
const FENCE: &str = "fence wait returned";

/// One instant ("i") event on thread `tid`.
fn instant(name: &str, tid: u32, at_ns: i64, frame: u64) -> Value {
    json!({
        "name": name, "cat": "sync", "ph": "i", "s": "t", "pid": PID, "tid": tid,
        "ts": us(at_ns), "args": { "frame": frame },
    })
}

/// The text of [`write_chrome_trace`].
pub fn chrome_trace(device_name: &str, frames: &[FrameProfile]) -> Result<String> {
    let calibrated = calibrated(frames);
    let clock = if calibrated { CALIBRATED } else { NOT_CALIBRATED };
    let meta =
        |name: &str, tid: u32, args: Value| json!({ "name": name, "ph": "M", "pid": PID, "tid": tid, "args": args });
    let mut events = vec![
        meta("process_name", 0, json!({ "name": "alpenglow" })),
        meta("process_labels", 0, json!({ "labels": format!("gpu clock: {clock}") })),
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
        if frame.fence_ms > 0.0 {
            events.push(instant(SUBMIT, CPU_TID, ns(frame.submit_ms), frame.frame));
            events.push(instant(FENCE, CPU_TID, ns(frame.fence_ms), frame.frame));
        }
        let gpu_start = match frame.gpu_start_on_cpu_ms {
            Some(at) if calibrated => ns(at),
            _ => cpu_start,
        }
        .max(gpu_end);
        let gpu_spans = frame
            .passes
            .iter()
            .map(|p| pass_span(frame, p, ns(p.gpu_start_ms), ns(p.gpu_ms)))
            .collect();
        gpu_end = push_track(&mut events, GPU_TID, frame, gpu_start, ns(frame.gpu_ms), gpu_spans);
    }
    json_text(&json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "otherData": { "gpu clock": clock },
    }))
}

/// A trace time (µs) in whole nanoseconds.
fn trace_ns(v: &Value) -> Option<i64> {
    v.as_f64().map(|us| (us * 1000.0).round() as i64)
}

/// The GPU events (frames and passes) of a calibrated trace (the text of
/// [`chrome_trace`]) that do not lie between their frame's submit and the
/// return of its fence wait on the CPU clock, one line each; empty when
/// all do. An error when the text is not such a trace, it is not
/// calibrated, or it lacks a GPU frame's submit or fence-wait event.
pub fn gpu_spans_outside_frames(trace: &str) -> Result<Vec<String>> {
    let bad = |m: &str| Error::invalid("trace", m);
    let v: Value = serde_json::from_str(trace).map_err(|e| Error::invalid("trace", e))?;
    if v["otherData"]["gpu clock"] != CALIBRATED {
        return Err(bad("the GPU clock is not calibrated"));
    }
    let events = v["traceEvents"].as_array().ok_or_else(|| bad("no traceEvents array"))?;
    let mut marks: BTreeMap<u64, (Option<i64>, Option<i64>)> = BTreeMap::new();
    for e in events.iter().filter(|e| e["ph"] == "i" && e["tid"] == CPU_TID) {
        let (Some(frame), Some(at)) = (e["args"]["frame"].as_u64(), trace_ns(&e["ts"])) else {
            continue;
        };
        let mark = marks.entry(frame).or_default();
        match e["name"].as_str() {
            Some(SUBMIT) => mark.0 = Some(at),
            Some(FENCE) => mark.1 = Some(at),
            _ => {}
        }
    }
    let mut outside = Vec::new();
    for e in events.iter().filter(|e| e["ph"] == "X" && e["tid"] == GPU_TID) {
        let name = e["name"].as_str().unwrap_or("?");
        let span = (e["args"]["frame"].as_u64(), trace_ns(&e["ts"]), trace_ns(&e["dur"]));
        let (Some(frame), Some(start), Some(dur)) = span else {
            return Err(bad(&format!("GPU event '{name}' lacks its frame, ts or dur")));
        };
        let Some(&(Some(submit), Some(fence))) = marks.get(&frame) else {
            return Err(bad(&format!("frame {frame} lacks its submit or fence-wait event")));
        };
        if start < submit || start + dur > fence {
            outside.push(format!(
                "frame {frame}: GPU '{name}' spans [{start}, {}] ns, outside [submit {submit}, fence wait {fence}] ns",
                start + dur
            ));
        }
    }
    Ok(outside)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::tests::{frames, temp};

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

    /// The fixture frames calibrated: frame i starts at 10i ms, is
    /// submitted at 10i + 0.3 ms, its GPU work runs from 10i + 0.5 ms to
    /// 10i + 4.25 + i ms (its last pass) and the fence wait returns 0.2 ms
    /// later.
    fn calibrated_frames() -> Vec<FrameProfile> {
        let mut frames = frames();
        for (i, f) in frames.iter_mut().enumerate() {
            let start = 10.0 * i as f64;
            f.cpu_start_ms = start;
            f.submit_ms = start + 0.3;
            f.gpu_start_on_cpu_ms = Some(start + 0.5);
            f.fence_ms = start + 4.45 + i as f64;
        }
        frames
    }

    #[test]
    fn a_calibrated_trace_places_the_gpu_between_submit_and_fence() {
        let text = chrome_trace("Test GPU", &calibrated_frames()).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["otherData"]["gpu clock"], "calibrated");
        let events = v["traceEvents"].as_array().unwrap();
        let frame1 = events
            .iter()
            .find(|e| e["tid"] == GPU_TID && e["name"] == "frame 1")
            .unwrap();
        assert_eq!(frame1["ts"], 10500.0, "placed at its calibrated start");
        assert_eq!(gpu_spans_outside_frames(&text).unwrap(), Vec::<String>::new());
    }

    #[test]
    fn the_check_fails_on_a_span_outside_its_frame() {
        // Frame 1's GPU work starts before its submit.
        let mut frames = calibrated_frames();
        frames[1].submit_ms = 10.6;
        let text = chrome_trace("Test GPU", &frames).unwrap();
        let outside = gpu_spans_outside_frames(&text).unwrap();
        assert!(
            !outside.is_empty() && outside.iter().all(|l| l.starts_with("frame 1:")),
            "{outside:?}"
        );
        // Frame 2's fence wait returns before its last pass ends (26.25 ms).
        let mut frames = calibrated_frames();
        frames[2].fence_ms = 25.5;
        let text = chrome_trace("Test GPU", &frames).unwrap();
        let outside = gpu_spans_outside_frames(&text).unwrap();
        assert_eq!(outside.len(), 2, "the frame and 'tonemap': {outside:?}");
        assert!(
            outside.iter().any(|l| l.starts_with("frame 2: GPU 'tonemap'")),
            "{outside:?}"
        );
    }

    #[test]
    fn an_uncalibrated_trace_says_so_and_cannot_be_checked() {
        let mut frames = calibrated_frames();
        frames[0].gpu_start_on_cpu_ms = None;
        let text = chrome_trace("Test GPU", &frames).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["otherData"]["gpu clock"], "not calibrated");
        let labels = (v["traceEvents"].as_array().unwrap().iter())
            .find(|e| e["name"] == "process_labels")
            .map(|e| e["args"]["labels"].clone());
        assert_eq!(labels, Some(json!("gpu clock: not calibrated")));
        let err = gpu_spans_outside_frames(&text).unwrap_err().to_string();
        assert!(err.contains("not calibrated"), "{err}");
        assert!(gpu_spans_outside_frames("[1, 2]").is_err());
    }
}
