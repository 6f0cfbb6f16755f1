"""What a selection gesture may pick, on hand-built inputs whose answers are known: the CPU
occlusion test (two parallel quads, the nearer hiding part of the farther), the depth-buffer
test on a tiny buffer, the exact ray cast under it, and the screen regions and mask helpers."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.mesh import selection as sel
from studio.core.mesh.picking import ray_triangles
from studio.core.mesh.selection import unoccluded_by_rays

pytestmark = pytest.mark.core

EYE = (0, 0, 5)  # ints on purpose: the eye may come as any sequence
# 0-3: back quad at z = 0, x and y in −1 … 1; 4-7: front quad at z = 1, x in 0.5 … 3, y in −2 … 2
# (a ray from the eye to a back corner crosses z = 1 at 0.8 of the corner's x and y, so the
# corners with x = 1 are hidden and those with x = −1 are not); 8: a loose vertex out in the
# open; 9: a loose vertex behind the front quad.
POSITIONS = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0],
                      [0.5, -2, 1], [3, -2, 1], [3, 2, 1], [0.5, 2, 1],
                      [5, 5, 0], [2, 0, -1]], np.float64)
TRIANGLES = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])


def test_vertices_behind_the_near_quad_are_hidden_and_the_rest_seen():
    """Each candidate is judged by what lies between it and the eye, in the candidates' order."""
    seen = unoccluded_by_rays(POSITIONS, TRIANGLES, EYE, np.arange(10), tolerance=1e-6)
    assert seen.dtype == bool
    assert seen.tolist() == [True, False, False, True, True, True, True, True, True, False]


def test_only_the_candidates_are_judged_in_the_order_given():
    """The answer has one entry per candidate (a list will do), not per vertex."""
    seen = unoccluded_by_rays(POSITIONS, TRIANGLES, EYE, [9, 3, 2, 8], tolerance=1e-6)
    assert seen.dtype == bool
    assert seen.tolist() == [False, True, False, True]
    assert unoccluded_by_rays(POSITIONS, TRIANGLES, EYE, [], tolerance=1e-6).tolist() == []


def test_a_vertex_first_hit_on_its_own_surface_is_seen_even_without_tolerance():
    """A ray that reaches the vertex's own triangle exactly at the vertex does not hide it."""
    positions = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], np.float64)
    seen = unoccluded_by_rays(positions, np.array([[0, 1, 2]]), [0.0, 0.0, 4.0], [0],
                              tolerance=0.0)
    assert seen.tolist() == [True]


def test_surface_within_the_tolerance_in_front_does_not_hide():
    """Skin a little in front of a vertex (closer than the tolerance) does not count as cover;
    the same skin further in front does."""
    # a vertex at the origin under a triangle at height h, seen from (0, 0, 4)
    def seen_under(height: float, tolerance: float) -> bool:
        positions = np.array([[0, 0, 0], [-1, -1, height], [3, -1, height], [-1, 3, height]],
                             np.float64)
        return bool(unoccluded_by_rays(positions, np.array([[1, 2, 3]]), [0.0, 0.0, 4.0], [0],
                                       tolerance)[0])

    assert seen_under(0.05, tolerance=0.1)
    assert not seen_under(0.2, tolerance=0.1)
    assert not seen_under(0.05, tolerance=0.01)


# --- the exact ray cast under it ---------------------------------------------------------------

def test_a_ray_through_no_triangles_hits_nothing():
    """A mesh part without triangles is simply never hit."""
    none = np.zeros((0, 3), np.int64)
    assert ray_triangles([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], POSITIONS, none) is None


@pytest.mark.parametrize("scale", [1e-13, 1e-7, 1.0, 1e13])
def test_a_ray_hits_a_triangle_in_any_units(scale):
    """Whether a triangle is too thin to hit is judged relative to its own size, so the same
    triangle is hit at the same place in any units, however small or large."""
    positions = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]) * scale
    hit = ray_triangles(np.array([0.25, 0.25, 2.0]) * scale, [0.0, 0.0, -1.0], positions,
                        np.array([[0, 1, 2]]))
    assert hit is not None
    assert hit.distance == pytest.approx(2.0 * scale)
    np.testing.assert_allclose(hit.barycentric, [0.5, 0.25, 0.25], atol=1e-9)


# --- the depth-buffer test -----------------------------------------------------------------------

# a 5 × 4 viewport, near plane 1 and far plane 9: depth-buffer value 0 is surface at view depth 1
# (right in front), 1 is nothing (the far plane, 9); the vertex sits at view depth 5
W, H, NEAR, FAR = 5, 4, 1.0, 9.0


def seen_with_background_at(pixel: tuple[float, float], cell: tuple[int, int] | None) -> bool:
    """Whether a vertex at depth 5 drawn at ``pixel`` (x right, y down) passes, when the surface
    covers the whole viewport but for one background pixel ``cell`` (column, row from the top)."""
    screen = np.zeros((H, W), np.float32)
    if cell is not None:
        screen[cell[1], cell[0]] = 1.0
    buffer = np.flipud(screen)  # rows from the bottom, as OpenGL reads them
    return bool(sel.unoccluded(np.array([pixel], np.float64), np.array([5.0]), buffer, NEAR, FAR,
                               tolerance=0.0)[0])


