//! Steady frames (dissertation §3.3: a driving simulator needs a constant,
//! high frame rate): tile generation spread over frames by a GPU time
//! budget, not only by tile and texel counts.
//!
//! The cost of generating a tile is about proportional to its texels (one
//! thread per texel in every `texturing.*` pass). [`GenerationPacer`]
//! learns the GPU time per texel from completed frames: the GPU time of a
//! frame's `texturing.*` passes (its [`FrameProfile`], from the frame ring's
//! timestamps) divided by the texels the frame generated, median over the
//! last [`WINDOW`] frames that generated any. A [`GpuTimeBudget`] then
//! becomes a texel cap for the next frame: the budget's milliseconds over
//! the time per texel. The cache still generates at least one tile per
//! frame ([`crate::texturing::atlas`]), so streaming always progresses.
//! Timings arrive a few frames late (frames in flight); until the first
//! generating frame completes there is no time cap, only the counts.

use std::collections::VecDeque;

use crate::profile::{median, FrameProfile};
use crate::texturing::stats::generation_gpu_ms;

/// Frames the medians look back over.
pub const WINDOW: usize = 16;

/// A GPU time cap on tile generation per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GpuTimeBudget {
    /// At most this many milliseconds (> 0).
    Ms(f32),
    /// At most this share (> 0) of the median GPU time of the rest of the
    /// frame (everything but the `texturing.*` passes) over recent frames:
    /// 0.25 lets generation lengthen a frame by a quarter at most.
    FrameShare(f32),
}

impl GpuTimeBudget {
    /// Whether the value is finite and positive.
    pub fn is_valid(&self) -> bool {
        let (GpuTimeBudget::Ms(v) | GpuTimeBudget::FrameShare(v)) = *self;
        v.is_finite() && v > 0.0
    }
}

/// Measured generation cost and frame time of recent frames.
#[derive(Clone, Debug, Default)]
pub struct GenerationPacer {
    /// Texels each prepared frame generates, until its profile arrives.
    generated: VecDeque<(u64, u64)>,
    /// Milliseconds per texel of recent generating frames.
    per_texel: VecDeque<f64>,
    /// GPU milliseconds of recent frames' other passes.
    rest: VecDeque<f64>,
    /// The newest frame observed.
    observed: Option<u64>,
}

fn push(window: &mut VecDeque<f64>, value: f64) {
    if value.is_finite() {
        window.push_back(value);
        if window.len() > WINDOW {
            window.pop_front();
        }
    }
}

impl GenerationPacer {
    /// Notes that `frame` generates `texels` (called when it is prepared).
    pub fn record(&mut self, frame: u64, texels: u64) {
        self.generated.push_back((frame, texels));
        // Frames whose profiles never arrive (taken elsewhere) age out.
        while self.generated.len() > 4 * WINDOW {
            self.generated.pop_front();
        }
    }

    /// Takes the timings of completed frames not seen yet.
    pub fn observe(&mut self, profiles: &[FrameProfile]) {
        for p in profiles {
            if self.observed.is_some_and(|o| p.frame <= o) {
                continue;
            }
            self.observed = Some(p.frame);
            let texturing = generation_gpu_ms(p);
            push(&mut self.rest, (p.gpu_ms - texturing).max(0.0));
            while self.generated.front().is_some_and(|&(f, _)| f < p.frame) {
                self.generated.pop_front();
            }
            if let Some(&(f, texels)) = self.generated.front() {
                if f == p.frame && texels > 0 {
                    push(&mut self.per_texel, texturing / texels as f64);
                }
            }
        }
    }

    /// Median GPU milliseconds per generated texel, once measured.
    pub fn ms_per_texel(&self) -> Option<f64> {
        (!self.per_texel.is_empty()).then(|| median(self.per_texel.iter().copied()))
    }

    /// Median GPU milliseconds of the frames' other passes, once measured.
    pub fn frame_ms(&self) -> Option<f64> {
        (!self.rest.is_empty()).then(|| median(self.rest.iter().copied()))
    }

    /// The most texels the next frame may generate within `budget`; None
    /// without a budget or before the first measurement.
    pub fn texel_cap(&self, budget: Option<GpuTimeBudget>) -> Option<u64> {
        let per_texel = self.ms_per_texel().filter(|&c| c > 0.0)?;
        let ms = match budget? {
            GpuTimeBudget::Ms(ms) => f64::from(ms),
            GpuTimeBudget::FrameShare(share) => f64::from(share) * self.frame_ms()?,
        };
        Some((ms / per_texel).clamp(0.0, u64::MAX as f64) as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texturing::stats::test_profile;

    fn profile(frame: u64, other_ms: f64, texturing_ms: f64) -> FrameProfile {
        test_profile(frame, &[("terrain.draw", other_ms), ("texturing.finish", texturing_ms)])
    }

    #[test]
    fn cost_per_texel_and_frame_time_become_a_texel_cap() {
        let mut pacer = GenerationPacer::default();
        assert_eq!(pacer.texel_cap(Some(GpuTimeBudget::Ms(1.0))), None, "nothing measured");
        // 1000 texels cost 2 ms (2 µs each); the rest of the frame 8 ms.
        for frame in 0..5 {
            pacer.record(frame, if frame == 3 { 0 } else { 1000 });
        }
        let profiles: Vec<FrameProfile> = (0..5)
            .map(|f| profile(f, 8.0, if f == 3 { 0.01 } else { 2.0 }))
            .collect();
        pacer.observe(&profiles[..2]);
        pacer.observe(&profiles);
        assert_eq!(pacer.per_texel.len(), 4, "frames 0, 1, 2 and 4, each once");
        assert!((pacer.ms_per_texel().unwrap() - 0.002).abs() < 1e-12);
        assert!((pacer.frame_ms().unwrap() - 8.0).abs() < 1e-12);
        assert_eq!(pacer.texel_cap(Some(GpuTimeBudget::Ms(1.0))), Some(500));
        assert_eq!(pacer.texel_cap(Some(GpuTimeBudget::FrameShare(0.25))), Some(1000));
        assert_eq!(pacer.texel_cap(None), None);
    }

    #[test]
    fn medians_follow_recent_frames() {
        let mut pacer = GenerationPacer::default();
        // Generation gets four times dearer: after a window, the cap follows.
        for frame in 0..2 * WINDOW as u64 {
            pacer.record(frame, 1000);
            let cost = if frame < WINDOW as u64 { 1.0 } else { 4.0 };
            pacer.observe(&[profile(frame, 10.0, cost)]);
        }
        assert_eq!(pacer.texel_cap(Some(GpuTimeBudget::Ms(2.0))), Some(500));
        assert!(GpuTimeBudget::FrameShare(0.25).is_valid());
        assert!(!GpuTimeBudget::Ms(0.0).is_valid() && !GpuTimeBudget::Ms(f32::NAN).is_valid());
    }
}
