"""Triangles that cannot show wrinkles are drawn with the plain program: hand-computed cases for
the split, and the picture identical to drawing every triangle with the technique's program."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.draw_split import (
    any_corner,
    boxes_touch,
    moved,
    nearest_first,
    triangle_texel_boxes,
    wrinkled_first,
)
from studio.core.wrinkles.influence import InfluenceArea
from studio.render.offscreen import OffscreenStudio
from studio.render.settings import RenderSettings

W, H = 400, 300


@pytest.mark.core
def test_a_triangles_texel_box_is_its_uv_footprint_grown_by_one_texel():
    uvs = np.array([[0.125, 0.875], [0.4375, 0.875], [0.125, 0.5625]])
    # on a 16 × 16 texture: x 2 … 7, rows (1 - v) * 16 = 2 … 7; end exclusive, one texel slack
    box = triangle_texel_boxes(uvs, np.array([[0, 1, 2]]), 16, 16)
    assert box.tolist() == [[1, 1, 9, 9]]


@pytest.mark.core
def test_boxes_touch_only_when_they_overlap():
    triangles = np.array([[0, 0, 5, 5], [5, 0, 8, 5], [0, 6, 2, 9]])
    areas = np.array([[4, 4, 6, 6],     # overlaps the first two, ends before the third's rows
                      [2, 2, 2, 2],     # empty: touches nothing
                      [1, 8, 3, 10]])   # only the third
    assert boxes_touch(triangles, areas).tolist() == [[True, True, False],
                                                      [False, False, False],
                                                      [False, False, True]]


@pytest.mark.core
def test_wrinkled_triangles_lead_the_order_each_group_in_mesh_order():
    triangles = np.arange(12).reshape(4, 3)
    flags = np.zeros(12, bool)
    flags[[4, 10]] = True
    wrinkled = any_corner(triangles, flags)
    assert wrinkled.tolist() == [False, True, False, True]
    ordered, count = wrinkled_first(triangles, wrinkled)
    assert count == 2
    assert ordered[:, 0].tolist() == [3, 9, 0, 6]


@pytest.mark.core
def test_nearest_first_and_wrinkled_first_keep_the_depth_order_in_each_group():
    centroids = np.array([[0, 0, -5.0], [0, 0, 1.0], [0, 0, -1.0], [0, 0, 3.0]])
    view = np.eye(4)
    view[2, 3] = -10.0  # a camera at z = 10 looking down -z: the largest z is nearest
    order = nearest_first(centroids, view)
    assert order.tolist() == [3, 1, 2, 0]
    triangles = np.arange(12).reshape(4, 3)
    ordered, count = wrinkled_first(triangles, np.array([True, False, True, False]), order)
    assert count == 2 and ordered[:, 0].tolist() == [6, 0, 9, 3]


@pytest.mark.core
def test_only_vertices_off_their_neutral_position_count_as_moved():
    rest = np.zeros((4, 3))
    positions = rest.copy()
    positions[1, 2] = 1e-12
    positions[3] = [0.5, -0.5, 0.0]
    assert moved(positions, rest).tolist() == [False, True, False, True]


@pytest.fixture
def studio(sample, gl_context):
    s = OffscreenStudio(sample, W, H, samples=0, ctx=gl_context)
    yield s
    s.release()


def both_ways(studio: OffscreenStudio, settings: RenderSettings) -> tuple[np.ndarray, np.ndarray]:
    """The frame drawn split, then with every triangle through the technique's program."""
    images = []
    for split in (True, False):
        studio.renderer.split_draws = split
        studio.renderer.render(studio.target.fbo, studio.camera, settings)
        images.append(studio.target.read())
    studio.renderer.split_draws = True
    return images[0], images[1]


def wrinkled_share(studio: OffscreenStudio, technique: str) -> float:
    settings = RenderSettings(technique=technique)
    return float(studio.renderer.face.wrinkled_triangles(settings).mean())


