"""Per-frame geometry against hand-worked values (SPEC §3: Eq. 4.1, 4.2, 4.8, 4.10)."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator

import numpy as np
import pytest

from studio.core.mesh import geometry
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import (
    DeformCache,
    bitangents,
    face_normals,
    vertex_normals,
    vertex_tangents,
)

pytestmark = pytest.mark.core

S2 = np.sqrt(2.0)
S3 = np.sqrt(3.0)
S5 = np.sqrt(5.0)

# A cube of side 2, CCW seen from outside. Every face's diagonal joins the two corners of the
# tetrahedron {1, 2, 4, 7}, so each corner is on the diagonal of all its three faces or of none:
# its three faces weigh the same and the area-weighted normal is exactly position / √3.
CUBE_P = np.array(
    [
        [-1, -1, -1],
        [-1, -1, 1],
        [-1, 1, -1],
        [-1, 1, 1],
        [1, -1, -1],
        [1, -1, 1],
        [1, 1, -1],
        [1, 1, 1],
    ],
    dtype=float,
)
CUBE_T = np.array(
    [
        [1, 3, 2], [1, 2, 0], [4, 6, 7], [4, 7, 5], [4, 5, 1], [4, 1, 0],
        [2, 3, 7], [2, 7, 6], [2, 6, 4], [2, 4, 0], [1, 5, 7], [1, 7, 3],
    ]
)  # fmt: skip


@contextlib.contextmanager
def _strict() -> Iterator[None]:
    """No floating-point warning may escape (zero areas must be handled, not divided by)."""
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        yield


def _mesh(positions, triangles, uvs=None, weld=None) -> FaceMesh:
    positions = np.asarray(positions, dtype=float)
    weld = np.arange(len(positions)) if weld is None else np.asarray(weld)
    uvs = positions[weld, :2] if uvs is None else np.asarray(uvs, dtype=float)
    return FaceMesh(rest=positions, triangles=np.asarray(triangles), uvs=uvs, weld=weld)


def _reference(mesh: FaceMesh, welded: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What DeformCache must produce, from the standalone functions."""
    n_welded = vertex_normals(welded, mesh.welded_triangles)
    n_render = n_welded[mesh.weld]
    tangents = vertex_tangents(welded[mesh.weld], mesh.uvs, mesh.triangles, n_render)
    return n_render, tangents


# --------------------------------------------------------------------------------------------
# Normals
# --------------------------------------------------------------------------------------------


def test_face_normal_of_one_triangle():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 1]], dtype=float)
    # (1,0,0) × (0,1,1) = (0·1 − 0·1, 0·0 − 1·1, 1·1 − 0·0) = (0, −1, 1)
    np.testing.assert_allclose(face_normals(p, [[0, 1, 2]]), [[0, -1 / S2, 1 / S2]], atol=1e-12)
    # Clockwise order flips it.
    np.testing.assert_allclose(face_normals(p, [[0, 2, 1]]), [[0, 1 / S2, -1 / S2]], atol=1e-12)


