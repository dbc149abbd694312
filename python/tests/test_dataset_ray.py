"""A two-shard job on a local Ray cluster (lavapipe), with its workers killed mid-job.

Shard 1's actor is killed twice (SIGKILL of its process): the first time Ray
restarts it and retries its frames (``max_restarts``/``max_task_retries``);
the second time its restarts are used up and the runner re-queues the
shard's uncommitted frames on a new actor. Every frame still arrives, byte
for byte equal to a single-process render of the same job.
"""

from __future__ import annotations

import os
import signal
import time

import pytest

from _dataset_support import PYTHON_DIR, cli_binary, tree_bytes, write_job

ray = pytest.importorskip("ray", reason="the [ray] extra is not installed (pip install './python[ray]')")

from alpenglow import dataset  # noqa: E402
from alpenglow.dataset.backend import native_available  # noqa: E402


@pytest.fixture(scope="module")
def renderer_env():
    if native_available():
        yield "native"
        return
    binary = cli_binary()
    if binary is None:
        pytest.fail("neither the native module nor the alpenglow program (ALPENGLOW_BIN, target/debug) is built")
    old = os.environ.get("ALPENGLOW_BIN")
    os.environ["ALPENGLOW_BIN"] = binary
    yield "cli"
    if old is None:
        os.environ.pop("ALPENGLOW_BIN", None)
    else:
        os.environ["ALPENGLOW_BIN"] = old


JOB = dict(
    path="type = \"orbit\"\nframes = 6\ncenter = [1280.0, 1280.0, 0.0]\nradius = 1500.0\nheight = 800.0",
    output='dir = "out"\naovs = ["rgba8", "depth", "class"]\nformats = { class = "npy" }\nshard_size = 3',
    ray="workers = 2\nnum_cpus = 1\nnum_gpus = 0\nmax_restarts = 1\nmax_task_retries = 1",
)


def test_killed_workers_still_give_every_frame_byte_identical(tmp_path, renderer_env):
    started = time.monotonic()
    os.makedirs(tmp_path / "local")
    os.makedirs(tmp_path / "ray")
    local = dataset.render(write_job(tmp_path / "local", **JOB), local=True, backend=renderer_env, progress=False)
    assert local.rendered == 6
    local_seconds = time.monotonic() - started

    env = {"PYTHONPATH": os.pathsep.join(p for p in (PYTHON_DIR, os.environ.get("PYTHONPATH")) if p)}
    ray.init(num_cpus=2, include_dashboard=False, runtime_env={"env_vars": env}, log_to_driver=False)
    try:
        kills = []

        def kill_shard_1(event):
            # After shard 1's first frame, and again after its restarted actor's first frame.
            if event.shard == 1 and len(kills) < 2 and event.pid not in kills:
                kills.append(event.pid)
                os.kill(event.pid, signal.SIGKILL)

        job = write_job(tmp_path / "ray", **JOB)
        result = dataset.render(job, backend=renderer_env, on_frame=kill_shard_1)
    finally:
        ray.shutdown()
    print(f"backend {renderer_env}: local render {local_seconds:.1f} s, Ray render {result.seconds:.1f} s")
    assert len(kills) == 2
    assert result.rendered == 6 and result.skipped == 0
    assert result.shard_retries == 1  # the second kill: shard 1 re-queued on a new actor
    assert result.workers == 3
    ray_files, local_files = tree_bytes(tmp_path / "ray" / "out"), tree_bytes(tmp_path / "local" / "out")
    assert len(local_files) == 18
    assert sorted(ray_files) == sorted(local_files)
    assert [name for name in local_files if ray_files[name] != local_files[name]] == []
    # A rerun finds everything done (the manifest) and renders nothing, without Ray.
    again = dataset.render(job, local=True, backend=renderer_env, progress=False)
    assert (again.rendered, again.skipped) == (0, 6)
