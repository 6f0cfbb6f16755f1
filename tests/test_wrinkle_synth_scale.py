"""Synthesised furrows sized to the face, and laid over the neutral map's own detail.

``face_options`` turns "furrows 2 % of the face apart" into texels through the skin's UV
density: a face in millimetres or metres, with its skin over a whole tile or packed into half
of one, must get furrows the same share of its skin apart, and triangles that are not skin (an
eye, a tooth) must not count. ``over_base`` is the whiteout blend of the furrows over the
neutral map: texels without furrows keep the neutral's exact values, whatever its bit depth
or size. Expected values are worked out by hand from the flat test face (the square
[-1, 1]² with UVs over [0, 1]²: UV area / surface area = 1/4, diagonal 2√2).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.setup import wrinkle_synth as synth
from tests.test_auto_setup import grid_mesh

pytestmark = pytest.mark.core


def project_of(mesh: FaceMesh, skin: np.ndarray | None = None) -> SimpleNamespace:
    """What ``face_options`` reads of a project: its mesh and its per-vertex skin weights."""
    weights = np.ones(len(mesh.rest), np.float32) if skin is None else skin
    return SimpleNamespace(mesh=mesh, skin_weights=lambda: weights)


def scaled(mesh: FaceMesh, factor: float, uv_scale: float = 1.0) -> FaceMesh:
    return FaceMesh(
        mesh.rest * np.float32(factor), mesh.triangles, mesh.uvs * np.float32(uv_scale), mesh.weld
    )


def test_furrow_spacing_is_a_share_of_the_face_in_texels() -> None:
    # texels per unit = 1024 · √(1/4) = 512; spacing = FURROW_SPACING · 2√2 · 512
    options = synth.face_options(project_of(grid_mesh()), 1024)
    assert options.size == 1024
    assert options.spacing == pytest.approx(synth.FURROW_SPACING * 2 * np.sqrt(2) * 512, rel=1e-5)
    assert options.depth == pytest.approx(synth.DEPTH_PER_SPACING * options.spacing, rel=1e-6)


@pytest.mark.parametrize("units", [0.001, 1.0, 1000.0])
def test_the_same_face_in_any_unit_gets_the_same_furrows(units: float) -> None:
    options = synth.face_options(project_of(scaled(grid_mesh(), units)), 1024)
    assert options.spacing == pytest.approx(synth.FURROW_SPACING * 2 * np.sqrt(2) * 512, rel=1e-4)


def test_skin_packed_into_half_the_tile_gets_furrows_half_as_many_texels_apart() -> None:
    options = synth.face_options(project_of(scaled(grid_mesh(), 1.0, 0.5)), 1024)
    assert options.spacing == pytest.approx(synth.FURROW_SPACING * 2 * np.sqrt(2) * 256, rel=1e-5)


def test_triangles_that_are_not_skin_do_not_count() -> None:
    """The left half is an eye (skin weight 0): the skin is the right half, [0, 1] × [-1, 1],
    diagonal √5, with the same UV density."""
    mesh = grid_mesh()
    skin = (mesh.rest[:, 0] >= 0.0).astype(np.float32)
    options = synth.face_options(project_of(mesh, skin), 1024)
    assert options.spacing == pytest.approx(synth.FURROW_SPACING * np.sqrt(5) * 512, rel=1e-5)


def test_spacing_stays_between_three_texels_and_an_eighth_of_the_map() -> None:
    assert synth.face_options(project_of(grid_mesh()), 64).spacing == 3.0  # 1.81 by the share
    # a long thin strip with a square's UVs: 100 units long, 0.01 wide, UV area 1/2 each way
    rest = np.array([[0, 0, 0], [100, 0, 0], [100, 0.01, 0], [0, 0.01, 0]], np.float32)
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    strip = FaceMesh(rest, np.array([[0, 1, 2], [0, 2, 3]]), uvs, np.arange(4))
    options = synth.face_options(project_of(strip), 1024)
    assert options.spacing == 1024 / 8 and options.depth == synth.DEPTH_PER_SPACING * 128


def test_a_face_without_usable_skin_gets_the_default_options() -> None:
    mesh = grid_mesh()
    none = synth.face_options(project_of(mesh, np.zeros(len(mesh.rest), np.float32)), 512)
    assert none == synth.SynthOptions(size=512)
    flat_uvs = FaceMesh(mesh.rest, mesh.triangles, np.zeros_like(mesh.uvs), mesh.weld)
    assert synth.face_options(project_of(flat_uvs), 512) == synth.SynthOptions(size=512)


# --- the whiteout blend ----------------------------------------------------------------------


def decode(image: np.ndarray) -> np.ndarray:
    top = 65535.0 if image.dtype == np.uint16 else 255.0
    return image.astype(np.float64) / top * 2.0 - 1.0


def reoriented(detail: np.ndarray, base: np.ndarray) -> np.ndarray:
    """Reoriented normal mapping, t·(t·u)/t.z − u with t = b + (0, 0, 1) and
    u = d·(−1, −1, 1), normalised: the formula the docstring names."""
    t = base + np.array([0.0, 0.0, 1.0])
    u = detail * np.array([-1.0, -1.0, 1.0])
    n = t * (t @ u) / t[2] - u
    return n / np.linalg.norm(n)


def test_furrows_blend_over_the_base_and_flat_texels_keep_it_exactly() -> None:
    detail = np.full((2, 2, 3), (128, 128, 255), np.uint8)  # flat: no furrow
    detail[0, 1] = (90, 170, 230)
    base = np.array(
        [[[160, 128, 240], [150, 100, 245]], [[128, 128, 255], [60, 200, 220]]], np.uint8
    )
    out = synth.over_base(detail, base)
    assert out.dtype == np.uint8
    for texel in [(0, 0), (1, 0), (1, 1)]:
        assert out[texel].tolist() == base[texel].tolist()
    expected = reoriented(decode(detail[0, 1]), decode(base[0, 1]))
    assert np.abs(decode(out[0, 1]) - expected).max() <= 1.0 / 255


def test_a_sixteen_bit_base_of_another_size_is_converted_and_resized() -> None:
    detail = np.full((4, 4, 3), (128, 128, 255), np.uint8)
    detail[3, 0] = (200, 128, 220)
    base = np.zeros((2, 2, 3), np.uint16)
    base[...] = (32768, 32768, 65535)
    base[1, 0] = (20000, 45000, 60000)  # covers texels (2..3, 0..1) once resized
    out = synth.over_base(detail, base)
    assert out.shape == (4, 4, 3) and out.dtype == np.uint8
    as_8_bits = np.floor((decode(base[1, 0]) * 0.5 + 0.5) * 255 + 0.5)
    for texel in [(2, 0), (2, 1), (3, 1)]:
        assert out[texel].tolist() == as_8_bits.tolist()
    assert out[0, 0].tolist() == [128, 128, 255]
    expected = reoriented(decode(detail[3, 0]), decode(as_8_bits.astype(np.uint8)))
    assert np.abs(decode(out[3, 0]) - expected).max() <= 1.0 / 255
