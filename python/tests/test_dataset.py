"""Dataset runner without Ray: job errors, sharding, manifest resume, encoders."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from _dataset_support import PYTHON_DIR, tree_bytes, write_job
from alpenglow import dataset
from alpenglow.dataset import encode
from alpenglow.dataset.job import JobError, path_pose


class FakeBackend:
    """Deterministic images computed from the camera, so no GPU is needed."""

    renders = 0

    def __init__(self, job):
        self.job = job

    def render(self, cam):
        FakeBackend.renders += 1
        h, w = self.job.height, self.job.width
        seed = int(abs(cam.eye[0] * 1000 + cam.eye[1])) % (2**32)
        rng = np.random.default_rng(seed)
        return {
            "rgba8": rng.integers(0, 256, (h, w, 4), dtype=np.uint8),
            "depth": np.full((h, w), cam.eye[0], np.float32),
            "class": rng.integers(0, 20, (h, w), dtype=np.uint32),
        }


# --- job errors: one line, naming the key ------------------------------------

BAD_JOBS = [
    ({"camera": "width = -3\nheight = 40"}, "camera.width"),
    ({"camera": "width = 64"}, "camera.height"),
    ({"camera": 'width = 64\nheight = 40\nfov_y = "wide"'}, "camera.fov_y"),
    ({"camera": "width = 64\nheight = 40\nfov_y = 200.0"}, "camera.fov_y"),
    ({"camera": "width = 64\nheight = 40\nnear = 10.0\nfar = 5.0"}, "camera.far"),
    ({"camera": "width = 64\nheight = 40\nwidht = 3"}, "camera.widht"),
    ({"scene": "seed = 3"}, "scene.heightmap"),
    ({"scene": 'heightmap = "missing.png"'}, "scene.heightmap"),
    ({"scene": 'procedural = "ridged"\nheightmap = "x.png"'}, "scene.heightmap"),
    ({"path": 'type = "spiral"\nframes = 8'}, "path.type"),
    ({"path": 'type = "orbit"\nframes = 0\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0'}, "path.frames"),
    ({"path": 'type = "orbit"\nframes = 8\ncenter = [0.0, 0.0]\nradius = 1.0'}, "path.center"),
    ({"path": 'type = "orbit"\nframes = 8\ncenter = [0.0, 0.0, 0.0]\nradius = -1.0'}, "path.radius"),
    ({"path": 'type = "keyframes"\nframes = 8'}, "path.key"),
    (
        {"path": 'type = "keyframes"\nframes = 8\n[[path.key]]\nframe = 0\neye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 1.0]'},
        "path.key[0].target",
    ),
    ({"output": 'aovs = ["rgba8"]'}, "output.dir"),
    ({"output": 'dir = "o"\naovs = ["rgb"]'}, "output.aovs"),
    ({"output": 'dir = "o"\naovs = ["depth"]\nformats = { depth = "png" }'}, "output.formats.depth"),
    ({"output": 'dir = "o"\naovs = ["rgba8"]\nshard_size = 0'}, "output.shard_size"),
    ({"frames": "start = 5\nend = 5"}, "frames.start"),
    ({"frames": "end = 9"}, "frames.end"),
    ({"ray": "max_restarts = -1"}, "ray.max_restarts"),
    ({"ray": "num_gpus = true"}, "ray.num_gpus"),
    ({"rig": '[[rig.view]]\nname = "a/b"'}, "rig.view[0].name"),
    ({"rig": '[[rig.view]]\nname = "a"\n[[rig.view]]\nname = "a"'}, "rig.view[1].name"),
    ({"render": "grid = [64]"}, "render.grid"),
    ({"lighting": "sun_elevation = nan"}, "lighting.sun_elevation"),
    (
        {
            "rig": '[[rig.view]]\nname = "a"\n[[rig.view]]\nname = "b"',
            "output": 'dir = "o"\naovs = ["motion"]',
        },
        "output.aovs",
    ),
    ({"extra": "x = 1"}, "extra"),
]


@pytest.mark.parametrize("sections,key", BAD_JOBS, ids=[k for _, k in BAD_JOBS])
def test_job_errors_are_one_line_and_name_the_key(tmp_path, sections, key):
    path = write_job(tmp_path, **sections)
    with pytest.raises(JobError) as info:
        dataset.load_job(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("job.toml: ")
    assert f" {key}: " in message, message


def test_invalid_toml_and_missing_file_are_one_line(tmp_path):
    path = tmp_path / "job.toml"
    path.write_text("[scene\n")
    with pytest.raises(JobError, match=r"^job.toml: not valid TOML") as info:
        dataset.load_job(path)
    assert "\n" not in str(info.value)
    with pytest.raises(JobError, match="cannot read the job file"):
        dataset.load_job(tmp_path / "nope.toml")


def test_job_paths_and_poses(tmp_path):
    job = dataset.load_job(write_job(tmp_path))
    assert job.out_dir == str(tmp_path / "out")
    assert job.frames() == range(0, 8)
    eye, target, up = path_pose(job.path, 2)  # a quarter of the orbit: +Y of the centre
    assert np.allclose(eye, (1280.0, 2780.0, 800.0)) and target == (1280.0, 1280.0, 0.0) and up == (0, 0, 1)
    assert [rel for _, _, rel in job.files(3)] == ["rgba8/000003.png", "depth/000003.exr", "class/000003.npy"]
    keys = 'type = "keyframes"\nframes = 5\n[[path.key]]\nframe = 1\neye = [0.0, 0.0, 10.0]\ntarget = [1.0, 0.0, 0.0]\n'
    keys += "[[path.key]]\nframe = 3\neye = [4.0, 0.0, 10.0]\ntarget = [5.0, 0.0, 0.0]"
    path = dataset.load_job(write_job(tmp_path, path=keys)).path
    assert path_pose(path, 0)[0] == (0.0, 0.0, 10.0)  # held before the first key
    assert path_pose(path, 2)[0] == (2.0, 0.0, 10.0)  # halfway
    assert path_pose(path, 4)[1] == (5.0, 0.0, 0.0)  # held after the last


def test_rig_views_name_their_files_and_turn(tmp_path):
    rig = '[[rig.view]]\nname = "front"\n[[rig.view]]\nname = "left"\nyaw_pitch_roll = [90.0, 0.0, 0.0]'
    job = dataset.load_job(write_job(tmp_path, rig=rig))
    assert [rel for _, _, rel in job.files(0)][:2] == ["front/rgba8/000000.png", "front/depth/000000.exr"]
    (_, front), (_, left) = job.cameras(0)
    eye = np.array(front.eye)
    f = np.array(front.target) - eye
    l_dir = np.array(left.target) - np.array(left.eye)
    # Turned 90° left in the rig frame: it looks along up × forward, as far.
    side = np.cross([0, 0, 1], f)
    assert np.allclose(l_dir, side / np.linalg.norm(side) * np.linalg.norm(f), atol=1e-6)
    assert np.allclose(left.eye, front.eye)


def test_shards_cover_the_range_and_skip_done_frames(tmp_path):
    job = dataset.load_job(write_job(tmp_path, frames="start = 1\nend = 8"))
    shards = dataset.make_shards(job)
    assert [s.frames for s in shards] == [(1, 2, 3, 4), (5, 6, 7)]
    assert [s.index for s in shards] == [0, 1]
    shards = dataset.make_shards(job, done={1, 2, 3, 4, 6})
    assert [(s.index, s.frames) for s in shards] == [(1, (5, 7))]


# --- rendering with a fake backend: resume, atomic outputs -------------------


class Interrupt(Exception):
    pass


def test_resume_renders_only_what_is_missing(tmp_path):
    job_path = write_job(tmp_path)
    os.makedirs(tmp_path / "ref")
    reference = dataset.render(write_job(tmp_path / "ref"), local=True, backend=FakeBackend, progress=False)
    assert reference.rendered == 8

    def stop_after_three(event):
        if event.done == 3:
            raise Interrupt

    with pytest.raises(Interrupt):
        dataset.render(job_path, local=True, backend=FakeBackend, progress=False, on_frame=stop_after_three)
    out = tmp_path / "out"
    # A crash mid-append: a torn manifest line, and a temporary file left behind.
    with open(out / "manifest.jsonl", "ab") as f:
        f.write(b'{"frame": 3, "fi')
    (out / "rgba8" / ".000003.png.tmp-ag-999").write_bytes(b"half")
    FakeBackend.renders = 0
    result = dataset.render(job_path, local=True, backend=FakeBackend, progress=False)
    assert (result.skipped, result.rendered, FakeBackend.renders) == (3, 5, 5)
    assert tree_bytes(out) == tree_bytes(tmp_path / "ref" / "out")
    lines = (out / "manifest.jsonl").read_bytes().split(b"\n")
    assert lines[-1] == b"" and all(json.loads(l) for l in lines[:-1])
    assert sorted(json.loads(l)["frame"] for l in lines[1:-1]) == list(range(8))

    # Everything done: a rerun renders nothing; a deleted file is rendered again.
    FakeBackend.renders = 0
    assert dataset.render(job_path, local=True, backend=FakeBackend, progress=False).rendered == 0
    os.unlink(out / "depth" / "000005.exr")
    result = dataset.render(job_path, local=True, backend=FakeBackend, progress=False)
    assert (result.rendered, FakeBackend.renders) == (1, 1)
    assert tree_bytes(out) == tree_bytes(tmp_path / "ref" / "out")


def test_a_folder_of_another_job_is_refused(tmp_path):
    dataset.render(write_job(tmp_path), local=True, backend=FakeBackend, progress=False)
    other = write_job(tmp_path, camera="width = 32\nheight = 40")
    with pytest.raises(JobError, match=r"output.dir: .* holds the frames of a different job") as info:
        dataset.render(other, local=True, backend=FakeBackend, progress=False)
    assert "\n" not in str(info.value)


# --- encoders ------------------------------------------------------------------


def test_encoders_round_trip():
    rng = np.random.default_rng(1)
    rgba = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    assert np.array_equal(encode.decode_png(encode.encode_png(rgba)), rgba)
    hdr = rng.standard_normal((5, 7, 4)).astype(np.float32)
    ch = encode.decode_exr(encode.encode_exr("hdr", hdr))
    assert np.array_equal(np.stack([ch[c] for c in "RGBA"], -1), hdr)
    depth = np.full((5, 7), np.inf, np.float32)
    assert np.array_equal(encode.decode_exr(encode.encode_exr("depth", depth))["Z"], depth)
    ids = rng.integers(0, 2**32, (5, 7), dtype=np.uint32)
    assert np.array_equal(encode.decode_exr(encode.encode_exr("instance", ids))["instance"], ids)
    assert encode.encode_png(rgba) == encode.encode_png(rgba.copy())  # deterministic bytes


def test_imports_and_renders_without_ray(tmp_path):
    job = write_job(tmp_path)
    missing = tmp_path / "out" / "rgba8" / "000000.png"
    code = (
        "import os, sys; sys.modules['ray'] = None\n"
        f"sys.path.insert(0, {PYTHON_DIR!r}); sys.path.insert(0, {os.path.dirname(__file__)!r})\n"
        "from alpenglow import dataset\n"
        "from test_dataset import FakeBackend\n"
        f"print(dataset.render({job!r}, local=True, backend=FakeBackend, progress=False).rendered)\n"
        f"print(dataset.render({job!r}, backend=FakeBackend, progress=False).rendered)\n"
        f"os.unlink({str(missing)!r})\n"
        "try:\n"
        f"    dataset.render({job!r}, backend=FakeBackend, progress=False)\n"
        "except RuntimeError as e:\n"
        "    print(e)\n"
    )
    # Ray is needed only when there is work for it, and then the error says how to get it.
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[:2] == ["8", "0"]
    assert lines[2].startswith("ray is not installed: pip install"), proc.stdout


def test_command_line_errors_are_one_line(tmp_path, capsys):
    from alpenglow.dataset.__main__ import main

    path = write_job(tmp_path, camera="width = 64\nheight = 0")
    assert main(["render", path, "--local"]) == 1
    err = capsys.readouterr().err
    assert err == "error: job.toml: camera.height: must be at least 1, got 0\n"
    with pytest.raises(SystemExit):
        main(["render", path, "--workers", "0"])
    assert "--workers: must be at least 1, got 0" in capsys.readouterr().err
