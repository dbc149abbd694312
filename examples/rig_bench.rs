//! Benchmark of multi-view rigs (§3.3): a `ring6` rig rendered by one
//! renderer (one frame graph, one submission, one shared texture atlas and
//! sky-light bake) against six renderers of one view each, and one view
//! alone (the per-view cost):
//!
//! `cargo run --release --example rig_bench -- [--width W] [--frames N] [--dem tests/data/jacksboro-fault.png]`
//!
//! Reports, per configuration, the median GPU time of a frame (all views),
//! the median wall time of a frame, and the device memory allocated.

use std::time::Instant;

use alpenglow::files::load_heightmap;
use alpenglow::tools::profile::median;
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, HeightmapOptions, Renderer, Rig, Scene, Settings, ViewSpec,
};
use glam::{DVec2, DVec3};

struct Options {
    width: u32,
    frames: u32,
    dem: Option<String>,
}

fn options() -> Options {
    let mut o = Options {
        width: 320,
        frames: 10,
        dem: None,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        let value = pair.get(1).cloned().unwrap_or_default();
        match pair[0].as_str() {
            "--width" => o.width = value.parse().expect("--width N"),
            "--frames" => o.frames = value.parse().expect("--frames N"),
            "--dem" => o.dem = Some(value),
            other => panic!("unknown option {other}"),
        }
    }
    o
}

/// The scene, and a rig camera 2 m above its ground, mid-field, looking along +y.
fn scene_and_camera(dem: &Option<String>) -> alpenglow::Result<(Scene, Camera)> {
    let scene = match dem {
        Some(path) => {
            let options = HeightmapOptions {
                spacing: Some(DVec2::new(74.4, 92.6)),
                ..HeightmapOptions::default()
            };
            Scene::new(load_heightmap(std::path::Path::new(path), &options)?)
        }
        None => Scene::default_terrain()?,
    };
    let extent = scene.heights.extent();
    let (x, y) = (0.5 * extent.x, 0.4 * extent.y);
    let eye = DVec3::new(x, y, scene.ground_height(x, y)? + 2.0);
    let camera = Camera {
        eye,
        target: eye + DVec3::Y,
        up: DVec3::Z,
        fov_y_deg: 50.0,
        near: 0.5,
        far: 2.0 * extent.length(),
    };
    Ok((scene, camera))
}

/// Settles every renderer, renders `frames` more; (median GPU ms per
/// frame summed over the renderers, median wall ms per frame).
fn measure(renderers: &mut [(Renderer, Vec<Camera>)], frames: u32) -> alpenglow::Result<(f64, f64)> {
    for (r, cameras) in renderers.iter_mut() {
        r.render_views_settled(cameras, 256)?;
        r.finish()?;
    }
    let mut wall = Vec::new();
    for _ in 0..frames {
        let t = Instant::now();
        for (r, cameras) in renderers.iter_mut() {
            r.render_views(cameras)?;
        }
        wall.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let mut gpu = vec![0.0; frames as usize];
    for (r, _) in renderers.iter_mut() {
        for (k, p) in r.finish()?.iter().enumerate() {
            gpu[k] += p.gpu_ms;
        }
    }
    Ok((median(gpu), median(wall)))
}

fn main() -> alpenglow::Result<()> {
    let o = options();
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    let (scene, camera) = scene_and_camera(&o.dem)?;
    let rig = Rig::ring6(o.width);
    let specs = rig.specs((o.width, o.width * 3 / 4))?;
    let cameras = rig.cameras(&camera)?;
    let base = ctx.allocated_bytes();
    println!(
        "{}: ring6 of {}×{} views, {} frames after settling",
        ctx.info().name,
        specs[0].width,
        specs[0].height,
        o.frames
    );
    println!(
        "{:<28} {:>12} {:>12} {:>12}",
        "configuration", "GPU ms", "wall ms", "memory MiB"
    );
    let report = |what: &str, renderers: &mut Vec<(Renderer, Vec<Camera>)>| -> alpenglow::Result<()> {
        let memory = ctx.allocated_bytes().saturating_sub(base) as f64 / (1 << 20) as f64;
        let (gpu, wall) = measure(renderers, o.frames)?;
        println!("{what:<28} {gpu:>12.2} {wall:>12.2} {memory:>12.1}");
        renderers.clear();
        Ok(())
    };
    let alone = |spec: &ViewSpec| ViewSpec {
        name: String::new(),
        ..spec.clone()
    };
    let one = Renderer::new(&ctx, &scene, Settings::for_views(vec![alone(&specs[0])]))?;
    report("one view alone", &mut vec![(one, vec![cameras[0]])])?;
    let shared = Renderer::new(&ctx, &scene, Settings::for_views(specs.clone()))?;
    report("ring6, one renderer", &mut vec![(shared, cameras.clone())])?;
    let mut separate = Vec::new();
    for (spec, camera) in specs.iter().zip(&cameras) {
        let renderer = Renderer::new(&ctx, &scene, Settings::for_views(vec![alone(spec)]))?;
        separate.push((renderer, vec![*camera]));
    }
    report("ring6, six renderers", &mut separate)?;
    Ok(())
}
