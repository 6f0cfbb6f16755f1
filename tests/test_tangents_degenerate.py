"""Per-vertex tangents where Lengyel's method has nothing or almost nothing to go on.

A scanned head brings triangles whose UVs collapse to a point, normals that lean almost onto
the UV direction, and mirrored UV islands next to those. The shader needs a unit tangent
perpendicular to the normal everywhere (or the normal map turns to noise there), the mirrored
side's handedness must survive its neighbours' fallbacks, and a tangent that is nearly but not
quite along the normal is still the Gram–Schmidt one (Eq. 4.9), not the fallback.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.geometry import vertex_tangents

pytestmark = pytest.mark.core

TRIANGLE = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float64)
UVS = np.array([[0, 0], [1, 0], [0, 1]], np.float64)  # u along +x, v along +y
UP = np.tile([0.0, 0.0, 1.0], (3, 1))


def test_u_along_x_gives_tangent_x_and_mirrored_uvs_flip_the_handedness() -> None:
    tangents = vertex_tangents(TRIANGLE, UVS, np.array([[0, 1, 2]]), UP)
    assert np.allclose(tangents, [[1, 0, 0, 1]] * 3)
    mirrored = UVS * [1, -1]  # v runs down the triangle: handedness −1
    assert np.allclose(vertex_tangents(TRIANGLE, mirrored, np.array([[0, 1, 2]]), UP)[:, 3], -1)


def test_uvs_collapsed_to_a_point_get_a_perpendicular_tangent_and_their_neighbours_keep_theirs():
    """Two triangles apart: a mirrored one (w = −1) and one whose UVs are all the same point
    (no tangent at all): the latter gets a unit tangent perpendicular to z with w = +1; the
    former keeps w = −1."""
    positions = np.concatenate([TRIANGLE, np.add(TRIANGLE, [5, 0, 0])])
    uvs = np.concatenate([UVS * [1, -1], np.full((3, 2), 0.5)])
    tangents = vertex_tangents(
        positions, uvs, np.array([[0, 1, 2], [3, 4, 5]]), np.tile(UP, (2, 1))
    )
    assert np.allclose(tangents[:3], [[1, 0, 0, -1]] * 3)
    fallback = tangents[3:]
    assert np.allclose(np.linalg.norm(fallback[:, :3], axis=1), 1.0)
    assert np.allclose(fallback[:, :3] @ [0, 0, 1], 0.0)
    assert np.allclose(fallback[:, 3], 1.0)


def test_a_tangent_along_the_normal_falls_back_to_a_perpendicular_one() -> None:
    along_x = np.tile([1.0, 0.0, 0.0], (3, 1))
    tangents = vertex_tangents(TRIANGLE, UVS, np.array([[0, 1, 2]]), along_x)
    assert np.allclose(tangents[:, :3] @ [1, 0, 0], 0.0)
    assert np.allclose(np.linalg.norm(tangents[:, :3], axis=1), 1.0)
    assert np.allclose(tangents[:, 3], 1.0)


def test_a_tangent_nearly_along_the_normal_is_still_gram_schmidt() -> None:
    """The normal leans to within 0.001 rad of the UV direction: T − (N·T)N is short but
    real, and points down −z; the fallback would point up."""
    n = np.array([1.0, 0.0, 1e-3]) / np.hypot(1.0, 1e-3)
    tangents = vertex_tangents(TRIANGLE, UVS, np.array([[0, 1, 2]]), np.tile(n, (3, 1)))
    t = np.array([1.0, 0.0, 0.0])
    expected = t - (n @ t) * n
    expected /= np.linalg.norm(expected)
    assert expected[2] < -0.99
    assert np.allclose(tangents[:, :3], expected, atol=1e-6)
