"""Height pyramids from Python: write one from an array, stream it as a
scene (a coarse level resident, a detail window of a finer one), place
things on its finest level with ground_height, render it."""

import numpy as np
import pytest

import alpenglow as ag

SIZE = 513


def rippled():
    """1 m samples: broad hills a coarse level holds, ripples 6-7 m long
    that vanish below level 2."""
    y, x = np.mgrid[0:SIZE, 0:SIZE].astype(np.float64)
    hills = 30.0 * np.sin(x / 90.0) * np.cos(y / 120.0) + 0.05 * x
    ripples = 1.5 * np.sin(x * 2 * np.pi / 6.0) * np.cos(y * 2 * np.pi / 7.0)
    return (hills + ripples + 50.0).astype(np.float32)


def knot_heights(h, r, c):
    """The cubic B-spline at a sample: the [1, 4, 1] / 6 average along each axis."""
    w = np.array([1.0, 4.0, 1.0]) / 6.0
    return float(w @ h[r - 1 : r + 2, c - 1 : c + 2].astype(np.float64) @ w)


@pytest.fixture(scope="module")
def pyramid(tmp_path_factory):
    path = tmp_path_factory.mktemp("pyramid") / "ripples.hpyr"
    h = rippled()
    levels = ag.write_pyramid(path, h, spacing=1.0, tile_side=64)
    assert levels == 5  # 513, 257, 129, 65, 33
    return path, h


def test_a_streamed_scene_answers_ground_queries_from_the_finest_level(pyramid):
    path, h = pyramid
    streamed = ag.Scene.from_pyramid(path, resident_side=65, detail_window=128)
    assert streamed.heights.shape == (65, 65)  # level 3 resident
    assert streamed.extent == pytest.approx((512.0, 512.0))
    resident = ag.Scene.from_pyramid(path, resident_side=65, detail_window=0)
    rng = np.random.default_rng(7)
    off_streamed, off_resident = [], []
    for r, c in rng.integers(2, SIZE - 2, size=(60, 2)):
        truth = knot_heights(h, r, c)
        off_streamed.append(abs(streamed.ground_height(float(c), float(r)) - truth))
        off_resident.append(abs(resident.ground_height(float(c), float(r)) - truth))
    # The streamed query carries the 1.5 m ripples (only the procedural
    # octaves finer than 1 m differ); the resident level does not.
    assert np.mean(off_streamed) < 0.06, np.mean(off_streamed)
    assert np.mean(off_resident) > 10 * np.mean(off_streamed), (np.mean(off_resident), np.mean(off_streamed))
    with pytest.raises(ValueError, match="ground position"):
        streamed.ground_height(-5.0, 10.0)


def test_a_streamed_scene_renders(ctx, pyramid):
    path, _ = pyramid
    scene = ag.Scene.from_pyramid(path, resident_side=65, detail_window=128)
    ground = scene.ground_height(250.0, 200.0)
    camera = ag.Camera.look_at(
        eye=(250.0, 200.0, ground + 6.0), target=(250.0, 320.0, ground - 10.0), fov_y=60.0, near=0.5, far=2e3
    )
    renderer = ag.Renderer(ctx, scene, width=96, height=64, terrain_detail=False)
    out = renderer.render(camera)
    depth = out["depth"]
    # Ground in the lower half, at distances the camera's pose allows.
    lower = depth[40:, :]
    assert np.isfinite(lower).all() and (lower > 0.5).all() and (lower < 2e3).all()


def test_bad_pyramids_name_the_parameter_or_file(tmp_path):
    with pytest.raises(ValueError, match="tile side"):
        ag.write_pyramid(tmp_path / "x.hpyr", rippled()[:65, :65], tile_side=3)
    not_a_pyramid = tmp_path / "not.hpyr"
    not_a_pyramid.write_bytes(b"nothing like a pyramid")
    with pytest.raises(ag.Error, match="not.hpyr"):
        ag.Scene.from_pyramid(not_a_pyramid)
    assert not (tmp_path / "x.hpyr").exists()
