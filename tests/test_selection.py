"""Vertex selection for technique-2 authoring (numpy core): screen regions, visibility,
adjacency, symmetry and suggestions, on meshes whose answers are known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh import selection as sel
from studio.core.mesh.camera import OrbitCamera
from studio.core.mesh.geometry import vertex_normals

pytestmark = pytest.mark.core


def grid(n: int = 5, spacing: float = 1.0, z: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """An n×n grid in the plane z (centred on x = 0), two triangles per cell, facing +Z."""
    xs = (np.arange(n) - (n - 1) / 2.0) * spacing
    x, y = np.meshgrid(xs, xs, indexing="xy")  # vertex (row j, column i) = j * n + i
    pts = np.c_[x.ravel(), y.ravel(), np.full(n * n, z)].astype(np.float64)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="xy")
    a = (j * n + i).ravel()
    b, c, d = a + 1, a + n, a + n + 1
    tris = np.r_[np.c_[a, b, d], np.c_[a, d, c]]  # counter-clockwise seen from +Z
    return pts, tris


def front_camera(pts: np.ndarray) -> OrbitCamera:
    cam = OrbitCamera(yaw=0.0, pitch=0.0)
    cam.frame(pts.min(axis=0), pts.max(axis=0))
    return cam


def test_box_selects_exactly_the_grid_vertices_inside_it():
    pts, tris = grid(5)
    cam = front_camera(pts)
    px, depth = cam.project(pts, 400, 400)
    normals = vertex_normals(pts, tris)
    view = sel.screen_view(px, depth, pts, normals, cam.eye())
    # a box around the central 3×3 vertices: halfway between grid lines
    step = px[1, 0] - px[0, 0]
    centre = px[12]
    box = view.select(sel.in_box(px, centre - 1.5 * step, centre + 1.5 * step))
    expected = np.zeros(25, bool)
    expected[[6, 7, 8, 11, 12, 13, 16, 17, 18]] = True
    assert np.array_equal(box, expected)
    # the same square as a lasso, drawn the other way round, selects the same
    a, b = centre - 1.5 * step, centre + 1.5 * step
    square = np.array([[a[0], a[1]], [a[0], b[1]], [b[0], b[1]], [b[0], a[1]]])
    assert np.array_equal(view.select(sel.in_lasso(px, square)), expected)
    # a brush of just over one grid step around the centre: the centre and its 4 neighbours
    brush = view.select(sel.in_circle(px, centre, 1.1 * abs(step)))
    assert set(np.flatnonzero(brush)) == {7, 11, 12, 13, 17}


def test_lasso_handles_a_concave_outline():
    pts = np.array([[1, 1], [5, 1], [1, 5], [5, 5], [3, 3]], float)
    # a "U" opening upward (y down is up on screen): the middle point lies in the notch
    u = np.array([[0, 0], [6, 0], [6, 6], [4, 6], [4, 2], [2, 2], [2, 6], [0, 6]], float)
    assert np.array_equal(sel.in_lasso(pts, u), [True, True, True, True, False])


def test_back_facing_vertices_are_not_picked_unless_selecting_through():
    front, tris = grid(4, z=0.5)
    back = front.copy()
    back[:, 2] = -0.5
    pts = np.r_[front, back]
    # the back sheet's triangles wind the other way: its normals face -Z, away from the camera
    faces = np.r_[tris, tris[:, ::-1] + len(front)]
    cam = front_camera(pts)
    px, depth = cam.project(pts, 300, 300)
    view = sel.screen_view(px, depth, pts, vertex_normals(pts, faces), cam.eye())
    everything = np.ones(len(pts), bool)
    assert np.array_equal(view.select(everything), np.r_[np.ones(16, bool), np.zeros(16, bool)])
    assert view.select(everything, through=True).all()


def test_depth_buffer_hides_vertices_behind_the_surface():
    pts, tris = grid(4)
    behind = pts + np.array([0.1, 0.1, -1.0])  # a second sheet behind the first, facing +Z
    pts = np.r_[pts, behind]
    faces = np.r_[tris, tris + 16]
    cam = front_camera(pts)
    w = h = 200
    px, depth = cam.project(pts, w, h)
    near, far = cam.clip_planes()
    # the depth buffer of the front sheet alone: a plane at the front sheet's view depth
    z_front = float(depth[:16].mean())
    ndc = (far + near - 2.0 * near * far / z_front) / (far - near)
    buffer = np.full((h, w), (ndc + 1.0) / 2.0, np.float32)
    view = sel.screen_view(px, depth, pts, vertex_normals(pts, faces), cam.eye(), buffer, near,
                           far, tolerance=0.01)
    assert view.visible[:16].all() and not view.visible[16:].any()
    assert sel.linear_depth(np.array([(ndc + 1) / 2]), near, far)[0] == pytest.approx(z_front)


def test_grow_and_shrink_follow_the_mesh_edges():
    _, tris = grid(5)
    edges = sel.edges(tris)
    assert len(edges) == 4 * 5 * 2 + 16  # 40 grid lines' segments + one diagonal per cell
    centre = np.zeros(25, bool)
    centre[12] = True
    once = sel.grow(centre, edges)
    assert once.sum() == 7  # an inner vertex of this triangulation has 6 neighbours
    assert sel.grow(centre, edges, steps=2).sum() == 19
    everything = np.ones(25, bool)
    assert sel.shrink(everything, edges).all()  # the mesh's own border is not a selection border
    below_first_row = np.arange(25) >= 5
    assert np.array_equal(sel.shrink(below_first_row, edges), np.arange(25) >= 10)
    assert sel.shrink(once, edges).sum() == 1  # back to the centre
    assert np.array_equal(sel.invert(once), ~once)


def test_mirror_pairs_vertices_across_x_zero():
    pts, _ = grid(5)
    rng = np.random.default_rng(1)
    order = rng.permutation(len(pts))
    shuffled = pts[order] + rng.normal(0.0, 1e-4, pts.shape)  # not exactly symmetric
    index = sel.mirror_map(shuffled)
    expected = shuffled.copy()
    expected[:, 0] *= -1.0
    assert np.allclose(shuffled[index], expected, atol=1e-3)
    assert np.array_equal(index[index], np.arange(len(pts)))  # a pairing
    on_plane = np.flatnonzero(np.abs(shuffled[:, 0]) < 1e-2)
    assert np.array_equal(index[on_plane], on_plane)
    right = shuffled[:, 0] > 0.1
    assert np.array_equal(sel.mirror(right, index), np.abs(shuffled[:, 0]) > 0.1)
    assert np.array_equal(sel.mirror(right, index, keep=False), shuffled[:, 0] < -0.1)


def test_nearest_neighbours_match_brute_force():
    rng = np.random.default_rng(7)
    points = rng.normal(size=(600, 3)) * [1.0, 2.0, 0.1]
    queries = rng.normal(size=(300, 3)) * 3.0  # many far from every point
    index, dist = sel.nearest_neighbours(points, queries)
    d = np.linalg.norm(queries[:, None] - points[None], axis=2)
    assert np.allclose(dist, d.min(axis=1))
    assert np.allclose(d[np.arange(300), index], d.min(axis=1))


def test_combine_modes():
    a = np.array([1, 1, 0, 0], bool)
    b = np.array([0, 1, 1, 0], bool)
    assert np.array_equal(sel.combine(a, b, sel.REPLACE), b)
    assert np.array_equal(sel.combine(a, b, sel.ADD), [1, 1, 1, 0])
    assert np.array_equal(sel.combine(a, b, sel.REMOVE), [1, 0, 0, 0])
    with pytest.raises(ValueError, match="unknown selection mode"):
        sel.combine(a, b, "xor")


def test_suggest_takes_the_vertices_a_pose_moves_most():
    rest = np.zeros((5, 3))
    target = rest.copy()
    target[:, 1] = [0.0, 0.1, 0.5, 1.0, 0.3]
    assert np.array_equal(sel.suggest(rest, target, 0.25), [0, 0, 1, 1, 1])
    assert not sel.suggest(rest, rest, 0.1).any()


def test_nearest_vertex_to_a_click():
    pts, tris = grid(3)
    cam = front_camera(pts)
    px, depth = cam.project(pts, 100, 100)
    view = sel.screen_view(px, depth, pts, vertex_normals(pts, tris), cam.eye())
    x, y = px[4] + 2.0
    assert sel.nearest_in_radius(view, x, y, 5.0) == 4
    assert sel.nearest_in_radius(view, -50.0, -50.0, 5.0) is None


def test_selection_stays_fast_on_30000_vertices():
    """A box selection and the mirror map on a 30k-vertex face (their speed is measured by
    the studio's own timing in the status bar, not asserted here)."""
    from studio.core.sample.synthetic import make_test_face

    mesh = make_test_face(30000, texture_size=16, mask_size=16).mesh
    pts = mesh.rest.astype(np.float64)
    cam = front_camera(pts)
    px, depth = cam.project(pts, 1200, 800)
    view = sel.screen_view(px, depth, pts, vertex_normals(pts, mesh.welded_triangles), cam.eye())
    hits = view.select(sel.in_box(px, (400, 200), (800, 400)))
    assert hits.sum() > 100
    index = sel.mirror_map(pts)
    assert (np.abs(pts[index][:, 0] + pts[:, 0]) < 0.05).mean() > 0.95


def test_a_point_on_the_lassos_left_or_top_edge_is_inside_and_on_its_right_or_bottom_outside():
    """Half-open edges (as for pixels): two lassos that share an edge never both take a vertex,
    and no vertex on a shared edge is left out of both."""
    square = np.array([(0, 0), (10, 0), (10, 10), (0, 10)], float)
    pts = np.array([(5, 5), (0, 5), (5, 0), (10, 5), (5, 10), (-0.01, 5), (5, -0.01), (15, 5)],
                   float)
    assert sel.in_lasso(pts, square).tolist() == [True, True, True, False, False, False, False,
                                                 False]
    right = square + np.array([10.0, 0.0])
    assert not (sel.in_lasso(pts, square) & sel.in_lasso(pts, right)).any()
    assert (sel.in_lasso(pts, square) | sel.in_lasso(pts, right))[3]  # (10, 5): in one of them
    assert not sel.in_lasso(pts, square[:2]).any()  # a line is no lasso
    # an outline with horizontal edges and a notch: the notch is outside its bounding box's fill
    notch = np.array([(0, 0), (9, 0), (9, 9), (6, 9), (6, 3), (3, 3), (3, 9), (0, 9)], float)
    probe = np.array([(1.5, 6), (4.5, 6), (7.5, 6), (4.5, 1.5)], float)
    assert sel.in_lasso(probe, notch).tolist() == [True, False, True, True]


def window_depth(distance: float, near: float, far: float) -> float:
    """The depth-buffer value a perspective projection stores for a view distance."""
    z = (far + near - 2.0 * near * far / distance) / (far - near)
    return (z + 1.0) / 2.0


def test_linear_depth_undoes_the_projection():
    near, far = 1.0, 10.0
    assert sel.linear_depth(np.array([0.0, 1.0]), near, far).tolist() == pytest.approx([1, 10])
    assert sel.linear_depth(np.array([window_depth(4.0, near, far)]), near, far)[0] == (
        pytest.approx(4.0))


def test_occlusion_reads_the_depth_buffer_bottom_up_with_a_forgiving_neighbourhood():
    near, far, h, w = 1.0, 10.0, 6, 7
    buffer = np.full((h, w), window_depth(5.0, near, far))
    buffer[h - 1 - 1, 3] = window_depth(8.0, near, far)  # screen pixel (3, 1) is farther
    pixels = np.array([(0.5, 4.5), (0.5, 4.5), (0.5, 4.5),  # depths 5, 5.005, 5.5
                       (3.5, 1.5), (4.5, 2.5), (5.5, 1.5),  # at, beside, two away from the hole
                       (3.5, 4.5),  # where the hole would be without the bottom-up flip
                       (-0.5, 2.0), (7.0, 2.0), (2.0, 6.0), (6.99, 5.99)])  # edges of the screen
    depth = np.array([5.0, 5.005, 5.5, 7.9, 7.9, 7.9, 7.9, 5.0, 5.0, 5.0, 5.0])
    seen = sel.unoccluded(pixels, depth, buffer, near, far, tolerance=0.01)
    assert seen.tolist() == [True, True, False, True, True, False, False, False, False, False,
                             True]
