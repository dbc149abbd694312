//! Fig. 10.9 (dissertation §10.1.9): with colour in the error measure the
//! point density follows texture detail. A 4 m × 4 m plane sampled every
//! 2 cm, its left half a fine checkerboard (8 cm squares of two contrasting
//! colours), its right half uniform grey with small noise (below the colour
//! threshold), is seen from 6 m above its centre; the CPU selection
//! ([`crate::points::build::spt::SequentialPointTree::select`], which the
//! GPU matches: `points::tests::render`) is drawn as small uniform dots, the
//! text's way of showing density (`ALPENGLOW_DUMP=DIR` writes
//! `color-density.png`: with the colour term left, without it right).
//!
//! The independent reference is the geometry: on a plane `e_p = e_t = 0`
//! for every node whose children tile it, so without the colour term both
//! halves get the same density, and the textured half's extra nodes are
//! the colour term's alone.

use glam::Vec3;

use crate::points::build::clip::ClipLines;
use crate::points::build::spt::{build_spt, epsilon_from_pixels, SequentialPointTree, SptOptions};
use crate::points::Surfel;
use crate::test_support::dump_pngs;

const SIDE: f32 = 4.0;
const SPACING: f32 = 0.02;
const SQUARE: f32 = 0.08;
const EYE: Vec3 = Vec3::new(2.0, 2.0, 6.0);
/// Image rows the threshold ε refers to (one pixel of a 50° view).
const ROWS: u32 = 200;
/// Side of each panel of the density plot (pixels; 1 cm each).
const PLOT: usize = 400;
/// How many times denser the textured half must be with the colour term
/// (measured 8.65× with it; 1.00× without).
const DENSER: f64 = 6.0;

fn surfels() -> Vec<Surfel> {
    let n = (SIDE / SPACING) as usize;
    let mut rng = crate::random::SplitMix64(9);
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = Vec3::new((i as f32 + 0.5) * SPACING, (j as f32 + 0.5) * SPACING, 0.0);
            let color = if p.x < SIDE / 2.0 {
                let dark = ((p.x / SQUARE).floor() as i64 + (p.y / SQUARE).floor() as i64) % 2 == 0;
                if dark {
                    [60, 40, 30]
                } else {
                    [220, 200, 120]
                }
            } else {
                let g = 128 + (rng.next_u64() % 9) as u8;
                [g, g, g]
            };
            out.push(Surfel {
                position: p,
                normal: Vec3::Z,
                radius: SPACING * 0.8,
                color,
                clip: ClipLines::NONE,
            });
        }
    }
    out
}

/// The selection's node centres seen from [`EYE`].
fn selected(tree: &SequentialPointTree) -> Vec<Vec3> {
    tree.select(|p| (p - EYE).length())
        .into_iter()
        .map(|i| tree.nodes[i].position)
        .collect()
}

/// Nodes selected on the textured (left) and the uniform (right) half.
fn halves(points: &[Vec3]) -> (usize, usize) {
    let left = points.iter().filter(|p| p.x < SIDE / 2.0).count();
    (left, points.len() - left)
}

/// Top view of `points` as one-pixel dark dots on white (the leaves lie
/// two pixels apart), `PLOT` pixels square.
fn plot(points: &[Vec3], rgba: &mut [u8], offset_x: usize, width: usize) {
    for p in points {
        let x = (((p.x / SIDE) * PLOT as f32) as usize).min(PLOT - 1) + offset_x;
        let y = PLOT - 1 - (((p.y / SIDE) * PLOT as f32) as usize).min(PLOT - 1);
        rgba[(y * width + x) * 4..][..3].copy_from_slice(&[20, 20, 20]);
    }
}

#[test]
fn point_density_follows_texture_detail() {
    let surfels = surfels();
    let epsilon = epsilon_from_pixels(1.0, 50f32.to_radians(), ROWS).unwrap();
    let with = build_spt(
        &surfels,
        &SptOptions {
            epsilon,
            ..SptOptions::default()
        },
        &mut |_| {},
    )
    .unwrap();
    let options = SptOptions {
        epsilon,
        color_threshold: f32::INFINITY,
        ..SptOptions::default()
    };
    let without = build_spt(&surfels, &options, &mut |_| {}).unwrap();
    let (with, without) = (selected(&with), selected(&without));
    let ((tl, ul), (tn, un)) = (halves(&with), halves(&without));
    eprintln!(
        "colour term: textured half {tl} nodes, uniform half {ul} ({:.2}×); without: {tn}, {un} ({:.2}×)",
        tl as f64 / ul as f64,
        tn as f64 / un as f64
    );
    assert!(
        tl as f64 >= DENSER * ul as f64,
        "textured {tl} not ≥ {DENSER} × uniform {ul}"
    );
    assert!(
        (tn as f64 / un as f64 - 1.0).abs() < 0.25,
        "without the colour term the halves differ: {tn} vs {un}"
    );
    // The uniform half's noise stays below the threshold: the colour term
    // changes nothing there.
    assert!(ul.abs_diff(un) * 20 <= un, "uniform half: {ul} with, {un} without");

    let width = 2 * PLOT + 4;
    let mut rgba = vec![255u8; width * PLOT * 4];
    plot(&with, &mut rgba, 0, width);
    plot(&without, &mut rgba, PLOT + 4, width);
    dump_pngs(&[("color-density", &rgba)], width as u32, PLOT as u32);
}
