"""Dataset jobs: a TOML file parsed into a validated :class:`Job`.

Every error is a :class:`JobError` (a ``ValueError``) with a one-line message
that names the file and the key, e.g. ``job.toml: camera.width: expected a
positive integer, got -3``. The format is documented in docs/EMBEDDING.md
(section *Datasets on Ray*).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from typing import Any

try:
    import tomllib
except ImportError:  # Python < 3.11: the same parser from PyPI
    import tomli as tomllib  # type: ignore[no-redef]

#: Every AOV a renderer hands out, and the formats each can be written in.
AOVS: dict[str, tuple[str, ...]] = {
    "rgba8": ("png", "npy"),
    "hdr": ("exr", "npy"),
    "depth": ("exr", "npy"),
    "distance": ("exr", "npy"),
    "normal": ("exr", "npy"),
    "class": ("exr", "npy"),
    "instance": ("exr", "npy"),
    "motion": ("exr", "npy"),
}
#: The format an AOV is written in when `output.formats` does not say.
DEFAULT_FORMAT = {a: f[0] for a, f in AOVS.items()}

_SECTIONS = ("scene", "camera", "render", "lighting", "path", "rig", "output", "frames", "ray")


class JobError(ValueError):
    """A job file that cannot be run; the message is one line naming the key."""


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


@dataclass(frozen=True)
class CameraSpec:
    """One view of one frame: a look-at camera (world metres, +Z up)."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float]
    fov_y: float
    near: float | None
    far: float | None
    intrinsics: tuple[float, float, float, float] | None = None


@dataclass(frozen=True)
class View:
    """A rig view: a pose in the rig frame (x forward, y left, z up)."""

    name: str
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_pitch_roll: tuple[float, float, float] = (0.0, 0.0, 0.0)
    fov_y: float | None = None


