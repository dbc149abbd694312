//! Per-frame statistics of point rendering (dissertation §10.1.7: the text
//! reports that the vertex stage culls 10–40 % of the prefix): splats in the
//! CPU's prefixes, splats that passed the GPU's interval test (counted by
//! the vertex stage with an atomic, when the device has
//! `vertexPipelineStoresAndAtomics`), and the share culled on the GPU.

use std::sync::Arc;

use serde::Serialize;

use crate::error::Result;
use crate::vulkan::{Buffer, FRAMES_IN_FLIGHT};

/// Bytes of the GPU counters (`SplatCounter` in glsl/include/splat.glsl).
pub(crate) const COUNTER_BYTES: usize = 20;

/// Point statistics of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PointFrameStats {
    pub frame: u64,
    /// Instances in the scene.
    pub instances: usize,
    /// Instances inside the view frustum with a non-empty prefix.
    pub instances_drawn: usize,
    /// Splats of the drawn instances' whole lists (what drawing every node would cost).
    pub list_splats: u64,
    /// Splats in the prefixes sent to the GPU.
    pub prefix_splats: u64,
    /// Splats that passed the vertex stage's interval test r_min ≤ r < r_max
    /// (None without `vertexPipelineStoresAndAtomics`).
    pub interval_passed: Option<u64>,
    /// Of those, splats drawn: not back-facing (unless two-sided), not
    /// ill-conditioned, in front of the near plane.
    pub drawn_splats: Option<u64>,
    /// Hybrid triangles (§10.1.8) in the prefixes sent to the GPU.
    pub prefix_triangles: u64,
    /// Of those, triangles drawn: passing `r < s/ε` and not back-facing
    /// (None without `vertexPipelineStoresAndAtomics`).
    pub triangles_drawn: Option<u64>,
    /// Single-pass splatting, compute backend (§10.4): tile entries dropped
    /// because the entry buffer was full (whole tiles' lists, which then show
    /// no splats; 0 in the other modes; None without GPU counters).
    pub tile_entries_dropped: Option<u64>,
    /// Single-pass splatting, compute backend: the longest tile list (the
    /// largest over the views; the merge walks it in one workgroup).
    pub longest_tile_list: Option<u64>,
    /// CPU time of the selection (prefix search, transforms), milliseconds.
    pub cpu_ms: f64,
}

impl PointFrameStats {
    /// Share of the prefixes the GPU's interval test culled, in [0, 1]
    /// (the figure the text reports as 10–40 %).
    pub fn gpu_culled_share(&self) -> Option<f64> {
        let passed = self.interval_passed?;
        (self.prefix_splats > 0).then(|| 1.0 - passed as f64 / self.prefix_splats as f64)
    }

    /// One line for logs and the CLI.
    pub fn summary(&self) -> String {
        let drawn = match (self.interval_passed, self.drawn_splats, self.gpu_culled_share()) {
            (Some(p), Some(d), Some(c)) => format!(
                "{p} pass the interval test ({:.1} % of the prefixes culled on the GPU), {d} drawn after back-face culling",
                c * 100.0
            ),
            (Some(p), Some(d), None) => format!("{p} pass the interval test, {d} drawn"),
            _ => "GPU counts unavailable (no vertexPipelineStoresAndAtomics)".into(),
        };
        let triangles = match (self.prefix_triangles, self.triangles_drawn) {
            (0, _) => String::new(),
            (p, Some(d)) => format!("; hybrid: {d} of {p} triangles in prefixes drawn"),
            (p, None) => format!("; hybrid: {p} triangles in prefixes"),
        };
        let tiles = match (self.longest_tile_list, self.tile_entries_dropped) {
            (Some(l), Some(0)) if l > 0 => format!("; tiles: longest list {l}"),
            (Some(l), Some(d)) if l > 0 => format!("; tiles: longest list {l}, {d} entries DROPPED (capacity)"),
            _ => String::new(),
        };
        format!(
            "points: {}/{} instances, {} splats in prefixes of {} listed, {}{triangles}{tiles}; CPU {:.3} ms",
            self.instances_drawn, self.instances, self.prefix_splats, self.list_splats, drawn, self.cpu_ms
        )
    }
}

/// The most frames of statistics kept until taken (the oldest are dropped).
pub const STATS_HISTORY: usize = crate::graph::DEFAULT_PROFILE_HISTORY;

/// Collects the statistics: the counter of a frame slot is read when the
/// slot is recorded again (its previous frame has completed) or at the end.
pub(crate) struct StatsLog {
    /// One host-visible counter per frame slot (None: no GPU counting).
    counters: Option<Vec<Arc<Buffer>>>,
    pending: [Option<PointFrameStats>; FRAMES_IN_FLIGHT],
    done: Vec<PointFrameStats>,
}

impl StatsLog {
    pub fn new(counters: Option<Vec<Arc<Buffer>>>) -> StatsLog {
        StatsLog {
            counters,
            pending: [None; FRAMES_IN_FLIGHT],
            // Reserved up front: recording frames allocates nothing.
            done: Vec::with_capacity(STATS_HISTORY),
        }
    }

    /// Fills in the GPU counts of `stats` from its slot's counter.
    fn read(&self, slot: usize, stats: &mut PointFrameStats) -> Result<()> {
        if let Some(c) = &self.counters {
            let bytes = c[slot].mapped()?;
            let word = |k: usize| {
                bytes
                    .get(4 * k..4 * k + 4)
                    .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            };
            let words = [0, 1, 2, 3, 4].map(|k| u64::from(word(k)));
            stats.interval_passed = Some(words[0]);
            stats.drawn_splats = Some(words[1]);
            stats.triangles_drawn = Some(words[2]);
            stats.tile_entries_dropped = Some(words[3]);
            stats.longest_tile_list = Some(words[4]);
            if words[3] > 0 {
                log::warn!(
                    "frame {}: single-pass splatting dropped {} tile entries (the entry buffer is full; whole tiles show no splats)",
                    stats.frame,
                    words[3]
                );
            }
        }
        Ok(())
    }

    /// Called while recording `stats.frame`, after its slot's previous frame
    /// completed: finishes that frame's entry and zeroes the counter.
    pub fn begin_frame(&mut self, stats: PointFrameStats) -> Result<()> {
        let slot = (stats.frame % FRAMES_IN_FLIGHT as u64) as usize;
        if let Some(mut previous) = self.pending[slot].take() {
            self.read(slot, &mut previous)?;
            if self.done.len() >= STATS_HISTORY {
                self.done.remove(0);
            }
            self.done.push(previous);
        }
        if let Some(c) = &self.counters {
            c[slot].write(0, &[0u8; COUNTER_BYTES])?;
        }
        self.pending[slot] = Some(stats);
        Ok(())
    }

    /// Finishes every pending frame (call after all frames completed) and
    /// returns the statistics gathered so far, in frame order.
    pub fn take_all_completed(&mut self) -> Result<Vec<PointFrameStats>> {
        for slot in 0..FRAMES_IN_FLIGHT {
            if let Some(mut s) = self.pending[slot].take() {
                self.read(slot, &mut s)?;
                self.done.push(s);
            }
        }
        let mut out = std::mem::replace(&mut self.done, Vec::with_capacity(STATS_HISTORY));
        out.sort_by_key(|s| s.frame);
        Ok(out)
    }
}
