"""Outputs of `Scene.render`: shapes, dtypes and conventions, on a numpy mesh whose true depth,
normals and ids are known, and on built-in scenes."""

from pathlib import Path

import numpy as np
import pytest

import kantele


def quad(z=0.0, size=1.0):
    """A square of two counter-clockwise triangles facing +Z at height `z`."""
    v = np.array([[-size, -size, z], [size, -size, z], [size, size, z], [-size, size, z]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    return v, f


def test_the_extension_is_one_abi3_module():
    module = Path(kantele._kantele.__file__).name
    assert ".abi3." in module, module


def test_outputs_of_a_numpy_quad_seen_head_on():
    v, f = quad()
    scene = kantele.Scene.from_arrays(v, f)
    cam = kantele.Camera.look_at(eye=(0, 0, 5), target=(0, 0, 0), up=(0, 1, 0), yfov=0.5)
    out = scene.render(camera=cam, size=(64, 48))
    assert set(out) == {"color", "depth", "normals", "ids"}

    color, depth, normals, ids = out["color"], out["depth"], out["normals"], out["ids"]
    assert color.shape == (48, 64, 4) and color.dtype == np.uint8
    assert depth.shape == (48, 64) and depth.dtype == np.float32
    assert normals.shape == (48, 64, 3) and normals.dtype == np.float32
    assert ids.shape == (48, 64, 3) and ids.dtype == np.uint32

    # The quad spans ±1 at distance 5 with yfov 0.5: it covers the middle, not the corners.
    covered = ids[..., 2] > 0
    assert covered[24, 32] and not covered[0, 0] and not covered[47, 63]
    # Depth is the distance along the view axis: 5 on the quad, inf elsewhere.
    np.testing.assert_allclose(depth[covered], 5.0, rtol=1e-4)
    assert np.isinf(depth[~covered]).all()
    # World normals face +Z; background normals are 0.
    np.testing.assert_allclose(normals[covered], np.broadcast_to([0, 0, 1], normals[covered].shape), atol=1e-6)
    assert (normals[~covered] == 0).all()
    # Ids: instance 1, primitive 1 (one draw), triangles 1 and 2; background 0.
    assert kantele.ID_CHANNELS == ("instance", "triangle", "primitive")
    assert (ids[covered][:, 0] == 1).all() and (ids[covered][:, 2] == 1).all()
    assert set(np.unique(ids[covered][:, 1])) == {1, 2}
    assert (ids[~covered] == 0).all()
    # The colour is lit (white material, headlight): bright and opaque where covered.
    assert (color[covered][:, :3] > 200).all() and (color[covered][:, 3] == 255).all()


def test_depth_follows_the_view_axis_not_the_ray_length():
    # A wide quad at distance 4: off-centre pixels are further along their rays, but their
    # distance along the view axis is still 4.
    v, f = quad(size=3.0)
    scene = kantele.Scene.from_arrays(v, f)
    cam = kantele.Camera.look_at((0, 0, 4), (0, 0, 0), (0, 1, 0), yfov=1.2)
    depth = scene.render(camera=cam, size=(40, 40), outputs=("depth",))["depth"]
    finite = np.isfinite(depth)
    assert finite.sum() > 1000
    np.testing.assert_allclose(depth[finite], 4.0, rtol=1e-4)


def test_image_rows_start_at_the_top_and_columns_at_the_left():
    # Vertex colours: red at the top-left corner of the view, so the image's [0, 0] is red.
    v, f = quad()
    colors = np.array([[0, 0, 1.0], [0, 0, 1.0], [0, 0, 1.0], [1.0, 0, 0]])
    scene = kantele.Scene.from_arrays(v, f, colors=colors)
    cam = kantele.Camera.look_at((0, 0, 2), (0, 0, 0), (0, 1, 0), yfov=0.9)  # the quad fills it
    c = scene.render(camera=cam, size=(32, 32), outputs=("color_linear",))["color_linear"]
    assert c.dtype == np.float32 and c.shape == (32, 32, 4)
    assert c[0, 0, 0] > c[0, 0, 2]      # top-left: mostly red
    assert c[31, 31, 2] > c[31, 31, 0]  # bottom-right: mostly blue


def test_color_is_the_srgb_encoding_of_color_linear():
    scene = kantele.Scene.builtin("cube")
    out = scene.render(size=(80, 60), outputs=("color", "color_linear"))
    lin = out["color_linear"].astype(np.float64)
    srgb = np.where(lin <= 0.0031308, lin * 12.92, 1.055 * np.power(np.maximum(lin, 0), 1 / 2.4) - 0.055)
    expected = np.round(np.clip(srgb, 0, 1) * 255)
    assert np.abs(out["color"][..., :3].astype(np.int32) - expected[..., :3]).max() <= 1
    np.testing.assert_array_equal(out["color"][..., 3], np.round(np.clip(lin[..., 3], 0, 1) * 255))


def test_trimesh_style_inputs_float64_and_int64_uint8_colors_and_a_texture():
    v, f = quad()
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], dtype=np.float64)
    texture = np.zeros((4, 4, 3), dtype=np.uint8)
    texture[:2] = [255, 0, 0]  # top half red
    texture[2:] = [0, 255, 0]  # bottom half green
    colors = np.full((4, 4), 255, dtype=np.uint8)
    scene = kantele.Scene.from_arrays(v.astype(np.float64), f.astype(np.int64), colors=colors,
                                      uvs=uvs, texture=texture, double_sided=True)
    cam = kantele.Camera.look_at((0, 0, 2), (0, 0, 0), (0, 1, 0), yfov=0.6)
    c = scene.render(camera=cam, size=(32, 32), outputs=("color",))["color"]
    assert c[4, 16, 0] > 150 and c[4, 16, 1] < 80     # top: red
    assert c[27, 16, 1] > 150 and c[27, 16, 0] < 80   # bottom: green
    # Seen from behind, a double-sided quad is still drawn.
    back = kantele.Camera.look_at((0, 0, -2), (0, 0, 0), (0, 1, 0), yfov=0.6)
    ids = scene.render(camera=back, size=(32, 32), outputs=("ids",))["ids"]
    assert ids[16, 16, 2] == 1


