"""The time ruler and the curves scrub, as on Blender's timeline: a click or a left drag on the
ruler or in the curves moves the playhead (never an edit), and no drag or wheel pans the view
to the frames before the first."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from tests.test_timeline_gui import wheel


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1200, 900)


def at_frame(panel, box, frame: float) -> QPoint:
    """The pixel of ``frame`` half-way up a view box of the timeline (ruler, rows, curves)."""
    middle = box.mapSceneToView(box.sceneBoundingRect().center()).y()
    return panel.view.mapFromScene(box.mapViewToScene(QPointF(frame, middle)))


def drag(qtbot, panel, start: QPoint, end: QPoint,
         button: Qt.MouseButton = Qt.MouseButton.LeftButton) -> None:
    viewport = panel.view.viewport()
    qtbot.mousePress(viewport, button, pos=start)
    for i in range(1, 11):
        qtbot.mouseMove(viewport, start + (end - start) * (i / 10))
    qtbot.mouseRelease(viewport, button, pos=end)


def test_clicking_and_dragging_on_the_ruler_moves_the_playhead(window, qtbot):
    """Red once: with the ruler's view box a plain ``TimeViewBox`` (no ``ScrubViewBox``) a click
    on the ruler left the playhead at 0 and a drag panned the view."""
    panel, doc = window.timeline_panel, window.doc
    ruler = panel.ruler.getViewBox()
    assert ruler.sceneBoundingRect().bottom() <= panel.track_box.sceneBoundingRect().top()
    qtbot.mouseClick(panel.view.viewport(), Qt.MouseButton.LeftButton,
                     pos=at_frame(panel, ruler, 60))
    assert doc.frame == pytest.approx(60, abs=1)
    shown = panel.track_box.viewRange()[0]
    drag(qtbot, panel, at_frame(panel, ruler, 20), at_frame(panel, ruler, 120))
    assert doc.frame == pytest.approx(120, abs=1)
    assert panel.track_box.viewRange()[0] == pytest.approx(shown)  # scrubbing never pans
    # what is shown: the playhead on the rows and its frame box on the ruler
    assert panel.playhead.value() == doc.frame == panel.ruler_playhead.value()
    assert panel.frame_label.text().startswith(f"Frame {doc.frame:.0f}")
    assert doc.undo_stack.count() == 0  # scrubbing is not an edit


def test_a_left_drag_in_the_curves_scrubs_instead_of_panning(window, qtbot):
    """Red once: with the curves' view box pyqtgraph's own (``pg.ViewBox``) the drag panned the
    view to negative frames and the playhead stayed at 0."""
    panel, doc = window.timeline_panel, window.doc
    curves = panel.curves.getViewBox()
    shown = panel.track_box.viewRange()[0]
    drag(qtbot, panel, at_frame(panel, curves, 10), at_frame(panel, curves, 90))
    assert doc.frame == pytest.approx(90, abs=1)
    assert panel.track_box.viewRange()[0] == pytest.approx(shown)
    assert panel.curve_playhead.value() == doc.frame


def test_the_view_never_pans_or_zooms_before_the_first_frame(window, qtbot):
    """Red once: without the view box's ``setLimits(xMin=…)`` (``frame_all_time``) a middle
    drag to the right showed frames down to about -27."""
    panel = window.timeline_panel
    timeline = window.doc.project.timeline
    span = timeline.end - timeline.start
    curves = panel.curves.getViewBox()
    wheel(panel.view.viewport(), at_frame(panel, curves, 60), 3)  # zoom in on frame 60
    lo, hi = panel.track_box.viewRange()[0]
    assert hi - lo < 0.8 * span and lo > 5
    for button in (Qt.MouseButton.MiddleButton, Qt.MouseButton.RightButton):
        for _ in range(3):  # drag the view rightwards (towards earlier frames), far
            drag(qtbot, panel, at_frame(panel, curves, lo + 0.1 * (hi - lo)),
                 at_frame(panel, curves, lo + 0.9 * (hi - lo)), button)
        assert panel.track_box.viewRange()[0][0] >= timeline.start - max(0.02 * span, 1.0) - 1e-6
    wheel(panel.view.viewport(), at_frame(panel, curves, 10), -8)  # zoom all the way out
    assert panel.track_box.viewRange()[0][0] >= timeline.start - max(0.02 * span, 1.0) - 1e-6
    assert panel.ruler.getViewBox().viewRange()[0] == pytest.approx(panel.track_box.viewRange()[0])
