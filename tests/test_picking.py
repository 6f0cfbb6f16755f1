"""Ray casting against hand-placed triangles."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.picking import nearest_corner, ray_triangles

pytestmark = pytest.mark.core

# two unit squares' worth of triangles facing +Z, one at z=0 and one behind it at z=-1
POSITIONS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0],
                      [0, 0, -1], [1, 0, -1], [0, 1, -1]], np.float32)
TRIANGLES = np.array([[0, 1, 2], [3, 4, 5]])


def test_hit_is_the_nearest_triangle_with_exact_barycentrics():
    hit = ray_triangles([0.25, 0.25, 5.0], [0, 0, -1], POSITIONS, TRIANGLES)
    assert hit is not None and hit.triangle == 0
    np.testing.assert_allclose(hit.point, [0.25, 0.25, 0.0], atol=1e-9)
    np.testing.assert_allclose(hit.barycentric, [0.5, 0.25, 0.25], atol=1e-9)
    assert hit.distance == 5.0
    np.testing.assert_allclose(hit.interpolate(POSITIONS[TRIANGLES[0]]), hit.point, atol=1e-6)


def test_miss_and_behind_the_origin():
    assert ray_triangles([2.0, 2.0, 5.0], [0, 0, -1], POSITIONS, TRIANGLES) is None
    assert ray_triangles([0.2, 0.2, 5.0], [0, 0, 1], POSITIONS, TRIANGLES) is None


def test_back_faces_can_be_culled():
    from_behind = ([0.2, 0.2, -5.0], [0, 0, 1])
    assert ray_triangles(*from_behind, POSITIONS, TRIANGLES).triangle == 1
    assert ray_triangles(*from_behind, POSITIONS, TRIANGLES, cull_back_faces=True) is None


def test_degenerate_triangle_is_never_hit():
    flat = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], np.float32)
    assert ray_triangles([0.5, 0.0, 1.0], [0, 0, -1], flat, np.array([[0, 1, 2]])) is None


def test_nearest_corner():
    hit = ray_triangles([0.9, 0.05, 1.0], [0, 0, -1], POSITIONS, TRIANGLES)
    assert nearest_corner(hit) == 1


def test_the_triangles_edges_and_corners_are_hit_and_just_outside_is_not():
    for x, y in ((0.0, 0.5), (0.5, 0.0), (0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0)):
        hit = ray_triangles([x, y, 2.0], [0, 0, -1], POSITIONS, TRIANGLES[:1])
        assert hit is not None, (x, y)
        np.testing.assert_allclose(hit.point, [x, y, 0.0], atol=1e-9)
    for x, y in ((-0.01, 0.5), (0.5, -0.01), (0.5, 0.51)):
        assert ray_triangles([x, y, 2.0], [0, 0, -1], POSITIONS, TRIANGLES[:1]) is None


def test_the_nearest_hit_wins_whatever_the_triangle_order_and_the_origin_plane_is_not_hit():
    hit = ray_triangles([0.2, 0.2, 5.0], [0, 0, -1], POSITIONS, TRIANGLES[::-1])
    assert hit.triangle == 1 and hit.distance == 5.0  # the front one, listed second
    hit = ray_triangles([0.2, 0.2, 0.0], [0, 0, -1], POSITIONS, TRIANGLES)  # starts on z = 0
    assert hit.triangle == 1 and hit.distance == 1.0


def test_a_back_face_hit_has_the_same_barycentrics_and_scale_does_not_matter():
    hit = ray_triangles([0.25, 0.5, -0.5], [0, 0, 1], POSITIONS, TRIANGLES[:1])
    np.testing.assert_allclose(hit.barycentric, [0.25, 0.25, 0.5], atol=1e-9)
    assert hit.distance == 0.5
    for scale in (1e-4, 1e4):
        hit = ray_triangles(np.array([0.25, 0.25, 1.0]) * scale, [0, 0, -1], POSITIONS * scale,
                            TRIANGLES[:1])
        assert hit is not None and hit.distance == pytest.approx(scale)
        np.testing.assert_allclose(hit.barycentric, [0.5, 0.25, 0.25], atol=1e-6)
