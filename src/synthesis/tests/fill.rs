//! Hole filling by pixel growing (dissertation §7.3; `synthesis::fill`) on a
//! real DEM, with the CPU search: a 128² crop of the Jacksboro SRTM model
//! (`tests/data/jacksboro-fault.png`) with four holes — a 24² square, a
//! 14×32 slot, a disc of radius 11 and a 20×16 notch on the field's edge.
//!
//! Criteria (stated in the README's "Height-field synthesis" section):
//!
//! * **Statistics**: the two-sample Kolmogorov–Smirnov statistic between
//!   the filled samples and the known samples of a ring around the holes
//!   (chessboard distance 1–8) is at most [`KS_BOUND`] = 0.25, both for
//!   the slope (gradient magnitude, central differences) and for the
//!   curvature (the 5-point Laplacian), computed on the output field.
//! * **No seam**: of the height differences across the holes' boundary
//!   (each pair of 4-neighbours, one filled and one known, as a slope),
//!   at least 95% are at most the 99th percentile of the same statistic
//!   over all pairs of known neighbours of the input.
//! * Known samples are untouched bit for bit; the same seed gives the same
//!   field, another seed another one.
//! * Sanity (the criteria can fail): a smooth membrane (Laplace)
//!   interpolation of the holes fails the statistics bound, and a constant
//!   fill (the mean height) fails the seam bound.
//!
//! Hillshades of the holes (white), the filled field and the original
//! crop are written side by side to `target/tmp/synthesis-fill-hillshade.png`
//! (Fig. 7.2).

use std::path::Path;

use crate::io::heightmap::{load_heightmap, HeightField, HeightmapOptions};
use crate::synthesis::fill::{fill_holes_cpu, plan_hole_fill, FillParams};
use glam::DVec2;

/// Upper bound of the Kolmogorov–Smirnov statistic (module docs).
const KS_BOUND: f64 = 0.25;
/// Side of the crop in samples.
const SIDE: u32 = 128;

/// The crop of the Jacksboro DEM (the rugged ridges south-west of the fault).
pub(super) fn crop() -> HeightField {
    let full = load_heightmap(
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/jacksboro-fault.png")),
        &HeightmapOptions {
            spacing: Some(DVec2::new(74.4, 92.6)),
            ..HeightmapOptions::default()
        },
    )
    .unwrap();
    let (x0, y0) = (60, 150);
    HeightField::from_fn(SIDE, SIDE, full.spacing, |c, r| full.height(x0 + c, y0 + r))
}

/// The four holes of the module docs.
fn holes() -> Vec<bool> {
    let n = SIDE as i64;
    (0..n * n)
        .map(|i| {
            let (c, r) = (i % n, i / n);
            let square = (20..44).contains(&c) && (24..48).contains(&r);
            let slot = (80..94).contains(&c) && (20..52).contains(&r);
            let disc = (c - 40).pow(2) + (r - 92).pow(2) <= 11 * 11;
            let notch = (108..128).contains(&c) && (84..100).contains(&r);
            square || slot || disc || notch
        })
        .collect()
}

/// The default parameters with `seed` and at most `candidates` candidate
/// windows: the crop has about 12k fully known windows; a third of them
/// (the nearest) keep the test's unoptimised build within seconds.
fn params(seed: u32, candidates: usize) -> FillParams {
    FillParams {
        seed,
        candidates,
        ..FillParams::default()
    }
}

/// Slope (gradient magnitude) and curvature (5-point Laplacian, per m²) of
/// `f` at an interior sample.
pub(super) fn slope_curvature(f: &HeightField, c: u32, r: u32) -> (f64, f64) {
    let h = |c: u32, r: u32| f64::from(f.height(c, r));
    let (dx, dy) = (f.spacing.x, f.spacing.y);
    let gx = (h(c + 1, r) - h(c - 1, r)) / (2.0 * dx);
    let gy = (h(c, r + 1) - h(c, r - 1)) / (2.0 * dy);
    let lap = (h(c + 1, r) - 2.0 * h(c, r) + h(c - 1, r)) / (dx * dx)
        + (h(c, r + 1) - 2.0 * h(c, r) + h(c, r - 1)) / (dy * dy);
    ((gx * gx + gy * gy).sqrt(), lap)
}

/// The two-sample Kolmogorov–Smirnov statistic: the largest distance
/// between the empirical distribution functions of `a` and `b`.
pub(super) fn ks(mut a: Vec<f64>, mut b: Vec<f64>) -> f64 {
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let (mut i, mut j, mut d) = (0, 0, 0.0f64);
    while i < a.len() && j < b.len() {
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / a.len() as f64 - j as f64 / b.len() as f64).abs());
    }
    d
}