@dataclass
class Job:
    """A validated dataset job (see :func:`load_job`)."""

    source: str
    base_dir: str
    scene: dict[str, Any]
    camera: dict[str, Any]
    render: dict[str, Any]
    lighting: dict[str, Any]
    path: dict[str, Any]
    views: list[View]
    aovs: list[str]
    formats: dict[str, str]
    out_dir: str
    start: int
    end: int
    shard_size: int
    ray: dict[str, Any] = field(default_factory=dict)

    @property
    def width(self) -> int:
        return self.camera["width"]

    @property
    def height(self) -> int:
        return self.camera["height"]

    def frames(self) -> range:
        """The frames this job renders (`frames.start` ..< `frames.end`)."""
        return range(self.start, self.end)

    def fingerprint(self) -> str:
        """A hash of everything that decides the pixels and the file names.

        The frame range, shard size and cluster settings are left out: a
        rerun may extend the range or use another cluster and still resume.
        """
        content = {
            "scene": self.scene,
            "camera": self.camera,
            "render": self.render,
            "lighting": self.lighting,
            "path": self.path,
            "views": [v.__dict__ for v in self.views],
            "aovs": self.aovs,
            "formats": self.formats,
        }
        text = json.dumps(content, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def files(self, frame: int) -> list[tuple[str, str, str]]:
        """(view, aov, relative path) of every file of `frame`."""
        out = []
        for view in self.views:
            for aov in self.aovs:
                ext = self.formats[aov]
                rel = f"{aov}/{frame:06d}.{ext}"
                if len(self.views) > 1 or view.name != "camera":
                    rel = f"{view.name}/{rel}"
                out.append((view.name, aov, rel))
        return out

    def cameras(self, frame: int) -> list[tuple[str, CameraSpec]]:
        """(view name, camera) of every view of `frame`."""
        eye, target, up = path_pose(self.path, frame)
        return [(v.name, view_camera(self.camera, v, eye, target, up)) for v in self.views]


class _Reader:
    """Typed access to a TOML table with errors naming `prefix.key`."""

    def __init__(self, source: str, table: dict[str, Any], prefix: str):
        self.source, self.table, self.prefix = source, table, prefix
        self.used: set[str] = set()

    def fail(self, key: str, what: str) -> JobError:
        name = f"{self.prefix}.{key}" if self.prefix else key
        return JobError(_one_line(f"{self.source}: {name}: {what}"))

    def get(self, key: str, default: Any = None) -> Any:
        self.used.add(key)
        return self.table.get(key, default)

    def number(self, key, default=None, *, positive=False, minimum=None, required=False):
        value = self.get(key, default)
        if value is None:
            if required:
                raise self.fail(key, "is required")
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.fail(key, f"expected a finite number, got {value!r}")
        if positive and value <= 0:
            raise self.fail(key, f"must be positive, got {value!r}")
        if minimum is not None and value < minimum:
            raise self.fail(key, f"must be at least {minimum}, got {value!r}")
        return float(value)

    def integer(self, key, default=None, *, minimum=None, required=False):
        value = self.get(key, default)
        if value is None:
            if required:
                raise self.fail(key, "is required")
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"expected an integer, got {value!r}")
        if minimum is not None and value < minimum:
            raise self.fail(key, f"must be at least {minimum}, got {value!r}")
        return value

    def vector(self, key, n, default=None, *, required=False):
        value = self.get(key, default)
        if value is None:
            if required:
                raise self.fail(key, "is required")
            return None
        ok = isinstance(value, (list, tuple)) and len(value) == n
        ok = ok and all(not isinstance(x, bool) and isinstance(x, (int, float)) and math.isfinite(x) for x in value)
        if not ok:
            raise self.fail(key, f"expected {n} finite numbers [..], got {value!r}")
        return tuple(float(x) for x in value)

    def string(self, key, default=None, *, choices=None, required=False):
        value = self.get(key, default)
        if value is None:
            if required:
                raise self.fail(key, "is required")
            return None
        if not isinstance(value, str) or not value:
            raise self.fail(key, f"expected a non-empty string, got {value!r}")
        if choices is not None and value not in choices:
            raise self.fail(key, f"{value!r} is not one of {', '.join(choices)}")
        return value

    def table_of(self, key) -> dict[str, Any]:
        value = self.get(key, {})
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table, got {value!r}")
        return value

    def finish(self) -> None:
        """Unknown keys are errors (a typo must not be silently ignored)."""
        for key in self.table:
            if key not in self.used:
                raise self.fail(key, "unknown key")


def _scene(r: _Reader, base_dir: str) -> dict[str, Any]:
    heightmap = r.string("heightmap")
    procedural = r.string("procedural")
    if (heightmap is None) == (procedural is None):
        raise r.fail("heightmap", "give exactly one of scene.heightmap (a file) or scene.procedural (a model name)")
    options = {}
    for key, value in r.table.items():
        if key in ("heightmap", "procedural"):
            continue
        r.get(key)
        if not isinstance(value, (bool, int, float, str)) and not (
            isinstance(value, list) and all(isinstance(x, (int, float)) for x in value)
        ):
            raise r.fail(key, f"expected a number, string, boolean or list of numbers, got {value!r}")
        if isinstance(value, float) and not math.isfinite(value):
            raise r.fail(key, f"expected a finite number, got {value!r}")
        options[key] = value
    scene: dict[str, Any] = {"options": options}
    if heightmap is not None:
        path = heightmap if os.path.isabs(heightmap) else os.path.join(base_dir, heightmap)
        if not os.path.isfile(path):
            raise r.fail("heightmap", f"no such file: {path}")
        scene["heightmap"] = os.path.abspath(path)
    else:
        scene["procedural"] = procedural
    return scene


