"""The relief choice in the studio window (issue 10): switched in the shading panel, drawn by
the viewport, saved with the project, and offered as parallax where OpenGL 4.0 is missing."""

from __future__ import annotations

import numpy as np

from studio.core.project.reader import load_project
from studio.core.project.writer import save_project
from studio.core.sample.synthetic import sample_landmarks
from studio.render.renderer import FaceRenderer
from tests.gui_helpers import viewport_image, viewport_marks


def choose_relief(window, key: str) -> None:
    combo = window.shading_panel.relief
    combo.setCurrentIndex(combo.findData(key))
    combo.activated.emit(combo.currentIndex())


def profile(window) -> None:
    """The surprised forehead from the side, close up, without the vector overlay."""
    camera = window.doc.camera
    camera.yaw, camera.pitch = 90.0, 0.0
    camera.target = sample_landmarks(window.doc.project)["forehead"].astype(float)
    camera.distance *= 0.4
    window.viewport.overlays = []
    window.doc.set_pose_weight("surprise", 1.0)
    window.doc.cameraChanged.emit()


def outline(image: np.ndarray) -> np.ndarray:
    background = image[3, 3].astype(int)
    return np.abs(image.astype(int) - background).max(axis=2) > 0


def test_displace_in_the_shading_panel_puts_wrinkles_in_the_outline(window, tmp_path):
    profile(window)
    off = viewport_image(window)
    assert window.viewport.renderer.can_displace  # Mesa gives the 3.3 core request 4.5
    choose_relief(window, "displace")
    assert window.doc.view.relief == "displace"
    assert window.shading_panel.relief_depth.isEnabled()
    shown = viewport_image(window)
    _, y = viewport_marks(window)["forehead"]
    rows = slice(y - 40, y + 41)
    assert (outline(off)[rows] & ~outline(shown)[rows]).sum() > 10  # valleys cut the outline
    window.doc.set_view(relief_depth=0.0)
    flat = viewport_image(window)
    assert (outline(off)[rows] != outline(flat)[rows]).sum() <= 2
    path = tmp_path / "relief.wrinkle"
    window.doc.store_view_state()
    save_project(window.doc.project, path)
    view = load_project(path).view["view"]
    assert view["relief"] == "displace" and view["relief_depth"] == 0.0


def test_without_opengl_4_displace_falls_back_to_parallax(window, qtbot, dialogs, monkeypatch):
    monkeypatch.setattr(FaceRenderer, "can_displace", property(lambda self: False))
    profile(window)
    choose_relief(window, "displace")
    window.viewport.update()
    qtbot.waitUntil(lambda: window.doc.view.relief == "parallax", timeout=5000)
    qtbot.waitUntil(lambda: bool(dialogs), timeout=5000)
    assert "OpenGL 4.0" in dialogs[0][1] and "parallax" in dialogs[0][1]
    assert window.shading_panel.relief.currentData() == "parallax"
    dialogs.clear()