/// Chessboard distance of each sample to the nearest hole sample (brute
/// force within 8; larger distances read as 9).
fn ring_distance(unknown: &[bool]) -> Vec<u32> {
    let n = SIDE as i64;
    (0..n * n)
        .map(|i| {
            let (c, r) = (i % n, i / n);
            (0..=8)
                .find(|&d: &i64| {
                    (-d..=d).any(|dy| {
                        (-d..=d).any(|dx| {
                            let (cc, rr) = (c + dx, r + dy);
                            cc >= 0 && rr >= 0 && cc < n && rr < n && unknown[(rr * n + cc) as usize]
                        })
                    })
                })
                .map_or(9, |d| d as u32)
        })
        .collect()
}

/// KS statistics (slope, curvature) of the filled samples against the
/// ring of known samples around them, on interior samples of `out`.
fn statistics(out: &HeightField, unknown: &[bool]) -> (f64, f64) {
    let distance = ring_distance(unknown);
    let (mut filled, mut ring) = ((vec![], vec![]), (vec![], vec![]));
    for r in 1..SIDE - 1 {
        for c in 1..SIDE - 1 {
            let i = (r * SIDE + c) as usize;
            let (s, k) = slope_curvature(out, c, r);
            let target = match distance[i] {
                0 => &mut filled,
                1..=8 => &mut ring,
                _ => continue,
            };
            target.0.push(s);
            target.1.push(k);
        }
    }
    (ks(filled.0, ring.0), ks(filled.1, ring.1))
}

/// |Δh| / spacing over 4-neighbour pairs: (pairs across the hole boundary
/// in `out`, pairs of known samples of `input`).
fn neighbour_slopes(input: &HeightField, out: &HeightField, unknown: &[bool]) -> (Vec<f64>, Vec<f64>) {
    let (mut boundary, mut known) = (vec![], vec![]);
    for r in 0..SIDE {
        for c in 0..SIDE {
            for (dc, dr, step) in [(1, 0, input.spacing.x), (0, 1, input.spacing.y)] {
                let (cc, rr) = (c + dc, r + dr);
                if cc >= SIDE || rr >= SIDE {
                    continue;
                }
                let (i, j) = ((r * SIDE + c) as usize, (rr * SIDE + cc) as usize);
                let slope = |f: &HeightField| f64::from((f.heights[i] - f.heights[j]).abs()) / step;
                match (unknown[i], unknown[j]) {
                    (false, false) => known.push(slope(input)),
                    (true, true) => {}
                    _ => boundary.push(slope(out)),
                }
            }
        }
    }
    (boundary, known)
}

/// Fraction of boundary slopes at most the input's 99th percentile.
fn seam_fraction(input: &HeightField, out: &HeightField, unknown: &[bool]) -> (f64, f64) {
    let (boundary, mut known) = neighbour_slopes(input, out, unknown);
    known.sort_by(f64::total_cmp);
    let p99 = known[(known.len() as f64 * 0.99) as usize];
    let within = boundary.iter().filter(|&&s| s <= p99).count();
    (within as f64 / boundary.len() as f64, p99)
}

/// Membrane interpolation: every hole sample the mean of its 4 neighbours
/// (Gauss–Seidel to convergence), the smoothest fill.
fn membrane(input: &HeightField, unknown: &[bool]) -> HeightField {
    let mut f = input.clone();
    let mean = 0.5 * (f.min_max().0 + f.min_max().1);
    for (h, &u) in f.heights.iter_mut().zip(unknown) {
        if u {
            *h = mean;
        }
    }
    for _ in 0..2000 {
        for r in 0..SIDE {
            for c in 0..SIDE {
                let i = (r * SIDE + c) as usize;
                if unknown[i] {
                    let n = |c: u32, r: u32| f.height(c, r);
                    let v = (n(c.saturating_sub(1), r) + n(c + 1, r) + n(c, r.saturating_sub(1)) + n(c, r + 1)) / 4.0;
                    f.heights[i] = v;
                }
            }
        }
    }
    f
}

/// A grey hillshade of `f` (light from the north-west) as RGBA.
pub(super) fn hillshade(f: &HeightField) -> Vec<u8> {
    let light = glam::DVec3::new(-0.5, 0.5, 0.7).normalize();
    let mut rgba = Vec::with_capacity(f.heights.len() * 4);
    for r in 0..f.rows {
        for c in 0..f.columns {
            let h = |c: u32, r: u32| f64::from(f.height(c, r));
            let gx = (h(c + 1, r) - h(c.saturating_sub(1), r)) / (2.0 * f.spacing.x);
            let gy = (h(c, r + 1) - h(c, r.saturating_sub(1))) / (2.0 * f.spacing.y);
            let shade = glam::DVec3::new(-gx, -gy, 1.0).normalize().dot(light).clamp(0.0, 1.0);
            let v = (shade * 255.0) as u8;
            rgba.extend([v, v, v, 255]);
        }
    }
    rgba
}

