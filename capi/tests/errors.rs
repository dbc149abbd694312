//! The error paths of the C API, called from Rust exactly as C calls them:
//! NULL pointers, bad values and bad sizes give a status and a one-line
//! message naming the culprit, never a crash, and leave out-pointers NULL.

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use alpenglow_c::*;

/// This thread's last error message.
fn last_error() -> String {
    // SAFETY: ag_last_error never returns NULL; the string lives until the next failure.
    unsafe { CStr::from_ptr(ag_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// Asserts `status` and that the message mentions every one of `words`.
fn expect(status: ag_status, expected: ag_status, words: &[&str]) {
    let message = last_error();
    assert_eq!(status, expected, "{message}");
    for word in words {
        assert!(message.contains(word), "{word:?} not in {message:?}");
    }
    assert!(!message.contains('\n'), "one line: {message:?}");
}

fn hills(columns: u32, rows: u32) -> Vec<f32> {
    (0..rows)
        .flat_map(|r| (0..columns).map(move |c| 100.0 + 50.0 * ((c as f32) * 0.2).sin() * ((r as f32) * 0.3).cos()))
        .collect()
}

#[test]
fn scenes_refuse_bad_heights_and_null_pointers() {
    let mut scene = null_mut();
    let mut heights = hills(9, 7);
    heights[12] = f32::NAN;
    // SAFETY: `heights` holds 9·7 floats; `scene` is writable.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 9, 7, 10.0, 10.0, &mut scene) };
    expect(
        status,
        ag_status::AG_ERROR_INVALID_ARGUMENT,
        &["heights", "column 3, row 1", "NaN"],
    );
    assert!(scene.is_null());

    heights[12] = f32::INFINITY;
    // SAFETY: as above.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 9, 7, 10.0, 10.0, &mut scene) };
    expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["heights", "inf"]);

    // SAFETY: NULL heights are checked before use.
    let status = unsafe { ag_scene_from_heights(null(), 9, 7, 10.0, 10.0, &mut scene) };
    expect(status, ag_status::AG_ERROR_NULL_POINTER, &["heights is NULL"]);

    let heights = hills(9, 7);
    // SAFETY: NULL out is checked first.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 9, 7, 10.0, 10.0, null_mut()) };
    expect(status, ag_status::AG_ERROR_NULL_POINTER, &["out is NULL"]);

    // SAFETY: valid arguments.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 9, 7, f64::NAN, 10.0, &mut scene) };
    expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["spacing"]);
    // SAFETY: 1×1 reads one float of 63.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 1, 1, 10.0, 10.0, &mut scene) };
    expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["heights", "2×2"]);

    let model = CString::new("alpine").unwrap();
    // SAFETY: NUL-terminated model; writable out.
    let status = unsafe { ag_scene_procedural(model.as_ptr(), 1, 33, 20.0, &mut scene) };
    expect(
        status,
        ag_status::AG_ERROR_INVALID_ARGUMENT,
        &["model", "alpine", "ridged"],
    );
    // SAFETY: NULL model is checked.
    let status = unsafe { ag_scene_procedural(null(), 1, 33, 20.0, &mut scene) };
    expect(status, ag_status::AG_ERROR_NULL_POINTER, &["model"]);

    let path = CString::new("/nonexistent/dem.png").unwrap();
    // SAFETY: NUL-terminated path, NULL options allowed, writable out.
    let status = unsafe { ag_scene_from_file(path.as_ptr(), null(), &mut scene) };
    expect(status, ag_status::AG_ERROR_INPUT, &["/nonexistent/dem.png"]);
    assert!(scene.is_null());

    // SAFETY: NULL handles are allowed (and ignored) by destroy.
    unsafe { ag_scene_destroy(null_mut()) };
    let mut camera = std::mem::MaybeUninit::<ag_camera>::uninit();
    // SAFETY: NULL scene is checked.
    let status = unsafe { ag_scene_default_camera(null(), camera.as_mut_ptr()) };
    expect(status, ag_status::AG_ERROR_NULL_POINTER, &["scene is NULL"]);
    // SAFETY: NULL scene is checked.
    let status = unsafe { ag_scene_add_rocks(null_mut(), 3) };
    expect(status, ag_status::AG_ERROR_NULL_POINTER, &["scene is NULL"]);
}

