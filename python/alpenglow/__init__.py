"""alpenglow: a Vulkan renderer for large outdoor scenes, from Python.

    import alpenglow as ag
    ctx = ag.Context(validation=False, device=None)
    scene = ag.Scene.procedural("ridged", seed=7, size=513, spacing=20.0)
    r = ag.Renderer(ctx, scene, width=640, height=360, terrain_detail=False)
    cam = ag.Camera.look_at(eye=(5000, -2000, 1500), target=(5000, 5000, 300))
    out = r.render(cam)          # dict of numpy arrays: rgba8, hdr, depth, ...
    ag.write_png("frame.png", out)
    ag.write_exr("frame.exr", out)

Invalid arguments raise ValueError naming the parameter; anything else the
library refuses raises alpenglow.Error with its one-line message.
See python/README.md.
"""

from ._alpenglow import (
    MAX_SETTLE_FRAMES,
    Camera,
    Context,
    Distortion,
    Error,
    Intrinsics,
    Lighting,
    Renderer,
    Rig,
    Scene,
    View,
    encode_exr,
    encode_png,
    write_exr,
    write_heightmap,
    write_pyramid,
    write_png,
)

__all__ = [
    "MAX_SETTLE_FRAMES",
    "Camera",
    "Context",
    "Distortion",
    "Error",
    "Intrinsics",
    "Lighting",
    "Renderer",
    "Rig",
    "Scene",
    "View",
    "encode_exr",
    "encode_png",
    "write_exr",
    "write_heightmap",
    "write_pyramid",
    "write_png",
]

__version__ = "0.1.0"
