"""A pose's onset on the Furrows panel with real events (issue 45, point 6): on the sample at half
a brow raise, an onset of 0.6 typed for that pose and Return takes the forehead's lines out of
the viewport (the pose still held) as one undo step, Ctrl+Z brings them back; a drag of the onset
for all poses is one step more; Ctrl+S saves the onset and the reopened project's panel shows
it."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face
from tests.gui_helpers import drag_slider, viewport_image, viewport_marks
from tests.regions import region_difference
from tests.test_files_gui import activate
from tests.test_furrow_controls_gui import (
    choose_pose,
    drag_handle,
    save_with_ctrl_s,
    settled_image,
    type_value,
)

CTRL = Qt.KeyboardModifier.ControlModifier
POSE = "surprise"  # raises both brows: the forehead's lines
CHANGED = 4.0
SAME = 0.5


def test_an_onset_typed_for_a_pose_holds_its_lines_back_and_undoes_in_one_step(
        open_window, qtbot, tmp_path, monkeypatch):
    window = open_window(make_test_face())
    doc, panel = window.doc, window.furrow_panel
    drag_slider(qtbot, window.pose_panel.pose_rows[POSE].slider, 0.5)
    weight = doc.pose_weights[POSE]
    assert 0.4 < weight < 0.6
    lined = settled_image(qtbot, window)
    forehead = viewport_marks(window)["forehead"]
    resting = doc.project.influence.activations({POSE: 0.0})
    assert not np.array_equal(doc.activations(), resting)  # half the pose: its areas show
    steps = doc.undo_stack.count()

    choose_pose(qtbot, panel, POSE)
    assert panel.rows["onset"].isEnabled()
    type_value(qtbot, panel.rows["onset"].spin, "0.6")
    assert doc.project.furrows.of(POSE).onset == 0.6
    assert doc.undo_stack.count() == steps + 1
    assert doc.pose_weights[POSE] == weight  # the face keeps its pose
    assert np.array_equal(doc.activations(), resting)  # technique 1: no lines yet
    held = settled_image(qtbot, window)
    assert region_difference(held, lined, forehead) > CHANGED  # technique 2's lines gone

    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_Z, CTRL)
    assert doc.project.furrows.of(POSE).onset == 0.0 and doc.undo_stack.index() == steps
    assert region_difference(settled_image(qtbot, window), lined, forehead) < SAME
    assert panel.rows["onset"].spin.value() == 0.0

    qtbot.keyClick(window, Qt.Key.Key_Z, CTRL | Qt.KeyboardModifier.ShiftModifier)  # redo
    assert doc.project.furrows.of(POSE).onset == 0.6
    panel.pose.setFocus()
    qtbot.keyClick(panel.pose, Qt.Key.Key_Home)  # the list's first entry
    assert panel.pose.currentText() == "All poses"
    drag_handle(qtbot, panel.rows["onset"].slider, 0.4)
    assert doc.project.furrows.all.onset == pytest.approx(0.38, abs=0.03)
    assert doc.undo_stack.count() == steps + 2  # the whole drag: one step

    saved = tmp_path / "onset.wrinkle"
    save_with_ctrl_s(qtbot, window, monkeypatch, saved)
    reopened = load_project(saved)
    assert reopened.furrows.controls(POSE).onset == 0.6
    assert reopened.furrows.all.onset == doc.project.furrows.all.onset

    again = open_window(reopened)
    choose_pose(qtbot, again.furrow_panel, POSE)
    assert again.furrow_panel.rows["onset"].spin.value() == 0.6
    assert viewport_image(again).any()