def test_vertex_normal_is_area_weighted():
    p = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    tris = [[0, 1, 2], [0, 3, 4]]
    # Cross products: (2,0,0)×(0,2,0) = (0,0,4) and (0,1,0)×(0,0,1) = (1,0,0).
    n = vertex_normals(p, tris)
    np.testing.assert_allclose(n[0], np.array([1, 0, 4]) / np.sqrt(17), atol=1e-12)
    np.testing.assert_allclose(n[1], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(n[3], [1, 0, 0], atol=1e-12)
    # The unweighted mean of unit normals would give (1,0,1)/√2 — not what we do.
    assert not np.allclose(n[0], np.array([1, 0, 1]) / S2, atol=1e-3)


def test_cube_vertex_normals_point_along_the_diagonals():
    n = vertex_normals(CUBE_P, CUBE_T)
    np.testing.assert_allclose(n, CUBE_P / S3, atol=1e-12)
    fn = face_normals(CUBE_P, CUBE_T)
    centres = CUBE_P[CUBE_T].mean(axis=1)
    assert (np.einsum("ij,ij->i", fn, centres) > 0).all()  # all outward: the data is CCW
    np.testing.assert_allclose(np.abs(fn).sum(axis=1), 1.0, atol=1e-12)  # axis-aligned


def test_cube_through_deform_cache():
    cache = DeformCache(_mesh(CUBE_P, CUBE_T))
    out = cache.update(CUBE_P)
    np.testing.assert_allclose(out[:, 3:6], CUBE_P / S3, atol=1e-6)
    np.testing.assert_allclose(out[:, :3], CUBE_P, atol=0)


def test_vertex_normals_match_trimesh_area_weighted_and_a_plain_loop():
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3)
    rng = np.random.default_rng(3)
    p = np.asarray(sphere.vertices) * (1 + 0.05 * rng.random((len(sphere.vertices), 1)))
    faces = np.asarray(sphere.faces)
    ours = vertex_normals(p, faces)

    # trimesh's Trimesh.vertex_normals weights by corner angle; its mean_vertex_normals sums
    # whatever face vectors it is given, so area-scaled unit normals make it area-weighted.
    bumpy = trimesh.Trimesh(p, faces, process=False)
    area_weighted = trimesh.geometry.mean_vertex_normals(
        len(p), faces, bumpy.face_normals * bumpy.area_faces[:, None]
    )
    np.testing.assert_allclose(ours, area_weighted, atol=1e-4)

    # An independent, deliberately naive implementation of Eq. 4.1/4.2 with area weights.
    loop = np.zeros_like(p)
    for a, b, c in faces:
        loop[[a, b, c]] += np.cross(p[b] - p[a], p[c] - p[a])
    loop /= np.linalg.norm(loop, axis=1, keepdims=True)
    np.testing.assert_allclose(ours, loop, atol=1e-10)

    # The angle-weighted default differs only slightly on such a smooth closed mesh.
    np.testing.assert_allclose(ours, bumpy.vertex_normals, atol=0.05)


# --------------------------------------------------------------------------------------------
# Tangents
# --------------------------------------------------------------------------------------------


def test_tangent_of_a_skewed_triangle():
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], dtype=float)
    uv = np.array([[0, 0], [1, 0], [0, 1]], dtype=float)
    # s1=1, t1=0, s2=0, t2=1 → r = 1, T = Q1 = (1,0,0), B = Q2 = (1,1,0) (not orthogonal to T).
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    t4 = vertex_tangents(p, uv, [[0, 1, 2]], n)
    np.testing.assert_allclose(t4, np.tile([1, 0, 0, 1], (3, 1)), atol=1e-12)
    # The shader's bitangent w·(N×T') is the orthogonal (0,1,0), not B.
    np.testing.assert_allclose(bitangents(n, t4), np.tile([0, 1, 0], (3, 1)), atol=1e-12)


def test_tangent_scaled_uvs_and_gram_schmidt():
    p = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], dtype=float)
    uv = np.array([[0, 0], [0.5, 0], [0, 0.25]], dtype=float)
    # s1=.5, t1=0, s2=0, t2=.25: r = 1/0.125 = 8, T = 8·0.25·Q1 = (4,0,0), B = 8·0.5·Q2 = (0,8,0)
    # With N = (1,0,1)/√2: T − (N·T)N = (4,0,0) − (4/√2)(1,0,1)/√2 = (2,0,−2) → (1,0,−1)/√2;
    # (N×T)·B = ((0,4/√2,0))·(0,8,0) > 0 → w = +1.
    n = np.tile(np.array([1.0, 0.0, 1.0]) / S2, (3, 1))
    t4 = vertex_tangents(p, uv, [[0, 1, 2]], n)
    np.testing.assert_allclose(t4[:, :3], np.tile(np.array([1, 0, -1]) / S2, (3, 1)), atol=1e-12)
    np.testing.assert_allclose(t4[:, 3], 1.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", t4[:, :3], n), 0.0, atol=1e-12)


def test_mirrored_triangle_has_negative_handedness():
    p = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], dtype=float)
    uv = np.array([[0, 0], [0, 1], [1, 0]], dtype=float)
    # s1=0, t1=1, s2=1, t2=0: r = −1, T = Q2 = (0,2,0), B = Q1 = (2,0,0);
    # (N×T)·B = (−2,0,0)·(2,0,0) = −4 → w = −1.
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    t4 = vertex_tangents(p, uv, [[0, 1, 2]], n)
    np.testing.assert_allclose(t4, np.tile([0, 1, 0, -1], (3, 1)), atol=1e-12)
    np.testing.assert_allclose(bitangents(n, t4), np.tile([1, 0, 0], (3, 1)), atol=1e-12)


