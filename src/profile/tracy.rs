//! Streaming to a running Tracy profiler (cargo feature `tracy`, with the
//! `tracy-client` crate): CPU zones of the prepare stages, GPU zones of
//! every render-graph pass (uploaded once the frame's timestamps are
//! read) and a frame mark per submitted frame. Without the feature every
//! call is a no-op and nothing is linked.
//!
//! GPU zones need calibrated timestamps: the Tracy GPU context is created,
//! and resynchronised after every submit, from a device timestamp read
//! together with the CPU clock. Without calibration only CPU zones are
//! streamed (a warning says so once).

#[cfg(feature = "tracy")]
use std::collections::VecDeque;

/// A CPU zone, ended when dropped.
#[cfg(feature = "tracy")]
pub(crate) type CpuZone = tracy_client::Span;
#[cfg(not(feature = "tracy"))]
pub(crate) struct CpuZone;

/// Starts the CPU zone `name` (a prepare stage); it ends when dropped.
#[cfg(feature = "tracy")]
pub(crate) fn cpu_zone(name: &str) -> CpuZone {
    tracy_client::Client::start().span_alloc(Some(name), "prepare", file!(), line!(), 0)
}

#[cfg(not(feature = "tracy"))]
pub(crate) fn cpu_zone(_name: &str) -> CpuZone {
    CpuZone
}

/// Marks the end of a frame (after its submit).
pub(crate) fn frame_mark() {
    #[cfg(feature = "tracy")]
    tracy_client::Client::start().frame_mark();
}

/// The GPU zones of one render graph's passes.
#[derive(Default)]
pub(crate) struct GpuZones {
    #[cfg(feature = "tracy")]
    state: Option<GpuState>,
    /// No calibration: GPU zones are off (warned once).
    #[cfg(feature = "tracy")]
    off: bool,
}

#[cfg(feature = "tracy")]
struct GpuState {
    context: tracy_client::GpuContext,
    /// The zones of the frame being recorded, and of submitted frames
    /// waiting for their timestamps (frame number, zones in pass order).
    recording: Vec<tracy_client::GpuSpan>,
    pending: VecDeque<(u64, Vec<tracy_client::GpuSpan>)>,
}

impl GpuZones {
    /// Starts the zone of pass `name` in the frame being recorded;
    /// `gpu_now_ns` (the device clock now, when calibrated) creates the
    /// Tracy GPU context the first time.
    #[cfg(feature = "tracy")]
    pub(crate) fn begin_pass(&mut self, name: &str, gpu_now_ns: impl FnOnce() -> Option<i64>) {
        if self.state.is_none() && !self.off {
            let context = gpu_now_ns().and_then(|now| {
                let client = tracy_client::Client::start();
                let made = client.new_gpu_context(Some("alpenglow"), tracy_client::GpuContextType::Vulkan, now, 1.0);
                made.map_err(|e| log::warn!("tracy: no GPU context: {e}")).ok()
            });
            match context {
                Some(context) => {
                    self.state = Some(GpuState {
                        context,
                        recording: Vec::new(),
                        pending: VecDeque::new(),
                    })
                }
                None => {
                    log::warn!("tracy: GPU zones need calibrated timestamps; streaming CPU zones only");
                    self.off = true;
                }
            }
        }
        if let Some(s) = &mut self.state {
            match s.context.span_alloc(name, "pass", file!(), line!()) {
                Ok(span) => s.recording.push(span),
                Err(e) => log::warn!("tracy: {e}"),
            }
        }
    }

    #[cfg(not(feature = "tracy"))]
    pub(crate) fn begin_pass(&mut self, _name: &str, _gpu_now_ns: impl FnOnce() -> Option<i64>) {}

    /// Ends the zone of the pass being recorded.
    pub(crate) fn end_pass(&mut self) {
        #[cfg(feature = "tracy")]
        if let Some(span) = self.state.as_mut().and_then(|s| s.recording.last_mut()) {
            span.end_zone();
        }
    }

    /// Frame `frame` was submitted: its zones wait for its timestamps;
    /// `gpu_now_ns` (the device clock now) resynchronises Tracy's GPU clock.
    pub(crate) fn submitted(&mut self, frame: u64, gpu_now_ns: impl FnOnce() -> Option<i64>) {
        #[cfg(feature = "tracy")]
        if let Some(s) = &mut self.state {
            let zones = std::mem::take(&mut s.recording);
            s.pending.push_back((frame, zones));
            if let Some(now) = gpu_now_ns() {
                s.context.sync_gpu_time(now);
            }
        }
        #[cfg(not(feature = "tracy"))]
        let _ = (frame, gpu_now_ns);
    }

    /// Uploads the timestamps of frame `frame`: `times` yields each pass's
    /// (begin, end) on the device clock in nanoseconds, in pass order.
    /// Zones of earlier frames that never completed are dropped.
    pub(crate) fn completed(&mut self, frame: u64, times: impl Iterator<Item = (f64, f64)>) {
        #[cfg(feature = "tracy")]
        if let Some(s) = &mut self.state {
            while s.pending.front().is_some_and(|(f, _)| *f < frame) {
                s.pending.pop_front();
            }
            if s.pending.front().is_some_and(|(f, _)| *f == frame) {
                let (_, zones) = s.pending.pop_front().expect("front exists");
                for (zone, (begin, end)) in zones.iter().zip(times) {
                    zone.upload_timestamp_start(begin as i64);
                    zone.upload_timestamp_end(end as i64);
                }
            }
        }
        #[cfg(not(feature = "tracy"))]
        let _ = (frame, times);
    }
}
