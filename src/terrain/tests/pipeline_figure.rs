//! The intermediate 2-D maps of geometry image warping, Fig. 7.8
//! (dissertation §7.4): the sketch map, the importance map (eq. 7.4), the
//! sketch geometry image (the warped grid `Φ`) and the detailed geometry
//! image (`Φ` zoomed to the output grid, heights from the atlas plus the
//! procedural octaves the mesh holds), from the CPU stage
//! ([`LodFrame::plan`]) and the CPU twin of `terrain.warp`
//! ([`Ground::vertex`]) for the default scene's default camera at the
//! aspect of a 320×200 render. The bump-mapped render, the figure's last
//! panel, is `alpenglow render --width 320 --height 200`.
//!
//! Checked, each against a reference computed here and not by the stage:
//! the importance is largest on the ground nearest the eye and larger
//! inside the view frustum (its own planes, [`Frustum::contains`]) than
//! outside; the warped grid is denser where the importance is high (the
//! area density of its cells, measured from their corners, grows with
//! the importance at the cells: log–log correlation and slope); the
//! detailed geometry image passes through the warped grid at the sketch
//! texels it shares with it, and its heights are the atlas's B-spline at
//! its own positions up to the procedural detail's bound (in this
//! overview the output grid is coarser than the finest atlas octave: no
//! detail octave reaches the mesh, the heights are the atlas's; the
//! detail is all bump mapping, §7.4.3).
//!
//! `ALPENGLOW_FIGURES=DIR cargo test --lib terrain::tests::pipeline_figure -- --nocapture`
//! writes the maps as PNGs into `DIR` (`fig-7-8-*.png`; rows far from the
//! eye at the top).

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use crate::io::image_out::write_png_rgba8;
use crate::renderer::Scene;
use crate::surface::bspline::sample_bspline;
use crate::terrain::geometry_image::TerrainSettings;
use crate::terrain::ground::Ground;
use crate::terrain::importance::Frustum;
use crate::terrain::lod::{DebugScalar, LodFrame, LodSettings};
use crate::terrain::warp::bilinear;

/// Width over height of the render panel (320×200).
const ASPECT: f64 = 1.6;
/// Side of the detailed geometry image: every second vertex is a sketch
/// texel of the 128² default (`(side − 1) = 2·(n − 1)`).
const DETAILED_SIDE: usize = 255;
/// Log–log correlation of cell density and importance, at least (measured
/// 0.80 on the default scene: the two 1-D passes meet a 2-D map only approximately).
const MIN_DENSITY_CORRELATION: f64 = 0.7;
/// Slope of ln(cell density) over ln(importance), inside: an isotropic
/// warp gives 2 (density per direction ∝ I); the two 1-D passes, the
/// warp's box filter and the importance floor give less (measured 0.85).
const DENSITY_SLOPE: (f64, f64) = (0.5, 2.2);

/// Grey or colour image of `n×n` values, rows flipped (row 0 at the bottom).
fn image(n: usize, colour: impl Fn(usize) -> [u8; 3]) -> Vec<u8> {
    (0..n * n)
        .flat_map(|k| {
            let (r, c) = (n - 1 - k / n, k % n);
            let [a, b, g] = colour(r * n + c);
            [a, b, g, 255]
        })
        .collect()
}

fn unit(v: f64, lo: f64, hi: f64) -> f64 {
    ((v - lo) / (hi - lo).max(1e-30)).clamp(0.0, 1.0)
}

fn byte(v: f64) -> u8 {
    (255.0 * v.clamp(0.0, 1.0)).round() as u8
}

/// Blue (0) → green → red (1).
fn heat(v: f64) -> [u8; 3] {
    let v = v.clamp(0.0, 1.0);
    [
        byte(2.0 * v - 1.0),
        byte(1.0 - (2.0 * v - 1.0).abs()),
        byte(1.0 - 2.0 * v),
    ]
}

/// Range of a component over points.
fn range(points: &[DVec3], f: impl Fn(&DVec3) -> f64) -> (f64, f64) {
    points
        .iter()
        .map(f)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// A geometry image as colour: (x, y, height) → (R, G, B) over `frame`'s ranges.
fn geometry_colours<'a>(points: &'a [DVec3], frame: &[DVec3]) -> impl Fn(usize) -> [u8; 3] + 'a {
    let (x, y, z) = (range(frame, |p| p.x), range(frame, |p| p.y), range(frame, |p| p.z));
    move |k| {
        let p = points[k];
        [
            byte(unit(p.x, x.0, x.1)),
            byte(unit(p.y, y.0, y.1)),
            byte(unit(p.z, z.0, z.1)),
        ]
    }
}