def _mirrored_strip() -> FaceMesh:
    """Two unit quads side by side in z=0; the right one's UV island is mirrored in u.

    Welded: 0 (0,0) 1 (1,0) 2 (2,0) 3 (0,1) 4 (1,1) 5 (2,1). The shared edge 1–4 is split:
    render 0–3 belong to the left quad (u = x), render 4–7 to the right one (u = 3 − x).
    """
    welded = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0]], float)
    weld = [0, 1, 4, 3, 1, 2, 5, 4]
    uvs = [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [1, 0], [1, 1], [2, 1]]
    tris = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
    return _mesh(welded, tris, uvs=uvs, weld=weld)


def test_mirrored_strip_handedness_flips_across_the_mirror():
    mesh = _mirrored_strip()
    out = DeformCache(mesh).update(mesh.rest)
    np.testing.assert_allclose(out[:, 3:6], np.tile([0, 0, 1], (8, 1)), atol=1e-6)
    np.testing.assert_allclose(out[:4, 6:9], np.tile([1, 0, 0], (4, 1)), atol=1e-6)
    np.testing.assert_allclose(out[4:, 6:9], np.tile([-1, 0, 0], (4, 1)), atol=1e-6)
    np.testing.assert_array_equal(out[:, 9], [1, 1, 1, 1, -1, -1, -1, -1])
    # Both sides reconstruct the same bitangent: +y, the direction v grows in.
    b = bitangents(out[:, 3:6], out[:, 6:10])
    np.testing.assert_allclose(b, np.tile([0, 1, 0], (8, 1)), atol=1e-6)
    # The standalone function agrees.
    _, t4 = _reference(mesh, mesh.rest)
    np.testing.assert_allclose(out[:, 6:10], t4, atol=1e-6)


# --------------------------------------------------------------------------------------------
# Seams and degenerate input
# --------------------------------------------------------------------------------------------


def _folded_seam() -> FaceMesh:
    """A floor quad (normal +z) and a wall quad (normal −x) meeting at the edge x=1, z=0.

    Welded: 0 (0,0,0) 1 (1,0,0) 2 (1,1,0) 3 (0,1,0) 4 (1,0,1) 5 (1,1,1). The seam edge 1–2 is
    split into render 1, 2 (floor island) and render 4, 5 (wall island).
    """
    welded = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, 1], [1, 1, 1]], float)
    weld = [0, 1, 2, 3, 1, 2, 4, 5]
    uvs = [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1], [3, 0], [3, 1]]
    # Floor: (0,1,2), (0,2,3); wall: welded (1,4,5), (1,5,2) → render (4,6,7), (4,7,5).
    tris = [[0, 1, 2], [0, 2, 3], [4, 6, 7], [4, 7, 5]]
    return _mesh(welded, tris, uvs=uvs, weld=weld)


