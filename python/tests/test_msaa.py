"""`msaa=`: multisampled colour, as `kantele render --msaa`. Edges are antialiased and nothing
else changes: interior colour, depth, normals and ids equal those of a 1x render."""

import numpy as np
import pytest

import kantele


def tilted_quad():
    """A square of two triangles facing +Z, turned 20 degrees about Z: slanted edges."""
    angle = np.radians(20.0)
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) @ rot.T
    v = np.column_stack([corners, np.zeros(4)])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    return kantele.Scene.from_arrays(v, f)


CAMERA = kantele.Camera.look_at(eye=(0, 0, 5), target=(0, 0, 0), up=(0, 1, 0), yfov=0.6)
SIZE = (96, 72)


def render(scene, msaa, **kwargs):
    return scene.render(camera=CAMERA, size=SIZE, outputs=("color", "depth", "normals", "ids"),
                        msaa=msaa, **kwargs)


def near_an_edge(ids, reach=1):
    """Pixels within `reach` pixels (in x and y) of a pixel showing other ids: triangle edges
    and the silhouette."""
    key = ids[..., 0].astype(np.int64) * 2**40 + ids[..., 1].astype(np.int64) * 2**20 + ids[..., 2]
    h, w = key.shape
    padded = np.pad(key, reach, mode="edge")
    edge = np.zeros((h, w), dtype=bool)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            shifted = padded[reach + dy:reach + dy + h, reach + dx:reach + dx + w]
            edge |= shifted != key
    return edge


@pytest.mark.parametrize("msaa", [4, 8])
def test_multisampling_changes_colour_only_at_edges(msaa):
    scene = tilted_quad()
    one = render(scene, 1)
    many = render(scene, msaa)
    edges = near_an_edge(one["ids"])
    changed = (many["color"] != one["color"]).any(axis=-1)
    # The slanted silhouette is antialiased: many pixels change, each next to an edge.
    assert changed.sum() > 50, changed.sum()
    assert not (changed & ~edges).any(), np.argwhere(changed & ~edges)[:5]
    # Partly covered silhouette pixels lie between the background and the quad's colour.
    covered = one["ids"][..., 2] > 0
    inside_value = one["color"][covered][:, 0].max()
    partial = many["color"][..., 0][changed & ~covered]
    assert ((partial > 0) & (partial < inside_value)).any()


@pytest.mark.parametrize("msaa", [4, 8])
def test_depth_normals_and_ids_at_msaa_equal_the_1x_ones(msaa):
    scene = tilted_quad()
    one = render(scene, 1)
    many = render(scene, msaa)
    np.testing.assert_array_equal(many["depth"], one["depth"])
    np.testing.assert_array_equal(many["normals"], one["normals"])
    np.testing.assert_array_equal(many["ids"], one["ids"])


def test_render_many_takes_msaa_and_switching_back_to_1x_restores_the_picture():
    scene = tilted_quad()
    one = render(scene, 1)
    [four] = scene.render_many([CAMERA], size=SIZE, outputs=("color",), msaa=4)
    assert (four["color"] != one["color"]).any()
    np.testing.assert_array_equal(render(scene, 4)["color"], four["color"])
    # The scene's cached backend is reused: a later 1x render is 1x again.
    np.testing.assert_array_equal(render(scene, 1)["color"], one["color"])


@pytest.mark.parametrize("msaa", [0, 2, 3, 16, -4, 2**40])
def test_an_unsupported_sample_count_is_a_one_line_value_error(msaa):
    scene = tilted_quad()
    with pytest.raises(ValueError, match=r"msaa: unsupported sample count -?\d+ \(expected 1, 4 or 8\)") as e:
        render(scene, msaa)
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="msaa"):
        scene.render_many([CAMERA], msaa=msaa)


def test_the_ray_renderer_passes_msaa_on(tmp_path):
    # Renderer.render_rows is plain Python: no Ray needed to check what it renders.
    from kantele.ray import Renderer

    path = tmp_path / "quad.obj"
    # Both windings: one side or the other faces every orbit camera.
    path.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\nf 1 3 2\nf 1 4 3\n")
    batch = {"scene": np.array([str(path)]), "views": np.array([3]), "view": np.array([1])}
    scene = kantele.load(path)
    camera = scene.orbit_cameras(3, size=SIZE)[1]
    for msaa in (1, 4):
        [(_, view, _, arrays)] = Renderer(SIZE, outputs=("color",), msaa=msaa).render_rows(batch)
        expected = scene.render(camera=camera, size=SIZE, outputs=("color",), msaa=msaa)
        assert view == 1
        np.testing.assert_array_equal(arrays["color"], expected["color"])
    one = Renderer(SIZE, outputs=("color",)).render_rows(batch)[0][3]["color"]
    four = Renderer(SIZE, outputs=("color",), msaa=4).render_rows(batch)[0][3]["color"]
    assert (one[..., :3] > 0).any(), "the quad is in view"
    assert (one != four).any()
