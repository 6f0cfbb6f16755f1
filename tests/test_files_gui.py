"""User stories with real events on the real widgets: a project saved with Ctrl+S, the window
closed with Ctrl+Q, and the project reopened from File ▸ Open Recent in a new window; a damaged
file picked from the same menu, with the real error dialog answered by a key; opening cancelled
from its progress dialog; a lasso drawn with the mouse around the forehead, then Create.

Only the operating system's file chooser is replaced (it is not part of the studio); every other
step is a mouse click, a drag or a key press, and each story checks both the document and the
drawn image.
"""

from __future__ import annotations

import copy
import threading

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt, QTimer
from PySide6.QtWidgets import (
    QApplication,
    QFileDialog,
    QMenu,
    QMessageBox,
    QProgressDialog,
    QPushButton,
)

from studio.core.project import reader
from studio.core.project.model import Project
from studio.core.project.reader import load_project
from studio.core.sample.synthetic import make_test_face
from studio.widgets.app_settings import settings
from studio.widgets.wdv import edits
from tests.gui_helpers import drag_slider, viewport_image, viewport_marks
from tests.regions import region_difference
from tests.test_wdv_gui import drag, forehead_box

CTRL = Qt.KeyboardModifier.ControlModifier
LEFT = Qt.MouseButton.LeftButton


def fresh_sample() -> Project:
    """A private copy of the sample face (saving stores the view into the project)."""
    return copy.deepcopy(make_test_face())


def click_menu_path(qtbot, window, *titles: str) -> None:
    """Open the first title's menu with a click on the menu bar, then walk to each item with
    the arrow keys and press Enter on it (a submenu opens the same way); the last item is
    triggered. (Keys, not clicks, inside the menu: a menu ignores the pointer until it has
    moved since the menu opened, and under Xvfb the pointer may rest where an earlier test
    left it.)"""
    bar = window.menuBar()
    (top,) = [a for a in bar.actions() if a.text().replace("&", "") == titles[0]]
    qtbot.mouseClick(bar, LEFT, pos=bar.actionGeometry(top).center())
    menu: QMenu = top.menu()
    qtbot.waitUntil(menu.isVisible, timeout=5000)
    for title in titles[1:]:
        (action,) = [a for a in menu.actions() if a.text().replace("&", "") == title]
        for _ in range(len(menu.actions()) + 1):
            if menu.activeAction() is action:
                break
            qtbot.keyClick(menu, Qt.Key.Key_Down)
        assert menu.activeAction() is action, f"cannot reach {title} in the menu"
        qtbot.keyClick(menu, Qt.Key.Key_Return)
        if action.menu() is not None:
            menu = action.menu()
            qtbot.waitUntil(menu.isVisible, timeout=5000)


def answer_the_next_message_box(qtbot, seen: list[tuple[QMessageBox.Icon, str]]) -> None:
    """When a message box comes up (modal, so from inside the click that caused it), note its
    icon and text and press Enter on it — as a user dismissing the dialog would."""
    def look() -> None:
        box = QApplication.activeModalWidget()
        if not isinstance(box, QMessageBox):
            QTimer.singleShot(50, look)
            return
        seen.append((box.icon(), box.text()))
        qtbot.keyClick(box, Qt.Key.Key_Return)

    QTimer.singleShot(0, look)


def activate(qtbot, window) -> None:
    """Make the window the active one, as a click on it would (window shortcuts need it)."""
    window.activateWindow()
    window.raise_()
    qtbot.waitUntil(lambda: QApplication.activeWindow() is window, timeout=5000)


@pytest.fixture
def real_message_boxes(dialogs, monkeypatch) -> None:
    """Undo the ``dialogs`` fixture's recording stand-ins: this module sees the real boxes."""
    monkeypatch.undo()


