"""The same N orbit views (Kantele's cameras) rendered by pyrender on EGL (Mesa llvmpipe when
there is no GPU): colour + depth, in-process frames/s, load excluded. For BENCHMARKS.md.

    PYOPENGL_PLATFORM=egl python pyrender_views.py SCENE N WxH
"""

import os
import sys
import time

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")

import numpy as np  # noqa: E402
import pyrender  # noqa: E402
import trimesh  # noqa: E402

import kantele  # noqa: E402

scene_path, n, size = sys.argv[1], int(sys.argv[2]), sys.argv[3]
w, h = (int(v) for v in size.split("x"))
cams = kantele.load(scene_path).orbit_cameras(n, size=(w, h))
loaded = trimesh.load(scene_path)
scene = pyrender.Scene.from_trimesh_scene(loaded) if isinstance(loaded, trimesh.Scene) else (
    pyrender.Scene(nodes=[pyrender.Node(mesh=pyrender.Mesh.from_trimesh(loaded))]))
light = pyrender.DirectionalLight(intensity=3.0)
camera = pyrender.PerspectiveCamera(yfov=cams[0].yfov, znear=cams[0].znear, zfar=cams[0].zfar)
cam_node = scene.add(camera)
light_node = scene.add(light)
renderer = pyrender.OffscreenRenderer(w, h)
poses = [np.linalg.inv(c.world_to_camera_gl.astype(np.float64)) for c in cams]
scene.set_pose(cam_node, poses[0])
renderer.render(scene)  # warm-up: upload and compile
start = time.perf_counter()
for pose in poses:
    scene.set_pose(cam_node, pose)
    scene.set_pose(light_node, pose)
    color, depth = renderer.render(scene)
elapsed = time.perf_counter() - start
print(f"pyrender {n} views: {elapsed:.3f} s, {n / elapsed:.2f} frames/s "
      f"({color.shape}, {depth.dtype}, {renderer._platform.__class__.__name__})")
from OpenGL import GL  # noqa: E402

print("GL_RENDERER:", GL.glGetString(GL.GL_RENDERER).decode())
renderer.delete()
