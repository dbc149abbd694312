//! Geometry image warping on the CPU (dissertation §7.4.2, Fig. 7.10–7.12;
//! `ALGORITHMS.md` §3 items 3–4) on a procedural terrain and on the real
//! Jacksboro DEM: no fold-over, the border stays the border, outputs stay on
//! the surface up to the box filter, obtained/demanded density (Fig. 7.12)
//! and the identity warp. Run with `--nocapture` to see the histograms.

use crate::test_support::jacksboro_field;

use crate::io::heightmap::HeightField;
use crate::terrain::importance::{importance_map, Backface, Frustum, ImportanceParams};
use crate::terrain::procedural::ProceduralTerrain;
use crate::terrain::warp::{
    density_ratio, fraction_within, histogram, warp, warp_with, ColumnImportance, PassOrder, WarpFilter, WarpOptions,
    WarpResult,
};
use glam::{DVec2, DVec3};

const N: usize = 128;

/// Bilinear height of `field` at world `(x, y)` (clamped to the field).
fn bilinear(field: &HeightField, x: f64, y: f64) -> f64 {
    let gx = (x / field.spacing.x).clamp(0.0, f64::from(field.columns - 1));
    let gy = (y / field.spacing.y).clamp(0.0, f64::from(field.rows - 1));
    let (c, r) = ((gx as u32).min(field.columns - 2), (gy as u32).min(field.rows - 2));
    let (fx, fy) = (gx - f64::from(c), gy - f64::from(r));
    let h = |c: u32, r: u32| f64::from(field.height(c, r));
    let top = h(c, r) + (h(c + 1, r) - h(c, r)) * fx;
    let bottom = h(c, r + 1) + (h(c + 1, r + 1) - h(c, r + 1)) * fx;
    top + (bottom - top) * fy
}

/// An `N×N` sketch map over the whole field (axis-aligned geometry image).
fn sketch_map(field: &HeightField) -> Vec<DVec3> {
    let e = field.extent();
    (0..N * N)
        .map(|k| {
            let (c, r) = ((k % N) as f64, (k / N) as f64);
            let (x, y) = (c * e.x / (N - 1) as f64, r * e.y / (N - 1) as f64);
            DVec3::new(x, y, bilinear(field, x, y))
        })
        .collect()
}

/// A terrain with its sketch map, the camera's frustum and importance map.
struct Scene {
    name: String,
    field: HeightField,
    sketch: Vec<DVec3>,
    frustum: Frustum,
    importance: Vec<f64>,
    /// Warp options for this view ([`PassOrder::for_view`]).
    options: WarpOptions,
}

/// Where the eye is: as fractions of the field's extent in x and y, and
/// metres above the highest point; and where it looks.
#[derive(Clone, Copy)]
struct Camera {
    name: &'static str,
    eye: DVec3,
    forward: DVec3,
}

/// Above the y = 0 side (3 % in), looking across (+y) and slightly down.
const ACROSS_Y: Camera = Camera {
    name: "from the y = 0 side looking +y",
    eye: DVec3::new(0.5, 0.03, 400.0),
    forward: DVec3::new(0.0, 1.0, -0.15),
};

/// Above the x = 0 side, looking across (+x): the columns-first case.
const ACROSS_X: Camera = Camera {
    name: "from the x = 0 side looking +x",
    eye: DVec3::new(0.03, 0.4, 400.0),
    forward: DVec3::new(1.0, 0.1, -0.15),
};

/// From a corner looking diagonally: neither pass order fits (information
/// only, see `density_ratio_mostly_between_half_and_one`).
const DIAGONAL: Camera = Camera {
    name: "from a corner looking diagonally",
    eye: DVec3::new(0.03, 0.03, 400.0),
    forward: DVec3::new(1.0, 1.0, -0.2),
};

/// The scene seen by `camera`: 50° vertical field of view, 16:9, safety
/// band two sketch texels wide, back-face factor on.
fn scene(terrain: &str, field: &HeightField, camera: Camera) -> Scene {
    let sketch = sketch_map(field);
    let e = field.extent();
    let top = f64::from(field.min_max().1);
    let eye = DVec3::new(camera.eye.x * e.x, camera.eye.y * e.y, top + camera.eye.z);
    let texel = e.max_element() / (N - 1) as f64;
    let frustum = Frustum::perspective(
        eye,
        camera.forward,
        DVec3::Z,
        50f64.to_radians(),
        16.0 / 9.0,
        2.0 * texel,
    )
    .expect("valid camera");
    let params = ImportanceParams {
        min_distance: texel,
        frustum: Some(frustum.clone()),
        backface: Some(Backface::default()),
        ..Default::default()
    };
    let importance = importance_map(&sketch, N, eye, &params).expect("importance map");
    let options = WarpOptions {
        order: PassOrder::for_view(camera.forward),
        ..Default::default()
    };
    Scene {
        name: format!("{terrain}, {}", camera.name),
        field: field.clone(),
        sketch,
        frustum,
        importance,
        options,
    }
}

