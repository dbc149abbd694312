"""The Jacksboro example runs (two tiny frames, under validation) and writes
a PNG and an EXR per frame."""

import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "jacksboro_flight.py"


def test_the_jacksboro_flight_writes_png_and_exr_frames(tmp_path):
    run = subprocess.run(
        [sys.executable, str(EXAMPLE), "--frames", "2", "--width", "64", "--height", "36"]
        + ["--out", str(tmp_path), "--validation"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["frame0000.exr", "frame0000.png", "frame0001.exr", "frame0001.png"]
    assert "frame 1:" in run.stdout
