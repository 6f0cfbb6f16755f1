"""The rules that pick which triangles the wrinkle program draws, each on its own case.

A triangle wrongly left out loses its wrinkles on screen; one wrongly kept only costs time, so
each rule is checked both ways: texel boxes that share only an edge do not touch (the boxes are
end-exclusive), boxes that overlap by one texel do, on either axis, with tall and wide boxes so
that x and y are never confused; a triangle counts as moved or flagged through any one of its
corners or coordinates.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.draw_split import any_corner, boxes_touch, moved, nearest_first

pytestmark = pytest.mark.core

AREA = np.array([[10, 20, 14, 30]])  # x0, y0, x1, y1: 4 wide, 10 tall


@pytest.mark.parametrize(
    ("box", "touches"),
    [
        ((14, 22, 16, 24), False),  # starts where the area ends in x
        ((8, 22, 10, 24), False),  # ends where the area starts in x
        ((13, 22, 16, 24), True),  # one texel column shared
        ((8, 22, 11, 24), True),
        ((11, 30, 12, 33), False),  # starts where the area ends in y
        ((11, 17, 12, 20), False),  # ends where the area starts in y
        ((11, 29, 12, 33), True),
        ((11, 17, 12, 21), True),
        ((15, 25, 17, 27), False),  # beyond x1 = 14 but inside y: the x end is x1, not y1
        ((11, 31, 12, 33), False),  # beyond y1 = 30, within x
        ((2, 21, 11, 29), True),
    ],
)
def test_a_triangles_box_touches_an_area_only_where_they_share_texels(box, touches) -> None:
    assert boxes_touch(np.array([box]), AREA).tolist() == [[touches]]


def test_an_empty_area_touches_nothing() -> None:
    empty = np.array([[10, 20, 10, 30], [10, 20, 9, 30]])  # no width; negative width
    assert not boxes_touch(np.array([[0, 0, 50, 50]]), empty).any()
    flat = np.array([[10, 20, 14, 20]])  # no height, but a width: the box test alone refuses
    assert not boxes_touch(np.array([[11, 21, 12, 22]]), flat).any()


def test_any_flagged_corner_flags_the_triangle() -> None:
    triangles = np.array([[0, 1, 2], [3, 0, 4], [4, 5, 1], [5, 4, 3]])
    for corner in range(6):
        flags = np.zeros(6, bool)
        flags[corner] = True
        expected = [(triangles[t] == corner).any() for t in range(4)]
        assert any_corner(triangles, flags).tolist() == expected


def test_a_vertex_moved_along_any_one_axis_has_moved() -> None:
    rest = np.zeros((4, 3), np.float32)
    positions = rest.copy()
    positions[1, 0] = 1e-7
    positions[2, 1] = -3.0
    positions[3, 2] = 0.5
    assert moved(positions, rest).tolist() == [False, True, True, True]


def test_equal_depths_keep_the_mesh_order() -> None:
    view = np.eye(4)  # looking down -z: larger z is nearer
    centroids = np.array([[0, 0, -5.0], [1, 0, -1.0], [2, 0, -5.0], [3, 0, -1.0], [0, 0, -3.0]])
    assert nearest_first(centroids, view).tolist() == [1, 3, 4, 0, 2]
