"""Bad inputs raise ValueError naming the parameter (or alpenglow.Error with
the library's one-line message), and a height map survives a round trip
through the library's writer and loader."""

import numpy as np
import pytest

import alpenglow as ag
from conftest import SPACING, hill


def test_nan_heights_name_the_parameter():
    h = hill(9, 9)
    h[3, 5] = np.nan
    with pytest.raises(ValueError, match=r"heights.*row 3, column 5"):
        ag.Scene.from_heights(h, spacing=SPACING)


@pytest.mark.parametrize("bad", [np.inf, -np.inf, 1e9])
def test_infinite_or_absurd_heights_are_refused(bad):
    h = hill(9, 9)
    h[0, 0] = bad
    with pytest.raises(ValueError, match="heights"):
        ag.Scene.from_heights(h, spacing=SPACING)


def test_a_wrong_dtype_names_the_parameter():
    with pytest.raises(ValueError, match=r"heights.*float32"):
        ag.Scene.from_heights(hill(9, 9).astype(np.float64), spacing=SPACING)
    with pytest.raises(ValueError, match="heights"):
        ag.Scene.from_heights([[1.0, 2.0], [3.0, 4.0]], spacing=SPACING)


@pytest.mark.parametrize("shape", [(16,), (4, 4, 2), (1, 8), (8, 1), (0, 0)])
def test_a_wrong_shape_names_the_parameter(shape):
    with pytest.raises(ValueError, match="heights"):
        ag.Scene.from_heights(np.zeros(shape, np.float32), spacing=SPACING)


@pytest.mark.parametrize("spacing", [0.0, -1.0, float("nan"), (1.0, 1e12), "x"])
def test_a_bad_spacing_names_the_parameter(spacing):
    with pytest.raises(ValueError, match="spacing"):
        ag.Scene.from_heights(hill(9, 9), spacing=spacing)


def test_non_contiguous_arrays_are_read_in_row_major_order():
    h = hill(9, 12)
    scene = ag.Scene.from_heights(np.asfortranarray(h), spacing=SPACING)
    np.testing.assert_array_equal(scene.heights, h)
    scene = ag.Scene.from_heights(h[::2, ::3], spacing=SPACING)
    np.testing.assert_array_equal(scene.heights, h[::2, ::3])


@pytest.mark.parametrize(
    "kwargs, parameter",
    [
        (dict(eye=(0, 0, 10), target=(0, 0, 10)), "camera"),
        (dict(eye=(0, 0, 10), target=(0, 100, 0), fov_y=0.0), "fov"),
        (dict(eye=(0, 0, 10), target=(0, 100, 0), fov_y=180.0), "fov"),
        (dict(eye=(0, 0, 10), target=(0, 100, 0), near=10.0, far=1.0), "near|far"),
        (dict(eye=(0, 0, 10), target=(0, 100, 0), near=-1.0), "near"),
        (dict(eye=(np.nan, 0, 10), target=(0, 100, 0)), "eye"),
        (dict(eye=(1e30, 0, 10), target=(0, 100, 0)), "eye"),
        (dict(eye=(0, 0, 10), target=(0, 100, 0), up=(0, 0, 0)), "up"),
        (dict(eye=(0, 0), target=(0, 100, 0)), "eye"),
        (dict(eye="here", target=(0, 100, 0)), "eye"),
    ],
)
def test_an_absurd_camera_names_the_parameter(kwargs, parameter):
    with pytest.raises(ValueError, match=parameter):
        ag.Camera.look_at(**kwargs)


def test_a_bad_pose_names_the_parameter():
    with pytest.raises(ValueError, match="pose"):
        ag.Camera.from_pose(np.eye(3))
    with pytest.raises(ValueError, match="pose"):
        ag.Camera.from_pose(np.zeros((4, 4)))
    pose = np.eye(4)
    pose[0, 3] = np.nan
    with pytest.raises(ValueError, match="pose"):
        ag.Camera.from_pose(pose)


def test_bad_renderer_settings_name_the_parameter(ctx, scene):
    with pytest.raises(ValueError, match="texturing"):
        ag.Renderer(ctx, scene, width=32, height=32, texturing="bogus")
    with pytest.raises(ValueError, match="raster"):
        ag.Renderer(ctx, scene, width=32, height=32, raster="bogus")
    with pytest.raises(ValueError, match="width|size|image"):
        ag.Renderer(ctx, scene, width=0, height=32)
    with pytest.raises(ValueError, match="distortion"):
        ag.Renderer(ctx, scene, width=32, height=32, distortion=ag.Distortion(k1=0.1))
    with pytest.raises(ValueError, match="k1"):
        ag.Distortion(k1=1e6)


def test_bad_lighting_names_the_parameter():
    with pytest.raises(ValueError, match="sky"):
        ag.Lighting(sky="cloudy")
    with pytest.raises(ValueError, match="sun_elevation"):
        ag.Lighting(sun_elevation=120.0)
    with pytest.raises(ValueError, match="date"):
        ag.Lighting().time_of_day("2024-13-40", "12:00", 0.0, 0.0)


def test_a_procedural_model_must_exist():
    with pytest.raises(ValueError, match="model.*ridged"):
        ag.Scene.procedural("volcanic", seed=1, size=33, spacing=10.0)
    scene = ag.Scene.procedural("ridged", seed=7, size=33, spacing=20.0)
    assert scene.heights.shape == (33, 33)
    assert scene.spacing == (20.0, 20.0)


def test_a_missing_file_raises_the_library_error(tmp_path):
    missing = tmp_path / "nothing.png"
    with pytest.raises(ag.Error, match="nothing.png"):
        ag.Scene.from_file(missing)
    with pytest.raises(ValueError, match="rows"):
        ag.Scene.from_file(missing, rows="east-up")


def test_a_height_map_round_trips_through_the_library(tmp_path):
    h = hill(37, 53)
    h[5, 7] = -12.25
    path = tmp_path / "hill.exr"
    ag.write_heightmap(path, h)
    scene = ag.Scene.from_file(path, spacing=SPACING)
    assert scene.heights.dtype == np.float32
    np.testing.assert_array_equal(scene.heights, h)
    assert scene.spacing == SPACING
    # The scene built from the array holds the same field.
    np.testing.assert_array_equal(ag.Scene.from_heights(h, spacing=SPACING).heights, h)


def test_the_library_scales_and_flips_like_the_cli(tmp_path):
    h = hill(9, 11)
    path = tmp_path / "hill.exr"
    ag.write_heightmap(path, h)
    scene = ag.Scene.from_file(path, spacing=2.0, height_scale=2.0, height_offset=5.0, rows="north-up")
    np.testing.assert_allclose(scene.heights, (h * 2.0 + 5.0)[::-1], rtol=1e-6)


def test_an_unknown_device_raises_the_library_error():
    with pytest.raises(ag.Error, match="no Vulkan device named like 'nonexistent'"):
        ag.Context(device="nonexistent")
    with pytest.raises(ag.Error, match="index 7"):
        ag.Context(device=7)
    with pytest.raises(ValueError, match="device"):
        ag.Context(device=1.5)