def _camera(r: _Reader) -> dict[str, Any]:
    cam: dict[str, Any] = {
        "width": r.integer("width", required=True, minimum=1),
        "height": r.integer("height", required=True, minimum=1),
        "fov_y": r.number("fov_y", 50.0, positive=True),
        "near": r.number("near", positive=True),
        "far": r.number("far", positive=True),
        "intrinsics": r.vector("intrinsics", 4),
    }
    if cam["fov_y"] >= 180:
        raise r.fail("fov_y", f"must be below 180 degrees, got {cam['fov_y']!r}")
    if cam["near"] is not None and cam["far"] is not None and cam["far"] <= cam["near"]:
        raise r.fail("far", f"must be beyond camera.near ({cam['near']!r}), got {cam['far']!r}")
    return cam


def _keywords(r: _Reader) -> dict[str, Any]:
    """A table of keyword settings handed to the renderer as they are (numbers, strings, booleans)."""
    out = {}
    for key, value in r.table.items():
        r.get(key)
        if isinstance(value, float) and not math.isfinite(value):
            raise r.fail(key, f"expected a finite number, got {value!r}")
        if not isinstance(value, (bool, int, float, str)):
            raise r.fail(key, f"expected a number, string or boolean, got {value!r}")
        out[key] = value
    return out


def _path(r: _Reader) -> dict[str, Any]:
    kind = r.string("type", required=True, choices=("orbit", "keyframes"))
    frames = r.integer("frames", required=True, minimum=1)
    up = r.vector("up", 3, (0.0, 0.0, 1.0))
    if not any(up):
        raise r.fail("up", "must not be the zero vector")
    path: dict[str, Any] = {"type": kind, "frames": frames, "up": up}
    if kind == "orbit":
        path["center"] = r.vector("center", 3, required=True)
        path["radius"] = r.number("radius", required=True, positive=True)
        path["height"] = r.number("height", 0.0)
        path["start_deg"] = r.number("start_deg", 0.0)
        path["degrees"] = r.number("degrees", 360.0)
    else:
        keys = r.get("key")
        if not isinstance(keys, list) or not keys:
            raise r.fail("key", "expected one or more [[path.key]] tables (frame, eye, target)")
        parsed = []
        for k, table in enumerate(keys):
            if not isinstance(table, dict):
                raise r.fail(f"key[{k}]", f"expected a table, got {table!r}")
            kr = _Reader(r.source, table, f"path.key[{k}]")
            entry = {
                "frame": kr.integer("frame", required=True, minimum=0),
                "eye": kr.vector("eye", 3, required=True),
                "target": kr.vector("target", 3, required=True),
            }
            kr.finish()
            if entry["eye"] == entry["target"]:
                raise kr.fail("target", "must differ from eye")
            if parsed and entry["frame"] <= parsed[-1]["frame"]:
                raise kr.fail("frame", f"must increase from key to key, got {entry['frame']} after {parsed[-1]['frame']}")
            parsed.append(entry)
        path["keys"] = parsed
    return path


def _views(r: _Reader) -> list[View]:
    tables = r.get("view")
    if tables is None:
        return [View("camera")]
    if not isinstance(tables, list) or not tables:
        raise r.fail("view", "expected one or more [[rig.view]] tables")
    views, names = [], set()
    for k, table in enumerate(tables):
        if not isinstance(table, dict):
            raise r.fail(f"view[{k}]", f"expected a table, got {table!r}")
        vr = _Reader(r.source, table, f"rig.view[{k}]")
        name = vr.string("name", required=True)
        if not name.replace("_", "").replace("-", "").isalnum():
            raise vr.fail("name", f"{name!r}: use letters, digits, '_' and '-' (it names a folder)")
        if name in names:
            raise vr.fail("name", f"{name!r} is used twice")
        names.add(name)
        fov = vr.number("fov_y", positive=True)
        if fov is not None and fov >= 180:
            raise vr.fail("fov_y", f"must be below 180 degrees, got {fov!r}")
        views.append(
            View(
                name,
                vr.vector("position", 3, (0.0, 0.0, 0.0)),
                vr.vector("yaw_pitch_roll", 3, (0.0, 0.0, 0.0)),
                fov,
            )
        )
        vr.finish()
    return views


