//! Vegetation as point trees (dissertation chapter 10 introduction, Fig.
//! 10.12), checked against independent references under validation:
//!
//! * the scatter is deterministic per seed, grows plants only where their
//!   layer shows (the CPU twin of the layer evaluation, not the scatter's
//!   own numbers), and its count matches density × ∫ share dA (integrated
//!   on a lattice) within a binomial bound;
//! * a plant's point tree covers the image its mesh covers (a CPU
//!   rasterisation of the triangles): no holes, two-sided leaves — and the
//!   same test fails when the object is not drawn two-sided;
//! * a hillside of more than 10 000 plants renders, and the class AOV shows
//!   vegetation.

use crate::io::heightmap::HeightField;
use crate::points::build::plants::generate_plant;
use crate::points::render::SplatSettings;
use crate::points::scene::{PointScene, PointTransform};
use crate::points::vegetation::{plant_prototype, prototype_seed, VegetationOptions};
use crate::renderer::{Camera, RenderSettings, Renderer, Scene};
use crate::surface::layers::vegetation::subtree_shares;
use crate::surface::layers::LayerTree;
use crate::surface::plants::PlantModel;
use crate::terrain::procedural::ProceduralTerrain;
use crate::test_support::points::render_points;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::texturing::reference::ReferenceSurface;
use crate::view::aov::CLASS_VEGETATION;
use crate::view::View;
use glam::{DVec2, DVec3};

/// Terrain noise seed of the default terrain settings (the scatter's).
const NOISE_SEED: u64 = 7;

fn hillside_field() -> HeightField {
    ProceduralTerrain::default()
        .try_generate(129, 129, DVec2::splat(16.0))
        .expect("terrain")
}

fn hillside_scene() -> Scene {
    let mut scene = Scene::new(hillside_field());
    scene.layers = LayerTree::load(&crate::test_support::data("layers-vegetation-hillside.toml")).expect("layers");
    scene
}

fn light_options(seed: u64) -> VegetationOptions {
    VegetationOptions {
        seed,
        variants: 2,
        samples: 0.3,
        ..VegetationOptions::default()
    }
}

#[test]
fn scatter_is_deterministic_follows_its_layer_and_matches_density() {
    let base = hillside_scene();
    let planted = |seed| {
        let mut scene = base.clone();
        let report = scene.add_vegetation(&light_options(seed)).expect("vegetation");
        (scene, report)
    };
    let (a, report) = planted(1);
    let (b, _) = planted(1);
    let (c, _) = planted(2);
    let places = |s: &Scene| -> Vec<(DVec3, u64, usize)> {
        (s.points.instances.iter())
            .map(|i| (i.transform.translation, i.transform.scale.to_bits(), i.object))
            .collect()
    };
    assert_eq!(places(&a), places(&b), "same seed, same plants");
    assert_ne!(places(&a), places(&c), "another seed, other plants");
    assert!(report.total() >= 10_000, "{report:?}");
    assert_eq!(report.thinned, 0);

    // Every plant stands where the meadow shows (CPU twin of the layers).
    let reference = ReferenceSurface::new(&a.heights, &a.layers, &a.input_maps, NOISE_SEED).expect("reference");
    let ground = a.ground(&Default::default()).expect("ground");
    let share_at = |xy: DVec2| subtree_shares(&a.layers, &reference.evaluate(xy, 0.0).coverage);
    for inst in &a.points.instances {
        let t = inst.transform.translation;
        let shares = share_at(t.truncate());
        assert!(
            shares[1] > 0.0,
            "a plant at {t} where the meadow's share is 0 ({shares:?})"
        );
        let rock_alone = shares[0] - shares[1] - shares[2];
        assert!(
            rock_alone < 0.999 && shares[2] < 0.999,
            "a plant on bare rock or snow at {t}"
        );
        assert!((t.z - ground.height(t.x, t.y).unwrap()).abs() < 1e-6);
    }

    // Count against density × ∫ share dA (midpoint rule on a 160² lattice).
    let extent = a.heights.extent();
    let n = 160;
    let mean_share: f64 = (0..n * n)
        .map(|k| {
            let xy = DVec2::new((k % n) as f64 + 0.5, (k / n) as f64 + 0.5) * extent / n as f64;
            f64::from(share_at(xy)[1])
        })
        .sum::<f64>()
        / (n * n) as f64;
    let density = 0.003 + 0.002 + 0.001;
    let expected = density * extent.x * extent.y * mean_share;
    let got = report.total() as f64;
    // Binomial spread (≤ √E) at 4.5σ, plus 3 % for the lattice's quadrature.
    let bound = 4.5 * expected.sqrt() + 0.03 * expected;
    println!("plants {got}, expected {expected:.0} ± {bound:.0} (mean share {mean_share:.3})");
    assert!(
        (got - expected).abs() <= bound,
        "{got} plants, expected {expected:.0} ± {bound:.0}"
    );
}