@pytest.mark.parametrize("technique", ["t2", "t1", "strain"])
def test_split_drawing_gives_the_same_picture_through_an_expression(studio, technique):
    none = studio.render(RenderSettings(technique="none"), {"surprise": 1.0})
    for weights in ({"surprise": 1.0}, {"surprise": 0.3, "squeeze": 0.8}, {"frown": 1.0}, {}):
        studio.scene.set_pose_weights(weights)
        split, whole = both_ways(studio, RenderSettings(technique=technique))
        assert np.array_equal(split, whole), weights
        if weights == {"surprise": 1.0}:
            assert not np.array_equal(split, none)  # the wrinkles are there
            assert 0.0 < wrinkled_share(studio, technique) < 0.6  # and most triangles are plain


def test_not_face_vertices_are_drawn_plain_with_the_same_picture(studio):
    project = studio.scene.project
    studio.scene.set_pose_weights({"surprise": 1.0})
    before = wrinkled_share(studio, "t2")
    project.not_face = project.mesh.rest[:, 1] > np.median(project.mesh.rest[:, 1])  # top half
    studio.renderer.set_skin(project.skin_weights())
    assert wrinkled_share(studio, "t2") < before
    split, whole = both_ways(studio, RenderSettings(technique="t2"))
    assert np.array_equal(split, whole)


def test_a_dab_in_an_empty_area_is_drawn_with_the_wrinkle_program(studio):
    """A new area starts empty (no triangle can show it); the first dab must move the triangles
    under it to the wrinkle program, or the painted wrinkles would not show."""
    project = studio.scene.project
    area = InfluenceArea("new", np.zeros_like(project.influence.areas[0].mask))
    area.activation = 1.0
    project.influence.areas.append(area)
    studio.scene.reload_masks()
    settings = RenderSettings(technique="t1")
    empty = studio.render(settings)
    h, w = area.mask.shape
    patch = np.ones((h // 5, w // 5), np.float32)
    x, y = w // 2 - w // 10, h // 5  # the forehead, in the UV layout
    area.mask[y:y + h // 5, x:x + w // 5] = patch
    studio.renderer.update_mask_region(len(project.influence.areas) - 1, x, y, patch)
    split, whole = both_ways(studio, settings)
    assert np.array_equal(split, whole)
    assert np.abs(split.astype(int) - empty.astype(int)).max(axis=2).astype(bool).sum() > 200


def test_the_index_buffer_is_rewritten_only_when_the_split_or_view_changes(studio, monkeypatch):
    writes = []
    ibo = studio.renderer.face.split.ibo
    original = ibo.write
    monkeypatch.setattr(ibo, "write", lambda data, **kw: (writes.append(1), original(data, **kw)))
    settings = RenderSettings(technique="t2")
    studio.render(settings, {"surprise": 1.0})
    first = len(writes)
    for weight in (0.5, 0.2, 0.8):  # the same vertices move: the same triangles can wrinkle
        studio.render(settings, {"surprise": weight})
    studio.camera.orbit(3.0, 0.0)  # a small turn keeps the depth order
    studio.render(settings, {"surprise": 1.0})
    assert len(writes) == first
    studio.render(settings, {"squeeze": 1.0})
    assert len(writes) == first + 1
    studio.camera.orbit(40.0, 0.0)
    studio.render(settings, {"squeeze": 1.0})
    assert len(writes) == first + 2


def test_triangles_are_drawn_nearest_first_for_the_view(studio):
    """Early depth testing skips the shading of hidden pixels only if the near surface is
    drawn first: the first triangles in the buffer are nearer the camera than the last."""
    studio.render(RenderSettings(technique="none"))
    order = np.frombuffer(studio.renderer.face.split.ibo.read(), np.int32).reshape(-1, 3)
    mesh = studio.scene.project.mesh
    view = studio.camera.view_matrix()
    depth = -(mesh.rest[mesh.weld][order].mean(axis=1) @ view[2, :3])
    tenth = len(depth) // 10
    assert depth[:tenth].max() <= depth[-tenth:].min()
