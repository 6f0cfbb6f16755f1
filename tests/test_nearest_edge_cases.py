"""Nearest-point search at its edges: coincident points (a UV seam's split vertices), one
point, no query, queries far outside the cloud, integer input.

``test_selection`` compares a random cloud with brute force; these are the cases a real mesh
brings that a random cloud does not. Coincident vertices must resolve to the first of them, so
a mirror map or a snapped pick is the same on every run and every machine.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh import selection as sel

pytestmark = pytest.mark.core


def brute_force(points: np.ndarray, queries: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.linalg.norm(queries[:, None, :] - points[None, :, :], axis=2)
    return d.argmin(axis=1), d.min(axis=1)  # argmin: the first of equals


def test_coincident_points_resolve_to_the_first_of_them() -> None:
    rng = np.random.default_rng(3)
    base = rng.uniform(-1.0, 1.0, (40, 3))
    points = np.concatenate([base, base, base])  # every vertex split twice, like a seam
    index, dist = sel.nearest_neighbours(points, base + 1e-9)
    assert np.array_equal(index, np.arange(40))
    assert np.allclose(dist, np.sqrt(3) * 1e-9)


def test_a_single_point_answers_every_query() -> None:
    points = np.array([[0.5, -2.0, 3.0]])
    queries = np.array([[0.5, -2.0, 3.0], [10.0, 0.0, 0.0], [-400.0, 7.0, 1.0]])
    index, dist = sel.nearest_neighbours(points, queries)
    assert index.tolist() == [0, 0, 0]
    assert np.allclose(dist, np.linalg.norm(queries - points, axis=1))


def test_no_queries_gives_empty_answers() -> None:
    index, dist = sel.nearest_neighbours(np.eye(3), np.zeros((0, 3)))
    assert index.shape == (0,) and dist.shape == (0,)
    assert index.dtype == np.int64


@pytest.mark.parametrize("scale", [1e-3, 1.0, 250.0])
def test_far_queries_on_any_scale_match_brute_force(scale: float) -> None:
    rng = np.random.default_rng(11)
    points = rng.normal(size=(50, 3)) * scale
    queries = np.concatenate(
        [
            rng.normal(size=(20, 3)) * scale * 40.0,  # far outside the cloud
            points[:5] * 1.0001,
        ]
    )
    index, dist = sel.nearest_neighbours(points, queries)
    expected_index, expected_dist = brute_force(points, queries)
    assert np.array_equal(index, expected_index)
    assert np.allclose(dist, expected_dist, rtol=1e-12)


def test_integer_coordinates_are_measured_as_floats() -> None:
    points = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 0]])
    queries = np.array([[1, 1, 0], [3, 4, 0]])
    index, dist = sel.nearest_neighbours(points, queries)
    assert index.tolist() == [0, 2]
    assert dist.dtype == np.float64
    assert np.allclose(dist, [np.sqrt(2), 3.0])
