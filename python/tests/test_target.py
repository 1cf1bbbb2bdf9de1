"""`target=`: the CPU backend's colour target. "srgb8" stores 8-bit sRGB tiles and gives the
same uint8 colour as the default "f32" target; depth, normals and ids are unchanged."""

import numpy as np
import pytest

import kantele


OUTPUTS = ("color", "depth", "normals", "ids")


def test_srgb8_target_gives_the_f32_targets_outputs():
    s = kantele.Scene.builtin("teapot")
    f32 = s.render(size=(96, 72), outputs=OUTPUTS)
    srgb8 = s.render(size=(96, 72), outputs=OUTPUTS, target="srgb8")
    assert len(np.unique(f32["color"].reshape(-1, 4), axis=0)) > 20, "a shaded picture"
    for name in OUTPUTS:
        assert np.array_equal(f32[name], srgb8[name]), name
    many = s.render_many([None, None], size=(40, 30), outputs=("color",), target="srgb8")
    assert many[0]["color"].shape == (30, 40, 4)
    assert np.array_equal(many[0]["color"], many[1]["color"])


def test_unknown_target_is_a_value_error():
    s = kantele.Scene.builtin("cube")
    with pytest.raises(ValueError, match="target"):
        s.render(size=(8, 8), target="rgb565")
    with pytest.raises(ValueError, match="CPU backend option"):
        s.render(size=(8, 8), backend="gl", target="srgb8")