/// Pixels (row-major) whose centre a triangle of `mesh` covers, placed by
/// `transform` and seen by `camera` at `width`×`height`.
fn rasterise(mesh: &crate::points::TriangleMesh, transform: &PointTransform, view: &View) -> Vec<bool> {
    let (w, h) = (view.width as usize, view.height as usize);
    let (model, view_proj) = (transform.matrix(), view.view_proj_f64());
    let project = |p: glam::Vec3| {
        let c = view_proj * model.transform_point3(p.as_dvec3()).extend(1.0);
        DVec2::new((c.x / c.w + 1.0) * 0.5 * w as f64, (c.y / c.w + 1.0) * 0.5 * h as f64)
    };
    let mut mask = vec![false; w * h];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| project(mesh.positions[i as usize]));
        let area = (b - a).perp_dot(c - a);
        if area == 0.0 {
            continue;
        }
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        for y in (lo.y.floor().max(0.0) as usize)..(hi.y.ceil().min(h as f64) as usize) {
            for x in (lo.x.floor().max(0.0) as usize)..(hi.x.ceil().min(w as f64) as usize) {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let e = [
                    (b - a).perp_dot(p - a),
                    (c - b).perp_dot(p - b),
                    (a - c).perp_dot(p - c),
                ];
                if e.iter().all(|&v| v * area >= 0.0) {
                    mask[y * w + x] = true;
                }
            }
        }
    }
    mask
}

/// Share of `a`'s pixels within `radius` pixels of one of `b`'s.
fn covered_share(a: &[bool], b: &[bool], (w, h): (usize, usize), radius: i64) -> f64 {
    let near = |x: usize, y: usize| {
        (-radius..=radius).any(|dy| {
            (-radius..=radius).any(|dx| {
                let (u, v) = (x as i64 + dx, y as i64 + dy);
                u >= 0 && v >= 0 && (u as usize) < w && (v as usize) < h && b[v as usize * w + u as usize]
            })
        })
    };
    let total = a.iter().filter(|&&v| v).count();
    let hit = (0..w * h).filter(|&i| a[i] && near(i % w, i / w)).count();
    hit as f64 / total.max(1) as f64
}

#[test]
fn a_plant_point_tree_covers_its_mesh_without_holes() {
    // Points only, and hybrid (§10.1.8: up close the leaves are triangles).
    for hybrid in [false, true] {
        let options = VegetationOptions {
            hybrid,
            ..VegetationOptions::default()
        };
        for model in [PlantModel::Shrub, PlantModel::GrassTuft] {
            let coverage = [true, false].map(|two_sided| plant_coverage(model, &options, two_sided));
            assert!(
                coverage[1] < coverage[0] - 0.03,
                "{model:?}, hybrid {hybrid}: culling back faces should open holes: {coverage:?}"
            );
        }
    }
}

