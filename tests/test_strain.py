"""Strain-driven wrinkles: compression against hand-made cases and the sample's poses."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.sample.synthetic import make_test_face, sample_landmarks
from studio.core.wrinkles.strain import StrainField

pytestmark = pytest.mark.core


def strip() -> FaceMesh:
    """Two triangles: a unit square in the xy plane."""
    rest = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    tris = np.array([[0, 1, 2], [1, 3, 2]])
    return FaceMesh(rest, tris, rest[:, :2], np.arange(4))


def test_rest_pose_has_no_compression():
    mesh = strip()
    assert np.array_equal(StrainField(mesh).compression(mesh.rest), np.zeros(4, np.float32))


def test_squashing_by_half_gives_hand_computed_compression():
    mesh = strip()
    field = StrainField(mesh)
    squashed = mesh.rest * [0.5, 1.0, 1.0]  # x halves: horizontal edges compress by 0.5
    # edges: (0,1) horizontal 0.5; (0,2) vertical 0; (1,2) diagonal 1 - sqrt(1.25)/sqrt(2);
    # (1,3) vertical 0; (2,3) horizontal 0.5
    diag = 1.0 - np.sqrt(0.25 + 1.0) / np.sqrt(2.0)
    expected = np.array([(0.5 + 0) / 2, (0.5 + diag + 0) / 3, (0 + diag + 0.5) / 3,
                         (0 + 0.5) / 2])
    np.testing.assert_allclose(field.compression(squashed), expected, atol=1e-6)
    np.testing.assert_allclose(field.weights(squashed, full_at=0.25), np.minimum(expected / 0.25,
                                                                              1.0), atol=1e-6)


def test_stretching_shows_nothing():
    mesh = strip()
    assert StrainField(mesh).compression(mesh.rest * 2.0).max() == 0.0


def test_surprise_compresses_the_forehead_and_not_the_chin():
    project = make_test_face(2172, texture_size=16, mask_size=16)
    field = StrainField(project.mesh)
    weights = field.weights(project.pose("surprise").positions)
    marks = sample_landmarks(project)

    def near(name: str) -> float:
        d = np.linalg.norm(project.mesh.rest - marks[name], axis=1)
        return float(weights[d < 0.08].mean())

    assert near("forehead") > 0.2
    assert near("chin") == 0.0
    assert field.weights(project.mesh.rest).max() == 0.0
