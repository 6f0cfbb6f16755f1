"""Edge cases of the through-the-mesh mirror, on hand-built meshes small enough to compute by hand.

Checks the geometry kernels (plane barycentrics, closest point on a triangle in its face, edge and
vertex regions, degenerate and tiny triangles), the uniform grid (its cells are enumerated exactly,
its candidate lists stay local, its lookups honour ``max_distance`` exactly), the UV-seam map on a
fan of three charts meeting at one vertex, and ``SurfaceMirror`` on two-chart strips (UV per model
unit, the radius scale, a degenerate triangle, a second image across a narrow UV gutter).
Degenerate input must also stay quiet: no divide-by-zero warnings reach the user's console.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.surface_mirror import (
    SeamMap,
    SurfaceMirror,
    TriangleGrid,
    _box_items,
    closest_on_triangles,
    plane_barycentric,
)

pytestmark = pytest.mark.core

Array = np.ndarray


def one(points: list[list[float]]) -> Array:
    return np.array(points, np.float64)


# --- plane barycentrics -----------------------------------------------------------------------


def test_barycentrics_inside_and_outside_a_triangle():
    a, b, c = one([[0.0, 0.0]]), one([[2.0, 0.0]]), one([[0.0, 2.0]])
    bary, ok = plane_barycentric(one([[0.5, 0.5]]), a, b, c)
    assert ok.tolist() == [True]
    assert bary[0] == pytest.approx([0.5, 0.25, 0.25])
    bary, _ = plane_barycentric(one([[3.0, 0.0]]), a, b, c)
    assert bary[0] == pytest.approx([-0.5, 1.5, 0.0])  # negative outside


def test_a_texel_sized_triangle_is_not_degenerate():
    """UV triangles of a dense mesh are tiny: legs of 1e-4 must still give exact weights."""
    a, b, c = one([[0.0, 0.0]]), one([[1e-4, 0.0]]), one([[0.0, 1e-4]])
    bary, ok = plane_barycentric(one([[2.5e-5, 5e-5]]), a, b, c)
    assert ok.tolist() == [True]
    assert bary[0] == pytest.approx([0.25, 0.25, 0.5])


def test_a_long_sliver_counts_as_degenerate_whatever_its_size():
    """Degeneracy is relative to the triangle's size: a sliver 1e7 times longer than wide is
    degenerate even when its determinant is far above any absolute epsilon."""
    a, b, c = one([[0.0, 0.0]]), one([[100.0, 0.0]]), one([[100.0, 1e-5]])
    bary, ok = plane_barycentric(one([[50.0, 0.0]]), a, b, c)
    assert ok.tolist() == [False]
    assert bary[0].tolist() == [1.0, 0.0, 0.0]


def test_degenerate_triangles_give_the_first_corner_quietly():
    a = one([[1.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    b = one([[1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    c = one([[1.0, 1.0, 0.0], [2.0, 0.0, 0.0]])  # a point; three collinear corners
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bary, ok = plane_barycentric(one([[3.0, 2.0, 1.0], [0.5, 0.5, 0.0]]), a, b, c)
    assert ok.tolist() == [False, False]
    assert bary.tolist() == [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]


# --- closest point on a triangle ---------------------------------------------------------------

TRI = (one([[0.0, 0.0]]), one([[1.0, 0.0]]), one([[0.0, 1.0]]))


def test_closest_point_in_the_face_edge_and_vertex_regions():
    bary, plane, dist = closest_on_triangles(one([[0.25, 0.25]]), *TRI)  # inside
    assert bary[0] == pytest.approx([0.5, 0.25, 0.25]) and dist[0] == pytest.approx(0.0)
    assert plane[0] == pytest.approx([0.5, 0.25, 0.25])
    bary, plane, dist = closest_on_triangles(one([[1.0, 1.0]]), *TRI)  # beyond edge b-c
    assert bary[0] == pytest.approx([0.0, 0.5, 0.5])
    assert dist[0] == pytest.approx(np.sqrt(0.5))
    assert plane[0] == pytest.approx([-1.0, 1.0, 1.0])  # unclamped, to extrapolate
    bary, plane, dist = closest_on_triangles(one([[-1.0, -1.0]]), *TRI)  # beyond corner a
    assert bary[0] == pytest.approx([1.0, 0.0, 0.0])
    assert dist[0] == pytest.approx(np.sqrt(2.0))
    assert plane[0] == pytest.approx([3.0, -1.0, -1.0])


def test_closest_point_above_a_triangle_in_3d():
    a, b, c = one([[0.0, 0.0, 0.0]]), one([[1.0, 0.0, 0.0]]), one([[0.0, 1.0, 0.0]])
    bary, _, dist = closest_on_triangles(one([[0.25, 0.5, 2.0]]), a, b, c)
    assert bary[0] == pytest.approx([0.25, 0.25, 0.5])
    assert dist[0] == pytest.approx(2.0)


def test_closest_point_on_degenerate_triangles():
    """A triangle collapsed to a point or a segment still has a closest point; its 'plane'
    coordinates fall back to the clamped ones, and nothing warns."""
    a = one([[1.0, 1.0], [0.0, 0.0]])
    b = one([[1.0, 1.0], [1.0, 0.0]])
    c = one([[1.0, 1.0], [2.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bary, plane, dist = closest_on_triangles(one([[4.0, 5.0], [1.5, 1.0]]), a, b, c)
    assert dist == pytest.approx([5.0, 1.0])
    assert bary[0] == pytest.approx([1.0, 0.0, 0.0])
    closest = bary[1, 0] * a[1] + bary[1, 1] * b[1] + bary[1, 2] * c[1]
    assert closest == pytest.approx([1.5, 0.0])
    assert plane.dtype == np.float64
    assert plane.tolist() == bary.tolist()


# --- the grid ---------------------------------------------------------------------------------


def test_box_items_lists_every_cell_of_each_inclusive_box():
    owner, cells = _box_items(np.array([[1, 2], [5, 5]]), np.array([[2, 3], [5, 5]]))
    assert cells.dtype.kind == "i"
    got = sorted(
        (int(o), tuple(int(v) for v in cell)) for o, cell in zip(owner, cells, strict=True)
    )
    assert got == [(0, (1, 2)), (0, (1, 3)), (0, (2, 2)), (0, (2, 3)), (1, (5, 5))]


def lattice() -> Array:
    """Right triangles with legs 0.3 on a 4 × 2 lattice of spacing 1 (lower-left corner at
    (-5, 2)), and one larger triangle with legs 1 off to the right: cells are 0.3 wide."""
    corners = []
    for j in range(2):
        for i in range(4):
            x, y = -5.0 + i, 2.0 + j
            corners.append([[x, y], [x + 0.3, y], [x, y + 0.3]])
    corners.append([[1.0, 2.0], [2.0, 2.0], [1.0, 3.0]])
    return np.array(corners)


def test_the_grid_keeps_candidates_local():
    corners = lattice()
    grid = TriangleGrid(corners)
    centroids = corners.mean(axis=1)
    for k in range(8):  # the small triangles: only themselves near their centroids
        qi, tri = grid.near(centroids[k : k + 1], 0.01)
        assert qi.tolist() == [0] and tri.tolist() == [k]
    gaps = np.array(
        [[-5.0 + i + 0.65, 2.15 + j] for i in range(3) for j in range(2)]
        + [[-4.9 + i, 2.65] for i in range(4)]
    )
    qi, tri = grid.near(gaps, 0.01)  # empty space between the triangles: no candidates
    assert qi.tolist() == [] and tri.tolist() == []


def test_closest_honours_max_distance_exactly():
    grid = TriangleGrid(np.array([[[0, 0], [1, 0], [0, 1]]]))  # integer corners are fine
    tri, bary, plane, dist = grid.closest(one([[0.5, -0.5], [3.0, 3.0]]), max_distance=0.5)
    assert tri.tolist() == [0, -1]  # exactly at max_distance counts; far away: none
    assert grid.corners[tri[:1]].shape == (1, 3, 2)  # an index, not a float
    assert dist[0] == pytest.approx(0.5) and dist[1] == np.inf
    assert bary[0] == pytest.approx([0.5, 0.5, 0.0])
    assert plane[0] == pytest.approx([1.0, 0.5, -0.5])
    assert bary[1].tolist() == [0.0, 0.0, 0.0]
    tri, _, _, dist = grid.closest(one([[3.0, 3.0]]))  # without a limit: always one
    assert tri.tolist() == [0] and dist[0] == pytest.approx(np.hypot(2.5, 2.5))


def test_the_grid_never_gets_finer_than_a_1024th_of_the_mesh():
    """Triangles collapsed to points spread over a wide area: the median size is 0, yet the
    grid keeps at most about 1024 cells along an axis."""
    pts = [[-700.0, -700.0], [0.0, 0.0], [700.0, 700.0]]
    grid = TriangleGrid(np.array([[p, p, p] for p in pts]))
    assert grid.dims.max() <= 1025
    assert grid.cell == pytest.approx(np.hypot(1400.0, 1400.0) / 1024.0)
    tri, _, _, dist = grid.closest(one([[1.0, 2.0]]))
    assert tri.tolist() == [1] and dist[0] == pytest.approx(np.sqrt(5.0))


# --- the seam map on a fan of three charts -------------------------------------------------------

FAN_REST = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, -1.0, 0.0]])
PO, PA, PB, PC = range(4)
S = 0.1  # UV per model unit in every chart
ORIGINS = [(0.1, 0.1), (0.5, 0.5), (0.52, 0.5)]  # where each chart puts O: charts 1 and 2 sit
REACH = 0.02  # one reach apart in UV, like islands with a narrow gutter


def fan() -> FaceMesh:
    """Three triangles around O, each its own UV chart: T0 = (B, O, A), T1 = (O, B, C),
    T2 = (O, C, A); chart k maps (x, y) to ORIGINS[k] + S·(x, y)."""
    tris = [(PB, PO, PA), (PO, PB, PC), (PO, PC, PA)]
    weld, uvs = [], []
    for k, tri in enumerate(tris):
        for w in tri:
            weld.append(w)
            uvs.append(np.array(ORIGINS[k]) + S * FAN_REST[w, :2])
    return FaceMesh(FAN_REST, np.arange(9).reshape(3, 3), np.array(uvs), np.array(weld))


def test_other_charts_lists_one_triangle_per_seam_vertex_and_chart():
    seams = SeamMap(fan())
    assert seams.seam_welded.tolist() == [True] * 4
    assert seams.other_charts(0) == [1, 1, 2, 2]  # via B: T1; via O: T1, T2; via A: T2


def test_a_point_next_to_the_shared_vertex_is_found_in_both_other_charts():
    mesh = fan()
    p = np.array([0.05, 0.05, 0.0])
    found = SeamMap(mesh).locations(0, p, mesh.rest[mesh.weld], REACH)
    assert [f for f, _ in found] == [1, 2]  # two charts, each once, though only REACH apart
    assert found[0][1] == pytest.approx([0.505, 0.505])
    assert found[1][1] == pytest.approx([0.525, 0.505])


def test_a_chart_out_of_reach_is_skipped_but_the_next_one_is_kept():
    mesh = fan()
    p = np.array([0.9, 0.05, 0.0])  # near A: 0.09 UV from T1's chart, 0.005 from T2's
    found = SeamMap(mesh).locations(0, p, mesh.rest[mesh.weld], REACH)
    assert [f for f, _ in found] == [2]
    assert found[0][1] == pytest.approx([0.61, 0.505])


# --- the surface mirror on two-chart strips ---------------------------------------------------

STRIP_REST = np.array(
    [
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [-1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]
)


def strip(right: tuple[float, float, float], extra: bool = False) -> FaceMesh:
    """The square x ∈ [−1, 1], y ∈ [0, 1], cut at x = 0 into two charts of two triangles:
    left uv = (0.3, 0.2) + 0.2·(x, y), right uv = (u0, v0) + s·(x, y) for ``right`` = (u0, v0, s).
    ``extra`` adds a fifth triangle over three collinear points: no area on the surface."""
    u0, v0, s = right
    weld = [0, 1, 4, 3, 1, 2, 5, 4]
    uvs = [(0.3 + 0.2 * STRIP_REST[w, 0], 0.2 + 0.2 * STRIP_REST[w, 1]) for w in weld[:4]]
    uvs += [(u0 + s * STRIP_REST[w, 0], v0 + s * STRIP_REST[w, 1]) for w in weld[4:]]
    tris = [(0, 1, 2), (0, 2, 3), (4, 5, 6), (4, 6, 7)]
    if extra:
        weld += [0, 1, 2]
        uvs += [(0.8, 0.8), (0.9, 0.8), (0.85, 0.9)]
        tris.append((8, 9, 10))
    return FaceMesh(STRIP_REST, np.array(tris), np.array(uvs), np.array(weld))


def test_uv_per_unit_and_the_radius_scale_between_charts():
    mirror = SurfaceMirror(strip((0.6, 0.6, 0.1)))
    assert mirror.uv_per_unit == pytest.approx([0.2, 0.2, 0.1, 0.1])
    owner, uv, scale = mirror.mirror_uv(one([[0.2, 0.25]]), reach=0.01)  # x = -0.5, y = 0.25
    assert owner.tolist() == [0]
    assert uv[0] == pytest.approx([0.65, 0.625])
    assert scale == pytest.approx([0.5])


def test_a_triangle_without_surface_area_has_no_uv_scale_and_leaves_dabs_unscaled():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mirror = SurfaceMirror(strip((0.6, 0.6, 0.1), extra=True))
        scale = mirror.scale(np.array([4, 0]), np.array([2, 2]))
    assert mirror.uv_per_unit[4] == 0.0
    assert scale == pytest.approx([1.0, 0.5])


def test_a_dab_beside_the_seam_also_lands_across_a_narrow_uv_gutter():
    """Both charts 0.2 UV per unit, the right one shifted 0.01 (one reach) along u: a dab
    0.01 left of the seam mirrors 0.01 right of it, and again, extrapolated, in the left chart
    just past its edge, one reach from the main image."""
    mirror = SurfaceMirror(strip((0.31, 0.2, 0.2)))
    owner, uv, scale = mirror.mirror_uv(one([[0.298, 0.3]]), reach=0.01)  # x = -0.01, y = 0.5
    assert owner.tolist() == [0, 0]
    assert uv == pytest.approx(np.array([[0.312, 0.3], [0.302, 0.3]]))
    assert scale == pytest.approx([1.0, 1.0])
    owner, uv, _ = mirror.mirror_uv(one([[0.28, 0.3]]), reach=0.01)  # x = -0.1: too far
    assert owner.tolist() == [0] and uv == pytest.approx(np.array([[0.33, 0.3]]))


def test_each_seam_vertex_names_one_triangle_of_the_other_chart():
    """The left chart's two triangles share the seam vertex at (0, 1): it is still listed once,
    so a right triangle with two seam vertices sees the left chart once per vertex."""
    seams = SeamMap(strip((0.6, 0.6, 0.1)))
    assert seams.seam_welded.tolist() == [False, True, False, False, True, False]
    assert seams.touches_seam.tolist() == [True, True, True, True]
    assert seams.other_charts(3) == [0, 0]  # via (0, 0) and via (0, 1)
    assert seams.other_charts(2) == [0]  # only (0, 0) is on the seam
