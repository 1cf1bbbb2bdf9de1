"""Kantele at dataset scale on Ray (``pip install "kantele[ray]"``).

The pipeline is plain ``ray.data``: rows of (scene path, view) go through ``map_batches`` with
:class:`Renderer`, an actor that loads each scene once and renders its views; the results are
written as files (by the actors, so a cluster needs a shared ``out`` directory) or kept as
columns for ``write_parquet``::

    import ray, kantele.ray as kr

    ray.init()                                   # or ray.init(address="ray://head:10001")
    ds = kr.dataset(["bunny.glb", "spot.glb"], views=8)
    ds = ds.map_batches(kr.Renderer, fn_constructor_kwargs={"size": (256, 256),
                        "outputs": ("color", "depth", "ids")},
                        batch_size=4, concurrency=2, num_cpus=1)
    ds.write_parquet("renders/")     # columns: scene, stem, view, camera, color, depth, ids

With ``out_dir=...`` the actors write ``{stem}_{view:03d}.png`` (colour) and
``{stem}_{view:03d}_{output}.npy`` (depth, normals, ids, color_linear) and return one row of
file names per view instead of the arrays; :func:`render_files` runs that and writes
``manifest.json``. The command line: ``python -m kantele.ray SCENE_OR_DIR... --views K
--size WxH --out DIR --workers N [--outputs color,depth,ids]``.

Views are ``Scene.orbit_cameras(views, size)``: the cameras of ``kantele render --orbit``.
"""

from __future__ import annotations

import json
import logging
import os
import time
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

import kantele

SCENE_SUFFIXES = (".glb", ".gltf", ".obj", ".ply", ".stl")


def find_scenes(paths: Iterable[str]) -> List[str]:
    """Scene files named by ``paths``: files as given, directories searched recursively for
    ``.glb``, ``.gltf``, ``.obj``, ``.ply`` and ``.stl`` files (sorted). Raises
    ``FileNotFoundError`` for a missing path and ``ValueError`` when nothing is found or two
    scenes share a file stem (their outputs would collide)."""
    found: List[str] = []
    for p in paths:
        path = Path(p)
        if path.is_dir():
            found.extend(
                str(f) for f in sorted(path.rglob("*")) if f.suffix.lower() in SCENE_SUFFIXES
            )
        elif path.is_file():
            found.append(str(path))
        else:
            raise FileNotFoundError(f"{p}: no such file or directory")
    if not found:
        raise ValueError("no scene files (.glb, .gltf, .obj, .ply, .stl) found")
    stems: Dict[str, str] = {}
    for f in found:
        stem = Path(f).stem
        if stem in stems:
            raise ValueError(f"{f}: same file stem as {stems[stem]} (outputs would collide)")
        stems[stem] = f
    return found


def rows(scenes: Sequence[str], views: int) -> List[Dict[str, Any]]:
    """One row per (scene, view): ``{"scene": path, "view": k, "views": views}``."""
    if views < 1:
        raise ValueError(f"views {views} must be at least 1")
    return [{"scene": str(s), "view": k, "views": views} for s in scenes for k in range(views)]


def dataset(scenes: Sequence[str], views: int):
    """A ``ray.data.Dataset`` of :func:`rows` (one block per row, so views spread over actors)."""
    import ray.data

    items = rows(scenes, views)
    return ray.data.from_items(items, override_num_blocks=len(items))


def file_names(stem: str, view: int, outputs: Sequence[str]) -> Dict[str, str]:
    """The file of each output of one view: colour as PNG, the rest as ``.npy``."""
    names = {}
    for o in outputs:
        if o == "color":
            names[o] = f"{stem}_{view:03d}.png"
        else:
            names[o] = f"{stem}_{view:03d}_{o}.npy"
    return names


def peak_rss_mb() -> float:
    """This process's peak resident memory so far, MiB (Linux and macOS)."""
    import resource
    import sys

    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024 * 1024) if sys.platform == "darwin" else peak / 1024


