"""The Furrows panel with real events (issue 45, point 6): on a face whose wrinkled maps the
studio synthesised (as New from Files does for a face that came without one), dragging Depth for
one pose deepens the forehead lines the viewport draws, as one undo step that Ctrl+Z takes back to
the map as synthesised; Spacing typed and Return is saved with Ctrl+S and shows again in the
panel of the reopened project."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QFileDialog, QSlider, QStyle, QStyleOptionSlider

from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face
from studio.core.setup.auto_setup import auto_start
from studio.core.wrinkles.influence import InfluenceSetup
from studio.core.wrinkles.textures import flat_normal_map
from studio.core.wrinkles.wdv import WdvSetup
from tests.gui_helpers import bring_forward, drag_slider, viewport_image, viewport_marks
from tests.regions import region_difference
from tests.test_files_gui import activate

CTRL = Qt.KeyboardModifier.ControlModifier
LEFT = Qt.MouseButton.LeftButton
POSE = "surprise"  # raises both brows: the forehead's lines


def save_with_ctrl_s(qtbot, window, monkeypatch, saved) -> None:
    """Ctrl+S on the window, the save dialog answering ``saved``: the file is written and the
    window no longer marked modified."""
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda *a, **k: (str(saved), "")))
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_S, CTRL)
    assert saved.is_file() and not window.isWindowModified()


@pytest.fixture(scope="module")
def synthesised_face():
    """The sample face as it would come from elsewhere (no areas, a flat wrinkled map), set up
    the way New from Files sets it up: areas from its poses and maps synthesised."""
    project = make_test_face()
    project.influence, project.wdv = InfluenceSetup(), WdvSetup()
    project.textures.wrinkle_maps = {"wrinkles": flat_normal_map(1024)}
    assert auto_start(project) is not None
    return project


def drag_handle(qtbot, slider: QSlider, fraction: float) -> None:
    """Press on the slider's handle where it is and drag it to ``fraction`` of the groove."""
    bring_forward(slider)
    option = QStyleOptionSlider()
    slider.initStyleOption(option)
    handle = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, option,
                                           QStyle.SubControl.SC_SliderHandle, slider)
    start, y = handle.center().x(), handle.center().y()
    end = round(handle.width() / 2 + (slider.width() - handle.width()) * fraction)
    qtbot.mousePress(slider, LEFT, pos=QPoint(start, y))
    for i in range(1, 11):
        qtbot.mouseMove(slider, QPoint(start + (end - start) * i // 10, y))
    qtbot.mouseRelease(slider, LEFT, pos=QPoint(end, y))


def choose_pose(qtbot, panel, name: str) -> None:
    """Walk the panel's pose list with the arrow key, as a person does on a focused list."""
    bring_forward(panel)
    panel.pose.setFocus()
    for _ in range(panel.pose.count()):
        if panel.pose.currentText() == name:
            return
        qtbot.keyClick(panel.pose, Qt.Key.Key_Down)
    assert panel.pose.currentText() == name


def type_value(qtbot, spin, text: str) -> None:
    qtbot.mouseClick(spin.lineEdit(), LEFT)
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_A, CTRL)
    qtbot.keyClicks(spin.lineEdit(), text)
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)


def settled_image(qtbot, window) -> np.ndarray:
    """The viewport once the maps made after the last edit are drawn: two grabs a moment
    apart alike (a grab draws the frame; the maps are made on the next turn of the loop)."""
    shown = [viewport_image(window)]

    def still() -> bool:
        shown.append(viewport_image(window))
        return np.array_equal(shown[-1], shown[-2])

    qtbot.wait(100)
    qtbot.waitUntil(still, timeout=30000)
    return shown[-1]


def test_depth_dragged_for_one_pose_deepens_its_lines_live_and_undoes_in_one_step(
        open_window, synthesised_face, qtbot, tmp_path, monkeypatch):
    window = open_window(copy.deepcopy(synthesised_face))
    doc, panel = window.doc, window.furrow_panel
    drag_slider(qtbot, window.pose_panel.pose_rows[POSE].slider, 1.0)
    (mine,) = doc.project.furrows.maps_of(POSE)
    synthesised = doc.project.textures.wrinkle_maps[mine]
    choose_pose(qtbot, panel, POSE)
    before = settled_image(qtbot, window)
    forehead = viewport_marks(window)["forehead"]
    steps = doc.undo_stack.count()

    drag_handle(qtbot, panel.rows["depth"].slider, 0.75)  # ×1 → ×3
    assert doc.project.furrows.of(POSE).depth == pytest.approx(3.0, abs=0.05)
    assert doc.undo_stack.count() == steps + 1  # the whole drag: one step
    qtbot.waitUntil(lambda: not np.array_equal(doc.project.textures.wrinkle_maps[mine],
                                               synthesised), timeout=20000)
    deeper = settled_image(qtbot, window)
    assert region_difference(deeper, before, forehead) > 4.0  # the lines the viewport draws
    assert panel.rows["depth"].spin.value() == pytest.approx(3.0, abs=0.05)

    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_Z, CTRL)
    assert doc.undo_stack.count() == steps + 1 and doc.undo_stack.index() == steps
    qtbot.waitUntil(lambda: np.array_equal(doc.project.textures.wrinkle_maps[mine],
                                           synthesised), timeout=20000)
    assert np.array_equal(settled_image(qtbot, window), before)  # as synthesised again
    assert panel.rows["depth"].spin.value() == 1.0

    type_value(qtbot, panel.rows["spacing"].spin, "2")
    assert doc.project.furrows.of(POSE).spacing == 2.0
    qtbot.waitUntil(lambda: not np.array_equal(doc.project.textures.wrinkle_maps[mine],
                                               synthesised), timeout=30000)
    spaced = doc.project.textures.wrinkle_maps[mine]
    assert region_difference(settled_image(qtbot, window), before, forehead) > 4.0

    saved = tmp_path / "spaced.wrinkle"
    save_with_ctrl_s(qtbot, window, monkeypatch, saved)
    reopened = load_project(saved)
    assert reopened.furrows.of(POSE).spacing == 2.0
    assert np.array_equal(reopened.textures.wrinkle_maps[mine], spaced)

    again = open_window(reopened)
    choose_pose(qtbot, again.furrow_panel, POSE)
    assert again.furrow_panel.rows["spacing"].spin.value() == 2.0
    assert again.furrow_panel.rows["depth"].spin.value() == 1.0
