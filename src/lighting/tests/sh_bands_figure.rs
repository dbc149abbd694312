//! Fig. 9.4 of the text in full (§9.3, §9.5): a terrain lit by the sun and
//! sky of the morning preset (Preetham, turbidity 2.1, day 298 07:30 at
//! 49.6° N), the reference against SH lighting with 26, 10 and 5 bands,
//! plain and filtered (Hanning; Lanczos in the numbers), drawn by a small
//! CPU renderer: the GPU bake stops at 5 bands (`docs/LIGHTING.md`).
//!
//! Per pixel of the Jacksboro valley view, the exact ray caster
//! ([`HeightFieldTracer`]) finds the surface point `x` and its normal `n`;
//! the terrain's horizon around `x` (64 azimuths, marched over the
//! bilinear surface to the field's edge) gives the visibility `V(x, ω)`
//! and the transfer `T(ω) = max(0, n·ω)·V(x, ω)/π` (white ground, exitant
//! radiance per unit albedo, no bounces; the ground below the horizontal
//! is black).
//!
//! * Reference: `∫ T·L_sky dω` by a product Gauss–Legendre quadrature of
//!   the upper hemisphere plus the sun exactly, `E_sun·max(0, n·s)/π`
//!   times the fraction of the sun's disc above the horizon.
//! * SH with `L` bands, window `σ`: `Σ_lm σ_l t_lm e_lm`, `t` the
//!   projection of `T` by the same quadrature, `e` the projection of the
//!   environment (`L_sky` above the horizontal, 0 below, by
//!   [`sh_bands::project`], plus the sun as a direction of irradiance
//!   `E_sun`). Since `t_lm = Σ_j w_j T(ω_j) y_lm(ω_j)`, the dot product is
//!   `Σ_j w_j T(ω_j) Ẽ(ω_j)` with `Ẽ = Σ_lm σ_l e_lm y_lm` the windowed
//!   band-limited environment at the quadrature directions: the test
//!   tabulates `Ẽ` once per variant and checks the identity against the
//!   explicit projection on a few pixels.
//!
//! Checked: the horizon's visibility agrees with traced rays; the relative
//! RMSE against the reference falls from 5 to 10 to 26 bands, plain and
//! filtered; at 10 and 26 bands the filtered sun has less negative light
//! (the Gibbs ringing of a truncated delta, the dark fringes of the text's
//! top row) than the plain one, and leaks more sun into the shadows
//! ("filtering reduces artifacts but increases the angular distribution of
//! the sun light", §9.5).
//!
//! 60×40 pixels and a 24×96 quadrature by default;
//! `ALPENGLOW_FIGURES=DIR cargo test --lib lighting::tests::sh_bands_figure -- --nocapture`
//! renders 240×160 with a 36×144 quadrature (about 2 min in debug) and writes
//! `DIR/fig-9-4-{reference,sh26,sh10,sh5,sh26-hanning,sh10-hanning,sh5-hanning}.png`
//! (one grey scale for all, linear in radiance: the reference's 1st
//! percentile black, its 99th white; the sky clips).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use crate::io::heightmap::HeightField;
use crate::io::image_out::write_png_rgba8;
use crate::lighting::preetham::{luminance, PreethamSky};
use crate::lighting::reference::HeightFieldTracer;
use crate::lighting::sh::gauss_legendre;
use crate::lighting::sh_bands::{self, Window};
use crate::lighting::solar::SkyPreset;
use crate::test_support::{jacksboro_field, jacksboro_valley_camera};

const BANDS: [usize; 3] = [26, 10, 5];
const WINDOWS: [Window; 3] = [Window::None, Window::Hanning, Window::Lanczos];
/// Horizon azimuths per point.
const AZIMUTHS: usize = 64;
/// Angular radius of the sun's disc (rad), as the renderer's.
const SUN_RADIUS: f64 = 0.00465;
/// Height above the surface point the horizon and rays start from (m).
const LIFT: f64 = 1.0;

