"""Rigs: several named views per frame, a dict of outputs per view name."""

import numpy as np
import pytest

import alpenglow as ag


def test_a_rig_renders_a_dict_per_view(ctx, scene, camera):
    rig = ag.Rig(
        [
            ag.View("left", yaw=20.0),
            ag.View("right", yaw=-20.0, width=48, height=40, fov_y=40.0),
        ]
    )
    assert rig.names == ["left", "right"] and len(rig) == 2
    r = ag.Renderer(ctx, scene, width=64, height=48, rig=rig, terrain_detail=False)
    assert r.views == ["left", "right"]
    out = r.render(camera)
    assert set(out) == {"left", "right"}
    assert out["left"]["rgba8"].shape == (48, 64, 4)
    assert out["right"]["depth"].shape == (40, 48)
    assert not np.array_equal(out["left"]["depth"][-1], out["right"]["depth"][-1][:48])
    # The pipelined pair returns the same per-view dicts.
    frame = r.wait(r.submit(camera))
    for name in rig.names:
        np.testing.assert_array_equal(frame[name]["rgba8"], out[name]["rgba8"])


def test_rig_cameras_follow_the_rig_camera(camera):
    rig = ag.Rig.ring6(32)
    cams = rig.cameras(camera)
    assert len(cams) == 6 and rig.names[0] == "front"
    np.testing.assert_allclose(cams[0].eye, camera.eye)


def test_explicit_cameras_per_view(ctx, scene, camera):
    rig = ag.Rig([ag.View("a"), ag.View("b")])
    r = ag.Renderer(ctx, scene, width=40, height=30, rig=rig, terrain_detail=False)
    out = r.render([camera, camera])
    np.testing.assert_array_equal(out["a"]["depth"], out["b"]["depth"])
    with pytest.raises(ValueError, match="camera"):
        r.render([camera])


def test_bad_rigs_name_the_problem():
    with pytest.raises(ValueError):
        ag.Rig([])
    with pytest.raises(ValueError, match="name|unique|twice|duplicate"):
        ag.Rig([ag.View("a"), ag.View("a")])
    with pytest.raises(ValueError, match="fov_y"):
        ag.View("a", fov_y=50.0, intrinsics=ag.Intrinsics(10, 10, 5, 5))
