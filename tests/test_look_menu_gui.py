"""Issue 46: View ▸ Look turns the clay view into the skin look, View ▸ Look ▸ Skin Lights picks
its rig, both from the menu bar as a person does, and the saved project opens with them."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog

from studio.core.project.reader import load_project
from tests.gui_helpers import viewport_image
from tests.test_files_gui import CTRL, activate, click_menu_path, fresh_sample


def _redrawn(qtbot, window) -> np.ndarray:
    drawn = window.viewport.frames_rendered
    qtbot.waitUntil(lambda: window.viewport.frames_rendered > drawn, timeout=10000)
    return viewport_image(window).astype(int)


def _face(image: np.ndarray) -> np.ndarray:
    return np.abs(image - image[2, 2]).max(-1) > 12


def _halves(image: np.ndarray) -> tuple[float, float]:
    """The mean brightness of the face's darker and lighter half (left and right of its
    middle column on screen)."""
    face = _face(image)
    columns = np.flatnonzero(face.any(axis=0))
    middle = (columns[0] + columns[-1]) // 2
    left, right = face.copy(), face.copy()
    left[:, middle:] = False
    right[:, :middle] = False
    dark, lit = sorted((image[left].mean(), image[right].mean()))
    return dark, lit


def test_the_skin_look_and_its_lights_from_the_view_menu_are_remembered(open_window, qtbot,
                                                                         tmp_path,
                                                                         monkeypatch):
    window = open_window(fresh_sample())
    assert window.doc.view.look == "clay"
    assert not window.look_menu.lights.isEnabled()  # the lights are the skin look's
    click_menu_path(qtbot, window, "View", "Look", "Clay")  # the layout settled, as after
    clay = _redrawn(qtbot, window)  # a person's first look around the menus
    face = _face(clay)

    click_menu_path(qtbot, window, "View", "Look", "Skin")
    skin = _redrawn(qtbot, window)
    assert window.doc.view.look == "skin" and window.look_menu.looks["skin"].isChecked()
    changed = np.abs(skin - clay).max(-1)[face] > 6
    assert changed.mean() > 0.3, changed.mean()

    click_menu_path(qtbot, window, "View", "Look", "Skin Lights", "Hard raking key")
    raking = _redrawn(qtbot, window)
    assert window.doc.view.light_rig == "raking"
    # one hard key from the side, no fill: the face's far half falls into shadow
    dark, lit = _halves(raking)
    studio_dark = _halves(skin)[0]
    assert dark < 0.6 * studio_dark and lit > 2 * dark, (dark, lit, studio_dark)

    saved = tmp_path / "look.wrinkle"
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        staticmethod(lambda *a, **k: (str(saved), "")))
    activate(qtbot, window)
    qtbot.keyClick(window, Qt.Key.Key_S, CTRL)
    assert saved.is_file()
    again = open_window(load_project(saved))
    assert (again.doc.view.look, again.doc.view.light_rig) == ("skin", "raking")
    assert again.look_menu.rigs["raking"].isChecked() and again.look_menu.lights.isEnabled()
    assert np.allclose(_halves(viewport_image(again).astype(int)), (dark, lit), rtol=0.1)
