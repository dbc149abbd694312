//! The neighbourhood search of non-parametric height-field synthesis
//! (dissertation §7.3; `ALGORITHMS.md` §2): for a pixel to fill, compare its
//! partly known n×n neighbourhood with every candidate window of the
//! exemplar and pick one of the closest.
//!
//! The rule, shared exactly by [`CpuSearch`] and the GPU search (the
//! compute passes in `glsl/synthesis/`):
//!
//! ```text
//! s(c)   = Σ_t w_t·[(h_t − h'_t)² + λ·((hx_t − hx'_t)² + (hy_t − hy'_t)²)]
//!          (λ = +∞: Σ_t w_t·[(hx_t − hx'_t)² + (hy_t − hy'_t)²], slopes only,
//!          the text's "no height criterion" of Fig. 7.4)
//! d(c)   = s(c) / Σ_t w_t
//! best   = min_c s(c)
//! accept = { c : s(c) ≤ (1 + ε)·best }
//! choice = the accepted c with the smallest (hash(seed, pixel, c), c)
//! ```
//!
//! The decision compares the weighted sums s(c): Σ_t w_t is the same for
//! every candidate of a query, so this is the text's rule on d, and it needs
//! only additions and multiplications, which Vulkan rounds correctly, so a
//! GPU that keeps the sum's order and contracts nothing (`precise`) agrees
//! with the CPU bit for bit. The division gives the reported distances only.
//!
//! `t` runs over the window's taps row by row (dy outer, dx inner, from
//! −(n−1)/2), `w_t = G·v` is the query's weight of tap `t` (0 where the
//! query's pixel is unknown), `(h', hx', hy')` the exemplar's texel under
//! tap `t` of the window centred at candidate `c`. The random pick among the
//! accepted candidates is a hash rather than a generator so that every
//! candidate can be judged in parallel and the result does not depend on
//! the order of evaluation: for a fixed pixel the hashes of the candidates
//! are independent and uniform, so the smallest one is a uniform choice.

use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};
use std::sync::{mpsc, Arc};

use crate::error::{Error, Result};

/// The exemplar a search reads: texels `(h, ∂h/∂x, ∂h/∂y)` row-major, and
/// the centres of the candidate windows (texel indices `row·width + column`;
/// each window lies inside the grid and is fully known).
#[derive(Clone, Debug, PartialEq)]
pub struct Exemplar {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 3]>,
    pub candidates: Vec<u32>,
}

impl Exemplar {
    /// The texel indices of a `width`×`height` grid whose `window`-wide
    /// window lies inside it, row-major (candidates before any filtering
    /// for known texels).
    pub fn inside_centres(width: u32, height: u32, window: u32) -> Vec<u32> {
        let r = window / 2;
        (0..width * height)
            .filter(|i| {
                let (x, y) = (i % width, i / width);
                x >= r && y >= r && x + r < width && y + r < height
            })
            .collect()
    }
}

/// The search's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchConfig {
    /// Window side n (odd).
    pub window: u32,
    /// Weight λ of the derivative channels (+∞: derivatives only, no
    /// height term).
    pub lambda: f32,
    /// Candidate tolerance ε ≥ 0.
    pub epsilon: f32,
    /// Seed of the random choice.
    pub seed: u32,
}

/// One pixel to fill: its index in the output grid (only the hash reads it)
/// and its window's taps `(h, hx, hy, w)`, n² of them in tap order (module
/// docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Query {
    pub pixel: u32,
    pub taps: Vec<[f32; 4]>,
}

/// The search's answer for one query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// Index into [`Exemplar::candidates`].
    pub candidate: u32,
    /// d of the chosen candidate (the normalised s).
    pub distance: f32,
    /// The smallest d over all candidates.
    pub best: f32,
}

/// A neighbourhood search (module docs): the CPU twin [`CpuSearch`] or the
/// GPU compute passes.
pub trait NeighbourhoodSearch {
    /// One choice per query, in query order.
    fn choose(&mut self, queries: &[Query]) -> Result<Vec<Choice>>;

    /// [`NeighbourhoodSearch::choose`], calling `progress` with the number
    /// of queries answered so far while it works (a long wave is not
    /// silent: [`CpuSearch`] reports about every `PROGRESS_INTERVAL`, the
    /// GPU search after each batch). By default it reports once at the end.
    fn choose_reporting(&mut self, queries: &[Query], progress: &mut dyn FnMut(usize)) -> Result<Vec<Choice>> {
        let choices = self.choose(queries)?;
        progress(queries.len());
        Ok(choices)
    }
}

/// How often [`CpuSearch`] reports the queries answered within a wave.
pub const PROGRESS_INTERVAL: std::time::Duration = std::time::Duration::from_millis(200);

/// lowbias32 (Chris Wellons' integer hash), the same in GLSL.
pub fn lowbias32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The hash that orders the accepted candidates of `pixel`.
pub fn choice_hash(seed: u32, pixel: u32, candidate: u32) -> u32 {
    lowbias32(lowbias32(lowbias32(seed) ^ pixel) ^ candidate)
}

