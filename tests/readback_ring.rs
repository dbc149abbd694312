//! Frames read without blocking (issue 26, item 2): the readback ring of
//! `submit` / `try_read` / `wait`, under validation and synchronization
//! validation. Pipelined frames equal blocking ones byte for byte, a
//! ticket whose slot was reused is an error, output subsets skip copies,
//! and steady-state frames allocate nothing on the heap (this binary's
//! counting global allocator).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

use alpenglow::glam::{DVec2, DVec3};
use alpenglow::{Camera, Context, FrameData, Output, Outputs, ProceduralTerrain, Renderer, Scene, Settings};
use common::{assert_validation_clean, validated_context};

/// Counts heap allocations (alloc, alloc_zeroed, realloc) of every thread
/// while [`COUNTING`] is set. With `ALPENGLOW_ALLOC_TRACE=N` in the
/// environment it prints the backtrace of every Nth counted allocation
/// (to find what allocates).
struct CountingAllocator;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
static TRACE: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static IN_TRACE: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if !COUNTING.load(Ordering::SeqCst) || IN_TRACE.with(|t| t.get()) {
        return;
    }
    let n = ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
    let every = TRACE.load(Ordering::Relaxed);
    if every > 0 && n % every == 0 && !IN_TRACE.with(|t| t.replace(true)) {
        eprintln!("allocation:\n{}", std::backtrace::Backtrace::force_capture());
        IN_TRACE.with(|t| t.set(false));
    }
}

// SAFETY: forwards to the system allocator unchanged; counting touches only atomics.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: the caller's contract is passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// The tests of this binary run one at a time: the allocation count is global.
static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Allocations made by `f`.
fn allocations<T>(f: impl FnOnce() -> T) -> (T, u64) {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    let value = f();
    COUNTING.store(false, Ordering::SeqCst);
    (value, ALLOCATIONS.load(Ordering::SeqCst) - before)
}

/// A small default-like scene: procedural terrain (atlas texturing) and boulders.
fn scene() -> Scene {
    let field = ProceduralTerrain::default()
        .try_generate(65, 49, DVec2::new(40.0, 55.0))
        .expect("procedural terrain");
    let mut scene = Scene::new(field);
    scene.add_rocks(12).expect("rocks");
    scene
}

/// `width`×`height` with a deterministic texture budget (tile counts, not
/// measured GPU time), so which frame generates which tile does not
/// depend on timings.
fn settings(width: u32, height: u32) -> Settings {
    let mut settings = Settings::new(width, height);
    settings.texture_streaming.budget.gpu_time = None;
    settings
}

/// A camera flying across the scene: frame `k`'s.
fn camera(scene: &Scene, k: u32) -> Camera {
    let base = scene.default_camera();
    let t = f64::from(k) / 100.0;
    let offset = DVec3::new(600.0 * t, 300.0 * t, -100.0 * t);
    Camera {
        eye: base.eye + offset,
        target: base.target + DVec3::new(200.0 * t, 0.0, 0.0),
        ..base
    }
}

/// Every output of every view of `frame`, concatenated in the caller's layout.
fn contents(frame: &FrameData<'_>) -> Vec<u8> {
    let mut bytes = Vec::new();
    for view in frame.views() {
        for plane in view.planes() {
            let start = bytes.len();
            bytes.resize(start + plane.pixels() * plane.output.bytes_per_pixel(), 0);
            plane.copy_into(&mut bytes[start..]).expect("copy");
        }
    }
    bytes
}

