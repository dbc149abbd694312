//! The GPU neighbourhood search of height-field synthesis (dissertation
//! §7.3; `ALGORITHMS.md` §2) against its CPU twin: random exemplars and
//! partly known queries over windows 3–17, with and without the derivative
//! channels and the tolerance, split into batches or not; the choices must
//! be the same candidates and the distances the same bits (both sum the
//! same terms in the same order with correctly rounded operations only).
//! Ties, an empty query list and bad input too, all under validation.

use std::sync::Arc;

use crate::random::SplitMix64;
use crate::synthesis::gpu::{GpuSearch, GpuSearchLimits};
use crate::synthesis::search::{Choice, CpuSearch, Exemplar, NeighbourhoodSearch, Query, SearchConfig};
use crate::test_support::{assert_validation_clean, validated_context};
use crate::vulkan::Context;

/// A `width`×`height` exemplar of random heights and slopes whose
/// candidates are every centre with a `window`-wide window inside the grid.
fn random_exemplar(rng: &mut SplitMix64, width: u32, height: u32, window: u32) -> Exemplar {
    let texels = (0..width * height)
        .map(|_| {
            let h = (rng.next_f64() * 100.0) as f32;
            let (hx, hy) = rng.gaussian_pair();
            [h, hx as f32, hy as f32]
        })
        .collect();
    Exemplar {
        width,
        height,
        texels,
        candidates: Exemplar::inside_centres(width, height, window),
    }
}

/// `count` queries: half copied from an exemplar window (plus small noise
/// on some), half random; about `known` of the taps known with Gaussian
/// weights, the others weight 0 and NaN values (which must be skipped).
fn random_queries(rng: &mut SplitMix64, exemplar: &Exemplar, window: u32, count: usize, known: f64) -> Vec<Query> {
    let (n, r) = (window as i64, window as i64 / 2);
    (0..count)
        .map(|k| {
            let centre = exemplar.candidates[(rng.next_u64() % exemplar.candidates.len() as u64) as usize];
            let (cx, cy) = (i64::from(centre % exemplar.width), i64::from(centre / exemplar.width));
            let noise = if k % 4 == 1 { 0.5 } else { 0.0 };
            let taps = (0..n * n)
                .map(|t| {
                    let (dx, dy) = (t % n - r, t / n - r);
                    if rng.next_f64() >= known {
                        return [f32::NAN, f32::NAN, f32::NAN, 0.0];
                    }
                    let w = (-((dx * dx + dy * dy) as f64) / (2.0 * (n as f64 / 6.4).powi(2))).exp() as f32;
                    if k % 2 == 0 {
                        let texel = exemplar.texels[((cy + dy) * i64::from(exemplar.width) + cx + dx) as usize];
                        let jitter = (rng.next_f64() * noise) as f32;
                        [texel[0] + jitter, texel[1], texel[2] - jitter, w]
                    } else {
                        let (hx, hy) = rng.gaussian_pair();
                        [(rng.next_f64() * 100.0) as f32, hx as f32, hy as f32, w]
                    }
                })
                .collect();
            Query {
                pixel: rng.next_u64() as u32 % 100_000,
                taps,
            }
        })
        .collect()
}

/// Fails unless `gpu` and `cpu` are the same choices, distances bit for bit.
fn assert_same(gpu: &[Choice], cpu: &[Choice], what: &str) {
    assert_eq!(gpu.len(), cpu.len(), "{what}: choice count");
    for (q, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        assert_eq!(g.candidate, c.candidate, "{what}: query {q}: GPU {g:?}, CPU {c:?}");
        assert_eq!(
            (g.distance.to_bits(), g.best.to_bits()),
            (c.distance.to_bits(), c.best.to_bits()),
            "{what}: query {q}: GPU {g:?}, CPU {c:?}"
        );
    }
}

/// The GPU's and the CPU's choices for `queries`.
fn both(
    ctx: &Context,
    exemplar: &Arc<Exemplar>,
    config: SearchConfig,
    limits: GpuSearchLimits,
    queries: &[Query],
) -> (Vec<Choice>, Vec<Choice>) {
    let mut gpu = GpuSearch::with_limits(ctx, exemplar.clone(), config, limits).expect("GPU search");
    let mut cpu = CpuSearch {
        exemplar: exemplar.clone(),
        config,
    };
    (
        gpu.choose(queries).expect("GPU choices"),
        cpu.choose(queries).expect("CPU choices"),
    )
}

