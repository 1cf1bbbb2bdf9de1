"""Bad input raises a Python exception with the library's one-line message, never a crash."""

import numpy as np
import pytest

import kantele

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
F = np.array([[0, 1, 2]])


def test_missing_file_is_file_not_found_naming_it(tmp_path):
    path = tmp_path / "nope.glb"
    with pytest.raises(FileNotFoundError) as e:
        kantele.load(path)
    assert str(path) in str(e.value) and "\n" not in str(e.value)


def test_malformed_and_unknown_files_are_value_errors(tmp_path):
    bad = tmp_path / "bad.glb"
    bad.write_bytes(b"glTF\x02\x00\x00\x00garbage")
    with pytest.raises(ValueError, match="bad.glb"):
        kantele.load(bad)
    txt = tmp_path / "scene.txt"
    txt.write_text("hello")
    with pytest.raises(ValueError, match="unknown scene format"):
        kantele.load(str(txt))
    broken_obj = tmp_path / "broken.obj"
    broken_obj.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match="broken.obj"):
        kantele.load(broken_obj)


def test_unknown_builtin():
    with pytest.raises(ValueError, match="no built-in scene named 'nope'"):
        kantele.Scene.builtin("nope")


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(vertices=V[:, :2], faces=F), r"vertices: expected shape \(N, 3\)"),
        (dict(vertices=V, faces=F[:, :2]), r"faces: expected shape \(N, 3\)"),
        (dict(vertices=V, faces=np.array([[0, 1, 3]])), "index 3 at row 0 is out of range for 3"),
        (dict(vertices=V, faces=np.array([[0, -1, 2]])), "index -1 at row 0 is out of range"),
        (dict(vertices=V, faces=F.astype(np.float32)), "faces: expected an integer array"),
        (dict(vertices=V * np.nan, faces=F), "vertices: value NaN at row 0 is not finite"),
        (dict(vertices=V, faces=F, normals=np.zeros((2, 3))), r"normals: expected shape \(3, 3\)"),
        (dict(vertices=V, faces=F, colors=np.zeros((3, 5))), r"colors: expected shape \(3, 3 or 4\)"),
        (dict(vertices=V, faces=F, texture=np.zeros((2, 2, 3), np.uint8)), "texture: needs uvs"),
        (dict(vertices=V, faces=F, uvs=np.zeros((3, 2)), texture=np.zeros((2, 2), np.uint8)),
         r"texture: expected shape \(H, W, 3 or 4\)"),
        (dict(vertices=V, faces=F, uvs=np.zeros((3, 2)), texture=np.zeros((0, 2, 3), np.uint8)),
         "invalid texture size"),
        (dict(vertices="abc", faces=F), "vertices"),
    ],
)
def test_bad_arrays_are_value_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        kantele.Scene.from_arrays(**kwargs)


def test_bad_render_arguments_are_value_errors():
    scene = kantele.Scene.from_arrays(V, F)
    with pytest.raises(ValueError, match="unknown output 'colour'"):
        scene.render(outputs=("colour",))
    with pytest.raises(ValueError, match="not a string"):
        scene.render(outputs="color")
    with pytest.raises(ValueError, match="outputs is empty"):
        scene.render(outputs=())
    for size in [(0, 10), (10, -1), (100000, 10)]:
        with pytest.raises(ValueError, match="outside 1..=16384"):
            scene.render(size=size)
    with pytest.raises(ValueError, match="unknown backend 'vulkan'"):
        scene.render(backend="vulkan")
    with pytest.raises(ValueError, match="threads 0"):
        scene.render(threads=0)
    with pytest.raises(TypeError):
        scene.render(camera="front")


def test_bad_cameras_are_value_errors():
    with pytest.raises(ValueError, match="same point"):
        kantele.Camera.look_at((0, 0, 1), (0, 0, 1))
    with pytest.raises(ValueError, match=r"yfov 4 rad is outside \(0, π\)"):
        kantele.Camera.look_at((0, 0, 1), (0, 0, 0), yfov=4.0)
    with pytest.raises(ValueError, match="must be finite"):
        kantele.Camera.look_at((0, 0, float("inf")), (0, 0, 0))
    with pytest.raises(ValueError, match="znear"):
        kantele.Camera.look_at((0, 0, 1), (0, 0, 0), znear=-1.0)
    with pytest.raises(ValueError, match="focal lengths must be finite and > 0"):
        kantele.Camera.from_opencv(-1, 100, 10, 10, np.eye(4), size=(20, 20))
    with pytest.raises(ValueError, match=r"expected a \(4, 4\) or \(3, 4\) matrix"):
        kantele.Camera.from_opencv(100, 100, 10, 10, np.eye(3), size=(20, 20))
    with pytest.raises(ValueError, match="singular"):
        kantele.Camera.from_opencv(100, 100, 10, 10, np.zeros((4, 4)), size=(20, 20))
    with pytest.raises(ValueError, match="outside 1..=16384"):
        kantele.Camera.from_opencv(100, 100, 10, 10, np.eye(4), size=(0, 20))
    with pytest.raises(ValueError, match="orbit of 0 views"):
        kantele.Scene.builtin("cube").orbit_cameras(0)
    empty = kantele.Scene.from_arrays(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    with pytest.raises(ValueError, match="draws nothing"):
        empty.orbit_cameras(3)
    with pytest.raises(ValueError, match="no image size of its own"):
        kantele.Camera.look_at((0, 0, 1), (0, 0, 0)).intrinsics()


def test_a_pinhole_camera_renders_only_at_its_own_size():
    cam = kantele.Camera.from_opencv(50, 50, 15.5, 11.5, np.eye(4), size=(32, 24))
    scene = kantele.Scene.from_arrays(V + [0, 0, 5], F, double_sided=True)
    assert scene.render(camera=cam, outputs=("ids",))["ids"].shape == (24, 32, 3)
    with pytest.raises(ValueError, match="intrinsics are for 32x24 images, not 64x48"):
        scene.render(camera=cam, size=(64, 48))


def test_write_png_errors(tmp_path):
    with pytest.raises(OSError, match="no-such-dir"):
        kantele.write_png(tmp_path / "no-such-dir" / "a.png", np.zeros((2, 2, 4), np.uint8))
    with pytest.raises(ValueError, match="channels"):
        kantele.write_png(tmp_path / "a.png", np.zeros((2, 2, 2), np.uint8))