fn with_context(test: impl FnOnce(&Context)) {
    let _serial = serial();
    let (ctx, report) = validated_context();
    test(&ctx);
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn pipelined_frames_equal_blocking_frames_byte_for_byte() {
    with_context(|ctx| {
        let scene = scene();
        // Forty frames: the ring of three slots wraps thirteen times.
        const FRAMES: u32 = 40;
        let mut blocking = Renderer::new(ctx, &scene, settings(64, 40)).expect("renderer");
        let expected: Vec<Vec<u8>> = (0..FRAMES)
            .map(|k| {
                let ticket = blocking.submit(&[camera(&scene, k)]).expect("submit");
                contents(&blocking.wait(ticket).expect("wait"))
            })
            .collect();
        drop(blocking);
        let mut pipelined = Renderer::new(ctx, &scene, settings(64, 40)).expect("renderer");
        let mut next = Some(pipelined.submit(&[camera(&scene, 0)]).expect("submit"));
        for k in 0..FRAMES {
            let ticket = next.take().expect("submitted");
            if k + 1 < FRAMES {
                next = Some(pipelined.submit(&[camera(&scene, k + 1)]).expect("submit"));
            }
            let frame = pipelined.wait(ticket).expect("wait");
            assert_eq!(frame.frame(), u64::from(k));
            assert!(contents(&frame) == expected[k as usize], "frame {k} differs");
        }
        // The blocking `render` + `read` API reads the same images.
        let outcome = pipelined.render(&camera(&scene, 7)).expect("render");
        let images = pipelined.read(&outcome).expect("read");
        let ticket = pipelined.submit(&[camera(&scene, 7)]).expect("submit");
        let frame = pipelined.wait(ticket).expect("wait");
        let view = frame.view(0).expect("view 0");
        let mut class = vec![0u32; 64 * 40];
        view.plane(Output::Class)
            .expect("class")
            .copy_into_u32(&mut class)
            .expect("copy");
        assert_eq!(images.class, class);
        assert_eq!(images.rgba8, view.plane(Output::Rgba8).expect("rgba8").bytes);
    });
}

#[test]
fn a_ticket_whose_slot_was_reused_is_an_error() {
    with_context(|ctx| {
        let scene = scene();
        let mut settings = settings(32, 20);
        settings.readback_slots = 2;
        let mut renderer = Renderer::new(ctx, &scene, settings).expect("renderer");
        let cam = [scene.default_camera()];
        let first = renderer.submit(&cam).expect("submit");
        let second = renderer.submit(&cam).expect("submit");
        assert!(renderer.wait(first).is_ok());
        let _third = renderer.submit(&cam).expect("submit");
        let e = renderer.wait(first).expect_err("slot reused");
        assert!(e.to_string().contains("ticket of frame 0"), "{e}");
        assert!(e.to_string().contains("reused by frame 2"), "{e}");
        assert!(renderer.try_read(first).is_err());
        assert!(renderer.wait(second).is_ok());
        // A ticket of another renderer is refused too.
        let mut other = Renderer::new(ctx, &scene, self::settings(32, 20)).expect("renderer");
        let e = other.wait(second).expect_err("other renderer");
        assert!(e.to_string().contains("not submitted to this renderer"), "{e}");
        let mut bad = self::settings(32, 20);
        bad.readback_slots = 0;
        let e = Renderer::new(ctx, &scene, bad).err().expect("0 slots");
        assert_eq!(e.parameter(), Some("readback_slots"), "{e}");
    });
}

#[test]
fn try_read_does_not_block_and_returns_the_frame_once_done() {
    with_context(|ctx| {
        let scene = scene();
        let mut renderer = Renderer::new(ctx, &scene, settings(64, 40)).expect("renderer");
        let cam = [scene.default_camera()];
        let ticket = renderer.submit(&cam).expect("submit");
        let start = std::time::Instant::now();
        let first = renderer.try_read(ticket).expect("try_read").map(|f| f.frame());
        let polled = start.elapsed();
        let waited = renderer.wait(ticket).expect("wait").frame();
        assert_eq!(waited, 0);
        // Polling returns at once: None while the GPU works, else the frame.
        assert!(first.is_none() || first == Some(0));
        assert!(
            polled < std::time::Duration::from_millis(50),
            "try_read took {polled:?}"
        );
        let mut polls = 0;
        let frame = loop {
            polls += 1;
            if let Some(frame) = renderer.try_read(ticket).expect("try_read") {
                break frame.frame();
            }
        };
        assert_eq!((frame, polls), (0, 1), "a completed frame is read at the first poll");
    });
}

#[test]
fn requested_output_subsets_are_read_back_and_the_others_refused() {
    with_context(|ctx| {
        let scene = scene();
        let mut all = Renderer::new(ctx, &scene, settings(48, 32)).expect("renderer");
        let cam = [scene.default_camera()];
        let ticket = all.submit(&cam).expect("submit");
        let full = all.wait(ticket).expect("wait");
        let full_view = full.view(0).expect("view");
        assert_eq!(full_view.outputs(), Outputs::ALL);
        let subset = Outputs::of(&[Output::Rgba8, Output::Instance, Output::Normal]);
        let mut settings = settings(48, 32);
        settings.outputs = subset;
        let mut some = Renderer::new(ctx, &scene, settings).expect("renderer");
        let ticket = some.submit(&cam).expect("submit");
        let frame = some.wait(ticket).expect("wait");
        let view = frame.view(0).expect("view");
        assert_eq!(view.outputs(), subset);
        assert_eq!((view.width(), view.height()), (48, 32));
        for output in subset.iter() {
            let (a, b) = (
                view.plane(output).expect("subset"),
                full_view.plane(output).expect("all"),
            );
            let mut x = vec![0u8; a.pixels() * output.bytes_per_pixel()];
            let mut y = x.clone();
            a.copy_into(&mut x).expect("copy");
            b.copy_into(&mut y).expect("copy");
            assert!(x == y, "{output} differs with the subset");
        }
        let e = view.plane(Output::Depth).expect_err("not requested");
        assert!(e.to_string().contains("'depth' is not read back"), "{e}");
        let mut normal = vec![0f32; 48 * 32 * 3];
        view.plane(Output::Normal)
            .expect("normal")
            .copy_into_f32(&mut normal)
            .expect("normal");
        assert!(normal.iter().any(|n| n.abs() > 0.5), "the terrain has normals");
    });
}

/// Allocations of pipelined frames of `scene` seen from `path`'s cameras:
/// `warm_up` frames, then (submit, read) counts over `measured` frames
/// that submit frame N+1 before reading and consuming frame N into
/// caller-owned buffers.
fn pipelined_allocations(ctx: &Context, scene: &Scene, path: &Scene, (warm_up, measured): (usize, usize)) -> [u64; 2] {
    let trace = std::env::var("ALPENGLOW_ALLOC_TRACE").ok().and_then(|v| v.parse().ok());
    let mut renderer = Renderer::new(ctx, scene, settings(160, 100)).expect("renderer");
    // A bounded profile history: once full, its oldest profile's memory is reused.
    renderer.set_profile_history(8);
    let cams: Vec<[Camera; 1]> = (0..warm_up + measured).map(|k| [camera(path, k as u32)]).collect();
    let mut rgba = vec![0u8; 160 * 100 * 4];
    let mut depth = vec![0f32; 160 * 100];
    let mut run = |renderer: &mut Renderer, frames: std::ops::Range<usize>| -> [u64; 2] {
        let mut counts = [0; 2];
        let (mut ticket, n) = allocations(|| renderer.submit(&cams[frames.start]).expect("submit"));
        counts[0] += n;
        for k in frames.clone() {
            let next = (k + 1 < frames.end).then_some(k + 1);
            let (next, n) = allocations(|| next.map(|k| renderer.submit(&cams[k]).expect("submit")));
            counts[0] += n;
            let (_, n) = allocations(|| {
                let frame = match renderer.try_read(ticket).expect("try_read") {
                    Some(frame) => frame,
                    None => renderer.wait(ticket).expect("wait"),
                };
                let view = frame.view(0).expect("view");
                view.copy_into(Output::Rgba8, &mut rgba).expect("rgba8");
                view.plane(Output::Depth)
                    .expect("depth")
                    .copy_into_f32(&mut depth)
                    .expect("depth");
            });
            counts[1] += n;
            ticket = next.unwrap_or(ticket);
        }
        counts
    };
    // Warm-up: pools, scratch vectors and the profile history fill.
    run(&mut renderer, 0..warm_up);
    TRACE.store(trace.unwrap_or(0), Ordering::Relaxed);
    let counts = run(&mut renderer, warm_up..warm_up + measured);
    TRACE.store(0, Ordering::Relaxed);
    counts
}

/// The frame counts of the allocation tests (`ALPENGLOW_ALLOC_FRAMES=W,M`
/// overrides them when tracing).
fn allocation_frames() -> (usize, usize) {
    let frames = std::env::var("ALPENGLOW_ALLOC_FRAMES").unwrap_or_default();
    let frames: Vec<usize> = frames.split(',').filter_map(|f| f.parse().ok()).collect();
    match frames[..] {
        [w, m] => (w, m),
        _ => (16, 12),
    }
}

/// Every part of the frame path but the terrain's: the renderer, the frame
/// graph (barriers, labels, uploads, profiles), the readback ring, the
/// lighting and shadow cascades, point selection and point shadow casters,
/// the AOVs: no allocation per pipelined frame.
#[test]
fn steady_state_frames_of_points_allocate_nothing() {
    with_context(|ctx| {
        let terrain = scene();
        let points = Scene::points_only(terrain.points.clone());
        let (warm_up, measured) = allocation_frames();
        let counts = pipelined_allocations(ctx, &points, &terrain, (warm_up, measured));
        eprintln!(
            "points scene, {measured} frames: allocations in submit {}, read {}",
            counts[0], counts[1]
        );
        assert_eq!(counts, [0, 0], "allocations in submit, read over {measured} frames");
    });
}

/// The default-like scene (terrain, atlas texturing, boulders): reading is
/// allocation-free; submitting still allocates in two CPU planners that
/// build their working sets afresh every frame, the terrain's LOD (sketch
/// map, importance map, warp scratch: about 11 per frame) and the texture
/// atlas's tile planning (selection, fit, page table, pacer median: about
/// 14 per frame), a count independent of the image size and the scene's
/// instances. This bound catches any new per-frame allocation elsewhere.
#[test]
fn steady_state_frames_of_terrain_allocate_only_in_lod_and_tile_planning() {
    with_context(|ctx| {
        let scene = scene();
        let (warm_up, measured) = allocation_frames();
        let counts = pipelined_allocations(ctx, &scene, &scene, (warm_up, measured));
        let per_frame = counts[0] as f64 / measured as f64;
        eprintln!(
            "terrain scene, {measured} frames: allocations in submit {} ({per_frame:.1} per frame), read {}",
            counts[0], counts[1]
        );
        assert_eq!(counts[1], 0, "allocations while reading");
        assert!(
            per_frame <= 30.0,
            "{per_frame} allocations per submitted frame (expected at most 30)"
        );
    });
}
