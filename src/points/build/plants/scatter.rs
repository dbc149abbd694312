//! Where plants grow (prepare time, CPU, deterministic): per rule (a plant
//! model with a density per m² and a scale range, owned by a surface layer)
//! a jittered grid of cells of area `1/density` over the terrain rectangle,
//! one candidate per cell at a random point of it, accepted with
//! probability equal to the owning layer's share at that point (a plant
//! grows only where its layer shows). The expected count over a region is
//! therefore `density · ∫ share dA`; a uniform share s over area A gives a
//! binomial count with mean `s·A·density`.
//!
//! Every cell draws from its own [`SplitMix64`] stream, seeded by a hash of
//! (seed, rule, cell), so a plant's place, scale (uniform in the rule's
//! range), yaw and prototype variant do not depend on the other rules or on
//! the order of evaluation. Candidates outside the rectangle (the last,
//! partial cells) are dropped, which keeps the density exact.
//!
//! The cap: when the rules would draw more than [`CANDIDATES_PER_PLANT`]
//! times `cap` candidates, all densities are scaled down alike first; when
//! more than `cap` plants are accepted, the `cap` with the smallest
//! per-plant hash are kept (a uniform random subset). Both are reported in
//! [`Scatter::thinned`] (the caller warns).

use glam::DVec2;

use crate::error::{Error, Result};
use crate::random::SplitMix64;
use crate::surface::plants::PlantModel;

/// Candidate budget per allowed plant before densities are scaled down.
pub const CANDIDATES_PER_PLANT: f64 = 4.0;

/// One way plants grow: `model` at `density` per m² where share `source`
/// shows, scaled uniformly in `scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterRule {
    pub model: PlantModel,
    /// Plants per m² where the share is 1 (≥ 0, finite).
    pub density: f64,
    /// Scale range [min, max], 0 < min ≤ max.
    pub scale: (f64, f64),
    /// Index into the shares the callback returns.
    pub source: usize,
}

/// One plant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Index of its rule.
    pub rule: usize,
    /// World xy (metres).
    pub xy: DVec2,
    pub scale: f64,
    /// Rotation about z (radians).
    pub yaw: f64,
    /// Random bits to pick a prototype variant.
    pub variant: u64,
}

/// The outcome of [`scatter`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scatter {
    pub placements: Vec<Placement>,
    /// Candidates evaluated.
    pub candidates: usize,
    /// Plants left out by the cap (0: none), expected before the cap.
    pub thinned: usize,
}