def test_seam_copies_share_one_welded_normal():
    mesh = _folded_seam()
    out = DeformCache(mesh).update(mesh.rest)
    n = out[:, 3:6]
    # Welded 1: floor (0,1,2) gives (0,0,1); wall (1,4,5) and (1,5,2) give (−1,0,0) each.
    np.testing.assert_allclose(n[1], np.array([-2, 0, 1]) / S5, atol=1e-6)
    # Welded 2: floor (0,1,2) and (0,2,3) give (0,0,1) each; wall (1,5,2) gives (−1,0,0).
    np.testing.assert_allclose(n[2], np.array([-1, 0, 2]) / S5, atol=1e-6)
    np.testing.assert_array_equal(n[1], n[4])  # bit-identical on both sides of the seam
    np.testing.assert_array_equal(n[2], n[5])
    np.testing.assert_allclose(n[0], [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(n[6], [-1, 0, 0], atol=1e-6)
    ref_n, ref_t = _reference(mesh, mesh.rest)
    np.testing.assert_allclose(n, ref_n, atol=1e-6)
    np.testing.assert_allclose(out[:, 6:10], ref_t, atol=1e-6)


def test_zero_area_triangle_gives_finite_output():
    # Triangle 1 is collinear; vertex 4 touches only it, vertex 5 touches nothing.
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [3, 0, 0], [5, 5, 5]], float)
    tris = [[0, 1, 2], [1, 3, 4]]
    with _strict():
        fn = face_normals(p, tris)
        vn = vertex_normals(p, tris)
        out = DeformCache(_mesh(p, tris)).update(p)
    np.testing.assert_array_equal(fn[1], [0, 0, 0])
    np.testing.assert_allclose(fn[0], [0, 0, 1])
    np.testing.assert_allclose(vn[[0, 1, 2]], np.tile([0, 0, 1], (3, 1)), atol=1e-12)
    np.testing.assert_allclose(vn[[3, 4, 5]], np.tile(geometry.FALLBACK_NORMAL, (3, 1)))
    assert np.isfinite(out).all()
    np.testing.assert_allclose(np.linalg.norm(out[:, 3:6], axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(out[:, 6:9], axis=1), 1.0, atol=1e-6)


def test_zero_area_uv_triangle_contributes_nothing():
    # Two triangles share the edge 1–2; the second has all its UVs at one point.
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0]], float)
    uv = np.array([[0, 0], [1, 0], [1, 1], [1, 1]], float)
    uv_degenerate = uv.copy()
    uv_degenerate[[1, 2, 3]] = [0.5, 0.5]  # collinear/coincident: det = 0
    tris = [[0, 1, 2], [1, 3, 2]]
    n = np.tile([0.0, 0.0, 1.0], (4, 1))
    with _strict():
        t4 = vertex_tangents(p, uv, tris, n)
        t4_bad = vertex_tangents(p, uv_degenerate, tris, n)
        out = DeformCache(_mesh(p, tris, uvs=uv_degenerate)).update(p)
    # First triangle alone: T = Q1 = (1,0,0) at vertices 0, 1, 2.
    np.testing.assert_allclose(t4[:3], np.tile([1, 0, 0, 1], (3, 1)), atol=1e-12)
    # All UV triangles degenerate: still unit tangents perpendicular to N, w = +1.
    for result in (t4_bad, out[:, 6:10]):
        assert np.isfinite(result).all()
        np.testing.assert_allclose(np.linalg.norm(result[:, :3], axis=1), 1.0, atol=1e-6)
        np.testing.assert_allclose(result[:, :3] @ [0, 0, 1], 0.0, atol=1e-6)
        np.testing.assert_array_equal(result[:, 3], 1.0)
    # Only the second UV triangle degenerate: vertex 1, 2 keep the first triangle's tangent.
    uv_half = uv.copy()
    uv_half[3] = [1.0, 0.5]  # u constant along the second triangle's edges → det = 0
    t4_half = vertex_tangents(p, uv_half, tris, n)
    np.testing.assert_allclose(t4_half[:3], np.tile([1, 0, 0, 1], (3, 1)), atol=1e-12)


# --------------------------------------------------------------------------------------------
# DeformCache against the standalone functions
# --------------------------------------------------------------------------------------------


