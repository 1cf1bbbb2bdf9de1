"""`kantele.ray` on a local 2-worker Ray: the command line's files and manifest equal
single-process renders of the same views (at 4x multisampling, passed through to every worker)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import kantele
from conftest import skip_or_fail
from pngread import read_png

SIZE = (48, 40)


def ray_installed():
    try:
        import ray  # noqa: F401
        import ray.data  # noqa: F401
    except ImportError:
        skip_or_fail("ray", 'Ray is not installed (pip install "ray[data]")')


def test_command_line_on_two_workers_equals_single_process_renders(tmp_path):
    ray_installed()
    scene_dir = tmp_path / "scenes"
    scene_dir.mkdir()
    # Two scenes written as OBJ from numpy, one of them in a subdirectory.
    (scene_dir / "sub").mkdir()
    write_obj(scene_dir / "tri.obj", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[1, 2, 3]])
    write_obj(scene_dir / "sub" / "quad.obj",
              [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[1, 2, 3], [1, 3, 4]])
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, "-m", "kantele.ray", str(scene_dir), "--views", "3",
         "--size", f"{SIZE[0]}x{SIZE[1]}", "--out", str(out), "--workers", "2",
         "--outputs", "color,depth,ids", "--msaa", "4"],
        capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["workers"] == 2 and manifest["size"] == list(SIZE) and manifest["msaa"] == 4
    renders = manifest["renders"]
    assert len(renders) == 6
    assert {(r["stem"], r["view"]) for r in renders} == {
        (s, v) for s in ("tri", "quad") for v in range(3)}
    for r in renders:
        scene = kantele.load(r["scene"])
        cam = scene.orbit_cameras(3, size=SIZE)[r["view"]]
        expected = scene.render(camera=cam, size=SIZE, outputs=("color", "depth", "ids"), msaa=4)
        files = r["files"]
        assert files["color"] == f"{r['stem']}_{r['view']:03d}.png"
        np.testing.assert_array_equal(read_png(out / files["color"]), expected["color"])
        np.testing.assert_array_equal(np.load(out / files["depth"]), expected["depth"])
        np.testing.assert_array_equal(np.load(out / files["ids"]), expected["ids"])
        # The manifest holds each view's camera as a sidecar does.
        np.testing.assert_array_equal(r["world_to_camera_opencv"], cam.world_to_camera_opencv)
        assert (r["camera"]["fx"], r["camera"]["cy"]) == pytest.approx(
            (cam.intrinsics()[0], cam.intrinsics()[3]))
    # Rendered in Ray worker processes, not in the driver (which of the two actors takes a
    # batch is Ray's choice).
    assert all(r["worker_pid"] != os.getpid() for r in renders)


def test_command_line_errors_are_one_line(tmp_path):
    ray_installed()
    run = subprocess.run(
        [sys.executable, "-m", "kantele.ray", str(tmp_path / "missing.glb"), "--out",
         str(tmp_path / "o")], capture_output=True, text=True, timeout=60)
    assert run.returncode == 1
    assert run.stderr.strip().count("\n") == 0 and "missing.glb" in run.stderr
    run = subprocess.run(
        [sys.executable, "-m", "kantele.ray", str(tmp_path), "--size", "12", "--out",
         str(tmp_path / "o")], capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and "WxH" in run.stderr
    # A scene that only fails inside a Ray worker still ends in one line naming it.
    bad = tmp_path / "broken.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    run = subprocess.run(
        [sys.executable, "-m", "kantele.ray", str(bad), "--size", "8x8", "--workers", "1",
         "--out", str(tmp_path / "o")], capture_output=True, text=True, timeout=300)
    assert run.returncode == 1, run.stderr[-2000:]
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith("kantele.ray: ") and "broken.obj" in last, run.stderr[-2000:]
    manifest = json.loads((tmp_path / "o" / "manifest.json").read_text())
    assert manifest["renders"] == [] and "broken.obj" in manifest["errors"][0]


def write_obj(path, vertices, faces):
    lines = [f"v {x} {y} {z}" for x, y, z in vertices]
    lines += ["f " + " ".join(str(i) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n")
