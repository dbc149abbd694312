"""Shared helpers of the dataset tests (not a test module)."""

from __future__ import annotations

import os
import shutil
import sys
import textwrap

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPO = os.path.dirname(PYTHON_DIR)

try:  # the installed package, or this checkout's python/ folder
    import alpenglow.dataset  # noqa: F401
except ImportError:
    sys.path.insert(0, PYTHON_DIR)


def write_job(folder, **sections) -> str:
    """A small job file in `folder`; `sections` replace whole tables (TOML text)."""
    tables = {
        "scene": 'procedural = "ridged"\nseed = 7\nsize = 129\nspacing = 20.0',
        "render": "grid = 64",
        "camera": "width = 64\nheight = 40\nfov_y = 50.0",
        "path": "type = \"orbit\"\nframes = 8\ncenter = [1280.0, 1280.0, 0.0]\nradius = 1500.0\nheight = 800.0",
        "output": 'dir = "out"\naovs = ["rgba8", "depth", "class"]\nformats = { class = "npy" }\nshard_size = 4',
    }
    tables.update(sections)
    text = "\n\n".join(f"[{name}]\n{textwrap.dedent(body).strip()}" for name, body in tables.items() if body is not None)
    path = os.path.join(folder, "job.toml")
    with open(path, "w") as f:
        f.write(text + "\n")
    return path


def cli_binary() -> str | None:
    """The alpenglow program the CLI backend runs, when the native module is not built."""
    candidates = [os.environ.get("ALPENGLOW_BIN")]
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(REPO, "target")
    candidates += [os.path.join(target, p, "alpenglow") for p in ("release", "debug")]
    candidates.append(shutil.which("alpenglow"))
    return next((c for c in candidates if c and os.path.isfile(c)), None)


def tree_bytes(folder) -> dict[str, bytes]:
    """Every output file under `folder` (the manifest left out) by relative path."""
    out = {}
    for root, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, folder)
            if rel != "manifest.jsonl":
                with open(path, "rb") as f:
                    out[rel] = f.read()
    return out
