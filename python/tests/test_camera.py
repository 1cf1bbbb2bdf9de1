"""Cameras: OpenCV intrinsics and matrices land points where the pinhole model says, look-at and
orbit helpers, and the sidecar-style dict reads back as the same camera."""

import inspect
import json

import numpy as np
import pytest

import kantele


def small_square(center, half=0.2):
    """A small double-sided square around `center`, facing ±Z."""
    c = np.asarray(center, dtype=np.float64)
    v = c + np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]])
    return kantele.Scene.from_arrays(v, np.array([[0, 1, 2], [0, 2, 3]]), double_sided=True)


@pytest.mark.parametrize("point", [(0.0, 0.0, 5.0), (0.7, -0.4, 5.0), (-1.1, 0.9, 4.0)])
def test_opencv_intrinsics_put_a_point_where_the_pinhole_model_says(point):
    fx, fy, cx, cy, size = 120.0, 110.0, 70.25, 41.5, (160, 90)
    # The OpenCV camera frame is the world frame: the camera at the origin looking down +Z.
    cam = kantele.Camera.from_opencv(fx, fy, cx, cy, np.eye(4), size=size)
    assert cam.intrinsics() == pytest.approx((fx, fy, cx, cy))
    out = small_square(point).render(camera=cam, outputs=("ids", "depth", "ray_depth"))
    covered = out["ids"][..., 2] > 0
    assert covered.sum() > 4
    ys, xs = np.nonzero(covered)
    x, y, z = point
    # Pixel (i, j) has its centre at (i, j): the covered pixels' centroid is the projection.
    assert xs.mean() == pytest.approx(fx * x / z + cx, abs=0.5)
    assert ys.mean() == pytest.approx(fy * y / z + cy, abs=0.5)
    np.testing.assert_allclose(out["depth"][covered], z, rtol=1e-4)
    # Ray depth: distance from the camera centre, longer than planar depth off the axis.
    u, v = xs.astype(np.float64), ys.astype(np.float64)
    factor = np.sqrt(1 + ((u - cx) / fx) ** 2 + ((v - cy) / fy) ** 2)
    np.testing.assert_allclose(out["ray_depth"][covered], z * factor, rtol=1e-4)
    assert np.isinf(out["ray_depth"][~covered]).all()


def test_opencv_and_opengl_matrices_describe_the_same_camera():
    cam = kantele.Camera.look_at(eye=(1, 2, 6), target=(0, 0.5, 0), up=(0, 1, 0), yfov=0.7,
                                 size=(64, 48))
    assert cam.eye == pytest.approx((1, 2, 6), abs=1e-5)
    gl, cv = cam.world_to_camera_gl, cam.world_to_camera_opencv
    np.testing.assert_allclose(cv, np.diag([1, -1, -1, 1]) @ gl, atol=1e-6)
    # The target is straight ahead: OpenCV z > 0, x = y = 0.
    t = cv @ np.array([0, 0.5, 0, 1])
    assert t[2] > 0 and abs(t[0]) < 1e-5 and abs(t[1]) < 1e-5
    fx, fy, cx, cy = cam.intrinsics()
    assert (cx, cy) == pytest.approx((31.5, 23.5))
    assert fy == pytest.approx(24 / np.tan(0.35)) and fx == pytest.approx(fy)
    # The same pose from its OpenCV description renders the same picture.
    scene = kantele.Scene.builtin("teapot")
    again = kantele.Camera.from_opencv(fx, fy, cx, cy, cv, size=(64, 48), znear=cam.znear)
    a = scene.render(camera=cam, outputs=("ids",))["ids"]
    b = scene.render(camera=again, outputs=("ids",))["ids"]
    assert (a != b).any(axis=2).mean() < 0.01