/// Checks that `exemplar`, `config` and `queries` fit together; every
/// search calls this first.
pub fn check(exemplar: &Exemplar, config: &SearchConfig, queries: &[Query]) -> Result<()> {
    let n = config.window;
    if n == 0 || n % 2 == 0 {
        return Err(Error::invalid(
            "--window",
            format!("{n} is not an odd number of samples"),
        ));
    }
    if config.lambda.is_nan() || config.lambda < 0.0 {
        return Err(Error::invalid(
            "--lambda",
            format!("{} is not a number ≥ 0 (or inf)", config.lambda),
        ));
    }
    if !(config.epsilon.is_finite() && config.epsilon >= 0.0) {
        return Err(Error::invalid(
            "--epsilon",
            format!("{} is not a finite number ≥ 0", config.epsilon),
        ));
    }
    if exemplar.texels.len() != exemplar.width as usize * exemplar.height as usize {
        return Err(Error::invalid("exemplar", "texel count differs from width × height"));
    }
    if exemplar.candidates.is_empty() {
        return Err(Error::invalid("exemplar", "no fully known window to copy from"));
    }
    let r = n / 2;
    let inside = |c: u32| {
        let (x, y) = (c % exemplar.width.max(1), c / exemplar.width.max(1));
        x >= r && y >= r && x + r < exemplar.width && y + r < exemplar.height
    };
    if let Some(c) = exemplar.candidates.iter().find(|&&c| !inside(c)) {
        return Err(Error::invalid(
            "exemplar",
            format!("candidate {c} has a window outside the grid"),
        ));
    }
    let taps = (n * n) as usize;
    if let Some(q) = queries.iter().find(|q| q.taps.len() != taps) {
        return Err(Error::invalid(
            "query",
            format!(
                "pixel {} has {} taps, a {n}×{n} window has {taps}",
                q.pixel,
                q.taps.len()
            ),
        ));
    }
    Ok(())
}

/// Σ_t w_t of a query (module docs).
pub fn total_weight(query: &Query) -> f32 {
    query.taps.iter().map(|t| t[3]).sum()
}

/// s(c) of the module docs for the window centred at texel `centre`: taps
/// in order, each term `w·(dh² + λ·(dhx² + dhy²))` (`w·(dhx² + dhy²)` for
/// λ = +∞) added to the running sum (the GPU keeps exactly this order and
/// rounding).
pub fn weighted_mismatch(exemplar: &Exemplar, config: &SearchConfig, query: &Query, centre: u32) -> f32 {
    let n = config.window as i64;
    let r = n / 2;
    let width = exemplar.width as i64;
    let (cx, cy) = (centre as i64 % width, centre as i64 / width);
    let mut sum = 0.0f32;
    for dy in -r..=r {
        for dx in -r..=r {
            let tap = query.taps[((dy + r) * n + dx + r) as usize];
            if tap[3] == 0.0 {
                continue;
            }
            let texel = exemplar.texels[((cy + dy) * width + cx + dx) as usize];
            let dh = tap[0] - texel[0];
            let dhx = tap[1] - texel[1];
            let dhy = tap[2] - texel[2];
            let slopes = dhx * dhx + dhy * dhy;
            let mismatch = if config.lambda.is_infinite() {
                slopes
            } else {
                dh * dh + config.lambda * slopes
            };
            sum += tap[3] * mismatch;
        }
    }
    sum
}

/// The rule's choice for one query given every candidate's s(c) and the
/// query's Σ w (module docs).
pub fn choose_from(sums: &[f32], total_weight: f32, config: &SearchConfig, pixel: u32) -> Choice {
    let best = sums.iter().copied().fold(f32::INFINITY, f32::min);
    let threshold = (1.0 + config.epsilon) * best;
    let mut pick: Option<(u32, u32)> = None;
    for (c, &s) in sums.iter().enumerate() {
        if s <= threshold {
            let key = (choice_hash(config.seed, pixel, c as u32), c as u32);
            if pick.map_or(true, |p| key < p) {
                pick = Some(key);
            }
        }
    }
    let candidate = pick.map_or(0, |(_, c)| c);
    normalised_choice(
        candidate,
        sums.get(candidate as usize).copied().unwrap_or(best),
        best,
        total_weight,
    )
}

/// The [`Choice`] of `candidate` from its s and the best s: both divided by
/// the query's Σ w (0 when no tap is known), as every search reports it.
pub fn normalised_choice(candidate: u32, chosen_sum: f32, best: f32, total_weight: f32) -> Choice {
    let normalise = |s: f32| if total_weight > 0.0 { s / total_weight } else { 0.0 };
    Choice {
        candidate,
        distance: normalise(chosen_sum),
        best: normalise(best),
    }
}

/// The CPU twin of the GPU search: every candidate's distance, then the
/// rule; queries are split over the machine's threads.
pub struct CpuSearch {
    pub exemplar: Arc<Exemplar>,
    pub config: SearchConfig,
}

impl NeighbourhoodSearch for CpuSearch {
    fn choose(&mut self, queries: &[Query]) -> Result<Vec<Choice>> {
        self.choose_reporting(queries, &mut |_| {})
    }

