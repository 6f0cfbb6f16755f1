"""Mirroring dabs through the mesh, on a symmetric surface whose UV layout is not symmetric.

The test surface is the flat strip z = 0, x ∈ [−1, 1], y ∈ [0, 1], cut at x = 0 into two UV
charts laid out differently, so every expected UV is a hand-computed affine map:

    left  (x ≤ 0), chart A:  u = 0.05 + 0.4·(x + 1),  v = 0.1 + 0.4·y   (0.4 UV per unit)
    right (x ≥ 0), chart B:  u = 0.6 + 0.2·y,         v = 0.9 − 0.2·x   (0.2 UV per unit, turned)

Mirroring in UV (u → 1 − u) would send a dab on the left anywhere but the right half's chart.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.brush import Brush, Stroke
from studio.core.wrinkles.surface_mirror import (
    SurfaceMirror,
    TriangleGrid,
    closest_on_triangles,
    footprint_ring,
)

pytestmark = pytest.mark.core

N = 4  # quads per unit along each axis


def uv_left(p: np.ndarray) -> np.ndarray:
    return np.array([0.05 + 0.4 * (p[0] + 1.0), 0.1 + 0.4 * p[1]])


def uv_right(p: np.ndarray) -> np.ndarray:
    return np.array([0.6 + 0.2 * p[1], 0.9 - 0.2 * p[0]])


def strip() -> FaceMesh:
    """The strip, triangulated differently on each side (diagonals one way on the left, the
    other way on the right), so the mirror cannot lean on matching triangles either."""
    xs = np.linspace(-1.0, 1.0, 2 * N + 1)
    ys = np.linspace(0.0, 1.0, N + 1)
    gx, gy = np.meshgrid(xs, ys)
    rest = np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)]
    cols = len(xs)
    uvs, weld, tris = [], [], []
    for side, (c0, c1), to_uv in (("left", (0, N), uv_left), ("right", (N, 2 * N), uv_right)):
        index = {}
        for j in range(N + 1):
            for i in range(c0, c1 + 1):
                index[(i, j)] = len(weld)
                weld.append(j * cols + i)
                uvs.append(to_uv(rest[j * cols + i]))
        for j in range(N):
            for i in range(c0, c1):
                a, b = index[(i, j)], index[(i + 1, j)]
                c, d = index[(i + 1, j + 1)], index[(i, j + 1)]
                tris += [(a, b, c), (a, c, d)] if side == "left" else [(a, b, d), (b, c, d)]
    return FaceMesh(rest, np.array(tris), np.array(uvs), np.array(weld))


@pytest.fixture(scope="module")
def mirror() -> SurfaceMirror:
    return SurfaceMirror(strip())


def test_the_strip_has_two_charts_joined_at_a_seam(mirror):
    mesh = mirror.mesh
    seam = np.flatnonzero(mirror.seams.seam_welded)
    assert np.allclose(mesh.rest[seam, 0], 0.0) and len(seam) == N + 1


def test_a_dab_on_the_left_lands_at_the_mirrored_point_in_the_right_chart(mirror):
    p = np.array([-0.5, 0.25, 0.0])
    owner, uv, scale = mirror.mirror_uv(uv_left(p)[None], reach=0.01)
    assert owner.tolist() == [0]
    assert uv[0] == pytest.approx(uv_right(np.array([0.5, 0.25])), abs=1e-6)  # (0.65, 0.8)
    assert uv[0] == pytest.approx([0.65, 0.8], abs=1e-6)
    assert scale[0] == pytest.approx(0.5)  # the right chart has half the UV per unit


def test_the_mirror_works_both_ways_and_for_many_dabs_at_once(mirror):
    points = np.array([[-0.9, 0.1, 0], [-0.3, 0.6, 0], [0.7, 0.8, 0], [0.2, 0.35, 0]])
    uvs = np.array([uv_left(p) if p[0] < 0 else uv_right(p) for p in points])
    owner, uv, scale = mirror.mirror_uv(uvs, reach=0.01)
    assert owner.tolist() == [0, 1, 2, 3]
    expected = [uv_right(-p * [1, -1, 1]) if p[0] < 0 else uv_left(p * [-1, 1, 1])
                for p in points]
    assert uv == pytest.approx(np.array(expected), abs=1e-6)
    assert scale == pytest.approx([0.5, 0.5, 2.0, 2.0])


def test_next_to_the_seam_the_mirror_image_lands_in_both_charts(mirror):
    p = np.array([-0.02, 0.5, 0.0])  # just left of the seam: its mirror is just right of it
    owner, uv, _ = mirror.mirror_uv(uv_left(p)[None], reach=0.02)
    assert owner.tolist() == [0, 0]
    assert uv[0] == pytest.approx([0.7, 0.896], abs=1e-6)  # chart B, as the surface has it
    # chart A extrapolated past its edge (u = 0.45): the dab's part across the seam
    assert uv[1] == pytest.approx([0.458, 0.3], abs=1e-6)


def test_a_point_off_every_chart_has_no_mirror_image(mirror):
    owner, uv, _ = mirror.mirror_uv(np.array([[0.95, 0.05]]), reach=0.01)
    assert len(owner) == 0 and uv.shape == (0, 2)


def test_a_stroke_with_the_surface_mirror_paints_a_half_size_dab_on_the_right(mirror):
    size = 200
    mask = np.zeros((size, size), np.float32)
    stroke = Stroke(mask, Brush(radius=6.0, hardness=1.0, flow=1.0), mirror=mirror)
    # p = (−0.5, 0.25): UV (0.25, 0.2) → pixel (50, 160); its mirror UV (0.65, 0.8) → (130, 40)
    stroke.jump(50.0, 160.0)
    assert mask[160, 50] == 1.0 and mask[40, 130] == 1.0
    assert mask[160, 50 + 5] == 1.0  # the source dab: radius 6
    assert mask[40, 130 + 3] == 0.0 and mask[40, 130 + 2] == 1.0  # the mirror: radius 3
    assert mask[40, 70] == 0.0  # where u → 1 − u would have put it: nothing
    painted = np.argwhere(mask > 0)
    assert {tuple(p) for p in painted} <= {
        (y, x) for y, x in painted if np.hypot(x + 0.5 - 50, y + 0.5 - 160) < 6
        or np.hypot(x + 0.5 - 130, y + 0.5 - 40) < 3}


def test_closest_point_on_a_triangle_inside_beyond_an_edge_and_beyond_a_corner():
    a, b, c = np.array([[0.0, 0, 0]]), np.array([[2.0, 0, 0]]), np.array([[0.0, 2, 0]])
    pts = np.array([[0.5, 0.5, 3.0],  # above the inside: the foot of the perpendicular
                    [2.0, 2.0, 0.0],  # beyond the long edge: its middle (1, 1)
                    [-1.0, -1.0, 0.0]])  # beyond the corner a
    k = len(pts)
    bary, plane, dist = closest_on_triangles(pts, *(np.repeat(v, k, axis=0) for v in (a, b, c)))
    assert bary[0] == pytest.approx([0.5, 0.25, 0.25]) and dist[0] == pytest.approx(3.0)
    assert bary[1] == pytest.approx([0.0, 0.5, 0.5]) and dist[1] == pytest.approx(np.sqrt(2))
    assert bary[2] == pytest.approx([1.0, 0.0, 0.0]) and dist[2] == pytest.approx(np.sqrt(2))
    assert plane[2] == pytest.approx([2.0, -0.5, -0.5])  # unclamped: extrapolates the plane


def test_the_grid_finds_the_same_closest_triangle_as_a_search_of_all():
    rng = np.random.default_rng(7)
    # a bumpy sphere: triangles of many sizes and orientations
    theta, phi = np.meshgrid(np.linspace(0.1, np.pi - 0.1, 14), np.linspace(0, 2 * np.pi, 21))
    r = 1.0 + 0.2 * np.sin(3 * theta) * np.cos(2 * phi)
    pts = np.stack([r * np.sin(theta) * np.cos(phi), r * np.sin(theta) * np.sin(phi),
                    r * np.cos(theta)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(20), np.arange(13), indexing="ij")
    v = (i * 14 + j).ravel()
    tris = np.concatenate([np.c_[v, v + 14, v + 15], np.c_[v, v + 15, v + 1]])
    corners = pts[tris]
    grid = TriangleGrid(corners)
    queries = rng.normal(size=(300, 3)) * 0.9
    _, _, _, dist = grid.closest(queries)
    k = len(tris)
    every = [closest_on_triangles(np.repeat(q[None], k, 0), corners[:, 0], corners[:, 1],
                                  corners[:, 2])[2].min() for q in queries]
    assert dist == pytest.approx(np.array(every), abs=1e-12)
    near, _, _, _ = grid.closest(queries, max_distance=0.05)
    assert np.array_equal(near >= 0, np.array(every) <= 0.05)  # none beyond the limit


def test_the_brush_footprint_on_the_surface_is_the_uv_circle_carried_over():
    # chart A: 0.4 UV per unit, so a UV radius of 0.04 is 0.1 on the surface
    p = np.array([-0.5, 0.25, 0.0])
    corners = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    uv_corners = np.array([uv_left(c) for c in corners])
    ring = footprint_ring(uv_left(p), (0.04, 0.04), uv_corners, corners, segments=16)
    assert np.linalg.norm(ring - p, axis=1) == pytest.approx(np.full(16, 0.1))
    assert ring[:, 2] == pytest.approx(np.zeros(16))
    assert footprint_ring(uv_left(p), (0.04, 0.04), np.zeros((3, 2)), corners) is None


def test_on_the_sample_face_the_left_cheek_mirrors_onto_the_right_cheek():
    from studio.core.sample.synthetic import landmark_uvs, make_test_face

    mirror = SurfaceMirror(make_test_face().mesh)
    uvs = landmark_uvs()
    owner, uv, scale = mirror.mirror_uv(np.array([uvs["cheek left"], uvs["forehead right"]]),
                                        reach=0.01)
    assert owner.tolist() == [0, 1]
    assert uv[0] == pytest.approx(uvs["cheek right"], abs=1e-4)
    assert uv[1] == pytest.approx(uvs["forehead left"], abs=1e-4)
    assert scale == pytest.approx([1.0, 1.0], abs=0.01)
