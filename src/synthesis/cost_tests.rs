use std::time::Instant;

use glam::DVec2;

use super::*;
use crate::io::heightmap::HeightField;
use crate::synthesis::fill::fill_holes_cpu;
use crate::synthesis::transition::Axis;

const CPU: SearchDevice = SearchDevice::Cpu { threads: 2 };

fn fill(columns: u32, unknown: u64, window: u32, candidates: usize) -> GrowthCost {
    let params = FillParams {
        window,
        candidates,
        ..FillParams::default()
    };
    GrowthCost::fill(columns, columns, unknown, &params)
}

fn unlimited() -> MemoryLimits {
    MemoryLimits {
        host: u64::MAX,
        device: u64::MAX,
        device_allocation: u64::MAX,
    }
}

#[test]
fn estimates_grow_with_every_size() {
    let base = fill(512, 400, 7, 4096);
    let (t, m) = (base.seconds(CPU), base.footprint(CPU).host);
    for bigger in [
        fill(1024, 400, 7, 4096),
        fill(512, 800, 7, 4096),
        fill(512, 400, 9, 4096),
        fill(512, 400, 7, 8192),
    ] {
        assert!(bigger.seconds(CPU) > t, "{bigger:?}");
        assert!(bigger.footprint(CPU).host >= m, "{bigger:?}");
    }
    let batch = GrowthCost {
        batch: 4096,
        ..base.clone()
    };
    assert!(batch.footprint(CPU).host > m, "larger waves hold more queries");
    // More threads: faster, never slower.
    assert!(base.seconds(SearchDevice::Cpu { threads: 8 }) < t);
    assert!(base.seconds(SearchDevice::Gpu) < base.seconds(SearchDevice::CpuDevice { threads: 2 }));
    // The search dominates: twice the candidates, about twice the time.
    let ratio = fill(512, 400, 7, 8192).seconds(CPU) / t;
    assert!((1.8..=2.0).contains(&ratio), "{ratio}");
}

#[test]
fn candidates_are_at_most_the_windows_inside() {
    assert_eq!(fill(100, 10, 7, 1_000_000).candidates(), 94 * 94);
    assert_eq!(fill(100, 10, 7, 100).candidates(), 100);
    assert_eq!(fill(5, 10, 7, 100).candidates(), 0, "a window larger than the field");
}

#[test]
fn a_transition_counts_its_band_and_blurs() {
    let params = TransitionParams {
        band_metres: 1000.0,
        ..TransitionParams::default()
    };
    let band = Band {
        axis: Axis::X,
        start: 100,
        width: 10,
    };
    let cost = GrowthCost::transition(257, 129, &band, &params);
    assert_eq!(cost.unknown, 10 * 129);
    let wide_blur = GrowthCost::transition(
        257,
        129,
        &band,
        &TransitionParams {
            blur_radius: 100_000,
            ..params
        },
    );
    assert!(wide_blur.seconds(CPU) > 10.0 * cost.seconds(CPU));
    let e = wide_blur.check(CPU, &unlimited(), 0.5, "A/B").unwrap_err().to_string();
    assert!(
        e.starts_with("invalid --blur 100000: blurring the 257×129 field"),
        "{e}"
    );
}

/// The example: `--window 63 --candidates 1000000` on a 20×20 hole
/// of a 1025² field is about half an hour on two CPU threads and twice the
/// default hour on lavapipe; refused there with the options, the estimate
/// and the limit.
#[test]
fn absurd_combinations_are_refused_naming_options_estimate_and_limit() {
    let cost = fill(1025, 400, 63, 1_000_000);
    let limit = crate::budget::DEFAULT_MAX_HOURS * 3600.0;
    let cpu = cost.seconds(CPU);
    assert!((900.0..3600.0).contains(&cpu), "{cpu} s on the CPU");
    assert!(cost.check(CPU, &unlimited(), limit, "--input dem.png").is_ok());
    let lavapipe = SearchDevice::CpuDevice { threads: 2 };
    let e = cost
        .check(lavapipe, &unlimited(), limit, "--input dem.png")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("invalid --window 63, --candidates 1000000: growing 400 samples"),
        "{e}"
    );
    assert!(e.contains(" h; the limit is 60.0 min (--max-hours raises it)"), "{e}");
    assert!(!e.contains('\n'));
    // Memory: waves of huge queries name --batch and --window.
    let waves = GrowthCost {
        batch: 1 << 20,
        unknown: 1 << 20,
        ..fill(4097, 0, 63, 16384)
    };
    let small = MemoryLimits {
        host: 1 << 30,
        ..unlimited()
    };
    let e = waves
        .check(CPU, &small, f64::INFINITY, "--input dem.png")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("invalid --batch 1048576, --window 63: waves of 1048576 queries"),
        "{e}"
    );
    assert!(e.contains("of host memory; 1.0 GiB is available"), "{e}");
    // A field too large names how it was given.
    let e = fill(40000, 100, 7, 16384)
        .check(CPU, &small, f64::INFINITY, "--input dem.png")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("invalid --input dem.png: 40000×40000 samples"), "{e}");
}

/// The estimate against a measured tiny fill on one thread (`--batch 1`):
/// within an order of magnitude either way in an optimised build. An
/// unoptimised build (the tests' default) runs the loop 10–50× slower, so
/// there the run must only not be much faster than estimated (an estimate
/// that is too pessimistic would refuse work that fits).
#[test]
fn the_estimate_is_within_an_order_of_magnitude_of_a_tiny_run() {
    let side = 72;
    let field = HeightField::from_fn(side, side, DVec2::ONE, |c, r| {
        (c as f32 * 0.31).sin() * 20.0 + (r as f32 * 0.17).cos() * 15.0 + (c * r % 7) as f32
    });
    let unknown: Vec<bool> = (0..side * side)
        .map(|i| (30..40).contains(&(i % side)) && (30..40).contains(&(i / side)))
        .collect();
    let params = FillParams {
        window: 7,
        candidates: 2048,
        batch: 1,
        ..FillParams::default()
    };
    let cost = GrowthCost::fill(side, side, 100, &params);
    let estimate = cost.seconds(SearchDevice::Cpu { threads: 1 });
    let started = Instant::now();
    fill_holes_cpu(&field, &unknown, &params, &mut |_, _| {}).unwrap();
    let measured = started.elapsed().as_secs_f64();
    assert!(
        measured > estimate / 10.0,
        "measured {measured} s, estimated {estimate} s"
    );
    if !cfg!(debug_assertions) {
        assert!(
            measured < estimate * 10.0,
            "measured {measured} s, estimated {estimate} s"
        );
    }
}