/// Hash of (seed, rule, cell).
fn cell_seed(seed: u64, rule: usize, i: u64, j: u64) -> u64 {
    let a = SplitMix64(seed ^ (rule as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64();
    let b = SplitMix64(a ^ i.wrapping_mul(0xc2b2_ae3d_27d4_eb4f)).next_u64();
    SplitMix64(b ^ j.wrapping_mul(0x1656_67b1_9e37_79f9)).next_u64()
}

/// The jittered grid of one rule.
struct Grid {
    rule: usize,
    cell: f64,
    extent: DVec2,
    seed: u64,
}

impl Grid {
    /// The plants of grid rows `rows`, and the candidates evaluated.
    fn scatter_rows(
        &self,
        rule: &ScatterRule,
        rows: std::ops::Range<u64>,
        shares: &Shares,
    ) -> Result<(Vec<Placement>, usize)> {
        let (cell, extent) = (self.cell, self.extent);
        let columns = (extent.x / cell).ceil() as u64;
        let (mut placements, mut candidates) = (Vec::new(), 0);
        for j in rows {
            for i in 0..columns {
                let mut rng = SplitMix64(cell_seed(self.seed, self.rule, i, j));
                let xy = DVec2::new((i as f64 + rng.next_f64()) * cell, (j as f64 + rng.next_f64()) * cell);
                let accept = rng.next_f64();
                let (scale, yaw, variant) = (rng.next_f64(), rng.next_f64(), rng.next_u64());
                if xy.x >= extent.x || xy.y >= extent.y {
                    continue;
                }
                candidates += 1;
                let share = shares(xy)?.get(rule.source).copied().unwrap_or(0.0).clamp(0.0, 1.0);
                if accept < f64::from(share) {
                    placements.push(Placement {
                        rule: self.rule,
                        xy,
                        scale: rule.scale.0 + (rule.scale.1 - rule.scale.0) * scale,
                        yaw: yaw * std::f64::consts::TAU,
                        variant,
                    });
                }
            }
        }
        Ok((placements, candidates))
    }
}

/// The shares of every source at a point.
pub type Shares<'a> = dyn Fn(DVec2) -> Result<Vec<f32>> + Sync + 'a;

/// Checks a rule's numbers; `what` names it in errors.
pub fn check_rule(rule: &ScatterRule, what: &str) -> Result<()> {
    if !(rule.density.is_finite() && rule.density >= 0.0) {
        return Err(Error::invalid(
            what,
            format!("density {} is not a finite number ≥ 0", rule.density),
        ));
    }
    let (lo, hi) = rule.scale;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi) {
        return Err(Error::invalid(what, format!("scale [{lo}, {hi}] is not 0 < min ≤ max")));
    }
    Ok(())
}

/// Scatters plants by `rules` over the rectangle `[0, extent]` (module
/// docs), at most `cap` of them. `shares(xy)` gives the share of every
/// source at a point (values outside [0, 1] are clamped); it is called once
/// per candidate, from as many threads as there are cores (rows of the
/// grid in bands).
pub fn scatter(rules: &[ScatterRule], extent: DVec2, seed: u64, cap: usize, shares: &Shares) -> Result<Scatter> {
    for (k, rule) in rules.iter().enumerate() {
        check_rule(rule, &format!("vegetation rule {k}"))?;
    }
    if !(extent.is_finite() && extent.x > 0.0 && extent.y > 0.0) {
        return Err(Error::invalid(
            "vegetation",
            format!("terrain extent {extent} is empty"),
        ));
    }
    let expected: f64 = rules.iter().map(|r| r.density * extent.x * extent.y).sum();
    let budget = CANDIDATES_PER_PLANT * cap as f64;
    let thin = if expected > budget { budget / expected } else { 1.0 };
    let mut out = Scatter::default();
    for (k, rule) in rules.iter().enumerate() {
        let density = rule.density * thin;
        if density <= 0.0 {
            continue;
        }
        let grid = Grid {
            rule: k,
            cell: density.recip().sqrt(),
            extent,
            seed,
        };
        let rows = (extent.y / grid.cell).ceil() as u64;
        // Bands of rows on the available cores, joined in order (deterministic).
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(8) as u64;
        let per_band = rows.div_ceil(threads).max(1);
        let bands: Vec<Result<(Vec<Placement>, usize)>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..rows)
                .step_by(per_band as usize)
                .map(|first| {
                    let grid = &grid;
                    scope.spawn(move || grid.scatter_rows(rule, first..(first + per_band).min(rows), shares))
                })
                .collect();
            (handles.into_iter())
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(Error::invalid("vegetation", "a scatter thread panicked")))
                })
                .collect()
        });
        for band in bands {
            let (placements, candidates) = band?;
            out.placements.extend(placements);
            out.candidates += candidates;
        }
    }
    let accepted = out.placements.len();
    if accepted > cap {
        // Keep the `cap` smallest hashes: a uniform subset, independent of order.
        out.placements.sort_by_key(|p| SplitMix64(p.variant).next_u64());
        out.placements.truncate(cap);
        out.placements.sort_by(|a, b| {
            (a.rule, a.xy.y, a.xy.x)
                .partial_cmp(&(b.rule, b.xy.y, b.xy.x))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
    }
    out.thinned = ((accepted as f64 / thin).round() as usize).saturating_sub(out.placements.len());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(density: f64, source: usize) -> ScatterRule {
        ScatterRule {
            model: PlantModel::Shrub,
            density,
            scale: (0.5, 2.0),
            source,
        }
    }

    fn constant(shares: Vec<f32>) -> impl Fn(DVec2) -> Result<Vec<f32>> + Sync {
        move |_| Ok(shares.clone())
    }

    #[test]
    fn deterministic_per_seed() {
        let rules = [rule(0.01, 0), rule(0.02, 1)];
        let extent = DVec2::new(300.0, 200.0);
        let run = |seed| scatter(&rules, extent, seed, 10_000, &constant(vec![0.5, 0.7])).unwrap();
        assert_eq!(run(1), run(1));
        assert_ne!(run(1).placements, run(2).placements);
        // A rule's plants do not depend on the other rules.
        let alone = scatter(&rules[..1], extent, 1, 10_000, &constant(vec![0.5, 0.7])).unwrap();
        let both = run(1);
        let first: Vec<_> = both.placements.iter().filter(|p| p.rule == 0).copied().collect();
        assert_eq!(alone.placements, first);
    }

    #[test]
    fn count_follows_area_density_and_share() {
        // Binomial: n cells, p the share; 4.5 standard deviations.
        let extent = DVec2::new(1000.0, 800.0);
        for (density, share) in [(0.01, 1.0f32), (0.01, 0.5), (0.003, 0.25), (0.02, 0.0)] {
            let out = scatter(&[rule(density, 0)], extent, 9, 1 << 20, &constant(vec![share])).unwrap();
            let n = extent.x * extent.y * density;
            let p = f64::from(share);
            let (mean, sigma) = (n * p, (n * p * (1.0 - p)).sqrt());
            let got = out.placements.len() as f64;
            assert!(
                (got - mean).abs() <= 4.5 * sigma + 1.0,
                "{density}, {share}: {got} vs {mean} ± {sigma}"
            );
            // Exact up to the partial cells along two edges.
            assert!((out.candidates as f64 - n).abs() <= (extent.x + extent.y) * density.sqrt());
            for p in &out.placements {
                assert!(p.xy.x >= 0.0 && p.xy.x < extent.x && p.xy.y >= 0.0 && p.xy.y < extent.y);
                assert!((0.5..=2.0).contains(&p.scale) && (0.0..std::f64::consts::TAU).contains(&p.yaw));
            }
        }
    }

    #[test]
    fn grows_only_where_the_share_is_positive() {
        let extent = DVec2::new(400.0, 400.0);
        let half = |xy: DVec2| Ok(vec![if xy.x < 200.0 { 1.0 } else { 0.0 }]);
        let out = scatter(&[rule(0.01, 0)], extent, 3, 100_000, &half).unwrap();
        assert!(out.placements.len() > 700 && out.placements.iter().all(|p| p.xy.x < 200.0));
    }

    #[test]
    fn the_cap_thins_uniformly_and_reports() {
        let extent = DVec2::new(1000.0, 1000.0);
        // 10 000 candidates, cap 1000: the budget (4000) scales densities first.
        let out = scatter(&[rule(0.01, 0)], extent, 5, 1000, &constant(vec![1.0])).unwrap();
        assert_eq!(out.placements.len(), 1000);
        assert!(out.candidates <= 4100);
        assert!(out.thinned > 8000 && out.thinned < 9500, "{}", out.thinned);
        // Spread over the whole rectangle, not the first rows.
        assert!(out.placements.iter().any(|p| p.xy.y > 900.0) && out.placements.iter().any(|p| p.xy.y < 100.0));
        let none = scatter(&[rule(0.01, 0)], extent, 5, 0, &constant(vec![1.0])).unwrap();
        assert!(none.placements.is_empty());
    }

    #[test]
    fn bad_rules_are_one_line_errors() {
        let extent = DVec2::new(10.0, 10.0);
        for bad in [
            ScatterRule {
                density: -1.0,
                ..rule(0.0, 0)
            },
            ScatterRule {
                density: f64::NAN,
                ..rule(0.0, 0)
            },
            ScatterRule {
                scale: (0.0, 1.0),
                ..rule(0.0, 0)
            },
            ScatterRule {
                scale: (2.0, 1.0),
                ..rule(0.0, 0)
            },
        ] {
            let e = scatter(&[bad], extent, 1, 10, &constant(vec![1.0]))
                .unwrap_err()
                .to_string();
            assert!(e.contains("vegetation rule 0") && !e.contains('\n'), "{e}");
        }
        assert!(scatter(&[], DVec2::ZERO, 1, 10, &constant(vec![])).is_err());
    }
}
