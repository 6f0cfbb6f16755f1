"""The Comb tool's math (studio/core/wrinkles/comb.py), on cases worked out by hand.

The camera in these cases looks down −Z from the eye (0, 0, 5), right = +X, up = +Y; a stroke
(dx, dy) is in pixels with y down, so (10, 0) is to the right and (0, −10) is up.
"""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.wrinkles.comb import (
    CombBrush,
    blend_directions,
    comb_dab,
    combed_lengths,
    dab_weights,
    stroke_directions,
    typical_length,
)

EYE = np.array([0.0, 0.0, 5.0])
RIGHT = np.array([1.0, 0.0, 0.0])
UP = np.array([0.0, 1.0, 0.0])
S2, S3 = np.sqrt(2.0), np.sqrt(3.0)


def directions(normal, stroke, position=(0.0, 0.0, 0.0)):
    d, ok = stroke_directions(np.array([position]), np.array([normal]), EYE, RIGHT, UP, stroke)
    return d[0], bool(ok[0])


def test_a_face_on_surface_takes_the_stroke_as_it_is():
    # v = (0,0,-5), u = (1,0,0): v×u = (0,-5,0); n×(v×u) = (0,0,1)×(0,-5,0) = (5,0,0)
    d, ok = directions((0, 0, 1), (10, 0))
    assert ok and np.allclose(d, (1, 0, 0))
    # a stroke to the left is the opposite direction, not the same line turned around
    d, _ = directions((0, 0, 1), (-10, 0))
    assert np.allclose(d, (-1, 0, 0))
    # up on the screen (dy < 0) is +Y
    d, _ = directions((0, 0, 1), (0, -7))
    assert np.allclose(d, (0, 1, 0))


def test_a_back_face_is_combed_the_way_of_the_drag_too():
    """A vertex facing away (picked with "select through"): n = (0,0,−1), n×(v×u) =
    (0,0,−1)×(0,−5,0) = (−5,0,0), against the drag; turned, it is (1,0,0).
    Red once with the turn (``t[along < 0] *= -1``) removed by hand: it gave (−1, 0, 0)."""
    d, ok = directions((0, 0, -1), (10, 0))
    assert ok and np.allclose(d, (1, 0, 0))


def test_a_surface_tilted_back_is_combed_up_its_slope():
    # n = (0,1,1)/√2, u = (0,1,0): v×u = (5,0,0)/5·…; n×(1,0,0) = (0,1,−1)/√2
    d, ok = directions((0, 1 / S2, 1 / S2), (0, -10))
    assert ok and np.allclose(d, (0, 1 / S2, -1 / S2))


def test_the_stroke_is_projected_along_the_view_not_along_the_normal():
    """A surface turned to the side (n = (1,0,1)/√2) combed diagonally up-right: u = (1,1,0)/√2,
    v×u ∝ (1,−1,0), n×(1,−1,0) ∝ (1,1,−1), so d = (1,1,−1)/√3, which on screen is (1,1): on the
    drag. The orthogonal projection u − (u·n)n ∝ (1,2,−1) would show 18° off it."""
    d, ok = directions((1 / S2, 0, 1 / S2), (10, -10))
    assert ok and np.allclose(d, (1 / S3, 1 / S3, -1 / S3))
    assert abs(d @ np.array([1 / S2, 0, 1 / S2])) < 1e-12  # in the tangent plane


def test_off_axis_vertices_follow_the_perspective():
    """A vertex right of the view axis at (1, 0, 0) facing +Z: v = (1,0,−5), u = (0,1,0),
    v×u = (5,0,1), n×(5,0,1) = (0,5,0): up stays up; with u = (1,0,0), v×u = (0,−5,0) and
    n×(0,−5,0) = (5,0,0)."""
    d, _ = directions((0, 0, 1), (0, -3), position=(1, 0, 0))
    assert np.allclose(d, (0, 1, 0))
    d, _ = directions((0, 0, 1), (3, 0), position=(1, 0, 0))
    assert np.allclose(d, (1, 0, 0))