fn procedural() -> HeightField {
    ProceduralTerrain::default()
        .try_generate(257, 257, DVec2::splat(40.0))
        .expect("procedural terrain")
}

fn terrains() -> [(&'static str, HeightField); 2] {
    [
        ("procedural ridged", procedural()),
        ("Jacksboro DEM", jacksboro_field()),
    ]
}

/// Both terrains seen by `cameras`, warped with the default options and the
/// pass order for the view.
fn scenes(cameras: &[Camera]) -> Vec<(Scene, WarpResult)> {
    let mut out = Vec::new();
    for (terrain, field) in terrains() {
        for &camera in cameras {
            let s = scene(terrain, &field, camera);
            let w = warp_with(&s.sketch, &s.importance, N, s.options).expect("warp");
            out.push((s, w));
        }
    }
    out
}

/// Quads whose x does not increase along the row or y along the column.
fn fold_count(p: &[DVec3]) -> usize {
    (0..N)
        .flat_map(|r| (1..N).map(move |c| (r, c)))
        .filter(|&(r, c)| p[r * N + c].x <= p[r * N + c - 1].x || p[c * N + r].y <= p[(c - 1) * N + r].y)
        .count()
}

#[test]
fn no_fold_over() {
    for (s, w) in scenes(&[ACROSS_Y, ACROSS_X, DIAGONAL]) {
        let p = &w.positions;
        for r in 0..N {
            for c in 1..N {
                let (a, b) = (p[r * N + c - 1], p[r * N + c]);
                assert!(
                    b.x > a.x,
                    "{}: x not increasing at row {r}, column {c}: {} → {}",
                    s.name,
                    a.x,
                    b.x
                );
                let (a, b) = (p[(c - 1) * N + r], p[c * N + r]);
                assert!(
                    b.y > a.y,
                    "{}: y not increasing at column {r}, row {c}: {} → {}",
                    s.name,
                    a.y,
                    b.y
                );
            }
        }
        // For information: the text's literal second pass (each column by
        // its own resampled importance) folds.
        let literal = WarpOptions {
            columns: ColumnImportance::PerColumn,
            ..s.options
        };
        let l = warp_with(&s.sketch, &s.importance, N, literal).unwrap();
        println!(
            "{}: folded quads with the per-column second pass: {}",
            s.name,
            fold_count(&l.positions)
        );
    }
}

#[test]
fn border_stays_border() {
    for (s, w) in scenes(&[ACROSS_Y, ACROSS_X]) {
        let e = s.field.extent();
        let tol = 1e-12 * e.max_element();
        let p = &w.positions;
        for k in 0..N {
            assert!(p[k * N].x.abs() <= tol, "{}: left border, row {k}", s.name);
            assert!(
                (p[k * N + N - 1].x - e.x).abs() <= tol,
                "{}: right border, row {k}",
                s.name
            );
            assert!(p[k].y.abs() <= tol, "{}: first row, column {k}", s.name);
            assert!(
                (p[(N - 1) * N + k].y - e.y).abs() <= tol,
                "{}: last row, column {k}",
                s.name
            );
        }
        for k in [0, N - 1, N * (N - 1), N * N - 1] {
            assert_eq!(p[k], s.sketch[k], "{}: corner {k} moved", s.name);
        }
    }
}

/// Checks one pass over `n` lines: each output lies on its input line
/// (coordinate `axis` constant up to rounding is not required), and its
/// height lies within the heights of the input points its box cell can have
/// touched. The cell of output `i` covers, along the monotonic line
/// coordinate `t`, at most `[t(out[i−1]), t(out[i+1])]` (a box mean of a
/// monotonic function lies below the function's value at the cell's end),
/// so the touched inputs are those with `t` in that range plus one on each
/// side. Returns the largest height excess found (0 when all pass).
fn box_span_excess(input: &[DVec3], output: &[DVec3], rows: bool) -> f64 {
    let idx = |line: usize, k: usize| if rows { line * N + k } else { k * N + line };
    let t = |p: DVec3| if rows { p.x } else { p.y };
    let mut worst = 0.0_f64;
    for line in 0..N {
        let inp: Vec<DVec3> = (0..N).map(|k| input[idx(line, k)]).collect();
        for i in 0..N {
            let (lo_t, hi_t) = (
                t(output[idx(line, i.saturating_sub(1))]),
                t(output[idx(line, (i + 1).min(N - 1))]),
            );
            let first = inp.partition_point(|q| t(*q) < lo_t).saturating_sub(1);
            let last = inp.partition_point(|q| t(*q) <= hi_t).min(N - 1);
            let (lo, hi) = inp[first..=last]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| (a.min(q.z), b.max(q.z)));
            let h = output[idx(line, i)].z;
            worst = worst.max(lo - h).max(h - hi);
        }
    }
    worst
}