    /// The workers count the queries they answered; this thread waits for
    /// them and reports the count every `PROGRESS_INTERVAL`.
    fn choose_reporting(&mut self, queries: &[Query], progress: &mut dyn FnMut(usize)) -> Result<Vec<Choice>> {
        check(&self.exemplar, &self.config, queries)?;
        let threads = std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(queries.len().max(1));
        let chunk = queries.len().div_ceil(threads).max(1);
        let (exemplar, config) = (&*self.exemplar, &self.config);
        let answered = AtomicUsize::new(0);
        let mut out = Vec::with_capacity(queries.len());
        std::thread::scope(|scope| {
            let (done_tx, done_rx) = mpsc::channel::<()>();
            let answered = &answered;
            let workers: Vec<_> = queries
                .chunks(chunk)
                .map(|part| {
                    let done_tx = done_tx.clone();
                    scope.spawn(move || {
                        let mut sums = vec![0.0f32; exemplar.candidates.len()];
                        let choices = part
                            .iter()
                            .map(|q| {
                                for (s, &c) in sums.iter_mut().zip(&exemplar.candidates) {
                                    *s = weighted_mismatch(exemplar, config, q, c);
                                }
                                answered.fetch_add(1, AtomicOrdering::Relaxed);
                                choose_from(&sums, total_weight(q), config, q.pixel)
                            })
                            .collect::<Vec<_>>();
                        // The receiver outlives every worker; a failed send cannot happen.
                        let _ = done_tx.send(());
                        choices
                    })
                })
                .collect();
            drop(done_tx);
            // Until every worker has sent (or dropped its sender on a panic).
            loop {
                match done_rx.recv_timeout(PROGRESS_INTERVAL) {
                    Ok(()) => {}
                    Err(mpsc::RecvTimeoutError::Timeout) => progress(answered.load(AtomicOrdering::Relaxed)),
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                }
            }
            for worker in workers {
                // A worker only panics on a bug; report it as an error.
                match worker.join() {
                    Ok(part) => out.extend(part),
                    Err(_) => return Err(Error::Graph("a CPU search thread panicked".into())),
                }
            }
            Ok(())
        })?;
        progress(queries.len());
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(width: u32, height: u32) -> Exemplar {
        let texels = (0..width * height).map(|i| [(i % width) as f32, 1.0, 0.0]).collect();
        Exemplar {
            width,
            height,
            texels,
            candidates: Exemplar::inside_centres(width, height, 3),
        }
    }

    #[test]
    fn an_exact_match_is_found_and_only_known_taps_count() {
        let exemplar = Arc::new(ramp(8, 5));
        let config = SearchConfig {
            window: 3,
            lambda: 1.0,
            epsilon: 0.0,
            seed: 7,
        };
        // The window centred at column 4: heights 3, 4, 5; the right column unknown.
        let taps = (0..9)
            .map(|t| {
                let dx = t % 3;
                [3.0 + dx as f32, 1.0, 0.0, if dx == 2 { 0.0 } else { 1.0 }]
            })
            .collect();
        let mut search = CpuSearch {
            exemplar: exemplar.clone(),
            config,
        };
        let choice = search.choose(&[Query { pixel: 0, taps }]).unwrap()[0];
        assert_eq!(choice.best, 0.0);
        let centre = exemplar.candidates[choice.candidate as usize];
        assert_eq!(centre % 8, 4, "matched column");
    }

    #[test]
    fn a_tolerance_admits_several_candidates_and_the_seed_picks() {
        let exemplar = Arc::new(ramp(16, 3));
        let taps: Vec<[f32; 4]> = (0..9).map(|_| [7.0, 1.0, 0.0, 1.0]).collect();
        let pick = |seed, epsilon| {
            let config = SearchConfig {
                window: 3,
                lambda: 0.0,
                epsilon,
                seed,
            };
            let mut search = CpuSearch {
                exemplar: exemplar.clone(),
                config,
            };
            search
                .choose(&[Query {
                    pixel: 3,
                    taps: taps.clone(),
                }])
                .unwrap()[0]
                .candidate
        };
        assert_eq!(pick(1, 0.0), pick(2, 0.0), "ε = 0 admits only the best");
        let picks: std::collections::BTreeSet<u32> = (0..32).map(|s| pick(s, 1e6)).collect();
        assert!(picks.len() > 4, "a large ε spreads the choice: {picks:?}");
    }

    #[test]
    fn mismatched_queries_are_errors() {
        let exemplar = Arc::new(ramp(8, 5));
        let mut config = SearchConfig {
            window: 3,
            lambda: 1.0,
            epsilon: 0.0,
            seed: 0,
        };
        let mut search = CpuSearch {
            exemplar: exemplar.clone(),
            config,
        };
        let err = search
            .choose(&[Query {
                pixel: 0,
                taps: vec![[0.0; 4]; 4],
            }])
            .unwrap_err();
        assert!(err.to_string().contains("taps"), "{err}");
        config.window = 4;
        let mut search = CpuSearch { exemplar, config };
        assert!(search.choose(&[]).unwrap_err().to_string().contains("--window"));
    }
}
