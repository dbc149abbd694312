"""Splits a job into shards and renders them, in this process or on a Ray cluster."""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import encode
from .job import Job, JobError, load_job
from .manifest import Manifest, remove_stale_temporaries


@dataclass(frozen=True)
class Shard:
    """Consecutive frames rendered by one worker, in order."""

    index: int
    frames: tuple[int, ...]


def make_shards(job: Job, done=()) -> list[Shard]:
    """Shards of `shard_size` consecutive frames; finished frames left out, empty shards dropped.

    Shard k always covers frames start + k·size ..< start + (k+1)·size, so a
    rerun keeps the shards of the first run.
    """
    done = set(done)
    shards = []
    for k, first in enumerate(range(job.start, job.end, job.shard_size)):
        frames = tuple(f for f in range(first, min(first + job.shard_size, job.end)) if f not in done)
        if frames:
            shards.append(Shard(k, frames))
    return shards


@dataclass(frozen=True)
class FrameEvent:
    """Handed to `on_frame` after each frame is committed."""

    frame: int
    shard: int
    worker: int
    pid: int
    done: int
    total: int


@dataclass
class Result:
    """What a call of :func:`render` did."""

    out_dir: str
    total: int
    rendered: int
    skipped: int
    seconds: float
    shard_retries: int = 0
    workers: int = 0
    failures: list[str] = field(default_factory=list)


class FrameWorker:
    """Holds one renderer (scene loaded and baked once) and renders whole frames.

    The same class runs in-process (``local=True``) and as a Ray actor, so a
    distributed render is byte-identical to a local one.
    """

    def __init__(self, job: Job, backend: str = "auto"):
        from .backend import open_backend

        self.job = job
        self.backend = open_backend(job, backend, _device())
        self.last_frame = None

    def pid(self) -> int:
        return os.getpid()

    def render_frame(self, frame: int) -> tuple[int, dict[str, bytes], int]:
        """(frame, {relative path: file bytes}, worker pid)."""
        job = self.job
        if "motion" in job.aovs and frame > 0 and self.last_frame != frame - 1:
            # Motion is measured from the previous frame: render it first so the
            # result does not depend on which worker rendered what before.
            for _, cam in job.cameras(frame - 1):
                self.backend.render(cam)
        images = {name: self.backend.render(cam) for name, cam in job.cameras(frame)}
        self.last_frame = frame
        files = {}
        for view, aov, rel in job.files(frame):
            array = images[view].get(aov)
            if array is None:
                raise RuntimeError(f"the renderer handed out no {aov!r} for frame {frame} (output.aovs)")
            fmt = job.formats[aov]
            if fmt == "png":
                files[rel] = encode.encode_png(np.asarray(array))
            elif fmt == "exr":
                files[rel] = encode.encode_exr(aov, np.asarray(array))
            else:
                files[rel] = encode.encode_npy(np.asarray(array))
        return frame, files, os.getpid()


def _device() -> str | None:
    """The Vulkan device of this worker: $ALPENGLOW_DEVICE, else the GPU Ray assigned.

    Vulkan does not read CUDA_VISIBLE_DEVICES, so a Ray actor holding GPU k
    would otherwise open device 0 like every other actor on its node; index k
    assumes Vulkan lists the node's GPUs in the same order as CUDA does (set
    ALPENGLOW_DEVICE on nodes where it does not).
    """
    device = os.environ.get("ALPENGLOW_DEVICE")
    if device:
        return device
    if "ray" not in sys.modules:
        return None
    try:
        import ray

        ids = ray.get_gpu_ids() if ray.is_initialized() else []
    except Exception:  # noqa: BLE001 - not in a Ray worker
        return None
    return str(int(ids[0])) if ids else None


class Progress:
    """Frames done / total and the rate, on one line per frame (stderr)."""

    def __init__(self, total: int, already: int, enabled: bool, stream=None):
        self.total, self.done, self.enabled = total, already, enabled
        self.stream = stream or sys.stderr
        self.started, self.rendered = time.monotonic(), 0

    def frame(self) -> None:
        self.done += 1
        self.rendered += 1
        if self.enabled:
            elapsed = max(time.monotonic() - self.started, 1e-9)
            rate = self.rendered / elapsed
            eta = (self.total - self.done) / rate if rate > 0 else float("inf")
            pct = 100.0 * self.done / self.total
            print(
                f"alpenglow.dataset: {self.done}/{self.total} frames ({pct:.0f}%), {rate:.2f} frames/s, ETA {eta:.0f} s",
                file=self.stream,
                flush=True,
            )

    def note(self, text: str) -> None:
        if self.enabled:
            print(f"alpenglow.dataset: {text}", file=self.stream, flush=True)


def render(
    job,
    address: str | None = None,
    *,
    local: bool = False,
    backend="auto",
    workers: int | None = None,
    progress: bool = True,
    on_frame: Callable[[FrameEvent], None] | None = None,
) -> Result:
    """Renders the frames of `job` (a path or a :class:`Job`) that are not done yet.

    `local=True` renders in this process with one renderer; otherwise on Ray:
    the cluster at `address` (``"auto"``, ``"ray://host:10001"``, ...), the
    one this process is already connected to, or a new local one. `workers`
    overrides ``ray.workers``; `on_frame` is called after each frame is
    committed (the tests use it to kill a worker mid-job).
    """
    if not isinstance(job, Job):
        job = load_job(job)
    manifest = Manifest(job)
    manifest.load()
    os.makedirs(job.out_dir, exist_ok=True)
    remove_stale_temporaries(job.out_dir)
    frames = job.frames()
    already = sum(1 for f in frames if f in manifest.done)
    shards = make_shards(job, manifest.done)
    report = Progress(len(frames), already, progress)
    result = Result(job.out_dir, len(frames), 0, already, 0.0)
    if already:
        report.note(f"{already} of {len(frames)} frames already done in {job.out_dir}; {len(frames) - already} to render")
    started = time.monotonic()
    manifest.open()
    try:
        if shards:
            if local:
                _render_local(job, shards, backend, manifest, report, result, on_frame)
            else:
                from .ray_runner import render_on_ray

                render_on_ray(job, shards, address, backend, workers, manifest, report, result, on_frame)
    finally:
        manifest.close()
    result.seconds = time.monotonic() - started
    report.note(f"{result.rendered} frames rendered in {result.seconds:.1f} s, {result.skipped} skipped ({job.out_dir})")
    return result


def _render_local(job, shards, backend, manifest, report, result, on_frame) -> None:
    worker = FrameWorker(job, backend)
    result.workers = 1
    for shard in shards:
        for frame in shard.frames:
            _, files, pid = worker.render_frame(frame)
            commit(job, manifest, report, result, on_frame, shard.index, 0, frame, files, pid)


def commit(job, manifest, report, result, on_frame, shard, worker, frame, files, pid) -> None:
    """Records one rendered frame (driver side)."""
    expected = {rel for _, _, rel in job.files(frame)}
    if set(files) != expected:
        raise RuntimeError(f"frame {frame}: a worker returned files {sorted(files)}, expected {sorted(expected)}")
    manifest.commit(frame, files)
    result.rendered += 1
    report.frame()
    if on_frame is not None:
        on_frame(FrameEvent(frame, shard, worker, pid, report.done, report.total))


__all__ = ["render", "make_shards", "Shard", "FrameEvent", "Result", "FrameWorker", "JobError"]
