"""The one place the dataset runner touches a renderer.

Two backends render a :class:`~alpenglow.dataset.job.CameraSpec` into a dict
of numpy arrays named like the Python API's frames (``rgba8`` (H,W,4) uint8,
``hdr`` (H,W,4) float32, ``depth``, ``distance``, ``normal`` (H,W,3),
``class``/``instance`` uint32, ``motion`` (H,W,2)):

* ``native``: the ``alpenglow`` Python package (pyo3): one ``Renderer`` per
  worker, the scene loaded and baked once.
* ``cli``: the ``alpenglow`` command-line program (``$ALPENGLOW_BIN`` or on
  ``PATH``), one ``alpenglow render`` process per view and frame. Slower (the
  scene is loaded for every frame) but needs only the binary; used when the
  native module is not built.

``auto`` picks ``native`` when ``alpenglow.Renderer`` exists, else ``cli``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from typing import Any

import numpy as np

from . import encode
from .job import CameraSpec, Job, JobError

#: Keys of `scene` that go into the CLI's `--terrain procedural:MODEL,k=v`.
_PROCEDURAL_KEYS = ("seed", "octaves", "lacunarity", "h", "offset", "gain", "wavelength", "amplitude", "size", "spacing")


def native_available() -> bool:
    try:
        import alpenglow  # noqa: F401
    except ImportError:
        return False
    return all(hasattr(alpenglow, n) for n in ("Context", "Scene", "Renderer", "Camera"))


def open_backend(job: Job, kind="auto", device: str | None = None):
    """A renderer for `job`: `kind` is auto, native, cli, or a callable(job) returning
    an object with ``render(CameraSpec) -> dict of arrays`` (tests use a fake);
    `device`: a Vulkan device index or name substring (None: the default one)."""
    if callable(kind):
        return kind(job)
    if kind == "auto":
        kind = "native" if native_available() else "cli"
    if kind == "native":
        return NativeBackend(job, device)
    if kind == "cli":
        return CliBackend(job, device)
    raise ValueError(f"backend: {kind!r} is not one of auto, native, cli")


class NativeBackend:
    """The Python API of issue 26: Context, Scene, Renderer, Camera.look_at."""

    def __init__(self, job: Job, device: str | None = None):
        import alpenglow as ag

        self.ag = ag
        self.job = job
        if device is not None and device.isdigit():
            device = int(device)
        self.ctx = ag.Context(validation=False, device=device)
        options = dict(job.scene["options"])
        try:
            if "heightmap" in job.scene:
                self.scene = ag.Scene.from_file(job.scene["heightmap"], **options)
            else:
                self.scene = ag.Scene.procedural(job.scene["procedural"], **options)
        except (TypeError, ValueError) as e:
            raise JobError(f"{job.source}: scene: {e}") from None
        settings = dict(job.render)
        try:
            if job.lighting:
                settings["lighting"] = ag.Lighting(**job.lighting)
        except (TypeError, ValueError) as e:
            raise JobError(f"{job.source}: lighting: {e}") from None
        if job.camera["intrinsics"] is not None:
            settings["intrinsics"] = ag.Intrinsics(*job.camera["intrinsics"])
        try:
            self.renderer = ag.Renderer(self.ctx, self.scene, width=job.width, height=job.height, **settings)
        except (TypeError, ValueError) as e:
            raise JobError(f"{job.source}: render: {e}") from None

    def render(self, cam: CameraSpec) -> dict[str, np.ndarray]:
        kw: dict[str, Any] = dict(eye=cam.eye, target=cam.target, up=cam.up, fov_y=cam.fov_y)
        if cam.near is not None:
            kw["near"] = cam.near
        if cam.far is not None:
            kw["far"] = cam.far
        camera = self.ag.Camera.look_at(**kw)
        return self.renderer.render(camera)


def _flag(key: str, value: Any) -> list[str]:
    name = "--" + key.replace("_", "-")
    if isinstance(value, bool):
        return [name] if value else ["--no-" + key.replace("_", "-")]
    if isinstance(value, list):
        return [name, ",".join(repr(float(x)) if isinstance(x, float) else str(x) for x in value)]
    return [name, repr(value) if isinstance(value, float) else str(value)]


def _vec(v) -> str:
    return ",".join(repr(float(x)) for x in v)


class CliBackend:
    """``alpenglow render`` per view and frame; the job's keywords become its options.

    `scene` keys become options (``height_scale = 2`` → ``--height-scale 2``,
    ``terrain_detail = false`` → ``--no-terrain-detail``); with
    ``procedural``, the model's keys (seed, size, spacing, ...) go into
    ``--terrain procedural:MODEL,key=value``. `render` and `lighting` keys
    likewise (``grid = 64`` → ``--grid 64``).
    """

    def __init__(self, job: Job, device: str | None = None):
        self.job = job
        self.env = dict(os.environ, ALPENGLOW_DEVICE=device) if device is not None else None
        binary = os.environ.get("ALPENGLOW_BIN") or shutil.which("alpenglow")
        if not binary or not os.path.isfile(binary):
            raise RuntimeError(
                "backend cli: no alpenglow program (set ALPENGLOW_BIN or put it on PATH), and the native module is not built"
            )
        self.binary = binary
        args: list[str] = []
        options = dict(job.scene["options"])
        if "heightmap" in job.scene:
            args += ["--heightmap", job.scene["heightmap"]]
        else:
            parts = [f"procedural:{job.scene['procedural']}"]
            for key in _PROCEDURAL_KEYS:
                if key in options:
                    value = options.pop(key)
                    if isinstance(value, list):
                        value = ":".join(str(x) for x in value)
                    parts.append(f"{key}={value}")
            args += ["--terrain", ",".join(parts)]
        for key, value in sorted(options.items()):
            args += _flag(key, value)
        for key, value in sorted({**job.render, **job.lighting}.items()):
            args += _flag(key, value)
        self.args = args
        self.need_exr = any(a != "rgba8" for a in job.aovs)

    def render(self, cam: CameraSpec) -> dict[str, np.ndarray]:
        with tempfile.TemporaryDirectory(prefix="ag-dataset-") as tmp:
            png, exr = os.path.join(tmp, "f.png"), os.path.join(tmp, "f.exr")
            cmd = [self.binary, "render", *self.args, "--width", str(self.job.width), "--height", str(self.job.height)]
            cmd += ["--eye", _vec(cam.eye), "--target", _vec(cam.target), "--up", _vec(cam.up)]
            if cam.intrinsics is not None:
                cmd += ["--intrinsics", _vec(cam.intrinsics)]
            else:
                cmd += ["--fov-y", repr(float(cam.fov_y))]
            if cam.near is not None:
                cmd += ["--near", repr(float(cam.near))]
            if cam.far is not None:
                cmd += ["--far", repr(float(cam.far))]
            cmd += ["--out", png]
            if self.need_exr:
                cmd += ["--exr", exr]
            proc = subprocess.run(cmd, capture_output=True, text=True, env=self.env)
            if proc.returncode != 0:
                lines = [l for l in proc.stderr.splitlines() if l.strip()] or [f"exit status {proc.returncode}"]
                raise RuntimeError(f"alpenglow render: {lines[-1]}")
            with open(png, "rb") as f:
                out = {"rgba8": encode.decode_png(f.read())}
            if self.need_exr:
                with open(exr, "rb") as f:
                    ch = encode.decode_exr(f.read())
                for aov, names in encode.EXR_CHANNELS.items():
                    if all(n in ch for n in names):
                        planes = [ch[n] for n in names]
                        out[aov] = planes[0] if len(planes) == 1 else np.stack(planes, axis=-1)
            return out
