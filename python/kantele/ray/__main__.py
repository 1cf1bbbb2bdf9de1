"""``python -m kantele.ray SCENE_OR_DIR... --views K --size WxH --out DIR --workers N
[--outputs color,depth,ids] [--msaa 1|4|8] [--address ADDR]``: orbit renders of every scene on a Ray cluster
(a local one with N workers unless ``--address`` names a running cluster)."""

from __future__ import annotations

import argparse
import logging
import sys
from typing import List, Optional, Tuple


def parse_size(text: str) -> Tuple[int, int]:
    """``WxH`` as ``(W, H)``."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size '{text}' is not WxH (e.g. 640x480)") from None
    if w < 1 or h < 1:
        raise argparse.ArgumentTypeError(f"size '{text}' must be at least 1x1")
    return w, h


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m kantele.ray",
        description="Render K orbit views of every scene on Ray into DIR "
        "({stem}_{view:03d}.png, .npy for float and id outputs, manifest.json).",
    )
    parser.add_argument("scenes", nargs="+", metavar="SCENE_OR_DIR")
    parser.add_argument("--views", type=int, default=1, help="orbit views per scene (default 1)")
    parser.add_argument("--size", type=parse_size, default=(512, 512), help="WxH (default 512x512)")
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--workers", type=int, default=1, help="Ray actors, one CPU each")
    parser.add_argument("--outputs", default="color,depth,ids",
                        help="comma-separated: color, color_linear, depth, normals, ids")
    parser.add_argument("--msaa", type=int, choices=(1, 4, 8), default=1,
                        help="samples per pixel of colour (default 1)")
    parser.add_argument("--address", default=None,
                        help="a running Ray cluster (ray.init(address=...)); default: a local one")
    parser.add_argument("--batch-size", type=int, default=4)
    args = parser.parse_args(argv)

    try:
        import ray
        import ray.data
    except ImportError:
        print('kantele.ray: Ray is not installed (pip install "kantele[ray]")', file=sys.stderr)
        return 2
    from . import find_scenes, render_files

    # Ray's own progress and info lines would drown the one-line result or error.
    logging.getLogger("ray").setLevel(logging.ERROR)
    ray.data.DataContext.get_current().enable_progress_bars = False

    try:
        scenes = find_scenes(args.scenes)
        outputs = [o.strip() for o in args.outputs.split(",") if o.strip()]
        if args.address:
            ray.init(address=args.address, log_to_driver=False, logging_level=logging.ERROR)
        manifest = render_files(scenes, args.views, args.size, args.out, args.workers,
                                outputs, args.batch_size, args.msaa)
    except (OSError, ValueError) as e:
        print(f"kantele.ray: {e}", file=sys.stderr)
        return 1
    except ray.exceptions.RayError as e:
        # A scene that fails inside a worker: its one-line message is the error's last line.
        lines = [line for line in str(e).splitlines() if line.strip()]
        print(f"kantele.ray: {lines[-1] if lines else e}", file=sys.stderr)
        return 1
    for error in manifest["errors"]:
        print(f"kantele.ray: {error}", file=sys.stderr)
    if manifest["errors"]:
        return 1
    n = len(manifest["renders"])
    print(f"{n} views of {len(scenes)} scenes in {manifest['elapsed_s']:.2f} s "
          f"({manifest['frames_per_s']:.2f} frames/s) -> {args.out}/manifest.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
