"""A key clicked into a row goes in at the weight the person set, and the rest of the curve keeps
its shape: one added between keys changes the curve only between them, one added past the last
key does not hold its weight to the end of the animation."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPointF, Qt

from tests.test_timeline_gui import click_track, keys


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1200, 900)


def scrub_ruler(qtbot, panel, frame: float) -> None:
    """A click on the time ruler at ``frame``."""
    ruler = panel.ruler.getViewBox()
    middle = ruler.mapSceneToView(ruler.sceneBoundingRect().center()).y()
    pos = panel.view.mapFromScene(ruler.mapViewToScene(QPointF(frame, middle)))
    qtbot.mouseClick(panel.view.viewport(), Qt.MouseButton.LeftButton, pos=pos)


def drawn_weight(panel, pose: str, frame: float) -> float:
    """The weight the row's curve shows at ``frame`` (its height above the baseline)."""
    from studio.widgets.timeline.panel import ROW_BAND, ROW_PAD

    x, y = panel.track_curves[pose].getData()
    return float((np.interp(frame, x, y) - panel.row_of(pose) - ROW_PAD) / ROW_BAND)


def test_a_key_between_keys_changes_the_curve_only_between_them(window, qtbot):
    """Surprise rises 72→84, holds to 96, falls to 108: a key clicked at 90 and 0.5 dips the
    hold and leaves the rise, the fall and everything else as it was."""
    panel, doc = window.timeline_panel, window.doc
    track = doc.project.timeline.track("surprise")
    frames = np.arange(0.0, 181.0)
    before = track.values_at(frames)
    click_track(qtbot, panel, "surprise", 90, 0.5)
    assert [k[:2] for k in keys(window, "surprise")] == [
        (72, 0), (84, 1), (90, 0.5), (96, 1), (108, 0)]
    after = doc.project.timeline.track("surprise").values_at(frames)
    outside = (frames <= 84) | (frames >= 96)
    assert after[outside] == pytest.approx(before[outside])
    assert after[90] == 0.5
    scrub_ruler(qtbot, panel, 90)
    assert doc.pose_weights["surprise"] == 0.5  # the face shows the weight that was set
    assert drawn_weight(panel, "surprise", 90) == pytest.approx(0.5, abs=0.02)


def test_a_key_past_the_last_does_not_hold_its_weight_to_the_end(window, qtbot):
    """Red once: with ``add_key`` merging the key in as before (``_merge_frame`` instead of
    ``insert_key``) the surprise stayed at 0.8 from frame 130 to the end."""
    panel, doc = window.timeline_panel, window.doc
    end = doc.project.timeline.end
    click_track(qtbot, panel, "surprise", 130, 0.8)
    assert (130.0, 0.8) in [k[:2] for k in keys(window, "surprise")]
    assert doc.undo_stack.count() == 1  # one step, the way back included
    scrub_ruler(qtbot, panel, 130)
    assert doc.pose_weights["surprise"] == pytest.approx(0.8)
    scrub_ruler(qtbot, panel, end)
    assert doc.frame == end
    assert doc.pose_weights["surprise"] == 0.0  # back to what the track held
    assert drawn_weight(panel, "surprise", end) == pytest.approx(0.0, abs=0.02)
    assert drawn_weight(panel, "surprise", 130) == pytest.approx(0.8, abs=0.02)
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert [k[:2] for k in keys(window, "surprise")] == [(72, 0), (84, 1), (96, 1), (108, 0)]