/// Directions and weights of the upper hemisphere: `nz` Gauss–Legendre
/// nodes in `z ∈ (0, 1)` times `na` azimuths.
fn hemisphere(nz: usize, na: usize) -> Vec<(DVec3, f64)> {
    let mut q = Vec::with_capacity(nz * na);
    for (x, wx) in gauss_legendre(nz) {
        let z = 0.5 * (x + 1.0);
        let r = (1.0 - z * z).max(0.0).sqrt();
        for i in 0..na {
            let phi = 2.0 * PI * (i as f64 + 0.5) / na as f64;
            q.push((
                DVec3::new(r * phi.cos(), r * phi.sin(), z),
                0.5 * wx * 2.0 * PI / na as f64,
            ));
        }
    }
    q
}

/// Bilinear height of the field's samples at world `xy` (the tracer's surface).
fn height(field: &HeightField, xy: DVec2) -> Option<f64> {
    let g = xy / field.spacing;
    let (w, h) = (f64::from(field.columns - 1), f64::from(field.rows - 1));
    if !(g.x >= 0.0 && g.y >= 0.0 && g.x <= w && g.y <= h) {
        return None;
    }
    let (c, r) = (g.x.floor().min(w - 1.0), g.y.floor().min(h - 1.0));
    let (u, v) = (g.x - c, g.y - r);
    let s = |dc: f64, dr: f64| f64::from(field.height((c + dc) as u32, (r + dr) as u32));
    Some(
        s(0.0, 0.0) * (1.0 - u) * (1.0 - v)
            + s(1.0, 0.0) * u * (1.0 - v)
            + s(0.0, 1.0) * (1.0 - u) * v
            + s(1.0, 1.0) * u * v,
    )
}

/// A lit surface point: position, normal and horizon elevation (rad, ≥ 0) per azimuth.
struct Point {
    x: DVec3,
    n: DVec3,
    horizon: [f64; AZIMUTHS],
}

impl Point {
    fn new(field: &HeightField, x: DVec3, n: DVec3) -> Point {
        let mut horizon = [0.0; AZIMUTHS];
        let z0 = x.z + LIFT;
        let step = field.spacing.min_element();
        for (k, h) in horizon.iter_mut().enumerate() {
            let phi = 2.0 * PI * k as f64 / AZIMUTHS as f64;
            let d = DVec2::new(phi.cos(), phi.sin());
            let (mut s, mut best) = (0.5 * step, 0.0f64);
            while let Some(z) = height(field, x.truncate() + d * s) {
                best = best.max((z - z0) / s);
                s = (s * 1.08).max(s + 0.5 * step);
            }
            *h = best.atan();
        }
        Point { x, n, horizon }
    }

    /// Horizon elevation towards azimuth `phi`, linear between the bins.
    fn horizon_at(&self, phi: f64) -> f64 {
        let t = phi.rem_euclid(2.0 * PI) / (2.0 * PI) * AZIMUTHS as f64;
        let k = t.floor() as usize % AZIMUTHS;
        let f = t - t.floor();
        self.horizon[k] * (1.0 - f) + self.horizon[(k + 1) % AZIMUTHS] * f
    }

    fn visible(&self, d: DVec3) -> bool {
        d.z > 0.0 && d.z.asin() > self.horizon_at(d.y.atan2(d.x))
    }

    fn transfer(&self, d: DVec3) -> f64 {
        if self.visible(d) {
            self.n.dot(d).max(0.0) / PI
        } else {
            0.0
        }
    }

    /// Fraction of the sun's disc (towards `s`) above the horizon.
    fn sun_visibility(&self, s: DVec3) -> f64 {
        let above = s.z.asin() - self.horizon_at(s.y.atan2(s.x));
        (above / (2.0 * SUN_RADIUS) + 0.5).clamp(0.0, 1.0)
    }
}

/// The morning preset's sky (luminance, 0 below the horizontal) and sun.
struct Environment {
    sky: PreethamSky,
    sun: DVec3,
    /// Luminance of the sun's irradiance on a plane facing it.
    sun_irradiance: f64,
}

impl Environment {
    fn morning() -> Environment {
        let preset = SkyPreset::Morning;
        let sun = preset.sun().expect("sun").direction();
        let sky = PreethamSky::new(sun, preset.turbidity()).expect("sky");
        let sun_irradiance = f64::from(luminance(sky.sun_irradiance()));
        Environment {
            sky,
            sun: sun.as_dvec3().normalize(),
            sun_irradiance,
        }
    }