#[test]
fn filled_holes_match_the_terrain_without_seams() {
    let input = crop();
    let unknown = holes();
    let out = fill_holes_cpu(&input, &unknown, &params(1, 4096), &mut |_, _| {}).unwrap();
    // Fig. 7.2: the holes (white), the filled field, the original crop.
    let side_by_side: Vec<u8> = {
        let mut holed = hillshade(&input);
        for (i, _) in unknown.iter().enumerate().filter(|(_, &u)| u) {
            holed[4 * i..4 * i + 4].fill(255);
        }
        let panels = [holed, hillshade(&out), hillshade(&input)];
        let row = SIDE as usize * 4;
        (0..SIDE as usize)
            .flat_map(|r| {
                panels
                    .iter()
                    .flat_map(move |p| p[r * row..(r + 1) * row].iter().copied())
            })
            .collect()
    };
    let shade_path = crate::test_support::target_tmp().join("synthesis-fill-hillshade.png");
    crate::io::image_out::write_png_rgba8(&shade_path, &side_by_side, 3 * SIDE, SIDE).unwrap();

    for (i, (a, b)) in input.heights.iter().zip(&out.heights).enumerate() {
        if !unknown[i] {
            assert_eq!(a.to_bits(), b.to_bits(), "known sample {i} changed");
        }
    }
    let (slope_ks, curvature_ks) = statistics(&out, &unknown);
    let (seam, p99) = seam_fraction(&input, &out, &unknown);
    eprintln!("fill: KS slope {slope_ks:.3}, curvature {curvature_ks:.3}; seam {seam:.3} ≤ p99 {p99:.3}");
    assert!(slope_ks <= KS_BOUND, "slope KS {slope_ks} > {KS_BOUND}");
    assert!(curvature_ks <= KS_BOUND, "curvature KS {curvature_ks} > {KS_BOUND}");
    assert!(
        seam >= 0.95,
        "only {seam} of the boundary slopes within the field's p99 {p99}"
    );

    // The criteria can fail: a smooth fill fails the statistics, a constant one the seam.
    let smooth = membrane(&input, &unknown);
    let (s, k) = statistics(&smooth, &unknown);
    eprintln!("membrane: KS slope {s:.3}, curvature {k:.3}");
    assert!(
        s > KS_BOUND || k > KS_BOUND,
        "a membrane fill passes the KS bound: {s}, {k}"
    );
    let mut flat = input.clone();
    let mean = input.heights.iter().map(|&h| f64::from(h)).sum::<f64>() / input.heights.len() as f64;
    for (h, &u) in flat.heights.iter_mut().zip(&unknown) {
        if u {
            *h = mean as f32;
        }
    }
    let (flat_seam, _) = seam_fraction(&input, &flat, &unknown);
    eprintln!("constant: seam {flat_seam:.3}");
    assert!(flat_seam < 0.95, "a constant fill passes the seam bound: {flat_seam}");
}

#[test]
fn a_seed_determines_the_fill() {
    let input = crop();
    let unknown = holes();
    let fill = |seed| fill_holes_cpu(&input, &unknown, &params(seed, 1024), &mut |_, _| {}).unwrap();
    let (a, b, c) = (fill(7), fill(7), fill(8));
    assert_eq!(a, b, "same seed, same field");
    let differ = (0..a.heights.len()).filter(|&i| a.heights[i] != c.heights[i]).count();
    assert!(differ > 100, "another seed changed only {differ} samples");
    for (i, (x, y)) in a.heights.iter().zip(&c.heights).enumerate() {
        if !unknown[i] {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
}

#[test]
fn bad_inputs_are_one_line_errors_naming_the_parameter() {
    let input = crop();
    let unknown = holes();
    let error = |unknown: &[bool], params: FillParams| {
        let e = plan_hole_fill(&input, unknown, &params)
            .err()
            .expect("an error")
            .to_string();
        assert_eq!(e.lines().count(), 1, "{e}");
        e
    };
    assert!(error(&unknown[1..], params(1, 1024)).contains("mask"));
    assert!(error(&vec![true; unknown.len()], params(1, 1024)).contains("every sample is unknown"));
    let even = FillParams {
        window: 6,
        ..params(1, 1024)
    };
    assert!(error(&unknown, even).contains("--window"));
    let huge = FillParams {
        window: 129,
        ..params(1, 1024)
    };
    assert!(error(&unknown, huge).contains("larger than"));
    let no_candidates = FillParams {
        candidates: 0,
        ..params(1, 1024)
    };
    assert!(error(&unknown, no_candidates).contains("--candidates"));
    let stripes: Vec<bool> = (0..unknown.len()).map(|i| i % 5 == 0).collect();
    assert!(error(&stripes, params(1, 1024)).contains("no fully known 7×7 window"));
    let nothing = fill_holes_cpu(&input, &vec![false; unknown.len()], &params(1, 1024), &mut |_, _| {}).unwrap();
    assert_eq!(nothing, input, "no unknown sample: the field unchanged");
}