def _output(r: _Reader, base_dir: str) -> tuple[str, list[str], dict[str, str]]:
    out_dir = r.string("dir", required=True)
    if not os.path.isabs(out_dir):
        out_dir = os.path.join(base_dir, out_dir)
    aovs = r.get("aovs", ["rgba8"])
    if not isinstance(aovs, list) or not aovs or not all(isinstance(a, str) for a in aovs):
        raise r.fail("aovs", f"expected a list of AOV names ({', '.join(AOVS)}), got {aovs!r}")
    for a in aovs:
        if a not in AOVS:
            raise r.fail("aovs", f"unknown AOV {a!r} (one of {', '.join(AOVS)})")
    if len(set(aovs)) != len(aovs):
        raise r.fail("aovs", f"lists an AOV twice: {aovs!r}")
    formats_table = r.table_of("formats")
    formats = {}
    for a in aovs:
        fmt = formats_table.get(a, DEFAULT_FORMAT[a])
        if fmt not in AOVS[a]:
            raise r.fail(f"formats.{a}", f"{fmt!r} cannot hold {a} (use {' or '.join(AOVS[a])})")
        formats[a] = fmt
    for a in formats_table:
        if a not in aovs:
            raise r.fail(f"formats.{a}", "names an AOV that output.aovs does not list")
    return os.path.abspath(out_dir), list(aovs), formats


def parse_job(data: dict[str, Any], source: str = "<job>", base_dir: str = ".") -> Job:
    """Validates a parsed TOML document (see :func:`load_job`)."""
    top = _Reader(source, data, "")
    for key in data:
        if key not in _SECTIONS:
            raise top.fail(key, f"unknown section (one of {', '.join(_SECTIONS)})")
    sections = {}
    for key in _SECTIONS:
        value = data.get(key, {})
        if not isinstance(value, dict):
            raise top.fail(key, f"expected a table [{key}], got {value!r}")
        sections[key] = _Reader(source, value, key)
    for key in ("scene", "camera", "path", "output"):
        if key not in data:
            raise top.fail(key, f"the [{key}] table is required")
    scene = _scene(sections["scene"], base_dir)
    camera = _camera(sections["camera"])
    render = _keywords(sections["render"])
    lighting = _keywords(sections["lighting"])
    path = _path(sections["path"])
    views = _views(sections["rig"])
    out_dir, aovs, formats = _output(sections["output"], base_dir)
    if "motion" in aovs and len(views) > 1:
        # Views are rendered one after the other: motion would be measured from
        # the previous view's camera, not from the same view's previous frame.
        raise sections["output"].fail("aovs", "motion with several rig views is not supported yet (render one view per job)")
    fr, oc = sections["frames"], sections["output"]
    start = fr.integer("start", 0, minimum=0)
    end = fr.integer("end", path["frames"], minimum=1)
    if end > path["frames"]:
        raise fr.fail("end", f"beyond the path's {path['frames']} frames, got {end}")
    if start >= end:
        raise fr.fail("start", f"must be below frames.end ({end}), got {start}")
    shard_size = oc.integer("shard_size", 16, minimum=1)
    rr = sections["ray"]
    ray = {
        "workers": rr.integer("workers", minimum=1),
        "num_gpus": rr.number("num_gpus", 0.0, minimum=0.0),
        "num_cpus": rr.number("num_cpus", 1.0, minimum=0.0),
        "max_restarts": rr.integer("max_restarts", 2, minimum=0),
        "max_task_retries": rr.integer("max_task_retries", 2, minimum=0),
        "max_shard_attempts": rr.integer("max_shard_attempts", 3, minimum=1),
    }
    for reader in sections.values():
        if reader.prefix != "scene":
            reader.finish()
    return Job(source, base_dir, scene, camera, render, lighting, path, views, aovs, formats, out_dir, start, end, shard_size, ray)