    fn sky(&self, d: DVec3) -> f64 {
        if d.z <= 0.0 {
            return 0.0;
        }
        f64::from(luminance(self.sky.radiance(d.as_vec3())))
    }

    /// SH coefficients (26 bands) of the sky and of the sun.
    fn coefficients(&self, n: usize) -> (Vec<f64>, Vec<f64>) {
        let bands = sh_bands::MAX_GENERIC_BANDS;
        let sky = sh_bands::project(|d| self.sky(d), bands, n);
        let mut sun = vec![0.0; bands * bands];
        sh_bands::basis(self.sun, bands, &mut sun);
        sun.iter_mut().for_each(|c| *c *= self.sun_irradiance);
        (sky, sun)
    }
}

/// One SH variant: its band count, window and the windowed band-limited
/// sky and sun at the quadrature directions.
struct Variant {
    bands: usize,
    window: Window,
    sky: Vec<f64>,
    sun: Vec<f64>,
}

fn windowed(c: &[f64], bands: usize, window: Window) -> Vec<f64> {
    let mut c = c[..bands * bands].to_vec();
    window.apply(&mut c, bands);
    c
}

fn variant(q: &[(DVec3, f64)], (sky, sun): (&[f64], &[f64]), bands: usize, window: Window) -> Variant {
    let (cs, cu) = (windowed(sky, bands, window), windowed(sun, bands, window));
    let mut y = vec![0.0; bands * bands];
    let (mut ts, mut tu) = (Vec::with_capacity(q.len()), Vec::with_capacity(q.len()));
    for (d, _) in q {
        sh_bands::basis(*d, bands, &mut y);
        ts.push(cs.iter().zip(&y).map(|(a, b)| a * b).sum());
        tu.push(cu.iter().zip(&y).map(|(a, b)| a * b).sum());
    }
    Variant {
        bands,
        window,
        sky: ts,
        sun: tu,
    }
}

/// Per pixel: None (sky) or the reference and per variant (sky part, sun part).
struct Pixel {
    reference: f64,
    /// Unshadowed sun, `E_sun·max(0, n·s)/π`, and the disc's visibility.
    sun_unshadowed: f64,
    sun_visibility: f64,
    sh: Vec<(f64, f64)>,
}

fn shade(point: &Point, env: &Environment, q: &[(DVec3, f64)], variants: &[Variant]) -> Pixel {
    let transfer: Vec<f64> = q.iter().map(|(d, w)| w * point.transfer(*d)).collect();
    let sky: f64 = q.iter().zip(&transfer).map(|((d, _), t)| t * env.sky(*d)).sum();
    let sun_unshadowed = env.sun_irradiance * point.n.dot(env.sun).max(0.0) / PI;
    let sun_visibility = point.sun_visibility(env.sun);
    let dot = |table: &[f64]| transfer.iter().zip(table).map(|(a, b)| a * b).sum::<f64>();
    Pixel {
        reference: sky + sun_unshadowed * sun_visibility,
        sun_unshadowed,
        sun_visibility,
        sh: variants.iter().map(|v| (dot(&v.sky), dot(&v.sun))).collect(),
    }
}

/// The camera's ray through pixel `(i, j)` of a `w×h` image.
fn ray(w: usize, h: usize, i: usize, j: usize) -> (DVec3, DVec3) {
    let camera = jacksboro_valley_camera();
    let f = (camera.target - camera.eye).normalize();
    let r = f.cross(camera.up).normalize();
    let u = r.cross(f);
    let t = (0.5 * camera.fov_y_deg.to_radians()).tan();
    let sx = (2.0 * (i as f64 + 0.5) / w as f64 - 1.0) * t * w as f64 / h as f64;
    let sy = (1.0 - 2.0 * (j as f64 + 0.5) / h as f64) * t;
    (camera.eye, (f + r * sx + u * sy).normalize())
}

struct Render {
    size: (usize, usize),
    /// Per pixel: the point and its shading, or the sky's luminance.
    pixels: Vec<Result<(Point, Pixel), f64>>,
}

