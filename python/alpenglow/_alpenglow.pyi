"""Type stubs of the native module alpenglow._alpenglow (python/src/*.rs)."""

from __future__ import annotations

import os
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

Vec3 = Union[Tuple[float, float, float], Sequence[float], npt.NDArray[np.floating]]
PathLike = Union[str, os.PathLike[str]]

Frame = Dict[str, np.ndarray]
"""One view's images: "rgba8" (H,W,4) uint8, "hdr" (H,W,4) float32, "depth" and
"distance" (H,W) float32 (inf where nothing was hit), "normal" (H,W,3),
"motion" (H,W,2), "visibility" (H,W,2) float32, "class" and "instance" (H,W)
uint32, and "weight" (H,W) float32 for scenes with points."""

MAX_SETTLE_FRAMES: int

class Error(Exception):
    """An error of the alpenglow library, with its one-line message."""

class Context:
    def __init__(self, validation: bool = False, device: Union[int, str, None] = None) -> None: ...
    @property
    def device_name(self) -> str: ...
    @property
    def validation(self) -> bool: ...
    @property
    def validation_messages(self) -> Optional[List[str]]: ...

class Scene:
    @staticmethod
    def from_heights(
        h: npt.NDArray[np.float32], spacing: Union[float, Tuple[float, float], None] = None
    ) -> Scene: ...
    @staticmethod
    def from_file(
        path: PathLike,
        spacing: Union[float, Tuple[float, float], None] = None,
        height_scale: float = 1.0,
        height_offset: float = 0.0,
        rows: str = "south-up",
        max_input_mb: int = 2048,
    ) -> Scene: ...
    @staticmethod
    def from_pyramid(path: PathLike, resident_side: int = 4096, detail_window: int = 1024) -> Scene: ...
    @staticmethod
    def procedural(model: str = "ridged", seed: int = 1, size: int = 513, spacing: float = 20.0) -> Scene: ...
    def add_rocks(self, count: int) -> None: ...
    def add_vegetation(self, density: float = 1.0, seed: int = 1) -> int: ...
    @property
    def heights(self) -> npt.NDArray[np.float32]: ...
    @property
    def spacing(self) -> Tuple[float, float]: ...
    @property
    def extent(self) -> Tuple[float, float]: ...
    @property
    def height_range(self) -> Tuple[float, float]: ...
    @property
    def point_instances(self) -> int: ...
    def ground_height(self, x: float, y: float) -> float: ...
    def default_camera(self) -> Camera: ...

class Camera:
    @staticmethod
    def look_at(
        eye: Vec3,
        target: Vec3,
        up: Optional[Vec3] = None,
        fov_y: float = 60.0,
        near: float = 1.0,
        far: float = 1e5,
    ) -> Camera: ...
    @staticmethod
    def from_pose(
        pose: Union[Sequence[Sequence[float]], npt.NDArray[np.floating]],
        fov_y: float = 60.0,
        near: float = 1.0,
        far: float = 1e5,
    ) -> Camera: ...
    @property
    def pose(self) -> npt.NDArray[np.float64]: ...
    @property
    def eye(self) -> Tuple[float, float, float]: ...
    @property
    def target(self) -> Tuple[float, float, float]: ...
    @property
    def up(self) -> Tuple[float, float, float]: ...
    @property
    def fov_y(self) -> float: ...
    @property
    def near(self) -> float: ...
    @property
    def far(self) -> float: ...

class Intrinsics:
    def __init__(self, fx: float, fy: float, cx: float, cy: float) -> None: ...
    @staticmethod
    def from_fov_y(fov_y: float, width: int, height: int) -> Intrinsics: ...
    @property
    def fx(self) -> float: ...
    @property
    def fy(self) -> float: ...
    @property
    def cx(self) -> float: ...
    @property
    def cy(self) -> float: ...

class Distortion:
    def __init__(
        self, k1: float = 0.0, k2: float = 0.0, k3: float = 0.0, p1: float = 0.0, p2: float = 0.0
    ) -> None: ...

class View:
    def __init__(
        self,
        name: str,
        *,
        position: Optional[Vec3] = None,
        yaw: float = 0.0,
        pitch: float = 0.0,
        roll: float = 0.0,
        fov_y: Optional[float] = None,
        intrinsics: Optional[Intrinsics] = None,
        distortion: Optional[Distortion] = None,
        width: Optional[int] = None,
        height: Optional[int] = None,
        near: Optional[float] = None,
        far: Optional[float] = None,
    ) -> None: ...
    @property
    def name(self) -> str: ...

class Rig:
    def __init__(self, views: List[View]) -> None: ...
    @staticmethod
    def ring6(width: int) -> Rig: ...
    @staticmethod
    def load(path: PathLike) -> Rig: ...
    @property
    def names(self) -> List[str]: ...
    def cameras(self, camera: Camera) -> List[Camera]: ...
    def __len__(self) -> int: ...

class Lighting:
    def __init__(
        self,
        *,
        sun_elevation: float = 25.0,
        sun_azimuth: float = 231.0,
        sky: str = "physical",
        turbidity: float = 3.0,
        exposure: Union[str, float, None] = None,
        shadows: str = "cascaded",
        sun_disc: str = "hard",
        sky_light: str = "sh",
        aerial_perspective: bool = True,
    ) -> None: ...
    def time_of_day(
        self, date: str, time: str, latitude: float, longitude: float, utc_offset: Optional[float] = None
    ) -> Lighting: ...
    @property
    def sun_direction(self) -> Tuple[float, float, float]: ...

FrameResult = Union[Frame, Dict[str, Frame]]
CameraArg = Union[Camera, List[Camera]]

class Renderer:
    def __init__(
        self,
        ctx: Context,
        scene: Scene,
        width: int = 640,
        height: int = 360,
        *,
        rig: Optional[Rig] = None,
        intrinsics: Optional[Intrinsics] = None,
        distortion: Optional[Distortion] = None,
        msaa: int = 1,
        terrain_detail: bool = True,
        grid: Optional[int] = None,
        texturing: str = "atlas",
        raster: str = "auto",
        lighting: Optional[Lighting] = None,
        cache_dir: Optional[PathLike] = None,
        readback_slots: Optional[int] = None,
    ) -> None: ...
    def render(self, camera: CameraArg) -> FrameResult: ...
    def submit(self, camera: CameraArg) -> int: ...
    def wait(self, ticket: int) -> FrameResult: ...
    def try_read(self, ticket: int) -> Optional[FrameResult]: ...
    def poll(self, ticket: int) -> Optional[FrameResult]: ...
    @property
    def lighting(self) -> Lighting: ...
    @lighting.setter
    def lighting(self, lighting: Lighting) -> None: ...
    @property
    def views(self) -> List[str]: ...
    @property
    def pass_names(self) -> List[str]: ...
    def finish(self) -> None: ...

def encode_png(image: Union[Frame, npt.NDArray[np.uint8]]) -> bytes: ...
def write_png(path: PathLike, image: Union[Frame, npt.NDArray[np.uint8]]) -> None: ...
def encode_exr(frame: Frame) -> bytes: ...
def write_exr(path: PathLike, frame: Frame) -> None: ...
def write_heightmap(path: PathLike, h: npt.NDArray[np.float32]) -> None: ...
def write_pyramid(
    path: PathLike,
    h: npt.NDArray[np.float32],
    spacing: Union[float, Tuple[float, float], None] = None,
    tile_side: int = 256,
    height_step: float = 0.00390625,
) -> int: ...