/// Renders variant 0 of `model` (1.7 m tall, 2.6 m away) drawn two-sided
/// or not, checks it against its rasterised mesh and returns the share of
/// the mesh's pixels it covers.
fn plant_coverage(model: PlantModel, options: &VegetationOptions, two_sided: bool) -> f64 {
    let (w, h) = (160u32, 100u32);
    let camera = Camera {
        eye: DVec3::new(0.0, -2.6, 1.3),
        target: DVec3::new(0.0, 0.0, 0.85),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.05,
        far: 100.0,
    };
    let transform = PointTransform {
        scale: f64::from(1.7 / model.nominal_height()),
        ..PointTransform::default()
    };
    let object = plant_prototype(model, 0, options).expect("prototype");
    let mesh = generate_plant(model, prototype_seed(model, 0, options));
    let reference = rasterise(&mesh, &transform, &View::new(camera, w, h));
    let mut points = PointScene::default();
    points.add(crate::points::scene::PointObject { two_sided, ..object }, transform);
    let settings = SplatSettings {
        shaded: false,
        ..SplatSettings::default()
    };
    let (frame, stats) = render_points(&Scene::points_only(points), &camera, settings, (w, h));
    let weight = frame.weight.expect("W");
    let drawn: Vec<bool> = weight.iter().map(|&v| v > 0.0).collect();
    let size = (w as usize, h as usize);
    // Mesh pixels with a splat or triangle on them (no tolerance: holes count).
    let recall = covered_share(&reference, &drawn, size, 0);
    let precision = covered_share(&drawn, &reference, size, 3);
    let what = format!("{model:?}, hybrid {}, two-sided {two_sided}", options.hybrid);
    crate::test_support::dump_pngs(&[(&what.replace([',', ' '], "-"), &frame.rgba8)], w, h);
    println!(
        "{what}: mesh pixels covered {recall:.3}, drawn pixels near the mesh {precision:.3}, {} triangles",
        stats.prefix_triangles
    );
    assert_eq!(stats.prefix_triangles > 0, options.hybrid, "{what}");
    if two_sided {
        assert!(recall >= 0.97, "{what}: holes: {recall}");
        assert!(precision >= 0.9, "{what}: drawn off the mesh: {precision}");
        let vegetation = frame.class.iter().filter(|&&c| c == CLASS_VEGETATION).count();
        assert!(
            vegetation >= drawn.iter().filter(|&&s| s).count() * 9 / 10,
            "{what}: class AOV"
        );
    }
    recall
}

#[test]
fn a_hillside_of_ten_thousand_plants_renders_and_shows_in_the_class_aov() {
    let mut scene = hillside_scene();
    let report = scene.add_vegetation(&light_options(1)).expect("vegetation");
    assert!(report.total() >= 10_000, "{report:?}");
    // Above the densest part of the meadow, looking down the slope.
    let extent = scene.heights.extent();
    let centre = DVec2::new(extent.x * 0.5, extent.y * 0.5);
    let ground = |p: DVec2| scene.ground_height(p.x, p.y).expect("ground");
    let eye = centre - DVec2::new(0.0, 300.0);
    let camera = Camera {
        eye: eye.extend(ground(eye) + 60.0),
        target: centre.extend(ground(centre)),
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.5,
        far: 20_000.0,
    };
    let (w, h) = (160u32, 100u32);
    let (ctx, validation) = validated_context();
    let (frame, stats) = {
        let mut renderer = Renderer::new(&ctx, &scene, RenderSettings::new(w, h)).expect("renderer");
        let frame = renderer.render(&camera).and_then(|f| renderer.read(&f)).expect("frame");
        renderer.finish().expect("finish");
        let stats = renderer.take_point_stats().expect("stats");
        (frame, *stats.last().expect("stats"))
    };
    drop(ctx);
    assert_validation_clean(&validation);
    let vegetation = frame.class.iter().filter(|&&c| c == CLASS_VEGETATION).count();
    let share = vegetation as f64 / frame.class.len() as f64;
    println!(
        "{} plants, {} drawn, {} splats in prefixes; vegetation pixels {share:.3}",
        report.total(),
        stats.instances_drawn,
        stats.prefix_splats
    );
    assert!(
        stats.instances == report.total() && stats.instances_drawn > 100,
        "{stats:?}"
    );
    assert!(share > 0.02 && share < 0.9, "vegetation covers {share} of the image");
    // Vegetation pixels carry a plant's instance id.
    let ids_ok = (0..frame.class.len())
        .filter(|&i| frame.class[i] == CLASS_VEGETATION)
        .all(|i| frame.instance[i] >= 1 && frame.instance[i] as usize <= report.total());
    assert!(ids_ok);
    crate::test_support::dump_pngs(&[("vegetation-hillside", &frame.rgba8)], w, h);
}
