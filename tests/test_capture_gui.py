"""File ▸ Import Capture… with real events: the menu clicked and the shortcut pressed, the file
chooser answered (only it is replaced), the report and error dialogs read, one Ctrl+Z taking the
whole take back, and playback driving every captured pose every frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog

from studio.core.animation.pose_names import ARKIT_NAMES
from studio.core.animation.poses import KeyPose
from studio.core.animation.timeline import Timeline
from studio.core.formats.capture import import_capture
from studio.core.project.reader import load_project
from studio.widgets.timeline.edits import TimelineState
from tests.test_capture import (
    MATCHED,
    NO_POSE,
    ROTATION,
    expected_weights,
    head_project,
    timecode,
    write_take,
)
from tests.test_files_gui import activate, click_menu_path

CTRL = Qt.KeyboardModifier.ControlModifier
__all__ = ["head_project"]  # the module fixture, shared with the command-line tests


@pytest.fixture
def chooser(monkeypatch):
    """Answers the open-file dialog with the next queued path; records the folder it opened in."""
    answers: list[Path] = []
    folders: list[str] = []

    def choose(parent, caption="", folder="", filter="", *args, **kwargs):
        folders.append(folder)
        return (str(answers.pop(0)), filter) if answers else ("", "")

    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(choose))
    return answers, folders


def test_import_capture_keys_the_take_and_one_ctrl_z_removes_it(
        qtbot, open_window, dialogs, chooser, head_project, tmp_path):
    window = open_window(load_project(head_project))
    doc = window.doc
    t, values = write_take(tmp_path / "take.csv")
    answers, folders = chooser
    answers.append(tmp_path / "take.csv")
    before = doc.undo_stack.count()
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_I, CTRL)
    qtbot.waitUntil(lambda: bool(dialogs), timeout=10000)

    (kind, text), = dialogs
    assert kind == "information"
    assert f"columns without a pose (1): {NO_POSE}" in text and ROTATION in text
    assert "eyeSquint_R" in text
    assert doc.undo_stack.count() == before + 1
    timeline = doc.project.timeline
    expected = expected_weights(t, values, timeline.fps)
    frames = len(next(iter(expected.values())))
    assert timeline.end == frames - 1
    for frame in (0, 7, frames // 2, frames - 1):
        weights = timeline.weights_at(frame)
        for pose, curve in expected.items():
            assert abs(weights[pose] - curve[frame]) <= 1 / 255

    # playback: every captured pose is driven, and what the viewport's scene shows follows
    scene = window.viewport.scene
    for frame in (3, 4, 5):
        doc.show_frame(frame)
        qtbot.waitUntil(lambda f=frame: scene.weights.get("jawOpen")
                        == pytest.approx(expected["jawOpen"][f], abs=1 / 255), timeout=5000)
        assert set(MATCHED.values()) <= set(scene.weights)
        for pose, curve in expected.items():
            assert doc.pose_weights[pose] == pytest.approx(curve[frame], abs=1 / 255)

    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_Z, CTRL)
    assert doc.undo_stack.count() == before + 1 and doc.undo_stack.index() == before
    assert not doc.project.timeline.has_keys

    # the next import, from the menu, opens where the take was (and cancelling changes nothing)
    click_menu_path(qtbot, window, "File", "Import Capture…")
    qtbot.waitUntil(lambda: len(folders) == 2, timeout=5000)
    assert folders == [folders[0], str(tmp_path)]
    assert doc.undo_stack.index() == before and len(dialogs) == 1


def test_a_bad_take_is_an_error_dialog_and_changes_nothing(
        qtbot, open_window, dialogs, chooser, head_project, tmp_path):
    window = open_window(load_project(head_project))
    bad = tmp_path / "bad.csv"
    bad.write_text("Timecode,BlendShapeCount,JawOpen\n00:00:00:01.000,61,0.5\n"
                   "00:00:00:02.000,61\n")
    chooser[0].append(bad)
    click_menu_path(qtbot, window, "File", "Import Capture…")
    qtbot.waitUntil(lambda: bool(dialogs), timeout=10000)
    (kind, text), = dialogs
    assert kind == "critical"
    assert str(bad) in text and "line 3 has 2 values" in text
    assert "Traceback" not in text
    assert window.doc.undo_stack.count() == 0
    assert not window.doc.project.timeline.has_keys


def test_a_52_curve_take_drives_every_pose_each_frame(qtbot, open_window, sample, tmp_path):
    """A take of all 52 ARKit shapes on a face with all 52 poses: each frame of playback moves
    every one of them."""
    base = sample.poses[0].positions
    sample.poses = [KeyPose(name, base) for name in ARKIT_NAMES]
    sample.timeline = Timeline(fps=30.0)  # the sample's own animation names its old poses
    t = np.arange(121) / 60.0
    rows = [",".join([timecode(s), "61", *(f"{0.5 + 0.4 * np.sin(3 * s + k):.5f}"
                                          for k in range(52))]) for s in t]
    (tmp_path / "all.csv").write_text(
        "Timecode,BlendShapeCount," + ",".join(n[0].upper() + n[1:] for n in ARKIT_NAMES)
        + "\n" + "\n".join(rows) + "\n")
    window = open_window(sample)
    doc = window.doc
    timeline, report = import_capture(tmp_path / "all.csv", doc.project.timeline,
                                      list(ARKIT_NAMES))
    assert len(report.matched) == 52 and not report.unmatched
    window.timeline_panel.edits.push("Import capture", TimelineState.of(timeline))
    scene = window.viewport.scene
    previous = None
    for frame in range(1, 6):
        doc.show_frame(frame)
        qtbot.waitUntil(lambda: scene.weights == doc.pose_weights, timeout=5000)
        current = dict(scene.weights)
        assert len(current) == 52
        if previous is not None:
            assert all(current[n] != previous[n] for n in ARKIT_NAMES)
        previous = current
