"""A pose's strain is measured only on the triangles it moves (issue 51: the set-up and the
synthesis measure every pose's strain, and most poses move a small part of the face); the
still triangles take the neutral face's values. Every array must equal, bit for bit, the
strain measured on every triangle, on a hand-made head in millimetres, Z up, far from the
origin, its UVs on the second UDIM tile, welded along a seam."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.skin_strain import SkinStrain, UvStrain

pytestmark = pytest.mark.core


def _head(n: int = 40) -> FaceMesh:
    """A dome of n × n vertices, 160 mm wide, Z up at (250, −40, 1600), UVs u ∈ [1, 2], its
    last column a UV seam (every other triangle's corners there are second vertices, welded
    to the first)."""
    s, t = np.meshgrid(np.linspace(-1.0, 1.0, n), np.linspace(-1.0, 1.0, n))
    dome = np.c_[80.0 * s.ravel(), -50.0 * (1.0 - 0.4 * (s * s + t * t)).ravel(),
                 100.0 * t.ravel()] + [250.0, -40.0, 1600.0]
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = (idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(),
                  idx[1:, :-1].ravel())
    triangles = np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    uvs = np.c_[1.0 + (s.ravel() + 1.0) / 2.0, (t.ravel() + 1.0) / 2.0]
    # the seam: every other triangle's corners on the last column are new vertices, welded
    seam = idx[:, -1]
    extra = np.arange(n * n, n * n + n)
    uvs = np.r_[uvs, uvs[seam] + [0.01, 0.0]]
    weld = np.r_[np.arange(n * n), seam]
    triangles = np.where(np.isin(triangles, seam) & (np.arange(len(triangles)) % 2 == 0)[:, None],
                         extra[np.searchsorted(seam, triangles).clip(0, n - 1)], triangles)
    return FaceMesh(dome.astype(np.float32), triangles, uvs.astype(np.float32), weld)


def _brow_raise(mesh: FaceMesh) -> np.ndarray:
    """The top fifth lifted and squeezed, fading out; a few vertices moved by a float's last
    bit only (they still count as moved)."""
    rest = mesh.rest.astype(np.float64)
    top = np.clip((rest[:, 2] - 1660.0) / 40.0, 0.0, 1.0)
    posed = rest.copy()
    posed[:, 2] += 6.0 * top
    posed[:, 0] = 250.0 + (rest[:, 0] - 250.0) * (1.0 - 0.15 * top)
    posed = posed.astype(np.float32)
    posed[5] = np.nextafter(posed[5], np.float32(np.inf))
    return posed


def test_a_pose_s_strain_on_the_skin_it_moves_equals_it_measured_everywhere():
    mesh = _head()
    strain = UvStrain(mesh)
    posed = _brow_raise(mesh)
    moved = strain.moved(posed)
    assert 0 < moved.sum() < 0.4 * len(moved)  # the shortcut is taken on most triangles
    got = strain.of(posed)
    everywhere = strain._strain(posed, slice(None))  # every triangle measured
    for name in ("compression", "wave", "anisotropy", "stretch"):
        np.testing.assert_array_equal(getattr(got, name), getattr(everywhere, name), name)
    assert got.compression.max() > 0.1  # the brow's squeeze is there
    skin = SkinStrain(mesh, np.ones(mesh.n_welded))
    np.testing.assert_array_equal(skin.of(posed).compression, everywhere.compression)
    np.testing.assert_array_equal(strain.of(mesh.rest).compression,
                                  strain._strain(mesh.rest, slice(None)).compression)
