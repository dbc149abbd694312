//! Streaming statistics of the texture atlas (dissertation §8.2): per frame
//! the tiles visible, hit, generated, evicted and deferred, and over a run
//! the hit rate, the most tiles one frame generated and the GPU time of the
//! `texturing.*` passes.

use serde::Serialize;

use crate::profile::{median, FrameProfile};
use crate::texturing::atlas::TileStats;

/// Texture statistics of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TextureFrameStats {
    pub frame: u64,
    /// Tiles visible, hits, generated, evicted, deferred, resident.
    #[serde(flatten)]
    pub tiles: TileStats,
    /// `hits / visible`.
    pub hit_rate: f64,
    /// Texels generated (borders included).
    pub texels_generated: u64,
    /// CPU time of selection, planning and the page table, milliseconds.
    pub cpu_ms: f64,
    /// Coarsenings the selection took to fit the atlas (halved tile sizes
    /// and leaves merged into parents, `crate::texturing::fit`): 0 when
    /// every view got the texels it needs.
    pub coarsened: usize,
    /// The frame's texel cap: the budget's, or lower where its GPU time
    /// allowed fewer (`crate::texturing::pacing`).
    pub texel_cap: u64,
}

/// Texture streaming over a run of frames.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TextureSummary {
    pub frames: usize,
    /// Hits / visible over all frames.
    pub hit_rate: f64,
    /// The first frame (index into the run) that drew every tile at its
    /// needed size: the atlas had filled up.
    pub settled_at: Option<usize>,
    /// Hits / visible from `settled_at` on (the steady state of streaming).
    pub steady_hit_rate: Option<f64>,
    /// The most tiles one frame generated.
    pub max_generated: usize,
    pub generated: usize,
    pub evicted: usize,
    /// Frames that drew some tile from a coarser one.
    pub frames_deferred: usize,
    /// Frames whose selection was coarsened to fit the atlas.
    pub frames_coarsened: usize,
    pub median_visible: f64,
    /// GPU time of the `texturing.*` passes per frame: min, median, max (ms).
    pub generation_gpu_ms: [f64; 3],
    /// Per tile generated, GPU time of all `texturing.*` passes (median over
    /// frames that generated any tile, ms).
    pub gpu_ms_per_tile: f64,
    /// The same per `texturing.*` pass (upsample, each layer, finish).
    pub pass_ms_per_tile: Vec<(String, f64)>,
}

/// GPU time of a frame's `texturing.*` passes (ms).
pub fn generation_gpu_ms(profile: &FrameProfile) -> f64 {
    let passes = profile.passes.iter().filter(|p| p.name.starts_with("texturing."));
    passes.map(|p| p.gpu_ms).sum()
}

impl TextureSummary {
    /// The summary of `stats` with the GPU times of the `profiles` of the
    /// same frames (matched by frame number).
    pub fn new(stats: &[TextureFrameStats], profiles: &[FrameProfile]) -> TextureSummary {
        let (hits, visible) = stats
            .iter()
            .fold((0, 0), |(h, v), s| (h + s.tiles.hits, v + s.tiles.visible));
        let gpu: Vec<(u64, f64)> = profiles.iter().map(|p| (p.frame, generation_gpu_ms(p))).collect();
        let times: Vec<f64> = gpu.iter().map(|g| g.1).collect();
        let per_tile = stats.iter().filter(|s| s.tiles.generated > 0).filter_map(|s| {
            let (_, ms) = gpu.iter().find(|g| g.0 == s.frame)?;
            Some(ms / s.tiles.generated as f64)
        });
        let generating: Vec<(&TextureFrameStats, &FrameProfile)> = (stats.iter())
            .filter(|s| s.tiles.generated > 0)
            .filter_map(|s| Some((s, profiles.iter().find(|p| p.frame == s.frame)?)))
            .collect();
        let names = profiles
            .first()
            .map_or(Vec::new(), |p| p.passes.iter().map(|q| q.name.clone()).collect());
        let pass_ms_per_tile = (names.into_iter())
            .filter(|n| n.starts_with("texturing."))
            .map(|name| {
                let per_tile = generating.iter().filter_map(|(s, p)| {
                    let pass = p.passes.iter().find(|q| q.name == name)?;
                    Some(pass.gpu_ms / s.tiles.generated as f64)
                });
                let ms = median(per_tile);
                (name, ms)
            })
            .collect();
        let settled_at = stats.iter().position(|s| s.tiles.deferred == 0);
        let steady_hit_rate = settled_at.map(|i| {
            let rest = &stats[i..];
            let (h, v) = rest
                .iter()
                .fold((0, 0), |(h, v), s| (h + s.tiles.hits, v + s.tiles.visible));
            if v == 0 {
                1.0
            } else {
                h as f64 / v as f64
            }
        });
        TextureSummary {
            settled_at,
            steady_hit_rate,
            pass_ms_per_tile,
            frames: stats.len(),
            hit_rate: if visible == 0 {
                1.0
            } else {
                hits as f64 / visible as f64
            },
            max_generated: stats.iter().map(|s| s.tiles.generated).max().unwrap_or(0),
            generated: stats.iter().map(|s| s.tiles.generated).sum(),
            evicted: stats.iter().map(|s| s.tiles.evicted).sum(),
            frames_deferred: stats.iter().filter(|s| s.tiles.deferred > 0).count(),
            frames_coarsened: stats.iter().filter(|s| s.coarsened > 0).count(),
            median_visible: median(stats.iter().map(|s| s.tiles.visible as f64)),
            generation_gpu_ms: match times.is_empty() {
                true => [0.0; 3],
                false => [
                    times.iter().copied().fold(f64::INFINITY, f64::min),
                    median(times.iter().copied()),
                    times.iter().copied().fold(0.0, f64::max),
                ],
            },
            gpu_ms_per_tile: median(per_tile),
        }
    }