@pytest.mark.parametrize(("pixel", "cell", "expected"), [
    ((2.5, 1.5), None, False),  # surface all around: hidden
    ((2.5, 1.5), (2, 1), True),  # its own pixel is background
    ((2.5, 1.5), (3, 1), True),  # each of the 8 neighbours forgives it
    ((2.5, 1.5), (1, 1), True),
    ((2.5, 1.5), (2, 0), True),
    ((2.5, 1.5), (2, 2), True),
    ((2.5, 1.5), (1, 0), True),
    ((2.5, 1.5), (3, 2), True),
    ((2.5, 1.5), (4, 1), False),  # two pixels away does not
    ((2.5, 1.5), (0, 1), False),
    ((2.5, 1.5), (2, 3), False),
    ((0.5, 1.5), (0, 1), True),  # at the left edge: its own column …
    ((0.5, 1.5), (1, 1), True),  # … and the next
    ((0.5, 1.5), (2, 1), False),  # but not two columns in, nor the far edge
    ((0.5, 1.5), (4, 1), False),
    ((4.5, 1.5), (4, 1), True),  # at the right edge
    ((4.5, 1.5), (3, 1), True),
    ((4.5, 1.5), (2, 1), False),
    ((4.5, 1.5), (0, 1), False),
    ((2.5, 3.5), (2, 3), True),  # on the bottom row
    ((2.5, 3.5), (2, 2), True),
    ((2.5, 3.5), (2, 1), False),
    ((2.5, 3.5), (2, 0), False),
    ((2.5, 0.5), (2, 0), True),  # on the top row
    ((2.5, 0.5), (2, 1), True),
    ((2.5, 0.5), (2, 2), False),
    ((2.5, 0.5), (2, 3), False),
    ((0.0, 1.5), (0, 1), True),  # the viewport's first column and row are on screen
    ((2.5, 0.0), (2, 0), True),
    ((4.999, 3.999), (4, 3), True),
    ((-0.01, 1.5), (0, 1), False),  # just off screen on every side
    ((2.5, -0.01), (2, 0), False),
    ((5.0, 1.5), (4, 1), False),
    ((2.5, 4.0), (2, 3), False),
])
def test_the_depth_buffer_hides_a_vertex_unless_its_3x3_neighbourhood_shows_background(
        pixel, cell, expected):
    """A vertex behind the surface passes only where background shows within one pixel of it,
    at the viewport's edges too; a vertex off screen never passes."""
    assert seen_with_background_at(pixel, cell) is expected


def test_the_depth_buffer_tolerance_is_inclusive():
    """A vertex exactly as deep as the farthest surface near it, or within the tolerance behind
    it, passes; a little further does not."""
    buffer = np.array([[0.0, 1.0]], np.float32)  # one row: surface (depth 1), background (9)
    at = np.array([[1.5, 0.5], [1.5, 0.5]])
    assert sel.unoccluded(at, np.array([9.0, 9.5]), buffer, NEAR, FAR,
                          tolerance=0.0).tolist() == [True, False]
    surface = np.zeros((3, 3), np.float32)  # surface everywhere, at view depth 1
    centre = np.array([[1.5, 1.5], [1.5, 1.5], [1.5, 1.5]])
    assert sel.unoccluded(centre, np.array([1.0, 1.5, 1.6]), surface, NEAR, FAR,
                          tolerance=0.5).tolist() == [True, True, False]


def test_linear_depth_keeps_double_precision_for_a_float32_buffer():
    """A float32 depth buffer (what OpenGL gives back) is turned into distances in double
    precision: near the far plane float32 arithmetic would be far off."""
    window = np.array([0.0, 0.5, 0.99999, 1.0], np.float32)
    exact = sel.linear_depth(window.astype(np.float64), 0.01, 1000.0)
    got = sel.linear_depth(window, 0.01, 1000.0)
    assert got.dtype == np.float64
    np.testing.assert_allclose(got, exact, rtol=1e-12)
    np.testing.assert_allclose(got[[0, 3]], [0.01, 1000.0], rtol=1e-12)


# --- screen regions ------------------------------------------------------------------------------

def test_a_triangle_lasso_selects_what_lies_inside_its_slanted_sides():
    """The smallest lasso, a triangle, works; points either side of its slanted sides are told
    apart exactly (triangle (0, 15), (10, 5), (10, 15): inside where x + y > 15)."""
    triangle = [(0, 15), (10, 5), (10, 15)]
    pixels = np.array([[2.0, 14.0], [1.0, 13.0], [9.0, 7.0], [9.0, 5.5], [6.0, 10.0],
                       [4.0, 10.0], [5.0, 14.9], [11.0, 10.0], [-1.0, 15.0]])
    assert sel.in_lasso(pixels, triangle).tolist() == [True, False, True, False, True,
                                                       False, True, False, False]


