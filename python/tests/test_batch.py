"""`render_many`: the same pictures as one `render` per camera, and the GIL released meanwhile."""

import threading
import time

import numpy as np

import kantele


def test_render_many_equals_render_per_camera():
    scene = kantele.Scene.builtin("teapot")
    cams = scene.orbit_cameras(4, size=(64, 48))
    many = scene.render_many(cams, size=(64, 48))
    assert len(many) == 4
    for cam, out in zip(cams, many):
        one = scene.render(camera=cam, size=(64, 48))
        assert set(one) == set(out)
        for k in one:
            np.testing.assert_array_equal(one[k], out[k])


def test_render_many_accepts_none_for_the_scene_camera_and_no_cameras():
    scene = kantele.Scene.builtin("cube")
    a, b = scene.render_many([None, scene.camera], size=(32, 32), outputs=["ids"])
    np.testing.assert_array_equal(a["ids"], b["ids"])
    assert scene.render_many([], size=(32, 32)) == []


def test_threads_option_gives_the_same_picture():
    scene = kantele.Scene.builtin("teapot")
    one = scene.render(size=(96, 96), outputs=("color",), threads=1)["color"]
    two = scene.render(size=(96, 96), outputs=("color",), threads=2)["color"]
    np.testing.assert_array_equal(one, two)


def test_the_gil_is_released_while_rendering():
    scene = kantele.Scene.builtin("teapot")
    cams = scene.orbit_cameras(24, size=(640, 480))
    scene.render(size=(8, 8), outputs=("color",), threads=1)  # prepare the backend first
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.05)
    start = time.perf_counter()
    scene.render_many(cams, size=(640, 480), outputs=("color", "depth"), threads=1)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert end - start > 0.2, "the batch was too short to tell"
    # Ticking every ~1 ms, the thread must have run all through the batch, not just at its end.
    assert len(during) >= 0.2 * (end - start) * 1000, (len(during), end - start)
    gaps = np.diff([start, *during, end])
    assert gaps.max() < 0.25 * (end - start), gaps.max()


def test_concurrent_renders_of_one_scene_from_threads_agree():
    scene = kantele.Scene.builtin("cube")
    results = [None] * 4

    def work(i):
        results[i] = scene.render(size=(64, 64), outputs=("color",))["color"]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results[1:]:
        np.testing.assert_array_equal(results[0], r)