#[test]
fn gpu_choices_equal_the_cpu_twins() {
    let (ctx, report) = validated_context();
    let mut rng = SplitMix64(16);
    for (window, known, count) in [(3, 1.0, 60), (7, 0.6, 50), (11, 0.4, 40), (17, 0.5, 12)] {
        let exemplar = Arc::new(random_exemplar(&mut rng, 41, 33, window));
        let queries = random_queries(&mut rng, &exemplar, window, count, known);
        for (lambda, epsilon) in [(0.0, 0.0), (0.7, 0.0), (0.7, 0.05), (2.0, 1e3), (f32::INFINITY, 0.05)] {
            let config = SearchConfig {
                window,
                lambda,
                epsilon,
                seed: 5 + window,
            };
            // Several batches: neither the batch nor the s buffer holds all queries.
            let limits = GpuSearchLimits {
                distance_bytes: 9 * exemplar.candidates.len() as u64 * 4,
                ..GpuSearchLimits::default()
            };
            let (gpu, cpu) = both(&ctx, &exemplar, config, limits, &queries);
            let what = format!("window {window}, λ {lambda}, ε {epsilon}");
            assert_same(&gpu, &cpu, &what);
            // Exact copies (even queries) are found: best 0.
            for q in (0..count).step_by(4) {
                assert_eq!(cpu[q].best, 0.0, "{what}: query {q} is a copy");
            }
            if epsilon > 100.0 {
                let spread: std::collections::BTreeSet<u32> = cpu.iter().map(|c| c.candidate).collect();
                assert!(spread.len() > count / 2, "{what}: a large ε spreads the choice");
            }
        }
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn splitting_into_batches_changes_nothing() {
    let (ctx, report) = validated_context();
    let mut rng = SplitMix64(7);
    let exemplar = Arc::new(random_exemplar(&mut rng, 30, 30, 7));
    let queries = random_queries(&mut rng, &exemplar, 7, 23, 0.7);
    let config = SearchConfig {
        window: 7,
        lambda: 0.3,
        epsilon: 0.2,
        seed: 99,
    };
    let row = exemplar.candidates.len() as u64 * 4;
    let mut whole = GpuSearch::new(&ctx, exemplar.clone(), config).expect("GPU search");
    assert!(whole.batch_queries() as usize >= queries.len());
    let reference = whole.choose(&queries).expect("one batch");
    // The s buffer, the batch and the workgroups along the candidates limited.
    for (distance_bytes, batch_queries, candidate_workgroups, batch) in [
        (5 * row + 3, 4096, u32::MAX, 5),
        (u64::MAX, 4, u32::MAX, 4),
        (row, 4096, u32::MAX, 1),
        (u64::MAX, 4096, 1, 4096),
    ] {
        let limits = GpuSearchLimits {
            distance_bytes,
            batch_queries,
            candidate_workgroups,
        };
        let mut split = GpuSearch::with_limits(&ctx, exemplar.clone(), config, limits).expect("GPU search");
        assert_eq!(split.batch_queries(), batch, "{limits:?}");
        // Twice: the graph runs again with new uploads.
        for _ in 0..2 {
            assert_same(
                &split.choose(&queries).expect("batches"),
                &reference,
                &format!("{limits:?}"),
            );
        }
        assert_same(
            &split.choose(&queries[3..9]).expect("a part"),
            &reference[3..9],
            "a part",
        );
    }
    let mut cpu = CpuSearch { exemplar, config };
    assert_same(&reference, &cpu.choose(&queries).expect("CPU"), "CPU");
    drop((whole, ctx));
    assert_validation_clean(&report);
}

#[test]
fn ties_are_broken_by_the_same_hash() {
    let (ctx, report) = validated_context();
    // A periodic exemplar: every window repeats every 4 texels, and every
    // candidate is listed twice, so many candidates have the same s.
    let (width, height) = (24u32, 20u32);
    let texels = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            [((x % 4) * 3 + (y % 4)) as f32, (x % 4) as f32 * 0.5, 0.25]
        })
        .collect();
    let mut candidates = Exemplar::inside_centres(width, height, 3);
    candidates.extend(candidates.clone());
    let exemplar = Arc::new(Exemplar {
        width,
        height,
        texels,
        candidates,
    });
    let mut rng = SplitMix64(3);
    let queries: Vec<Query> = (0..40)
        .map(|k| {
            let centre = exemplar.candidates[(rng.next_u64() % exemplar.candidates.len() as u64) as usize];
            let (cx, cy) = (centre % width, centre / width);
            let taps = (0..9)
                .map(|t| {
                    let texel = exemplar.texels[((cy + t / 3 - 1) * width + cx + t % 3 - 1) as usize];
                    [
                        texel[0],
                        texel[1],
                        texel[2],
                        if t == 4 && k % 3 == 0 { 0.0 } else { 1.0 },
                    ]
                })
                .collect();
            Query { pixel: k * 17, taps }
        })
        .collect();
    for epsilon in [0.0, 0.5] {
        let config = SearchConfig {
            window: 3,
            lambda: 1.0,
            epsilon,
            seed: 11,
        };
        let (gpu, cpu) = both(&ctx, &exemplar, config, GpuSearchLimits::default(), &queries);
        assert_same(&gpu, &cpu, &format!("ties, ε {epsilon}"));
        let picks: std::collections::BTreeSet<u32> = gpu.iter().map(|c| c.candidate).collect();
        assert!(picks.len() > 20, "the hash spreads tied choices: {picks:?}");
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn degenerate_sums_are_handled_like_the_cpu() {
    let (ctx, report) = validated_context();
    let mut rng = SplitMix64(4);
    let exemplar = Arc::new(random_exemplar(&mut rng, 14, 12, 3));
    let query = |pixel: u32, tap: [f32; 4]| Query {
        pixel,
        taps: vec![tap; 9],
    };
    let queries = vec![
        // Nothing known: every s is 0, every candidate accepted, d = 0.
        query(1, [f32::NAN, 0.0, 0.0, 0.0]),
        // A NaN weight: every s is NaN, nothing accepted, candidate 0.
        query(2, [1.0, 0.0, 0.0, f32::NAN]),
        // Overflow: every s is +∞, all accepted (∞ ≤ ∞).
        query(3, [3e38, 0.0, 0.0, 1.0]),
        // Negative heights, known.
        query(4, [-5.0, 1.0, -1.0, 0.5]),
    ];
    for epsilon in [0.0, 1.0] {
        let config = SearchConfig {
            window: 3,
            lambda: 0.5,
            epsilon,
            seed: 8,
        };
        let (gpu, cpu) = both(&ctx, &exemplar, config, GpuSearchLimits::default(), &queries);
        assert_same(&gpu, &cpu, &format!("degenerate, ε {epsilon}"));
        assert_eq!(cpu[1].candidate, 0, "nothing accepted");
        assert_eq!(cpu[2].best, f32::INFINITY);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn passes_are_named_and_timed_and_an_empty_list_is_no_work() {
    let (ctx, report) = validated_context();
    let mut rng = SplitMix64(1);
    let exemplar = Arc::new(random_exemplar(&mut rng, 16, 16, 3));
    let config = SearchConfig {
        window: 3,
        lambda: 1.0,
        epsilon: 0.0,
        seed: 0,
    };
    let mut search = GpuSearch::new(&ctx, exemplar.clone(), config).expect("GPU search");
    assert_eq!(search.choose(&[]).expect("empty"), Vec::<Choice>::new());
    let names = [
        "synthesis.clear",
        "synthesis.distance",
        "synthesis.accept",
        "synthesis.pick",
        "synthesis.resolve",
    ];
    assert_eq!(search.pass_names(), names);
    let queries = random_queries(&mut rng, &exemplar, 3, 5, 1.0);
    search.choose(&queries).expect("choices");
    let profiles = search.take_profiles().expect("profiles");
    assert_eq!(profiles.len(), 1, "one batch");
    let timed: Vec<&str> = profiles[0].passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(timed, names);
    drop((search, ctx));
    assert_validation_clean(&report);
}

#[test]
fn bad_input_is_a_one_line_error() {
    let (ctx, report) = validated_context();
    let mut rng = SplitMix64(2);
    let exemplar = Arc::new(random_exemplar(&mut rng, 12, 12, 5));
    let config = SearchConfig {
        window: 5,
        lambda: 1.0,
        epsilon: 0.0,
        seed: 0,
    };
    let error = |result: crate::Result<GpuSearch>| match result {
        Ok(_) => panic!("accepted bad input"),
        Err(e) => e.to_string(),
    };
    let one_line = |message: String, names: &str| {
        assert!(!message.contains('\n'), "{message}");
        assert!(message.contains(names), "{message} should name {names}");
    };
    for (window, lambda, epsilon, names) in [
        (4, 1.0, 0.0, "--window"),
        (0, 1.0, 0.0, "--window"),
        (5, -1.0, 0.0, "--lambda"),
        (5, f32::NAN, 0.0, "--lambda"),
        (5, 1.0, f32::NAN, "--epsilon"),
    ] {
        let bad = SearchConfig {
            window,
            lambda,
            epsilon,
            seed: 0,
        };
        one_line(error(GpuSearch::new(&ctx, exemplar.clone(), bad)), names);
    }
    // A window larger than the exemplar's candidates allow.
    let wide = SearchConfig { window: 7, ..config };
    one_line(error(GpuSearch::new(&ctx, exemplar.clone(), wide)), "outside the grid");
    let empty = Arc::new(Exemplar {
        candidates: Vec::new(),
        ..(*exemplar).clone()
    });
    one_line(error(GpuSearch::new(&ctx, empty, config)), "exemplar");
    // Not even one query's s fits the batch.
    let tiny = GpuSearchLimits {
        distance_bytes: 8,
        ..GpuSearchLimits::default()
    };
    one_line(
        error(GpuSearch::with_limits(&ctx, exemplar.clone(), config, tiny)),
        "synthesis search",
    );
    let mut search = GpuSearch::new(&ctx, exemplar.clone(), config).expect("GPU search");
    let short = Query {
        pixel: 4,
        taps: vec![[0.0; 4]; 9],
    };
    let mut queries = random_queries(&mut rng, &exemplar, 5, 3, 1.0);
    queries.push(short);
    match search.choose(&queries) {
        Ok(_) => panic!("accepted a 3×3 query in a 5×5 search"),
        Err(e) => one_line(e.to_string(), "taps"),
    }
    // The search still works after the error.
    assert_eq!(search.choose(&queries[..3]).expect("good queries").len(), 3);
    drop((search, ctx));
    assert_validation_clean(&report);
}
