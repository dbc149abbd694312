"""Flies a camera along the valley of the Jacksboro fault (the real DEM in
tests/data) and saves every frame as PNG and EXR.

    python python/examples/jacksboro_flight.py --frames 8 --out target/jacksboro

The frames are pipelined: frame N+1 is submitted before frame N is read and
written, so the GPU renders while Python writes files.
"""

import argparse
import pathlib

import numpy as np

import alpenglow as ag

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEM = ROOT / "tests" / "data" / "jacksboro-fault.png"
SPACING = (74.4, 92.6)  # metres between samples (tests/data/README.md)


def flight(frames):
    """Cameras along the valley, south-west to north-east, 300-750 m up."""
    start, end = np.array([13600.0, 9600.0]), np.array([18500.0, 21500.0])
    for k in range(frames):
        t = k / max(frames - 1, 1) * 0.6
        eye = start + (end - start) * t
        look = start + (end - start) * (t + 0.35)
        yield ag.Camera.look_at(
            eye=(eye[0], eye[1], 750.0 - 250.0 * t),
            target=(look[0], look[1], 350.0),
            fov_y=50.0,
            near=5.0,
            far=1e5,
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=180)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "target" / "jacksboro")
    parser.add_argument("--validation", action="store_true", help="Khronos validation layers")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    ctx = ag.Context(validation=args.validation)
    scene = ag.Scene.from_file(DEM, spacing=SPACING)
    lighting = ag.Lighting().time_of_day("2024-10-15", "16:30", latitude=36.4, longitude=-84.1)
    r = ag.Renderer(ctx, scene, width=args.width, height=args.height, lighting=lighting)
    print(f"{ctx.device_name}: {scene!r}")

    cameras = list(flight(args.frames))
    # The first frame settles the texture atlas; the rest stream.
    r.render(cameras[0])
    pending = None
    for k, camera in enumerate(cameras + [None]):
        ticket = r.submit(camera) if camera is not None else None
        if pending is not None:
            j, t = pending
            frame = r.wait(t)
            ag.write_png(args.out / f"frame{j:04}.png", frame)
            ag.write_exr(args.out / f"frame{j:04}.exr", frame)
            hit = np.isfinite(frame["depth"])
            print(f"frame {j}: {hit.mean():.0%} terrain, nearest {frame['distance'][hit].min():.0f} m")
        pending = (k, ticket) if ticket is not None else None
    if args.validation and ctx.validation_messages:
        raise SystemExit(f"validation messages: {ctx.validation_messages}")


if __name__ == "__main__":
    main()
