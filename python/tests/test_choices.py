"""What to draw of a file from Python: `load`'s `animation`, `time`, `scene` and `cull`, and
`Scene.at_time`, which poses a loaded scene as loading at that time does."""

import numpy as np
import pytest

import kantele
from conftest import shared_root, skip_or_fail


def realworld(name):
    path = shared_root() / "realworld" / name
    if not path.exists():
        skip_or_fail("realworld", f"{path} is absent")
    return path


def color(scene):
    return scene.render(size=(64, 64))["color"]


def test_at_time_poses_as_loading_at_that_time():
    man = realworld("skin-anim/CesiumMan.glb")
    start = kantele.load(man, animation=0, time=0.0)
    index, name, (first, last) = start.animation
    assert index == 0 and 0.0 <= first < 0.1 and last > 1.0
    camera = start.camera
    for t in (0.5, 1.25):
        loaded = kantele.load(man, animation=0, time=t)
        posed = start.at_time(t)
        a = posed.render(camera=camera, size=(64, 64))["color"]
        b = loaded.render(camera=camera, size=(64, 64))["color"]
        assert np.array_equal(a, b), f"at {t} s"
    moved = start.at_time(0.5).render(camera=camera, size=(64, 64))["color"]
    still = start.render(camera=camera, size=(64, 64))["color"]
    assert not np.array_equal(moved, still), "the figure walks"


def test_choices_that_the_file_lacks_are_value_errors():
    man = realworld("skin-anim/CesiumMan.glb")
    with pytest.raises(ValueError, match="no-such"):
        kantele.load(man, animation="no-such")
    with pytest.raises(ValueError, match="without an animation"):
        kantele.load(man).at_time(1.0)
    with pytest.raises(ValueError, match="cull"):
        kantele.load(man, cull="sideways")
    scenes = realworld("MultipleScenes/glTF/MultipleScenes.gltf")
    with pytest.raises(ValueError, match="scene"):
        kantele.load(scenes, scene=9)


def test_cull_decides_whether_a_face_seen_from_behind_is_drawn(tmp_path):
    # Counter-clockwise seen from -Z: its front faces away from a camera on +Z.
    quad = tmp_path / "quad.obj"
    quad.write_text("v -1 -1 0\nv -1 1 0\nv 1 1 0\nv 1 -1 0\nf 1 2 3 4\n")
    camera = kantele.Camera.look_at(eye=[0, 0, 4], target=[0, 0, 0])

    def covered(**kw):
        out = kantele.load(quad, **kw).render(camera=camera, size=(32, 32))
        return int(np.count_nonzero(out["depth"] < np.inf))

    drawn = covered()
    assert drawn > 100, "OBJ faces are drawn from both sides"
    assert covered(cull="back") == 0
    assert covered(cull="front") == drawn
    assert covered(cull="none") == drawn
