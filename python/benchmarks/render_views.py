"""One process doing what `kantele render SCENE --orbit N --size WxH -o ... --depth ...` does,
through the Python package: load, render N orbit views (colour + depth), write PNG + .npy.
Prints the in-process render_many time. Used for BENCHMARKS.md (binding overhead).

    python render_views.py SCENE N WxH OUT_DIR
"""

import sys
import time

import numpy as np

import kantele

scene_path, n, size, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
w, h = (int(v) for v in size.split("x"))
scene = kantele.load(scene_path)
cams = scene.orbit_cameras(n, size=(w, h))
start = time.perf_counter()
views = scene.render_many(cams, outputs=("color", "depth"))
render_s = time.perf_counter() - start
for i, v in enumerate(views):
    kantele.write_png(f"{out}/{i:03d}.png", v["color"])
    np.save(f"{out}/{i:03d}_depth.npy", v["depth"])
print(f"render_many {n} views: {render_s:.3f} s, {n / render_s:.2f} frames/s")
