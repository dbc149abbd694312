"""Shared fixtures: one validated Vulkan context for the whole run (lavapipe
in CI), a small synthetic terrain, and a camera that sees terrain below and
sky above. Renders stay tiny (at most 160x100): lavapipe is a CPU."""

import numpy as np
import pytest

import alpenglow as ag

WIDTH, HEIGHT = 96, 64
SPACING = (10.0, 12.0)


def hill(rows=65, cols=65):
    """A smooth hill, float32 (rows, cols), metres."""
    y, x = np.mgrid[0:rows, 0:cols].astype(np.float32)
    r2 = ((x - cols / 2) / (cols / 3)) ** 2 + ((y - rows / 2) / (rows / 3)) ** 2
    return (40.0 + 120.0 * np.exp(-r2)).astype(np.float32)


@pytest.fixture(scope="session")
def ctx():
    context = ag.Context(validation=True)
    yield context
    # Every Vulkan call of the suite ran under the Khronos validation layers.
    assert context.validation_messages == []


@pytest.fixture(scope="session")
def heights():
    return hill()


@pytest.fixture(scope="session")
def scene(heights):
    return ag.Scene.from_heights(heights, spacing=SPACING)


@pytest.fixture(scope="session")
def camera():
    # Above the southern part, looking north over the hill: terrain in the
    # lower part of the image, sky at the top.
    return ag.Camera.look_at(eye=(320.0, 40.0, 220.0), target=(320.0, 500.0, 60.0), fov_y=50.0, near=1.0, far=1e4)


@pytest.fixture(scope="session")
def renderer(ctx, scene):
    return ag.Renderer(ctx, scene, width=WIDTH, height=HEIGHT, terrain_detail=False)