#[test]
fn outputs_stay_on_the_surface_up_to_the_box_filter() {
    for (s, w) in scenes(&[ACROSS_Y, ACROSS_X]) {
        let (hmin, hmax) = s.field.min_max();
        let tol = 1e-9 * f64::from(hmax - hmin);
        let rows_first = s.options.order == PassOrder::RowsFirst;
        let first = box_span_excess(&s.sketch, &w.positions_after_first_pass, rows_first);
        let second = box_span_excess(&w.positions_after_first_pass, &w.positions, !rows_first);
        assert!(
            first <= tol && second <= tol,
            "{}: height outside its span by {first} / {second} m",
            s.name
        );
        // For information: distance to the full-resolution height field
        // (bilinear) at the warped (x, y), everywhere and inside the frustum;
        // includes the sketch map's own 128² resampling.
        let stats = |inside_only: bool| {
            let dev: Vec<f64> = w
                .positions
                .iter()
                .filter(|p| !inside_only || s.frustum.contains(**p))
                .map(|p| (p.z - bilinear(&s.field, p.x, p.y)).abs())
                .collect();
            let rms = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len().max(1) as f64).sqrt();
            (rms, dev.iter().copied().fold(0.0, f64::max))
        };
        let ((rms, max), (rms_in, max_in)) = (stats(false), stats(true));
        println!(
            "{}: |h − field(x, y)| rms {rms:.2} m, max {max:.2} m; in the frustum rms {rms_in:.2} m, max {max_in:.2} m \
             (height range {} m)",
            s.name,
            hmax - hmin
        );
    }
}

/// Quantiles 10/50/90 % of `v`.
fn quantiles(v: &[f64]) -> [f64; 3] {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    [0.1, 0.5, 0.9].map(|f| {
        s.get(((s.len().max(1) - 1) as f64 * f) as usize)
            .copied()
            .unwrap_or(f64::NAN)
    })
}

/// Fig. 7.12: obtained/demanded density mostly in [0.5, 1]. Demanded is
/// `k·I` normalised to the mesh's `(N−1)²` cells
/// ([`crate::terrain::warp::density_ratio`]); obtained is per texel
/// `1/sqrt(s_row · s_col)` (the isotropic, i.e. areal, density). Only
/// texels whose warped position lies inside the frustum count.
///
/// The per-direction ratios are printed but not asserted: a square n×n mesh
/// over a wedge-shaped frustum cannot be isotropic (every row has n
/// samples), so one direction is over- and the other under-sampled by up to
/// ≈1.5× (medians ≈1.2–1.4 across the view, ≈0.6–0.8 along it).
#[test]
fn density_ratio_mostly_between_half_and_one() {
    let edges = [0.0, 0.25, 0.33, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0, 4.0];
    let measure = |s: &Scene, w: &WarpResult| {
        let d = density_ratio(&w.positions, &s.sketch, &s.importance, N).expect("density ratio");
        let inside: Vec<usize> = (0..N * N).filter(|&k| s.frustum.contains(w.positions[k])).collect();
        let pick = |v: &[f64]| inside.iter().map(|&k| v[k]).collect::<Vec<f64>>();
        (pick(&d.combined), pick(&d.along_rows), pick(&d.along_columns))
    };
    for (s, w) in scenes(&[ACROSS_Y, ACROSS_X]) {
        let (combined, rows, cols) = measure(&s, &w);
        let frac = fraction_within(&combined, 0.5, 1.0);
        let [q10, q50, q90] = quantiles(&combined);
        println!(
            "{} ({:?}): {} of {} warped texels in the frustum; obtained/demanded density:\n{}",
            s.name,
            s.options.order,
            combined.len(),
            N * N,
            histogram(&combined, &edges)
        );
        println!(
            "  in [0.5, 1]: {:.1} %, in [0.5, 2]: {:.1} %; quantiles 10/50/90 %: {q10:.3} {q50:.3} {q90:.3}",
            100.0 * frac,
            100.0 * fraction_within(&combined, 0.5, 2.0),
        );
        println!(
            "  per direction, median (in [0.5, 1]): along rows {:.3} ({:.1} %), along columns {:.3} ({:.1} %)\n",
            quantiles(&rows)[1],
            100.0 * fraction_within(&rows, 0.5, 1.0),
            quantiles(&cols)[1],
            100.0 * fraction_within(&cols, 0.5, 1.0)
        );
        assert!(combined.len() > N * N / 2, "{}: too few texels in the frustum", s.name);
        assert!(frac >= 0.8, "{}: only {:.1} % in [0.5, 1]", s.name, 100.0 * frac);
    }
    // For information: the other pass order, the literal per-column second
    // pass, and a diagonal view (neither order fits; a view-aligned sketch
    // map would).
    for (s, _) in scenes(&[ACROSS_Y, ACROSS_X, DIAGONAL]) {
        let flipped = match s.options.order {
            PassOrder::RowsFirst => PassOrder::ColumnsFirst,
            PassOrder::ColumnsFirst => PassOrder::RowsFirst,
        };
        let variants = [
            ("default", s.options),
            (
                "other pass order",
                WarpOptions {
                    order: flipped,
                    ..s.options
                },
            ),
            (
                "per-column 2nd pass",
                WarpOptions {
                    columns: ColumnImportance::PerColumn,
                    ..s.options
                },
            ),
        ];
        for (label, options) in variants {
            let w = warp_with(&s.sketch, &s.importance, N, options).unwrap();
            let (combined, _, _) = measure(&s, &w);
            let [q10, q50, q90] = quantiles(&combined);
            println!(
                "info: {} / {label}: in [0.5, 1] {:.1} %, in [0.5, 2] {:.1} %, q10/50/90 {q10:.2} {q50:.2} {q90:.2}, folded quads {}",
                s.name,
                100.0 * fraction_within(&combined, 0.5, 1.0),
                100.0 * fraction_within(&combined, 0.5, 2.0),
                fold_count(&w.positions)
            );
        }
    }
}

