//! Frames per second of the readback ring (issue 26, item 2): blocking
//! frames (submit, wait, consume) against pipelined ones (submit frame
//! N+1, then wait for and consume frame N), consuming every requested
//! output into caller-owned buffers:
//!
//! `cargo run --release --example readback_bench -- [--width W] [--height H] [--frames N] [--outputs all|rgba8,depth,…]`

use std::time::Instant;

use alpenglow::glam::DVec3;
use alpenglow::{
    Camera, Context, ContextOptions, DeviceSelector, FrameData, Output, Outputs, Renderer, Scene, Settings,
};

struct Options {
    width: u32,
    height: u32,
    frames: u32,
    outputs: Outputs,
}

fn options() -> alpenglow::Result<Options> {
    let mut o = Options {
        width: 320,
        height: 180,
        frames: 60,
        outputs: Outputs::ALL,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        let value = pair.get(1).cloned().unwrap_or_default();
        let number = |what: &str| {
            value
                .parse()
                .map_err(|_| alpenglow::Error::invalid(what, format!("'{value}' is not a number")))
        };
        match pair[0].as_str() {
            "--width" => o.width = number("--width")?,
            "--height" => o.height = number("--height")?,
            "--frames" => o.frames = number("--frames")?,
            "--outputs" if value == "all" => o.outputs = Outputs::ALL,
            "--outputs" => o.outputs = value.split(',').map(str::parse).collect::<alpenglow::Result<_>>()?,
            other => return Err(alpenglow::Error::invalid("option", format!("unknown option {other}"))),
        }
    }
    Ok(o)
}

/// Frame `k` of a camera flying across the scene.
fn camera(scene: &Scene, k: u32) -> Camera {
    let base = scene.default_camera();
    let t = f64::from(k) * 10.0;
    Camera {
        eye: base.eye + DVec3::new(t, 0.5 * t, 0.0),
        target: base.target + DVec3::new(t, 0.5 * t, 0.0),
        ..base
    }
}

/// Copies every output of `frame` into `buffers` (one per output, reused).
fn consume(frame: &FrameData<'_>, buffers: &mut [Vec<u8>]) -> alpenglow::Result<()> {
    for view in frame.views() {
        for (plane, buffer) in view.planes().zip(buffers.iter_mut()) {
            buffer.resize(plane.pixels() * plane.output.bytes_per_pixel(), 0);
            plane.copy_into(buffer)?;
        }
    }
    Ok(())
}

/// Seconds per frame of `frames` frames, pipelined or blocking.
fn run(renderer: &mut Renderer, scene: &Scene, frames: u32, pipelined: bool) -> alpenglow::Result<f64> {
    let mut buffers = vec![Vec::new(); Output::ALL.len()];
    let start = Instant::now();
    let mut pending = None;
    for k in 0..frames {
        let ticket = renderer.submit(&[camera(scene, k)])?;
        if !pipelined {
            consume(&renderer.wait(ticket)?, &mut buffers)?;
            continue;
        }
        if let Some(previous) = pending.replace(ticket) {
            consume(&renderer.wait(previous)?, &mut buffers)?;
        }
    }
    if let Some(last) = pending {
        consume(&renderer.wait(last)?, &mut buffers)?;
    }
    Ok(start.elapsed().as_secs_f64() / f64::from(frames.max(1)))
}

fn main() -> alpenglow::Result<()> {
    let o = options()?;
    let ctx = Context::new(&ContextOptions {
        validation: false,
        device: DeviceSelector::Best,
    })?;
    let mut scene = Scene::default_terrain()?;
    scene.add_rocks(200)?;
    let mut settings = Settings::new(o.width, o.height);
    settings.outputs = o.outputs;
    let mut renderer = Renderer::new(&ctx, &scene, settings)?;
    renderer.set_profile_history(8);
    println!(
        "device: {}; {}×{}, outputs {:?}, {} frames each",
        ctx.info().name,
        o.width,
        o.height,
        o.outputs,
        o.frames
    );
    // Warm-up (the texture atlas fills), then alternate to share any drift.
    run(&mut renderer, &scene, 10, false)?;
    let mut times = [Vec::new(), Vec::new()];
    for round in 0..4 {
        for (i, pipelined) in [(0, false), (1, true)] {
            let _ = round;
            times[i].push(run(&mut renderer, &scene, o.frames / 4, pipelined)?);
        }
    }
    let fps = |t: &[f64]| t.len() as f64 / t.iter().sum::<f64>();
    let (blocking, pipelined) = (fps(&times[0]), fps(&times[1]));
    println!("blocking:  {blocking:.2} frames/s");
    println!(
        "pipelined: {pipelined:.2} frames/s ({:+.0} %)",
        (pipelined / blocking - 1.0) * 100.0
    );
    Ok(())
}