def load_job(path: str | os.PathLike) -> Job:
    """Reads and validates a job file; relative paths are taken from its folder."""
    path = os.fspath(path)
    name = os.path.basename(path) or path
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as e:
        raise JobError(_one_line(f"{path}: cannot read the job file: {e.strerror or e}")) from None
    except tomllib.TOMLDecodeError as e:
        raise JobError(_one_line(f"{name}: not valid TOML: {e}")) from None
    return parse_job(data, name, os.path.dirname(os.path.abspath(path)))


# --- camera path and rig -------------------------------------------------


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def _scale(a, s):
    return tuple(x * s for x in a)


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a):
    length = math.sqrt(sum(x * x for x in a))
    return tuple(x / length for x in a) if length > 0 else a


def path_pose(path: dict[str, Any], frame: int):
    """(eye, target, up) of the path at `frame`.

    Orbit: the eye circles `center` at `radius`, `height` above it, starting at
    `start_deg` (0 = +X, counter-clockwise) and sweeping `degrees` over the
    path's `frames` (frame k at start + degrees·k/frames, so a 360° orbit does
    not repeat its first frame). Keyframes: eye and target interpolated
    linearly between the keys' frames, held before the first and after the last.
    """
    up = path["up"]
    if path["type"] == "orbit":
        angle = math.radians(path["start_deg"] + path["degrees"] * frame / path["frames"])
        c = path["center"]
        eye = (c[0] + path["radius"] * math.cos(angle), c[1] + path["radius"] * math.sin(angle), c[2] + path["height"])
        return eye, c, up
    keys = path["keys"]
    if frame <= keys[0]["frame"]:
        return keys[0]["eye"], keys[0]["target"], up
    for a, b in zip(keys, keys[1:]):
        if frame <= b["frame"]:
            t = (frame - a["frame"]) / (b["frame"] - a["frame"])
            lerp = lambda p, q: tuple(x + (y - x) * t for x, y in zip(p, q))  # noqa: E731
            return lerp(a["eye"], b["eye"]), lerp(a["target"], b["target"]), up
    return keys[-1]["eye"], keys[-1]["target"], up


def view_camera(camera: dict[str, Any], view: View, eye, target, up) -> CameraSpec:
    """The camera of `view` on a rig posed at (eye, target, up).

    The rig frame is x forward (towards the target), y left, z up, like the
    CLI's rig files; yaw turns left, pitch up, roll turns the camera's right
    side down (clockwise seen from behind).
    """
    fwd = _norm(_sub(target, eye))
    left = _norm(_cross(up, fwd))
    top = _cross(fwd, left)
    px, py, pz = view.position
    yaw, pitch, roll = (math.radians(a) for a in view.yaw_pitch_roll)
    if not any(view.position) and not any(view.yaw_pitch_roll):
        v_eye, v_target, v_up = eye, target, up
    else:
        v_eye = _add(eye, _add(_scale(fwd, px), _add(_scale(left, py), _scale(top, pz))))
        # Direction in the rig frame after yaw (about z) then pitch (about the new y).
        d = (math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw), math.sin(pitch))
        u = (-math.sin(pitch) * math.cos(yaw), -math.sin(pitch) * math.sin(yaw), math.cos(pitch))
        side = _cross(u, d)  # the view's left
        u = _sub(_scale(u, math.cos(roll)), _scale(side, math.sin(roll)))
        to_world = lambda a: _add(_scale(fwd, a[0]), _add(_scale(left, a[1]), _scale(top, a[2])))  # noqa: E731
        dist = math.sqrt(sum(x * x for x in _sub(target, eye)))
        v_target = _add(v_eye, _scale(to_world(d), dist))
        v_up = to_world(u)
    return CameraSpec(
        tuple(v_eye),
        tuple(v_target),
        tuple(v_up),
        view.fov_y if view.fov_y is not None else camera["fov_y"],
        camera["near"],
        camera["far"],
        camera["intrinsics"],
    )