/// Every `step`-th grid line of the warped `n×n` grid drawn over a
/// `side×side` top view of the sketch region (grid coordinates), white on
/// black, far rows at the top.
fn grid_lines(grid: &[DVec2], n: usize, side: usize, step: usize) -> Vec<u8> {
    let mut rgba = vec![0u8; side * side * 4];
    for p in rgba.chunks_exact_mut(4) {
        p[3] = 255;
    }
    let scale = (side - 1) as f64 / (n - 1) as f64;
    let mut plot = |a: DVec2, b: DVec2| {
        let steps = ((b - a).length() * scale * 2.0).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let q = (a + (b - a) * (s as f64 / steps as f64)) * scale;
            let (x, y) = (q.x.round(), (side - 1) as f64 - q.y.round());
            if (0.0..side as f64).contains(&x) && (0.0..side as f64).contains(&y) {
                let i = 4 * (y as usize * side + x as usize);
                rgba[i..i + 3].copy_from_slice(&[255, 255, 255]);
            }
        }
    };
    for line in (0..n).step_by(step).chain([n - 1]) {
        for k in 0..n - 1 {
            plot(grid[line * n + k], grid[line * n + k + 1]);
            plot(grid[k * n + line], grid[(k + 1) * n + line]);
        }
    }
    rgba
}

fn write(dir: &Path, name: &str, rgba: &[u8], side: usize) {
    let path = dir.join(format!("fig-7-8-{name}.png"));
    write_png_rgba8(&path, rgba, side as u32, side as u32).expect("figure PNG");
    println!("wrote {}", path.display());
}

/// Pearson correlation and least-squares slope of `ys` over `xs`.
fn correlation_and_slope(xs: &[f64], ys: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in xs.iter().zip(ys) {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx).powi(2);
        syy += (y - my).powi(2);
    }
    (sxy / (sxx * syy).sqrt(), sxy / sxx)
}