#[test]
fn renderer_functions_refuse_null_handles() {
    let camera = ag_camera {
        eye: [0.0, 0.0, 100.0],
        target: [10.0, 10.0, 0.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 50.0,
        near: 1.0,
        far: 1000.0,
    };
    let mut ticket = 0;
    let mut bytes = 0;
    let mut renderer = null_mut();
    // SAFETY: NULL handles are checked before anything else is read.
    unsafe {
        let status = ag_renderer_render(null_mut(), &camera, 1, null(), 0);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["renderer is NULL"]);
        let status = ag_renderer_submit(null_mut(), &camera, 1, &mut ticket);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["renderer is NULL"]);
        let status = ag_renderer_wait(null_mut(), 1, null(), 0);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["renderer is NULL"]);
        let status = ag_renderer_poll(null_mut(), 1, null(), 0);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["renderer is NULL"]);
        let status = ag_renderer_output_bytes(null(), 0, AG_OUTPUT_DEPTH, &mut bytes);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["renderer is NULL"]);
        let status = ag_renderer_create(null(), null(), null(), &mut renderer);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["ctx is NULL"]);
        assert!(renderer.is_null());
        let status = ag_context_create(null(), null_mut());
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["out is NULL"]);
        assert_eq!(ag_context_destroy(null_mut(), null_mut()), ag_status::AG_OK);
        ag_renderer_destroy(null_mut());
    }
    // SAFETY: ag_version returns a static NUL-terminated string.
    let version = unsafe { CStr::from_ptr(ag_version()) };
    assert_eq!(version.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    assert_eq!(ag_abi_version(), AG_ABI_VERSION);
}

/// One renderer under validation: bad cameras, settings, buffers, outputs
/// and tickets are refused with the culprit named; nothing is reported by
/// the validation layers.
#[test]
fn rendering_refuses_bad_cameras_buffers_and_tickets() {
    let mut ctx = null_mut();
    let options = ag_context_options {
        validation: true,
        device: null(),
    };
    // SAFETY: valid options, writable out.
    let status = unsafe { ag_context_create(&options, &mut ctx) };
    assert_eq!(status, ag_status::AG_OK, "{}", last_error());
    let heights = hills(33, 25);
    let mut scene = null_mut();
    // SAFETY: 33·25 floats; writable out.
    let status = unsafe { ag_scene_from_heights(heights.as_ptr(), 33, 25, 30.0, 30.0, &mut scene) };
    assert_eq!(status, ag_status::AG_OK, "{}", last_error());

    let mut settings = ag_settings_default();
    settings.width = 0;
    let mut renderer = null_mut();
    // SAFETY: live handles, valid settings, writable out.
    let status = unsafe { ag_renderer_create(ctx, scene, &settings, &mut renderer) };
    expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["width"]);
    settings.width = 32;
    settings.height = 24;
    settings.terrain_detail = false;
    settings.readback_slots = 17;
    // SAFETY: as above.
    let status = unsafe { ag_renderer_create(ctx, scene, &settings, &mut renderer) };
    expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["readback_slots", "17"]);
    settings.readback_slots = 0;
    // SAFETY: as above.
    let status = unsafe { ag_renderer_create(ctx, scene, &settings, &mut renderer) };
    assert_eq!(status, ag_status::AG_OK, "{}", last_error());

    let mut camera = std::mem::MaybeUninit::<ag_camera>::uninit();
    // SAFETY: live scene, writable camera.
    let status = unsafe { ag_scene_default_camera(scene, camera.as_mut_ptr()) };
    assert_eq!(status, ag_status::AG_OK);
    // SAFETY: initialised by the call above.
    let camera = unsafe { camera.assume_init() };

    let mut depth = vec![0f32; 32 * 24];
    let mut buffers = no_buffers();
    buffers.depth = ag_buffer {
        data: depth.as_mut_ptr().cast(),
        bytes: depth.len() * 4,
    };
    // SAFETY (every call below): live renderer, arrays as long as their counts,
    // buffers writable for their sizes.
    unsafe {
        let bad = ag_camera {
            fov_y_deg: 0.0,
            ..camera
        };
        let status = ag_renderer_render(renderer, &bad, 1, &buffers, 1);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["fov"]);
        let bad = ag_camera {
            eye: [f64::NAN, 0.0, 0.0],
            ..camera
        };
        let status = ag_renderer_render(renderer, &bad, 1, &buffers, 1);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["camera.eye"]);
        // Two cameras for one view.
        let cameras = [camera, camera];
        let status = ag_renderer_render(renderer, cameras.as_ptr(), 2, null(), 0);
        expect(
            status,
            ag_status::AG_ERROR_INVALID_ARGUMENT,
            &["cameras", "2 cameras for 1 views"],
        );
        let status = ag_renderer_render(renderer, null(), 1, null(), 0);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["cameras is NULL"]);

        // Buffers: too small, too many views, NULL views with a count.
        let mut small = buffers;
        small.depth.bytes -= 1;
        depth.fill(-1.0);
        let status = ag_renderer_render(renderer, &camera, 1, &small, 1);
        expect(
            status,
            ag_status::AG_ERROR_BUFFER_TOO_SMALL,
            &["views[0].depth", "3071 bytes", "3072"],
        );
        assert!(depth.iter().all(|&d| d == -1.0), "nothing is written on a refused call");
        let two = [buffers, buffers];
        let status = ag_renderer_render(renderer, &camera, 1, two.as_ptr(), 2);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["view_count", "2"]);
        let status = ag_renderer_render(renderer, &camera, 1, null(), 1);
        expect(status, ag_status::AG_ERROR_NULL_POINTER, &["views is NULL"]);
        let mut bytes = 0;
        let status = ag_renderer_output_bytes(renderer, 0, 99, &mut bytes);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["output", "99"]);
        let status = ag_renderer_output_bytes(renderer, 1, AG_OUTPUT_RGBA8, &mut bytes);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["view", "1"]);
        let status = ag_renderer_output_bytes(renderer, 0, AG_OUTPUT_NORMAL, &mut bytes);
        assert_eq!((status, bytes), (ag_status::AG_OK, 32 * 24 * 12));

        // A good frame, then tickets: unknown, and overwritten by later frames.
        let status = ag_renderer_render(renderer, &camera, 1, &buffers, 1);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        assert!(depth.iter().any(|d| d.is_finite()) && depth.iter().all(|&d| d > 0.0));
        let status = ag_renderer_wait(renderer, 12345, &buffers, 1);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["ticket", "12345"]);
        let mut tickets = [0; 4];
        for ticket in &mut tickets {
            let status = ag_renderer_submit(renderer, &camera, 1, ticket);
            assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        }
        let status = ag_renderer_wait(renderer, tickets[0], &buffers, 1);
        expect(
            status,
            ag_status::AG_ERROR_INVALID_ARGUMENT,
            &["ticket of frame", "reused"],
        );
        let status = ag_renderer_wait(renderer, tickets[3], &buffers, 1);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());

        ag_renderer_destroy(renderer);
        ag_scene_destroy(scene);
        let mut messages = u64::MAX;
        let status = ag_context_destroy(ctx, &mut messages);
        assert_eq!((status, messages), (ag_status::AG_OK, 0), "{}", last_error());
    }
}

