"""Renders of a small height field: shapes, dtypes and values of every
output, the pipelined pair, cameras from poses, intrinsics, lighting."""

import threading
import time

import numpy as np
import pytest

import alpenglow as ag
from conftest import HEIGHT, WIDTH

SHAPES = {
    "rgba8": ((HEIGHT, WIDTH, 4), np.uint8),
    "hdr": ((HEIGHT, WIDTH, 4), np.float32),
    "depth": ((HEIGHT, WIDTH), np.float32),
    "distance": ((HEIGHT, WIDTH), np.float32),
    "normal": ((HEIGHT, WIDTH, 3), np.float32),
    "class": ((HEIGHT, WIDTH), np.uint32),
    "instance": ((HEIGHT, WIDTH), np.uint32),
    "motion": ((HEIGHT, WIDTH, 2), np.float32),
    "visibility": ((HEIGHT, WIDTH, 2), np.float32),
}


def test_render_gives_every_output_with_its_shape_and_dtype(renderer, camera):
    out = renderer.render(camera)
    for key, (shape, dtype) in SHAPES.items():
        assert out[key].shape == shape, key
        assert out[key].dtype == dtype, key
    # The scene has no point objects: no splat weight.
    assert "weight" not in out


def test_render_values_are_plausible(renderer, camera):
    out = renderer.render(camera)
    depth, distance = out["depth"], out["distance"]
    sky = ~np.isfinite(depth)
    # Sky at the top row, terrain at the bottom row.
    assert sky[0].all()
    assert np.isfinite(depth[-1]).all()
    assert (depth[~sky] > 0).all()
    # Euclidean distance along the ray is at least the view-space depth.
    assert (distance[~sky] >= depth[~sky] * (1 - 1e-4)).all()
    assert np.isinf(distance[sky]).all()
    # Sky is class 0; terrain class 1 or 10 + its surface layer.
    assert (out["class"][sky] == 0).all()
    assert ((out["class"][~sky] == 1) | (out["class"][~sky] >= 10)).all()
    assert (out["instance"] == 0).all()
    # Unit shading normals on the terrain, pointing up-ish; zero for sky.
    n = out["normal"][~sky]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-2)
    assert (n[:, 2] > 0).mean() > 0.9
    # Opaque, not black, and the sky unlike the terrain.
    rgba = out["rgba8"]
    assert (rgba[..., 3] == 255).all()
    assert rgba[..., :3].mean() > 20
    colour = rgba[..., :3].astype(float)
    assert np.abs(colour[sky].mean(axis=0) - colour[~sky].mean(axis=0)).max() > 10
    assert np.isfinite(out["hdr"]).all() and (out["hdr"][..., :3] >= 0).all()


def test_submit_then_wait_equals_render(renderer, camera):
    settled = renderer.render(camera)
    ticket = renderer.submit(camera)
    frame = renderer.wait(ticket)
    for key in SHAPES:
        np.testing.assert_array_equal(frame[key], settled[key], err_msg=key)


def read_when_done(read, ticket, timeout=300.0):
    """Polls `read` (try_read or poll) until the frame is there."""
    deadline = time.monotonic() + timeout
    while (frame := read(ticket)) is None:
        assert time.monotonic() < deadline, "the frame never finished"
        time.sleep(0.005)
    return frame


def test_try_read_and_poll_give_the_frame(renderer, camera):
    first, second = renderer.submit(camera), renderer.submit(camera)
    assert second != first
    frame = read_when_done(renderer.try_read, first)
    assert frame["rgba8"].shape == (HEIGHT, WIDTH, 4)
    assert read_when_done(renderer.poll, second)["depth"].shape == (HEIGHT, WIDTH)
    # Read again while its readback slot holds it: the same frame.
    np.testing.assert_array_equal(renderer.wait(first)["hdr"], frame["hdr"])
    with pytest.raises(ag.Error, match="ticket"):
        renderer.wait(10**9)


def test_a_ticket_whose_slot_was_reused_is_an_error(renderer, camera):
    old = renderer.submit(camera)
    # More frames than the renderer keeps readback slots for.
    newer = [renderer.submit(camera) for _ in range(3)]
    with pytest.raises(ag.Error, match="overwritten|reused"):
        renderer.wait(old)
    assert renderer.wait(newer[-1])["depth"].shape == (HEIGHT, WIDTH)


def test_camera_from_pose_round_trips(camera):
    again = ag.Camera.from_pose(camera.pose, fov_y=camera.fov_y, near=camera.near, far=camera.far)
    np.testing.assert_allclose(again.pose, camera.pose, atol=1e-9)
    np.testing.assert_allclose(again.eye, camera.eye)
    # The OpenGL convention: the camera looks down its -z axis.
    forward = -camera.pose[:3, 2]
    direction = np.subtract(camera.target, camera.eye)
    np.testing.assert_allclose(forward, direction / np.linalg.norm(direction), atol=1e-12)


def test_centred_intrinsics_equal_the_field_of_view(ctx, scene, camera, renderer):
    k = ag.Intrinsics.from_fov_y(camera.fov_y, WIDTH, HEIGHT)
    assert k.cx == pytest.approx((WIDTH - 1) / 2) and k.fx == pytest.approx(k.fy)
    pinhole = ag.Renderer(ctx, scene, width=WIDTH, height=HEIGHT, terrain_detail=False, intrinsics=k)
    a, b = pinhole.render(camera), renderer.render(camera)
    np.testing.assert_allclose(a["depth"], b["depth"], rtol=1e-3)


def test_time_of_day_moves_the_sun(renderer, camera):
    noon = ag.Lighting().time_of_day("2024-06-21", "12:00", latitude=36.4, longitude=-84.1)
    dusk = ag.Lighting().time_of_day("2024-06-21", "19:30", latitude=36.4, longitude=-84.1)
    assert noon.sun_direction[2] > 0.9 > dusk.sun_direction[2]
    before = renderer.render(camera)["hdr"]
    renderer.lighting = dusk
    try:
        assert renderer.lighting.sun_direction == dusk.sun_direction
        after = renderer.render(camera)["hdr"]
    finally:
        renderer.lighting = ag.Lighting()
    assert not np.array_equal(before, after)
    assert after[..., :3].mean() < before[..., :3].mean()


def test_the_gil_is_released_while_the_gpu_works(renderer, camera):
    done = threading.Event()
    worker = threading.Thread(target=lambda: (renderer.render(camera), done.set()))
    ticks = 0
    worker.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    # A render takes far longer than 50 ms on lavapipe; holding the GIL
    # would have stopped this loop for all of it.
    assert ticks > 50


def test_readback_slots_bound_the_unread_frames(ctx, scene, camera):
    with pytest.raises(ValueError, match="readback_slots"):
        ag.Renderer(ctx, scene, width=32, height=24, readback_slots=0)
    r = ag.Renderer(ctx, scene, width=32, height=24, terrain_detail=False, readback_slots=1)
    old = r.submit(camera)
    new = r.submit(camera)
    with pytest.raises(ag.Error, match="readback_slots"):
        r.wait(old)
    assert r.wait(new)["rgba8"].shape == (24, 32, 4)


def test_the_compute_raster_path_matches_the_hardware_path(ctx, scene, camera, renderer):
    compute = ag.Renderer(ctx, scene, width=WIDTH, height=HEIGHT, terrain_detail=False, raster="compute")
    a, b = compute.render(camera), renderer.render(camera)
    both = np.isfinite(a["depth"]) & np.isfinite(b["depth"])
    assert both.mean() > 0.2
    np.testing.assert_allclose(a["depth"][both], b["depth"][both], rtol=1e-3)