#[test]
fn pipeline_maps_of_the_default_view() {
    let scene = Scene::default_terrain().expect("default terrain");
    let field = &scene.heights;
    let camera = scene.default_camera();
    let mut lod = LodFrame::default();
    (lod.plan(field, &camera, ASPECT, &LodSettings::default(), DebugScalar::None)).expect("plan");
    let sketch = lod.sketch.as_ref().expect("sketch map");
    let (n, importance, warped) = (sketch.n, &lod.importance, &lod.warp.positions);
    assert_eq!((importance.len(), warped.len()), (n * n, n * n));

    // Importance: largest on the ground nearest the eye, larger in the frustum.
    let inside: Vec<usize> = (0..n * n).filter(|&k| !sketch.outside[k]).collect();
    let mut by_distance: Vec<f64> = inside
        .iter()
        .map(|&k| sketch.geometry[k].distance(camera.eye))
        .collect();
    by_distance.sort_by(f64::total_cmp);
    let top = (0..n * n)
        .max_by(|&a, &b| importance[a].total_cmp(&importance[b]))
        .expect("texels");
    let top_distance = sketch.geometry[top].distance(camera.eye);
    let nearest_share = by_distance.partition_point(|&d| d < top_distance) as f64 / inside.len() as f64;
    println!(
        "largest importance {top_distance:.0} m from the eye: {:.1} % of the terrain texels are nearer",
        100.0 * nearest_share
    );
    assert!(
        nearest_share < 0.05,
        "the largest importance is not near the eye ({nearest_share:.3})"
    );
    let (fov, forward) = (camera.fov_y_deg.to_radians(), camera.forward());
    let frustum = Frustum::perspective(camera.eye, forward, camera.up, fov, ASPECT, 0.0).expect("frustum");
    let mean = |ks: &mut dyn Iterator<Item = usize>| {
        let (s, c) = ks.fold((0.0, 0usize), |(s, c), k| (s + importance[k], c + 1));
        s / c.max(1) as f64
    };
    let seen = mean(&mut inside.iter().copied().filter(|&k| frustum.contains(sketch.geometry[k])));
    let unseen = mean(
        &mut inside
            .iter()
            .copied()
            .filter(|&k| !frustum.contains(sketch.geometry[k])),
    );
    println!("mean importance in the frustum {seen:.3e}, outside {unseen:.3e}");
    assert!(
        seen > 3.0 * unseen,
        "importance in the frustum {seen} vs outside {unseen}"
    );

    // Warped grid: cell density (1 / area in sketch grid units) against importance.
    let grid: Vec<DVec2> = warped
        .iter()
        .map(|p| sketch.region.grid_coord(p.truncate(), n))
        .collect();
    let (mut log_importance, mut log_density) = (Vec::new(), Vec::new());
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            let q = [
                grid[r * n + c],
                grid[r * n + c + 1],
                grid[(r + 1) * n + c + 1],
                grid[(r + 1) * n + c],
            ];
            let area = 0.5 * (0..4).map(|i| q[i].perp_dot(q[(i + 1) % 4])).sum::<f64>().abs();
            let centre = 0.25 * (q[0] + q[1] + q[2] + q[3]);
            let i = bilinear(importance, n, centre);
            if area > 0.0 && i > 0.0 {
                log_importance.push(i.ln());
                log_density.push(-area.ln());
            }
        }
    }
    let (corr, slope) = correlation_and_slope(&log_importance, &log_density);
    println!(
        "ln(cell density) over ln(importance): correlation {corr:.3}, slope {slope:.2} ({} cells)",
        log_density.len()
    );
    assert!(
        corr > MIN_DENSITY_CORRELATION,
        "density follows importance poorly: correlation {corr}"
    );
    assert!(
        (DENSITY_SLOPE.0..DENSITY_SLOPE.1).contains(&slope),
        "density slope {slope}"
    );

    // Detailed geometry image: through Φ at shared texels, on the atlas up to the detail.
    let ground = Ground::new(field, &TerrainSettings::default()).expect("ground");
    let extent = field.extent();
    let side = DETAILED_SIDE;
    let detailed: Vec<DVec3> = (0..side * side)
        .map(|k| ground.vertex(warped, n, side, k % side, k / side).truncate())
        .collect();
    let mut worst_xy = 0.0f64;
    for r in 0..n {
        for c in 0..n {
            let expected = warped[r * n + c].truncate().clamp(DVec2::ZERO, extent);
            worst_xy = worst_xy.max(detailed[2 * r * side + 2 * c].truncate().distance(expected));
        }
    }
    assert!(worst_xy < 1e-6, "detailed image off the warped grid by {worst_xy} m");
    let detail: Vec<f64> = detailed.iter().map(|p| p.z - sample_bspline(field, p.x, p.y)).collect();
    let (worst, rms) = (
        detail.iter().fold(0.0f64, |m, d| m.max(d.abs())),
        (detail.iter().map(|d| d * d).sum::<f64>() / detail.len() as f64).sqrt(),
    );
    let bound = ground.omitted_detail_bound(0.0);
    println!("detailed heights − atlas: rms {rms:.3} m, largest {worst:.3} m (bound {bound:.3} m)");
    assert!(worst <= bound + 1e-9, "detail {worst} m beyond its bound {bound} m");

    if let Some(dir) = std::env::var_os("ALPENGLOW_FIGURES").map(PathBuf::from) {
        write_maps(&dir, &lod, &grid, &detailed);
    }
}

/// Writes the maps of `lod` (sketch map, importance, Φ as colour), the
/// warped `grid` (sketch grid coordinates) and the `detailed` geometry
/// image into `dir`.
fn write_maps(dir: &Path, lod: &LodFrame, grid: &[DVec2], detailed: &[DVec3]) {
    let sketch = lod.sketch.as_ref().expect("sketch map");
    let (n, importance, warped) = (sketch.n, &lod.importance, &lod.warp.positions);
    let side = DETAILED_SIDE;
    let heights = range(&sketch.geometry, |p| p.z);
    write(
        dir,
        "sketch-map",
        &image(n, |k| [byte(unit(sketch.geometry[k].z, heights.0, heights.1)); 3]),
        n,
    );
    let logs: Vec<f64> = importance.iter().map(|i| i.max(1e-30).ln()).collect();
    let (lo, hi) = logs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    write(dir, "importance", &image(n, |k| heat(unit(logs[k], lo, hi))), n);
    write(
        dir,
        "sketch-geometry-image",
        &image(n, geometry_colours(warped, &sketch.geometry)),
        n,
    );
    write(dir, "warped-grid", &grid_lines(grid, n, 512, 4), 512);
    write(
        dir,
        "detailed-geometry-image",
        &image(side, geometry_colours(detailed, &sketch.geometry)),
        side,
    );
}
