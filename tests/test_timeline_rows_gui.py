"""Track rows a weight can be clicked into: tall enough, the baseline 0 and the top 1 easy to
hit, their height the user's (the Rows control or a drag on the names, remembered), and the
current row — the pose K keys — marked."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, Qt

from studio.core.animation.timeline import Timeline
from studio.widgets.app_settings import settings
from studio.widgets.timeline.panel import ROW_HEIGHT_KEY
from tests.test_timeline_gui import keys, show_row


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1200, 900)


@pytest.fixture(autouse=True)
def default_row_height():
    """Every test starts, and leaves the next one, with the rows' default height."""
    settings().remove(ROW_HEIGHT_KEY)
    yield
    settings().remove(ROW_HEIGHT_KEY)


@pytest.fixture
def blank(open_window, sample):
    sample.timeline = Timeline()
    return open_window(sample)


def row_pitch(panel) -> float:
    """Pixels from the top row's baseline to the next row's (shown, or just below)."""
    first = panel.visible_rows()[0]
    second = panel.poses[panel.poses.index(first) + 1]
    return panel.key_widget_pos(second, 0, 0).y() - panel.key_widget_pos(first, 0, 0).y()


def click(qtbot, panel, pos: QPoint) -> None:
    qtbot.mouseClick(panel.view.viewport(), Qt.MouseButton.LeftButton, pos=pos)


def test_a_click_on_the_baseline_is_weight_zero_and_rows_are_tall(blank, qtbot):
    """Red once: with the old 16-pixel rows and the snap to 0 a share of the row
    (``1.5 * VALUE_SNAP`` instead of ``SNAP_PIXELS``) a click 3 px above the baseline gave
    0.2 (the issue's 0.15 came from the same rows)."""
    panel = blank.timeline_panel
    show_row(qtbot, panel, "frown")
    baseline = panel.key_widget_pos("frown", 10, 0.0)
    top = panel.key_widget_pos("frown", 30, 1.0)
    click(qtbot, panel, baseline + QPoint(0, -3))
    click(qtbot, panel, top + QPoint(0, 3))
    middle = panel.key_widget_pos("frown", 50, 0.5)
    click(qtbot, panel, middle)
    assert [k[:2] for k in keys(blank, "frown")] == [(10.0, 0.0), (30.0, 1.0),
                                                     (50.0, pytest.approx(0.5, abs=0.05)),
                                                     (96.0, 0.0)]  # back to 0 at the end
    assert row_pitch(panel) == pytest.approx(32, abs=1)
    assert top.y() - baseline.y() <= -24  # 0..1 over 24 px: 0.05 is more than a pixel


def test_the_rows_height_is_set_by_the_control_or_a_drag_and_remembered(open_window, sample,
                                                                         qtbot):
    """Red once: without ``settings().setValue(ROW_HEIGHT_KEY, …)`` in ``set_row_pixels`` the
    next window's rows were 32 px again; with the names' drag branch (``axis == 1``) taken out
    of ``TrackViewBox.mouseDragEvent`` the drag scrubbed and left the rows 48 px."""
    window = open_window(sample)
    panel = window.timeline_panel
    spin = panel.row_height
    qtbot.mouseClick(spin.lineEdit(), Qt.MouseButton.LeftButton)
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(spin.lineEdit(), "48")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    assert panel.row_pixels == 48
    assert row_pitch(panel) == pytest.approx(48, abs=1)
    # the bottom edge of the top row, in the names' column, dragged 24 px down
    names = panel.tracks.getAxis("left").sceneBoundingRect()
    top_of_rows = panel.view.mapFromScene(panel.track_box.sceneBoundingRect().topLeft()).y()
    first_bottom = top_of_rows + 48
    x = panel.view.mapFromScene(names.center()).x()
    viewport = panel.view.viewport()
    start, end = QPoint(x, first_bottom), QPoint(x, first_bottom + 24)
    qtbot.mousePress(viewport, Qt.MouseButton.LeftButton, pos=start)
    for i in range(1, 9):
        qtbot.mouseMove(viewport, start + (end - start) * (i / 8))
        qtbot.wait(20)  # a hand's pace: pyqtgraph drops moves that come too fast
    qtbot.mouseRelease(viewport, Qt.MouseButton.LeftButton, pos=end)
    assert panel.row_pixels == pytest.approx(72, abs=2)
    assert spin.value() == panel.row_pixels
    assert row_pitch(panel) == pytest.approx(panel.row_pixels, abs=1)
    assert window.doc.undo_stack.count() == 0 and window.doc.frame == 0  # neither edit nor scrub
    chosen = panel.row_pixels
    again = open_window(sample).timeline_panel
    assert again.row_pixels == chosen and again.row_height.value() == chosen


def test_the_current_row_is_marked(blank, qtbot):
    """Red once: with ``set_current_pose`` not moving ``row_marker`` the band stayed where it
    was (on the bottom row) after a click in surprise's row."""
    panel = blank.timeline_panel
    show_row(qtbot, panel, "surprise")
    click(qtbot, panel, panel.key_widget_pos("surprise", 10, 1.0))
    row = panel.row_of("surprise")
    assert panel.current_pose == "surprise"
    assert panel.row_marker.isVisible() and panel.row_marker.getRegion() == (row, row + 1)
    names = dict(panel.tracks.getAxis("left")._tickLevels[0])
    assert names[row + 0.5] == "▸ surprise"  # the pointer in the names' column too
    assert sum(name.startswith("▸") for name in names.values()) == 1
    qtbot.wait(50)
    image = panel.view.grab().toImage()
    others = [p for p in panel.visible_rows() if p != "surprise"]
    assert others

    def tint(pose: str) -> int:
        """Red + green − 2·blue of an empty spot of a row, above its curve: the yellow band."""
        at = panel.key_widget_pos(pose, 80, 1.1)  # above the top of the curve
        colour = image.pixelColor(at.x(), at.y())
        return colour.red() + colour.green() - 2 * colour.blue()

    assert tint("surprise") > tint(others[0]) + 10


def test_the_weight_a_click_would_set_shows_beside_the_pointer(blank, qtbot):
    """Red once: with ``TrackViewBox.hoverEvent`` taken out the label never showed."""
    panel = blank.timeline_panel
    show_row(qtbot, panel, "frown")
    viewport = panel.view.viewport()

    def hover_at(frame: float, value: float) -> None:
        at = panel.key_widget_pos("frown", frame, value)
        for dx in (-6, -3, 0):
            qtbot.mouseMove(viewport, at + QPoint(dx, 0))
            qtbot.wait(30)  # a hand's pace: pyqtgraph drops moves that come too fast

    hover_at(40, 0.0)
    assert panel.weight_label.isVisible() and panel.weight_label.textItem.toPlainText() == (
        "40: 0.00")
    hover_at(40, 0.5)
    assert panel.weight_label.textItem.toPlainText() == "40: 0.50"
    click(qtbot, panel, panel.key_widget_pos("frown", 40, 0.5))
    assert (40.0, 0.5) in [k[:2] for k in keys(blank, "frown")]  # the weight it said
    hover_at(40, 0.5)  # over the new key: a click would select it, not key
    assert not panel.weight_label.isVisible()