def test_single_sided_faces_are_culled_from_behind():
    scene = kantele.Scene.from_arrays(*quad())
    back = kantele.Camera.look_at((0, 0, -2), (0, 0, 0), (0, 1, 0), yfov=0.6)
    assert (scene.render(camera=back, size=(16, 16), outputs=("ids",))["ids"] == 0).all()


def test_arrays_are_handed_over_writable_and_owned():
    out = kantele.Scene.builtin("cube").render(size=(16, 16), outputs=("color", "depth"))
    for a in out.values():
        assert a.flags.c_contiguous and a.flags.writeable
        a[...] = 0  # the caller owns the memory


def test_default_camera_and_size_come_from_the_scene():
    scene = kantele.Scene.builtin("cube")
    w, h = scene.resolution
    out = scene.render(outputs=("ids",))
    assert out["ids"].shape == (h, w, 3)
    same = scene.render(camera=scene.camera, size=(w, h), outputs=("ids",))
    np.testing.assert_array_equal(out["ids"], same["ids"])


def test_scene_properties():
    scene = kantele.Scene.builtin("teapot")
    assert scene.triangle_count > 100
    assert scene.source == "builtin:teapot"
    (cx, cy, cz), r = scene.bounding_sphere
    assert r > 0
    assert scene.primitives and scene.primitives[0]["id"] == 1
    # The old name still answers, with a DeprecationWarning.
    with pytest.warns(DeprecationWarning, match="Scene.primitives"):
        assert scene.draws == scene.primitives
    assert "teapot" in repr(scene)
    m = scene.camera.world_to_camera_gl
    assert m.shape == (4, 4) and m.dtype == np.float32