fn render(size: (usize, usize), quadrature: (usize, usize), env: &Environment, variants: &[Variant]) -> Render {
    let field = jacksboro_field();
    let tracer = HeightFieldTracer::new(&field).expect("tracer");
    let q = hemisphere(quadrature.0, quadrature.1);
    let (w, h) = size;
    let pixels = (0..w * h)
        .map(|k| {
            let (eye, dir) = ray(w, h, k % w, k / w);
            match tracer.trace(eye, dir) {
                Some(hit) => {
                    let point = Point::new(&field, hit.position, tracer.normal_at(hit.grid));
                    let pixel = shade(&point, env, &q, variants);
                    Ok((point, pixel))
                }
                // Past the field's edge: the sky just above the horizon.
                None => Err(env.sky(dir.with_z(dir.z.max(1e-3)).normalize())),
            }
        })
        .collect();
    Render { size, pixels }
}

/// Relative RMSE, mean negative sun light and mean sun leaking into the
/// shadow (both per unshadowed sun), of variant `v` over the terrain pixels.
struct Errors {
    rmse: f64,
    negative: f64,
    leak: f64,
}

fn errors(render: &Render, v: usize) -> Errors {
    let terrain: Vec<&Pixel> = render
        .pixels
        .iter()
        .filter_map(|p| p.as_ref().ok().map(|p| &p.1))
        .collect();
    let n = terrain.len() as f64;
    let mean = terrain.iter().map(|p| p.reference).sum::<f64>() / n;
    let sq = terrain
        .iter()
        .map(|p| (p.sh[v].0 + p.sh[v].1 - p.reference).powi(2))
        .sum::<f64>();
    let lit: Vec<&&Pixel> = terrain.iter().filter(|p| p.sun_unshadowed > 0.0).collect();
    let negative = lit
        .iter()
        .map(|p| (-p.sh[v].1).max(0.0) / p.sun_unshadowed)
        .sum::<f64>()
        / lit.len() as f64;
    let shadow: Vec<&&Pixel> = lit.iter().copied().filter(|p| p.sun_visibility == 0.0).collect();
    let leak = shadow.iter().map(|p| p.sh[v].1 / p.sun_unshadowed).sum::<f64>() / shadow.len().max(1) as f64;
    Errors {
        rmse: (sq / n).sqrt() / mean,
        negative,
        leak,
    }
}

fn write_panels(dir: &Path, render: &Render, variants: &[Variant]) {
    let (w, h) = render.size;
    let mut terrain: Vec<f64> = (render.pixels.iter().filter_map(|p| p.as_ref().ok()))
        .map(|p| p.1.reference)
        .collect();
    terrain.sort_by(f64::total_cmp);
    let (lo, hi) = (terrain[terrain.len() / 100], terrain[terrain.len() * 99 / 100]);
    let panel = |value: &dyn Fn(&Pixel) -> f64| -> Vec<u8> {
        (render.pixels.iter())
            .flat_map(|p| {
                let v = match p {
                    Ok((_, pixel)) => value(pixel),
                    Err(sky) => *sky,
                };
                let c = (255.0 * ((v - lo) / (hi - lo)).clamp(0.0, 1.0)).round() as u8;
                [c, c, c, 255]
            })
            .collect()
    };
    let mut panels = vec![("reference".to_string(), panel(&|p| p.reference))];
    for (k, v) in variants.iter().enumerate() {
        let suffix = match v.window {
            Window::None => String::new(),
            Window::Hanning => "-hanning".into(),
            Window::Lanczos => continue,
        };
        panels.push((format!("sh{}{suffix}", v.bands), panel(&|p| p.sh[k].0 + p.sh[k].1)));
    }
    for (name, rgba) in panels {
        let path = dir.join(format!("fig-9-4-{name}.png"));
        write_png_rgba8(&path, &rgba, w as u32, h as u32).expect("figure PNG");
        println!("wrote {}", path.display());
    }
}

/// The explicit projection `Σ σ_l t_lm e_lm` at one point, for the identity check.
fn explicit(point: &Point, q: &[(DVec3, f64)], (sky, sun): (&[f64], &[f64]), bands: usize, window: Window) -> f64 {
    let mut t = vec![0.0; bands * bands];
    let mut y = vec![0.0; bands * bands];
    for (d, w) in q {
        let v = w * point.transfer(*d);
        if v != 0.0 {
            sh_bands::basis(*d, bands, &mut y);
            t.iter_mut().zip(&y).for_each(|(t, y)| *t += v * y);
        }
    }
    window.apply(&mut t, bands);
    (0..bands * bands).map(|i| t[i] * (sky[i] + sun[i])).sum()
}

