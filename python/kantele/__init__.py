"""Kantele: a software rasterizer. Load glTF 2.0 / OBJ / PLY / STL files or numpy meshes and
render colour, depth, normals and ids into numpy arrays on the CPU.

>>> import kantele
>>> scene = kantele.load("bunny.glb")
>>> out = scene.render(size=(640, 480))
>>> out["color"].shape, out["color"].dtype
((480, 640, 4), dtype('uint8'))

Conventions of every output (row 0 is the top row of the image):

- ``color``: ``uint8`` (H, W, 4), RGB sRGB-encoded, alpha linear (the bytes of the CLI's PNG);
- ``color_linear``: ``float32`` (H, W, 4), linear RGBA;
- ``depth``: ``float32`` (H, W), distance along the camera's view axis (OpenCV camera z, scene
  units), ``inf`` where nothing was drawn;
- ``ray_depth``: ``float32`` (H, W), distance from the camera centre, ``inf`` where nothing was
  drawn;
- ``normals``: ``float32`` (H, W, 3), world-space unit normals, 0 where nothing was drawn;
- ``ids``: ``uint32`` (H, W, 3), channels named by ``ID_CHANNELS``: instance id (glTF node index
  + 1), triangle id (triangle index in its primitive + 1), primitive id (index into
  ``Scene.primitives`` + 1); 0 = background.

Id names follow glTF and are the CLI's ``--ids KIND=FILE`` kinds: a *primitive* is a mesh
primitive placed by a node (one draw), a *triangle* is a triangle's index within it.
"""

from ._kantele import MAX_SIZE, OUTPUTS, Camera, Scene, isa, load, write_png

#: The names of the ``ids`` output's channels, in order (the CLI's ``--ids`` kinds).
ID_CHANNELS = ("instance", "triangle", "primitive")

__all__ = ["Camera", "Scene", "load", "write_png", "isa", "MAX_SIZE", "OUTPUTS", "ID_CHANNELS"]
