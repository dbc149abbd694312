//! `ag_renderer`: renders frames of a scene and copies their outputs into
//! caller-owned buffers, blocking (`ag_renderer_render`) or pipelined
//! (`ag_renderer_submit`, then `ag_renderer_poll` or `ag_renderer_wait`).

use crate::adapter::{self, FramePipe, Output, ViewImages};
use crate::context::ag_context;
use crate::scene::ag_scene;
use crate::status::{ag_status, arg, arg_mut, guard, put, Failure, Outcome};
use crate::types::{ag_camera, ag_frame_buffers, ag_output, ag_settings, output};

/// Identifies a submitted frame; never 0.
#[allow(non_camel_case_types)]
pub type ag_ticket = u64;

/// A renderer of one scene (opaque). Use it from one thread at a time.
#[allow(non_camel_case_types)]
pub struct ag_renderer {
    pipe: FramePipe,
    settle_frames: u32,
    /// (width, height) of each view.
    sizes: Vec<(u32, u32)>,
}

/// Builds a renderer of `scene` on `ctx` (uploads the scene, bakes the
/// frame graph); `settings` NULL: `ag_settings_default()`. Errors name the
/// setting at fault (`settings.width`, ...).
///
/// # Safety
/// `ctx` and `scene` are NULL or live handles; `settings` is NULL or valid;
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_create(
    ctx: *const ag_context,
    scene: *const ag_scene,
    settings: *const ag_settings,
    out: *mut *mut ag_renderer,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(out, "out", std::ptr::null_mut()) }?;
        // SAFETY: the caller passes NULL or live handles / a valid struct.
        let (ctx, scene) = unsafe { (arg(ctx, "ctx")?, arg(scene, "scene")?) };
        let settings = match settings.is_null() {
            true => crate::types::ag_settings_default(),
            // SAFETY: not NULL; the caller guarantees a valid struct.
            false => *unsafe { arg(settings, "settings") }?,
        };
        let mut rust = adapter::render_settings(
            settings.width,
            settings.height,
            settings.msaa,
            settings.terrain_detail,
            settings.readback_slots,
        );
        rust.raster = crate::types::raster(settings.raster)?;
        let pipe = FramePipe::new(&ctx.ctx, &scene.scene, rust)?;
        let renderer = ag_renderer {
            sizes: pipe.view_sizes(),
            pipe,
            settle_frames: settings.settle_frames,
        };
        // SAFETY: checked writable above.
        unsafe { put(out, "out", Box::into_raw(Box::new(renderer))) }?;
        Ok(ag_status::AG_OK)
    })
}

/// Destroys `renderer` (NULL: nothing to do), after the GPU finished its frames.
///
/// # Safety
/// `renderer` is NULL or a renderer from `ag_renderer_create` not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_destroy(renderer: *mut ag_renderer) {
    if !renderer.is_null() {
        // SAFETY: a live handle from Box::into_raw, owned by the caller until now.
        let renderer = unsafe { Box::from_raw(renderer) };
        // A panic while freeing GPU objects must not unwind into C.
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || drop(renderer)));
    }
}

/// How many views a frame has (1 for a plain renderer).
///
/// # Safety
/// `renderer` is NULL or a live renderer; `count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_view_count(renderer: *const ag_renderer, count: *mut u32) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live handle.
        let renderer = unsafe { arg(renderer, "renderer") }?;
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(count, "count", renderer.sizes.len() as u32) }?;
        Ok(ag_status::AG_OK)
    })
}

/// The bytes `output` (an `AG_OUTPUT_*`) of view `view` takes: width ×
/// height × its pixel size. Size each `ag_buffer` with it.
///
/// # Safety
/// `renderer` is NULL or a live renderer; `bytes` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_output_bytes(
    renderer: *const ag_renderer,
    view: u32,
    output: ag_output,
    bytes: *mut usize,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a live handle.
        let renderer = unsafe { arg(renderer, "renderer") }?;
        let size = renderer.output_bytes(view as usize, self::output(output)?)?;
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(bytes, "bytes", size) }?;
        Ok(ag_status::AG_OK)
    })
}

