"""The MikkTSpace-style tangent frame by hand (core/tangent_frames.py), against the thesis's
frame where they must agree, and inside DeformCache where the renderer and the baker read it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from studio.core.animation.poses import PoseBlender
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache, vertex_normals, vertex_tangents
from studio.core.mesh.tangent_frames import TANGENT_FRAMES, corner_angles, mikktspace_tangents

pytestmark = pytest.mark.core

UP = np.array([[0.0, 0.0, 1.0]])


def quad(uvs: np.ndarray, rotation: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A unit square in z = 0, turned by ``rotation`` about z, as two triangles."""
    c, s = math.cos(rotation), math.sin(rotation)
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return square @ turn.T, np.array([[0, 1, 2], [0, 2, 3]])


def test_a_quad_s_tangent_runs_along_plus_u():
    """UVs = the square's own corners, the square turned by 30°: the tangent is the turned
    x axis (where u grows), w = +1."""
    p, tris = quad(np.zeros(0), math.radians(30))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    t4 = mikktspace_tangents(p, uv, tris, np.repeat(UP, 4, axis=0))
    expected = [math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0]
    np.testing.assert_allclose(t4[:, :3], np.tile(expected, (4, 1)), atol=1e-12)
    np.testing.assert_array_equal(t4[:, 3], 1.0)


def test_the_tangent_is_made_perpendicular_to_the_vertex_normal():
    """The same quad with its vertex normals tilted toward +x (as on a curved face): the
    tangent +x loses its part along the normal, T = normalize(x − (N·x)N) = (1, 0, −1)/√2."""
    p, tris = quad(np.zeros(0))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    tilted = np.tile([1.0, 0.0, 1.0], (4, 1)) / math.sqrt(2)
    t4 = mikktspace_tangents(p, uv, tris, tilted)
    np.testing.assert_allclose(t4[:, :3], np.tile([1.0, 0, -1], (4, 1)) / math.sqrt(2),
                               atol=1e-12)


def test_u_running_the_other_way_is_a_mirrored_island_with_handedness_minus_one():
    """u = 1 − x (the island mirrored): the tangent points to −x and w = −1, so the bitangent
    w·(N×T) = −(z × −x) = +y still points where v grows."""
    p, tris = quad(np.zeros(0))
    uv = np.array([[1, 0], [0, 0], [0, 1], [1, 1]], float)
    t4 = mikktspace_tangents(p, uv, tris, np.repeat(UP, 4, axis=0))
    np.testing.assert_allclose(t4[:, :3], np.tile([-1.0, 0, 0], (4, 1)), atol=1e-12)
    np.testing.assert_array_equal(t4[:, 3], -1.0)
    bitangent = t4[:, 3:] * np.cross(UP, t4[:, :3])
    np.testing.assert_allclose(bitangent, np.tile([0.0, 1, 0], (4, 1)), atol=1e-12)


def test_a_shared_vertex_averages_its_triangles_by_their_angle_there():
    """Vertex 0 is shared by a right triangle (90° at it, u along x) and a 45° one whose UVs
    are sheared so its u runs along y. MikkTSpace weights the unit tangents by the angles:
    T = normalize(90°·x + 45°·y) = (2, 1, 0)/√5. The thesis's frame weights them by position
    area over UV area instead and gives another direction — the frames really differ."""
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 1, 0], [0, 1, 0]], float)
    tris = np.array([[0, 1, 2], [0, 4, 3]])  # (0, 1) is split: its UV differs per triangle
    # triangle 0: u = x, v = y; triangle 1: u grows along +y and v along −x
    uv = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [1, 0]], float)
    angles = np.degrees(corner_angles(p[tris]))
    np.testing.assert_allclose(angles[:, 0], [90.0, 45.0])
    normals = np.repeat(UP, 5, axis=0)
    t4 = mikktspace_tangents(p, uv, tris, normals)
    np.testing.assert_allclose(t4[0, :3], np.array([2.0, 1.0, 0.0]) / math.sqrt(5), atol=1e-12)
    assert t4[0, 3] == 1.0
    thesis = vertex_tangents(p, uv, tris, normals)
    assert np.degrees(np.arccos(thesis[0, :3] @ t4[0, :3])) > 5.0


