"""What the Wrinkle vectors panel says, without Qt (studio/widgets/wdv/wdv_model.py), and the
layer-list rules it shares with the Areas panel (studio/widgets/layer_list_model.py)."""

from __future__ import annotations

import numpy as np
import pytest

from studio.core.animation.poses import NEUTRAL
from studio.widgets.layer_list_model import solo
from studio.widgets.wdv.wdv_model import (
    area_tooltip,
    colour_text,
    create_refused,
    created_text,
    flat_text,
    pose_choices,
    selection_text,
    suggested_text,
)

pytestmark = pytest.mark.core


def test_an_area_follows_any_pose_but_the_neutral():
    assert pose_choices([NEUTRAL, "browInnerUp", "Frown_L"]) == ["browInnerUp", "Frown_L"]


def test_an_areas_row_says_its_pose_vectors_and_painted_cones():
    authored = np.array([True, False, True, True])
    cones = np.array([0.0, 12.5, 0.0, 30.0])
    text = area_tooltip("Brow", "browInnerUp", authored, 25.0, cones)
    assert text.startswith("Brow: pose “browInnerUp”, 3 vectors, cone 25° (2 vertices painted)")
    assert "(0 vertices painted)" in area_tooltip("Brow", "browInnerUp", authored, 25.0, None)


def test_colour_and_selection_in_words():
    assert colour_text((255, 8, 160)) == " #ff08a0"
    assert selection_text(np.array([True, False, True])) == "2 of 3 vertices selected"
    assert suggested_text(np.array([True, True, False]), "Frown_L") == (
        "Suggested 2 vertices that “Frown_L” moves")


def test_the_flat_map_warning_names_the_area_and_pose():
    assert flat_text("Brow", None, "browInnerUp") == ""
    assert flat_text("Brow", "lands on a flat part of its map", "browInnerUp") == (
        "“Brow” lands on a flat part of its map at “browInnerUp”: select where the map has "
        "wrinkles, or choose another map.")


def test_create_says_why_it_cannot_run_and_what_it_made():
    assert create_refused(None, 10) == "Add an area first."
    assert create_refused("Brow", 0).startswith("Select the vertices first")
    assert create_refused("Brow", 3) == ""
    assert created_text(12, 0, "Brow", "browInnerUp") == (
        "12 wrinkle direction vectors created for “Brow”.", False)
    text, warning = created_text(12, 5, "Brow", "browInnerUp")
    assert warning and text == ("5 of the 12 selected vertices do not move in “browInnerUp”, "
                                "so they got no direction; 7 vectors created.")


def test_solo_mutes_the_others_and_again_shows_all():
    assert solo((True, False, True), 2, "Cheek") == ((False, False, True), "Solo Cheek")
    assert solo((False, False, True), 2, "Cheek") == ((True, True, True), "Show all areas")
