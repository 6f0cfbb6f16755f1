"""A new area's colour can be told apart from those already there and from the selection's
(issue #35). Seen red: with the old palette taken in order, a new vector area on the sample
was (255, 150, 40), 53 (redmean) from an existing area's colour and next to the selection's
orange; with the selection drawn in the area's colour, the dots and the vectors shared it."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QPushButton

from studio.core.wrinkles.colours import SELECTION, colour_distance, distinct_colour
from tests.gui_helpers import bring_forward


def test_the_redmean_distance_by_hand():
    assert colour_distance(np.array([0, 0, 0]), np.array([0, 0, 0])) == 0.0
    # pure red against black: r̄ = 127.5, so (2 + 127.5/256) · 255²
    assert colour_distance(np.array([255, 0, 0]), np.array([0, 0, 0])) == pytest.approx(
        np.sqrt((2 + 127.5 / 256) * 255 ** 2))
    assert colour_distance(np.array([0, 255, 0]), np.array([0, 0, 0])) == pytest.approx(510.0)


def test_a_new_colour_is_far_from_every_colour_in_use():
    rng = np.random.default_rng(3)
    used = [tuple(int(v) for v in c) for c in rng.integers(0, 256, (17, 3))]
    new = distinct_colour(used)
    nearest = colour_distance(np.array([*used, SELECTION]), np.array(new)).min()
    assert nearest > 90
    assert distinct_colour([]) != SELECTION
    assert colour_distance(np.array(distinct_colour([(255, 0, 0)])), np.array(SELECTION)) > 100


def test_a_new_vector_area_and_the_selection_read_apart_on_the_sample(open_window, qtbot):
    from studio.widgets.main_window import sample_project

    window = open_window(sample_project())
    panel = window.wdv_tools.panel
    bring_forward(panel)
    before = [a.colour for a in window.doc.project.wdv.areas]
    add = next(b for b in panel.findChildren(QPushButton) if b.text() == "Add")
    qtbot.mouseClick(add, Qt.MouseButton.LeftButton)
    new = window.doc.project.wdv.areas[-1].colour
    assert colour_distance(np.array(before), np.array(new)).min() > 60
    overlay = window.wdv_tools.overlay
    assert overlay.point_colour[:3] == pytest.approx(tuple(c / 255 for c in SELECTION))
