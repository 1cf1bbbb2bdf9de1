"""Type stubs of the extension module (re-exported by `kantele`)."""

import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
OutputName = Literal["color", "color_linear", "depth", "ray_depth", "normals", "ids"]
Backend = Literal["cpu", "gl"]

MAX_SIZE: int
"""Largest image side in pixels."""
OUTPUTS: List[str]
"""Every output name `render` knows."""

Shading = Literal["auto", "lambert", "pbr"]
Tonemap = Literal["none", "pbr-neutral", "aces"]
Cull = Literal["back", "front", "none"]

def load(
    path: PathLike,
    shading: Shading = "auto",
    environment: Optional[PathLike] = None,
    environment_intensity: float = 1.0,
    environment_rotation: float = 0.0,
    exposure: float = 0.0,
    tonemap: Tonemap = "pbr-neutral",
    *,
    scene: Union[int, str, None] = None,
    variant: Optional[str] = None,
    animation: Union[int, str, None] = None,
    time: float = 0.0,
    cull: Optional[Cull] = None,
) -> Scene:
    """Loads a glTF 2.0 (`.gltf`, `.glb`), OBJ, PLY or STL file. `FileNotFoundError`/`OSError`
    when it cannot be read, `ValueError` when it is malformed. `shading`: `auto` (glTF reference
    scenes and OBJ, PLY and STL files Lambert, other glTF files PBR), `lambert` or `pbr`; for
    PBR, `environment` (`"studio"`, `"none"` or an .hdr / .exr file; default: the studio when
    the file has no lights), `environment_intensity`, `environment_rotation` (degrees about
    +Y), `exposure` (stops) and `tonemap`, as the `kantele` command's options. Of a glTF
    file, `scene` (index or name) picks the scene, `variant` a material variant
    (KHR_materials_variants), `animation` (index or name) and `time` (seconds) the pose
    (without `animation`: the rest pose, skins applied); `cull` overrides every material's face
    culling (default: glTF by `doubleSided`, OBJ, PLY and STL two-sided)."""

def write_png(path: PathLike, image: npt.NDArray[np.uint8]) -> None:
    """Writes a `uint8` (H, W, 4) or (H, W, 3) image, row 0 at the top, as PNG."""

def _run_cli(args: List[str]) -> int:
    """Runs the `kantele` command on `args` (its name first) and returns its exit status; the
    package's `kantele` console script and `python -m kantele` call it."""

def isa() -> str:
    """The instruction set the CPU renderer uses in this process (`avx512`, `avx2`, `sse41`,
    `sse2`, `neon` or `scalar`): the best this CPU has, or the one `KANTELE_ISA` names. A
    `KANTELE_ISA` naming no level, or one this CPU lacks, gives a `RuntimeWarning` at import and
    the best level."""

class Camera:
    """A camera (conventions of `kantele_output::pose`, as the CLI's sidecar): the OpenGL camera
    frame looks down -Z with y up, the OpenCV frame down +Z with y down; intrinsics in pixels
    with the top-left pixel's centre at (0, 0); matrices row-major, points as columns. A camera
    may be tied to an image size (pinhole cameras always are)."""

    @staticmethod
    def look_at(
        eye: Sequence[float],
        target: Sequence[float],
        up: Sequence[float] = (0.0, 1.0, 0.0),
        yfov: float = 0.8,
        size: Optional[Tuple[int, int]] = None,
        znear: Optional[float] = None,
        zfar: Optional[float] = None,
    ) -> Camera:
        """Perspective camera at `eye` looking at `target`; `yfov` in radians; depth range
        [0.01*|eye-target|, inf) unless given."""
    @staticmethod
    def from_opencv(
        fx: float,
        fy: float,
        cx: float,
        cy: float,
        world_to_camera: npt.ArrayLike,
        size: Tuple[int, int],
        znear: float = 0.01,
        zfar: Optional[float] = None,
    ) -> Camera:
        """Pinhole camera from OpenCV intrinsics and a (4, 4) or (3, 4) OpenCV world-to-camera
        matrix, for images of `size` = (width, height)."""
    @staticmethod
    def from_opengl(
        world_to_camera: npt.ArrayLike,
        yfov: float = 0.8,
        size: Optional[Tuple[int, int]] = None,
        znear: float = 0.01,
        zfar: Optional[float] = None,
    ) -> Camera:
        """Perspective camera from an OpenGL world-to-camera (view) matrix."""
    @staticmethod
    def read_views(path: PathLike, size: Optional[Tuple[int, int]] = None) -> List[Camera]:
        """Cameras of a view file: `kantele render` sidecars, `to_dict()` output, or pose
        records (see `kantele render --views`)."""
    def with_depth_range(self, znear: float, zfar: Optional[float] = None) -> Camera: ...
    @property
    def size(self) -> Optional[Tuple[int, int]]:
        """The image size the camera was made for, or None."""
    @property
    def world_to_camera_gl(self) -> npt.NDArray[np.float32]:
        """4x4 world -> camera, OpenGL frame (x right, y up, looking down -z)."""
    @property
    def world_to_camera_opencv(self) -> npt.NDArray[np.float32]:
        """4x4 world -> camera, OpenCV frame (x right, y down, looking down +z)."""
    @property
    def eye(self) -> Tuple[float, float, float]: ...
    @property
    def yfov(self) -> Optional[float]: ...
    @property
    def znear(self) -> float: ...
    @property
    def zfar(self) -> Optional[float]: ...
    def intrinsics(
        self, size: Optional[Tuple[int, int]] = None
    ) -> Tuple[float, float, float, float]:
        """(fx, fy, cx, cy) in pixels for images of `size` (default: the camera's size)."""
    def projection(self, size: Optional[Tuple[int, int]] = None) -> npt.NDArray[np.float32]:
        """4x4 OpenGL projection (eye -> clip) for images of `size`."""
    def to_dict(self, size: Optional[Tuple[int, int]] = None) -> Dict[str, Any]:
        """{"camera": {...}, "world_to_camera_gl": rows, "world_to_camera_opencv": rows}, the
        layout of a `kantele render` sidecar."""