fn no_buffers() -> ag_frame_buffers {
    let none = ag_buffer {
        data: null_mut(),
        bytes: 0,
    };
    ag_frame_buffers {
        rgba8: none,
        hdr: none,
        depth: none,
        distance: none,
        normal: none,
        class_id: none,
        instance_id: none,
        motion: none,
    }
}

/// `ag_settings.raster`: an unknown value is an invalid argument naming
/// it; the compute path (lavapipe has 64-bit buffer atomics) renders the
/// terrain's depth under validation.
#[test]
fn the_raster_setting_is_checked_and_the_compute_path_renders() {
    let mut ctx = null_mut();
    let options = ag_context_options {
        validation: true,
        device: null(),
    };
    // SAFETY (every call below): valid options and structs, live handles,
    // writable outs, buffers as long as their sizes.
    unsafe {
        let status = ag_context_create(&options, &mut ctx);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        let heights = hills(33, 25);
        let mut scene = null_mut();
        let status = ag_scene_from_heights(heights.as_ptr(), 33, 25, 30.0, 30.0, &mut scene);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        let mut settings = ag_settings_default();
        (settings.width, settings.height, settings.raster) = (32, 24, 9);
        let mut renderer = null_mut();
        let status = ag_renderer_create(ctx, scene, &settings, &mut renderer);
        expect(status, ag_status::AG_ERROR_INVALID_ARGUMENT, &["raster", "9"]);
        settings.raster = AG_RASTER_COMPUTE;
        let status = ag_renderer_create(ctx, scene, &settings, &mut renderer);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        let mut camera = std::mem::MaybeUninit::<ag_camera>::uninit();
        assert_eq!(ag_scene_default_camera(scene, camera.as_mut_ptr()), ag_status::AG_OK);
        let camera = camera.assume_init();
        let mut depth = vec![0f32; 32 * 24];
        let mut buffers = no_buffers();
        buffers.depth = ag_buffer {
            data: depth.as_mut_ptr().cast(),
            bytes: depth.len() * 4,
        };
        let status = ag_renderer_render(renderer, &camera, 1, &buffers, 1);
        assert_eq!(status, ag_status::AG_OK, "{}", last_error());
        assert!(
            depth.iter().filter(|d| d.is_finite()).count() > 100,
            "terrain in the compute path"
        );
        ag_renderer_destroy(renderer);
        ag_scene_destroy(scene);
        let mut messages = u64::MAX;
        let status = ag_context_destroy(ctx, &mut messages);
        assert_eq!((status, messages), (ag_status::AG_OK, 0), "{}", last_error());
    }
}
