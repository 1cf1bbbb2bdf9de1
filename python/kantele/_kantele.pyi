"""Type stubs of the extension module (re-exported by `kantele`)."""

import os
from typing import Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
OutputName = Literal["color", "color_linear", "depth", "normals", "ids"]
Backend = Literal["cpu", "gl"]

MAX_SIZE: int
"""Largest image side in pixels."""
OUTPUTS: List[str]
"""Every output name `render` knows."""

def load(path: PathLike) -> Scene:
    """Loads a glTF 2.0 (`.gltf`, `.glb`) or OBJ file. `FileNotFoundError`/`OSError` when it
    cannot be read, `ValueError` when it is malformed."""

def write_png(path: PathLike, image: npt.NDArray[np.uint8]) -> None:
    """Writes a `uint8` (H, W, 4) or (H, W, 3) image, row 0 at the top, as PNG."""

class Camera:
    """A perspective camera (OpenGL conventions: looks down -Z of its frame, y up)."""

    @staticmethod
    def look_at(
        eye: Sequence[float],
        target: Sequence[float],
        up: Sequence[float] = (0.0, 1.0, 0.0),
        yfov: float = 0.8,
        znear: float = 0.01,
        zfar: Optional[float] = None,
    ) -> Camera:
        """A camera at `eye` looking at `target`; `yfov` in radians; `zfar=None`: infinite."""
    @property
    def world_to_camera_gl(self) -> npt.NDArray[np.float32]:
        """4x4 world -> camera matrix, OpenGL camera frame (x right, y up, looking down -z)."""
    @property
    def yfov(self) -> float: ...
    @property
    def znear(self) -> float: ...
    @property
    def zfar(self) -> Optional[float]: ...

class Scene:
    """A scene ready to render."""

    @staticmethod
    def load(path: PathLike) -> Scene:
        """Same as `kantele.load`."""
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
    def draws(self) -> List[Dict[str, Union[int, str]]]:
        """Per draw: id, node_index, node_name, mesh_index, mesh_name."""
    def orbit_cameras(
        self, views: int, size: Optional[Tuple[int, int]] = None, elevation: float = 20.0
    ) -> List[Camera]:
        """The cameras of `kantele render --orbit VIEWS` for images of `size`."""
    def render(
        self,
        camera: Optional[Camera] = None,
        size: Optional[Tuple[int, int]] = None,
        outputs: Optional[Sequence[OutputName]] = None,
        backend: Backend = "cpu",
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]:
        """Renders one view (GIL released). Outputs (default color, depth, normals, ids):
        color uint8 (H, W, 4) sRGB; color_linear float32 (H, W, 4); depth float32 (H, W)
        distance along the view axis, inf = background; normals float32 (H, W, 3) world space,
        0 = background; ids uint32 (H, W, 3) instance, primitive, draw; 0 = background."""
    def render_many(
        self,
        cameras: Sequence[Optional[Camera]],
        size: Optional[Tuple[int, int]] = None,
        outputs: Optional[Sequence[OutputName]] = None,
        backend: Backend = "cpu",
        threads: Optional[int] = None,
    ) -> List[Dict[str, np.ndarray]]:
        """`render` for every camera, the GIL released for the whole batch."""
