"""The viewport's gestures and words without Qt or GL: Blender's navigation, how far a drag turns
the camera, the numpad views, the split panes and the note on a reduced picture
(studio/widgets/viewport/viewport_model.py)."""

from __future__ import annotations

import itertools
from fractions import Fraction

import pytest

from studio.core.wrinkles.techniques import SPLIT
from studio.widgets.viewport.viewport_model import (
    camera_move,
    navigation,
    numpad_view,
    reduced_note,
    split_columns,
)

pytestmark = pytest.mark.core


@pytest.mark.parametrize(("button", "shift", "ctrl", "alt", "mode"), [
    ("middle", False, False, False, "orbit"), ("middle", True, False, False, "pan"),
    ("middle", False, True, False, "zoom"), ("left", False, False, True, "orbit"),
    ("left", True, False, True, "pan"), ("left", False, False, False, None),
    ("left", True, True, False, None), ("right", False, False, True, None)])
def test_navigation_follows_blender_and_leaves_the_left_button_to_tools(button, shift, ctrl,
                                                                          alt, mode):
    assert navigation(button, shift, ctrl, alt) == mode


def test_a_drag_turns_pans_or_zooms_by_the_pixels_moved():
    assert camera_move("orbit", 10, -5, 600) == ("orbit", (-4.0, -2.0))
    move, (x, y) = camera_move("pan", 30, 60, 600)
    assert move == "pan" and (x, y) == (pytest.approx(-0.05), pytest.approx(0.1))
    assert camera_move("pan", 1, 1, 0)[1] == (-1.0, 1.0)  # a collapsed view divides by one
    move, (factor,) = camera_move("zoom", 0, 10, 600)
    assert move == "zoom" and factor == pytest.approx(1.01 ** 10)


def test_numpad_keys_give_front_side_and_top_views():
    assert numpad_view("1", False) == (0.0, 0.0)
    assert numpad_view("3", False) == (90.0, 0.0) and numpad_view("3", True) == (-90.0, 0.0)
    assert numpad_view("7", True) == (0.0, 89.0)
    assert numpad_view("5", False) is None


def test_split_panes_cover_the_width_without_gaps():
    columns = split_columns(1001)
    assert len(columns) == len(SPLIT) and columns[0][0] == 0
    assert all(a + w == b for (a, w), (b, _) in itertools.pairwise(columns))
    assert sum(w for _, w in columns) == 1001


def test_the_picture_says_when_it_is_drawn_reduced():
    assert reduced_note(None, True, 4) is None  # a still frame
    assert reduced_note(Fraction(1, 3), False, 0) == (
        "drawing at 1/3 resolution while you move (software OpenGL)")
    assert reduced_note(Fraction(1), True, 4) == (
        "drawing without anti-aliasing while you move (software OpenGL)")
    assert reduced_note(Fraction(1), True, 1) is None