def test_save_close_and_reopen_from_the_recent_files_menu(real_message_boxes, open_window,
                                                          qtbot, tmp_path, monkeypatch):
    settings().setValue("recent_files", [])
    window = open_window(fresh_sample())
    drag_slider(qtbot, window.pose_panel.pose_rows["surprise"].slider, 0.5)
    weight = window.doc.pose_weights["surprise"]
    assert 0.4 < weight < 0.6
    assert not window.isWindowModified()  # a view of the face, not an edit (issue #35)
    # the file chooser returns a name without the extension, as a user would type it
    chosen = tmp_path / "my face"
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda *a, **k: (str(chosen), "")))
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_S, CTRL)
    saved = tmp_path / "my face.wrinkle"
    assert saved.is_file() and window.doc.path == saved
    assert not window.isWindowModified() and "my face" in window.windowTitle()
    assert load_project(saved).pose("surprise") is not None
    shown = viewport_image(window)

    qtbot.keyClick(window, Qt.Key.Key_Q, CTRL)  # nothing unsaved: closes without asking
    qtbot.waitUntil(lambda: not window.isVisible(), timeout=5000)

    again = open_window(fresh_sample())
    assert again.doc.path is None and again.doc.pose_weights.get("surprise", 0.0) == 0.0
    assert not np.array_equal(viewport_image(again), shown)
    click_menu_path(qtbot, again, "File", "Open Recent", "my face.wrinkle")
    qtbot.waitUntil(lambda: again.doc.path == saved, timeout=10000)
    assert again.doc.pose_weights["surprise"] == pytest.approx(weight)
    assert not again.isWindowModified() and "my face" in again.windowTitle()
    drawn = again.viewport.frames_rendered
    qtbot.waitUntil(lambda: again.viewport.frames_rendered > drawn, timeout=10000)
    assert np.array_equal(viewport_image(again), shown)


def test_a_damaged_file_from_the_recent_menu_shows_the_error_dialog(real_message_boxes,
                                                                    open_window, qtbot,
                                                                    tmp_path):
    settings().setValue("recent_files", [])
    window = open_window(fresh_sample())
    path = tmp_path / "damaged.wrinkle"
    assert window.save_to(path)
    drag_slider(qtbot, window.pose_panel.pose_rows["frown"].slider, 1.0)
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_S, CTRL)  # saved again: nothing to ask about
    assert not window.isWindowModified()
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])  # cut short, as by a crash
    project, steps = window.doc.project, window.doc.undo_stack.count()
    before = viewport_image(window)

    seen: list[tuple[QMessageBox.Icon, str]] = []
    answer_the_next_message_box(qtbot, seen)
    click_menu_path(qtbot, window, "File", "Open Recent", "damaged.wrinkle")
    qtbot.waitUntil(lambda: bool(seen), timeout=10000)
    ((icon, error),) = seen
    assert icon == QMessageBox.Icon.Critical
    assert "damaged.wrinkle" in error and "damaged" in error.replace("damaged.wrinkle", "")
    # the open project is untouched, and the broken file is no longer offered
    assert window.doc.project is project and window.doc.undo_stack.count() == steps
    assert window.doc.pose_weights["frown"] == pytest.approx(1.0, abs=0.01)
    assert str(path.resolve()) not in window.recent_files()
    assert np.array_equal(viewport_image(window), before)