class Scene:
    """A scene ready to render."""

    @staticmethod
    def load(
        path: PathLike,
        shading: Shading = "auto",
        environment: Optional[PathLike] = None,
        environment_intensity: float = 1.0,
        environment_rotation: float = 0.0,
        exposure: float = 0.0,
        tonemap: Tonemap = "pbr-neutral",
        *,
        scene: Union[int, str, None] = None,
        variant: Optional[str] = None,
        animation: Union[int, str, None] = None,
        time: float = 0.0,
        cull: Optional[Cull] = None,
    ) -> Scene:
        """Same as `kantele.load`."""
    def at_time(self, time: float) -> Scene:
        """This scene posed at `time` seconds of the animation it was loaded with, as loading
        at that time would give, without reading the file again. `ValueError` for a scene
        loaded without an animation."""
    @property
    def animation(self) -> Optional[Tuple[int, str, Tuple[float, float]]]:
        """The animation the scene was loaded with: (index, name, (first, last key time)), or
        None."""
    @staticmethod
    def from_arrays(
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        normals: Optional[npt.ArrayLike] = None,
        colors: Optional[npt.ArrayLike] = None,
        uvs: Optional[npt.ArrayLike] = None,
        texture: Optional[npt.ArrayLike] = None,
        double_sided: bool = False,
    ) -> Scene:
        """One mesh from numpy: vertices (N, 3), faces (M, 3) ints (counter-clockwise = front),
        normals (N, 3), colors (N, 3|4; uint8 sRGB or float linear), uvs (N, 2) with (0, 0) the
        texture's top-left, texture (H, W, 3|4; uint8 sRGB or float linear)."""
    @staticmethod
    def builtin(name: str) -> Scene:
        """A built-in scene: `cube`, `teapot`, `ground` or `pixel-edges`."""
    @property
    def source(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def triangle_count(self) -> int: ...
    @property
    def resolution(self) -> Tuple[int, int]:
        """(width, height) used when `size` is None."""
    @property
    def camera(self) -> Camera:
        """The file's camera, or one framing everything drawn."""
    @property
    def bounding_sphere(self) -> Optional[Tuple[Tuple[float, float, float], float]]: ...
    @property
    def primitives(self) -> List[Dict[str, Union[int, str]]]:
        """Per primitive (a mesh primitive placed by a node; the `ids` output's third channel):
        id, node_index, node_name, mesh_index, mesh_name."""
    @property
    def draws(self) -> List[Dict[str, Union[int, str]]]:
        """Deprecated name of `primitives` (warns)."""
    def orbit_cameras(
        self,
        views: int,
        size: Optional[Tuple[int, int]] = None,
        elevation: float = 20.0,
        yfov_deg: float = 45.0,
    ) -> List[Camera]:
        """The cameras of `kantele render --orbit VIEWS` for images of `size`."""
    def framing_camera(
        self,
        direction: Sequence[float] = (0.4, 0.5, 1.0),
        size: Optional[Tuple[int, int]] = None,
        yfov_deg: float = 45.0,
    ) -> Camera:
        """A camera framing everything drawn, seen from `direction`."""
    def render(
        self,
        camera: Optional[Camera] = None,
        size: Optional[Tuple[int, int]] = None,
        outputs: Optional[Sequence[OutputName]] = None,
        backend: Backend = "cpu",
        threads: Optional[int] = None,
        msaa: int = 1,
        target: Literal["f32", "srgb8"] = "f32",
    ) -> Dict[str, np.ndarray]:
        """Renders one view (GIL released); `msaa` = samples per pixel of colour (1, 4 or 8;
        depth, normals and ids stay per pixel); `target` = the CPU colour target ("srgb8":
        8-bit sRGB tiles, the same uint8 color). Outputs (default color, depth, normals, ids):
        color uint8 (H, W, 4) sRGB; color_linear float32 (H, W, 4); depth float32 (H, W)
        distance along the view axis, inf = background; ray_depth float32 (H, W) distance from
        the camera centre; normals float32 (H, W, 3) world space,
        0 = background; ids uint32 (H, W, 3) instance, triangle, primitive (ID_CHANNELS); 0 = background."""
    def render_many(
        self,
        cameras: Sequence[Optional[Camera]],
        size: Optional[Tuple[int, int]] = None,
        outputs: Optional[Sequence[OutputName]] = None,
        backend: Backend = "cpu",
        threads: Optional[int] = None,
        msaa: int = 1,
        target: Literal["f32", "srgb8"] = "f32",
    ) -> List[Dict[str, np.ndarray]]:
        """`render` for every camera, the GIL released for the whole batch."""