/// Renders a frame of `cameras` (one per view) until its textures settled,
/// waits for it and copies the outputs of views `0..view_count` into
/// `views` (NULL with `view_count` 0: nothing is copied). Every buffer is
/// checked before anything is rendered: on a bad one nothing is written.
///
/// # Safety
/// `renderer` is NULL or a live renderer used by no other thread;
/// `cameras` is NULL or readable for `camera_count` cameras; `views` is
/// NULL or readable for `view_count` structs whose non-NULL buffers are
/// writable for their `bytes`.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_render(
    renderer: *mut ag_renderer,
    cameras: *const ag_camera,
    camera_count: usize,
    views: *const ag_frame_buffers,
    view_count: usize,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller's promises above, passed on.
        let (renderer, cameras, views) = unsafe { frame_args(renderer, cameras, camera_count, views, view_count) }?;
        let cameras: Vec<_> = cameras.iter().map(|c| c.to_rust()).collect();
        renderer.check_buffers(views)?;
        let images = (renderer.pipe).render_blocking(&cameras, renderer.settle_frames, views.len())?;
        // SAFETY: the buffers were checked; the caller guarantees they are writable.
        unsafe { copy_out(&images, views) };
        Ok(ag_status::AG_OK)
    })
}

/// Submits a frame of `cameras` (one per view) and returns at once;
/// `*ticket` identifies it for `ag_renderer_poll` / `ag_renderer_wait`.
/// A frame must be read before too many later frames are submitted (then
/// its ticket is an error, never stale data).
///
/// # Safety
/// As `ag_renderer_render`; `ticket` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_submit(
    renderer: *mut ag_renderer,
    cameras: *const ag_camera,
    camera_count: usize,
    ticket: *mut ag_ticket,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller passes NULL or a writable pointer.
        unsafe { put(ticket, "ticket", 0) }?;
        // SAFETY: the caller's promises, passed on (no buffers).
        let (renderer, cameras, _) = unsafe { frame_args(renderer, cameras, camera_count, std::ptr::null(), 0) }?;
        let cameras: Vec<_> = cameras.iter().map(|c| c.to_rust()).collect();
        let value = renderer.pipe.submit(&cameras)?;
        // SAFETY: checked writable above.
        unsafe { put(ticket, "ticket", value) }?;
        Ok(ag_status::AG_OK)
    })
}

/// If the frame of `ticket` is done, copies its views `0..view_count` into
/// `views` and returns `AG_OK`; else returns `AG_NOT_READY` at once
/// (never blocks).
///
/// # Safety
/// As `ag_renderer_render` for `renderer` and `views`.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_poll(
    renderer: *mut ag_renderer,
    ticket: ag_ticket,
    views: *const ag_frame_buffers,
    view_count: usize,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller's promises, passed on (no cameras).
        let (renderer, _, views) = unsafe { frame_args(renderer, std::ptr::null(), 0, views, view_count) }?;
        renderer.check_buffers(views)?;
        // SAFETY: the buffers were checked; the caller guarantees they are writable.
        let mut destinations = unsafe { destinations(views) };
        match renderer.pipe.try_read(ticket, &mut destinations)? {
            false => Ok(ag_status::AG_NOT_READY),
            true => Ok(ag_status::AG_OK),
        }
    })
}

/// Waits until the frame of `ticket` is done and copies its views
/// `0..view_count` into `views`.
///
/// # Safety
/// As `ag_renderer_poll`.
#[no_mangle]
pub unsafe extern "C" fn ag_renderer_wait(
    renderer: *mut ag_renderer,
    ticket: ag_ticket,
    views: *const ag_frame_buffers,
    view_count: usize,
) -> ag_status {
    guard(|| {
        // SAFETY: the caller's promises, passed on (no cameras).
        let (renderer, _, views) = unsafe { frame_args(renderer, std::ptr::null(), 0, views, view_count) }?;
        renderer.check_buffers(views)?;
        // SAFETY: the buffers were checked; the caller guarantees they are writable.
        let mut destinations = unsafe { destinations(views) };
        renderer.pipe.wait(ticket, &mut destinations)?;
        Ok(ag_status::AG_OK)
    })
}

impl ag_renderer {
    fn output_bytes(&self, view: usize, output: Output) -> Outcome<usize> {
        let (w, h) = self.sizes.get(view).copied().ok_or_else(|| {
            Failure::invalid("view", format!("{view}; the renderer has {} view(s)", self.sizes.len()))
        })?;
        Ok(w as usize * h as usize * output.pixel_bytes())
    }

