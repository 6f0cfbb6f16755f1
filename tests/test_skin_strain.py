"""Principal skin strain, worked out by hand on a flat grid (tests/test_auto_setup.py's)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.skin_strain import WRINKLING_COMPRESSION, SkinStrain, compression_weights
from tests.test_auto_setup import grid_mesh

pytestmark = pytest.mark.core


def rotation_z(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def test_a_sideways_squeeze_that_keeps_the_area_is_compression():
    """x → 0.9·x, y → y / 0.9: the area stays, the skin shortens by 10 % along x — a frown's
    squeeze between the brows. Every triangle: compression 0.1, largest stretch 1/0.9 − 1."""
    mesh = grid_mesh()
    squeezed = mesh.rest * np.float32([0.9, 1 / 0.9, 1.0])
    strain = SkinStrain(mesh).of(squeezed)
    np.testing.assert_allclose(strain.compression, 0.1, atol=1e-5)
    np.testing.assert_allclose(strain.stretch, 1 / 0.9 - 1, atol=1e-5)
    # the furrows' wave vector runs along x (the image's u), across the furrows
    np.testing.assert_allclose(np.abs(strain.wave[:, 0]), 1.0, atol=1e-5)


def test_rigid_motion_and_pure_stretch_compress_nothing_and_say_so():
    mesh = grid_mesh()
    skin = SkinStrain(mesh)
    turned = mesh.rest @ rotation_z(35).T.astype(np.float32) + np.float32([3, -2, 1])
    strain = skin.of(turned)
    assert strain.compression.max() < 1e-5
    summary = skin.summary(strain, moved=0.5)
    assert not summary.compresses and "without deforming" in summary.describe()
    stretched = mesh.rest * np.float32([1.2, 1.0, 1.0])
    summary = skin.summary(skin.of(stretched), moved=0.1)
    assert not summary.compresses and "only stretches the skin (up to 20 %" in summary.describe()
    assert not compression_weights(skin, skin.of(stretched).compression).any()
    assert skin.summary(skin.of(mesh.rest), moved=0.0).describe() == "moves no skin"


def test_the_summary_measures_the_compressed_share_and_where():
    mesh = grid_mesh()  # [-1, 1]²: squeeze the left half only, by 10 % along x
    posed = mesh.rest.copy()
    posed[:, 0] = np.where(mesh.rest[:, 0] < 0, mesh.rest[:, 0] * 0.9, mesh.rest[:, 0])
    skin = SkinStrain(mesh)
    summary = skin.summary(skin.of(posed), moved=0.1)
    assert summary.compresses
    assert summary.peak_compression == pytest.approx(0.1, abs=1e-5)
    assert summary.compressed_share == pytest.approx(0.5, abs=1e-6)
    np.testing.assert_allclose(summary.centre, [-0.5, 0.0, 0.0], atol=1e-6)


def test_not_skin_triangles_and_weak_poses_are_left_out():
    mesh = grid_mesh()
    not_skin = mesh.rest[:, 1] > 0.5
    skin = SkinStrain(mesh, ~not_skin)
    squeezed = mesh.rest * np.float32([0.9, 1.0, 1.0])
    weights = compression_weights(skin, skin.of(squeezed).compression)
    assert not weights[not_skin].any()
    assert weights[mesh.rest[:, 1] < 0.3].min() == pytest.approx(1.0, abs=1e-4)
    faint = mesh.rest * np.float32([1 - WRINKLING_COMPRESSION / 2, 1.0, 1.0])
    assert not compression_weights(skin, skin.of(faint).compression).any()