class Renderer:
    """A ``map_batches`` callable class (a Ray actor): loads each scene once, renders the views
    of a batch with ``Scene.render_many`` (``msaa`` samples per pixel of colour: 1, 4 or 8) and
    returns their arrays as columns, or, with ``out_dir``, writes them as files and returns
    their names."""

    def __init__(
        self,
        size: Tuple[int, int],
        outputs: Sequence[str] = ("color", "depth", "ids"),
        out_dir: Optional[str] = None,
        threads: Optional[int] = None,
        msaa: int = 1,
    ):
        self.size = (int(size[0]), int(size[1]))
        self.outputs = tuple(outputs)
        self.out_dir = out_dir
        self.threads = threads
        self.msaa = msaa
        self.scenes: Dict[str, kantele.Scene] = {}

    def scene(self, path: str) -> "kantele.Scene":
        """The scene at ``path``, loaded on first use."""
        if path not in self.scenes:
            self.scenes[path] = kantele.load(path)
        return self.scenes[path]

    def render_rows(self, batch: Dict[str, np.ndarray]) -> List[Tuple[str, int, Any, Any]]:
        """Renders every row of ``batch`` (rows of one scene together, with ``render_many``):
        ``(scene path, view, camera, arrays)`` in row order. With ``out_dir``, a scene that
        cannot be loaded or rendered gives ``(path, view, None, message)`` rows instead of
        failing the whole job."""
        groups: Dict[Tuple[str, int], List[int]] = {}
        for i, (path, views) in enumerate(zip(batch["scene"], batch["views"])):
            groups.setdefault((str(path), int(views)), []).append(i)
        out: List[Any] = [None] * len(batch["scene"])
        for (path, views), indices in groups.items():
            try:
                scene = self.scene(path)
                cameras = scene.orbit_cameras(views, size=self.size)
                chosen = [cameras[int(batch["view"][i])] for i in indices]
                images = scene.render_many(chosen, outputs=self.outputs, threads=self.threads,
                                           msaa=self.msaa)
            except (OSError, ValueError) as e:
                if self.out_dir is None:
                    raise
                for i in indices:
                    out[i] = (path, int(batch["view"][i]), None, str(e))
                continue
            for i, camera, arrays in zip(indices, chosen, images):
                out[i] = (path, int(batch["view"][i]), camera, arrays)
        return out

    def __call__(self, batch: Dict[str, np.ndarray]) -> Dict[str, Any]:
        rendered = self.render_rows(batch)
        columns: Dict[str, Any] = {
            "scene": [r[0] for r in rendered],
            "stem": [Path(r[0]).stem for r in rendered],
            "view": [r[1] for r in rendered],
            # The camera as a `kantele render` sidecar has it (Camera.read_views reads it).
            "camera": [json.dumps(r[2].to_dict() if r[2] else None) for r in rendered],
        }
        if self.out_dir is None:
            for o in self.outputs:
                columns[o] = np.stack([r[3][o] for r in rendered])
            return columns
        files, errors = [], []
        for path, view, camera, arrays in rendered:
            if camera is None:
                files.append(json.dumps({}))
                errors.append(arrays)
                continue
            names = file_names(Path(path).stem, view, self.outputs)
            for o, name in names.items():
                target = os.path.join(self.out_dir, name)
                if o == "color":
                    kantele.write_png(target, arrays[o])
                else:
                    np.save(target, arrays[o])
            files.append(json.dumps(names))
            errors.append("")
        columns["files"] = files
        columns["error"] = errors
        columns["worker_pid"] = [os.getpid()] * len(rendered)
        columns["worker_peak_rss_mb"] = [peak_rss_mb()] * len(rendered)
        return columns


def render_files(
    scenes: Sequence[str],
    views: int,
    size: Tuple[int, int],
    out_dir: str,
    workers: int,
    outputs: Sequence[str] = ("color", "depth", "ids"),
    batch_size: int = 4,
    msaa: int = 1,
) -> Dict[str, Any]:
    """Renders ``views`` orbit views of every scene on ``workers`` Ray actors (one CPU each) into
    ``out_dir`` (``msaa`` samples per pixel of colour) and writes ``out_dir/manifest.json``;
    returns the manifest. Scenes that cannot
    be loaded or rendered are left out and listed (one message each) under ``errors``. Uses the running Ray
    (``ray.init(address=...)`` first for a cluster) or starts a local one with ``workers``
    CPUs."""
    import ray

    for o in outputs:
        if o not in kantele.OUTPUTS:
            raise ValueError(f"unknown output '{o}' (choose from: {', '.join(kantele.OUTPUTS)})")
    if workers < 1:
        raise ValueError(f"workers {workers} must be at least 1")
    if msaa not in (1, 4, 8):
        raise ValueError(f"msaa: unsupported sample count {msaa} (expected 1, 4 or 8)")
    os.makedirs(out_dir, exist_ok=True)
    out_abs = os.path.abspath(out_dir)
    if not ray.is_initialized():
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False,
                 logging_level=logging.getLogger("ray").getEffectiveLevel())
    start = time.perf_counter()
    ds = dataset(scenes, views).map_batches(
        Renderer,
        fn_constructor_kwargs={"size": size, "outputs": tuple(outputs), "out_dir": out_abs,
                               "threads": 1, "msaa": msaa},
        batch_size=batch_size,
        concurrency=workers,
        num_cpus=1,
    )
    records = sorted(ds.take_all(), key=lambda r: (str(r["scene"]), int(r["view"])))
    elapsed = time.perf_counter() - start
    failed = [r for r in records if r["error"]]
    records = [r for r in records if not r["error"]]
    manifest = {
        "size": [int(size[0]), int(size[1])],
        "views": views,
        "outputs": list(outputs),
        "msaa": msaa,
        "workers": workers,
        "elapsed_s": elapsed,
        "frames_per_s": len(records) / elapsed if elapsed > 0 else None,
        "cameras": "Scene.orbit_cameras(views, size): the cameras of `kantele render --orbit`",
        "renders": [
            {
                "scene": str(r["scene"]),
                "stem": str(r["stem"]),
                "view": int(r["view"]),
                "files": json.loads(r["files"]),
                "worker_pid": int(r["worker_pid"]),
                **json.loads(r["camera"]),
            }
            for r in records
        ],
        "errors": sorted({str(r["error"]) for r in failed}),
        "worker_peak_rss_mb": {
            str(pid): max(float(r["worker_peak_rss_mb"]) for r in records if r["worker_pid"] == pid)
            for pid in sorted({int(r["worker_pid"]) for r in records})
        },
    }
    with open(os.path.join(out_dir, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    return manifest