def test_opening_a_project_can_be_cancelled_and_keeps_the_open_one(real_message_boxes,
                                                                    open_window, qtbot,
                                                                    tmp_path, monkeypatch):
    """File ▸ Open reads the project on a worker thread behind a progress dialog: the window
    keeps drawing, and Cancel (clicked with the mouse) stops the load with nothing changed."""
    window = open_window(fresh_sample())
    assert window.save_to(tmp_path / "face.wrinkle")
    path = tmp_path / "big.wrinkle"
    path.write_bytes((tmp_path / "face.wrinkle").read_bytes())
    drag_slider(qtbot, window.pose_panel.pose_rows["frown"].slider, 1.0)
    project, steps = window.doc.project, window.doc.undo_stack.count()
    before = viewport_image(window)
    # hold the load after its first member until the test has pressed Cancel, so the dialog
    # is certainly up (a real large project takes seconds here)
    held, release = threading.Event(), threading.Event()
    real_read = reader._Loader.read

    def slow_read(self, name, what):
        data = real_read(self, name, what)
        if not held.is_set():
            held.set()
            release.wait(10)
        return data

    monkeypatch.setattr(reader._Loader, "read", slow_read)
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        staticmethod(lambda *a, **k: (str(path), "")))
    monkeypatch.setattr(window, "maybe_save", lambda: True)  # keep the edit: no question

    def press_cancel() -> None:
        dialog = window.findChild(QProgressDialog)
        if dialog is None or not dialog.isVisible():
            QTimer.singleShot(50, press_cancel)
            return
        assert held.is_set()
        (button,) = dialog.findChildren(QPushButton)
        qtbot.mouseClick(button, LEFT)
        release.set()

    QTimer.singleShot(0, press_cancel)
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_O, CTRL)
    assert release.is_set()  # the dialog came up and was cancelled
    assert window.doc.project is project and window.doc.path == tmp_path / "face.wrinkle"
    assert window.doc.undo_stack.count() == steps
    assert "cancelled" in window.statusBar().currentMessage()
    assert np.array_equal(viewport_image(window), before)

    monkeypatch.setattr(reader._Loader, "read", real_read)  # and the same file opens whole
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_O, CTRL)
    assert window.doc.path == path and window.doc.pose_weights.get("frown", 0.0) == 0.0


@pytest.fixture
def window_size() -> tuple[int, int]:
    return (1600, 1000)


def test_a_lasso_around_the_forehead_then_create_authors_its_vectors(window, qtbot):
    """A lasso drawn along a rectangle picks what a box over it picks; Create writes those
    vertices' wrinkle directions, and the surprise pose then wrinkles the forehead only."""
    doc, panel = window.doc, window.wdv_tools.panel
    edits.clear_areas(doc)
    qtbot.mouseClick(panel.add_button, LEFT)
    combo = panel.pose_combo
    combo.setCurrentIndex(combo.findData("surprise"))
    combo.activated.emit(combo.currentIndex())
    window.wdv_tools.overlay.visible = False  # judge the shading, not the outline drawn over it
    window.viewport.setFocus()
    qtbot.keyClick(window, Qt.Key.Key_S)
    assert window.viewport.tool is window.wdv_tools.tool
    start, end = forehead_box(window)
    drag(qtbot, window.viewport, start, end)
    boxed = doc.selection.copy()
    qtbot.mouseClick(panel.op_buttons["None"], LEFT)
    assert not doc.selection.any()

    qtbot.mouseClick(panel.mode_buttons["lasso"], LEFT)
    corners = [start, QPoint(end.x(), start.y()), end, QPoint(start.x(), end.y())]
    qtbot.mousePress(window.viewport, LEFT, pos=corners[0])
    for a, b in zip(corners, [*corners[1:], corners[0]], strict=True):
        for i in range(1, 7):
            qtbot.mouseMove(window.viewport, a + (b - a) * (i / 6))
    qtbot.mouseRelease(window.viewport, LEFT, pos=corners[0])
    lassoed = doc.selection.copy()
    assert lassoed.sum() > 30
    # the same vertices, give or take those on the outline itself
    assert (lassoed ^ boxed).sum() <= 0.05 * boxed.sum()

    marks = viewport_marks(window)
    doc.set_pose_weight("surprise", 1.0)
    unauthored = viewport_image(window)
    qtbot.mouseClick(panel.create_button, LEFT)
    (area,) = doc.project.wdv.areas
    rest = doc.project.mesh.rest
    delta = doc.project.pose("surprise").positions - rest
    length = np.linalg.norm(delta, axis=1)
    moving = lassoed & (length > 1e-6 * np.ptp(rest, axis=0).max())
    assert moving.sum() > 30
    assert np.allclose(area.directions[moving], delta[moving] / length[moving, None], atol=1e-5)
    assert not area.authored[~moving].any()
    after = viewport_image(window)
    assert region_difference(unauthored, after, marks["forehead"]) > 2.0
    for corner in ("eye corner right", "eye corner left"):
        assert region_difference(unauthored, after, marks[corner]) == 0.0
