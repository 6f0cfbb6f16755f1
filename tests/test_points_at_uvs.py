"""Surface points at UV positions: the landmarks (forehead, eye corners, chin) that the render
tests and the benchmark measure regions around are found this way on any mesh.

Hand-built meshes: a UV square mapped onto a 3-D quad folded along its diagonal (so a point
taken from the wrong triangle lands off the surface), where each point is known in closed
form, and the same square with a degenerate (zero-area) UV triangle laid over it, which must
never be the one chosen.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.sample.synthetic import _points_at_uvs

pytestmark = pytest.mark.core

# a unit UV square on a quad folded along the diagonal from corner 0 to corner 2
UVS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], np.float32)
REST = np.array([[0, 0, 0], [2, 0, 1], [2, 3, 4], [0, 3, 1]], np.float32)
SQUARE = np.array([[0, 1, 2], [0, 2, 3]], np.int32)


def expected(uv: np.ndarray) -> np.ndarray:
    """x = 2u and y = 3v on both halves; z = u + 3v below the diagonal (u ≥ v, the triangle
    0-1-2) and 3u + v above it (the triangle 0-2-3)."""
    u, v = uv[:, 0], uv[:, 1]
    return np.stack([2 * u, 3 * v, np.where(u >= v, u + 3 * v, 3 * u + v)], axis=1)


QUERIES = np.array([[0.25, 0.1], [0.1, 0.8], [0.5, 0.5], [0.9, 0.3], [0.0, 0.0]])


def test_points_inside_either_triangle_are_exact() -> None:
    mesh = FaceMesh(REST, SQUARE, UVS, np.arange(4, dtype=np.int32))
    assert np.allclose(_points_at_uvs(mesh, QUERIES), expected(QUERIES), atol=1e-6)


def test_a_triangle_with_no_uv_area_is_never_chosen() -> None:
    # a fifth render vertex far away in 3-D, on the UV square's diagonal: the sliver
    # (0, 2, 4) has zero UV area, and its barycentrics would be nonsense
    rest = np.concatenate([REST, [[50.0, 50.0, 50.0]]]).astype(np.float32)
    uvs = np.concatenate([UVS, [[0.5, 0.5]]]).astype(np.float32)
    triangles = np.array([[0, 2, 4], *SQUARE], np.int32)
    mesh = FaceMesh(rest, triangles, uvs, np.arange(5, dtype=np.int32))
    assert np.allclose(_points_at_uvs(mesh, QUERIES), expected(QUERIES), atol=1e-6)


def test_a_uv_outside_the_layout_takes_the_nearest_triangle() -> None:
    mesh = FaceMesh(REST, SQUARE, UVS, np.arange(4, dtype=np.int32))
    # just right of the square: extrapolated from the triangle it is closest to containing
    found = _points_at_uvs(mesh, np.array([[1.1, 0.2]]))
    assert np.allclose(found, expected(np.array([[1.1, 0.2]])), atol=1e-6)