#[test]
fn equal_importance_is_the_identity() {
    for (name, field) in terrains() {
        let s = scene(name, &field, ACROSS_Y);
        let flat = vec![1.0; N * N];
        let scale = s.field.extent().max_element();
        let (hmin, hmax) = s.field.min_max();
        let hscale = f64::from(hmax - hmin).max(1.0);
        let point = warp_with(
            &s.sketch,
            &flat,
            N,
            WarpOptions {
                filter: WarpFilter::Point,
                ..Default::default()
            },
        )
        .unwrap();
        for (p, q) in point.positions.iter().zip(&s.sketch) {
            assert!(
                (p.truncate() - q.truncate()).length() <= 1e-9 * scale,
                "{}: point {p} vs {q}",
                s.name
            );
            assert!((p.z - q.z).abs() <= 1e-9 * hscale, "{}: point {p} vs {q}", s.name);
        }
        // The box filter keeps x and y exactly and filters heights with the
        // separable kernel (1, 6, 1)/8 (border samples pinned), which is the
        // identity only where the heights are linear.
        let boxed = warp(&s.sketch, &flat, N).unwrap();
        let columns_first = WarpOptions {
            order: PassOrder::ColumnsFirst,
            ..Default::default()
        };
        let transposed = warp_with(&s.sketch, &flat, N, columns_first).unwrap();
        let h = |r: usize, c: usize| s.sketch[r * N + c].z;
        let filter = |a: f64, b: f64, c: f64| (a + 6.0 * b + c) / 8.0;
        let row_filtered = |r: usize, c: usize| {
            if c == 0 || c == N - 1 {
                h(r, c)
            } else {
                filter(h(r, c - 1), h(r, c), h(r, c + 1))
            }
        };
        for r in 0..N {
            for c in 0..N {
                let (p, q) = (boxed.positions[r * N + c], s.sketch[r * N + c]);
                assert!(
                    (p.truncate() - q.truncate()).length() <= 1e-9 * scale,
                    "{}: box {p} vs {q}",
                    s.name
                );
                let t = transposed.positions[r * N + c];
                assert!((t - p).length() <= 1e-9 * scale, "{}: columns first {t} vs {p}", s.name);
                let expect = if r == 0 || r == N - 1 {
                    row_filtered(r, c)
                } else {
                    filter(row_filtered(r - 1, c), row_filtered(r, c), row_filtered(r + 1, c))
                };
                assert!(
                    (p.z - expect).abs() <= 1e-9 * hscale,
                    "{}: box h {} vs {expect}",
                    s.name,
                    p.z
                );
            }
        }
    }
    // On a plane the box filter is the identity too.
    let plane: Vec<DVec3> = (0..N * N)
        .map(|k| {
            let (x, y) = ((k % N) as f64 * 10.0, (k / N) as f64 * 12.0);
            DVec3::new(x, y, 0.3 * x - 0.2 * y + 50.0)
        })
        .collect();
    let w = warp(&plane, &vec![2.5; N * N], N).unwrap();
    for (p, q) in w.positions.iter().zip(&plane) {
        assert!((*p - *q).length() <= 1e-9 * 1524.0, "plane: {p} vs {q}");
    }
}