#[test]
fn sh_bands_against_the_reference_on_a_terrain() {
    let figures = std::env::var_os("ALPENGLOW_FIGURES").map(PathBuf::from);
    let (size, quadrature, projection) = match figures {
        Some(_) => ((240, 160), (36, 144), 96),
        None => ((60, 40), (24, 96), 48),
    };
    let env = Environment::morning();
    let (sky, sun) = env.coefficients(projection);
    let q = hemisphere(quadrature.0, quadrature.1);
    let variants: Vec<Variant> = (BANDS.iter())
        .flat_map(|&b| WINDOWS.iter().map(move |&w| (b, w)))
        .map(|(b, w)| variant(&q, (&sky, &sun), b, w))
        .collect();
    let render = render(size, quadrature, &env, &variants);
    let points: Vec<&(Point, Pixel)> = render.pixels.iter().filter_map(|p| p.as_ref().ok()).collect();
    assert!(
        points.len() > size.0 * size.1 / 2,
        "too little terrain in view ({})",
        points.len()
    );

    // The tabulated dot product is the explicit projection's.
    for (point, pixel) in points.iter().step_by(points.len() / 3) {
        for (k, v) in variants.iter().enumerate() {
            let want = explicit(point, &q, (&sky, &sun), v.bands, v.window);
            let got = pixel.sh[k].0 + pixel.sh[k].1;
            assert!(
                (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                "{} bands {:?}: {got} vs {want}",
                v.bands,
                v.window
            );
        }
    }

    // The horizon's visibility agrees with traced rays.
    let field = jacksboro_field();
    let tracer = HeightFieldTracer::new(&field).expect("tracer");
    let (mut agree, mut total) = (0usize, 0usize);
    for (point, _) in points.iter().step_by(points.len() / 40) {
        for (d, _) in q.iter().step_by(q.len() / 60) {
            if point.n.dot(*d) <= 0.0 {
                continue;
            }
            let escapes = tracer.trace(point.x + DVec3::Z * LIFT, *d).is_none();
            agree += usize::from(escapes == point.visible(*d));
            total += 1;
        }
    }
    let agreement = agree as f64 / total as f64;
    println!(
        "horizon visibility agrees with traced rays for {:.1} % of {total} rays",
        100.0 * agreement
    );
    assert!(agreement > 0.95, "horizon visibility vs traced rays: {agreement}");

    let sun_share = points
        .iter()
        .map(|p| p.1.sun_unshadowed * p.1.sun_visibility)
        .sum::<f64>()
        / points.iter().map(|p| p.1.reference).sum::<f64>();
    println!("the sun's share of the reference: {:.1} %", 100.0 * sun_share);
    println!("bands window    relRMSE  negative  leak");
    let mut rows = Vec::new();
    for (k, v) in variants.iter().enumerate() {
        let e = errors(&render, k);
        println!(
            "{:5} {:9} {:7.4} {:9.4} {:6.3}",
            v.bands,
            format!("{:?}", v.window),
            e.rmse,
            e.negative,
            e.leak
        );
        rows.push((v.bands, v.window, e));
    }
    let get = |b: usize, w: Window| &rows.iter().find(|r| r.0 == b && r.1 == w).expect("variant").2;
    for w in WINDOWS {
        assert!(
            get(26, w).rmse < get(10, w).rmse && get(10, w).rmse < get(5, w).rmse,
            "{w:?}: RMSE must fall with the bands"
        );
    }
    for b in [26, 10] {
        let plain = get(b, Window::None);
        for w in [Window::Hanning, Window::Lanczos] {
            let f = get(b, w);
            assert!(
                f.negative < 0.5 * plain.negative,
                "{b} bands {w:?}: negative light {} vs plain {}",
                f.negative,
                plain.negative
            );
            assert!(
                f.leak > plain.leak,
                "{b} bands {w:?}: leak {} vs plain {}",
                f.leak,
                plain.leak
            );
        }
    }

    if let Some(dir) = figures {
        write_panels(&dir, &render, &variants);
    }
}