    /// GPU time per tile of each pass, one line; None when no frame
    /// generated a tile.
    pub fn per_pass_line(&self) -> Option<String> {
        if self.generated == 0 {
            return None;
        }
        let parts: Vec<String> = (self.pass_ms_per_tile.iter())
            .map(|(name, ms)| format!("{} {ms:.3}", name.trim_start_matches("texturing.")))
            .collect();
        Some(format!("texture generation GPU ms per tile: {}", parts.join(", ")))
    }

    /// One line for the terminal.
    pub fn line(&self) -> String {
        let [lo, med, hi] = self.generation_gpu_ms;
        let steady = match (self.settled_at, self.steady_hit_rate) {
            (Some(i), Some(r)) if i > 0 => format!(" ({r:.4} from frame {i} on, once the atlas had filled)"),
            _ => String::new(),
        };
        let per_tile = match self.generated {
            0 => String::new(),
            _ => format!(", {:.3} ms per tile", self.gpu_ms_per_tile),
        };
        let coarsened = match self.frames_coarsened {
            0 => String::new(),
            n => format!(", {n} frames coarsened to fit the atlas"),
        };
        format!(
            "textures: hit rate {:.4}{steady} over {} frames, {:.0} tiles visible (median), {} generated (at most {} per frame), {} evicted, {} frames with deferred tiles{coarsened}; generation GPU min {lo:.3} median {med:.3} max {hi:.3} ms/frame{per_tile}",
            self.hit_rate, self.frames, self.median_visible, self.generated, self.max_generated, self.evicted, self.frames_deferred
        )
    }
}

/// A profile of `frame` whose passes took `passes` (name, GPU ms) one
/// after the other, for tests.
#[cfg(test)]
pub(crate) fn test_profile(frame: u64, passes: &[(&str, f64)]) -> FrameProfile {
    let passes: Vec<crate::profile::PassTiming> = (passes.iter())
        .map(|&(name, gpu_ms)| crate::profile::PassTiming {
            name: name.into(),
            gpu_ms,
            cpu_ms: 0.0,
            gpu_start_ms: 0.0,
            cpu_start_ms: 0.0,
            pipeline_stats: None,
        })
        .collect();
    FrameProfile {
        frame,
        gpu_ms: passes.iter().map(|p| p.gpu_ms).sum(),
        passes,
        cpu_ms: 1.0,
        ..FrameProfile::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(frame: u64, visible: usize, hits: usize, generated: usize, deferred: usize) -> TextureFrameStats {
        TextureFrameStats {
            frame,
            tiles: TileStats {
                visible,
                hits,
                generated,
                deferred,
                ..TileStats::default()
            },
            ..TextureFrameStats::default()
        }
    }

    fn profile(frame: u64, layer_ms: f64) -> FrameProfile {
        test_profile(frame, &[("terrain.draw", 100.0), ("texturing.layer0.rock", layer_ms)])
    }

    #[test]
    fn summary_counts_steady_state_and_cost_per_tile() {
        let stats = [frame(0, 10, 0, 4, 6), frame(1, 10, 4, 6, 0), frame(2, 10, 10, 0, 0)];
        let profiles = [profile(0, 8.0), profile(1, 12.0), profile(2, 0.5)];
        let s = TextureSummary::new(&stats, &profiles);
        assert_eq!(
            (s.frames, s.generated, s.max_generated, s.frames_deferred),
            (3, 10, 6, 1)
        );
        assert!((s.hit_rate - 14.0 / 30.0).abs() < 1e-12);
        assert_eq!((s.settled_at, s.steady_hit_rate), (Some(1), Some(0.7)));
        // Generating frames: 8 ms / 4 tiles and 12 ms / 6 tiles.
        assert_eq!(s.gpu_ms_per_tile, 2.0);
        assert_eq!(s.pass_ms_per_tile, [("texturing.layer0.rock".to_string(), 2.0)]);
        assert_eq!(s.generation_gpu_ms, [0.5, 8.0, 12.0]);
        assert!(s.line().contains("0.7000 from frame 1 on"), "{}", s.line());
        let idle = TextureSummary::new(&stats[2..], &profiles[2..]);
        assert!(idle.per_pass_line().is_none() && !idle.line().contains("per tile"));
    }
}