def _grid(nx: int, ny: int, seam: bool) -> FaceMesh:
    x, y = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 1, ny))
    p = np.stack([x.ravel(), y.ravel(), 0.1 * np.sin(6 * x.ravel()) * y.ravel()], axis=1)
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    uvs, weld = p[:, :2].copy(), np.arange(nx * ny)
    if seam:  # split the middle column; faces right of it use copies in a shifted UV island
        col = idx[:, nx // 2]
        copy_of = np.full(nx * ny, -1)
        copy_of[col] = nx * ny + np.arange(ny)
        uvs = np.vstack([uvs, uvs[col] + [0.5, 0.0]])
        weld = np.concatenate([weld, col])
        right = x.ravel()[tris].min(axis=1) >= x.ravel()[col[0]] - 1e-12
        on_col = copy_of[tris] >= 0
        tris = np.where(right[:, None] & on_col, copy_of[tris], tris)
    return _mesh(p, tris, uvs=uvs, weld=weld)


def _fan(n: int) -> FaceMesh:
    """A disc: one centre vertex of valence n, the rim vertices of valence 2."""
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    p = np.vstack([[0, 0, 0.3], np.stack([np.cos(angle), np.sin(angle), 0 * angle], 1)])
    tris = [[0, 1 + i, 1 + (i + 1) % n] for i in range(n)]
    return _mesh(p, tris, uvs=p[:, :2] * 0.5 + 0.5)


def _permuted_weld() -> FaceMesh:
    """No seams, but render vertex i sits at welded position n-1-i, plus an unused position."""
    grid = _grid(6, 5, seam=False)
    n = grid.n_welded
    welded = np.vstack([grid.rest[::-1], [[9.0, 9.0, 9.0]]])
    return _mesh(welded, grid.triangles, uvs=grid.uvs, weld=np.arange(n)[::-1])


def _uv_sphere() -> FaceMesh:
    trimesh = pytest.importorskip("trimesh")
    s = trimesh.creation.uv_sphere(count=[12, 16])
    rng = np.random.default_rng(0)
    uvs = rng.random((len(s.vertices), 2))
    return _mesh(np.asarray(s.vertices), np.asarray(s.faces), uvs=uvs)


MESHES = pytest.mark.parametrize(
    "make",
    [
        lambda: _grid(13, 9, seam=False),
        lambda: _grid(13, 9, seam=True),
        lambda: _fan(40),
        _uv_sphere,
        _folded_seam,
        _mirrored_strip,
        _permuted_weld,
    ],
    ids=["grid", "grid-seam", "fan", "uv-sphere", "folded-seam", "mirrored", "permuted"],
)
SMALL_CHUNKS = pytest.mark.parametrize("small_chunks", [False, True])


def _small_chunks(monkeypatch) -> None:
    """Many chunks and merged groups, as large irregular meshes get."""
    monkeypatch.setattr(geometry, "_CHUNK", 7)
    monkeypatch.setattr(geometry, "_MIN_GROUP", 4)
    monkeypatch.setattr(geometry, "_PAD_WASTE", 0.0)


@MESHES
@SMALL_CHUNKS
def test_deform_cache_matches_standalone(make, small_chunks, monkeypatch):
    if small_chunks:
        _small_chunks(monkeypatch)
    mesh = make()
    cache = DeformCache(mesh)
    rng = np.random.default_rng(7)
    first = None
    for _ in range(3):
        welded = mesh.rest + 0.02 * rng.standard_normal(mesh.rest.shape).astype(np.float32)
        with _strict():
            out = cache.update(welded)
        first = out if first is None else first
        assert out is first  # one buffer, reused
        assert out.dtype == np.float32 and out.shape == (mesh.n_vertices, 10)
        normals, tangents = _reference(mesh, welded.astype(np.float64))
        np.testing.assert_allclose(out[:, :3], welded[mesh.weld], atol=0)
        np.testing.assert_allclose(out[:, 3:6], normals, atol=2e-5)
        np.testing.assert_allclose(out[:, 6:9], tangents[:, :3], atol=2e-4)
        np.testing.assert_array_equal(out[:, 9], tangents[:, 3])


def test_deform_cache_plans_cover_both_orders():
    # Regular grids need no reordering; a fan (one vertex of valence 40) is grouped by valence.
    assert DeformCache(_grid(60, 50, seam=False))._plan.identity
    assert not DeformCache(_fan(40))._plan.identity


def test_deform_cache_rejects_wrong_shape():
    cache = DeformCache(_grid(5, 4, seam=False))
    with pytest.raises(ValueError, match="shape"):
        cache.update(np.zeros((3, 3), np.float32))


# --------------------------------------------------------------------------------------------
# Frames that move part of the face
# --------------------------------------------------------------------------------------------


def _moving_parts(mesh: FaceMesh, frames: int = 40) -> list[np.ndarray]:
    """Welded positions frame by frame: a patch of the mesh swelling and settling (its edge
    flickering in and out, as tiny offsets round away), a hold, a patch elsewhere, the first
    patch again, everything moving, and single positions moving."""
    rng = np.random.default_rng(3)
    rest = mesh.rest.astype(np.float32)
    size = np.ptp(rest, axis=0).max()

    def patch(centre: int, radius: float) -> np.ndarray:
        d = np.linalg.norm(rest - rest[centre], axis=1) / (radius * size)
        return (np.clip(1.0 - d, 0.0, 1.0) ** 2)[:, None] * rng.standard_normal(3) * 0.05 * size

    first, second = patch(0, 0.3), patch(len(rest) - 1, 0.25)
    out, weights = [], np.sin(np.linspace(0.1, np.pi - 0.1, frames // 4))
    for w in weights:
        flicker = rng.random(len(rest)) < 0.05  # some of the patch stays put this frame
        out.append(rest + np.where(flicker[:, None], 0.0, w * first).astype(np.float32))
    out += [out[-1].copy(), out[-1].copy()]  # a held pose: nothing moves
    out += [rest + (w * second).astype(np.float32) for w in weights]
    out += [rest + (w * first).astype(np.float32) for w in weights]  # back to the first patch
    out.append(rest + 0.01 * size * rng.standard_normal(rest.shape).astype(np.float32))
    for i in (0, len(rest) // 2, len(rest) - 1):
        single = out[-1].copy()
        single[i] += 0.02 * size
        out.append(single)
    return out


@MESHES
@SMALL_CHUNKS
def test_a_frame_that_moves_part_of_the_mesh_matches_a_whole_recomputation(
    make, small_chunks, monkeypatch
):
    """The cache redoes only what moved positions reach; the result must be exactly what
    recomputing the whole frame from scratch gives, whatever moved before."""
    if small_chunks:
        _small_chunks(monkeypatch)
    mesh = make()
    cache = DeformCache(mesh)
    recomputed = []
    for welded in _moving_parts(mesh):
        with _strict():
            out = cache.update(welded)
        np.testing.assert_array_equal(out, DeformCache(mesh).update(welded))
        recomputed.append(cache.last_recomputed)
        lo, hi = cache.last_span
        assert 0 <= lo <= hi <= mesh.n_vertices
    assert 0 in recomputed  # the held frames redid nothing
    if mesh.n_vertices > 100:  # small meshes: any patch is most of the mesh
        assert any(0 < r < mesh.n_vertices for r in recomputed)


def test_only_the_reported_span_of_the_buffer_changes():
    mesh = _grid(30, 20, seam=True)
    cache = DeformCache(mesh)
    frames = _moving_parts(mesh, frames=12)
    before = cache.update(frames[0]).copy()
    for welded in frames[1:]:
        after = cache.update(welded)
        lo, hi = cache.last_span
        np.testing.assert_array_equal(after[:lo], before[:lo])
        np.testing.assert_array_equal(after[hi:], before[hi:])
        before = after.copy()


def test_deform_cache_on_the_sample_animation_matches_a_plain_reference(sample):
    """The sample face through the benchmark's animation (blend, then normals and tangents),
    against float64 NumPy written the obvious way: the standalone functions and
    ``rest + Σ w·(pose − rest)``."""
    from studio.core.animation.poses import PoseBlender
    from studio.core.animation.timeline import sequence_all_poses

    mesh = sample.mesh
    timeline = sequence_all_poses([p.name for p in sample.poses], fps=24.0)
    blender, cache = PoseBlender(mesh.rest, sample.poses), DeformCache(mesh)
    rest = mesh.rest.astype(np.float64)
    partial = 0
    for frame in range(0, timeline.end, 2):
        weights = timeline.weights_at(frame)
        welded = rest + sum(w * (sample.pose(name).positions - rest)
                            for name, w in weights.items())
        out = cache.update(blender.blend(weights))
        partial += 0 < cache.last_recomputed < mesh.n_vertices
        normals, tangents = _reference(mesh, welded)
        np.testing.assert_allclose(out[:, :3], welded[mesh.weld], atol=1e-6)
        np.testing.assert_allclose(out[:, 3:6], normals, atol=1e-5)
        np.testing.assert_allclose(out[:, 6:9], tangents[:, :3], atol=1e-5)
        np.testing.assert_array_equal(out[:, 9], tangents[:, 3])
    assert partial > 10  # most frames move one pose's part of the face