def test_a_vertex_on_a_uv_mirror_line_takes_the_side_most_of_its_angle_lies_on():
    """Three right angles around vertex 0 in one plane, the vertex keeping one UV: two
    triangles with u along +x, and a mirrored one (its UV triangle clockwise) with u along −y.
    The vertex lies mostly on the unmirrored side, so it sums only those two (T = +x,
    w = +1); summing the mirrored one too would tilt it to (2, −1)/√5."""
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 0, 0]], float)
    tris = np.array([[0, 1, 2], [0, 2, 3], [0, 4, 5]])
    uv = np.array([[0, 0], [1, 0], [0, 1], [-1, 0], [1, 0], [0, -1]], float)
    t4 = mikktspace_tangents(p, uv, tris, np.repeat(UP, 6, axis=0))
    np.testing.assert_allclose(t4[0], [1.0, 0.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(t4[4], [0.0, -1.0, 0.0, -1.0], atol=1e-12)  # mirrored side


def test_degenerate_uvs_give_a_perpendicular_tangent_not_nan():
    p, tris = quad(np.zeros(0))
    t4 = mikktspace_tangents(p, np.zeros((4, 2)), tris, np.repeat(UP, 4, axis=0))
    assert np.isfinite(t4).all()
    np.testing.assert_allclose(t4[:, :3] @ UP[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(t4[:, :3], axis=1), 1.0)
    np.testing.assert_array_equal(t4[:, 3], 1.0)


def grid(n: int, bumpy: bool) -> FaceMesh:
    """An n × n grid over [0, 1]², UVs = (x, y); ``bumpy`` lifts it into a curved, unevenly
    spaced sheet with the same UVs."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    idx = np.arange(x.size).reshape(x.shape)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    uv = np.stack([x.ravel(), y.ravel()], 1)
    xs, ys = (x ** 1.7, y + 0.2 * np.sin(3 * x)) if bumpy else (x, y)
    z = 0.3 * np.sin(2.5 * x) * np.cos(2 * y) if bumpy else np.zeros_like(x)
    rest = np.stack([xs.ravel(), ys.ravel(), z.ravel()], 1)
    return FaceMesh(rest, tris, uv, np.arange(len(rest)))


def test_on_a_flat_uv_aligned_grid_the_two_frames_are_the_same():
    mesh = grid(6, bumpy=False)
    thesis = DeformCache(mesh, "thesis").update(mesh.rest).copy()
    mikk = DeformCache(mesh, "mikktspace").update(mesh.rest)
    np.testing.assert_allclose(mikk, thesis, atol=1e-6)
    np.testing.assert_allclose(mikk[:, 6:10], np.tile([1.0, 0, 0, 1], (mesh.n_vertices, 1)),
                               atol=1e-6)


def test_deform_cache_fills_the_frame_it_is_set_to_every_frame():
    """The cache's MikkTSpace columns are the standalone function's over its welded normals,
    at rest and on every posed frame (partial updates included); switching the frame switches
    the columns, and switching back gives the thesis's again."""
    mesh = grid(12, bumpy=True)
    lifted = mesh.rest.copy()
    lifted[:40, 2] += 0.2  # a pose moving part of the sheet
    from studio.core.animation.poses import KeyPose

    blender = PoseBlender(mesh.rest, [KeyPose("lift", lifted)])
    cache = DeformCache(mesh, "mikktspace")
    for weight in (0.0, 0.5, 1.0, 0.25):
        positions = blender.blend({"lift": weight})
        out = cache.update(positions)
        normals = vertex_normals(positions, mesh.triangles)
        expected = mikktspace_tangents(positions, mesh.uvs, mesh.triangles, normals)
        np.testing.assert_allclose(out[:, 6:10], expected, atol=2e-5)
        np.testing.assert_allclose(out[:, 3:6], normals, atol=2e-5)
    thesis = DeformCache(mesh, "thesis").update(positions).copy()
    assert np.abs(out[:, 6:9] - thesis[:, 6:9]).max() > 0.01  # curved: the frames differ
    cache.set_frame("thesis")
    np.testing.assert_array_equal(cache.update(positions), thesis)
    with pytest.raises(ValueError, match="unknown tangent frame"):
        cache.set_frame("blender")
    assert set(TANGENT_FRAMES) == {"mikktspace", "thesis"}


def test_corner_angles_by_hand():
    """A 30-60-90 triangle in each corner order, and a sliver: the angle at every corner."""
    p = np.array([[0.0, 0.0, 0.0], [np.sqrt(3.0), 0.0, 0.0], [0.0, 1.0, 0.0]])
    for order in ([0, 1, 2], [1, 2, 0], [2, 0, 1]):
        angles = np.degrees(corner_angles(p[order][None]))[0]
        expected = np.array([90.0, 30.0, 60.0])[order]
        np.testing.assert_allclose(angles, expected, atol=1e-9)
    sliver = np.array([[[0.0, 0, 0], [1.0, 0, 0], [0.5, 1e-9, 0]]])
    np.testing.assert_allclose(corner_angles(sliver)[0].sum(), np.pi, atol=1e-12)


def test_the_posed_frame_s_angles_are_the_corner_angles_degenerate_triangles_too():
    """Every posed frame takes the third angle as π minus the other two: the same angles as
    three atan2s, on random triangles, a sliver, three points in a line and two corners at one
    point (which has no angle but the atan2's 0 at the lone corner)."""
    from studio.core.mesh.tangent_frames import _posed_angles

    rng = np.random.default_rng(4)
    corners = rng.normal(size=(200, 3, 3))
    corners[0] = [[0, 0, 0], [1, 0, 0], [0.5, 1e-6, 0]]  # a sliver
    corners[1] = [[0, 0, 0], [1, 0, 0], [3, 0, 0]]  # in a line: 180° at corner 1
    corners[2] = [[0, 0, 0], [2, 0, 0], [-1, 0, 0]]  # in a line: 180° at corner 0
    corners[3] = [[0, 0, 0], [0, 0, 0], [1, 1, 0]]  # corners 0 and 1 at one point
    corners[4] = [[1, 2, 3], [4, 5, 6], [4, 5, 6]]  # corners 1 and 2 at one point
    c = np.moveaxis(corners, 2, 0)
    edges = (c[:, :, 1] - c[:, :, 0], c[:, :, 2] - c[:, :, 0], c[:, :, 2] - c[:, :, 1])
    np.testing.assert_allclose(_posed_angles(*edges), corner_angles(corners), atol=1e-12)
    np.testing.assert_allclose(_posed_angles(*edges)[1], [0.0, np.pi, 0.0], atol=1e-12)
    as_float32 = _posed_angles(*(e.astype(np.float32) for e in edges))
    assert as_float32.dtype == np.float32
    np.testing.assert_allclose(as_float32, corner_angles(corners), atol=2e-6)