def test_a_lasso_drawn_from_its_far_corner_still_finds_points_near_the_origin():
    """Where the outline starts does not matter: a slanted quadrilateral drawn from its
    bottom-right corner selects the same as drawn from its top-left one."""
    quad = np.array([[40.0, 42.0], [12.0, 30.0], [2.0, 3.0], [30.0, 10.0]])
    pixels = np.array([[5.0, 5.0], [20.0, 20.0], [35.0, 35.0], [3.0, 20.0], [38.0, 15.0],
                       [25.0, 40.0]])
    expected = [True, True, True, False, False, False]
    assert sel.in_lasso(pixels, quad).tolist() == expected
    assert sel.in_lasso(pixels, np.roll(quad, 2, axis=0)).tolist() == expected
    assert sel.in_lasso(pixels, quad[::-1]).tolist() == expected


def test_a_lasso_of_two_points_selects_nothing():
    """A click-and-release lasso (fewer than three points) has no inside."""
    pixels = np.array([[1.0, 1.0], [0.0, 0.0]])
    assert sel.in_lasso(pixels, [(0, 0), (2, 2)]).tolist() == [False, False]


def test_the_brush_includes_its_rim():
    """A pixel exactly one radius from the brush centre is inside the brush."""
    pixels = np.array([[13.0, 24.0], [13.0, 25.0], [10.0, 20.0]])
    assert sel.in_circle(pixels, (10, 20), 5.0).tolist() == [True, False, True]


# --- click picking -------------------------------------------------------------------------------

def click_view() -> sel.ScreenView:
    """Four vertices near pixel (100, 50): #0 farthest, #1 nearest but hidden, #2 next nearest
    and visible, #3 behind the camera."""
    pixels = np.array([[104.0, 50.0], [100.0, 51.0], [98.0, 48.0], [100.0, 50.0]])
    depth = np.array([2.0, 2.0, 2.0, -1.0])
    visible = np.array([True, False, True, True])
    return sel.ScreenView(pixels, depth, visible.copy(), visible)


def test_a_click_picks_the_nearest_visible_vertex():
    """The closest pickable vertex to the click wins; a hidden one is passed over unless
    selecting through, and nothing behind the camera is picked."""
    view = click_view()
    assert sel.nearest_in_radius(view, 100.0, 50.0, 10.0) == 2
    assert sel.nearest_in_radius(view, 100.0, 50.0, 10.0, through=True) == 1
    assert sel.nearest_in_radius(view, 105.0, 50.0, 2.0) == 0
    assert sel.nearest_in_radius(view, 200.0, 50.0, 10.0) is None


# --- topology and masks --------------------------------------------------------------------------

def test_edges_of_a_large_mesh_with_32_bit_indices():
    """Vertex indices beyond 65 536 in a uint32 index array (glTF's) still give exact edges."""
    tris = np.array([[0, 70000, 70001], [70001, 70000, 99999]], np.uint32)
    assert sel.edges(tris).tolist() == [[0, 70000], [0, 70001], [70000, 70001], [70000, 99999],
                                        [70001, 99999]]


def test_no_triangles_have_no_edges():
    """An empty mesh has no edges (not an error)."""
    assert sel.edges(np.zeros((0, 3), np.int64)).shape == (0, 2)


CHAIN = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])  # six vertices in a row


def test_a_0_1_mask_grows_shrinks_inverts_and_mirrors_like_a_bool_one():
    """Selections stored as 0/1 bytes give the same boolean answers as bool masks."""
    mask = np.array([0, 0, 1, 1, 0, 0], np.uint8)
    grown = sel.grow(mask, CHAIN)
    assert grown.dtype == bool and grown.tolist() == [False, True, True, True, True, False]
    wide = np.array([0, 1, 1, 1, 1, 0], np.uint8)
    assert sel.shrink(wide, CHAIN).tolist() == [False, False, True, True, False, False]
    inverted = sel.invert(mask)
    assert inverted.dtype == bool and inverted.tolist() == [True, True, False, False, True, True]
    reverse = np.arange(6)[::-1]  # the chain is symmetric about its middle
    one = np.array([1, 0, 0, 0, 0, 0], np.uint8)
    assert sel.mirror(one, reverse).tolist() == [True, False, False, False, False, True]
    assert sel.mirror(one, reverse, keep=False).tolist() == [False] * 5 + [True]


def test_shrink_by_several_steps():
    """Shrinking two steps peels two vertices off each end of a selected run."""
    everything_but_ends = np.array([False, True, True, True, True, False])
    assert sel.shrink(everything_but_ends, CHAIN, steps=2).tolist() == [False] * 6
    seven = np.ones(8, bool)
    seven[0] = False
    chain8 = np.c_[np.arange(7), np.arange(1, 8)]
    assert sel.shrink(seven, chain8, steps=2).tolist() == [False] * 3 + [True] * 5