    /// Fails, naming the buffer, on one smaller than its output or on more
    /// views than the renderer has.
    fn check_buffers(&self, views: &[ag_frame_buffers]) -> Outcome {
        if views.len() > self.sizes.len() {
            return Err(Failure::invalid(
                "view_count",
                format!("{}; the renderer has {} view(s)", views.len(), self.sizes.len()),
            ));
        }
        for (k, buffers) in views.iter().enumerate() {
            for output in Output::ALL {
                let buffer = buffers.get(output);
                let needed = self.output_bytes(k, output)?;
                if !buffer.data.is_null() && buffer.bytes < needed {
                    return Err(Failure::new(
                        ag_status::AG_ERROR_BUFFER_TOO_SMALL,
                        format!(
                            "views[{k}].{}: {} bytes, the output needs {needed}",
                            output.field(),
                            buffer.bytes
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The checked arguments of a frame function.
///
/// # Safety
/// `renderer` is NULL or live and unshared; `cameras` is NULL or readable
/// for `camera_count`; `views` is NULL or readable for `view_count`.
unsafe fn frame_args<'a>(
    renderer: *mut ag_renderer,
    cameras: *const ag_camera,
    camera_count: usize,
    views: *const ag_frame_buffers,
    view_count: usize,
) -> Outcome<(&'a mut ag_renderer, &'a [ag_camera], &'a [ag_frame_buffers])> {
    // SAFETY: the caller passes NULL or a live, unshared handle.
    let renderer = unsafe { arg_mut(renderer, "renderer") }?;
    // SAFETY: the caller guarantees the lengths of non-NULL arrays.
    let cameras = unsafe { array(cameras, camera_count, "cameras") }?;
    // SAFETY: as above.
    let views = unsafe { array(views, view_count, "views") }?;
    Ok((renderer, cameras, views))
}

/// `count` elements at `pointer` (NULL is allowed for 0 elements).
///
/// # Safety
/// A non-NULL `pointer` is readable for `count` elements.
unsafe fn array<'a, T>(pointer: *const T, count: usize, parameter: &str) -> Outcome<&'a [T]> {
    match (pointer.is_null(), count) {
        (true, 0) => Ok(&[]),
        (true, _) => Err(Failure::null(parameter)),
        // SAFETY: not NULL; the caller guarantees `count` readable elements.
        (false, _) => Ok(unsafe { std::slice::from_raw_parts(pointer, count) }),
    }
}

/// The caller's buffers of `views` as byte slices, per output in `Output::ALL` order.
///
/// # Safety
/// Every non-NULL buffer of `views` is writable for its `bytes` and
/// aliases nothing else for `'a`.
unsafe fn destinations<'a>(views: &[ag_frame_buffers]) -> Vec<adapter::Destinations<'a>> {
    let slice = |buffer: crate::types::ag_buffer| -> Option<&'a mut [u8]> {
        // SAFETY: non-NULL buffers are writable for `bytes` and unaliased (caller's promise).
        (!buffer.data.is_null())
            .then(|| unsafe { std::slice::from_raw_parts_mut(buffer.data.cast::<u8>(), buffer.bytes) })
    };
    (views.iter())
        .map(|buffers| Output::ALL.map(|output| slice(buffers.get(output))))
        .collect()
}

/// Copies every wanted output of `images` into the caller's buffers.
///
/// # Safety
/// Every non-NULL buffer of `views` was checked large enough by
/// `check_buffers` and is writable for its `bytes`.
unsafe fn copy_out(images: &[ViewImages], views: &[ag_frame_buffers]) {
    for (image, buffers) in images.iter().zip(views) {
        for output in Output::ALL {
            let buffer = buffers.get(output);
            if buffer.data.is_null() {
                continue;
            }
            let bytes = image.bytes(output);
            let n = bytes.len().min(buffer.bytes);
            // SAFETY: `buffer.data` is writable for `buffer.bytes` ≥ n bytes (caller's
            // promise, size checked) and is caller memory, not overlapping `bytes`.
            unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.data.cast::<u8>(), n) };
        }
    }
}
