"""The Python package against the `kantele` command, same scenes and views: colour byte for
byte, depth (eye distance, PFM) and every id channel (16-bit PNG, `--ids KIND=FILE` with the
package's channel names) exactly, normals within the PNG's 8-bit quantisation."""

import subprocess

import numpy as np
import pytest

import kantele
from pngread import read_pfm, read_png

# Scenes whose ids fit the CLI's 16-bit PNG (bunny's 69451 triangles do not).
SCENES = ["thesis-cube-textured.glb", "spot-textured.glb", "alpha-blend.glb", "thesis-t2-cubes.glb"]
SIZE = (96, 72)


def output_args(base):
    """The CLI's outputs for file names starting with `base`: colour, depth, normals, instance
    ids (`--ids FILE`) and one file per id kind, named as the package names its id channels."""
    return ["-o", f"{base}.png", "--depth", f"{base}.pfm", "--normals", f"{base}_n.png",
            "--ids", f"{base}_ids.png",
            *[a for kind in kantele.ID_CHANNELS for a in ("--ids", f"{kind}={base}_{kind}.png")]]


def cli_render(cli, scene_paths, out_dir, orbit=None):
    args = [cli, "render", *map(str, scene_paths), "--size", f"{SIZE[0]}x{SIZE[1]}",
            *output_args(f"{out_dir}/{{stem}}_{{frame}}")]
    if orbit:
        args += ["--orbit", str(orbit)]
    subprocess.run(args, check=True, capture_output=True)


def cli_base(out_dir, stem, frame):
    """The CLI's file name stem for a view: `{frame}` is zero-padded to a width of its own."""
    for f in out_dir.glob(f"{stem}_*.png.json"):
        number = f.name[len(stem) + 1 : -len(".png.json")]
        if number.isdigit() and int(number) == frame:
            return out_dir / f"{stem}_{number}"
    raise AssertionError(f"the CLI wrote no {stem} view {frame} in {out_dir}")


def check_same(expected_dir, stem, frame, out):
    base = cli_base(expected_dir, stem, frame)
    np.testing.assert_array_equal(out["color"], read_png(f"{base}.png"),
                                  err_msg=f"{stem} view {frame}: colour differs from the CLI")
    np.testing.assert_array_equal(out["depth"], read_pfm(f"{base}.pfm"))
    # `--ids FILE` writes the instance ids as one 16-bit channel (0 = background): the first of
    # the package's (instance, triangle, primitive) channels.
    ids = read_png(f"{base}_ids.png")
    assert ids.dtype == np.uint16
    instance = ids.reshape(out["ids"].shape[:2]).astype(np.uint32)
    np.testing.assert_array_equal(out["ids"][..., 0], instance)
    # One vocabulary: the CLI's id kinds are the package's channel names, channel for channel.
    for k, kind in enumerate(kantele.ID_CHANNELS):
        channel = read_png(f"{base}_{kind}.png").reshape(out["ids"].shape[:2]).astype(np.uint32)
        np.testing.assert_array_equal(out["ids"][..., k], channel, err_msg=f"{kind} ids differ")
    normals_png = read_png(f"{base}_n.png")
    covered = normals_png[..., 3] == 255
    assert covered.any()
    encoded = np.round(np.clip(out["normals"] * 0.5 + 0.5, 0, 1) * 255).astype(np.uint8)
    np.testing.assert_array_equal(encoded[covered], normals_png[..., :3][covered])
    assert (out["normals"][~covered] == 0).all()
    assert np.isinf(out["depth"][~covered]).all()
    assert np.isfinite(out["depth"][covered]).all()


def test_scene_cameras_match_the_cli(cli, scenes_dir, tmp_path):
    paths = [scenes_dir / s for s in SCENES]
    cli_render(cli, paths, tmp_path)
    for p in paths:
        out = kantele.load(p).render(size=SIZE)
        check_same(tmp_path, p.stem, 0, out)


def test_orbit_views_match_the_cli(cli, scenes_dir, tmp_path):
    path = scenes_dir / "spot-textured.glb"
    cli_render(cli, [path], tmp_path, orbit=3)
    scene = kantele.load(path)
    views = scene.render_many(scene.orbit_cameras(3, size=SIZE), size=SIZE)
    assert len(views) == 3
    for frame, out in enumerate(views):
        check_same(tmp_path, "spot-textured", frame, out)
    # The views differ from each other.
    assert not np.array_equal(views[0]["color"], views[1]["color"])


def test_builtin_scene_matches_the_cli(cli, tmp_path):
    subprocess.run([cli, "render", "--builtin", "teapot", "--size", f"{SIZE[0]}x{SIZE[1]}",
                    *output_args(f"{tmp_path}/teapot_0")], check=True, capture_output=True)
    check_same(tmp_path, "teapot", 0, kantele.Scene.builtin("teapot").render(size=SIZE))
