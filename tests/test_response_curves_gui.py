"""Response curves in the Areas panel (issue #21): choosing a curve for a pose link and dragging
a custom curve's point change the document and the shaded face, one undo step each; area edits
keep the curves with their areas."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.response_handles import added, converted, moved, nearest, removed
from studio.widgets.paint.curve_edits import link_curve, set_link_curve
from tests.gui_helpers import viewport_image, viewport_marks
from tests.regions import region_difference

AREA, POSE = "between brows", "frown"  # the sample links frown → between brows with gain 1
EASE_IN = ResponseCurve("ease_in")


# --------------------------------------------------------------------------- handle edits

def test_handle_edits_keep_the_curve_valid() -> None:
    custom = converted(EASE_IN, "custom")
    assert custom.points[2] == (0.5, 0.25)
    dragged = moved(custom, 2, 0.9, 1.4)  # past the next point and above the square
    assert dragged.points[2] == (pytest.approx(0.749), 1.0)
    assert moved(custom, 0, -0.5, 0.3).points[0] == (0.0, 0.3)
    grown = added(custom, 0.6, 0.7)
    assert grown.points[3] == (0.6, 0.7) and len(grown.points) == 6
    assert added(custom, 0.5, 0.9) == custom  # on an existing point's x: refused
    assert removed(removed(removed(removed(custom, 1), 1), 1), 1).points == ((0.0, 0.0),
                                                                            (1.0, 1.0))
    step = converted(EASE_IN, "smooth_step")
    assert (step.start, step.end) == (0.25, 0.75)
    assert moved(step, 0, 0.9, 0.5) == ResponseCurve("smooth_step", 0.749, 0.75)
    assert nearest(custom, 0.52, 0.24, 0.05, 0.05) == 2
    assert nearest(custom, 0.4, 0.9, 0.05, 0.05) is None
    assert converted(custom, "ease_out") == ResponseCurve("ease_out")


# --------------------------------------------------------------------------- the panel

def between_brows_shading(window) -> tuple[np.ndarray, tuple[int, int]]:
    return viewport_image(window), viewport_marks(window)[AREA]


def plot_point(plot, index: int) -> QPoint:
    return plot.handle_position(index).toPoint()


def test_choosing_ease_in_and_dragging_a_custom_point_reshape_the_wrinkles(window, qtbot):
    doc = window.doc
    doc.set_view(technique="t1")
    doc.set_pose_weight(POSE, 0.5)
    window.docks["Areas"].show()
    window.docks["Areas"].raise_()
    panel = window.mask_tools.panel
    panel.select([a.name for a in doc.project.influence.areas].index(AREA))
    index = panel.state.active
    qtbot.waitUntil(lambda: window.viewport.frames_rendered > 0)
    linear, centre = between_brows_shading(window)
    steps = doc.undo_stack.count()
    assert doc.activations()[index] == pytest.approx(0.5)

    # ease in: y = x², so the link gives 0.25 at weight 0.5 — fewer wrinkles between the brows
    assert "squeeze" not in panel.link_editors  # not linked: not listed, no curve to edit
    editor = panel.link_editors[POSE]
    qtbot.waitUntil(lambda: editor.kind.isVisible() and editor.plot.isVisible())
    panel.ensureWidgetVisible(editor)
    qtbot.mouseClick(editor.kind, Qt.MouseButton.LeftButton)  # opens the list
    qtbot.keyClick(editor.kind.view(), Qt.Key.Key_Down)
    qtbot.keyClick(editor.kind.view(), Qt.Key.Key_Return)
    assert link_curve(doc, POSE, AREA) == EASE_IN
    assert doc.activations()[index] == pytest.approx(0.25)
    assert doc.undo_stack.count() == steps + 1
    qtbot.waitUntil(lambda: region_difference(linear, viewport_image(window), centre) > 2.0)
    eased = viewport_image(window)

    # custom, starting from the ease-in shape: its middle point (0.5, 0.25) dragged up
    editor.kind.setFocus()
    qtbot.keyClick(editor.kind, Qt.Key.Key_End)  # the last kind: custom
    custom = link_curve(doc, POSE, AREA)
    assert custom.kind == "custom" and custom.points[2] == (0.5, 0.25)
    assert doc.activations()[index] == pytest.approx(0.25)
    viewport = editor.plot.viewport()
    start = plot_point(editor.plot, 2)
    top = editor.plot.handle_position(4).toPoint()  # (1, 1): the height of response 1
    end = QPoint(start.x(), round(start.y() + (top.y() - start.y()) * 0.8))  # y ≈ 0.85
    qtbot.mousePress(viewport, Qt.MouseButton.LeftButton, pos=start)
    for i in range(1, 9):
        qtbot.mouseMove(viewport, QPoint(start.x(), start.y() + (end.y() - start.y()) * i // 8))
    qtbot.mouseRelease(viewport, Qt.MouseButton.LeftButton, pos=end)
    dragged = link_curve(doc, POSE, AREA)
    x, y = dragged.points[2]
    assert x == pytest.approx(0.5, abs=0.01) and y == pytest.approx(0.85, abs=0.03)
    assert doc.undo_stack.count() == steps + 3  # the choice of custom, then one for the drag
    assert doc.activations()[index] == pytest.approx(y, abs=0.02)
    qtbot.waitUntil(lambda: region_difference(eased, viewport_image(window), centre) > 2.0)
    assert editor.plot.points.data["y"][2] == pytest.approx(y)  # the plot shows it

    # Ctrl+Z: the drag, the custom choice, the ease in — the face is the linear one again
    window.viewport.setFocus()
    for curve in (custom, EASE_IN, ResponseCurve()):
        qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
        assert link_curve(doc, POSE, AREA) == curve
        assert editor.kind.currentData() == curve.kind
    assert doc.project.influence.curves == {}
    assert doc.activations()[index] == pytest.approx(0.5)
    qtbot.waitUntil(lambda: np.array_equal(viewport_image(window), linear))


def test_a_right_click_removes_a_point_and_a_double_click_adds_one(window, qtbot):
    doc, panel = window.doc, window.mask_tools.panel
    window.docks["Areas"].raise_()
    panel.select([a.name for a in doc.project.influence.areas].index(AREA))
    set_link_curve(doc, POSE, AREA, converted(EASE_IN, "custom"))
    plot = panel.link_editors[POSE].plot
    qtbot.mouseClick(plot.viewport(), Qt.MouseButton.RightButton, pos=plot_point(plot, 1))
    assert [x for x, _ in link_curve(doc, POSE, AREA).points] == [0.0, 0.5, 0.75, 1.0]
    a, b = plot_point(plot, 0), plot_point(plot, 1)
    between = QPoint((a.x() + b.x()) // 2, (a.y() + b.y()) // 2 - 20)
    qtbot.mouseDClick(plot.viewport(), Qt.MouseButton.LeftButton, pos=between)
    points = link_curve(doc, POSE, AREA).points
    assert len(points) == 5 and 0.2 < points[1][0] < 0.3 and points[1][1] > 0.1
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert link_curve(doc, POSE, AREA) == converted(EASE_IN, "custom")


# --------------------------------------------------------------------------- area edits

def test_area_edits_keep_the_curves_with_their_areas(qtbot, sample):
    from studio.widgets.document import Document
    from studio.widgets.paint.edits import delete_area, rename_area

    doc = Document(sample)
    names = [a.name for a in sample.influence.areas]
    set_link_curve(doc, POSE, AREA, EASE_IN)
    set_link_curve(doc, "surprise", "forehead left", ResponseCurve("ease_out"))
    assert rename_area(doc, names.index(AREA), "glabella")
    assert link_curve(doc, POSE, "glabella") == EASE_IN
    assert AREA not in doc.project.influence.curves[POSE]
    delete_area(doc, names.index(AREA))
    assert POSE not in doc.project.influence.curves  # no curve outlives its area
    assert link_curve(doc, "surprise", "forehead left") == ResponseCurve("ease_out")
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert link_curve(doc, POSE, AREA) == EASE_IN


def test_a_mirrored_area_takes_the_curves_of_its_source_to_the_paired_poses(qtbot, sample):
    from studio.core.wrinkles.surface_mirror import SurfaceMirror
    from studio.widgets.document import Document
    from studio.widgets.paint.edits import mirror_area

    doc = Document(sample)
    names = [a.name for a in sample.influence.areas]
    set_link_curve(doc, "brow_raise_left", "forehead left", EASE_IN)
    set_link_curve(doc, "brow_raise_right", "forehead right", ResponseCurve("ease_out"))
    set_link_curve(doc, "surprise", "forehead right", ResponseCurve("ease_in_out"))
    made = mirror_area(doc, names.index("forehead left"),
                       SurfaceMirror(sample.mesh, *doc.mirror_plane()))
    assert made.name == "forehead right"  # the paired area, replaced with its curves
    assert link_curve(doc, "brow_raise_right", "forehead right") == EASE_IN
    assert link_curve(doc, "surprise", "forehead right") == ResponseCurve()  # linear like left's
    doc.undo_stack.undo()
    assert link_curve(doc, "brow_raise_right", "forehead right") == ResponseCurve("ease_out")
    assert link_curve(doc, "surprise", "forehead right") == ResponseCurve("ease_in_out")