def test_camera_dicts_read_back_as_the_same_cameras(tmp_path):
    scene = kantele.Scene.builtin("teapot")
    cams = scene.orbit_cameras(3, size=(48, 40))
    path = tmp_path / "views.json"
    path.write_text(json.dumps({"views": [c.to_dict() for c in cams]}))
    read = kantele.Camera.read_views(path)
    assert len(read) == 3 and read[0].size == (48, 40)
    for a, b in zip(cams, read):
        np.testing.assert_array_equal(a.world_to_camera_gl, b.world_to_camera_gl)
        np.testing.assert_array_equal(a.projection(), b.projection())
        ra = scene.render(camera=a, outputs=("color",))["color"]
        rb = scene.render(camera=b, outputs=("color",))["color"]
        np.testing.assert_array_equal(ra, rb)
    d = cams[0].to_dict()
    assert {"fx", "fy", "cx", "cy", "width", "height", "znear", "zfar"} <= set(d["camera"])
    assert np.asarray(d["world_to_camera_opencv"]).shape == (4, 4)


def test_orbit_cameras_circle_the_scene_and_frame_it():
    scene = kantele.Scene.builtin("teapot")
    (c, r) = scene.bounding_sphere
    cams = scene.orbit_cameras(4, size=(64, 64))
    eyes = np.array([cam.eye for cam in cams]) - np.asarray(c)
    dist = np.linalg.norm(eyes, axis=1)
    np.testing.assert_allclose(dist, dist[0], rtol=1e-5)
    assert (eyes[:, 1] > 0).all()  # 20 degrees above
    # Starting on +Z, turning towards +X.
    assert eyes[0, 2] > 0 and eyes[1, 0] > 0 and eyes[2, 2] < 0 and eyes[3, 0] < 0
    for cam in cams:
        ids = scene.render(camera=cam, outputs=("ids",))["ids"]
        covered = ids[..., 2] > 0
        assert covered.any()
        # Framed: nothing touches the image border.
        assert not (covered[0].any() or covered[-1].any() or covered[:, 0].any()
                    or covered[:, -1].any())


def test_framing_camera_and_scene_camera():
    scene = kantele.Scene.builtin("cube")
    cam = scene.framing_camera(size=(40, 30))
    assert cam.size == (40, 30)
    ids = scene.render(camera=cam, outputs=("ids",))["ids"]
    assert ids.shape == (30, 40, 3) and (ids[..., 2] > 0).any()
    assert scene.camera.size is None
    w, h = scene.resolution
    assert scene.camera.intrinsics(size=(w, h))[2] == pytest.approx((w - 1) / 2)


def test_look_at_depth_range_and_camera_size():
    cam = kantele.Camera.look_at((0, 0, 10), (0, 0, 0))
    assert cam.znear == pytest.approx(0.1) and cam.zfar is None and cam.size is None
    cam = cam.with_depth_range(1.0, 20.0)
    assert (cam.znear, cam.zfar) == (1.0, 20.0)
    sized = kantele.Camera.look_at((0, 0, 10), (0, 0, 0), size=(30, 20))
    out = kantele.Scene.builtin("cube").render(camera=sized, outputs=("depth",))
    assert out["depth"].shape == (20, 30)


def test_read_views_of_a_missing_file_is_file_not_found(tmp_path):
    path = tmp_path / "nope.json"
    with pytest.raises(FileNotFoundError) as e:
        kantele.Camera.read_views(path)
    assert str(path) in str(e.value) and "\n" not in str(e.value)


def test_a_pose_without_znear_gets_from_opencvs_default(tmp_path):
    """`--views` and `Camera.read_views` read a pose record without `znear` with the near plane
    `Camera.from_opencv` defaults to."""
    record = {"world_to_camera": np.eye(4).tolist(), "convention": "opencv",
              "fx": 100.0, "fy": 100.0, "cx": 31.5, "cy": 23.5, "width": 64, "height": 48}
    path = tmp_path / "views.json"
    path.write_text(json.dumps({"views": [record]}))
    (camera,) = kantele.Camera.read_views(path)
    default = inspect.signature(kantele.Camera.from_opencv).parameters["znear"].default
    assert camera.znear == pytest.approx(default) and default == 0.01