def test_a_surface_seen_edge_on_falls_back_to_the_orthogonal_projection():
    # n = (1,0,0) at the origin, stroke up: v×u ∝ (1,0,0) ∥ n, so n×(v×u) = 0;
    # u − (u·n)n = (0,1,0)
    d, ok = directions((1, 0, 0), (0, -10))
    assert ok and np.allclose(d, (0, 1, 0))
    # stroke right on it: the stroke plane y = 0 cuts the tangent plane x = 0 along the view
    # ray (0,0,±1), which moves nothing on screen, and u − (u·n)n = (1,0,0) − (1,0,0) = 0:
    # no direction, the vertex is left alone
    d, ok = directions((1, 0, 0), (10, 0))
    assert not ok and not d.any()


def test_no_stroke_no_direction():
    d, ok = stroke_directions(np.zeros((2, 3)), np.tile((0.0, 0.0, 1.0), (2, 1)), EYE, RIGHT,
                              UP, (0.0, 0.0))
    assert not ok.any() and not d.any()


def test_blending_bends_toward_the_target_and_takes_it_where_there_was_none():
    old = np.array([[1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0], [1.0, 0, 0]])
    target = np.array([[0.0, 1, 0], [0.0, 1, 0], [0.0, 1, 0], [0.0, 1, 0], [-1.0, 0, 0]])
    w = np.array([0.5, 1.0, 0.0, 0.2, 0.5])
    out = blend_directions(old, target, w)
    assert np.allclose(out[0], (1 / S2, 1 / S2, 0))  # (0.5, 0.5, 0) normalised
    assert np.allclose(out[1], (0, 1, 0))
    assert np.allclose(out[2], (1, 0, 0))  # no weight: untouched
    assert np.allclose(out[3], (0, 1, 0))  # unauthored: the comb at once
    assert np.allclose(out[4], (-1, 0, 0))  # opposed halves cancel: the comb wins
    # w = 0.25: (0.75, 0.25, 0)/|…| = (3, 1, 0)/√10
    assert np.allclose(blend_directions(old[:1], target[:1], [0.25])[0],
                       np.array([3, 1, 0]) / np.sqrt(10))


def test_dab_weights_are_strength_times_the_falloff():
    brush = CombBrush(radius=10.0, hardness=0.5, strength=0.8)
    pixels = np.array([[100.0, 100.0], [104.0, 103.0], [107.5, 100.0], [110.0, 100.0],
                       [200.0, 0.0]])
    w = dab_weights(pixels, (100.0, 100.0), brush)
    # distances 0, 5 (inside hardness·radius), 7.5 (t = (1 − .75)/.5 = .5: smoothstep .5),
    # 10 (the edge) and far
    assert np.allclose(w, [0.8, 0.8, 0.4, 0.0, 0.0])


def test_a_dab_changes_only_the_rows_it_reaches():
    brush = CombBrush(radius=10.0, hardness=0.999, strength=1.0)
    positions = np.array([[0.0, 0, 0], [0.1, 0, 0], [3.0, 0, 0]])
    normals = np.tile((0.0, 0.0, 1.0), (3, 1))
    pixels = np.array([[50.0, 50.0], [55.0, 50.0], [90.0, 50.0]])
    old = np.array([[0.0, 1, 0], [0.0, 0, 0], [0.0, 1, 0]], np.float32)
    rows, new = comb_dab(old, positions, normals, pixels, (50.0, 50.0), (4.0, 0.0), brush,
                         EYE, RIGHT, UP)
    assert rows.tolist() == [0, 1]
    assert np.allclose(new, [(1, 0, 0), (1, 0, 0)], atol=1e-6)
    assert new.dtype == np.float32


def test_combed_vertices_become_authored():
    lengths = np.array([0.5, 0.0, 0.0], np.float32)
    motion = np.array([0.7, 0.3, 0.0], np.float32)
    # kept where authored, the pose's motion where it moves, the fallback where it does not
    assert combed_lengths(lengths, motion, 0.2, 1e-6).tolist() == pytest.approx([0.5, 0.3, 0.2])
    # the fallback: the median motion of the moving vertices, else the face's size
    assert typical_length(np.array([0.0, 1.0, 2.0, 4.0]), 10.0) == 2.0
    assert typical_length(np.zeros(3), 10.0) == 10.0
