"""The normal-map baker's parts, each against a reference worked out without it.

The baker casts a line from each texel of the low face along its normal and takes the nearest
hit on the high mesh whose normal faces the same way; a wrong hit is a wrong detail in the
map, so the grid search is compared with brute force over every triangle, on random triangles
in every orientation (a flat test sheet hides terms of the intersection that vanish in a
plane). The tangent-space conversion must invert the frame the shader builds, for skewed and
mirrored frames too, and tip a normal that faces away just above the surface; the encoding
must hit the exact 8- and 16-bit codes.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.bake import (
    _MIN_Z,
    _to_tangent_space,
    _TriangleGrid,
    default_max_distance,
    encode_normals,
)

pytestmark = pytest.mark.core


def brute_force_hits(positions, triangles, normals, origin, direction, reach):
    """Per line: the nearest |t| ≤ reach hit whose interpolated normal faces along the line."""
    best_tri = np.full(len(origin), -1)
    best_bary = np.zeros((len(origin), 3))
    for i, (o, d) in enumerate(zip(origin, direction, strict=True)):
        best = np.inf
        for f, (a, b, c) in enumerate(positions[triangles]):
            m = np.column_stack([b - a, c - a, -d])
            if abs(np.linalg.det(m)) < 1e-12:
                continue
            u, v, t = np.linalg.solve(m, o - a)
            bary = np.array([1 - u - v, u, v])
            if bary.min() < 0 or abs(t) > reach or abs(t) >= best:
                continue
            if bary @ normals[triangles[f]] @ d <= 0:
                continue
            best, best_tri[i], best_bary[i] = abs(t), f, bary
    return best_tri, best_bary


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_grid_finds_the_nearest_facing_hit_like_brute_force(seed: int) -> None:
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (80, 1, 3))
    positions = (centres + rng.normal(scale=0.3, size=(80, 3, 3))).reshape(-1, 3)
    triangles = np.arange(240).reshape(80, 3)
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    face_normals = np.cross(b - a, c - a)
    normals = np.repeat(face_normals / np.linalg.norm(face_normals, axis=1)[:, None], 3, axis=0)
    origin = rng.uniform(-1.0, 1.0, (60, 3))
    direction = rng.normal(size=(60, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    reach = 1.0
    grid = _TriangleGrid(positions, triangles, reach)
    tri, bary = grid.nearest_hits(origin, direction, normals, reach)
    expected_tri, expected_bary = brute_force_hits(
        positions, triangles, normals, origin, direction, reach
    )
    assert (tri >= 0).sum() >= 10  # the case is not empty
    assert tri.tolist() == expected_tri.tolist()
    assert np.allclose(bary, expected_bary, atol=1e-9)


def frame(t, b, n):
    return (np.atleast_2d(np.asarray(v, np.float64)) for v in (t, b, n))


@pytest.mark.parametrize(
    ("t", "b", "n"),
    [
        ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
        ((1, 0, 0), (0.5, 1, 0), (0, 0.2, 1)),  # skewed, as interpolation leaves it
        ((1, 0, 0), (0, -1, 0), (0, 0, 1)),  # a mirrored UV island
        ((0, 0, 2), (0, 3, 0.3), (-1, 0.1, 0)),  # rotated, not unit
    ],
)
def test_tangent_space_inverts_the_shaders_frame(t, b, n) -> None:
    world = np.array([[0.3, -0.2, 0.9], [-0.5, 0.4, 0.7], [0.1, 0.6, 0.79]])
    world /= np.linalg.norm(world, axis=1)[:, None]
    t3, b3, n3 = (np.repeat(v, 3, axis=0) for v in frame(t, b, n))
    local = _to_tangent_space(world, t3, b3, n3)
    assert np.allclose(np.linalg.norm(local, axis=1), 1.0)
    rebuilt = t3 * local[:, :1] + b3 * local[:, 1:2] + n3 * local[:, 2:]
    rebuilt /= np.linalg.norm(rebuilt, axis=1)[:, None]
    facing = local[:, 2] > _MIN_Z
    assert facing.any()
    assert np.allclose(rebuilt[facing], world[facing], atol=1e-9)


def test_a_normal_facing_away_is_tipped_just_above_the_surface() -> None:
    t, b, n = frame((1, 0, 0), (0, 1, 0), (0, 0, 1))
    world = np.array([[0.6, 0.0, -0.8], [0.0, -0.6, -0.8], [0.0, 0.0, 1.0]])
    local = _to_tangent_space(world, *(np.repeat(v, 3, axis=0) for v in (t, b, n)))
    side = np.sqrt(1 - _MIN_Z**2)
    assert np.allclose(
        local, [[side, 0, _MIN_Z], [0, -side, _MIN_Z], [0, 0, 1]], rtol=0, atol=1e-12
    )


def test_normals_encode_to_the_exact_codes() -> None:
    normals = np.array([[0.0, 0.0, 1.0], [-1.0, 1.0, 0.0], [1.2, -1.2, 0.5]])
    assert encode_normals(normals).tolist() == [[128, 128, 255], [0, 255, 128], [255, 0, 191]]
    sixteen = encode_normals(normals, bits=16)
    assert sixteen.dtype == np.uint16
    assert sixteen.tolist() == [[32768, 32768, 65535], [0, 65535, 32768], [65535, 0, 49151]]


def test_the_default_reach_is_a_share_of_the_face() -> None:
    rest = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 12]], np.float32)
    mesh = FaceMesh(rest, np.array([[0, 1, 2]]), np.zeros((3, 2), np.float32), np.arange(3))
    assert default_max_distance(mesh) == pytest.approx(0.02 * 13)
    point = FaceMesh(np.ones((3, 3), np.float32), mesh.triangles, mesh.uvs, mesh.weld)
    assert default_max_distance(point) == pytest.approx(0.02)
